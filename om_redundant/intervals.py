r"""Feasible intervals of the arm angle psi: where a branch's exact solution exists, is
within the joint limits and keeps the required clearance.

For one pose and one branch (the configuration's signs), one psi can have several exact
solutions (2-4 near a singular wrist or a straight elbow), so "the solution at psi" is
defined by continuation:

* **Solution path.** Each solution is the one nearest a neighbouring solution
  (``q_hint``). Two solutions lie on one path when it can be followed from one to the other
  in steps that each move the joints by at most :data:`JUMP` (max-norm); a step that moves
  them more is halved (near a singular shoulder or wrist two joints turn fast), down to
  :data:`END_TOLERANCE`. Below that, the path has ended (it folded back in psi, or left the
  branch or the reach) and the solver returned another root: the path breaks there. For
  the intervals, revolute joints are compared modulo 2 pi and each solution is taken at the
  representative nearest mid-range (the solver's within-limits one, if any): feasibility is
  that of the arm's pose, not of one unwrapped joint vector. Tracking compares the joints as
  they are (the path the joints can move along).
* **Samples.** The branch is solved on a psi grid in one parallel batch without hints (the
  solver then prefers a root within the limits), and followed from the previous sample
  wherever neighbours are further apart than :data:`JUMP`. Every sample carries its
  feasibility functions :math:`g_j` (each joint's margin, each clearance minus d_min,
  normalised; feasible iff all :math:`g_j \ge 0`) and their rates :math:`dg_j/d\psi`
  (through dq/dpsi). Linked samples between which a joint moves more than
  :data:`FINE_STEP` get samples in between; then between two linked samples each
  :math:`g_j` is modelled by the cubic Hermite interpolant of those values and rates, and
  where the models predict a feasible island or an infeasible dip that the
  two samples do not show (joints turning fast, two limits pinching), an exact sample is
  inserted there, and the cell is checked again.
* **Feasible interval.** A maximal psi interval over which one solution path is exact,
  within the limits and clear: a run of feasible, linked samples, extended at each end
  (:func:`refine_end`) to the root of the feasibility slack along the path, or to the end of
  the path, each to :data:`END_TOLERANCE`.

So a psi can lie in two intervals of one branch (two solution paths), and a root at psi
that no path reaches is not counted. Intervals are arcs of the circle: ``lo`` in
[-pi, pi), ``lo < hi``, ``hi > pi`` when the arc crosses +-pi.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

import numpy as np

from .configuration import Configuration
from .objective import Evaluation, Group, Objective
from .self_motion import self_motion_tangent
from .solver import OMSolver

JUMP = 1.0  # rad, max-norm joint step between neighbouring solutions of one path
END_TOLERANCE = 1e-9  # rad, width of the bracket that refines an interval's end
SLACK_TOLERANCE = 1e-12  # a refined end whose feasibility slack is this small is on the boundary
_MAX_REFINE = 60  # Illinois steps per refined end
_MODEL_POINTS = 256  # points of a cell where the Hermite models are checked
FINE_STEP = 0.25  # rad: cells in which a joint moves further are halved before they are modelled
_MAX_INSERTED = 64  # exact samples inserted per cell
_T = np.arange(1, _MODEL_POINTS + 1) / (_MODEL_POINTS + 1)
_HERMITE = np.array(
    [2 * _T**3 - 3 * _T**2 + 1, _T**3 - 2 * _T**2 + _T, -2 * _T**3 + 3 * _T**2, _T**3 - _T**2]
)


@dataclass(frozen=True)
class PsiInterval:
    """A feasible interval of the arm angle on one branch (see the module docstring).

    Attributes:
        signs: The branch signs.
        lo: Start (rad), in [-pi, pi).
        hi: End (rad), above lo; above pi when the arc crosses +-pi. (An arc longer than
            2 pi is a path that does not close after one turn: it covers every psi.)
        closed: The whole circle is feasible and the solution path closes on itself.
    """

    signs: tuple[int, ...]
    lo: float
    hi: float
    closed: bool = False

    @property
    def width(self) -> float:
        return self.hi - self.lo

    def contains(self, psi: float) -> bool:
        """Whether the angle psi (any representative) lies on the arc."""
        return self.closed or (psi - self.lo) % (2.0 * math.pi) <= self.width


@dataclass(frozen=True, eq=False)
class Point:
    """An exact solution on a branch, its objective, and their rates along psi.

    Attributes:
        psi: The redundancy value (rad); an (r,) array for r > 1 redundancy variables.
        q: The joints.
        evaluation: The objective at q.
        groups: The objective's groups at q, their jacobians by psi (p_g, r).
        tangent: dq/dpsi (dof, r).
    """

    psi: float | np.ndarray
    q: np.ndarray
    evaluation: Evaluation
    groups: list[Group]
    tangent: np.ndarray

    def pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """The feasibility functions g_j (all >= 0 iff feasible; see
        :meth:`~om_redundant.objective.Group.constraints`) and dg_j/dpsi."""
        if not self.groups:
            return np.zeros(0), np.zeros(0)
        g, dg = zip(*(group.constraints() for group in self.groups), strict=True)
        return np.concatenate(g), np.concatenate(dg)


@dataclass(frozen=True, eq=False)
class Run:
    """A feasible interval with its feasible samples and refined ends, ordered by psi."""

    interval: PsiInterval
    points: list[Point]


class Probe:
    """Exact solutions along one branch at one pose, and their objective.

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
        self._centre = np.where(self._centred, (arm.lower + arm.upper) / 2.0, 0.0)

    def step(self, a: np.ndarray, b: np.ndarray) -> float:
        """The largest joint step between joint vectors a and b."""
        d = b - a
        return float(np.abs(np.where(self._cyclic, _wrap(d), d)).max())

    def point(self, psi: float | np.ndarray, q: np.ndarray) -> Point:
        """The point of solution q at psi, q at its representative (see the class)."""
        q = np.where(self._centred, self._centre + _wrap(q - self._centre), q)
        tangent = self_motion_tangent(self.solver, q)
        groups = [g.along(tangent) for g in self.objective.groups(q, jacobian=True)]
        return Point(psi, q, self.objective.evaluation(groups), groups, tangent)

    def at(self, psi: float | np.ndarray, hint: np.ndarray) -> Point | None:
        """The solution at psi nearest ``hint``; None if none exists or it is more than
        :data:`JUMP` away from the hint (another solution path)."""
        sol = self.solver.solve(self.T, Configuration(self.signs, tuple(np.atleast_1d(psi))), q_hint=hint)
        if not sol.ok or self.step(hint, sol.q) > JUMP:
            return None
        return self.point(psi, sol.q)

    def follow(self, start: Point, psi: float) -> tuple[Point, bool]:
        """Continue start's solution path towards psi, in steps that each move the joints by
        at most :data:`JUMP`: a step that moves them more is halved, and doubled again after
        a success.

        Returns:
            The point reached and whether it is at psi. When the path ends on the way (the
            step falls below :data:`END_TOLERANCE`) the point is its end, to that tolerance.
        """
        point, step = start, psi - start.psi
        while point.psi != psi:
            if abs(step) < END_TOLERANCE:
                return point, False
            x = psi if abs(psi - point.psi) <= abs(step) else point.psi + step
            nxt = self.at(x, point.q)
            if nxt is None:
                step /= 2.0
            else:
                point, step = nxt, 2.0 * step
        return point, True


