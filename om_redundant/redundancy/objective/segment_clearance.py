r"""The clearance along a straight joint-space segment, certified by a Lipschitz bound
(:meth:`Clearance.minimum_along <om_redundant.Clearance.minimum_along>`)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

#: m: :func:`segment_minimum` stops splitting a piece whose bound is this close to its ends'.
ALONG_TOLERANCE = 2e-4


def segment_minimum(
    distances: Callable[[np.ndarray], np.ndarray],
    q_from: np.ndarray,
    q_to: np.ndarray,
    lipschitz: float,
    floor: float,
    budget: float,
) -> float:
    r"""The clearance along the segment from q_from to q_to as far as it matters against
    ``floor``: pieces of the segment whose bound :math:`(D_0 + D_1 - L h) / 2` is below
    ``floor`` are halved, a round at a time, until an end falls below it or a piece is within
    :data:`ALONG_TOLERANCE` of its ends (the returns of :meth:`Clearance.minimum_along
    <om_redundant.Clearance.minimum_along>`).

    Args:
        distances: The pair distances (M, pairs) of joint vectors (M, dof).
        q_from, q_to: The segment's ends (dof,).
        lipschitz: L, the most any distance changes over the whole segment.
        floor: The clearance (m) it is checked against.
        budget: The most joint vectors sampled inside the segment (inf: no limit).
    """
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
