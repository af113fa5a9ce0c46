r"""The climb: a trust-region SQP that maximises the objective over the redundancy variables.

From a feasible exact solution q(psi) on a branch, every piece v_j of every group g of the
objective (:mod:`om_redundant.redundancy.objective`) is linearised through the self-motion tangent
dq/dpsi (:func:`self_motion_tangent`), :math:`v_j(\psi + \delta) \approx v_j + a_j^T\delta`,
and the QP

.. math::  \max_{\delta, t}\ \sum_g w_g t_g - \tfrac12 \delta^T B \delta
           \quad\text{s.t.}\quad t_g \le v_j + a_j^T\delta\ (j \in g),\quad
           \mathrm{floor}_g \le t_g \le \mathrm{cap}_g,\quad
           |\delta|_\infty \le \Delta,\quad lo \le \psi + \delta \le hi

(the epigraph form of the max-min objective; the floors keep the linearised margins >= 0
and clearances >= d_min) is solved exactly with one variable (:mod:`~om_redundant.redundancy.box_qp`),
else by OSQP through qpsolvers. B is a damped BFGS estimate of
the curvature of the Lagrangian, from the QP's multipliers z_j:
:math:`s = \delta`, :math:`y = -\sum_j z_j (a_j^{new} - a_j^{old})`. The step is solved
exactly (the current q as hint); it is accepted when the exact point is feasible and gains
at least a tenth of the model's gain :math:`\sum_g w_g \min(cap_g, \min_j (v_j + a_j^T\delta))
- \tfrac12\delta^T B\delta - f`; the trust radius Delta then doubles (a good full step) or
otherwise shrinks to a quarter of the step. The climb stops when the step or the model's
gain vanishes. Everything here is written for r redundancy variables (r = 1 for 7-DOF arms);
with one, the climb runs on Python floats and one compiled call per QP (the same operations).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace

import numpy as np
import qpsolvers
import scipy.sparse as sp

from .box_qp import Pieces, step_1d
from .objective import Group
from .probe import Point, Probe

STEP_TOLERANCE = 1e-9  # rad: the climb stops when the step is this small
GAIN_TOLERANCE = 1e-12  # the climb stops when the model promises no more
_MAX_CLIMB = 60  # QPs per climb
_ACCEPT = 0.1  # accepted steps gain this fraction of the model's gain
_INITIAL_CURVATURE = 0.1  # B at the first QP of a climb
_JOINT_STEP = 0.25  # rad: the trust radius keeps the linearised joint motion within this
_FLAT = 1e-9  # slopes of the linearised pieces below this are rounding errors
_OSQP = {
    "eps_abs": 1e-6,
    "eps_rel": 1e-6,
    "polishing": True,
    "rho": 1.0,
    "verbose": False,
    "raise_error": False,
}


@dataclass(frozen=True)
class _Step:
    """A QP step: delta, the model's gain over the current value, multipliers per group."""

    delta: np.ndarray
    gain: float
    multipliers: list[np.ndarray]


def qp_step(
    groups: list[Group],
    curvature: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
) -> _Step | None:
    """Solve the climb's QP (module docstring) for the step delta.

    Pieces that cannot be their group's minimum anywhere in the box [lower, upper] are left
    out (their constraints are implied by the minimum's); their multipliers are zero.

    Args:
        groups: Groups with jacobians (p_g, r) by the redundancy variables.
        curvature: B (r, r), positive definite.
        lower, upper: (r,) bounds of delta (trust region and interval), lower <= 0 <= upper.

    Returns:
        The step, or None when the QP has no solution or OSQP returns no iterate. With one
        variable the QP is solved exactly (:func:`~om_redundant.redundancy.box_qp.step_1d`);
        otherwise by OSQP, whose iterate is taken even when it did not meet its tolerances
        (on nearly degenerate problems, at a kink the climb has already reached): the climb
        checks every step exactly.
    """
    r = len(lower)
    if r == 1:
        pieces = Pieces.of(groups)
        found = step_1d(pieces, float(curvature[0, 0]), float(lower[0]), float(upper[0]))
        if found is None:
            return None
        delta, gain, z = found
        return _Step(np.array([delta]), gain, pieces.split(z))
    reach = np.maximum(-lower, upper)
    keep = [_may_be_least(g, reach) for g in groups]
    found = _osqp_step(groups, keep, curvature, lower, upper, reach)
    if found is None:
        return None
    delta, duals = found
    gain = _model(groups, delta) - 0.5 * delta @ curvature @ delta - _model(groups, np.zeros(r))
    multipliers = [np.zeros(len(g.values)) for g in groups]
    for full, k, z in zip(multipliers, keep, duals, strict=True):
        full[k] = z
    return _Step(delta, gain, multipliers)


