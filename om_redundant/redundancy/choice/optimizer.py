r"""The redundancy optimiser: a QP picks the arm angle for joint-limit margin, clearance and
distance from singularities.

For a pose T, :meth:`RedundancyOptimizer.choose` returns the configuration
c = (signs, psi) that maximises the objective f of
:mod:`om_redundant.redundancy.objective.objective` (weighted
normalised joint-limit margin, capped obstacle clearance and capped distance from the
model's singularities) over the feasible set (within the limits, clearance >= d_min), and
the exact OM solution in it:

1. **Sweep.** Every allowed branch's exact solutions are sampled on a psi grid and linked
   into solution paths (:mod:`om_redundant.redundancy.paths.linking`), which are cut into feasible intervals
   with refined ends (:mod:`om_redundant.redundancy.paths.intervals`).
2. **Starts.** In each interval, the samples that are local maxima of f. A climb from a
   start is taken to end within R, twice the start's distance to its farther neighbour, and
   each function to change at most by L, its largest slope between neighbouring samples of
   the start's interval (a climb stays within it). On each side of the start, such a
   function is below the cones of slope L from the start's value u_0 and the neighbour's
   u_h (h away): below
   ``max((u_0 + u_h + L h) / 2, u_h + L (R - h))`` (:func:`_cone_bound`; at most
   ``u_0 + L R``). A start can only lead above the larger side's smaller of that bound of f
   and ``sum_g w_g min(cap_g, min_j bound_j)``, the second with each function v_j of each
   group (a joint's margin, a pair's distance, a singularity distance;
   :meth:`~om_redundant.redundancy.objective.objective.Objective.term_functions`) bounded by its own
   slope: where what binds every term does not move with the self-motion (the elbow of an
   S-R-S arm binding the margin, the hand nearest an obstacle, or a term at its cap), f
   cannot rise above its start value.
   Starts are climbed best first, and those whose bound is below the best value found (by
   more than :data:`PLATEAU` when tracking; not above it by :data:`~.start_bounds.CLIMB_ROUNDING`
   otherwise, a climb that could at most tie) are skipped. This is what finds the global
   optimum rather than the nearest local one.
3. **Climb** from each start (:func:`~om_redundant.redundancy.choice.climb.maximise`): a trust-region SQP
   whose QP, solved exactly, linearises margins and clearances around the current exact
   solution, within the interval. The result is the best point's own exact solve.

**Tracking** (``choose(T, previous)``): the one-call tracking step of
:mod:`~om_redundant.redundancy.choice.tracking` (an exact solve at the previous psi, the 1-variable
box QP along the self-motion, an exact solve at the new psi). Where it cannot step or lands
on an infeasible point, the optimiser **chooses afresh from the arm's joints** ``q_current``
(:mod:`~om_redundant.redundancy.choice.reachable`): the previous branch's feasible samples first,
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
from dataclasses import replace
from typing import Any

import mujoco
import numpy as np

from ...exceptions import InvalidInput
from ...ik.reach_envelope import ReachEnvelope
from ...ik.solver import OMSolver
from ...validation import as_count, as_instance, as_joint_vector, as_number, as_pose, as_signs
from ..free_rotation import FreeRotation
from ..objective.clearance import DEFAULT_DISTMAX, Clearance
from ..objective.objective import Objective
from ..objective.shapes import Shape
from ..objective.singularity import Singularity
from ..objective.terms import (
    DEFAULT_CLEARANCE_WEIGHT,
    DEFAULT_MARGIN_WEIGHT,
    DEFAULT_SINGULARITY_WEIGHT,
    check_weights,
)
from ..paths.intervals import PsiInterval
from ..paths.linking import LinkedMemo
from .global_choice import GlobalChoice
from .reachable import DEFAULT_TRAVEL_WEIGHT
from .result import RedundancyChoice, failed_choice
from .tracking import MAX_CURVATURE, Tracked, Tracker

#: Tracking with a free rotation: a turn is taken where it gains more than this.
_TURN_GAIN = 1e-9
#: Bounds of ``grid_points`` (psi samples per branch; the sweep's cost grows with it).
MIN_GRID_POINTS, MAX_GRID_POINTS = 16, 100_000


class RedundancyOptimizer(GlobalChoice):
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
            objective (:class:`~om_redundant.redundancy.objective.objective.Objective`; the singularity
            term is the model's, ``Singularity.of(solver.model_arm)``).
        branches: Allowed branch signs, e.g. ``[(1, -1, 1)]``; default all.
        grid_points: psi samples per branch of the sweep, a whole number from 16 to 100,000.
        max_step: Largest psi change (rad) per tracking call, in (0, pi].
        travel_weight: w_t >= 0, the objective given up per radian of joint travel when
            choosing from the arm's joints (:mod:`~om_redundant.redundancy.choice.reachable`).

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
        self._reach = ReachEnvelope(solver)
        self._linked = LinkedMemo()

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
        rechoose: bool = True,
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
            rechoose: Where tracking from ``previous`` cannot continue, choose afresh (the
                choice ``rechosen``); False: a choice that is not ok, the reason saying why
                tracking stopped (to learn whether tracking continues, without a sweep).

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
        version = self._clearance_version()  # (read first: an update meanwhile is seen next call)
        if previous is None or not previous.ok:
            if q_current is None and free is None:
                return self._stamped(self._best_anywhere(T, self.branches), version)
            signs = None if q_current is None else self.solver.configuration_of(q_current).signs
            chosen = self._from_joints(T, q_current, signs if signs in self.branches else None, free)
            return self._stamped(chosen, version)
        if previous.configuration.signs not in self.branches:
            raise InvalidInput(
                f"previous branch {previous.configuration.signs} is not among the allowed branches"
            )
        if (free is None) != (previous.turn is None):
            raise InvalidInput(
                "previous was chosen with another free rotation: choose afresh (previous=None)"
            )
        return self._stamped(self._track(T, previous, q_current, free, version, rechoose), version)

    # -----------------------------------------------------------------------------------

    def _clearance_version(self) -> int:
        clearance = self.objective.clearance
        return 0 if clearance is None else clearance.version

    @staticmethod
    def _stamped(choice: RedundancyChoice, version: int) -> RedundancyChoice:
        """The choice with the clearance's version it was weighed in."""
        return choice if choice.clearance_version == version else replace(choice, clearance_version=version)

    def _track(
        self,
        T: np.ndarray,
        previous: RedundancyChoice,
        q_current: np.ndarray | None,
        free: FreeRotation | None,
        version: int,
        rechoose: bool,
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
            and previous.clearance_version == version
        ):
            # at the same pose, obstacles unmoved, a step may only climb: one that loses (the
            # model's kink or curvature overshot the optimum, a step back and forth about it) is
            # not taken (obstacles that moved change the values: the step is the choice)
            curvature = min(4.0 * step.curvature, MAX_CURVATURE)
            return replace(previous, curvature=curvature, reason="", rechosen=False, branch_flipped=False)
        if isinstance(step, Tracked):
            travel = math.nan if q_current is None else float(np.linalg.norm(step.solution.q - q_current))
            return RedundancyChoice(
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
                travel=travel,
                clearance_version=version,
            )
        stopped = f"tracking from branch {signs} at psi = {psi:+.4f} stopped: {step}"
        if not rechoose:
            return failed_choice((), stopped)
        start = q_previous if q_current is None else q_current
        chosen = self._from_joints(T, start, signs, free)
        if not chosen.ok:
            return chosen
        flipped = chosen.configuration.signs != signs
        reason = (
            f"{stopped}; chose afresh from the arm's joints: branch {chosen.configuration.signs} at psi = "
            f"{chosen.configuration.redundancy[0]:+.4f}, {chosen.travel:.3f} rad of joint travel"
        )
        if chosen.reason:
            reason += f" ({chosen.reason})"
        return replace(chosen, rechosen=True, branch_flipped=flipped, reason=reason)


def _rebuilt(solver: OMSolver, clearance: Clearance | None, options: dict[str, Any]) -> RedundancyOptimizer:
    """A :class:`RedundancyOptimizer` unpickled (:meth:`RedundancyOptimizer.__reduce__`)."""
    return RedundancyOptimizer(solver, clearance, **options)
