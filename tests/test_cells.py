"""The compiled cell test of the global choose's solution paths (``_core.pieces``,
``_core.surprise``, ``_core.joint_step`` and ``_core.cell_looks``, csrc/cells.c)
against the numpy it replaces: the feasibility functions of the margin and clearance groups
and their rates, where the cubic Hermite models of a cell predict a feasibility its ends do
not explain, the largest joint step, and the first tests of every cell of a path."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from benchmarks.control_rate import HOMES
from om_redundant import _core
from om_redundant.redundancy.paths import _BOUND_SLACK, _HERMITE, FINE_STEP
from om_redundant.redundancy.self_motion import self_motion_tangents
from tests.conftest import steps_numpy
from tests.test_redundancy_batch import optimizer_of


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)), count=st.sampled_from([0, 1, 3]))
def test_pieces_are_the_groups_constraints(seed, name, count):
    """Objective.pieces: the margin and clearance groups' Group.constraints along the
    tangent, to rounding (the rates' sums may be ordered otherwise), near the obstacles (the
    pairs capped at 2 d_cap) and far."""
    optimizer = optimizer_of(name, count)
    objective, arm = optimizer.objective, optimizer.solver.arm
    q = np.random.default_rng(seed).uniform(arm.lower - 0.3, arm.upper + 0.3, (10, arm.dof))
    tangents = self_motion_tangents(optimizer.solver, q)
    for row, t in zip(q, tangents, strict=True):
        pairs = None if objective.clearance is None else objective.clearance.distances_and_gradients(row)
        g, dg = objective.pieces(row, t, pairs)
        groups = objective.constrained_groups(row, tangent=t)
        want_g, want_dg = (
            np.concatenate(x) for x in zip(*(group.constraints() for group in groups), strict=True)
        )
        np.testing.assert_allclose(g, want_g, rtol=0, atol=1e-15 * (1 + np.abs(want_g).max()))
        np.testing.assert_allclose(dg, want_dg, rtol=0, atol=1e-13 * (1 + np.abs(want_dg).max()))


def surprise_numpy(ga, da, gb, db, span, feasible_a, feasible_b):
    """The reference: every model at every point of the cell."""
    models = np.column_stack([ga, da * span, gb, db * span]) @ _HERMITE
    pattern = np.concatenate([[feasible_a], (models >= 0.0).all(axis=0), [feasible_b]])
    changes = np.flatnonzero(pattern[1:] != pattern[:-1])
    if len(changes) <= int(pattern[0] != pattern[-1]):
        return None
    return (changes[0] + 1 + changes[1]) / 2.0 / (len(pattern) - 1)


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 12), span=st.floats(1e-6, 1.0))
def test_surprise_is_numpys(seed, pieces, span):
    """_core.surprise gives the numpy models' answer (pieces whose bound keeps them
    positive skipped), for ends feasible or not as their values say, with dips and islands
    between them (slopes large against the values)."""
    rng = np.random.default_rng(seed)
    ga, gb = rng.normal(0.3, 0.5, (2, pieces))
    da, db = rng.normal(0.0, 3.0 / span, (2, pieces))
    fa, fb = bool((ga >= 0).all()), bool((gb >= 0).all())
    got = _core.surprise(_core.CellModels(ga, da, gb, db, span, _HERMITE), fa, fb, _BOUND_SLACK)
    assert got == surprise_numpy(ga, da, gb, db, span, fa, fb)


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


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 12), span=st.floats(-1.0, 1.0))
def test_crossing_is_numpys(seed, pieces, span):
    """_core.crossing gives the numpy models' first zero, to rounding (pieces whose bound
    keeps them positive skipped), from a feasible end towards either side (span < 0: the
    cell lies below the feasible end), with dips and islands between."""
    rng = np.random.default_rng(seed)
    ga, gb = np.abs(rng.normal(0.3, 0.5, pieces)), rng.normal(0.3, 0.5, pieces)
    da, db = rng.normal(0.0, 3.0 / max(abs(span), 1e-6), (2, pieces))
    got, want = (
        _core.crossing(_core.CellModels(ga, da, gb, db, span, _HERMITE)),
        crossing_numpy(ga, da, gb, db, span),
    )
    assert (got is None) == (want is None)
    if want is not None:
        assert 0.0 <= got <= 1.0 and abs(got - want) <= 1e-12


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


def cell_looks(paths):
    """_core.cell_looks of paths [(q, psi, g, dg, feasible, cyclic)], given as lists of
    samples; each path's looks."""
    lengths = [len(psi) for _, psi, *_ in paths]
    q, psi, pieces, feasible = [], [], [], []
    for q_p, psi_p, g_p, dg_p, feasible_p, _ in paths:
        q += list(q_p)
        psi += psi_p.tolist()
        pieces += list(zip(g_p, dg_p, strict=True))
        feasible += feasible_p.tolist()
    bounds = np.cumsum([0, *lengths])
    cyclic = np.array([c for *_, c in paths], dtype=bool).reshape(-1, 7)
    first = np.full(len(psi), -7.0)
    samples = _core.CellSamples(q, psi, pieces, feasible, bounds, cyclic)
    _core.cell_looks(samples, FINE_STEP, _BOUND_SLACK, _HERMITE, first)
    return np.split(first, bounds[1:-1]) if paths else []


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 12), span=st.floats(-1.0, 1.0))
def test_a_quiet_cell_has_no_surprise(seed, pieces, span):
    """cell_looks' bounds: where they call a cell quiet, _core.surprise finds no change
    that its ends do not explain (so skipping its look changes no sample); cells drawn near
    the bounds' edge (values small against the slopes), ends feasible or not as they say;
    and the bounds are numpy's (quiet_numpy)."""
    rng = np.random.default_rng(seed)
    ga, gb = rng.normal(0.05, 0.3, (2, pieces))
    da, db = rng.normal(0.0, 0.5 / max(abs(span), 1e-6), (2, pieces))
    fa, fb = bool((ga >= 0).all()), bool((gb >= 0).all())
    q, cyclic = np.zeros((2, 7)), np.ones(7, dtype=bool)  # (no step: the looks are the bounds')
    feasible = np.array([fa, fb])
    (first,) = cell_looks(
        [(q, np.array([0.0, span]), np.array([ga, gb]), np.array([da, db]), feasible, cyclic)]
    )
    quiet = quiet_numpy(
        np.array([span]), ga[None], da[None], gb[None], db[None], np.array([fa]), np.array([fb])
    )
    surprise = _core.surprise(_core.CellModels(ga, da, gb, db, span, _HERMITE), fa, fb, _BOUND_SLACK)
    assert np.isnan(first[0]) == (quiet[0] or surprise is None)
    if quiet[0]:
        assert surprise is None


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), dof=st.integers(1, 7), scale=st.sampled_from([0.1, 1.0, 10.0, 1e3]))
def test_joint_step_is_the_numpy_step(seed, dof, scale):
    """_core.joint_step is the numpy reference (steps_numpy) to the bit: joints drawn far
    apart (turns of the cyclic ones) and at exact multiples of pi apart, where the remainder's
    sign rule decides."""
    rng = np.random.default_rng(seed)
    cyclic = rng.random(dof) < 0.7
    a = rng.normal(0.0, scale, (8, dof))
    b = a + rng.normal(0.0, scale, (8, dof))
    b[-2:] = a[-2:] + math.pi * rng.integers(-4, 5, (2, dof))  # (rounded: near the turn's edge)
    want = steps_numpy(cyclic, a, b)
    got = [_core.joint_step(cyclic, x, y) for x, y in zip(a, b, strict=True)]
    assert np.array_equal(got, want)


