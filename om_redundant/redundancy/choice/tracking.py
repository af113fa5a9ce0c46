r"""The tracking step: the optimiser's choice for the next pose of a path in one compiled call.

From the previous choice (branch signs, psi, joints q'), :func:`_core.track_step
<om_redundant.ckernels>` (``csrc/redundancy/tracking.c``) does, for the new pose T:

1. the exact solution :math:`q_0` at the previous psi, hinted by :math:`q'`;
2. the self-motion tangent :math:`t = dq/d\psi = n / (D\psi(q_0)\,n)`, n the null vector of
   the Jacobian by cofactors, :math:`n_i = (-1)^i \det J_{-i}` (no factorisation);
3. every piece :math:`v_j` of the objective (:mod:`om_redundant.redundancy.objective.objective`) at
   :math:`q_0` and its rate :math:`a_j = \nabla v_j \cdot t` -- the margins and the
   singularity distances exactly, the clearances linearised about the joints where they were
   last evaluated, :math:`d_k + \nabla d_k \cdot (q_0 - q_{ref})`;
4. the step :math:`\delta` of the box QP in the N - 6 = 1 redundancy variable,

   .. math::  \max_\delta\ \sum_g w_g \min\big(cap_g, \min_{j\in g} v_j + a_j\delta\big)
              - \tfrac12 b\,\delta^2 \quad\text{s.t.}\quad v_j + a_j\delta \ge floor_g,
              \ |\delta| \le \min(\Delta_{max}, 0.25 / |t|_\infty),

   solved exactly (concave, its right derivative non-increasing: bisection on its sign,
   to rounding), b the curvature carried from the previous step
   (:attr:`RedundancyChoice.curvature`: the secant of the active pieces' rates);
5. the exact solution at :math:`\psi + \delta`, hinted by :math:`q_0` and checked to
   continue the self-motion (else :math:`\delta` is halved).

Each exact solve's local root is taken without the windowed scan for a nearer root where it
continues its path from the hint beyond doubt (within a quarter of its joint step of the
first-order prediction, as ``_core.follow`` takes its roots): the first solve's along the
hand's motion at fixed psi, :math:`[J; D\psi](q')\,\Delta q = [\Delta p; \omega; 0]` for the
flange's move from :math:`\mathrm{fk}(q')` to T, the second's along the self-motion,
:math:`t\,\delta`. Else the scan decides, as in :meth:`~om_redundant.OMSolver.solve`.

Python then evaluates the clearance exactly at the new joints (for the feasibility check and
as the next step's linearisation, :meth:`~om_redundant.Clearance.distances_within`), and the
result is a :class:`~om_redundant.RedundancyChoice`. A step that cannot be taken (no exact
solution continues the previous joints, a fold of the self-motion, nothing feasible within
the step, the result infeasible) answers why, in words: the optimiser then chooses afresh
from the arm's joints (:mod:`~om_redundant.redundancy.choice.reachable`). Repeated at one pose the
steps converge to a local optimum of the objective on the branch (a Newton-like iteration on
the crossing of the active pieces).
"""

from __future__ import annotations

import math
import threading
from typing import NamedTuple

import numpy as np

from ... import _core
from ...angles import wrap_angle
from ...ik.configuration import Configuration
from ...ik.solver import OMSolver, Solution
from ..objective.objective import Objective
from ..objective.terms import SINGULARITY_CAP

#: Curvature b of the first tracking step's model (per rad^2), and its largest (csrc/redundancy/tracking.c).
INITIAL_CURVATURE, MAX_CURVATURE = 0.1, 1e3
#: Where nothing is feasible within max_step (the feasible range moved away faster), the step
#: is tried again within this many times max_step: the joint step bounds it as before.
WIDER = 64.0
#: Where a step, and one more from it, land outside a floor, or it leaves the solution path, the
#: step is tried again within a quarter of the last reach, at most this many times (to
#: max_step / 4^8, 8e-8 rad at 0.005), and then at psi itself: a maximum on a floor is reached
#: to rounding, and its step lands outside by that; one at a fold, where the path ends, is
#: approached in shorter steps, and then held.
SHRINKS = 8
_JOINT_STEP = 0.25  # rad: the step keeps the linearised joint motion within this
#: Why _core.track_step refused, by its status (csrc/redundancy/redundancy.h).
_REFUSED = {
    _core.TRACK_NO_SOLUTION: "no exact solution at the previous psi continues the previous joints",
    _core.TRACK_SINGULAR: "the self-motion folds there (psi does not move along it)",
    _core.TRACK_INFEASIBLE: "nothing within the limits and clearance within max_step",
    _core.TRACK_LEFT: "the step along the self-motion left the solution path",
}
#: The clearances at joints q, the tracking step's model of them about q (``_core.Linearisation``).
Linearisation = _core.Linearisation


class Tracked(NamedTuple):
    """A tracking step taken: the exact solution at the new psi and the objective there.

    Attributes:
        solution: The exact solution (configuration: the branch and the new psi).
        margin, clearance, value: M, D and f at its joints.
        curvature: The curvature the next step's model takes.
        feasible: Within the limits and clear (what the optimiser is given always is).
    """

    solution: Solution
    margin: float
    clearance: float
    value: float
    curvature: float
    feasible: bool = True