@dataclass(frozen=True, eq=False)
class Samples:
    """Samples of one branch in increasing psi.

    Attributes:
        signs: The branch.
        psi: (n,) angles, in [-pi, pi) on the full circle.
        points: The solution at each psi, None where none was found.
        linked: (n,) sample k continues sample k-1's solution path; on a cyclic sweep
            ``linked[0]`` links sample 0 to sample n-1 across +-pi.
        cyclic: The samples cover the whole circle.
    """

    signs: tuple[int, ...]
    psi: np.ndarray
    points: list[Point | None]
    linked: np.ndarray
    cyclic: bool

    def feasible(self, k: int) -> bool:
        p = self.points[k]
        return p is not None and p.evaluation.feasible

    def gap(self, k_from: int, k_to: int) -> float:
        """psi from sample k_from forwards to sample k_to."""
        d = self.psi[k_to] - self.psi[k_from]
        return d % (2.0 * math.pi) if self.cyclic else d


def sweep_circle(
    solver: OMSolver, objective: Objective, T: np.ndarray, branches: list[tuple[int, ...]], n: int
) -> list[Samples]:
    """Samples of every branch on the grid psi_k = -pi + 2 pi k / n, with the hidden
    features of the cells sampled (module docstring)."""
    psi = -math.pi + 2.0 * math.pi * np.arange(n) / n
    batch = solver.solve_batch(
        np.repeat(T[None], n * len(branches), axis=0),
        np.repeat(branches, n, axis=0),
        np.tile(psi, len(branches)),
    )
    sweeps = []
    for b, signs in enumerate(branches):
        q, ok = batch.q[b * n : (b + 1) * n], batch.ok[b * n : (b + 1) * n]
        probe = Probe(solver, objective, T, signs)
        points = [probe.point(psi[k], q[k]) if ok[k] else None for k in range(n)]
        linked = np.zeros(n, dtype=bool)
        for k in [*range(1, n), 0]:  # continuation where neighbours are far apart; the seam last
            before, here = points[k - 1], points[k]
            if before is None or here is None:
                continue
            linked[k] = probe.step(before.q, here.q) <= JUMP
            if not linked[k] and k > 0:  # sample 0 stays: the seam is only checked
                followed, linked[k] = probe.follow(before, here.psi)
                points[k] = followed if linked[k] else here
        sweeps.append(_with_hidden(probe, Samples(signs, psi, points, linked, cyclic=True)))
    return sweeps


