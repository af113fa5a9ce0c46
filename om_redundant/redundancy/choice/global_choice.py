r"""The optimiser's global choice (the module docstring of :mod:`.optimizer`, steps 1-3): every
allowed branch swept along psi (its solution paths and feasible runs), the best start of each
run climbed, and, from where the arm is, the best candidate with a clear joint-space way."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ...angles import wrap_angle
from ...exceptions import SingularSelfMotion
from ...ik.configuration import Configuration
from ...ik.reach_envelope import ReachEnvelope
from ...ik.solver import OMSolver, Solution
from ..free_rotation import FreeRotation
from ..objective.objective import Objective
from ..objective.terms import Evaluation
from ..paths.intervals import BranchRuns, PsiInterval, Run, feasible_runs
from ..paths.linking import LinkedMemo, sweep_circle
from ..paths.points import Point
from ..paths.probe import END_TOLERANCE, Probe
from .climb import maximise, maximise_from_path_end
from .reachable import Way, candidates, clear_way
from .result import RedundancyChoice, failed_choice
from .start_bounds import CLIMB_ROUNDING, StartBounds


class GlobalChoice:
    """The global choice of :class:`~om_redundant.RedundancyOptimizer` (its ``solver``,
    ``objective``, ``branches``, ``grid_points``, ``_reach`` and ``_linked``: the paths of the
    poses swept last, which a pose swept again takes while the obstacles move)."""

    solver: OMSolver
    objective: Objective
    branches: list[tuple[int, ...]]
    grid_points: int
    _reach: ReachEnvelope
    _linked: LinkedMemo

    def _sweep(self, T: np.ndarray, branches: list[tuple[int, ...]], quick: bool = False) -> list[BranchRuns]:
        """Every branch's solution paths and feasible runs. Where a path runs within rounding
        of a singular set (SingularSelfMotion), the branches are swept one by one and those
        that raise have none, the reason in their ``unswept``; where T is proven out of reach
        (:class:`~om_redundant.ik.reach_envelope.ReachEnvelope`), none is swept, and each says so.

        ``quick``: the rows search no band (:func:`~om_redundant.redundancy.paths.linking.sweep_circle`).

        Raises:
            SingularSelfMotion: Every branch raised.
        """
        beyond = self._reach.beyond(T)
        if beyond is not None:
            distance = f"{beyond:.4f} m" if beyond < 1e6 else "too far"
            why = (
                f"the target is out of reach: its wrist centre lies {distance} beyond where the arm's "
                f"elbow reaches (more than the {self._reach.slack:.4f} m its offsets can make up), at every "
                "arm angle and branch"
            )
            return [BranchRuns(signs, [], [], why) for signs in branches]
        probes = [self._probe(T, signs) for signs in branches]
        try:
            swept = sweep_circle(probes, self.grid_points, quick, self._linked)
        except SingularSelfMotion as singular:
            if len(branches) == 1:
                raise
            alone = [self._sweep_alone(T, signs, quick) for signs in branches]
            if all(branch.unswept for branch in alone):
                raise singular
            return alone
        paths = [(probe, path) for probe, paths in zip(probes, swept, strict=True) for path in paths]
        runs = iter(feasible_runs(paths))
        return [
            BranchRuns(signs, paths, [run for _ in paths for run in next(runs)])
            for signs, paths in zip(branches, swept, strict=True)
        ]

    def _sweep_alone(self, T: np.ndarray, signs: tuple[int, ...], quick: bool = False) -> BranchRuns:
        try:
            return self._sweep(T, [signs], quick)[0]
        except SingularSelfMotion as singular:
            return BranchRuns(signs, [], [], str(singular))

    def _probe(self, T: np.ndarray, signs: tuple[int, ...]) -> Probe:
        return Probe(self.solver, self.objective, T, signs)

    def _best_anywhere(self, T: np.ndarray, branches: list[tuple[int, ...]]) -> RedundancyChoice:
        swept = self._sweep(T, branches)
        runs = [run for branch in swept for run in branch.runs]
        if not runs:
            why = self._reasons(swept)
            return failed_choice((), f"no feasible arm angle: {why}")
        return self._result(T, self._climb_all(T, runs), runs)

    def _from_joints(
        self,
        T: np.ndarray,
        q_from: np.ndarray | None,
        signs: tuple[int, ...] | None,
        free: FreeRotation | None,
    ) -> RedundancyChoice:
        """The fresh choice from the arm's joints (:mod:`~om_redundant.redundancy.choice.reachable`;
        without them, the best scored): a quick look at branch ``signs`` alone first (its grid
        rows searching no band), then, where it has no clear way, every allowed branch at once
        (None: at once from the start); with a free rotation, over the turns it starts from. (The
        quick look costs a sweep of all branches at once a fifth to a third of it, whether it
        finds a way or not: Gen3 1.8 ms median against 10.1, Sawyer 10-14 against 45-49.)"""
        hand = None if q_from is None else self.solver.arm.fk(q_from)
        turns = [None] if free is None else free.starts(T, hand)
        targets = [T if R is None else free.turned(T, R) for R in turns]
        at_once = signs is None
        swept = [
            self._sweep(target, self.branches) if at_once else [self._sweep_alone(target, signs, quick=True)]
            for target in targets
        ]
        way = self._way(targets, swept, q_from, signs)
        note = ""
        if (way is None or not way[0].clear) and signs is not None:
            own = [b for branches in swept for b in branches if b.signs == signs]
            unswept = next((b.unswept for b in own if b.unswept), "")
            ran = any(b.runs for b in own)
            note = f"branch {signs} has no {'clear way' if ran else 'feasible arm angle at this pose'}"
            note = f"branch {signs} was not swept: {unswept}" if unswept else note
            if not at_once:  # (the branch again, with its neighbours: its band is theirs)
                swept = [self._sweep(target, self.branches) for target in targets]
            way = self._way(targets, swept, q_from)
        if way is not None and not way[0].clear:
            note = "; ".join(filter(None, [note, "no candidate has a clear way: the best is taken"]))
        if way is None:
            why = self._reasons(swept[0])
            return failed_choice((), f"no feasible arm angle: {why}")
        chosen, k = way
        intervals = tuple(run.interval for branch in swept[k] for run in branch.runs)
        return self._chosen(targets[k], chosen, intervals, note, turns[k])

    def _way(
        self,
        targets: list[np.ndarray],
        swept: list[list[BranchRuns]],
        q_from: np.ndarray | None,
        signs: tuple[int, ...] | None = None,
    ) -> tuple[Way, int] | None:
        """The best candidate of the targets' runs (branch ``signs``' only, if given) with a
        clear way from q_from (or the best), and its target's index."""
        owner, ranked = {}, []
        for k, branches in enumerate(swept):
            runs = [run for b in branches if signs in (None, b.signs) for run in b.runs]
            owner.update((id(run), k) for run in runs)
            ranked += candidates(self.objective, runs, q_from, self.travel_weight)
        ranked.sort(key=lambda c: -c.score)
        way = clear_way(self.objective, ranked, q_from)
        return None if way is None else (way, owner[id(way.candidate.run)])

    def _chosen(
        self, T: np.ndarray, way: Way, intervals: tuple[PsiInterval, ...], note: str, turn: np.ndarray | None
    ) -> RedundancyChoice:
        """The choice of a candidate: its exact solution at its joints."""
        candidate = way.candidate
        configuration = Configuration(candidate.run.interval.signs, (wrap_angle(candidate.point.psi),))
        solution = candidate.point.solution or self.solver.solve(T, configuration, q_hint=candidate.point.q)
        return self._exact_choice(
            T,
            configuration,
            solution,
            candidate.q,
            candidate.evaluation,
            intervals,
            reason=note,
            travel=candidate.travel,
            way_clearance=way.clearance,
            way_clear=way.clear,
            turn=turn,
        )

    def _climb_all(self, T: np.ndarray, runs: list[Run]) -> tuple[Run, Point]:
        """The global maximum over the runs: climbs from the best starts (module docstring)."""
        # every run's samples at once (their slope bounds: StartBounds)
        points = [p for run in runs for p in run.points]
        owner = np.repeat(np.arange(len(runs)), [len(run.points) for run in runs])
        first = np.flatnonzero(np.diff(owner, prepend=-1))  # each run's first sample
        first, last = first[owner], np.append(first[1:], len(points))[owner] - 1
        psi = np.array([p.psi for p in points])
        f = np.array([p.evaluation.value for p in points])
        pairs = [p.terms.get_pairs() for p in points]  # (computed for the evaluations)
        distances = None if pairs[0] is None else np.array([d for d, _ in pairs])
        terms = self.objective.term_functions(np.array([p.q for p in points]), distances)
        # local maxima among a run's samples (its ends against their one neighbour)
        rising = np.concatenate([[True], f[1:] >= f[:-1]]) | (first == np.arange(len(f)))
        falling = np.concatenate([f[:-1] >= f[1:], [True]]) | (last == np.arange(len(f)))
        k = np.flatnonzero(rising & falling)
        gap = np.maximum(psi[np.minimum(k + 1, last[k])] - psi[k], psi[k] - psi[np.maximum(k - 1, first[k])])
        bounds = StartBounds(psi, f, terms, first, last)
        bound = bounds.cone(k, 2.0 * gap)
        rows = zip(f[k].tolist(), gap.tolist(), bound.tolist(), k.tolist(), strict=True)
        starts = [(f_k, gap_k, bound_k, j) for f_k, gap_k, bound_k, j in rows]
        starts.sort(key=lambda s: -s[0])
        found = [(runs[owner[starts[0][3]]], points[starts[0][3]])]
        best = found[0][1].evaluation.value
        probes = {}
        for _, gap, bound, j in starts:
            least = best + CLIMB_ROUNDING  # what a climb must reach
            if bound < least or bounds.within(j, 2.0 * gap) < least:  # (the cheap bound first)
                continue
            run = runs[owner[j]]
            lo, hi = (-math.inf, math.inf) if run.interval.closed else (run.interval.lo, run.interval.hi)
            signs = run.interval.signs
            if signs not in probes:
                probes[signs] = self._probe(T, signs)
            point = _climb(probes[signs], run, j - first[j], lo, hi, max(gap, 1e-6))
            found.append((run, point))
            best = max(best, point.evaluation.value)
        return next((run, point) for run, point in found if point.evaluation.value == best)

    def _result(self, T: np.ndarray, best: tuple[Run, Point], runs: list[Run]) -> RedundancyChoice:
        run, point = best
        configuration = Configuration(run.interval.signs, (wrap_angle(point.psi),))
        # The point's own solve (a batch sample is solved again, nearest itself), at the
        # point's representative of the joints: where psi has several roots near a singular
        # wrist, a fresh solve might return another one.
        solution = point.solution or self.solver.solve(T, configuration, q_hint=point.q)
        if not solution.ok:
            return failed_choice(
                tuple(r.interval for r in runs), f"the exact solve at the chosen psi: {solution.status}"
            )
        intervals = tuple(r.interval for r in runs)
        return self._exact_choice(T, configuration, solution, point.q, point.evaluation, intervals)

    def _exact_choice(
        self,
        T: np.ndarray,
        configuration: Configuration,
        solution: Solution,
        q: np.ndarray,
        evaluation: Evaluation,
        intervals: tuple[PsiInterval, ...],
        **fields: Any,
    ) -> RedundancyChoice:
        """The choice of the exact solution at joints q (q's own turns of the solution's
        joints) in ``configuration`` (psi wrapped), with q's evaluation."""
        solution = replace(
            solution, q=q, configuration=configuration, within_limits=self.solver.arm.within_limits(q)
        )
        ev = evaluation
        values = (ev.margin, ev.clearance, ev.value)
        return RedundancyChoice(solution.ok, configuration, solution, *values, intervals, pose=T, **fields)

    def _reasons(self, branches: list[BranchRuns]) -> str:
        """Why the branches hold nothing feasible: the one reason all share (the target out
        of reach), else each branch's."""
        shared = {branch.unswept for branch in branches}
        if len(shared) == 1 and (reason := shared.pop()):
            return reason
        return "; ".join(self._why(branch) for branch in branches)

    def _why(self, branch: BranchRuns) -> str:
        """Why a branch's solution paths hold nothing feasible."""
        signs = branch.signs
        if branch.unswept:
            return f"branch {signs}: not swept ({branch.unswept})"
        points = [p for path in branch.paths for p in path.points]
        if not points:
            return f"branch {signs}: no solution at any of {self.grid_points} arm angles"
        within = [p for p in points if p.evaluation.margin >= 0.0]
        if not within:
            best = max(p.evaluation.margin for p in points)
            return f"branch {signs}: outside the joint limits wherever solved (best margin {best:.3f})"
        best = max(p.evaluation.clearance for p in within)
        return (
            f"branch {signs}: clearance below {self.objective.min_clearance} m wherever within the limits "
            f"(best {best:.4f} m)"
        )


def _climb(probe: Probe, run: Run, k: int, lower: float, upper: float, radius: float) -> Point:
    """The climb from sample k of the run (:func:`~.climb.maximise`, within [lower, upper], its
    first trust radius ``radius``), and where it starts or ends at an end of the run where
    the path ends (:attr:`~om_redundant.redundancy.paths.intervals.Run.path_ends`), the search
    of that end's cell (:func:`~.climb.maximise_from_path_end`: at a fold no climb leaves the
    end); the best point found."""
    points = run.points
    sides = ((0, 1, run.path_ends[0]), (-1, -2, run.path_ends[1]))  # (its end, the sample next to it)
    ends = [(e, n) for e, n, path_end in sides if path_end] if len(points) > 1 else []
    start = points[k]
    at_end = any(points[e] is start for e, _ in ends)
    point = start if at_end else maximise(probe, start, lower, upper, radius)
    for e, n in ends:
        if abs(point.psi - points[e].psi) <= END_TOLERANCE:
            found = maximise_from_path_end(probe, points[e], points[n], lower, upper)
            point = found if found.evaluation.value > point.evaluation.value else point
    return point
