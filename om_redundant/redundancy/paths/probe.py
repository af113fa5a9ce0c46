r"""Exact solutions along one branch of a 7-DOF arm at one pose: the points of its solution
paths (:mod:`om_redundant.redundancy.paths.linking`), and how a path is followed along psi.

**Following.** From a solution, the next one is the solution nearest it (``q_hint``),
accepted when it continues the path (:meth:`Probe.continues`: no joint moves more than
:data:`JUMP`, and the joints move as the path's tangent predicts); a step that fails is
halved (near a singular shoulder or wrist two joints turn fast), and doubled again after a
success; where the last two points predict the path's end short of the next step, the step
aims just short of it (:meth:`Probe.follow`). Below :data:`END_TOLERANCE` the path has *ended*: it folded
back in psi, or left the branch or the reach (a solution exactly at a fold, where psi does not
move along the self-motion, fails its step as any other: the path ends beside it). The loop
runs in one call (``_core.follow``, ``csrc/redundancy/follow.c``; the tangents of
``csrc/redundancy/self_motion.c``; its solves are the hinted solve's local part, so a failed local solve
is a failed step without the bounded search, a root within a quarter of its step of the
first-order prediction is taken without the scan for a nearer one, and a step whose
prediction moves a joint farther than any root as near as the local one could continue
fails without it, as it would with it; on an arm with shoulder offsets the scan starts from
where the self-motion that the sweep's batch traced crosses the step's psi, instead of from a
grid over a window of the torus: :meth:`Probe.use_traces`); Python builds only the point
reached. The linking of
a branch's grid roots into paths runs in one call too (:meth:`Probe.link`,
``_core.link_paths``, ``csrc/redundancy/link.c``). Both loops are written in Python in
``tests/reference/follow.py``, the oracle they are tested against.
"""

from __future__ import annotations

import itertools

import numpy as np

from ... import _core
from ...angles import TURN, wrap_angles
from ...exceptions import SingularSelfMotion
from ...ik.solver import OMSolver, Solution
from ..objective.objective import Objective
from ..self_motion import self_motion_tangent, self_motion_tangents
from .points import Point, PointTerms

#: rad, max-norm: the largest joint step between neighbouring solutions of one path
#: (csrc/redundancy/om_paths.h's).
JUMP = _core.PATH_JUMP
#: rad: a path whose following step falls below this has ended (csrc/redundancy/om_paths.h's).
END_TOLERANCE = _core.END_TOLERANCE
#: rad, max-norm: two solutions at one psi this close are one (csrc/redundancy/link.c reads it there too).
SAME = _core.PATH_SAME
# A follow stalls (csrc/redundancy/om_paths.h: a path within rounding of a singular set advances by
# ~1e-6 rad a step, FOLLOW_CRAWL_STEPS steps in a row, or takes FOLLOW_MAX_ATTEMPTS
# attempts): then SingularSelfMotion.
_ARRIVED, _STALLED = _core.FOLLOW_ARRIVED, _core.FOLLOW_STALLED


