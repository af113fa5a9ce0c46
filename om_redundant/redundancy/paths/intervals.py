r"""Feasible intervals of the arm angle psi: where a branch's exact solution exists, is
within the joint limits and keeps the required clearance.

A **feasible interval** is a maximal psi interval over which one solution path
(:mod:`om_redundant.redundancy.paths.linking`) is exact, within the limits and clear: a run of feasible
neighbouring samples of the path, extended at each end to the boundary. Where the path's
next sample is infeasible, the boundary is the root of the continuous feasibility slack
(:class:`~om_redundant.redundancy.objective.terms.Evaluation`) along the path between the two
(:func:`_refined`: from the root of the cubic models of the cell, Newton steps on the
rates the trials carry, the Illinois method where those leave the bracket; every end of the
sweep at once); where the path itself ends, its end; both to
:data:`~om_redundant.redundancy.paths.probe.END_TOLERANCE`.

So a psi can lie in two intervals of one branch (two solution paths), and a solution that
no path reaches (a path shorter than the sweep's grid step that meets no other) is not
counted. Intervals are arcs of the circle: ``lo`` in [-pi, pi), ``lo < hi``, ``hi > pi``
when the arc crosses +-pi.
"""

from __future__ import annotations

import math
from collections.abc import Generator, Sequence
from dataclasses import dataclass
from typing import NamedTuple

from ... import _core
from ...angles import wrap_angle
from .linking import _HERMITE, Follow, Path, lockstep
from .points import Point
from .probe import END_TOLERANCE, Probe

SLACK_TOLERANCE = 1e-12  # a refined end whose feasibility slack is this small is on the boundary
_MAX_REFINE = 60  # trials per refined end


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


class BranchRuns(NamedTuple):
    """A branch's solution paths swept over the circle and their feasible runs; ``unswept``:
    why it has none without a sweep (its sweep stalled: the SingularSelfMotion of a path within
    rounding of a singular set; the target out of reach), else ""."""

    signs: tuple[int, ...]
    paths: list[Path]
    runs: list[Run]
    unswept: str = ""


@dataclass(frozen=True, eq=False)
class Run:
    """A feasible interval with its feasible samples and refined ends, ordered by psi.

    Attributes:
        interval: The interval.
        points: The samples, its refined ends included.
        path_ends: Whether its first and its last sample are where the path ends (not a
            refined end): at a fold, where the path turns back in psi and no follow leaves
            the sample (:func:`~om_redundant.redundancy.paths.linking._hidden`), or where it
            leaves the branch or the reach.
    """

    interval: PsiInterval
    points: list[Point]
    path_ends: tuple[bool, bool] = (False, False)


def feasible_runs(paths: Sequence[tuple[Probe, Path]]) -> list[list[Run]]:
    """The feasible intervals along each (probe, path), with their ends refined: every end
    of every path at once (:func:`~om_redundant.redundancy.paths.linking.lockstep`)."""
    spans = [[(probe, span) for span in _spans(path)] for probe, path in paths]
    ends = [
        _refined(probe, inside, outside)
        for path_spans in spans
        for probe, span in path_spans
        for inside, outside in ((span.points[0], span.before), (span.points[-1], span.after))
        if outside is not None
    ]
    refined = iter(lockstep(ends))  # (in the order of ends)
    return [
        [
            _run(
                probe,
                span,
                None if span.before is None else next(refined),
                None if span.after is None else next(refined),
            )
            for probe, span in path_spans
        ]
        for path_spans in spans
    ]


class _Span(NamedTuple):
    """A run of feasible neighbouring samples of a path, ordered by psi, and the path's
    infeasible samples next to its ends (None where the path ends there, or the swept
    range does); closed: the whole loop."""

    points: list[Point]
    before: Point | None
    after: Point | None
    closed: bool = False


def _spans(path: Path) -> list[_Span]:
    """The runs of feasible samples along a path."""
    points, n = path.points, len(path.points)
    feasible = [p.evaluation.feasible for p in points]
    if path.turns and all(feasible):
        return [_Span(list(points), None, None, closed=True)]
    period = 2.0 * math.pi * path.turns
    # a loop is scanned from after an infeasible sample (so that no run wraps past the scan's
    # end); a run of a loop past its last sample continues a turn later
    start = next((k for k in range(n) if not feasible[k - 1]), 0) if path.turns else 0
    spans = []
    for i, j in _runs(feasible[start:] + feasible[:start]):
        k_first, k_last = (start + i) % n, (start + j - 1) % n
        if k_first <= k_last:
            run = points[k_first : k_last + 1]
        else:
            run = points[k_first:] + [p.at(p.psi + period) for p in points[: k_last + 1]]
        spans.append(_span(path, run, k_first, k_last))
    return spans


def _runs(flags: list[bool]) -> list[tuple[int, int]]:
    """The maximal runs [i, j) of true flags (found by list.index, not flag by flag)."""
    runs, i, n = [], 0, len(flags)
    while i < n:
        try:
            i = flags.index(True, i)
        except ValueError:
            break
        try:
            j = flags.index(False, i)
        except ValueError:
            j = n
        runs.append((i, j))
        i = j
    return runs


def _span(path: Path, points: list[Point], k_first: int, k_last: int) -> _Span:
    """The run of samples k_first..k_last with the path's samples next to it, on a loop at
    the representatives of psi next to the run's."""
    n, period = len(path.points), 2.0 * math.pi * path.turns
    before = after = None
    if k_first > 0 or path.turns:
        before = path.points[k_first - 1]
        before = before.at(points[0].psi - (points[0].psi - before.psi) % period) if path.turns else before
    if k_last < n - 1 or path.turns:
        after = path.points[(k_last + 1) % n]
        after = after.at(points[-1].psi + (after.psi - points[-1].psi) % period) if path.turns else after
    return _Span(points, before, after)


