"""The objective's terms from its groups (:class:`~om_redundant.redundancy.objective.objective.Group`): the
oracle of ``_core.evaluate`` (``csrc/redundancy/objective.c``), which computes f and the slack at once."""

from __future__ import annotations

from om_redundant.redundancy.objective.terms import Group


def term(group: Group) -> float:
    """The group's term of f: ``weight * min(cap, min_j values_j)``."""
    return group.weight * min(group.cap, float(group.values.min()))


def slack(group: Group) -> float:
    """The group's feasibility slack: ``min_j values_j - floor`` (>= 0 where feasible)."""
    return float(group.values.min()) - group.floor
