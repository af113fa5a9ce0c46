r"""Obstacle clearance of an arm, computed with the arm's own kinematics.

The clearance of joint vector q is the smallest signed distance between the arm's collision
geoms and the obstacle geoms,

.. math::  D(q) = \min_k d_k(q), \qquad d_k(q) = \mathrm{dist}\big(A_k(q), O_k\big),

over the pairs k of (arm geom :math:`A_k`, obstacle geom :math:`O_k`), negative when the
geoms overlap, capped at ``distmax``. The arm geoms are placed by the arm's DH chain: a geom
moved by joints 1..l sits at a fixed offset :math:`G` in link l's frame :math:`F_l(q)` (the
chain's frame before joint l+1's row), :math:`X(q) = K F_l(q) G`, with :math:`K` the world
pose of DH frame 0. Both are taken once from the model at its ``qpos0``: :math:`K` carries
the joints' axis lines of the chain onto MuJoCo's (``xaxis``, ``xanchor``), and
:math:`G = (K F_l(q_0))^{-1} X(q_0)`; the set-up checks the placement against MuJoCo's
``mj_kinematics`` at random joint vectors (:class:`~om_redundant.ModelMismatch` otherwise).
One compiled call (``ckernels.arm_clearance``, ``csrc/clearance.c``) places the geoms for
every row of a batch of joint vectors and computes the pairs of a sphere or capsule arm
geom and a sphere, capsule or box obstacle exactly (closest points of segments, and of a
segment and a box, in closed form; overlapping where the cores do not touch), and
``mujoco.mj_geomDistance`` the rest (other kinds, cores touching, boxes touched), the arm
geoms placed as the kernel places them; ``tests/test_clearance.py`` checks both against
MuJoCo. Where MuJoCo says a sphere or capsule is apart from a box that its core overlaps (its
box-capsule distance is positive for about 0.3 % of such pairs, up to 0.09 m, a capsule
through a thin box), the exact signed distance is taken instead (``ckernels.box_overlap``).
With :math:`p_A, p_O` the nearest points and :math:`n_k = (p_O - p_A)/d_k` the unit direction
from the arm geom to the obstacle (the division by the signed distance keeps it pointing that
way when the geoms overlap), moving the arm point by :math:`dp` changes the distance by
:math:`-n_k \cdot dp`, so

.. math::  \frac{\partial d_k}{\partial q_j} = -n_k \cdot \big(a_j \times (p_A - o_j)\big)

for each revolute joint j <= l (axis :math:`a_j` through :math:`o_j`, the z axis and origin
of the chain's frame before joint j's row; :math:`-n_k \cdot a_j` for a prismatic joint),
computed in the same call. A pair farther apart than ``distmax`` reports ``distmax`` with a
zero gradient.

Obstacles come three ways: simple shapes (:class:`Sphere`, :class:`Capsule`, :class:`Box`)
or the primitive geoms of a MuJoCo model, placed in the arm's root frame and combined with
the project's MJCF of the arm (:meth:`Clearance.for_arm`); or geoms named in the user's own
MuJoCo model that contains the arm, its joints found by name with an optional prefix
(:class:`Clearance`). The arm's collision geoms are the geoms with a non-zero ``contype`` or
``conaffinity`` on the bodies that the arm's joints move; the model's other joints (a
gripper's) stay at ``qpos0``.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from typing import NamedTuple

import mujoco
import numpy as np

from .. import ckernels
from ..exceptions import InvalidInput, ModelMismatch
from ..kinematics.arm import Arm
from ..mujoco_io.arm_in_model import MATCH_TOLERANCE, ArmJoints
from ..mujoco_io.mjcf import arm_mjcf
from ..validation import as_instance, as_joint_vector, as_positive
from .shapes import Shape, model_geoms, shape_geoms

DEFAULT_DISTMAX = 1.0  # m: pairs farther apart report this distance
_CHECKS = 3  # random joint vectors at which the geoms' placement is checked against MuJoCo's


#: The largest coordinate or size (m) of an obstacle geom: distances are computed in doubles to
#: about 1e-16 of the largest coordinates, 1e-10 m at this extent; beyond about 1e154 their
#: squares overflow (a sphere of radius 1e155 about the arm was reported clear).
MAX_EXTENT = 1e6

_POINT, _SEGMENT, _BOX = 1, 2, 3  # ArmCores.kind: the cores that ckernels.arm_clearance computes


class Clearance:
    """Signed distances between an arm's collision geoms and obstacle geoms (module docstring).

    Threads may share one: its MuJoCo data, where the pairs left to MuJoCo are computed, is
    taken by one call at a time.

    Args:
        model: A MuJoCo model holding the arm and the obstacles, e.g. the user's scene.
        arm: The arm; its joints are found in the model as ``prefix + joint name``.
        obstacle_geoms: Names of the obstacle geoms in the model.
        prefix: Prepended to the arm's joint names; default the arm's (``arm.prefix``).
        distmax: Pairs farther apart than this (m) report ``distmax``.

    Raises:
        JointNotFound: A joint is not in the model (as in :class:`~om_redundant.ArmJoints`).
        ModelMismatch: A joint's type differs from the arm's, or the arm's collision geoms do
            not move like its kinematic chain (another arm).
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
        prefix: str | None = None,
        distmax: float = DEFAULT_DISTMAX,
    ):
        as_instance(model, mujoco.MjModel, "model", "a mujoco.MjModel")
        as_instance(arm, Arm, "arm")
        names = isinstance(obstacle_geoms, Sequence) and not isinstance(obstacle_geoms, str)
        if not (names and all(isinstance(g, str) for g in obstacle_geoms)):
            raise InvalidInput(f"obstacle_geoms must be a sequence of geom names, got {obstacle_geoms!r}")
        self.model, self.arm, self._dof = model, arm, arm.dof
        self.distmax = as_positive(distmax, "distmax")
        joints = ArmJoints(arm, model, prefix)
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
        # the model's geom ids of each pair (arm geom, obstacle) and the arm geom's index, for
        # mj_geomDistance
        self._pair_geoms = [(a, o, i) for i, a in enumerate(arm_geoms) for o in obstacles]
        self._arm_ids = np.array(arm_geoms, dtype=np.int64)
        self._data = mujoco.MjData(model)  # at qpos0, placed: the obstacles and mj_geomDistance's scratch
        mujoco.mj_kinematics(model, self._data)
        for o in obstacles:
            extent = max(np.abs(self._data.geom_xpos[o]).max(), model.geom_size[o].max())
            if not extent <= MAX_EXTENT:
                raise InvalidInput(
                    f"obstacle geom '{model.geom(o).name}': its position and sizes must be within "
                    f"{MAX_EXTENT:g} m, got {extent:.3g} m"
                )
        self._placed = (self._data.geom_xpos, self._data.geom_xmat)  # (views of the data's arrays)
        self._data_lock = threading.Lock()  # the data is every call's scratch: one call at a time
        self._cores = _arm_cores(model, self._data, joints, arm_geoms, obstacles)
        # arm_clearance's arguments before and after q
        self._arguments, self._n_pairs = (self._cores[:5], self._cores[5:]), len(self._pair_geoms)
        self.arm_geoms: tuple[str, ...] = tuple(model.geom(g).name for g in arm_geoms)
        _check_placement(self, joints)
        self.pairs: tuple[tuple[str, str], ...] = tuple(
            (model.geom(a).name, model.geom(o).name) for a, o, _ in self._pair_geoms
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
        return self._evaluate(q, self.distmax, gradient=False)[0]

    def minimum(self, q: np.ndarray) -> float:
        """The clearance D(q) = min_k d_k(q) in metres."""
        return float(self.distances(q).min())

    def distances_and_gradients(self, q: np.ndarray, near: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
        """d_k(q) and their gradients dd_k/dq (module docstring): (P,) and (P, dof) for a
        joint vector q (dof,), (M, P) and (M, P, dof) for the rows of q (M, dof), all rows
        in one ``ckernels.arm_clearance`` call.

        Args:
            q: (dof,) joint vector, or (M, dof) rows.
            near: Where a pair of a row is nearer than this (m), only the gradients of the
                pairs nearer than it, the others zero (the objective reads no more:
                :attr:`Objective.clearance_reach
                <om_redundant.redundancy.objective.Objective.clearance_reach>`); all by default.
        """
        return self._evaluate(q, self.distmax, gradient=True, near=near)

    def distances_within(
        self, q: np.ndarray, reach: float, gradient: bool = False
    ) -> tuple[np.ndarray, np.ndarray]:
        r"""Like :meth:`distances_and_gradients` with distances capped at ``reach`` instead
        of ``distmax``: :math:`\min(d_k(q), reach)`, zero gradients where capped. Only the
        pairs whose bounding spheres come within ``reach`` are computed (a test on the
        geoms' centres and radii), which is what makes it cheap with far obstacles.

        Args:
            q: (dof,) joint vector, or (M, dof) rows.
            reach: Cap (m), positive, at most ``distmax``.
            gradient: Also compute the gradients (else they are zero).

        Returns:
            (P,) distances and (P, dof) gradients, in the order of :attr:`pairs`; (M, P) and
            (M, P, dof) for rows.
        """
        dist, grad = self._evaluate(q, min(as_positive(reach, "reach"), self.distmax), gradient)
        return dist, np.zeros((*dist.shape, self._dof)) if grad is None else grad

    def minima(self, q: np.ndarray) -> np.ndarray:
        """The clearance D(q) of every row of q, as :meth:`minimum` gives it.

        Args:
            q: (M, dof) joint vectors.

        Returns:
            (M,) clearances in metres (at most ``distmax``).
        """
        return self.distances(as_joint_vector(q, self._dof).reshape(-1, self._dof)).min(axis=1)

    def geom_poses(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where the arm's collision geoms are at the joint vector q (module docstring).

        Args:
            q: (dof,) joint vector.

        Returns:
            (A, 3) positions and (A, 3, 3) rotations in the model's world frame, in the order
            of :attr:`arm_geoms`.
        """
        q = as_joint_vector(q, self._dof, stack=False)
        xpos, xmat = np.empty((len(self.arm_geoms), 3)), np.empty((len(self.arm_geoms), 9))
        ckernels.arm_geom_poses(*self._arguments[0], q, xpos, xmat)
        return xpos, xmat.reshape(-1, 3, 3)

    def _evaluate(
        self, q: np.ndarray, reach: float, gradient: bool, near: float = math.inf
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Distances capped at reach and, if asked (else None), their gradients (only the
        pairs nearer than ``near`` where one is: :meth:`distances_and_gradients`) at a joint
        vector or the rows of q: one ``ckernels.arm_clearance`` call, then
        ``mj_geomDistance`` for the pairs it leaves (:meth:`_by_mujoco`)."""
        q = as_joint_vector(q, self._dof)
        shape = (*q.shape[:-1], self._n_pairs)
        dist, fromto = np.empty(shape), np.empty((*shape, 6))
        grad = np.empty((*shape, self._dof)) if gradient else None
        arm, geoms = self._arguments
        if ckernels.arm_clearance(*arm, q, *geoms, reach, near, dist, fromto, grad, False):
            self._by_mujoco(
                q.reshape(-1, self._dof), reach, near, dist.reshape(-1, self._n_pairs), fromto, grad
            )
        return dist, grad

    def _by_mujoco(
        self,
        q: np.ndarray,
        reach: float,
        near: float,
        dist: np.ndarray,
        fromto: np.ndarray,
        grad: np.ndarray | None,
    ) -> None:
        """The pairs ``ckernels.arm_clearance`` left (nan: kinds it does not compute, cores
        touching, boxes touched) by ``mj_geomDistance``, the arm geoms placed as it places
        them (all those rows' in one call), and those rows' gradients (in one call)."""
        m, d, n_pairs = self.model, self._data, self._n_pairs
        fromto = fromto.reshape(-1, n_pairs, 6)
        left = np.isnan(dist)
        rows = np.flatnonzero(left.any(axis=1))
        arm, geoms = self._arguments
        n_arm = len(self._arm_ids)
        xpos, xmat = np.empty((len(rows), n_arm, 3)), np.empty((len(rows), n_arm, 9))
        ckernels.arm_geom_poses(*arm, q[rows], xpos, xmat)
        at, placed = rows.tolist(), self._placed
        kind, radius, half = self._cores.kind, self._cores.radius, self._cores.half
        for r, k in np.argwhere(left[rows]).tolist():  # (only the pair's arm geom placed: the one read)
            a, o, i = self._pair_geoms[k]
            with self._data_lock:
                placed[0][a], placed[1][a] = xpos[r, i], xmat[r, i]
                found = mujoco.mj_geomDistance(m, d, a, o, reach, fromto[at[r], k])
            b = self._cores.pairs[k, 1]
            if found > 0.0 and kind[b] == _BOX and kind[i] in (_POINT, _SEGMENT):
                # The kernel leaves such a pair where the cores say it overlaps; MuJoCo's
                # box-capsule distance can be positive for a capsule whose core pierces a
                # thin box (0.3 % of such pairs, up to 0.09 m): the exact depth instead.
                found = ckernels.box_overlap(
                    xpos[r, i],
                    xmat[r, i],
                    half[i],
                    radius[i],
                    d.geom_xpos[o],
                    d.geom_xmat[o],
                    half[b],
                    fromto[at[r], k],
                )
            dist[at[r], k] = found
        if grad is not None:
            given = np.empty((len(rows), n_pairs, self._dof))
            ckernels.arm_clearance(*arm, q[rows], *geoms, reach, near, dist[rows], fromto[rows], given, True)
            grad.reshape(-1, n_pairs, self._dof)[rows] = given


class ArmCores(NamedTuple):
    """What ``ckernels.arm_clearance`` reads, in its order, set up once per :class:`Clearance`:
    the arm's links (its DH chain placed in the world) with the arm geoms' offsets in them,
    and the geoms as cores, the arm's A geoms first, then the O obstacles (G = A + O).

    Attributes:
        table: The arm's DH table (``KinematicChain.table``).
        start: (12,) world pose of DH frame 0: rotation (row-major) and position.
        link: (A,) each arm geom's link: the number of the arm's joints that move it.
        offset: (A, 12) each arm geom's pose in its link's frame, as ``start``.
        slide: (dof,) which joints slide (else turn).
        obstacle_pos, obstacle_mat: (O, 3), (O, 9) the obstacles' world poses.
        kind: (G,) each geom's core: 1 a point (sphere), 2 a segment (capsule), 3 a box;
            0 where MuJoCo computes its distances (other kinds, arm geoms other than
            spheres and capsules).
        radius: (G,) radius about the core (0 for a box).
        half: (G, 3) half length of a segment along its z axis (0, 0, l); a box's half sizes.
        pairs: (P, 2) each pair's geoms: (arm geom, obstacle) in this numbering.
        bounds: (P,) sum of each pair's bounding-sphere radii (inf: a plane).
    """

    table: np.ndarray
    start: np.ndarray
    link: np.ndarray
    offset: np.ndarray
    slide: np.ndarray
    obstacle_pos: np.ndarray
    obstacle_mat: np.ndarray
    kind: np.ndarray
    radius: np.ndarray
    half: np.ndarray
    pairs: np.ndarray
    bounds: np.ndarray


def _arm_cores(
    model: mujoco.MjModel, data: mujoco.MjData, joints: ArmJoints, arm_geoms: list[int], obstacles: list[int]
) -> ArmCores:
    """The :class:`ArmCores` of a model placed at its ``qpos0`` in data: DH frame 0's world
    pose fitted to the joints' axis lines (:func:`_dh_frame_zero`), and each arm geom's
    offset in its link, :math:`G = F_l(q_0)^{-1} X(q_0)` at the arm's joints in ``qpos0``."""
    arm, geoms = joints.arm, arm_geoms + obstacles
    table = np.ascontiguousarray(arm.chain.table)
    slide = np.ascontiguousarray(~arm.revolute, dtype=np.uint8)
    q0 = np.ascontiguousarray(data.qpos[joints.qpos_ids])
    frames = _link_frames(table, np.concatenate([np.eye(3).ravel(), np.zeros(3)]), slide, q0)
    start = _dh_frame_zero(frames, data.xaxis[joints.joint_ids], data.xanchor[joints.joint_ids], arm.revolute)
    frames = _link_frames(table, _as_row(start), slide, q0)
    inside = np.array([_subtree(model, model.jnt_bodyid[j]) for j in joints.joint_ids])  # (dof, nbody)
    link = inside[:, model.geom_bodyid[arm_geoms]].sum(axis=0)
    for g, n in zip(arm_geoms, link.tolist(), strict=True):
        if not inside[:n, model.geom_bodyid[g]].all():
            raise ModelMismatch(
                f"geom '{model.geom(g).name}' is moved by joints of arm '{arm.name}' out of the chain's order"
            )
    offset = np.empty((len(arm_geoms), 12))
    for a, (g, n) in enumerate(zip(arm_geoms, link.tolist(), strict=True)):
        X = np.eye(4)
        X[:3, :3], X[:3, 3] = data.geom_xmat[g].reshape(3, 3), data.geom_xpos[g]
        offset[a] = _as_row(np.linalg.solve(frames[n], X))
    kind = np.zeros(len(geoms), dtype=np.int64)
    radius, half = np.zeros(len(geoms)), np.zeros((len(geoms), 3))
    for i, g in enumerate(geoms):
        size = model.geom_size[g]
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:
            kind[i], radius[i] = _POINT, size[0]
        elif model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE:
            kind[i], radius[i], half[i, 2] = _SEGMENT, size[0], size[1]
        elif model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX:
            kind[i], half[i] = _BOX, size
    n_arm = len(arm_geoms)
    pairs = np.array([(a, n_arm + o) for a in range(n_arm) for o in range(len(obstacles))], dtype=np.int64)
    pairs = pairs.reshape(-1, 2)
    # bounding-sphere radii (MuJoCo's rbound; 0 means unbounded, a plane)
    rbound = np.where(model.geom_rbound[geoms] > 0.0, model.geom_rbound[geoms], np.inf)
    return ArmCores(
        table,
        np.ascontiguousarray(_as_row(start)),
        np.ascontiguousarray(link, dtype=np.int64),
        offset,
        slide,
        np.ascontiguousarray(data.geom_xpos[obstacles]),
        np.ascontiguousarray(data.geom_xmat[obstacles]),
        kind,
        radius,
        half,
        pairs,
        np.ascontiguousarray(rbound[pairs[:, 0]] + rbound[pairs[:, 1]]),
    )


def _link_frames(table: np.ndarray, start: np.ndarray, slide: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The (dof + 1, 4, 4) poses of links 0..dof at q, DH frame 0 at ``start`` (csrc/clearance.c):
    ``ckernels.arm_geom_poses`` of a geom at the origin of every link."""
    links = np.arange(len(q) + 1, dtype=np.int64)
    identity = np.tile(np.concatenate([np.eye(3).ravel(), np.zeros(3)]), (len(links), 1))
    xpos, xmat = np.empty((len(links), 3)), np.empty((len(links), 9))
    ckernels.arm_geom_poses(table, start, links, identity, slide, q, xpos, xmat)
    frames = np.tile(np.eye(4), (len(links), 1, 1))
    frames[:, :3, :3], frames[:, :3, 3] = xmat.reshape(-1, 3, 3), xpos
    return frames


def _dh_frame_zero(
    frames: np.ndarray, axes: np.ndarray, anchors: np.ndarray, revolute: np.ndarray
) -> np.ndarray:
    r"""The world pose (4, 4) of the arm's DH frame 0 that carries the joints' axis lines in
    DH frame 0 (z axes and origins of ``frames``, links 0..dof-1 at the same q) onto the
    model's (MuJoCo's ``xaxis`` and ``xanchor``): the rotation by the SVD of
    :math:`\sum_j a_j w_j^T` (Kabsch), the translation by least squares of
    :math:`(I - w_j w_j^T)(R o_j + t - x_j) = 0` over the revolute joints (a slide's line may
    lie anywhere along its axis)."""
    a, o = frames[:-1, :3, 2], frames[:-1, :3, 3]
    U, _, Vt = np.linalg.svd(a.T @ axes)
    R = Vt.T @ np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))]) @ U.T
    across = np.eye(3) - axes[revolute, :, None] * axes[revolute, None, :]  # (n, 3, 3)
    rhs = np.einsum("nij,nj->ni", across, anchors[revolute] - o[revolute] @ R.T)
    t = np.linalg.lstsq(across.reshape(-1, 3), rhs.reshape(-1), rcond=None)[0]
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def _check_placement(clearance: Clearance, joints: ArmJoints) -> None:
    """The arm geoms' poses from the arm's chain (:meth:`Clearance.geom_poses`) must be
    MuJoCo's at random joint vectors within the limits, to :data:`MATCH_TOLERANCE`."""
    model, data = clearance.model, mujoco.MjData(clearance.model)
    low = np.where(np.isfinite(joints.lower), joints.lower, -np.pi)
    high = np.where(np.isfinite(joints.upper), joints.upper, np.pi)
    ids = clearance._arm_ids
    for q in np.random.default_rng(0).uniform(low, high, (_CHECKS, joints.arm.dof)):
        data.qpos[:] = joints.qpos_with(model.qpos0, q)
        mujoco.mj_kinematics(model, data)
        xpos, xmat = clearance.geom_poses(q)
        position = np.abs(xpos - data.geom_xpos[ids]).max(initial=0.0)
        rotation = np.abs(xmat.reshape(-1, 9) - data.geom_xmat[ids]).max(initial=0.0)
        if max(position, rotation) > MATCH_TOLERANCE:
            raise ModelMismatch(
                f"the collision geoms of arm '{joints.arm.name}' in the model do not move like its "
                f"kinematic chain ({position:.2g} m, {rotation:.2g} off at q = {np.round(q, 3).tolist()})"
            )


def _as_row(T: np.ndarray) -> np.ndarray:
    """A pose (4, 4) as (12,): rotation row-major, then position (csrc/clearance.c)."""
    return np.concatenate([T[:3, :3].ravel(), T[:3, 3]])


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