def _run(probe: Probe, span: _Span, lo: Point | None, hi: Point | None) -> Run:
    """The run's interval: from its end refined towards the sample before (lo), if there
    is one, to its end refined towards the sample after (hi), if there is one (else the
    run ends where the path does, or at the swept range's edge)."""
    if span.closed:
        return Run(PsiInterval(probe.signs, -math.pi, math.pi, closed=True), span.points)
    points = [*([] if lo is None else [lo]), *span.points, *([] if hi is None else [hi])]
    lo_psi = wrap_angle(points[0].psi)
    shift = lo_psi - points[0].psi
    points = [p.at(p.psi + shift) for p in points] if shift else points
    return Run(
        PsiInterval(probe.signs, lo_psi, points[-1].psi), points, (span.before is None, span.after is None)
    )


def _refined(probe: Probe, inside: Point, outside: Point) -> Generator[Follow, tuple[Point, bool], Point]:
    r"""The last feasible point between a feasible ``inside`` and an infeasible ``outside``,
    neighbours on one path: a process of :func:`~om_redundant.redundancy.paths.linking.lockstep`,
    which asks for each trial's follow.

    The feasibility slack s (the smallest feasibility function g_j) changes sign between
    them. Each trial is followed from the inner end of the bracket
    (:meth:`~om_redundant.redundancy.paths.probe.Probe.follow`) and replaces the end on its side.
    The trials: first where the cubic Hermite models of the g_j (:func:`_modelled_end`)
    first reach zero; then Newton steps on the g_j binding at the last trial, aimed at
    :math:`s = \frac12` :data:`SLACK_TOLERANCE` with the rate dg_j/dpsi the trial carries,
    so that they end on the feasible side; where such a step leaves the bracket, the
    Illinois method (regula falsi that halves the slack kept at a stale end). It stops when
    the bracket is narrower than :data:`~om_redundant.redundancy.paths.probe.END_TOLERANCE` or the
    inner slack below :data:`SLACK_TOLERANCE`.

    **Path ends.** ``inside`` can be where its path ends (a run that is its path's first or
    last sample alone): at a fold, where the path turns back in psi and
    :math:`q - q_f \sim (\psi_f - \psi)^{1/2}`, the sample lies within END_TOLERANCE of the
    fold, :math:`|dq/d\psi|` there about 1e4-1e10. No follow leaves it (the first-order
    prediction of a step longer than its distance to the fold overshoots; a shorter one is
    refused), and its rates, which the models use, are a square root's (g_j goes as one
    too), not a smooth function's. The path between it and ``outside`` is one sheet over
    psi, which a follow from ``outside`` traces. So where the trial from ``inside`` is not
    arrived at, or one farther than END_TOLERANCE from a later inner end (then that end is
    where the path ends), the trials are followed from the bracket's outer end (the path's
    point at b) instead, the next one placed by the Illinois method (not by the inner end's
    rates), until one is feasible and becomes the inner end; a follow from the outer end
    that is not arrived at stops the refinement. A trial nearer a later inner end than
    END_TOLERANCE is refused by the follow and stops it: its Newton step (from the rates of
    a point that a follow arrived at) or secant puts the boundary within END_TOLERANCE.
    """
    a, fa, b, fb = inside, inside.evaluation.slack, outside.psi, outside.evaluation.slack
    beyond, ended = outside, False  # the path's point at b; a is the path's end (see above)
    x = _modelled_end(inside, outside)
    stale = 0  # +1: b was kept last time, -1: a was
    for _ in range(_MAX_REFINE):
        if abs(b - a.psi) <= END_TOLERANCE or fa <= SLACK_TOLERANCE:
            break
        if x is None or not 0.0 < (x - a.psi) / (b - a.psi) < 1.0:
            x = b - fb * (b - a.psi) / (fb - fa)
        p, arrived = yield probe, beyond if ended else a, x
        if not arrived:
            if ended or (a is not inside and abs(x - a.psi) < END_TOLERANCE):
                break
            ended, x = True, None
            continue
        if p.evaluation.feasible:
            a, fa, ended = p, p.evaluation.slack, False
            fb, stale = (fb / 2.0 if stale == 1 else fb), 1
        else:
            b, fb, beyond = x, p.evaluation.slack, p
            fa, stale = (fa / 2.0 if stale == -1 else fa), -1
        x = _newton(p)
    return a


def _newton(point: Point) -> float | None:
    """The Newton step on the feasibility function binding at point, aimed at a slack of
    half :data:`SLACK_TOLERANCE`; None where it does not move along psi."""
    g, dg = point.pieces()
    if len(g) == 0:
        return None
    j = int(g.argmin())
    rate = float(dg[j])  # (float arithmetic: numpy's scalars are slower)
    return point.psi + (0.5 * SLACK_TOLERANCE - float(g[j])) / rate if rate != 0.0 else None


def _modelled_end(inside: Point, outside: Point) -> float | None:
    """Where the first of the feasibility functions' cubic Hermite models between inside
    (s = 0) and outside (s = 1) reaches zero (``_core.crossing``, ``csrc/redundancy/cells.c``): the
    first of the _MODEL_POINTS points of the cell where one is negative, refined by that
    model's secant from the point before; None where none is negative there."""
    (ga, da), (gb, db) = inside.pieces(), outside.pieces()
    span = outside.psi - inside.psi
    s = _core.crossing(_core.CellModels(ga, da, gb, db, span, span, _HERMITE)) if len(ga) else None
    return None if s is None else inside.psi + span * s