@settings(max_examples=200, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1), paths=st.lists(st.integers(1, 12), max_size=4), pieces=st.integers(0, 9)
)
def test_cell_looks_are_numpys(seed, paths, pieces):
    """_core.cell_looks gives each cell's first look as the reference (calm: NaN; a step
    above FINE_STEP: 1/2; else the numpy surprise), path by path with each path's cyclic
    joints: samples close and far apart in the joints, values small against the slopes
    (dips and islands), ends feasible or not as they say, no pieces at all, no paths."""
    rng = np.random.default_rng(seed)
    drawn = []
    for samples in paths:
        q = np.cumsum(rng.normal(0.0, rng.choice([0.02, 0.3]), (samples, 7)), axis=0)
        psi = np.cumsum(rng.uniform(1e-6, 0.2, samples))
        g = rng.normal(0.1, 0.3, (samples, pieces))
        dg = rng.normal(0.0, 2.0, (samples, pieces))
        drawn.append((q, psi, g, dg, (g >= 0.0).all(axis=1), rng.random(7) < 0.8))
    for got, path in zip(cell_looks(drawn), drawn, strict=True):
        assert np.array_equal(got, looks_numpy(*path), equal_nan=True)


def test_cell_looks_refuses_what_it_cannot_read():
    """Samples of another size or kind than the first's, and bounds that do not cover the
    samples, are refused with the error named (not read past)."""
    q, pieces, feasible = [np.zeros(7)] * 2, [(np.zeros(3), np.zeros(3))] * 2, [True, True]
    bounds, cyclic, first = np.array([0, 2]), np.ones((1, 7), dtype=bool), np.empty(2)
    rest = (FINE_STEP, _BOUND_SLACK, _HERMITE, first)
    _core.cell_looks(_core.CellSamples(q, [0.0, 0.1], pieces, feasible, bounds, cyclic), *rest)
    assert first[0] == 0.5 or np.isnan(first[0])
    wider = [pieces[0], (np.zeros(4), np.zeros(4))]
    with pytest.raises(ValueError, match="g must have 3 entries"):
        _core.cell_looks(_core.CellSamples(q, [0.0, 0.1], wider, feasible, bounds, cyclic), *rest)
    with pytest.raises(TypeError, match="q must be float64"):
        _core.cell_looks(
            _core.CellSamples([q[0], np.zeros(7, np.float32)], [0.0, 0.1], pieces, feasible, bounds, cyclic),
            *rest,
        )
    with pytest.raises(ValueError, match="disagree"):
        _core.cell_looks(_core.CellSamples(q, [0.0, 0.1], pieces, feasible, np.array([0, 3]), cyclic), *rest)
    with pytest.raises(ValueError, match="disagree"):
        _core.cell_looks(_core.CellSamples(q, [0.0], pieces, feasible, bounds, cyclic), *rest)
