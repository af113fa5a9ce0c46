r"""Feasible intervals of the arm angle psi: where a branch's exact solution exists, is
within the joint limits and keeps the required clearance.

For one pose and one branch (the configuration's signs), one psi can have several exact
solutions (2-4 near a singular wrist or a straight elbow), so "the solution at psi" is
defined by continuation:

* **Samples.** psi runs over a grid; each sample is the exact solution nearest the
  previous sample's (``q_hint``). Neighbouring samples lie on one *solution path* when the
  path can be followed from one to the other in steps that each move the joints by at most
  :data:`JUMP` (max-norm); a step that moves them more is halved (near a singular shoulder
  or wrist two joints turn fast), down to :data:`END_TOLERANCE`. Below that, the path has
  ended (it folded back in psi, or left the branch or the reach) and the solver returned
  another root: the path breaks there. On the full circle the grid is first solved in one
  parallel batch without hints (the solver then prefers a root within the limits) and
  followed from the previous sample wherever neighbours are further apart than
  :data:`JUMP`.
* **Feasible interval.** A maximal psi interval over which one solution path is exact,
  within the limits and clear: a run of feasible, linked samples, extended at each end to
  the boundary. Where the neighbouring sample is on the same path, the boundary is the
  root of the continuous feasibility slack (:class:`~om_redundant.objective.Evaluation`),
  found by the Illinois method; where the path breaks or the solution ceases to exist, by
  bisection; each to :data:`END_TOLERANCE`.

So a psi can lie in two intervals of one branch (two solution paths), and a root at psi
that no path reaches is not counted. Intervals are arcs of the circle: ``lo`` in
[-pi, pi) and ``lo < hi <= lo + 2 pi``, ``hi > pi`` when the arc crosses +-pi.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .configuration import Configuration
from .objective import Evaluation, Objective
from .solver import OMSolver

JUMP = 1.0  # rad, max-norm joint step between neighbouring samples of one solution path
END_TOLERANCE = 1e-9  # rad, width of the bracket that refines an interval's end
SLACK_TOLERANCE = 1e-12  # a refined end whose feasibility slack is this small is on the boundary
_MAX_REFINE = 80  # evaluations per refined end (the bracket shrinks at least by half every other)


@dataclass(frozen=True)
class PsiInterval:
    """A feasible interval of the arm angle on one branch (see the module docstring).

    Attributes:
        signs: The branch signs.
        lo: Start (rad), in [-pi, pi).
        hi: End (rad), ``lo < hi <= lo + 2 pi``; above pi when the arc crosses +-pi.
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
    """An exact solution on a branch and its objective: psi (rad), joints, evaluation."""

    psi: float
    q: np.ndarray
    evaluation: Evaluation


@dataclass(frozen=True, eq=False)
class Run:
    """A feasible interval with its feasible samples and refined ends, ordered by psi."""

    interval: PsiInterval
    points: list[Point]


class Probe:
    """Exact solutions along one branch at one pose, and their objective."""

    def __init__(self, solver: OMSolver, objective: Objective, T: np.ndarray, signs: tuple[int, ...]):
        self.solver, self.objective, self.T, self.signs = solver, objective, T, signs

    def at(self, psi: float, hint: np.ndarray) -> Point | None:
        """The solution at psi nearest ``hint``; None if none exists or it is more than
        :data:`JUMP` away from the hint (another solution path)."""
        sol = self.solver.solve(self.T, Configuration(self.signs, (psi,)), q_hint=hint)
        if not sol.ok or np.abs(sol.q - hint).max() > JUMP:
            return None
        return Point(psi, sol.q, self.objective.evaluate(sol.q))

    def follow(self, start: Point, psi: float) -> Point | None:
        """Continue start's solution path to psi, in steps that each move the joints by at
        most :data:`JUMP`: a step that moves them more is halved (near a singular shoulder or
        wrist the path turns two joints fast), and doubled again after a success. None if
        the path ends on the way (the step falls below :data:`END_TOLERANCE`)."""
        point, step = start, psi - start.psi
        while point.psi != psi:
            if abs(step) < END_TOLERANCE:
                return None
            x = psi if abs(psi - point.psi) <= abs(step) else point.psi + step
            nxt = self.at(x, point.q)
            if nxt is None:
                step /= 2.0
            else:
                point, step = nxt, 2.0 * step
        return point


