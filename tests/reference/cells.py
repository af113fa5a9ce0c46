"""The numpy references of the cell test of the solution paths (``_core.surprise``,
``_core.crossing`` and ``_core.cell_looks``, csrc/redundancy/cells.c): every Hermite model at every
point of a cell, where the compiled test skips what its bounds settle."""

from __future__ import annotations

import numpy as np

from om_redundant.redundancy.paths.linking import _BOUND_SLACK, _HERMITE, FINE_STEP
from tests.conftest import steps_numpy


def surprise_numpy(ga, da, gb, db, span, feasible_a, feasible_b):
    """The reference: every model at every point of the cell."""
    models = np.column_stack([ga, da * span, gb, db * span]) @ _HERMITE
    pattern = np.concatenate([[feasible_a], (models >= 0.0).all(axis=0), [feasible_b]])
    changes = np.flatnonzero(pattern[1:] != pattern[:-1])
    if len(changes) <= int(pattern[0] != pattern[-1]):
        return None
    return (changes[0] + 1 + changes[1]) / 2.0 / (len(pattern) - 1)


def crossing_numpy(ga, da, gb, db, span):
    """The reference: the first point of the cell where a model is negative, and the secant
    of the most negative one there from the point before (from the cell's start at the
    first point)."""
    models = np.column_stack([ga, da * span, gb, db * span]) @ _HERMITE
    below = np.flatnonzero((models < 0.0).any(axis=0))
    if len(below) == 0:
        return None
    k = below[0]
    j = np.argmin(models[:, k])
    n = models.shape[1] + 1
    s0, m0 = (0.0, ga[j]) if k == 0 else (k / n, models[j, k - 1])
    return s0 + (1.0 / n) * m0 / (m0 - models[j, k])


def quiet_numpy(span, ga, da, gb, db, feasible_a, feasible_b):
    """The reference of cell_looks' quiet test, cells (rows) at once: a model lies within
    (4/27) |span| (|g'_a| + |g'_b|) of the ends' range; quiet: both ends feasible and every
    model stays > 0, or both infeasible and one function's model stays < 0."""
    spread = 4.0 / 27.0 * np.abs(span)[:, None] * (np.abs(da) + np.abs(db)) + _BOUND_SLACK
    clear = (np.minimum(ga, gb) - spread > 0.0).all(axis=1)
    blocked = (np.maximum(ga, gb) + spread < 0.0).any(axis=1)
    return (feasible_a == feasible_b) & np.where(feasible_a, clear, blocked)


def looks_numpy(q, psi, g, dg, feasible, cyclic):
    """The reference of cell_looks for one path: NaN where a cell is calm (no step above
    FINE_STEP, quiet), 1/2 where a step is above FINE_STEP, else the numpy surprise (NaN for
    none); NaN for the last sample."""
    steps = steps_numpy(cyclic, q[:-1], q[1:])
    quiet = quiet_numpy(psi[1:] - psi[:-1], g[:-1], dg[:-1], g[1:], dg[1:], feasible[:-1], feasible[1:])
    first = []
    for k in range(len(steps)):
        if steps[k] <= FINE_STEP and quiet[k]:
            first.append(np.nan)
        elif steps[k] > FINE_STEP:
            first.append(0.5)
        else:
            span = psi[k + 1] - psi[k]
            t = surprise_numpy(g[k], dg[k], g[k + 1], dg[k + 1], span, feasible[k], feasible[k + 1])
            first.append(np.nan if t is None or g.shape[1] == 0 else t)
    return np.array([*first, np.nan])
