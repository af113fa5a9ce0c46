r"""The redundancy optimiser: a QP picks the arm angle for joint-limit margin, clearance and
distance from singularities.

For a pose T, :meth:`RedundancyOptimizer.choose` returns the configuration
c = (signs, psi) that maximises the objective f of :mod:`om_redundant.redundancy.objective` (weighted
normalised joint-limit margin, capped obstacle clearance and capped distance from the
model's singularities) over the feasible set (within the limits, clearance >= d_min), and
the exact OM solution in it:

1. **Sweep.** Every allowed branch's exact solutions are sampled on a psi grid and linked
   into solution paths (:mod:`om_redundant.redundancy.paths`), which are cut into feasible intervals
   with refined ends (:mod:`om_redundant.redundancy.intervals`).
2. **Starts.** In each interval, the samples that are local maxima of f. A climb from a
   start is taken to end within R, twice the start's distance to its farther neighbour, and
   each function to change at most by L, its largest slope between neighbouring samples
   (over every interval). On each side of the start, such a function is below the cones of
   slope L from the start's value u_0 and the neighbour's u_h (h away): below
   ``max((u_0 + u_h + L h) / 2, u_h + L (R - h))`` (:func:`_cone_bound`; at most
   ``u_0 + L R``). A start can only lead above the larger side's smaller of that bound of f
   and ``sum_g w_g min(cap_g, min_j bound_j)``, the second with each function v_j of each
   group (a joint's margin, a pair's distance, a singularity distance;
   :meth:`~om_redundant.redundancy.objective.Objective.term_functions`) bounded by its own
   slope: where what binds every term does not move with the self-motion (the elbow of an
   S-R-S arm binding the margin, the hand nearest an obstacle, or a term at its cap), f
   cannot rise above its start value.
   Starts are climbed best first, and those whose bound is below the best value found (by
   more than :data:`PLATEAU` when tracking; not above it by :data:`_CLIMB_ROUNDING`
   otherwise, a climb that could at most tie) are skipped. This is what finds the global
   optimum rather than the nearest local one.
3. **Climb** from each start (:func:`~om_redundant.redundancy.climb.maximise`): a trust-region SQP
   whose QP, solved exactly, linearises margins and clearances around the current exact
   solution, within the interval. The result is the best point's own exact solve.

**Tracking** (``choose(T, previous)``): the one-call tracking step of
:mod:`~om_redundant.redundancy.tracking` (an exact solve at the previous psi, the 1-variable
box QP along the self-motion, an exact solve at the new psi). Where it cannot step or lands
on an infeasible point, the optimiser **chooses afresh from the arm's joints** ``q_current``
(:mod:`~om_redundant.redundancy.reachable`): the previous branch's feasible samples first,
scored by f less the joint travel from ``q_current``, the first with a clear way winning;
the other branches only if the previous one has no feasible sample with a clear way. The
result says so (``rechosen``, ``branch_flipped``, ``reason``). It is not ok only when no
branch has a feasible arm angle at this pose: then :meth:`RedundancyOptimizer.intervals` is
empty too.

**From the arm's joints** (``choose(T, q_current=q)``): the same fresh choice without a
previous one, for the first target of a mink loop.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import mujoco
import numpy as np

from .. import _core
from ..exceptions import InvalidInput, SingularSelfMotion
from ..ik.configuration import Configuration
from ..ik.solver import OMSolver, Solution
from ..validation import as_count, as_instance, as_joint_vector, as_number, as_pose, as_signs
from .arm_angle import wrap_psi
from .clearance import DEFAULT_DISTMAX, Clearance
from .climb import maximise
from .free_rotation import FreeRotation
from .intervals import BranchRuns, PsiInterval, Run, feasible_runs
from .objective import Objective
from .objective_terms import (
    DEFAULT_CLEARANCE_WEIGHT,
    DEFAULT_MARGIN_WEIGHT,
    DEFAULT_SINGULARITY_WEIGHT,
    check_weights,
)
from .paths import sweep_circle
from .points import Point
from .probe import Probe
from .reachable import DEFAULT_TRAVEL_WEIGHT, Way, candidates, clear_way
from .shapes import Shape
from .singularity import Singularity
from .tracking import MAX_CURVATURE, Tracked, Tracker

#: Tracking with a free rotation: a turn is taken where it gains more than this.
_TURN_GAIN = 1e-9
#: Global choose: a start whose bound is within this of the best found is not climbed (it can
#: at most tie).
_CLIMB_ROUNDING = 1e-12
#: Bounds of ``grid_points`` (psi samples per branch; the sweep's cost grows with it).
MIN_GRID_POINTS, MAX_GRID_POINTS = 16, 100_000


@dataclass(frozen=True, eq=False)
class RedundancyChoice:
    """What :meth:`RedundancyOptimizer.choose` picked.

    Attributes:
        ok: A feasible configuration was found.
        configuration: The chosen configuration (signs, (psi,)), psi in [-pi, pi); None if not ok.
        solution: The exact OM solution in it; None if not ok.
        margin: Smallest normalised joint-limit margin M(q) (nan if not ok).
        clearance: Clearance D(q) in metres (inf without obstacles, nan if not ok).
        value: The objective f(q) (nan if not ok).
        intervals: The feasible intervals searched: every allowed branch's, or, chosen
            afresh from the arm's joints, those of the branches swept (the previous one
            first); empty from the one-call tracking step
            (:mod:`~om_redundant.redundancy.tracking`), which searches none.
        reason: Why nothing is feasible, or why tracking chose afresh; "" otherwise.
        branch_flipped: The choice left the previous choice's branch.
        curvature: The curvature (per rad^2) of the objective along psi that the next
            tracking step's model takes (:mod:`~om_redundant.redundancy.tracking`); nan:
            its initial value.
        rechosen: Tracking could not continue from the previous choice, and this choice
            was made afresh from the arm's joints (``reason`` says why).
        travel: Joint travel (rad, Euclidean) from the arm's joints ``q_current`` (or the
            previous choice's) to ``solution.q``; nan from a global choice.
        way_clearance: Of a choice made afresh from the arm's joints: a lower bound of the
            clearance along the straight joint-space way from them to ``solution.q``
            (:meth:`~om_redundant.Clearance.minimum_along`), at least
            ``min(min_clearance, D(q_current))`` less 1 mm where the way is clear; inf
            without obstacles; nan otherwise (a tracking step moves the joints a step at a
            time, each step's joints clear).
        way_clear: The way is certified clear, or none was checked (``way_clearance`` nan).
        turn: With a free rotation (``choose(..., free=...)``), the turn R of the target the
            solution reaches, :meth:`FreeRotation.turned(T, R)
            <om_redundant.FreeRotation.turned>`; None without.
        pose: The end-effector pose the solution reaches (T, or T turned); None if not ok.
    """

    ok: bool
    configuration: Configuration | None
    solution: Solution | None
    margin: float
    clearance: float
    value: float
    intervals: tuple[PsiInterval, ...]
    reason: str = ""
    branch_flipped: bool = False
    curvature: float = math.nan
    rechosen: bool = False
    travel: float = math.nan
    way_clearance: float = math.nan
    way_clear: bool = True
    turn: np.ndarray | None = None
    pose: np.ndarray | None = None


class RedundancyOptimizer:
    """Picks the arm angle psi (and branch) of a 7-DOF arm for margin, clearance and distance
    from singularities.

    Threads may share an optimiser (and its :class:`~om_redundant.Clearance`): the scratch
    that calls share (the tracking step's arrays, the MuJoCo data of the clearance's MuJoCo
    pairs) is taken by one call at a time.

    Args:
        solver: The OM solver of an arm with one redundancy variable.
        obstacles: None; shapes (:class:`~om_redundant.Sphere`, ``Capsule``, ``Box``) or a
            MuJoCo model of obstacles, in the arm's root frame (combined with the project's
            MJCF of the arm); or a :class:`~om_redundant.Clearance` (e.g. of your own model).
        margin_weight, clearance_weight, singularity_weight, clearance_cap, min_clearance: The
            objective (:class:`~om_redundant.redundancy.objective.Objective`; the singularity
            term is the model's, ``Singularity.of(solver.model_arm)``).
        branches: Allowed branch signs, e.g. ``[(1, -1, 1)]``; default all.
        grid_points: psi samples per branch of the sweep, a whole number from 16 to 100,000.
        max_step: Largest psi change (rad) per tracking call, in (0, pi].
        travel_weight: w_t >= 0, the objective given up per radian of joint travel when
            choosing from the arm's joints (:mod:`~om_redundant.redundancy.reachable`).

    Raises:
        InvalidInput: An argument of the wrong type or out of range (named); numbers must be
            numbers (``"1"`` is refused).

    Example::

        optimizer = om.RedundancyOptimizer(om.OMSolver("panda"), [om.Sphere([0.4, 0, 0.6], 0.05)])
        choice = optimizer.choose(T)
        if choice.ok:
            q = choice.solution.q
    """

    def __init__(
        self,
        solver: OMSolver,
        obstacles: Sequence[Shape] | mujoco.MjModel | Clearance | None = None,
        *,
        margin_weight: float = DEFAULT_MARGIN_WEIGHT,
        clearance_weight: float = DEFAULT_CLEARANCE_WEIGHT,
        singularity_weight: float = DEFAULT_SINGULARITY_WEIGHT,
        clearance_cap: float = 0.1,
        min_clearance: float = 0.0,
        branches: Sequence[Sequence[int]] | None = None,
        grid_points: int = 64,
        max_step: float = 0.05,
        travel_weight: float = DEFAULT_TRAVEL_WEIGHT,
    ):
        as_instance(solver, OMSolver, "solver")
        if len(solver.redundancy_names) != 1:
            raise InvalidInput(
                f"arm '{solver.arm.name}' has {len(solver.redundancy_names)} redundancy variables; "
                "the optimiser needs one (a 7-DOF arm's arm angle)"
            )
        check_weights(margin_weight, clearance_weight, clearance_cap, min_clearance, singularity_weight)
        if obstacles is not None and not isinstance(obstacles, Clearance):
            distmax = max(DEFAULT_DISTMAX, 2.0 * clearance_cap)
            obstacles = Clearance.for_arm(solver.arm, obstacles, distmax=distmax)
        self.solver = solver
        self.objective = Objective(
            solver.arm,
            obstacles,
            Singularity.of(solver.model_arm, solver.flip),
            margin_weight=margin_weight,
            clearance_weight=clearance_weight,
            singularity_weight=singularity_weight,
            clearance_cap=clearance_cap,
            min_clearance=min_clearance,
        )
        every = [c.signs for c in solver.configurations()]
        if branches is None:
            self.branches = every
        else:
            k = len(solver.sign_names)
            signs = as_signs(branches, k, "branches", stack=True).reshape(-1, k)
            self.branches = list(dict.fromkeys(tuple(int(s) for s in row) for row in signs))
        self.grid_points = as_count(grid_points, "grid_points", MIN_GRID_POINTS, MAX_GRID_POINTS)
        self.max_step = as_number(max_step, "max_step")
        if not 0.0 < self.max_step <= math.pi:
            raise InvalidInput(f"max_step must be in (0, pi] rad, got {max_step}")
        self.travel_weight = as_number(travel_weight, "travel_weight")
        if not self.travel_weight >= 0.0:
            raise InvalidInput(f"travel_weight must be >= 0, got {travel_weight}")
        self._tracker = Tracker(solver, self.objective, self.max_step)
        # shoulder offsets (the torus): a batch's branches share their grid search
        self._shared_search = bool(np.any(solver.model_arm.shoulder))

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickled as its solver, clearance and options (the tracking step's state is rebuilt)."""
        objective = self.objective
        options = {
            "margin_weight": objective.margin_weight,
            "clearance_weight": objective.clearance_weight,
            "singularity_weight": objective.singularity_weight,
            "clearance_cap": objective.clearance_cap,
            "min_clearance": objective.min_clearance,
            "branches": self.branches,
            "grid_points": self.grid_points,
            "max_step": self.max_step,
            "travel_weight": self.travel_weight,
        }
        return (_rebuilt, (self.solver, objective.clearance, options))

    @property
    def clearance(self) -> Clearance | None:
        """The obstacles' :class:`~om_redundant.Clearance` (None without obstacles)."""
        return self.objective.clearance

    @property
    def min_clearance(self) -> float:
        """The clearance every choice keeps, d_min (m)."""
        return self.objective.min_clearance

    def intervals(self, T: Any) -> list[PsiInterval]:
        """The feasible psi intervals of every allowed branch at pose T."""
        T = as_pose(T)
        return [run.interval for branch in self._sweep(T, self.branches) for run in branch.runs]

    def choose(
        self,
        T: Any,
        previous: RedundancyChoice | None = None,
        *,
        q_current: Any = None,
        free: FreeRotation | None = None,
    ) -> RedundancyChoice:
        """The best configuration for pose T; with ``previous``, the best near it; with the
        arm's joints ``q_current``, one the arm can reach from where it is.

        Args:
            T: Target pose of the end effector in the root frame: 4x4 or ``mink.SE3``.
            previous: The choice for the previous pose of a path: tracking mode (module
                docstring). A previous choice that is not ok starts afresh.
            q_current: The arm's joints now (dof,), e.g. a mink configuration's: a fresh
                choice weighs the joint travel from them and wants a clear way from them.
                Default: a global choice, or the previous choice's joints when tracking.
            free: Rotations of T left free (a tool axis to point, or a position to reach):
                the optimiser picks the turn too (:mod:`~om_redundant.redundancy.free_rotation`),
                reported as the choice's ``turn``.

        Returns:
            A :class:`RedundancyChoice`; ``ok`` is False, with the reason, only when no
            allowed branch has a feasible arm angle at T.

        Raises:
            InvalidInput: A malformed pose, previous choice or joint vector.
            SingularSelfMotion: A solution met where psi does not move along the
                self-motion (a stretched arm, e.g. the iiwa14 at q = 0), so no rates exist.
        """
        T = as_pose(T)
        if q_current is not None:
            q_current = as_joint_vector(q_current, self.solver.arm.dof, "q_current", stack=False)
        if previous is not None and not isinstance(previous, RedundancyChoice):
            raise InvalidInput(f"previous must be a RedundancyChoice, got {type(previous).__name__}")
        if free is not None:
            as_instance(free, FreeRotation, "free")
        if previous is None or not previous.ok:
            if q_current is None and free is None:
                return self._best_anywhere(T, self.branches)
            signs = None if q_current is None else self.solver.configuration_of(q_current).signs
            return self._from_joints(T, q_current, signs if signs in self.branches else None, free)
        if previous.configuration.signs not in self.branches:
            raise InvalidInput(
                f"previous branch {previous.configuration.signs} is not among the allowed branches"
            )
        if (free is None) != (previous.turn is None):
            raise InvalidInput(
                "previous was chosen with another free rotation: choose afresh (previous=None)"
            )
        return self._track(T, previous, q_current, free)

    # -----------------------------------------------------------------------------------

    def _sweep(self, T: np.ndarray, branches: list[tuple[int, ...]]) -> list[BranchRuns]:
        """Every branch's solution paths and feasible runs. Where a path runs within rounding
        of a singular set (SingularSelfMotion), the branches are swept one by one and those
        that raise have none, the reason in their ``stalled``.

        Raises:
            SingularSelfMotion: Every branch raised.
        """
        probes = [self._probe(T, signs) for signs in branches]
        try:
            swept = sweep_circle(probes, self.grid_points)
        except SingularSelfMotion as singular:
            if len(branches) == 1:
                raise
            alone = [self._sweep_alone(T, signs) for signs in branches]
            if all(branch.stalled for branch in alone):
                raise singular
            return alone
        paths = [(probe, path) for probe, paths in zip(probes, swept, strict=True) for path in paths]
        runs = iter(feasible_runs(paths))
        return [
            BranchRuns(signs, paths, [run for _ in paths for run in next(runs)])
            for signs, paths in zip(branches, swept, strict=True)
        ]

    def _sweep_alone(self, T: np.ndarray, signs: tuple[int, ...]) -> BranchRuns:
        try:
            return self._sweep(T, [signs])[0]
        except SingularSelfMotion as singular:
            return BranchRuns(signs, [], [], str(singular))

    def _probe(self, T: np.ndarray, signs: tuple[int, ...]) -> Probe:
        return Probe(self.solver, self.objective, T, signs)

    def _best_anywhere(self, T: np.ndarray, branches: list[tuple[int, ...]]) -> RedundancyChoice:
        swept = self._sweep(T, branches)
        runs = [run for branch in swept for run in branch.runs]
        if not runs:
            why = "; ".join(self._why(branch) for branch in swept)
            return _failure((), f"no feasible arm angle: {why}")
        return self._result(T, self._climb_all(T, runs), runs)

    def _track(
        self,
        T: np.ndarray,
        previous: RedundancyChoice,
        q_current: np.ndarray | None,
        free: FreeRotation | None,
    ) -> RedundancyChoice:
        signs, (psi,) = previous.configuration.signs, previous.configuration.redundancy
        q_previous = previous.solution.q
        turn = previous.turn
        target = T if free is None else free.turned(T, turn)
        step = self._tracker.step(target, signs, psi, q_previous, previous.curvature)
        if free is not None:  # a step each way about each free axis: the best feasible that gains on
            # both this step and the previous choice (a turn back and forth about an optimum is none)
            for trial in free.trials(turn, self.max_step):
                turned = free.turned(T, trial)
                tried = self._tracker.step(turned, signs, psi, q_previous, previous.curvature)
                least = (
                    max(step.value if isinstance(step, Tracked) else -math.inf, previous.value) + _TURN_GAIN
                )
                if isinstance(tried, Tracked) and (not isinstance(step, Tracked) or tried.value > least):
                    step, turn, target = tried, trial, turned
        if (
            isinstance(step, Tracked)
            and step.value < previous.value
            and np.array_equal(target, previous.pose)
        ):
            # at the same pose a step may only climb: one that loses (the model's kink or curvature
            # overshot the optimum, a step back and forth about it) is not taken
            curvature = min(4.0 * step.curvature, MAX_CURVATURE)
            return replace(previous, curvature=curvature, reason="", rechosen=False, branch_flipped=False)
        if isinstance(step, Tracked):
            choice = RedundancyChoice(
                True,
                step.solution.configuration,
                step.solution,
                step.margin,
                step.clearance,
                step.value,
                (),
                curvature=step.curvature,
                turn=turn,
                pose=target,
            )
            if q_current is not None:
                choice = replace(choice, travel=float(np.linalg.norm(step.solution.q - q_current)))
            return choice
        start = q_previous if q_current is None else q_current
        chosen = self._from_joints(T, start, signs, free)
        if not chosen.ok:
            return chosen
        flipped = chosen.configuration.signs != signs
        reason = (
            f"tracking from branch {signs} at psi = {psi:+.4f} stopped: {step}; chose afresh from the "
            f"arm's joints: branch {chosen.configuration.signs} at psi = "
            f"{chosen.configuration.redundancy[0]:+.4f}, {chosen.travel:.3f} rad of joint travel"
        )
        if chosen.reason:
            reason += f" ({chosen.reason})"
        return replace(chosen, rechosen=True, branch_flipped=flipped, reason=reason)

    def _from_joints(
        self,
        T: np.ndarray,
        q_from: np.ndarray | None,
        signs: tuple[int, ...] | None,
        free: FreeRotation | None,
    ) -> RedundancyChoice:
        """The fresh choice from the arm's joints (:mod:`~om_redundant.redundancy.reachable`;
        without them, the best scored): branch ``signs`` first (None: every allowed branch at
        once); with a free rotation, over the turns it starts from. An arm whose branches share
        their grid search in one batch (shoulder offsets: the torus) sweeps them all at once."""
        hand = None if q_from is None else self.solver.arm.fk(q_from)
        turns = [None] if free is None else free.starts(T, hand)
        targets = [T if R is None else free.turned(T, R) for R in turns]
        at_once = signs is None or self._shared_search
        first = self.branches if at_once else [signs]
        swept = [self._sweep(target, first) for target in targets]
        way = self._way(targets, swept, q_from, signs)
        note = ""
        if (way is None or not way[0].clear) and signs is not None:
            own = [b for branches in swept for b in branches if b.signs == signs]
            stalled = next((b.stalled for b in own if b.stalled), "")
            ran = any(b.runs for b in own)
            note = f"branch {signs} has no {'clear way' if ran else 'feasible arm angle at this pose'}"
            note = f"branch {signs} was not swept: {stalled}" if stalled else note
            if not at_once:
                others = [b for b in self.branches if b != signs]
                swept = [
                    branch + self._sweep(target, others)
                    for branch, target in zip(swept, targets, strict=True)
                ]
            way = self._way(targets, swept, q_from)
        if way is not None and not way[0].clear:
            note = "; ".join(filter(None, [note, "no candidate has a clear way: the best is taken"]))
        if way is None:
            why = "; ".join(self._why(branch) for branch in swept[0])
            return _failure((), f"no feasible arm angle: {why}")
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
        configuration = Configuration(candidate.run.interval.signs, (wrap_psi(candidate.point.psi),))
        solution = candidate.point.solution or self.solver.solve(T, configuration, q_hint=candidate.point.q)
        solution = replace(
            solution,
            q=candidate.q,
            configuration=configuration,
            within_limits=self.solver.arm.within_limits(candidate.q),
        )
        ev = candidate.evaluation
        return RedundancyChoice(
            solution.ok,
            configuration,
            solution,
            ev.margin,
            ev.clearance,
            ev.value,
            intervals,
            reason=note,
            travel=candidate.travel,
            way_clearance=way.clearance,
            way_clear=way.clear,
            turn=turn,
            pose=T,
        )

    def _climb_all(self, T: np.ndarray, runs: list[Run]) -> tuple[Run, Point]:
        """The global maximum over the runs: climbs from the best starts (module docstring)."""
        # every run's samples at once (their slope bounds: _StartBounds)
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
        bounds = _StartBounds(psi, f, terms, first, last)
        bound = bounds.cone(k, 2.0 * gap)
        rows = zip(f[k].tolist(), gap.tolist(), bound.tolist(), k.tolist(), strict=True)
        starts = [(f_k, gap_k, bound_k, j) for f_k, gap_k, bound_k, j in rows]
        starts.sort(key=lambda s: -s[0])
        found = [(runs[owner[starts[0][3]]], points[starts[0][3]])]
        best = found[0][1].evaluation.value
        probes = {}
        for _, gap, bound, j in starts:
            least = best + _CLIMB_ROUNDING  # what a climb must reach
            if bound < least or bounds.within(j, 2.0 * gap) < least:  # (the cheap bound first)
                continue
            run, start = runs[owner[j]], points[j]
            lo, hi = (-math.inf, math.inf) if run.interval.closed else (run.interval.lo, run.interval.hi)
            signs = run.interval.signs
            if signs not in probes:
                probes[signs] = self._probe(T, signs)
            point = maximise(probes[signs], start, lo, hi, max(gap, 1e-6))
            found.append((run, point))
            best = max(best, point.evaluation.value)
        return next((run, point) for run, point in found if point.evaluation.value == best)

    def _result(self, T: np.ndarray, best: tuple[Run, Point], runs: list[Run]) -> RedundancyChoice:
        run, point = best
        configuration = Configuration(run.interval.signs, (wrap_psi(point.psi),))
        # The point's own solve (a batch sample is solved again, nearest itself), at the
        # point's representative of the joints: where psi has several roots near a singular
        # wrist, a fresh solve might return another one.
        solution = point.solution or self.solver.solve(T, configuration, q_hint=point.q)
        if not solution.ok:
            return _failure(
                tuple(r.interval for r in runs), f"the exact solve at the chosen psi: {solution.status}"
            )
        solution = replace(
            solution,
            q=point.q,
            configuration=configuration,
            within_limits=self.solver.arm.within_limits(point.q),
        )
        ev = point.evaluation
        return RedundancyChoice(
            solution.ok,
            configuration,
            solution,
            ev.margin,
            ev.clearance,
            ev.value,
            tuple(r.interval for r in runs),
            pose=T,
        )

    def _why(self, branch: BranchRuns) -> str:
        """Why a branch's solution paths hold nothing feasible."""
        signs = branch.signs
        if branch.stalled:
            return f"branch {signs}: not swept ({branch.stalled})"
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


class _StartBounds:
    r"""Bounds of what climbs from the samples of runs can reach (module docstring, Starts):
    f within a reach R of a start, a function u of slope bound L being below the cones
    :math:`u_i + L |x - \psi_i|` of the samples of its run.

    Args:
        psi, f: (M,) the runs' samples, a run's in increasing psi, and f there.
        terms: :meth:`~om_redundant.redundancy.objective.Objective.term_functions` at them.
        first, last: (M,) each sample's run's first and last sample.
        slope, slopes: L of f and of each group's functions (p_g,); None: sampled, the
            largest slope between neighbouring samples of a run (module docstring).
    """

    def __init__(
        self,
        psi: np.ndarray,
        f: np.ndarray,
        terms: list[tuple[float, float, np.ndarray]],
        first: np.ndarray,
        last: np.ndarray,
        slope: float | None = None,
        slopes: list[np.ndarray] | None = None,
    ):
        # f and every group's functions as the columns of one array, their slope bounds L
        self.psi, self.first, self.last = psi, first, last
        self._values = np.ascontiguousarray(
            np.hstack([f[:, None]] + [v for _, _, v in terms])
        )  # (row by row)
        if slope is None:
            inner = first[1:] == first[:-1]  # neighbours on one run
            step = np.maximum(np.diff(psi), 1e-12)[inner]
            rise = np.abs(np.diff(self._values, axis=0)[inner])
            self._slopes = np.max(rise / step[:, None], axis=0, initial=0.0)
        else:
            self._slopes = np.concatenate([[slope], *slopes])
        # each group's first column
        self._groups = np.cumsum([1] + [v.shape[1] for _, _, v in terms[:-1]], dtype=np.int64)[: len(terms)]
        self._weights = np.array([w for w, _, _ in terms])
        self._caps = np.array([cap for _, cap, _ in terms])
        self._samples = _core.StartSamples(
            self.psi, self._values, self._slopes, self._groups, self._weights, self._caps
        )

    def cone(self, k: np.ndarray, reach: np.ndarray) -> np.ndarray:
        r"""(K,) the bounds from the starts' own cones: the smaller of :math:`f_k + L R` and
        :math:`\sum_g w_g \min(cap_g, \min_j (v_{jk} + L_j R))`, the groups summed in their
        order (``_core.start_cones``, ``csrc/start_bounds.c``; its numpy oracle is
        ``tests/reference/start_bounds.py``)."""
        bounds, reach = np.empty(len(k)), np.ascontiguousarray(reach, dtype=float)
        _core.start_cones(self._samples, np.ascontiguousarray(k, dtype=np.int64), reach, bounds)
        return bounds

    def within(self, k: int, reach: float) -> float:
        r"""The bound of start k from every sample of its run within its reach R (never
        above :meth:`cone`'s for consistent slopes). Between neighbouring samples i, i + 1
        (h apart) the cones of the two meet at most at :math:`(u_i + u_{i+1} + L h)/2`; in
        a cell that R cuts, or beyond the run's end, the last sample's cone reaches
        :math:`u_i + L r` (r the reach left). Per cell or cut cell the smaller of f's bound
        and the terms' (:meth:`cone`'s sum), the largest over the cells; at least f_k
        (``_core.start_bound``, ``csrc/start_bounds.c``; its numpy oracle is
        ``tests/reference/start_bounds.py``).

        Args:
            k: The start's sample.
            reach: R >= 0.
        """
        return _core.start_bound(self._samples, int(k), int(self.first[k]), int(self.last[k]), reach)


def _rebuilt(solver: OMSolver, clearance: Clearance | None, options: dict[str, Any]) -> RedundancyOptimizer:
    """A :class:`RedundancyOptimizer` unpickled (:meth:`RedundancyOptimizer.__reduce__`)."""
    return RedundancyOptimizer(solver, clearance, **options)


def _failure(intervals: tuple[PsiInterval, ...], reason: str) -> RedundancyChoice:
    return RedundancyChoice(False, None, None, math.nan, math.nan, math.nan, intervals, reason)