def sweep_window(probe: Probe, center: float, hint: np.ndarray, half_width: float, n: int) -> Samples:
    """Samples at center + half_width * j / n, j = -n..n, followed outwards from the
    solution nearest ``hint`` at the centre, with the hidden features of the cells sampled.
    Each side stops where the path ends, so every sample is on the hint's solution path."""
    psi = center + half_width * np.arange(-n, n + 1) / n
    points: list[Point | None] = [None] * len(psi)
    points[n] = probe.at(center, hint)
    for side in (1, -1):
        k = n
        while points[k] is not None and 0 <= k + side < len(psi):
            reached, arrived = probe.follow(points[k], psi[k + side])
            points[k + side] = reached if arrived else None
            k += side
    linked = np.array(
        [k > 0 and points[k] is not None and points[k - 1] is not None for k in range(len(psi))]
    )
    return _with_hidden(probe, Samples(probe.signs, psi, points, linked, cyclic=False))


def _with_hidden(probe: Probe, samples: Samples) -> Samples:
    """The samples with exact samples inserted where a linked cell hides a feature."""
    n = len(samples.psi)
    entries = [(samples.psi[0], samples.points[0], bool(samples.linked[0]))]  # (psi, point, linked)
    for k in [*range(1, n), 0] if samples.cyclic else range(1, n):
        a, b = samples.points[k - 1], samples.points[k]
        if samples.linked[k]:  # (the cell across +-pi ends beyond pi, before sample 0)
            entries += [
                (p.psi, p, True) for p in _hidden(probe, a, replace(b, psi=a.psi + samples.gap(k - 1, k)))
            ]
        if k > 0:
            entries.append((samples.psi[k], b, bool(samples.linked[k])))
    psi, points, linked = zip(*entries, strict=True)
    return Samples(samples.signs, np.array(psi), list(points), np.array(linked), samples.cyclic)


def _hidden(probe: Probe, a: Point, b: Point) -> list[Point]:
    """Exact samples inserted between linked a and b, in order: halving until no joint moves
    more than :data:`FINE_STEP` in a sub-cell, then until the Hermite models of every
    sub-cell agree with its ends (module docstring)."""
    inserted, cells = [], [(a, b)]
    while cells and len(inserted) < _MAX_INSERTED:
        left, right = cells.pop()
        t = 0.5 if probe.step(left.q, right.q) > FINE_STEP else _surprise(left, right)
        if t is None or right.psi - left.psi <= END_TOLERANCE:
            continue
        middle, arrived = probe.follow(left, left.psi + t * (right.psi - left.psi))
        if arrived:
            inserted.append(middle)
            cells += [(left, middle), (middle, right)]
    return sorted(inserted, key=lambda p: p.psi)


def _surprise(a: Point, b: Point) -> float | None:
    """Where, as a fraction of the cell, the pieces' cubic models predict a feasibility that
    the ends do not explain: more changes between feasible and infeasible than the ends'
    (none if alike, one if not). Returns the middle of the first unexplained stretch."""
    (ga, da), (gb, db) = a.pieces(), b.pieces()
    if len(ga) == 0:
        return None
    span = b.psi - a.psi
    models = np.column_stack([ga, da * span, gb, db * span]) @ _HERMITE  # (pieces, points)
    pattern = np.concatenate([[a.evaluation.feasible], (models >= 0.0).all(axis=0), [b.evaluation.feasible]])
    changes = np.flatnonzero(pattern[1:] != pattern[:-1])
    if len(changes) <= int(pattern[0] != pattern[-1]):
        return None
    return (changes[0] + 1 + changes[1]) / 2.0 / (len(pattern) - 1)