def _osqp_step(
    groups: list[Group],
    keep: list[np.ndarray],
    curvature: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    reach: np.ndarray,
) -> tuple[np.ndarray, list[np.ndarray]] | None:
    """The QP solved by OSQP: delta and the kept pieces' multipliers per group."""
    r = len(lower)
    scale = _scale(np.vstack([g.jacobian[k] for g, k in zip(groups, keep, strict=True)]), reach)
    problem = _problem(groups, keep, curvature, scale, lower, upper)
    start = np.concatenate([np.zeros(r), [min(g.cap, g.values.min()) for g in groups]])  # delta = 0
    with warnings.catch_warnings():  # an iterate that OSQP did not certify is still a proposal
        warnings.filterwarnings("ignore", "OSQP exited with status", UserWarning)
        solution = qpsolvers.solve_problem(problem, solver="osqp", initvals=start, **_OSQP)
    if solution.x is None or not np.isfinite(solution.x).all():
        return None
    duals = np.split(np.maximum(solution.z, 0.0), np.cumsum([k.sum() for k in keep])[:-1])
    return solution.x[:r] * scale, duals


def _may_be_least(group: Group, reach: np.ndarray) -> np.ndarray:
    """Which pieces can be the group's minimum somewhere in the box |delta_i| <= reach_i."""
    change = np.abs(group.jacobian) @ reach
    return group.values - change <= (group.values + change).min()


