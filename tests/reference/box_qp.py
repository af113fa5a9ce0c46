r"""The QP in one variable in numpy (:mod:`om_redundant.redundancy.choice.box_qp`), solved another
way than ``_core.step_1d`` (``csrc/redundancy/box_qp.c``, a bisection on phi's slope): between its
breakpoints (two pieces of a group crossing, a piece crossing its group's cap) phi is one
quadratic, with slope :math:`D_k - b\delta` (:math:`D_k` the weighted rates of the uncapped
groups' least pieces), so the maximiser is a breakpoint, an end, or a segment's stationary point
:math:`D_k/b`: all of them are evaluated and the best taken. Over every piece (the kernel's
leaves out those that cannot be least in the box)."""

from __future__ import annotations

import numpy as np

from om_redundant.redundancy.choice.box_qp import Pieces
from tests.reference.objective import Group

_TIE = 1e-12  # pieces within this of their group's minimum meet there


def concatenated(groups: list[Group]) -> Pieces:
    """The pieces of groups with jacobians (p_g, 1), as the climb's QP reads them."""
    ends = np.cumsum([0] + [len(g.values) for g in groups], dtype=np.int64)
    weights, floors, caps = np.array([(g.weight, g.floor, g.cap) for g in groups], dtype=float).T.copy()
    values = np.concatenate([g.values for g in groups])
    rates = np.concatenate([g.jacobian[:, 0] for g in groups])
    return Pieces(values, rates, ends, weights, floors, caps)


def least(pieces: Pieces, values: np.ndarray) -> np.ndarray:
    """(G,) each group's smallest of ``values`` (n,), one per piece."""
    return np.minimum.reduceat(values, pieces.ends[:-1])


def model(pieces: Pieces, delta: float) -> float:
    """The linearised objective sum_g w_g min(cap_g, min_j (v_j + a_j delta)), summed in the
    groups' order."""
    terms = pieces.weights * np.minimum(pieces.caps, least(pieces, pieces.values + pieces.rates * delta))
    return sum(terms.tolist())


def step_1d(
    pieces: Pieces, curvature: float, lower: float, upper: float
) -> tuple[float, float, np.ndarray] | None:
    """:func:`om_redundant.redundancy.choice.box_qp.step_1d` by the breakpoints: delta, the
    model's gain, every piece's multiplier; None when the floors leave no delta."""
    bounds = zip(pieces.ends[:-1].tolist(), pieces.ends[1:].tolist(), strict=True)
    numbers = zip(pieces.weights.tolist(), pieces.floors.tolist(), pieces.caps.tolist(), strict=True)
    groups = [
        Group("", w, floor, cap, pieces.values[a:b], pieces.rates[a:b, None])
        for (a, b), (w, floor, cap) in zip(bounds, numbers, strict=True)
    ]
    found = maximise_1d(groups, curvature, lower, upper)
    if found is None:
        return None
    delta, z = found
    gain = model(pieces, delta) - 0.5 * delta * curvature * delta - model(pieces, 0.0)
    return delta, gain, np.concatenate(z)


def maximise_1d(
    groups: list[Group], curvature: float, lower: float, upper: float
) -> tuple[float, list[np.ndarray]] | None:
    """The maximiser delta of phi (:mod:`om_redundant.redundancy.choice.box_qp`) and each group's
    multipliers, or None when the floors leave no delta.

    Args:
        groups: Groups with jacobians (p_g, 1) by the redundancy variable, each with a piece.
        curvature: b > 0.
        lower, upper: Bounds of delta, lower <= 0 <= upper.
    """
    v = [g.values for g in groups]
    a = [g.jacobian[:, 0] for g in groups]
    lo, hi = lower, upper
    for g, vg, ag in zip(groups, v, a, strict=True):
        if g.floor == -np.inf:
            continue
        gap = g.floor - vg
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = gap / ag
        if (gap[ag == 0.0] > 0.0).any():
            return None
        lo = max(lo, float(bound[ag > 0.0].max(initial=-np.inf)))
        hi = min(hi, float(bound[ag < 0.0].min(initial=np.inf)))
    if not lo <= hi:
        return None
    points = [np.array([lo, hi])]
    for g, vg, ag in zip(groups, v, a, strict=True):
        with np.errstate(divide="ignore", invalid="ignore"):
            crossings = (vg[None, :] - vg[:, None]) / (ag[:, None] - ag[None, :])
            points += [crossings.ravel(), (g.cap - vg) / ag]
    points = np.concatenate(points)
    points = np.unique(points[np.isfinite(points) & (points >= lo) & (points <= hi)])
    middles = (points[:-1] + points[1:]) / 2.0
    slopes = sum(
        (g.weight * _least_rate(g, vg, ag, middles) for g, vg, ag in zip(groups, v, a, strict=True)),
        start=np.zeros(len(middles)),
    )
    stationary = np.clip(slopes / curvature, points[:-1], points[1:])
    candidates = np.concatenate([points, stationary])
    values = sum(
        (
            g.weight * np.minimum(g.cap, (vg[None, :] + ag[None, :] * candidates[:, None]).min(axis=1))
            for g, vg, ag in zip(groups, v, a, strict=True)
        ),
        start=-0.5 * curvature * candidates**2,
    )
    delta = float(candidates[np.argmax(values)])
    return delta, _multipliers(groups, v, a, curvature, delta)


def _least_rate(group: Group, v: np.ndarray, a: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The rate of the group's term at each point of ``at`` (inside a segment): its least
    piece's rate, 0 where the term is capped."""
    values = v[None, :] + a[None, :] * at[:, None]
    lowest = values.argmin(axis=1)
    return np.where(values[np.arange(len(at)), lowest] < group.cap, a[lowest], 0.0)


def _multipliers(
    groups: list[Group], v: list[np.ndarray], a: list[np.ndarray], curvature: float, delta: float
) -> list[np.ndarray]:
    """Each piece's multiplier at delta (:mod:`om_redundant.redundancy.choice.box_qp`)."""
    multipliers = [np.zeros(len(vg)) for vg in v]
    kinks, balance = [], curvature * delta
    for g, vg, ag, z in zip(groups, v, a, multipliers, strict=True):
        values = vg + ag * delta
        lowest = values.min()
        if lowest > g.cap + _TIE or g.weight == 0.0:
            continue
        meeting = np.flatnonzero(values <= lowest + _TIE)
        if len(meeting) == 1:
            z[meeting[0]] = g.weight
            balance -= g.weight * ag[meeting[0]]
        else:
            kinks.append((g.weight, ag, z, meeting[np.argmin(ag[meeting])], meeting[np.argmax(ag[meeting])]))
    for weight, ag, z, falling, rising in kinks:  # z_f a_f + z_r a_r = balance share, z_f + z_r = w
        spread = ag[rising] - ag[falling]
        share = balance / len(kinks)
        z[rising] = min(max((share - weight * ag[falling]) / spread, 0.0), weight) if spread > 0.0 else weight
        z[falling] = weight - z[rising]
    return multipliers