@dataclass(eq=False)
class Samples:
    """Samples of one branch in increasing psi.

    Attributes:
        signs: The branch.
        psi: (n,) angles.
        points: The solution at each psi, None where none was found.
        linked: (n,) sample k continues sample k-1's solution path; on a cyclic sweep
            ``linked[0]`` links sample 0 to sample n-1.
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


def sweep_circle(
    solver: OMSolver, objective: Objective, T: np.ndarray, branches: list[tuple[int, ...]], n: int
) -> list[Samples]:
    """Samples of every branch on the grid psi_k = -pi + 2 pi k / n (module docstring)."""
    psi = -math.pi + 2.0 * math.pi * np.arange(n) / n
    batch = solver.solve_batch(
        np.repeat(T[None], n * len(branches), axis=0),
        np.repeat(branches, n, axis=0),
        np.tile(psi, len(branches)),
    )
    sweeps = []
    for b, signs in enumerate(branches):
        rows = slice(b * n, (b + 1) * n)
        q, ok = batch.q[rows], batch.ok[rows]
        probe = Probe(solver, objective, T, signs)
        points = [Point(psi[k], q[k], objective.evaluate(q[k])) if ok[k] else None for k in range(n)]
        linked = np.zeros(n, dtype=bool)
        for k in range(n):  # continuation where neighbours are far apart
            before, here = points[k - 1], points[k]
            if before is None or here is None:
                continue
            if np.abs(here.q - before.q).max() <= JUMP:
                linked[k] = True
            elif k > 0:  # (sample 0 is not replaced: the circle's seam stays unlinked)
                followed = probe.follow(before, here.psi)
                linked[k] = followed is not None
                points[k] = followed or here
        sweeps.append(Samples(signs, psi, points, linked, cyclic=True))
    return sweeps


def sweep_window(probe: Probe, center: float, hint: np.ndarray, half_width: float, n: int) -> Samples:
    """Samples at center + half_width * j / n, j = -n..n, followed outwards from the
    solution nearest ``hint`` at the centre. Each side stops where the path ends, so every
    sample found is on the hint's solution path."""
    psi = center + half_width * np.arange(-n, n + 1) / n
    points: list[Point | None] = [None] * len(psi)
    points[n] = probe.at(center, hint)
    for side in (1, -1):
        k = n
        while points[k] is not None and 0 <= k + side < len(psi):
            points[k + side] = probe.follow(points[k], psi[k + side])
            k += side
    linked = np.array(
        [k > 0 and points[k] is not None and points[k - 1] is not None for k in range(len(psi))]
    )
    return Samples(probe.signs, psi, points, linked, cyclic=False)


def feasible_runs(probe: Probe, samples: Samples) -> list[Run]:
    """The feasible intervals of a branch's samples, with their ends refined."""
    n = len(samples.psi)
    if samples.cyclic and all(samples.feasible(k) for k in range(n)) and samples.linked.all():
        points = list(samples.points)
        return [Run(PsiInterval(probe.signs, -math.pi, math.pi, closed=True), points)]
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
    turn = 2.0 * math.pi if samples.cyclic else 0.0
    # Unwrap psi along the run (a cyclic run may cross +-pi).
    points = [samples.points[run[0]]]
    for k in run[1:]:
        p = samples.points[k]
        shift = turn if samples.psi[k] < points[-1].psi else 0.0
        points.append(Point(p.psi + shift, p.q, p.evaluation))
    step = samples.psi[1] - samples.psi[0]  # the grids are uniform
    ends = []
    for end, outward, k_out in ((points[0], -1, run[0] - 1), (points[-1], 1, run[-1] + 1)):
        if not samples.cyclic and not 0 <= k_out < n:
            ends.append(None)  # the window's edge: a bound, not a boundary
            continue
        k_out %= n
        linked = samples.linked[k_out] if outward == 1 else samples.linked[(k_out + 1) % n]
        outside = samples.points[k_out] if linked else None
        ends.append(refine_end(probe, end, end.psi + outward * step, outside))
    points = ([ends[0]] if ends[0] else []) + points + ([ends[1]] if ends[1] else [])
    lo = math.remainder(points[0].psi, 2.0 * math.pi)
    lo = -math.pi if lo >= math.pi else lo
    shift = lo - points[0].psi
    points = [Point(p.psi + shift, p.q, p.evaluation) for p in points]
    return Run(PsiInterval(probe.signs, lo, points[-1].psi), points)


def refine_end(probe: Probe, inside: Point, psi_out: float, outside: Point | None) -> Point:
    """The last feasible point between a feasible ``inside`` and an infeasible psi_out.

    ``outside`` is the solution at psi_out on inside's path, if there is one. While the
    slack is known at both ends of the bracket the Illinois method (regula falsi that halves
    the slack kept at a stale end) moves the inner end; where the outer end has no solution
    on the path, bisection. Every trial is followed from the inner end
    (:meth:`Probe.follow`). It stops when the bracket is narrower than
    :data:`END_TOLERANCE` or the inner slack below :data:`SLACK_TOLERANCE`.
    """
    a, fa = inside, inside.evaluation.slack
    b = psi_out
    fb = outside.evaluation.slack if outside is not None else math.nan
    stale = 0  # +1: b was kept last time, -1: a was
    for _ in range(_MAX_REFINE):
        if abs(b - a.psi) <= END_TOLERANCE or fa <= SLACK_TOLERANCE:
            break
        if math.isfinite(fb) and fa > fb:
            x = b - fb * (b - a.psi) / (fb - fa)
        else:
            x = 0.5 * (a.psi + b)
        p = probe.follow(a, x)
        if p is not None and p.evaluation.feasible:
            a, fa = p, p.evaluation.slack
            fb, stale = (fb / 2.0 if stale == 1 else fb), 1
        else:
            b, fb = x, (p.evaluation.slack if p is not None else math.nan)
            fa, stale = (fa / 2.0 if stale == -1 else fa), -1
    return a
