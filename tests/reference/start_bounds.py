"""The bound of a climb's start in numpy (``optimizer._StartBounds.within``): the oracle of
``_core.start_bound`` (``csrc/start_bounds.c``, the same operations in loops)."""

from __future__ import annotations

import bisect
import math

import numpy as np

from om_redundant.redundancy.optimizer import _StartBounds


def within(bounds: _StartBounds, k: int, reach: float) -> float:
    """:meth:`_StartBounds.within` of start k with reach R (its docstring), from the samples'
    arrays of ``bounds``."""
    a, b = int(bounds.first[k]), int(bounds.last[k])
    values, slopes, psi = bounds._values, bounds._slopes, bounds.psi
    at = psi.tolist()
    x = at[k]
    lo = bisect.bisect_left(at, x - reach, a, b + 1)  # the samples within reach: lo..hi
    hi = bisect.bisect_right(at, x + reach, a, b + 1) - 1
    cells = np.arange(lo - 1 if lo > a else lo, hi + 1 if hi < b else hi)  # whole and cut
    u, v, h = values[cells], values[cells + 1], psi[cells + 1] - psi[cells]
    peaks = np.maximum(0.5 * (u + v + slopes * h[:, None]), np.maximum(u, v))
    ends = np.array([lo, hi])
    left = np.maximum(reach - np.abs(psi[ends] - x), 0.0)
    found = bounds._bound(np.vstack([peaks, values[ends] + slopes * left[:, None]]))
    bounded = np.full(hi - lo + 2, math.inf)  # the cut cells', then the whole ones
    bounded[int(lo == a) : len(cells) + int(lo == a)] = found[: len(cells)]
    cut = np.minimum(bounded[[0, -1]], found[len(cells) :])
    whole = bounded[1:-1].max(initial=-math.inf)
    return float(np.max([whole, cut.max(), values[k, 0]]))  # (NaN if any is: numpy's max)
