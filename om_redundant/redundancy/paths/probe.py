r"""Exact solutions along one branch of a 7-DOF arm at one pose: the points of its solution
paths (:mod:`om_redundant.redundancy.paths.linking`), and how a path is followed along psi.

**Following.** From a solution, the next one is the solution nearest it (``q_hint``),
accepted when it continues the path (:meth:`Probe.continues`: no joint moves more than
:data:`JUMP`, and the joints move as the path's tangent predicts); a step that fails is
halved (near a singular shoulder or wrist two joints turn fast), and doubled again after a
success; where the last two points predict the path's end short of the next step, the step
aims just short of it (:meth:`Probe.follow`). Below :data:`END_TOLERANCE` the path has *ended*: it folded
back in psi, or left the branch or the reach. With a compiled solver the loop runs in one
call (``_core.follow``, ``csrc/follow.c``: the same steps and tests, the tangents of
``csrc/self_motion.c``; its solves are the hinted solve's local part, so a failed local solve
is a failed step without the bounded search, a root within a quarter of its step of the
first-order prediction is taken without the scan for a nearer one, and a step whose
prediction moves a joint farther than any root as near as the local one could continue
fails without it, as it would with it); Python builds only the point reached. The linking of
a branch's grid roots into paths runs in one call too (:meth:`Probe.link`,
``_core.link_paths``, ``csrc/link.c``: those follows and the decisions of
:func:`~om_redundant.redundancy.paths.linking._link`'s loop).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ... import _core
from ...angles import TURN, wrap_angles
from ...exceptions import SingularSelfMotion
from ...ik.configuration import Configuration
from ...ik.solver import BRANCH_BAND, OMSolver, Solution
from ..objective.objective import Objective
from ..self_motion import self_motion_tangent, self_motion_tangents
from .points import Point, PointTerms, evaluated_terms

#: rad, max-norm: the largest joint step between neighbouring solutions of one path (csrc/om_paths.h's).
JUMP = _core.PATH_JUMP
#: rad: a path whose following step falls below this has ended (one value with csrc/om_paths.h's).
END_TOLERANCE = _core.END_TOLERANCE
#: rad, max-norm: two solutions at one psi this close are one (csrc/link.c reads it there too).
SAME = _core.PATH_SAME
_AIM = _core.FOLLOW_AIM  # of the distance to a path's predicted end, a step aimed there goes
_ARRIVED, _SINGULAR, _STALLED = _core.FOLLOW_ARRIVED, _core.FOLLOW_SINGULAR, _core.FOLLOW_STALLED
# A follow stalls (csrc/om_paths.h: a path within rounding of a singular set advances by
# ~1e-6 rad a step) after CRAWL_STEPS accepted steps in a row shorter than CRAWL, or after
# MAX_ATTEMPTS attempts: then SingularSelfMotion.
CRAWL, CRAWL_STEPS = _core.FOLLOW_CRAWL, _core.FOLLOW_CRAWL_STEPS
MAX_ATTEMPTS = _core.FOLLOW_MAX_ATTEMPTS


class Probe:
    """Exact solutions along one branch at one pose, and their objective.

    Args:
        solver, objective, T, signs: The solver, the objective, the pose and the branch.
        wrapped: Revolute joints modulo 2 pi, at the representative nearest mid-range (for
            the feasible intervals); False keeps them as solved (for tracking).
        compiled: Follow paths with ``_core.follow`` where the arm has 7 joints; False:
            always the Python loop (the reference it is tested against).
    """

    def __init__(
        self,
        solver: OMSolver,
        objective: Objective,
        T: np.ndarray,
        signs: tuple[int, ...],
        wrapped: bool = True,
        compiled: bool = True,
    ):
        self.solver, self.objective, self.T, self.signs = solver, objective, T, signs
        arm = solver.arm
        self._cyclic = arm.revolute & wrapped
        self._centred = self._cyclic & np.isfinite(arm.lower) & np.isfinite(arm.upper)
        # (inf + -inf of an unlimited joint would be NaN: only finite limits are added)
        lower, upper = np.where(self._centred, arm.lower, 0.0), np.where(self._centred, arm.upper, 0.0)
        self._centre = (lower + upper) / 2.0
        # (where every joint is cyclic, or centred, no np.where picks between the two)
        self._all_cyclic, self._all_centred = all(self._cyclic.tolist()), all(self._centred.tolist())
        self._work = None  # the compiled follow's arrays: a 7-DOF arm's only
        if compiled and arm.dof == 7:
            self._work = _core.FollowWork(
                solver.kernel,
                np.ascontiguousarray(T, dtype=float),
                np.array(signs, dtype=np.int64),
                self._cyclic.astype(np.uint8),
                self._centred.astype(np.uint8),
                np.ascontiguousarray(self._centre, dtype=float),
                np.empty(7),
                np.empty(7),
            )

    def step(self, a: np.ndarray, b: np.ndarray) -> float:
        """The largest joint step max_i |b_i - a_i| between joint vectors a and b (float64,
        (dof,)), the :attr:`cyclic` joints' differences taken to [-pi, pi); NaN where a
        joint's is (``_core.joint_step``)."""
        return _core.joint_step(self._cyclic, a, b)

    @property
    def cyclic(self) -> np.ndarray:
        """(dof,) bool: the joints that :meth:`step` compares modulo 2 pi."""
        return self._cyclic

    def _delta(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        d = b - a
        return wrap_angles(d) if self._all_cyclic else np.where(self._cyclic, wrap_angles(d), d)

    def point(self, psi: float | np.ndarray, q: np.ndarray, solution: Solution | None = None) -> Point:
        """The point of solution q at psi, q at its representative (see the class)."""
        return self._point(psi, self._represent(q), solution)

    def _represent(self, q: np.ndarray) -> np.ndarray:
        centred = self._centre + wrap_angles(q - self._centre)
        return centred if self._all_centred else np.where(self._centred, centred, q)

    def _point(self, psi: float | np.ndarray, q: np.ndarray, solution: Solution | None) -> Point:
        tangent = self_motion_tangent(self.solver, q)
        return Point(psi, q, tangent, PointTerms(self.objective, q, tangent), solution)

    def points(self, psi: np.ndarray, q: np.ndarray) -> list[Point | None]:
        """:meth:`point` for every psi and row of q (M, dof) of a 7-DOF arm, the tangents and
        the objective (:func:`evaluate_points`) computed for all rows at once; None for a row
        exactly where psi does not move along the self-motion (a fold met by the grid itself,
        a straight or folded elbow): the paths end beside it, as at any fold.

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
            terms = map(
                PointTerms,
                itertools.repeat(self.objective),
                rows,
                rates,
                *evaluated_terms(self.objective, q, tangents),
            )
            for k, point in zip(at, map(Point, psi[good].tolist(), rows, rates, terms), strict=True):
                points[k] = point
        return points

    def at(self, psi: float | np.ndarray, hint: np.ndarray) -> Point | None:
        """The solution at psi nearest ``hint``, if there is one."""
        sol = self._solve(psi, hint)
        return self.point(psi, sol.q, sol) if sol.ok else None

    def _solve(self, psi: float | np.ndarray, hint: np.ndarray) -> Solution:
        return self.solver.solve(self.T, Configuration(self.signs, tuple(np.atleast_1d(psi))), q_hint=hint)

    def continues(self, point: Point, other: Point) -> bool:
        r"""Whether ``other`` continues point's path: its joints moved at most :data:`JUMP` and
        as the path's tangent predicts to first order,
        :math:`|\Delta q - (dq/d\psi)\,\Delta\psi|_\infty \le \frac12 |\Delta q|_\infty`. (A
        solution on another path, however near, is off by the paths' separation, which no
        shorter step of psi shrinks.)"""
        return self._continues(point, other.psi, other.q)

    def _continues(self, point: Point, psi: float | np.ndarray, q: np.ndarray) -> bool:
        moved = self._delta(point.q, q)
        return bool(_continuing(moved, moved - point.tangent @ np.atleast_1d(psi - point.psi)))

    def next(self, point: Point, psi: float | np.ndarray) -> Point | None:
        """The solution at psi nearest point, if it continues point's path (the objective
        evaluated only then): one attempt of :meth:`follow`'s loop."""
        if self._work is not None and psi != point.psi:
            found = self._follow_compiled(point, psi, abs(psi - point.psi))
            if found is not None:
                return found[0] if found[1] else None
        sol = self._solve(psi, point.q)
        if not sol.ok:
            return None
        q = self._represent(sol.q)
        return self._point(psi, q, sol) if self._continues(point, psi, q) else None

    def follow(self, start: Point, psi: float) -> tuple[Point, bool]:
        """Continue start's path towards psi (module docstring). Where the secant of an end
        measure (:meth:`_end_measures`) through the last two points predicts the path's end
        short of the next step, the step aims :data:`_AIM` of the way there instead (at
        least 1.5 :data:`END_TOLERANCE`): the end is approached in a few successful steps
        rather than by halving, whose failing attempts beyond the end are the costliest.

        Returns:
            The point reached and whether it is at psi. When the path ends on the way the
            point is its end, to :data:`END_TOLERANCE`.
        """
        if self._work is not None:
            reached = self._follow_compiled(start, psi)
            if reached is not None:
                return reached
        point, step = start, psi - start.psi
        ends, behind = self._end_measures(point), None  # behind: (psi, end measures) of the point before
        crawled = 0  # accepted steps in a row shorter than CRAWL
        for attempts in itertools.count():
            if point.psi == psi:
                break
            if abs(step) < END_TOLERANCE:
                return point, False
            if attempts == MAX_ATTEMPTS or crawled == CRAWL_STEPS:
                _stalled(point.psi, point.q)
            x = psi if abs(psi - point.psi) <= abs(step) else point.psi + step
            aim = math.inf
            if behind is not None:
                ahead = _predicted_end(behind[1], ends, abs(point.psi - behind[0]))
                aim = max(_AIM * ahead, 1.5 * END_TOLERANCE)
            if aim < abs(x - point.psi):
                x = point.psi + math.copysign(aim, step)
            nxt = self.next(point, x)
            if nxt is None:  # (halved from x, not from step: psi nearer than step is not tried again)
                step = 0.5 * (x - point.psi)
            else:
                crawled = crawled + 1 if abs(x - point.psi) < CRAWL else 0
                step = 2.0 * (x - point.psi)
                behind, point = (point.psi, ends), nxt
                ends = self._end_measures(point)
        return point, True

    def _end_measures(self, point: Point) -> list[float]:
        """What ends a path, as functions of its point that fall to zero there linearly in
        psi: 1 / |dq/dpsi|^2 at a fold (q - q_f ~ (psi_f - psi)^(1/2)), and s_i b_i +
        BRANCH_BAND where branch quantity b_i leaves its sign s_i beyond the band."""
        branch, redundancy = np.empty(len(self.signs)), np.empty(1)
        self.solver.kernel.configuration_values(np.ascontiguousarray(point.q), branch, redundancy)
        tt = 0.0
        for v in point.tangent[:, 0].tolist():  # (summed in order, as csrc/follow.c does)
            tt += v * v
        return [1.0 / tt] + [
            float(s) * b + BRANCH_BAND for s, b in zip(self.signs, branch.tolist(), strict=True)
        ]

    def _follow_compiled(
        self, start: Point, psi: float, min_step: float = END_TOLERANCE
    ) -> tuple[Point, bool] | None:
        """:meth:`follow` in one ``_core.follow`` call, ending where the step falls below
        ``min_step``; None where it met a point without a tangent (a fold met exactly: the
        Python loop then decides)."""
        work = self._work
        work.q[:] = start.q
        work.t[:] = start.tangent[:, 0]
        reached, status, steps = _core.follow(work, float(start.psi), float(psi), float(min_step))
        if status == _SINGULAR:
            return None
        if status == _STALLED:
            _stalled(reached, work.q)
        if steps == 0:
            return start, status == _ARRIVED
        q, tangent = work.q.copy(), work.t.copy()[:, None]
        return Point(reached, q, tangent, PointTerms(self.objective, q, tangent)), status == _ARRIVED

    def link(self, psi: np.ndarray, roots: list[list[Point]]) -> list[tuple[list[Point], int]] | None:
        """The paths through the solutions ``roots[k]`` at the increasing grid psi[k] (within a
        turn) that :func:`~om_redundant.redundancy.paths.linking._link`'s loop finds, in one
        ``_core.link_paths`` call (``csrc/link.c``: the same follows, in the same order, and
        the same decisions): each path's points and turns. Python builds only the points that
        following added. None where the solver is not a 7-DOF arm's compiled one or where a
        follow met a fold exactly (:meth:`_follow_compiled`): the loop then decides. (Room for
        two added points per root and one per grid psi: paths start only at listed roots and
        end once on each side, and a root that the bounded search did not list, which a
        follow arrives at, is rare; where following adds more, the call is made again with
        twice the room: its follows and decisions are the same, only their rows more.)"""
        work = self._work
        if work is None:
            return None
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
        if found.status != _core.LINK_DONE:
            return None
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


def _predicted_end(before: list[float], now: list[float], moved: float) -> float:
    """The distance in psi ahead of a point (end measures ``now``) to the nearest end that
    the secant of a measure falling towards zero predicts, from the point ``moved`` behind
    (measures ``before``); inf where none falls."""
    ahead = [moved * f / (b - f) for b, f in zip(before, now, strict=True) if 0.0 < f < b]
    return min(ahead, default=math.inf)


def _continuing(moved: np.ndarray, error: np.ndarray) -> np.ndarray:
    """The rule of :meth:`Probe.continues` on the last axis: the joint step |moved|_inf at
    most JUMP and the first-order prediction's error within half of it (plus SAME)."""
    jump = np.abs(moved).max(axis=-1)
    return (jump <= JUMP) & (np.abs(error).max(axis=-1) <= 0.5 * jump + SAME)
