r"""Obstacle clearance of an arm, computed with the arm's own kinematics.

The clearance of joint vector q is the smallest signed distance between the arm's collision
geoms and the obstacle geoms,

.. math::  D(q) = \min_k d_k(q), \qquad d_k(q) = \mathrm{dist}\big(A_k(q), O_k\big),

over the pairs k of (arm geom :math:`A_k`, obstacle geom :math:`O_k`), negative when the
geoms overlap, capped at ``distmax``. The arm geoms are placed by the arm's DH chain
(:mod:`~om_redundant.redundancy.objective.arm_geoms`: each at its offset in its link, checked against
MuJoCo's ``mj_kinematics`` at set-up). One compiled call (``_core.arm_clearance``,
``csrc/redundancy/clearance.c``) places the geoms for every row of a batch of joint vectors and computes
the pairs of a sphere or capsule arm geom and a sphere, capsule or box obstacle, and of a box
arm geom (a gripper's pad) and a sphere or capsule obstacle, exactly (closest points of
segments, and of a segment and a box, in closed form; overlapping where the cores do not
touch), and ``mujoco.mj_geomDistance`` the rest (other kinds, two boxes, cores touching,
boxes touched; a row's arm geoms placed once, as the kernel places them);
``tests/test_clearance.py`` checks both against MuJoCo. Where MuJoCo says a sphere or capsule
is apart from a box that its core overlaps (its box-capsule distance is positive for about
0.3 % of such pairs, up to 0.09 m, a capsule through a thin box), the exact signed distance is
taken instead (``_core.box_overlap``). With :math:`p_A, p_O` the nearest points and
:math:`n_k = (p_O - p_A)/d_k` the unit direction from the arm geom to the obstacle (the
division by the signed distance keeps it pointing that way when the geoms overlap), moving
the arm point by :math:`dp` changes the distance by :math:`-n_k \cdot dp`, so

.. math::  \frac{\partial d_k}{\partial q_j} = -n_k \cdot \big(a_j \times (p_A - o_j)\big)

for each revolute joint j <= l (axis :math:`a_j` through :math:`o_j`, the z axis and origin
of the chain's frame before joint j's row; :math:`-n_k \cdot a_j` for a prismatic joint),
computed in the same call. A pair farther apart than ``distmax`` reports ``distmax`` with a
zero gradient.

**The world moves.** The obstacles and the arm's root are where the model puts them at its
``qpos0`` until :meth:`Clearance.update` reads them from a ``mujoco.MjData`` of the model:
mocap bodies, bodies moved by other joints (a second arm, a conveyor), the arm's own mobile
base. :class:`~om_redundant.ExactPoseTask` does this every tick from its
``mink.Configuration`` when the optimiser's clearance is of the task's model.

**Along a motion.** :meth:`Clearance.minimum_along` bounds the clearance along a straight
joint-space segment from below: every pair's distance changes by at most
:math:`\sum_j r_j |\Delta q_j|` (:func:`~om_redundant.redundancy.objective.arm_geoms.lever_arms`), so
two ends' distances certify the segment between them, split where they do not.

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
import warnings
from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np

from ... import _core
from ...exceptions import InvalidInput
from ...ik.threads import run_rows
from ...kinematics.arm import Arm
from ...mujoco_io.arm_in_model import ArmJoints
from ...mujoco_io.mjcf import arm_mjcf
from ...validation import as_count, as_instance, as_joint_vector, as_number, as_positive
from .arm_geoms import (
    arm_cores,
    as_row,
    body_pose,
    check_extent,
    check_placement,
    find_geom,
    geom_label,
    lever_arms,
    subtree,
)
from .mujoco_pairs import MujocoPairs
from .segment_clearance import segment_minimum
from .shapes import Shape, model_geoms, shape_geoms

DEFAULT_DISTMAX = 1.0  # m: pairs farther apart report this distance


class Clearance:
    """Signed distances between an arm's collision geoms and obstacle geoms (module docstring).

    Threads may share one: its MuJoCo data, where the pairs left to MuJoCo are computed, is
    taken by one call at a time, and :meth:`update` swaps in the new poses at once.

    Args:
        model: A MuJoCo model holding the arm and the obstacles, e.g. the user's scene.
        arm: The arm; its joints are found in the model as ``prefix + joint name``.
        obstacle_geoms: Names of the obstacle geoms in the model.
        prefix: Prepended to the arm's joint names; default the arm's (``arm.prefix``).
        distmax: Pairs farther apart than this (m) report ``distmax``.

    Attributes:
        model, arm: As given.
        arm_geoms: The arm's collision geoms' names (unnamed ones as ``"<body>/geom<k>"``).
        pairs: (arm geom, obstacle) names of every pair, in the order of :meth:`distances`.
        geom_pairs: The same pairs as mink's ``CollisionAvoidanceLimit`` takes them (geom ids):
            ``mink.CollisionAvoidanceLimit(model, clearance.geom_pairs, ...)`` keeps mink's
            steps clear of what the optimiser keeps its choices clear of, but for those in
            ``mink_drops``.
        mink_drops: (arm geom, obstacle) names of the pairs mink's limit ignores, as it
            builds its pairs: bodies welded together or parent and child (the first link's
            geoms and the world's, in every scene), and geoms whose ``contype`` and
            ``conaffinity`` cannot collide (a warning names these).
        version: Counts the moves :meth:`update` has read.

    Raises:
        JointNotFound: A joint is not in the model (as in :class:`~om_redundant.ArmJoints`).
        ModelMismatch: A joint's type differs from the arm's, or the arm's collision geoms do
            not move like its kinematic chain (another arm).
        InvalidInput: A geom is missing, an obstacle geom moves with the arm, no obstacle is
            given, the arm has no collision geoms, or distmax is not positive.

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
        self._given = (tuple(obstacle_geoms), prefix)
        joints = ArmJoints(arm, model, prefix)
        first_body = model.jnt_bodyid[joints.joint_ids[0]]
        moving = subtree(model, first_body)
        arm_geoms = [
            g
            for g in range(model.ngeom)
            if moving[model.geom_bodyid[g]] and (model.geom_contype[g] or model.geom_conaffinity[g])
        ]
        if not arm_geoms:
            raise InvalidInput(
                f"the bodies that the joints of arm '{arm.name}' move carry no collision geoms (geoms with "
                "a non-zero contype or conaffinity); a Menagerie model loaded without its meshes has "
                "none: add primitive geoms (capsules) to its links, or use om.arm_model(arm)"
            )
        if not obstacle_geoms:
            raise InvalidInput("no obstacle geoms given")
        obstacles = [find_geom(model, name) for name in obstacle_geoms]
        for o in obstacles:
            if moving[model.geom_bodyid[o]]:
                raise InvalidInput(f"obstacle geom '{geom_label(model, o)}' moves with the arm")
        # the model's geom ids of each pair (arm geom, obstacle) and the arm geom's index, for
        # mj_geomDistance
        pair_geoms = [(a, o, i) for i, a in enumerate(arm_geoms) for o in obstacles]
        self._arm_ids, self._obstacle_ids = np.array(arm_geoms, dtype=np.int64), np.array(obstacles)
        self._mujoco = MujocoPairs(model, pair_geoms, len(arm_geoms), arm.dof)
        data = self._mujoco.data  # at qpos0: the obstacles placed
        check_extent(model, obstacles, data.geom_xpos[obstacles])
        self._cores = arm_cores(model, data, joints, arm_geoms, obstacles)
        self._n_pairs = len(pair_geoms)
        # The arm's root body (its first joint's body's parent) carries DH frame 0: K_root, K in it.
        self._root = int(model.body_parentid[first_body])
        self._root_moves = bool(model.body_weldid[self._root] != 0)
        K = np.eye(4)
        K[:3, :3], K[:3, 3] = self._cores.start[:9].reshape(3, 3), self._cores.start[9:]
        self._start_in_root = np.linalg.solve(body_pose(data, self._root), K)
        self._lever = lever_arms(model, self._cores, arm_geoms, joints)
        self.version = 0
        self.arm_geoms: tuple[str, ...] = tuple(geom_label(model, g) for g in arm_geoms)
        check_placement(model, joints, self._arm_ids, self.geom_poses)
        self.pairs: tuple[tuple[str, str], ...] = tuple(
            (geom_label(model, a), geom_label(model, o)) for a, o, _ in pair_geoms
        )
        self.geom_pairs: list[tuple[list[int], list[int]]] = [(list(arm_geoms), list(obstacles))]
        why = [_mink_drops(model, a, o) for a, o, _ in pair_geoms]  # (in the order of self.pairs)
        self.mink_drops: tuple[tuple[str, str], ...] = tuple(
            p for p, w in zip(self.pairs, why, strict=True) if w
        )
        # (welded or parent and child: the first link's geoms and the world's, in every scene,
        # which turn about the base's axis; geoms that cannot collide are the user's own choice)
        apart = [p for p, w in zip(self.pairs, why, strict=True) if w == _APART]
        if apart:
            shown = ", ".join(f"({a}, {o})" for a, o in apart[:4])
            more = f" and {len(apart) - 4} more" if len(apart) > 4 else ""
            warnings.warn(
                f"Clearance: mink's CollisionAvoidanceLimit ignores {len(apart)} of its pairs, "
                f"{shown}{more}: their geoms cannot collide (neither's contype meets the other's "
                "conaffinity). The optimiser keeps them clear at its choices and on their ways, but "
                "no limit keeps mink's steps clear of them; give the geoms a contype and conaffinity "
                "that collide",
                stacklevel=2,
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

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickled as what it was built from, with the poses :meth:`update` last read."""
        cores = self._cores
        moved = (cores.start, cores.obstacle_pos, cores.obstacle_mat, self.version)
        return (_restored, (self.model, self.arm, *self._given, self.distmax, moved))

    def distances(self, q: np.ndarray) -> np.ndarray:
        """Signed distance d_k(q) of every pair (m), in the order of :attr:`pairs`: (P,) for
        a joint vector q (dof,), (M, P) for the rows of q (M, dof)."""
        return self._evaluate(q, self.distmax, gradient=False)[0]

    def minimum(self, q: np.ndarray) -> float:
        """The clearance D(q) = min_k d_k(q) in metres, of a joint vector q (dof,)."""
        return float(self.distances(as_joint_vector(q, self._dof, stack=False)).min())

    def distances_and_gradients(self, q: np.ndarray, near: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
        """d_k(q) and their gradients dd_k/dq (module docstring): (P,) and (P, dof) for a
        joint vector q (dof,), (M, P) and (M, P, dof) for the rows of q (M, dof), the rows
        in ``_core.arm_clearance`` calls of up to :data:`~om_redundant.ik.threads.BATCH_CHUNK`
        rows each, on the pool's threads.

        Args:
            q: (dof,) joint vector, or (M, dof) rows.
            near: Where a pair of a row is nearer than this (m), only the gradients of the
                pairs nearer than it, the others zero (the objective reads no more:
                :attr:`Objective.clearance_reach
                <om_redundant.redundancy.objective.objective.Objective.clearance_reach>`); all by default.
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
        _core.arm_geom_poses(self._cores, q, xpos, xmat)
        return xpos, xmat.reshape(-1, 3, 3)

    def update(self, data: mujoco.MjData) -> bool:
        """Read where the obstacles and the arm's root are now.

        Takes the obstacle geoms' poses and the arm's root body's pose from ``data``'s
        kinematics as last computed (``mj_kinematics``, ``mj_forward``, or
        ``mink.Configuration.update``, which run it): mocap bodies, bodies moved by other
        joints (another arm), the arm's own mobile base. The arm's joints are not read: the
        distances are of the joints asked for.

        Args:
            data: A ``mujoco.MjData`` of this clearance's model.

        Returns:
            Whether anything moved since the last read (then :attr:`version` counts it).

        Raises:
            InvalidInput: data is of another model, or an obstacle beyond :data:`MAX_EXTENT`.
        """
        if not (isinstance(data, mujoco.MjData) and data.model is self.model):
            what = "the data of another model" if isinstance(data, mujoco.MjData) else type(data).__name__
            raise InvalidInput(
                f"Clearance.update takes a mujoco.MjData of the clearance's own model, got {what}"
            )
        cores = self._cores
        ids = self._obstacle_ids
        position, rotation = data.geom_xpos[ids], data.geom_xmat[ids]
        start = cores.start
        if self._root_moves:
            start = as_row(body_pose(data, self._root) @ self._start_in_root)
        if (  # (== and all: a third of np.array_equal's time, read every tick; NaN has moved)
            (position == cores.obstacle_pos).all()
            and (rotation == cores.obstacle_mat).all()
            and (start == cores.start).all()
        ):
            return False
        check_extent(self.model, ids, position)
        # (one assignment: a call in another thread reads the old poses or the new, whole)
        self._cores = cores._replace(
            start=np.ascontiguousarray(start),
            obstacle_pos=np.ascontiguousarray(position),
            obstacle_mat=np.ascontiguousarray(rotation),
        )
        self.version += 1
        return True

    def minimum_along(
        self, q_from: np.ndarray, q_to: np.ndarray, floor: float, max_samples: int | None = None
    ) -> float:
        r"""The clearance along the straight joint-space segment from q_from to q_to, as far
        as it matters against ``floor``.

        Every distance changes by at most :math:`L h` over a piece of the segment h long (in
        its parameter), :math:`L = \sum_j r_j |q_{to,j} - q_{from,j}|` (module docstring), so
        a piece whose ends' clearances are :math:`D_0, D_1` stays above
        :math:`(D_0 + D_1 - L h) / 2`. Pieces whose bound is below ``floor`` are halved (all
        the midpoints of a round in one call) until one's end falls below ``floor`` or the
        piece is within :data:`ALONG_TOLERANCE` of its ends.

        Args:
            q_from, q_to: The segment's ends (dof,).
            floor: The clearance (m) it is checked against.
            max_samples: The most joint vectors sampled inside the segment (None: as many
                as the tolerance takes, up to ~1/ALONG_TOLERANCE per metre of lever): a
                round of halving that would exceed it is not made.

        Returns:
            At least ``floor`` only if the whole segment is clear of ``floor`` (a certified
            lower bound); else a sampled clearance below ``floor``, or a bound within
            :data:`ALONG_TOLERANCE` of the segment's true clearance; NaN where ``max_samples``
            ran out before either (undecided: no sample below ``floor``, some piece's bound
            below it).
        """
        q_from = as_joint_vector(q_from, self._dof, stack=False)
        q_to = as_joint_vector(q_to, self._dof, stack=False)
        floor = as_number(floor, "floor")
        budget = math.inf if max_samples is None else as_count(max_samples, "max_samples", 0, 2**31)
        lipschitz = float(self._lever @ np.abs(q_to - q_from))
        cores = self._cores  # (the world as read now, for every round)

        def fill(q: np.ndarray, dist: np.ndarray, fromto: np.ndarray) -> None:
            self._mujoco.fill(cores, q, self.distmax, math.inf, dist, fromto, None)

        return segment_minimum(cores, fill, q_from, q_to, lipschitz, floor, budget, self.distmax)

    def _evaluate(
        self, q: np.ndarray, reach: float, gradient: bool, near: float = math.inf
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """Distances capped at reach and, if asked (else None), their gradients (only the
        pairs nearer than ``near`` where one is: :meth:`distances_and_gradients`) at a joint
        vector or the rows of q: ``_core.arm_clearance`` (a batch split across the pool's
        threads), then ``mj_geomDistance`` for the pairs it leaves
        (:class:`~.mujoco_pairs.MujocoPairs`)."""
        q = as_joint_vector(q, self._dof)
        rows, P, dof = q.reshape(-1, self._dof), self._n_pairs, self._dof
        M = len(rows)
        dist, fromto = np.empty((M, P)), np.empty((M, P, 6))
        grad = np.empty((M, P, dof)) if gradient else None
        cores, left = self._cores, []  # left: whether a chunk left pairs to MuJoCo

        def chunk(start: int, stop: int) -> None:  # (the kernel releases the GIL: threads share a batch)
            part = _core.PairDistances(
                dist[start:stop], fromto[start:stop], None if grad is None else grad[start:stop]
            )
            left.append(_core.arm_clearance(cores, rows[start:stop], reach, near, part, False))

        run_rows(chunk, M)
        if any(left):
            self._mujoco.fill(cores, rows, reach, near, dist, fromto, grad)
        shape = (*q.shape[:-1], P)
        return dist.reshape(shape), None if grad is None else grad.reshape(*shape, dof)


_APART, _JOINED = "cannot collide", "welded or parent and child"


def _mink_drops(model: mujoco.MjModel, a: int, o: int) -> str:
    """Why mink's ``CollisionAvoidanceLimit`` leaves out the pair of geoms a and o, as it
    builds its pairs (``mink/limits/collision_avoidance_limit.py``), or "": geoms that cannot
    collide (neither's ``contype`` meets the other's ``conaffinity``), or bodies welded
    together, or whose welds are parent and child."""
    contype, conaffinity = model.geom_contype, model.geom_conaffinity
    if not (contype[a] & conaffinity[o] or contype[o] & conaffinity[a]):
        return _APART
    weld_a, weld_o = model.body_weldid[model.geom_bodyid[[a, o]]]
    parent_a, parent_o = model.body_weldid[model.body_parentid[[weld_a, weld_o]]]
    return _JOINED if weld_a in (weld_o, parent_o) or weld_o == parent_a else ""


def _restored(
    model: mujoco.MjModel,
    arm: Arm,
    obstacle_geoms: tuple[str, ...],
    prefix: str | None,
    distmax: float,
    moved: tuple[np.ndarray, np.ndarray, np.ndarray, int],
) -> Clearance:
    """A :class:`Clearance` unpickled (:meth:`Clearance.__reduce__`), the world as it was read."""
    clearance = Clearance(model, arm, list(obstacle_geoms), prefix=prefix, distmax=distmax)
    start, position, rotation, version = moved
    clearance._cores = clearance._cores._replace(start=start, obstacle_pos=position, obstacle_mat=rotation)
    clearance.version = version
    return clearance
