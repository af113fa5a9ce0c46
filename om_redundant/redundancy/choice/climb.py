r"""The climb: a trust-region SQP that maximises the objective over the arm angle.

From a feasible exact solution q(psi) on a branch, every piece v_j of every group g of the
objective (:mod:`om_redundant.redundancy.objective.objective`) is linearised through the self-motion tangent
dq/dpsi (:func:`self_motion_tangent`), :math:`v_j(\psi + \delta) \approx v_j + a_j\delta`,
and the QP

.. math::  \max_{\delta, t}\ \sum_g w_g t_g - \tfrac12 b\,\delta^2
           \quad\text{s.t.}\quad t_g \le v_j + a_j\delta\ (j \in g),\quad
           \mathrm{floor}_g \le t_g \le \mathrm{cap}_g,\quad
           |\delta| \le \Delta,\quad lo \le \psi + \delta \le hi

(the epigraph form of the max-min objective; the floors keep the linearised margins >= 0
and clearances >= d_min) is solved exactly in its one variable
(:func:`~om_redundant.redundancy.choice.box_qp.step_1d`, ``csrc/redundancy/box_qp.c``). b is a damped BFGS
estimate of the curvature of the Lagrangian, from the QP's multipliers z_j:
:math:`s = \delta`, :math:`y = -\sum_j z_j (a_j^{new} - a_j^{old})`. The step is solved
exactly (the current q as hint); it is accepted when the exact point is feasible and gains
at least a tenth of the model's gain :math:`\sum_g w_g \min(cap_g, \min_j (v_j + a_j\delta))
- \tfrac12 b\delta^2 - f`; the trust radius Delta then doubles (a good full step) or
otherwise shrinks to a quarter of the step. The climb stops when the step or the model's
gain vanishes. It runs on Python floats, one compiled call per QP. (One variable: the
optimiser takes arms with one redundancy variable, :class:`~om_redundant.RedundancyOptimizer`.)
"""

from __future__ import annotations

import math

import numpy as np

from ..paths.points import Point
from ..paths.probe import Probe
from .box_qp import Pieces, step_1d

STEP_TOLERANCE = 1e-9  # rad: the climb stops when the step is this small
GAIN_TOLERANCE = 1e-12  # the climb stops when the model promises no more
_MAX_CLIMB = 60  # QPs per climb
_ACCEPT = 0.1  # accepted steps gain this fraction of the model's gain
_INITIAL_CURVATURE = 0.1  # b at the first QP of a climb
_JOINT_STEP = 0.25  # rad: the trust radius keeps the linearised joint motion within this
_FOLD_TRIALS = 10  # golden-section trials in a path's end cell (its bracket 0.618^9 ~ 1.3 % of the cell in s)
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def maximise(probe: Probe, start: Point, lower: float, upper: float, radius: float) -> Point:
    """Climb from a feasible point to a local maximum of f within [lower, upper].

    The trust radius Delta is also kept below ``_JOINT_STEP / max_i |dq_i/dpsi|``, so that no
    step moves a joint by more than 0.25 rad to first order (near a fold of the solution path
    dq/dpsi is large and the linearisation holds only briefly). A point's pieces come
    concatenated from one compiled call (:class:`~om_redundant.redundancy.choice.box_qp.Pieces`).

    Args:
        probe: Exact solutions on the branch at the pose.
        start: A feasible point; every step continues from the current one.
        lower, upper: Bounds of psi (the feasible interval).
        radius: First trust radius (rad).

    Returns:
        The best feasible point found.
    """
    if not len(probe.objective.layout.weights):  # nothing to maximise: f is constant
        return start
    point, x, b = start, float(start.psi), _INITIAL_CURVATURE
    pieces = Pieces.at(point)
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
        moved = Pieces.at(trial)
        y = -float(z @ (moved.rates - pieces.rates))  # y = -sum_j z_j (a_j^new - a_j^old)
        b = _bfgs(b, delta, y)
        if gain > 0.75 * model_gain and size >= 0.9 * radius:
            radius *= 2.0
        point, x, pieces = trial, x + delta, moved
    return point.at(x)


def maximise_from_path_end(probe: Probe, end: Point, neighbour: Point, lower: float, upper: float) -> Point:
    r"""The best point found in a path's end cell: from ``end``, where the path ends (a fold,
    where it turns back in psi, or the branch's or the reach's edge), to its neighbour sample.

    At a fold :math:`q - q_f \sim (\psi - \psi_f)^{1/2}`: no follow leaves the end, so
    :func:`maximise` cannot, and its model along psi, whose rates are about 1e4-1e10 there,
    fails within the cell (a climb from inside it that steps onto the end, gaining, is
    stuck there). The path is smooth in :math:`s = ((\psi - \psi_e) / (\psi_n - \psi_e))^{1/2}`
    instead. Where the end's model promises a gain into the cell (the sign of its rates, which
    its tangent gives), a golden-section search over s in [0, 1], its trials followed from the
    neighbour (the one sheet between them), brackets the best to :data:`_FOLD_TRIALS` trials,
    and :func:`maximise` climbs from the best trial within its bracket, where the end, worse
    than that trial, is never taken.

    Args:
        probe: Exact solutions on the branch at the pose.
        end, neighbour: The path's end sample and the next, both feasible.
        lower, upper: Bounds of psi (the feasible interval).

    Returns:
        The best feasible point found: ``end`` where nothing in the cell beats it.
    """
    span = neighbour.psi - end.psi
    into = step_1d(Pieces.at(end), _INITIAL_CURVATURE, min(span, 0.0), max(span, 0.0))
    if into is None or into[1] <= GAIN_TOLERANCE:
        return end

    def trial(s: float) -> tuple[Point, float]:
        point, arrived = probe.follow(neighbour, end.psi + span * s * s)
        return point, point.evaluation.value if arrived and point.evaluation.feasible else -math.inf

    a, b = 0.0, 1.0  # the bracket in s, and its inner trials c < d
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    (pc, fc), (pd, fd) = trial(c), trial(d)
    for _ in range(_FOLD_TRIALS - 2):
        if fc >= fd:
            b, d, pd, fd = d, c, pc, fc
            c = b - _GOLDEN * (b - a)
            pc, fc = trial(c)
        else:
            a, c, pc, fc = c, d, pd, fd
            d = a + _GOLDEN * (b - a)
            pd, fd = trial(d)
    best, value = (pc, fc) if fc >= fd else (pd, fd)
    if value <= end.evaluation.value:
        return end
    lo, hi = sorted((end.psi + span * a * a, end.psi + span * b * b))
    return maximise(probe, best, max(lo, lower), min(hi, upper), hi - lo)


def _bfgs(b: float, s: float, y: float) -> float:
    """Damped (Powell) BFGS update of the curvature b, kept positive."""
    bs = b * s
    sbs = s * bs
    if sbs <= 1e-300:
        return b
    sy = s * y
    if sy < 0.2 * sbs:
        theta = 0.8 * sbs / (sbs - sy)
        y, sy = theta * y + (1.0 - theta) * bs, 0.2 * sbs
    return b - bs * bs / sbs + y * y / sy
