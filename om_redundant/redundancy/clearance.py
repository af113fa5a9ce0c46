r"""Obstacle clearance of an arm, computed with MuJoCo's kinematics.

The clearance of joint vector q is the smallest signed distance between the arm's collision
geoms and the obstacle geoms,

.. math::  D(q) = \min_k d_k(q), \qquad d_k(q) = \mathrm{dist}\big(A_k(q), O_k\big),

over the pairs k of (arm geom :math:`A_k`, obstacle geom :math:`O_k`), negative when the
geoms overlap, capped at ``distmax``. One ``mj_kinematics`` places the geoms; a compiled
kernel (``ckernels.geom_distances``, ``csrc/clearance.c``) computes the pairs of a sphere or
capsule arm geom and a sphere, capsule or box obstacle that do not touch, exactly (closest
points of segments, and of a segment and a box, in closed form), and
``mujoco.mj_geomDistance`` the rest (other kinds, touching or overlapping geoms);
``tests/test_clearance.py`` checks the kernel against ``mj_geomDistance``. With
:math:`p_A, p_O` the nearest points and :math:`n_k = (p_O - p_A)/d_k` the unit direction
from the arm geom to the obstacle (the division by the signed distance keeps it pointing
that way when the geoms overlap), moving the arm point by :math:`dp` changes the distance
by :math:`-n_k \cdot dp`, so

.. math::  \frac{\partial d_k}{\partial q_j} = -n_k \cdot \big(a_j \times (p_A - o_j)\big)

for each hinge joint j that moves the arm geom (axis :math:`a_j` through :math:`o_j`,
MuJoCo's ``xaxis`` and ``xanchor``; :math:`-n_k \cdot a_j` for a slide joint), computed by
``ckernels.distance_gradients``. A pair farther apart than ``distmax`` reports ``distmax``
with a zero gradient.

Obstacles come three ways: simple shapes (:class:`Sphere`, :class:`Capsule`, :class:`Box`)
or the primitive geoms of a MuJoCo model, placed in the arm's root frame and combined with
the project's MJCF of the arm (:meth:`Clearance.for_arm`); or geoms named in the user's own
MuJoCo model that contains the arm, its joints found by name with an optional prefix
(:class:`Clearance`). The arm's collision geoms are the geoms with a non-zero ``contype`` or
``conaffinity`` on the bodies that the arm's joints move.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import mujoco
import numpy as np

from .. import ckernels
from ..exceptions import InvalidInput
from ..kinematics.arm import Arm
from ..mujoco_io.arm_in_model import ArmJoints
from ..mujoco_io.mjcf import arm_mjcf
from ..validation import as_instance, as_joint_vector, as_positive
from .shapes import Shape, model_geoms, shape_geoms

DEFAULT_DISTMAX = 1.0  # m: pairs farther apart report this distance


class Clearance:
    """Signed distances between an arm's collision geoms and obstacle geoms (module docstring).

    Args:
        model: A MuJoCo model holding the arm and the obstacles, e.g. the user's scene.
        arm: The arm; its joints are found in the model as ``prefix + joint name``.
        obstacle_geoms: Names of the obstacle geoms in the model.
        prefix: Prepended to the arm's joint names.
        distmax: Pairs farther apart than this (m) report ``distmax``.

    Raises:
        JointNotFound: A joint is not in the model (as in :class:`~om_redundant.ArmJoints`).
        ModelMismatch: A joint's type differs from the arm's.
        InvalidInput: A geom is missing, an obstacle geom moves with the arm, no obstacle is
            given, or distmax is not positive.

    Example::

        clearance = om.Clearance.for_arm(arm, [om.Sphere([0.5, 0.0, 0.4], 0.05)])
        clearance.minimum(q)  # metres
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        arm: Arm,
        obstacle_geoms: Sequence[str],
        *,
        prefix: str = "",
        distmax: float = DEFAULT_DISTMAX,
    ):
        as_instance(model, mujoco.MjModel, "model", "a mujoco.MjModel")
        as_instance(arm, Arm, "arm")
        names = isinstance(obstacle_geoms, Sequence) and not isinstance(obstacle_geoms, str)
        if not (names and all(isinstance(g, str) for g in obstacle_geoms)):
            raise InvalidInput(f"obstacle_geoms must be a sequence of geom names, got {obstacle_geoms!r}")
        self.model, self.arm, self._dof = model, arm, arm.dof
        self.distmax = as_positive(distmax, "distmax")
        self._data = mujoco.MjData(model)
        # the data's arrays that each evaluation writes or reads (views of its buffers)
        d = self._data
        self._views = (d.qpos, d.geom_xpos, d.geom_xmat, d.xanchor, d.xaxis)
        joints = ArmJoints(arm, model, prefix)
        self._qpos = joints.qpos_index
        moving = _subtree(model, model.jnt_bodyid[joints.joint_ids[0]])
        arm_geoms = [
            g
            for g in range(model.ngeom)
            if moving[model.geom_bodyid[g]] and (model.geom_contype[g] or model.geom_conaffinity[g])
        ]
        if not obstacle_geoms:
            raise InvalidInput("no obstacle geoms given")
        obstacles = [_find(model, mujoco.mjtObj.mjOBJ_GEOM, name, "geom") for name in obstacle_geoms]
        for o in obstacles:
            if moving[model.geom_bodyid[o]]:
                raise InvalidInput(f"obstacle geom '{model.geom(o).name}' moves with the arm")
        self._pairs = np.array([(a, o) for a in arm_geoms for o in obstacles], dtype=np.int64).reshape(-1, 2)
        # bounding-sphere radii of each pair (MuJoCo's rbound; 0 means unbounded, a plane)
        rbound = np.where(model.geom_rbound > 0.0, model.geom_rbound, np.inf)
        self._geoms = _geom_cores(model, self._pairs, rbound, joints)
        self.pairs: tuple[tuple[str, str], ...] = tuple(
            (model.geom(a).name, model.geom(o).name) for a, o in self._pairs
        )

    @classmethod
    def for_arm(
        cls,
        arm: Arm,
        obstacles: Sequence[Shape | mujoco.MjModel] | mujoco.MjModel,
        *,
        radius: float | None = None,
        distmax: float = DEFAULT_DISTMAX,
    ) -> Clearance:
        """The project's MJCF of the arm (:func:`~om_redundant.arm_mjcf`) with obstacles added.

        Args:
            arm: The arm; its root frame is the model's world frame.
            obstacles: Shapes, or a MuJoCo model whose primitive geoms (plane, sphere,
                capsule, ellipsoid, cylinder, box), as placed at its ``qpos0``, are the obstacles;
                or a sequence mixing both (e.g. a scene and a few shapes).
            radius: Capsule radius of the arm's MJCF (default: :func:`~om_redundant.arm_mjcf`'s).
            distmax: As in :class:`Clearance`.
        """
        as_instance(arm, Arm, "arm")
        geoms = model_geoms(obstacles) if isinstance(obstacles, mujoco.MjModel) else shape_geoms(obstacles)
        spec = mujoco.MjSpec.from_string(arm_mjcf(arm, radius=radius))
        taken = {g.name for g in spec.geoms}
        for g in geoms:
            if g.name in taken:
                raise InvalidInput(f"obstacle name '{g.name}' is already taken")
            taken.add(g.name)
            spec.worldbody.add_geom(name=g.name, type=g.type, size=g.size, pos=g.pos, quat=g.quat)
        return cls(spec.compile(), arm, [g.name for g in geoms], distmax=distmax)

    def distances(self, q: np.ndarray) -> np.ndarray:
        """Signed distance d_k(q) of every pair (m), in the order of :attr:`pairs`: (P,) for
        a joint vector q (dof,), (M, P) for the rows of q (M, dof)."""
        if np.ndim(q) == 2:
            rows = [self._evaluate(row, gradient=False)[0] for row in q]
            return np.array(rows).reshape(len(q), len(self._pairs))
        return self._evaluate(q, gradient=False)[0]

    def minimum(self, q: np.ndarray) -> float:
        """The clearance D(q) = min_k d_k(q) in metres."""
        return float(self.distances(q).min())

    def distances_and_gradients(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """d_k(q) and their gradients dd_k/dq (module docstring): (P,) and (P, dof) for a
        joint vector q (dof,), (M, P) and (M, P, dof) for the rows of q (M, dof), one
        ``mj_kinematics`` per row."""
        if np.ndim(q) == 2:
            q = as_joint_vector(q, self._dof)
            shape = (len(q), len(self._pairs))
            dist, grad = np.empty(shape), np.empty((*shape, self._dof))
            fromto = np.empty((len(self._pairs), 6))  # scratch: each pair's slot is written afresh
            for row, row_dist, row_grad in zip(q, dist, grad, strict=True):
                self._measure(row, self.distmax, row_dist, fromto, row_grad)
            return dist, grad
        return self._evaluate(q, gradient=True)

    def distances_within(
        self, q: np.ndarray, reach: float, gradient: bool = False
    ) -> tuple[np.ndarray, np.ndarray]:
        r"""Like :meth:`distances_and_gradients` with distances capped at ``reach`` instead
        of ``distmax``: :math:`\min(d_k(q), reach)`, zero gradients where capped. Only the
        pairs whose bounding spheres come within ``reach`` are computed (one vectorised test
        on the geoms' centres and radii), which is what makes it cheap with far obstacles.

        Args:
            q: (dof,) joint vector.
            reach: Cap (m), positive, at most ``distmax``.
            gradient: Also compute the gradients (else they are zero).

        Returns:
            (P,) distances and (P, dof) gradients, in the order of :attr:`pairs`.
        """
        return self._evaluate(q, gradient, min(as_positive(reach, "reach"), self.distmax))

    def minima(self, q: np.ndarray) -> np.ndarray:
        """The clearance D(q) of every row of q, as :meth:`minimum` gives it.

        Args:
            q: (M, dof) joint vectors.

        Returns:
            (M,) clearances in metres (at most ``distmax``).
        """
        return self.distances(as_joint_vector(q, self._dof).reshape(-1, self._dof)).min(axis=1)

    def _evaluate(
        self, q: np.ndarray, gradient: bool, reach: float | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Distances capped at reach (default distmax), and their gradients if asked (else
        zero): :meth:`_measure` into new arrays."""
        q = as_joint_vector(q, self._dof, stack=False)
        n_pairs = len(self._pairs)
        dist, fromto = np.empty(n_pairs), np.empty((n_pairs, 6))
        grad = np.empty((n_pairs, self._dof)) if gradient else np.zeros((n_pairs, self._dof))
        self._measure(q, self.distmax if reach is None else reach, dist, fromto, grad if gradient else None)
        return dist, grad

    def _measure(
        self, q: np.ndarray, reach: float, dist: np.ndarray, fromto: np.ndarray, grad: np.ndarray | None
    ) -> None:
        """Write the distances capped at reach, the nearest points and (unless ``grad`` is
        None) the gradients at the joint vector q: one ``mj_kinematics``, then
        ``ckernels.geom_distances`` (sphere and capsule arm geoms against sphere, capsule and
        box obstacles, apart) with ``mj_geomDistance`` for the pairs it leaves, and
        ``ckernels.distance_gradients`` (module docstring)."""
        m, d, geoms, (qpos, xpos, xmat, xanchor, xaxis) = self.model, self._data, self._geoms, self._views
        qpos[self._qpos] = q
        mujoco.mj_kinematics(m, d)
        if ckernels.geom_distances(
            geoms.kind,
            geoms.radius,
            geoms.half,
            xpos,
            xmat,
            self._pairs,
            geoms.bounds,
            reach,
            dist,
            fromto,
        ):
            for k in np.flatnonzero(np.isnan(dist)).tolist():
                a, o = self._pairs[k].tolist()
                dist[k] = mujoco.mj_geomDistance(m, d, a, o, reach, fromto[k])
        if grad is not None:  # every row written
            ckernels.distance_gradients(
                dist, fromto, reach, xanchor, xaxis, geoms.joints, geoms.slide, geoms.moves, grad
            )


class GeomCores(NamedTuple):
    """What ``ckernels.geom_distances`` and ``distance_gradients`` read of a model, set up
    once per :class:`Clearance`.

    Attributes:
        kind: (G,) each geom's core: 1 a point (sphere), 2 a segment (capsule), 3 a box;
            0 where MuJoCo computes its distances (other kinds, arm geoms other than
            spheres and capsules).
        radius: (G,) radius about the core (0 for a box).
        half: (G, 3) half length of a segment along its z axis (0, 0, l); a box's half sizes.
        bounds: (P,) sum of each pair's bounding-sphere radii (inf: a plane).
        joints: (dof,) the arm's joint ids in the model.
        slide: (dof,) which of them slide (else hinges).
        moves: (P, dof) whether joint j moves pair k's arm geom.
    """

    kind: np.ndarray
    radius: np.ndarray
    half: np.ndarray
    bounds: np.ndarray
    joints: np.ndarray
    slide: np.ndarray
    moves: np.ndarray


def _geom_cores(model: mujoco.MjModel, pairs: np.ndarray, rbound: np.ndarray, joints: ArmJoints) -> GeomCores:
    kind = np.zeros(model.ngeom, dtype=np.int64)
    radius, half = np.zeros(model.ngeom), np.zeros((model.ngeom, 3))
    for g in range(model.ngeom):
        size = model.geom_size[g]
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:
            kind[g], radius[g] = 1, size[0]
        elif model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE:
            kind[g], radius[g], half[g, 2] = 2, size[0], size[1]
        elif model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX:
            kind[g], half[g] = 3, size
    inside = np.array([_subtree(model, model.jnt_bodyid[j]) for j in joints.joint_ids])  # (dof, nbody)
    moves = np.ascontiguousarray(inside[:, model.geom_bodyid[pairs[:, 0]]].T)
    return GeomCores(
        kind,
        radius,
        half,
        np.ascontiguousarray(rbound[pairs[:, 0]] + rbound[pairs[:, 1]]),
        np.ascontiguousarray(joints.joint_ids, dtype=np.int64),
        model.jnt_type[joints.joint_ids] == mujoco.mjtJoint.mjJNT_SLIDE,
        moves,
    )


def _find(model: mujoco.MjModel, kind: mujoco.mjtObj, name: str, what: str) -> int:
    index = mujoco.mj_name2id(model, kind, name)
    if index < 0:
        raise InvalidInput(f"the MuJoCo model has no {what} named '{name}'")
    return index


def _subtree(model: mujoco.MjModel, root: int) -> np.ndarray:
    """Whether each body is ``root`` or one of its descendants."""
    inside = np.zeros(model.nbody, dtype=bool)
    for b in range(model.nbody):  # parents come before their children
        inside[b] = b == root or (b > 0 and inside[model.body_parentid[b]])
    return inside
