r"""Feasible intervals of the arm angle psi: where a branch's exact solution exists, is
within the joint limits and keeps the required clearance.

A **feasible interval** is a maximal psi interval over which one solution path
(:mod:`om_redundant.redundancy.paths`) is exact, within the limits and clear: a run of feasible
neighbouring samples of the path, extended at each end to the boundary. Where the path's
next sample is infeasible, the boundary is the root of the continuous feasibility slack
(:class:`~om_redundant.redundancy.objective.Evaluation`) along the path between the two, by the
Illinois method (:func:`refine_end`); where the path itself ends, its end; both to
:data:`~om_redundant.redundancy.probe.END_TOLERANCE`.

So a psi can lie in two intervals of one branch (two solution paths), and a solution that
no path reaches (a path shorter than the sweep's grid step that meets no other) is not
counted. Intervals are arcs of the circle: ``lo`` in [-pi, pi), ``lo < hi``, ``hi > pi``
when the arc crosses +-pi.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .arm_angle import wrap_psi
from .paths import Path
from .probe import END_TOLERANCE, Point, Probe

SLACK_TOLERANCE = 1e-12  # a refined end whose feasibility slack is this small is on the boundary
_MAX_REFINE = 60  # Illinois steps per refined end


@dataclass(frozen=True)
class PsiInterval:
    """A feasible interval of the arm angle on one branch (see the module docstring).

    Attributes:
        signs: The branch signs.
        lo: Start (rad), in [-pi, pi).
        hi: End (rad), above lo; above pi when the arc crosses +-pi. (An arc longer than
            2 pi is a path that does not close after one turn: it covers every psi.)
        closed: The whole circle is feasible on a path that closes on itself.
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
class Run:
    """A feasible interval with its feasible samples and refined ends, ordered by psi."""

    interval: PsiInterval
    points: list[Point]


def feasible_runs(probe: Probe, path: Path) -> list[Run]:
    """The feasible intervals along a path, with their ends refined."""
    points, n = path.points, len(path.points)
    feasible = [p.evaluation.feasible for p in points]
    if path.turns and all(feasible):
        return [Run(PsiInterval(probe.signs, -math.pi, math.pi, closed=True), list(points))]
    period = 2.0 * math.pi * path.turns
    start = next((k for k in range(n) if not feasible[k - 1]), 0) if path.turns else 0
    runs, current = [], []
    for k in [*range(start, n), *range(start)]:  # a loop is scanned from after an infeasible sample
        if feasible[k]:
            wrapped = bool(current) and k < current[0][0]  # (a run of a loop past its last sample)
            current.append((k, points[k].at(points[k].psi + period) if wrapped else points[k]))
        elif current:
            runs.append(current)
            current = []
    runs += [current] if current else []
    return [_run(probe, path, [p for _, p in run], run[0][0], run[-1][0]) for run in runs]


def _run(probe: Probe, path: Path, points: list[Point], k_first: int, k_last: int) -> Run:
    """The run's interval: each end refined towards the path's infeasible neighbour sample,
    if there is one (else the run ends where the path does, or at the swept range's edge)."""
    n, period = len(path.points), 2.0 * math.pi * path.turns
    if k_first > 0 or path.turns:
        before = path.points[k_first - 1]
        before = before.at(points[0].psi - (points[0].psi - before.psi) % period) if path.turns else before
        points = [refine_end(probe, points[0], before), *points]
    if k_last < n - 1 or path.turns:
        after = path.points[(k_last + 1) % n]
        after = after.at(points[-1].psi + (after.psi - points[-1].psi) % period) if path.turns else after
        points = [*points, refine_end(probe, points[-1], after)]
    lo = wrap_psi(points[0].psi)
    shift = lo - points[0].psi
    points = [p.at(p.psi + shift) for p in points]
    return Run(PsiInterval(probe.signs, lo, points[-1].psi), points)


def refine_end(probe: Probe, inside: Point, outside: Point) -> Point:
    """The last feasible point between a feasible ``inside`` and an infeasible ``outside``,
    neighbours on one path.

    The feasibility slack changes sign between them; the Illinois method (regula falsi that
    halves the slack kept at a stale end) finds the root, each trial followed from the inner
    end (:meth:`~om_redundant.redundancy.probe.Probe.follow`). It stops when the bracket is narrower
    than :data:`~om_redundant.redundancy.probe.END_TOLERANCE` or the inner slack below
    :data:`SLACK_TOLERANCE`.
    """
    a, fa, b, fb = inside, inside.evaluation.slack, outside.psi, outside.evaluation.slack
    stale = 0  # +1: b was kept last time, -1: a was
    for _ in range(_MAX_REFINE):
        if abs(b - a.psi) <= END_TOLERANCE or fa <= SLACK_TOLERANCE:
            break
        x = b - fb * (b - a.psi) / (fb - fa)
        p, arrived = probe.follow(a, x)
        if not arrived:  # (cannot happen between neighbours of one path)
            break
        if p.evaluation.feasible:
            a, fa = p, p.evaluation.slack
            fb, stale = (fb / 2.0 if stale == 1 else fb), 1
        else:
            b, fb = x, p.evaluation.slack
            fa, stale = (fa / 2.0 if stale == -1 else fa), -1
    return a
