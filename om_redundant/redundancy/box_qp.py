r"""The climb's QP (:mod:`om_redundant.redundancy.climb`) in one redundancy variable, solved exactly.

With one variable the epigraph QP is the maximisation of the concave, piecewise quadratic

.. math::  \phi(\delta) = \sum_g w_g \min\big(cap_g,\ \min_{j \in g} v_j + a_j\delta\big)
           - \tfrac12 b\,\delta^2

over the interval where every group with a floor keeps :math:`\min_j v_j + a_j\delta \ge
floor_g`, within the box [lower, upper]. Between its breakpoints (two pieces of a group
crossing, a piece crossing its group's cap) phi is one quadratic, with slope
:math:`D_k - b\delta` (:math:`D_k` the weighted rates of the uncapped groups' least pieces),
so the maximiser is a breakpoint, an end, or a segment's stationary point :math:`D_k/b`:
all of them are evaluated at once and the best taken. The multipliers of the pieces are
those of the epigraph's KKT conditions: each uncapped group's weight on its least piece, or
at a kink split between the least and the most increasing of the pieces that meet there so
that the slope balances :math:`b\delta`.
"""

from __future__ import annotations

import itertools

import numpy as np

from .. import _core
from .objective import Group

_TIE = 1e-12  # pieces within this of their group's minimum meet there


class Pieces(_core.Pieces):
    """Groups of one variable concatenated, as ``_core.maximise_1d`` reads them
    (``_core.Pieces``: values, rates, ends, weights, floors, caps), with what the climb does
    with them."""

    __slots__ = ()

    @classmethod
    def of(cls, groups: list[Group]) -> Pieces:
        """The pieces of groups with jacobians (p_g, 1)."""
        ends = np.cumsum([0] + [len(g.values) for g in groups], dtype=np.int64)
        numbers = np.array([(g.weight, g.floor, g.cap) for g in groups], dtype=float).T.copy()
        return cls(*_values_and_rates(groups), ends, *numbers)

    def at(self, groups: list[Group]) -> Pieces:
        """The pieces of groups of the same sizes, weights, floors and caps as these (the same
        objective's at another point), which share these' ends and numbers."""
        values, rates = _values_and_rates(groups)
        if len(values) != self.ends[-1]:
            raise ValueError(f"{len(values)} pieces where these groups have {self.ends[-1]}")
        return self._replace(values=values, rates=rates)

    def least(self, values: np.ndarray) -> np.ndarray:
        """(G,) each group's smallest of ``values`` (n,), one per piece."""
        return np.minimum.reduceat(values, self.ends[:-1])

    def model(self, delta: float) -> float:
        """The linearised objective sum_g w_g min(cap_g, min_j (v_j + a_j delta)), summed
        in the groups' order."""
        terms = self.weights * np.minimum(self.caps, self.least(self.values + self.rates * delta))
        return sum(terms.tolist())

    def kept(self, keep: np.ndarray) -> Pieces:
        """The pieces where ``keep`` (n,) holds, at least one per group."""
        ends = np.concatenate([[0], np.cumsum(keep)[self.ends[1:] - 1]]).astype(np.int64)
        return self._replace(values=self.values[keep], rates=self.rates[keep], ends=ends)

    def split(self, z: np.ndarray) -> list[np.ndarray]:
        """(n,) per piece into one array per group (views)."""
        return [z[a:b] for a, b in itertools.pairwise(self.ends.tolist())]


def solve_1d(pieces: Pieces, curvature: float, lower: float, upper: float) -> tuple[float, np.ndarray] | None:
    """:func:`maximise_1d` of the pieces by ``_core.maximise_1d``: (delta, the pieces'
    multipliers (n,)), or None when the floors leave no delta."""
    z = np.empty(len(pieces.values))
    delta = _core.maximise_1d(pieces, curvature, lower, upper, z)
    return None if delta is None else (delta, z)


def _values_and_rates(groups: list[Group]) -> tuple[np.ndarray, np.ndarray]:
    """The groups' pieces v_j and rates a_j (jacobians (p_g, 1)), concatenated."""
    return np.concatenate([g.values for g in groups]), np.concatenate([g.jacobian[:, 0] for g in groups])


def step_1d(
    pieces: Pieces, curvature: float, lower: float, upper: float, compiled: bool = True
) -> tuple[float, float, np.ndarray] | None:
    r"""The climb's QP step in one variable (:func:`~om_redundant.redundancy.climb.qp_step`):
    the pieces that can be their group's minimum somewhere in the box, :math:`v_j - |a_j| r
    \le \min_{i \in g} v_i + |a_i| r` with r = max(-lower, upper) (the others' constraints
    are implied by the minimum's), maximised as by :func:`maximise_1d`.

    Args:
        pieces: The groups' pieces.
        curvature: b > 0.
        lower, upper: Bounds of delta, lower <= 0 <= upper.
        compiled: By ``_core.step_1d`` (``csrc/box_qp.c``, the same operations); False:
            numpy, the reference it is tested against.

    Returns:
        (delta, the model's gain ``model(delta) - b delta^2 / 2 - model(0)`` (:meth:`Pieces.model`),
        every piece's multiplier (n,), 0 for those left out), or None when the floors leave
        no delta.
    """
    if compiled:
        z = np.empty(len(pieces.values))
        found = _core.step_1d(pieces, curvature, lower, upper, z)
        return None if found is None else (found.delta, found.gain, z)
    reach = max(-lower, upper)
    change = np.abs(pieces.rates) * reach
    least = pieces.least(pieces.values + change)
    keep = pieces.values - change <= np.repeat(least, np.diff(pieces.ends))
    found = solve_1d(pieces.kept(keep), curvature, lower, upper)
    if found is None:
        return None
    delta, z = found
    gain = pieces.model(delta) - 0.5 * delta * curvature * delta - pieces.model(0.0)
    multipliers = np.zeros(len(keep))
    multipliers[keep] = z
    return delta, gain, multipliers


def maximise_1d(
    groups: list[Group], curvature: float, lower: float, upper: float, compiled: bool = True
) -> tuple[float, list[np.ndarray]] | None:
    """The maximiser delta of phi (module docstring) and each group's multipliers.

    Args:
        groups: Groups with jacobians (p_g, 1) by the redundancy variable, each with a piece.
        curvature: b > 0.
        lower, upper: Bounds of delta, lower <= 0 <= upper.
        compiled: By ``_core.maximise_1d`` (``csrc/box_qp.c``, the same operations;
            :func:`solve_1d`); False: numpy, the reference it is tested against.

    Returns:
        (delta, multipliers per group), or None when the floors leave no delta.
    """
    if compiled:
        pieces = Pieces.of(groups)
        found = solve_1d(pieces, curvature, lower, upper)
        return None if found is None else (found[0], pieces.split(found[1]))
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
    least = values.argmin(axis=1)
    return np.where(values[np.arange(len(at)), least] < group.cap, a[least], 0.0)


def _multipliers(
    groups: list[Group], v: list[np.ndarray], a: list[np.ndarray], curvature: float, delta: float
) -> list[np.ndarray]:
    """Each piece's multiplier at delta (module docstring)."""
    multipliers = [np.zeros(len(vg)) for vg in v]
    kinks, balance = [], curvature * delta
    for g, vg, ag, z in zip(groups, v, a, multipliers, strict=True):
        values = vg + ag * delta
        least = values.min()
        if least > g.cap + _TIE or g.weight == 0.0:
            continue
        meeting = np.flatnonzero(values <= least + _TIE)
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