def feasible_runs(probe: Probe, samples: Samples) -> list[Run]:
    """The feasible intervals of a branch's samples, with their ends refined."""
    n = len(samples.psi)
    if samples.cyclic and all(samples.feasible(k) for k in range(n)) and samples.linked.all():
        return [Run(PsiInterval(probe.signs, -math.pi, math.pi, closed=True), list(samples.points))]
    order = np.arange(n)
    if samples.cyclic:  # start the scan where a run cannot continue across
        breaks = [k for k in range(n) if not (_joined(samples, k) and samples.feasible(k))]
        order = np.roll(order, -breaks[0])
    runs, current = [], []
    for k in order:
        if current and not _joined(samples, k):
            runs.append(current)
            current = []
        if samples.feasible(k):
            current.append(k)
        elif current:
            runs.append(current)
            current = []
    runs += [current] if current else []
    return [_refined_run(probe, samples, run) for run in runs]


def _joined(samples: Samples, k: int) -> bool:
    """Sample k continues sample k-1's path, both feasible."""
    return bool(samples.linked[k]) and samples.feasible(k) and samples.feasible(k - 1)


def _refined_run(probe: Probe, samples: Samples, run: list[int]) -> Run:
    n = len(samples.psi)
    points = [samples.points[run[0]]]
    for k_before, k in itertools.pairwise(run):  # psi unwrapped along the run
        points.append(replace(samples.points[k], psi=points[-1].psi + samples.gap(k_before, k)))
    ends = []
    for end, k_out, sign in ((points[0], run[0] - 1, -1.0), (points[-1], run[-1] + 1, 1.0)):
        if not samples.cyclic and not 0 <= k_out < n:
            ends.append(None)  # the window's edge: a bound, not a boundary
            continue
        k_out %= n
        distance = samples.gap(k_out, run[0]) if sign < 0 else samples.gap(run[-1], k_out)
        ends.append(refine_end(probe, end, end.psi + sign * distance))
    points = ([ends[0]] if ends[0] else []) + points + ([ends[1]] if ends[1] else [])
    lo = math.remainder(points[0].psi, 2.0 * math.pi)
    lo = -math.pi if lo >= math.pi else lo
    shift = lo - points[0].psi
    points = [replace(p, psi=p.psi + shift) for p in points]
    return Run(PsiInterval(probe.signs, lo, points[-1].psi), points)


def refine_end(probe: Probe, inside: Point, psi_out: float) -> Point:
    """The last feasible point of inside's solution path towards psi_out.

    The path is followed towards psi_out (:meth:`Probe.follow`); if it ends on the way
    while still feasible, its end (to :data:`END_TOLERANCE`) is the boundary. Otherwise the
    feasibility slack changes sign between ``inside`` and the point reached, and the
    Illinois method (regula falsi that halves the slack kept at a stale end) finds the
    root, each trial followed from the inner end. It stops when the bracket is narrower
    than :data:`END_TOLERANCE` or the inner slack below :data:`SLACK_TOLERANCE`.
    """
    outer, _ = probe.follow(inside, psi_out)
    if outer.evaluation.feasible:
        return outer
    a, fa, b, fb = inside, inside.evaluation.slack, outer.psi, outer.evaluation.slack
    stale = 0  # +1: b was kept last time, -1: a was
    for _ in range(_MAX_REFINE):
        if abs(b - a.psi) <= END_TOLERANCE or fa <= SLACK_TOLERANCE:
            break
        x = b - fb * (b - a.psi) / (fb - fa)
        p, arrived = probe.follow(a, x)
        if not arrived:  # (x lies on the path already walked)
            break
        if p.evaluation.feasible:
            a, fa = p, p.evaluation.slack
            fb, stale = (fb / 2.0 if stale == 1 else fb), 1
        else:
            b, fb = x, p.evaluation.slack
            fa, stale = (fa / 2.0 if stale == -1 else fa), -1
    return a


def _wrap(x: np.ndarray) -> np.ndarray:
    return np.remainder(x + math.pi, 2.0 * math.pi) - math.pi