class Probe:
    """Exact solutions along one branch of a 7-DOF arm at one pose, and their objective.

    Args:
        solver, objective, T, signs: The solver, the objective, the pose and the branch.
        wrapped: Revolute joints modulo 2 pi, at the representative nearest mid-range (for
            the feasible intervals); False keeps them as solved (for tracking).
    """

    def __init__(
        self,
        solver: OMSolver,
        objective: Objective,
        T: np.ndarray,
        signs: tuple[int, ...],
        wrapped: bool = True,
    ):
        self.solver, self.objective, self.T, self.signs = solver, objective, T, signs
        arm = solver.arm
        self._cyclic = arm.revolute & wrapped
        self._centred = self._cyclic & np.isfinite(arm.lower) & np.isfinite(arm.upper)
        # (inf + -inf of an unlimited joint would be NaN: only finite limits are added)
        lower, upper = np.where(self._centred, arm.lower, 0.0), np.where(self._centred, arm.upper, 0.0)
        self._centre = (lower + upper) / 2.0
        self._all_centred = all(self._centred.tolist())  # (then no np.where picks between the two)
        self._work = _core.FollowWork(  # the compiled follow's arrays
            solver.kernel,
            np.ascontiguousarray(T, dtype=float),
            np.array(signs, dtype=np.int64),
            self._cyclic.astype(np.uint8),
            self._centred.astype(np.uint8),
            np.ascontiguousarray(self._centre, dtype=float),
            np.empty(7),
            np.empty(7),
        )

    def use_traces(self, traces: object | None) -> None:
        """Follow with the pose's self-motion a batch traced (``_core.torus_traces``, kept by
        :meth:`~om_redundant.OMSolver.solve_grid`): a follow's scan for a root nearer its
        step's start then starts from where the trace crosses the step's psi instead of sampling
        a window of the torus (an arm with shoulder offsets; the same roots, as the batch's
        searches take them). None: sample the window."""
        self._work = self._work._replace(traces=traces)

    def step(self, a: np.ndarray, b: np.ndarray) -> float:
        """The largest joint step max_i |b_i - a_i| between joint vectors a and b (float64,
        (dof,)), the :attr:`cyclic` joints' differences taken to [-pi, pi); NaN where a
        joint's is (``_core.joint_step``)."""
        return _core.joint_step(self._cyclic, a, b)

    @property
    def cyclic(self) -> np.ndarray:
        """(dof,) bool: the joints that :meth:`step` compares modulo 2 pi."""
        return self._cyclic

    def point(self, psi: float | np.ndarray, q: np.ndarray, solution: Solution | None = None) -> Point:
        """The point of solution q at psi, q at its representative (see the class)."""
        q = self._represent(q)
        tangent = self_motion_tangent(self.solver, q)
        return Point(psi, q, tangent, PointTerms(self.objective, q, tangent), solution)

    def _represent(self, q: np.ndarray) -> np.ndarray:
        centred = self._centre + wrap_angles(q - self._centre)
        return centred if self._all_centred else np.where(self._centred, centred, q)

    def points(self, psi: np.ndarray, q: np.ndarray) -> list[Point | None]:
        """:meth:`point` for every psi and row of q (M, dof) of a 7-DOF arm, the tangents
        computed for all rows at once and the objective not yet (:func:`evaluate_points`
        computes it for many points at once); None for a row exactly where psi does not move
        along the self-motion (a fold met by the grid itself, a straight or folded elbow): the
        paths end beside it, as at any fold.

        Raises:
            SingularSelfMotion: psi moves along the self-motion at none of the rows (the arm
                stretched along psi's axis: no arm angle to choose).
        """
        q = self._represent(q)
        tangents = self_motion_tangents(self.solver, q)
        good = np.isfinite(tangents).all(axis=(1, 2))
        if len(q) and not good.any():
            self_motion_tangent(self.solver, q[0])  # raises SingularSelfMotion
        points: list[Point | None] = [None] * len(q)
        if good.any():
            q, tangents, at = q[good], tangents[good], np.flatnonzero(good).tolist()
            rows, rates = list(q), list(tangents)  # (each row's views, shared by its point and terms)
            terms = map(PointTerms, itertools.repeat(self.objective), rows, rates)
            for k, point in zip(at, map(Point, psi[good].tolist(), rows, rates, terms), strict=True):
                points[k] = point
        return points

    def next(self, point: Point, psi: float) -> Point | None:
        """The solution at psi nearest point, if it continues point's path (:meth:`follow`'s
        test; the objective evaluated only then): one attempt of its loop, the climb's trial
        step."""
        reached, arrived = self._follow(point, psi, abs(psi - point.psi))
        return reached if arrived else None

    def follow(self, start: Point, psi: float) -> tuple[Point, bool]:
        """Continue start's path towards psi (module docstring) in one ``_core.follow`` call.
        Where the secant of an end measure (1 / |dq/dpsi|^2 at a fold, a branch quantity's
        distance beyond :data:`~om_redundant.ik.solver.BRANCH_BAND`) through the last two
        points predicts the path's end short of the next step, the step aims
        ``_core.FOLLOW_AIM`` of the way there instead (at least 1.5 :data:`END_TOLERANCE`):
        the end is approached in a few successful steps rather than by halving, whose failing
        attempts beyond the end are the costliest.

        Returns:
            The point reached and whether it is at psi. When the path ends on the way the
            point is its end, to :data:`END_TOLERANCE`.

        Raises:
            SingularSelfMotion: The follow stalled: the path runs within rounding of a
                singular set.
        """
        return self._follow(start, psi, END_TOLERANCE)

    def _follow(self, start: Point, psi: float, min_step: float) -> tuple[Point, bool]:
        """:meth:`follow`, ending where the step falls below ``min_step``."""
        work = self._work
        work.q[:] = start.q
        work.t[:] = start.tangent[:, 0]
        reached, status, steps = _core.follow(work, float(start.psi), float(psi), float(min_step))
        if status == _STALLED:
            _stalled(reached, work.q)
        if steps == 0:
            return start, status == _ARRIVED
        q, tangent = work.q.copy(), work.t.copy()[:, None]
        return Point(reached, q, tangent, PointTerms(self.objective, q, tangent)), status == _ARRIVED

    def link(self, psi: np.ndarray, roots: list[list[Point]]) -> list[tuple[list[Point], int]]:
        """The paths through the solutions ``roots[k]`` at the increasing grid psi[k] (within a
        turn), in one ``_core.link_paths`` call (``csrc/redundancy/link.c``; the rule in
        :mod:`~om_redundant.redundancy.paths.linking`'s docstring): each path's points and
        turns. Python builds only the points that following added. (Room for
        two added points per root and one per grid psi: paths start only at listed roots and
        end once on each side, and a root that the bounded search did not list, which a
        follow arrives at, is rare; where following adds more, the call is made again with
        twice the room: its follows and decisions are the same, only their rows more.)"""
        work = self._work
        flat = [p for points in roots for p in points]
        counts = np.array([len(points) for points in roots], dtype=np.int64)
        q = np.array([p.q for p in flat], dtype=float).reshape(len(flat), 7)
        t = np.array([p.tangent for p in flat], dtype=float).reshape(len(flat), 7)  # (each (7, 1))
        capacity = 2 * len(flat) + len(psi)
        while True:
            members, paths = np.empty((2, len(flat) + capacity, 2), dtype=np.int64)
            added = _core.LinkRows(
                np.empty(capacity), np.empty((capacity, 7)), np.empty((capacity, 7)), members, paths
            )
            found = _core.link_paths(work, _core.LinkRoots(psi, counts, q, t), added)
            if found.status != _core.LINK_FULL:
                break
            capacity = 2 * capacity + 1  # (the same follows and decisions again, with room for their rows)
        new = slice(0, found.added)
        for x, qk, tk in zip(added.psi[new].tolist(), added.q[new], added.t[new, :, None], strict=True):
            flat.append(Point(x, qk, tk, PointTerms(self.objective, qk, tk)))
        linked, begin = [], 0
        for end, turns in paths[: found.paths].tolist():  # (a member's k: the turns of psi it is taken at)
            rows = members[begin:end].tolist()
            linked.append(([flat[r].at(flat[r].psi + TURN * k) if k else flat[r] for r, k in rows], turns))
            begin = end
        return linked


def _stalled(psi: float, q: np.ndarray) -> None:
    """Raise for a follow that stalled (:data:`CRAWL_STEPS`, :data:`MAX_ATTEMPTS`): the
    path runs within rounding of a singular set, where it is accepted only in steps of ~1e-6
    rad."""
    raise SingularSelfMotion(
        f"the self-motion crawls at psi = {psi:+.6f}, q = {np.round(q, 6).tolist()}: the pose is "
        "within rounding of one where the arm's joint axes align (e.g. q2 = q6 = 0)"
    )
