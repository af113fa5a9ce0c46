"""The objective's groups in numpy (:class:`~om_redundant.redundancy.objective.objective.Objective`'s
module docstring): the oracle of what the compiled kernels compute from them, ``_core.evaluate``
(f and the slack at once), ``_core.pieces`` (the feasibility functions along the self-motion) and
``_core.linearise`` (the pieces and their rates that the climb's QP reads)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from om_redundant.redundancy.objective.objective import Objective
from om_redundant.redundancy.objective.terms import SINGULARITY_CAP, limit_distances


@dataclass(slots=True)
class Group:
    """One term of the objective: ``weight * min(cap, min_j values_j)``, feasible if
    ``min_j values_j >= floor``.

    Attributes:
        kind: ``"margin"``, ``"clearance"`` or ``"singularity"``.
        weight: w >= 0.
        floor: Feasibility bound on the minimum; -inf for none (no constraint).
        cap: Upper cap of the term (inf for none).
        values: (p,) the pieces v_j.
        jacobian: (p, n) their derivatives by n variables (q, or the redundancy variables),
            or None when not asked for.
    """

    kind: str
    weight: float
    floor: float
    cap: float
    values: np.ndarray
    jacobian: np.ndarray | None = None

    def constraints(self) -> tuple[np.ndarray, np.ndarray]:
        """The group's feasibility functions, >= 0 where feasible, and their derivatives
        (by the first variable of the jacobian). A joint's two margin pieces count as one
        function, the smaller: 1 - |q_i - c_i| / h_i about mid-range c_i, continuous also
        where a revolute joint's angle is taken modulo 2 pi at the representative nearest c_i.
        A group without a floor has none.
        """
        if self.floor == -math.inf:
            return np.zeros(0), np.zeros(0)
        v, d = self.values - self.floor, self.jacobian[:, 0]
        if self.kind != "margin":
            return v, d
        half = len(v) // 2
        lower = v[:half] <= v[half:]
        return np.where(lower, v[:half], v[half:]), np.where(lower, d[:half], d[half:])


def term(group: Group) -> float:
    """The group's term of f: ``weight * min(cap, min_j values_j)``."""
    return group.weight * min(group.cap, float(group.values.min()))


def slack(group: Group) -> float:
    """The group's feasibility slack: ``min_j values_j - floor`` (>= 0 where feasible)."""
    return float(group.values.min()) - group.floor


def groups(
    objective: Objective,
    q: np.ndarray,
    jacobian: bool = False,
    pairs: tuple[np.ndarray, np.ndarray] | None = None,
    tangent: np.ndarray | None = None,
) -> list[Group]:
    """The objective's groups at q: margin (if any joint is limited), clearance (if there are
    obstacles), then singularity (if it has the term); their jacobians by q if asked.

    Args:
        objective: The objective.
        q: (dof,) joint vector.
        jacobian: Also the jacobians.
        pairs: The clearance's pair distances (P,) and gradients (P, dof) at q if already
            computed (``Objective.pairs`` or ``Clearance.distances_and_gradients``): the same
            groups from them.
        tangent: (dof, r) dq/dpsi at q: the jacobians chained through it, by psi (J_q dq/dpsi;
            implies ``jacobian``).
    """
    jacobian = jacobian or tangent is not None
    found = [_margin(objective, q, jacobian, tangent)] if len(objective._limited) else []
    if objective.clearance is not None:
        found.append(_clearance(objective, q, jacobian, pairs, tangent))
    if objective.singularity is not None:
        weight, source = objective.singularity_weight, objective.singularity
        found.append(_capped("singularity", weight, -math.inf, source, SINGULARITY_CAP, q, jacobian, tangent))
    return found


def _margin(objective: Objective, q: np.ndarray, jacobian: bool, tangent: np.ndarray | None) -> Group:
    o, lim = objective, objective._limited
    pieces = np.concatenate(limit_distances(q[lim], o._lower, o._upper, o._half))
    eye = np.eye(len(q))[lim] / o._half[:, None]
    rates = _chained(np.vstack([eye, -eye]), tangent) if jacobian else None  # (q - l)/h, then (u - q)/h
    return Group("margin", o.margin_weight, 0.0, math.inf, pieces, rates)


def _clearance(
    objective: Objective,
    q: np.ndarray,
    jacobian: bool,
    pairs: tuple[np.ndarray, np.ndarray] | None,
    tangent: np.ndarray | None,
) -> Group:
    """The clearance pieces d_k / d_cap, the pairs at 2 d_cap or farther taken there with zero
    gradient where some pair is nearer; all of them exactly when none is that near."""
    o = objective
    floor, cap, reach = o.min_clearance / o.clearance_cap, o.clearance_cap, o.clearance_reach
    if pairs is not None:
        d, grad = pairs
        if np.minimum.reduce(d) < reach:
            near = d < reach
            d = np.where(near, d, reach)
            grad = np.where(near[:, None], grad, 0.0) if jacobian else None
        rates = _chained(grad / cap, tangent) if jacobian else None
        return Group("clearance", o.clearance_weight, floor, 1.0, d / cap, rates)
    d, grad = o.clearance.distances_within(q, reach, gradient=jacobian)
    if np.minimum.reduce(d) < reach:
        rates = _chained(grad / cap, tangent) if jacobian else None
        return Group("clearance", o.clearance_weight, floor, 1.0, d / cap, rates)
    return _capped("clearance", o.clearance_weight, floor, o.clearance, cap, q, jacobian, tangent)


def _capped(
    kind: str,
    weight: float,
    floor: float,
    source: Any,
    cap: float,
    q: np.ndarray,
    jacobian: bool,
    tangent: np.ndarray | None = None,
) -> Group:
    """The group of distances capped at ``cap``: ``source.distances(q) / cap``, cap 1."""
    if jacobian:
        d, grad = source.distances_and_gradients(q)
        return Group(kind, weight, floor, 1.0, d / cap, _chained(grad / cap, tangent))
    return Group(kind, weight, floor, 1.0, source.distances(q) / cap)


def _chained(jacobian: np.ndarray, tangent: np.ndarray | None) -> np.ndarray:
    """The jacobian by q, or by psi through dq/dpsi = tangent: J_q dq/dpsi."""
    return jacobian if tangent is None else jacobian @ tangent
