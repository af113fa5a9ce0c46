"""The bounds of a climb's start in numpy (``start_bounds.StartBounds.cone`` and ``within``): the
oracle of ``_core.start_cones`` and ``_core.start_bound`` (``csrc/redundancy/start_bounds.c``, the same
operations in loops)."""

from __future__ import annotations

import bisect
import math

import numpy as np

from om_redundant.redundancy.choice.start_bounds import StartBounds


def bound(bounds: StartBounds, values: np.ndarray) -> np.ndarray:
    """(N,) the smaller of f's bound and sum_g w_g min(cap_g, min_j bound_j), from bounds
    (N, 1 + n) of f and of each group's functions, the groups summed in their order."""
    if not len(bounds._weights):  # no terms: f = 0
        return np.minimum(values[:, 0], 0.0)
    least = np.minimum.reduceat(values, bounds._groups, axis=1)
    terms = bounds._weights * np.minimum(bounds._caps, least)
    total = 0.0
    for column in terms.T:
        total = total + column
    return np.minimum(values[:, 0], total)


def cone(bounds: StartBounds, k: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """:meth:`StartBounds.cone`: (K,) the bounds of starts k from their own cones with reach R."""
    return bound(bounds, bounds._values[k] + bounds._slopes[k] * reach[:, None])


def within(bounds: StartBounds, k: int, reach: float) -> float:
    """:meth:`StartBounds.within` of start k with reach R (its docstring), from the samples'
    arrays of ``bounds``."""
    a, b = int(bounds.first[k]), int(bounds.last[k])
    values, slopes, psi = bounds._values, bounds._slopes[k], bounds.psi  # (its run's)
    at = psi.tolist()
    x = at[k]
    lo = bisect.bisect_left(at, x - reach, a, b + 1)  # the samples within reach: lo..hi
    hi = bisect.bisect_right(at, x + reach, a, b + 1) - 1
    cells = np.arange(lo - 1 if lo > a else lo, hi + 1 if hi < b else hi)  # whole and cut
    u, v, h = values[cells], values[cells + 1], psi[cells + 1] - psi[cells]
    peaks = np.maximum(0.5 * (u + v + slopes * h[:, None]), np.maximum(u, v))
    ends = np.array([lo, hi])
    left = np.maximum(reach - np.abs(psi[ends] - x), 0.0)
    found = bound(bounds, np.vstack([peaks, values[ends] + slopes * left[:, None]]))
    bounded = np.full(hi - lo + 2, math.inf)  # the cut cells', then the whole ones
    bounded[int(lo == a) : len(cells) + int(lo == a)] = found[: len(cells)]
    cut = np.minimum(bounded[[0, -1]], found[len(cells) :])
    whole = bounded[1:-1].max(initial=-math.inf)
    return float(np.max([whole, cut.max(), values[k, 0]]))  # (NaN if any is: numpy's max)
