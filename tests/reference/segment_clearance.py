"""The clearance along a joint-space segment in numpy (``segment_clearance.segment_minimum``):
the oracle of ``_core.segment_minimum`` (``csrc/redundancy/segment_clearance.c``, the same
operations in loops), its distances those of a :class:`~om_redundant.Clearance`."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from om_redundant.redundancy.objective.segment_clearance import ALONG_TOLERANCE


def segment_minimum(
    distances: Callable[[np.ndarray], np.ndarray],
    q_from: np.ndarray,
    q_to: np.ndarray,
    lipschitz: float,
    floor: float,
    budget: float,
) -> float:
    """The reference: the pairs' distances (M, pairs) of joint vectors (M, dof) from
    ``distances``, the pieces halved a round at a time (the rule of the compiled one)."""
    ends = distances(np.array([q_from, q_to])).min(axis=1)
    pieces = [(0.0, 1.0, ends[0], ends[1])]
    least = math.inf
    while pieces:
        lowest = min(min(d0, d1) for _, _, d0, d1 in pieces)
        if lowest < floor:
            return lowest
        split = []
        for t0, t1, d0, d1 in pieces:
            bound = 0.5 * (d0 + d1 - lipschitz * (t1 - t0))
            if bound >= floor or lipschitz * (t1 - t0) <= ALONG_TOLERANCE:
                least = min(least, bound)
            else:
                split.append((t0, t1, d0, d1))
        if not split:
            break
        if len(split) > budget:
            return math.nan
        budget -= len(split)
        t = np.array([0.5 * (t0 + t1) for t0, t1, _, _ in split])
        middle = distances(q_from + t[:, None] * (q_to - q_from)).min(axis=1).tolist()
        pieces = [
            piece
            for (t0, t1, d0, d1), tm, dm in zip(split, t.tolist(), middle, strict=True)
            for piece in ((t0, tm, d0, dm), (tm, t1, dm, d1))
        ]
    return least