def _scale(slopes: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """Per variable, OSQP solves for u = delta / scale, scale = sqrt(reach / largest slope):
    the box of u and the rows' entries then have the same size, sqrt(reach * slope).
    Slopes and trust radii far from 1 (a flat optimum, a fold, a tiny late step) otherwise
    stall its ADMM iteration. Slopes below _FLAT are rounding (a joint that the self-motion
    does not move, like the elbow of an S-R-S arm): then scale = reach."""
    largest = np.abs(slopes).max(axis=0)
    scale = np.where(largest > _FLAT, np.sqrt(reach / np.maximum(largest, _FLAT)), reach)
    return np.where(scale > 0.0, scale, 1.0)


def _problem(
    groups: list[Group],
    keep: list[np.ndarray],
    curvature: np.ndarray,
    scale: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
) -> qpsolvers.Problem:
    """The QP in x = (u, t): minimise 1/2 u^T S B S u - sum_g w_g t_g subject to
    t_g - a_j^T S u <= v_j for the kept pieces, the box of u, floor_g <= t_g <= cap_g."""
    n_groups = len(groups)
    rows = [
        np.hstack([-g.jacobian[k] * scale, np.tile(np.eye(n_groups)[i], (k.sum(), 1))])
        for i, (g, k) in enumerate(zip(groups, keep, strict=True))
    ]
    P = sp.block_diag([curvature * np.outer(scale, scale), np.zeros((n_groups, n_groups))], format="csc")
    return qpsolvers.Problem(
        P,
        np.concatenate([np.zeros(len(scale)), [-g.weight for g in groups]]),
        sp.csc_matrix(np.vstack(rows)),
        np.concatenate([g.values[k] for g, k in zip(groups, keep, strict=True)]),
        lb=np.concatenate([lower / scale, [g.floor for g in groups]]),
        ub=np.concatenate([upper / scale, [g.cap for g in groups]]),
    )


def _model(groups: list[Group], delta: np.ndarray) -> float:
    """The linearised objective sum_g w_g min(cap_g, min_j (v_j + a_j delta))."""
    return sum(g.weight * min(g.cap, float((g.values + g.jacobian @ delta).min())) for g in groups)


def _bfgs(B: np.ndarray, s: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Damped (Powell) BFGS update of B, kept positive definite."""
    Bs = B @ s
    sBs = s @ Bs
    if sBs <= 1e-300:
        return B
    sy = s @ y
    if sy < 0.2 * sBs:
        theta = 0.8 * sBs / (sBs - sy)
        y, sy = theta * y + (1.0 - theta) * Bs, 0.2 * sBs
    return B - np.outer(Bs, Bs) / sBs + np.outer(y, y) / sy


def maximise(
    probe: Probe, start: Point, lower: float, upper: float, radius: float, scalar: bool = True
) -> Point:
    """Climb from a feasible point to a local maximum of f within [lower, upper].

    The trust radius Delta is also kept below ``_JOINT_STEP / max_i sum_c |dq_i/dpsi_c|``,
    so that no step moves a joint by more than 0.25 rad to first order (near a fold of the
    solution path dq/dpsi is large and the linearisation holds only briefly).

    Args:
        probe: Exact solutions on the branch at the pose.
        start: A feasible point; every step continues from the current one.
        lower, upper: Bounds of psi (the feasible interval).
        radius: First trust radius (rad).
        scalar: With one variable, the climb in floats (:func:`_maximise_1d`, the same
            operations); False: the general one on arrays, the reference it is tested against.

    Returns:
        The best feasible point found.
    """
    if not start.groups:  # nothing to maximise: f is constant
        return start
    if scalar and np.ndim(start.psi) == 0:
        return _maximise_1d(probe, start, lower, upper, radius)
    point, x = start, np.atleast_1d(start.psi).astype(float)
    B = _INITIAL_CURVATURE * np.eye(len(x))
    for _ in range(_MAX_CLIMB):
        radius = min(radius, _JOINT_STEP / max(float(np.abs(point.tangent).sum(axis=1).max()), 1e-12))
        if radius <= STEP_TOLERANCE:
            break
        lo = np.minimum(np.maximum(lower - x, -radius), 0.0)
        step = qp_step(point.groups, B, lo, np.maximum(np.minimum(upper - x, radius), 0.0))
        if step is None or np.abs(step.delta).max() <= STEP_TOLERANCE or step.gain <= GAIN_TOLERANCE:
            break
        size = np.abs(step.delta).max()
        trial = probe.next(point, _angle(x + step.delta))
        gain = trial.evaluation.value - point.evaluation.value if trial is not None else -math.inf
        if trial is None or not trial.evaluation.feasible or gain < _ACCEPT * step.gain:
            radius = size / 4.0
            continue
        y = -sum(
            z @ (new.jacobian - old.jacobian)
            for z, old, new in zip(step.multipliers, point.groups, trial.groups, strict=True)
        )
        B = _bfgs(B, step.delta, y)
        if gain > 0.75 * step.gain and size >= 0.9 * radius:
            radius *= 2.0
        point, x = trial, x + step.delta
    return replace(point, psi=_angle(x))


def _maximise_1d(probe: Probe, start: Point, lower: float, upper: float, radius: float) -> Point:
    """:func:`maximise` with one variable: psi, the step, B and the BFGS update as floats,
    the pieces of a point concatenated once (:class:`~om_redundant.redundancy.box_qp.Pieces`),
    each operation the general loop's, so that the climb is the same to the last bit."""
    point, x, b = start, float(start.psi), _INITIAL_CURVATURE
    pieces = Pieces.of(point.groups)
    for _ in range(_MAX_CLIMB):
        radius = min(radius, _JOINT_STEP / max(float(np.abs(point.tangent).max()), 1e-12))
        if radius <= STEP_TOLERANCE:
            break
        found = step_1d(pieces, b, min(max(lower - x, -radius), 0.0), max(min(upper - x, radius), 0.0))
        if found is None or abs(found[0]) <= STEP_TOLERANCE or found[1] <= GAIN_TOLERANCE:
            break
        delta, model_gain, z = found
        size = abs(delta)
        trial = probe.next(point, x + delta)
        gain = trial.evaluation.value - point.evaluation.value if trial is not None else -math.inf
        if trial is None or not trial.evaluation.feasible or gain < _ACCEPT * model_gain:
            radius = size / 4.0
            continue
        moved = pieces.at(trial.groups)
        rise = moved.rates - pieces.rates  # y = -sum_j z_j (a_j^new - a_j^old), group by group
        y = -sum(z_g @ rise_g for z_g, rise_g in zip(pieces.split(z), pieces.split(rise), strict=True))
        b = _bfgs_1d(b, delta, y)
        if gain > 0.75 * model_gain and size >= 0.9 * radius:
            radius *= 2.0
        point, x, pieces = trial, x + delta, moved
    return point.at(x)


def _bfgs_1d(b: float, s: float, y: float) -> float:
    """:func:`_bfgs` of a 1 x 1 B, in its operations."""
    bs = b * s
    sbs = s * bs
    if sbs <= 1e-300:
        return b
    sy = s * y
    if sy < 0.2 * sbs:
        theta = 0.8 * sbs / (sbs - sy)
        y, sy = theta * y + (1.0 - theta) * bs, 0.2 * sbs
    return b - bs * bs / sbs + y * y / sy


def _angle(x: np.ndarray) -> float | np.ndarray:
    return float(x[0]) if len(x) == 1 else x