class Tracker:
    """The tracking step of one optimiser (module docstring).

    Args:
        solver: The solver of a 7-DOF arm.
        objective: The optimiser's objective.
        max_step: Largest psi change per step (rad).
    """

    def __init__(self, solver: OMSolver, objective: Objective, max_step: float):
        self.solver, self.objective = solver, objective
        sing = objective.singularity
        n_sing = 0 if sing is None or objective.singularity_weight == 0.0 else len(sing.joints)
        arm = solver.arm
        self.work = _core.TrackingWork(
            solver.kernel,
            np.ascontiguousarray(arm.lower, dtype=float),
            np.ascontiguousarray(arm.upper, dtype=float),
            np.array(sing.joints[:n_sing] if n_sing else [], dtype=float),
            np.array(sing.offsets[:n_sing] if n_sing else [], dtype=float),
            np.zeros(arm.dof),
            margin_weight=objective.margin_weight,
            clearance_weight=objective.clearance_weight,
            singularity_weight=objective.singularity_weight,
            clearance_floor=objective.min_clearance / objective.clearance_cap,
            clearance_cap=objective.clearance_cap,
            singularity_cap=SINGULARITY_CAP,
            joint_step=_JOINT_STEP,
        )
        self.max_step = max_step
        # The last step's clearances, at its result's joints: the next step's linearisation.
        # Without obstacles, no pairs.
        self._last = Linearisation(np.zeros(arm.dof), np.zeros(0), np.zeros((0, arm.dof)))
        self._signs: dict[tuple[int, ...], np.ndarray] = {}  # each branch's signs as the kernel takes them
        self._lock = threading.Lock()  # the work arrays and the last linearisation: one step at a time

    def step(
        self, T: np.ndarray, signs: tuple[int, ...], psi: float, q: np.ndarray, curvature: float
    ) -> Tracked | str:
        """One tracking step from (signs, psi, q) to pose T.

        Returns:
            The step at the new psi, or why it cannot be taken or lands on an infeasible
            point (module docstring).
        """
        with self._lock:
            step = self._step(T, signs, psi, q, curvature, self.max_step)
            if step == _REFUSED[_core.TRACK_INFEASIBLE]:
                step = self._step(T, signs, psi, q, curvature, WIDER * self.max_step)
            if isinstance(step, Tracked) and not step.feasible:
                # just outside a floor (the pieces' curvature over the step): one step more from
                # there at the same pose, which the floors' linear models put back inside
                (psi_out,) = step.solution.configuration.redundancy
                step = self._step(T, signs, psi_out, step.solution.q, step.curvature, self.max_step)
            reach = self.max_step
            for k in range(SHRINKS + 1):
                # (a maximum on a floor: the step lands on it, rounded outside; at a fold, where
                # the path ends: the step leaves the path beyond it; the last try stays at psi)
                outside = isinstance(step, Tracked) and not step.feasible
                if not (outside or step == _REFUSED[_core.TRACK_LEFT]):
                    break
                reach = reach / 4.0 if k < SHRINKS else 0.0
                step = self._step(T, signs, psi, q, curvature, reach)
            if isinstance(step, Tracked) and not step.feasible:
                if not step.margin >= 0.0:
                    return f"the step's joints leave the limits (margin {step.margin:.3g})"
                return f"the step's joints come within {step.clearance:.4f} m of an obstacle"
            return step

    def _step(
        self,
        T: np.ndarray,
        signs: tuple[int, ...],
        psi: float,
        q: np.ndarray,
        curvature: float,
        max_step: float,
    ) -> Tracked | str:
        work, objective = self.work, self.objective
        linearised = self._linearised_at(q)
        signs_array = self._signs.get(signs)
        if signs_array is None:
            signs_array = self._signs[signs] = np.array(signs, dtype=np.int64)
        curvature = curvature if math.isfinite(curvature) else INITIAL_CURVATURE
        start = _core.TrackingStart(T, signs_array, psi, q, curvature)
        out = _core.track_step(work, start, linearised, max_step)
        if out.status != _core.TRACK_OK:
            return _REFUSED[out.status]
        q_new = work.q.copy()
        distances = None
        if objective.clearance is not None:
            self._last = self._linearisation(q_new)
            distances = self._last.distances
        evaluation = objective.evaluate(q_new, distances)
        clearance = evaluation.clearance
        if distances is not None and clearance >= objective.clearance_reach:  # (all pairs beyond the reach)
            clearance = objective.clearance.minimum(q_new)
        configuration = Configuration(signs, (wrap_angle(out.psi),))
        solution = Solution(
            q_new,
            True,
            "ok",
            configuration,
            out.position_error,
            out.orientation_error,
            out.evaluations,
            out.within_limits,
        )
        return Tracked(
            solution, evaluation.margin, clearance, evaluation.value, out.curvature, evaluation.feasible
        )

    def _linearised_at(self, q: np.ndarray) -> Linearisation:
        """The clearances at q: the last step's where q is its result's joints and the
        obstacles have not moved since (or there are no obstacles), else evaluated."""
        last, clearance = self._last, self.objective.clearance
        if clearance is None:
            return last
        if last.version == clearance.version and (last.q is q or np.array_equal(last.q, q)):
            return last
        return self._linearisation(q)

    def _linearisation(self, q: np.ndarray) -> Linearisation:
        """The clearances at q, evaluated (the pairs within the objective's reach)."""
        objective = self.objective
        clearance = objective.clearance
        version = clearance.version  # (read first: an update meanwhile makes the next step evaluate again)
        return Linearisation(
            q, *clearance.distances_within(q, objective.clearance_reach, gradient=True), version
        )
