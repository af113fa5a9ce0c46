"""The numpy references of the cell test of the solution paths (``_core.surprise``,
``_core.crossing`` and ``_core.cell_looks``, csrc/redundancy/cells.c): every Hermite model at every
point of a cell, where the compiled test skips what its bounds settle; the looks' models along
the cell's chord (``_core.cell_spans``)."""

from __future__ import annotations

import math

import numpy as np

from om_redundant.redundancy.paths.linking import _BOUND_SLACK, _HERMITE, FINE_STEP
from tests.conftest import steps_numpy


def chord_spans_numpy(cyclic, qa, ta, qb, tb):
    """The reference of ``_core.cell_spans``: the chord |qb - qa| (the cyclic joints' differences
    taken to one turn) over each end's |dq/dpsi|, 0 where that is 0; summed in the joints'
    order, as the kernel sums."""
    d = [wrap_numpy(y - x) if c else y - x for c, x, y in zip(cyclic, qa.tolist(), qb.tolist(), strict=True)]
    chord = math.sqrt(sum(x * x for x in d))
    speeds = [math.sqrt(sum(x * x for x in t.ravel().tolist())) for t in (ta, tb)]
    return tuple(chord / speed if speed > 0.0 else 0.0 for speed in speeds)


def wrap_numpy(x: float) -> float:
    """The kernel's wrap of an angle into [-pi, pi) (``om_wrap``, csrc/ik/om_math.h): fmod."""
    if -math.pi <= x < math.pi:
        return x
    r = math.fmod(x, 2.0 * math.pi)
    return r - 2.0 * math.pi if r >= math.pi else r + 2.0 * math.pi if r < -math.pi else r


def surprise_numpy(ga, da, gb, db, span_a, span_b, feasible_a, feasible_b):
    """The reference: every model at every point of the cell."""
    models = np.column_stack([ga, da * span_a, gb, db * span_b]) @ _HERMITE
    pattern = np.concatenate([[feasible_a], (models >= 0.0).all(axis=0), [feasible_b]])
    changes = np.flatnonzero(pattern[1:] != pattern[:-1])
    if len(changes) <= int(pattern[0] != pattern[-1]):
        return None
    return (changes[0] + 1 + changes[1]) / 2.0 / (len(pattern) - 1)


def crossing_numpy(ga, da, gb, db, span_a, span_b):
    """The reference: the first point of the cell where a model is negative, and the secant
    of the most negative one there from the point before (from the cell's start at the
    first point)."""
    models = np.column_stack([ga, da * span_a, gb, db * span_b]) @ _HERMITE
    below = np.flatnonzero((models < 0.0).any(axis=0))
    if len(below) == 0:
        return None
    k = below[0]
    j = np.argmin(models[:, k])
    n = models.shape[1] + 1
    s0, m0 = (0.0, ga[j]) if k == 0 else (k / n, models[j, k - 1])
    return s0 + (1.0 / n) * m0 / (m0 - models[j, k])


def quiet_numpy(span_a, span_b, ga, da, gb, db, feasible_a, feasible_b):
    """The reference of cell_looks' quiet test, cells (rows) at once: a model lies within
    (4/27) (|span_a g'_a| + |span_b g'_b|) of the ends' range; quiet: both ends feasible and
    every model stays > 0, or both infeasible and one function's model stays < 0."""
    spread = 4.0 / 27.0 * (np.abs(span_a[:, None] * da) + np.abs(span_b[:, None] * db)) + _BOUND_SLACK
    clear = (np.minimum(ga, gb) - spread > 0.0).all(axis=1)
    blocked = (np.maximum(ga, gb) + spread < 0.0).any(axis=1)
    return (feasible_a == feasible_b) & np.where(feasible_a, clear, blocked)


def looks_numpy(q, t, psi, g, dg, feasible, cyclic):
    """The reference of cell_looks for one path: NaN where a cell is calm (no step above
    FINE_STEP, quiet), 1/2 where a step is above FINE_STEP, else the numpy surprise (NaN for
    none); NaN for the last sample; the models along each cell's chord."""
    steps = steps_numpy(cyclic, q[:-1], q[1:])
    spans = [chord_spans_numpy(cyclic, q[k], t[k], q[k + 1], t[k + 1]) for k in range(len(steps))]
    span_a, span_b = np.array(spans).reshape(-1, 2).T
    quiet = quiet_numpy(span_a, span_b, g[:-1], dg[:-1], g[1:], dg[1:], feasible[:-1], feasible[1:])
    first = []
    for k in range(len(steps)):
        if steps[k] <= FINE_STEP and quiet[k]:
            first.append(np.nan)
        elif steps[k] > FINE_STEP:
            first.append(0.5)
        else:
            s = surprise_numpy(
                g[k], dg[k], g[k + 1], dg[k + 1], span_a[k], span_b[k], feasible[k], feasible[k + 1]
            )
            first.append(np.nan if s is None or g.shape[1] == 0 else s)
    return np.array([*first, np.nan])
