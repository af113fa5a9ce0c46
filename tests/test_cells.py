"""The compiled cell test of the global choose's solution paths (``ckernels.pieces`` and
``ckernels.surprise``, csrc/cells.c) against the numpy it replaces: the feasibility functions
of the margin and clearance groups and their rates, and where the cubic Hermite models of a
cell predict a feasibility its ends do not explain."""

from __future__ import annotations

import functools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.control_rate import HOMES, MIN_CLEARANCE, obstacles
from om_redundant import ckernels
from om_redundant.redundancy.paths import _BOUND_SLACK, _HERMITE, _quiet
from om_redundant.redundancy.self_motion import self_motion_tangents


@functools.cache
def optimizer_of(name: str, count: int) -> om.RedundancyOptimizer:
    solver = om.OMSolver(name)
    shapes = obstacles(solver.arm.fk(HOMES[name])[:3, 3], count)
    return om.RedundancyOptimizer(solver, shapes or None, min_clearance=MIN_CLEARANCE)


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
        groups = [group.along(t) for group in objective.constrained_groups(row, jacobian=True)]
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
    """ckernels.surprise gives the numpy models' answer (pieces whose bound keeps them
    positive skipped), for ends feasible or not as their values say, with dips and islands
    between them (slopes large against the values)."""
    rng = np.random.default_rng(seed)
    ga, gb = rng.normal(0.3, 0.5, (2, pieces))
    da, db = rng.normal(0.0, 3.0 / span, (2, pieces))
    fa, fb = bool((ga >= 0).all()), bool((gb >= 0).all())
    got = ckernels.surprise(ga, da, gb, db, span, _HERMITE, fa, fb, _BOUND_SLACK)
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
    """ckernels.crossing gives the numpy models' first zero, to rounding (pieces whose bound
    keeps them positive skipped), from a feasible end towards either side (span < 0: the
    cell lies below the feasible end), with dips and islands between."""
    rng = np.random.default_rng(seed)
    ga, gb = np.abs(rng.normal(0.3, 0.5, pieces)), rng.normal(0.3, 0.5, pieces)
    da, db = rng.normal(0.0, 3.0 / max(abs(span), 1e-6), (2, pieces))
    got, want = ckernels.crossing(ga, da, gb, db, span, _HERMITE), crossing_numpy(ga, da, gb, db, span)
    assert (got is None) == (want is None)
    if want is not None:
        assert 0.0 <= got <= 1.0 and abs(got - want) <= 1e-12


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pieces=st.integers(1, 12), span=st.floats(-1.0, 1.0))
def test_a_quiet_cell_has_no_surprise(seed, pieces, span):
    """paths._quiet's bounds: where they call a cell quiet, ckernels.surprise finds no change
    that its ends do not explain (so skipping its look changes no sample); cells drawn near
    the bounds' edge (values small against the slopes), ends feasible or not as they say."""
    rng = np.random.default_rng(seed)
    ga, gb = rng.normal(0.05, 0.3, (2, pieces))
    da, db = rng.normal(0.0, 0.5 / max(abs(span), 1e-6), (2, pieces))
    fa, fb = bool((ga >= 0).all()), bool((gb >= 0).all())
    quiet = _quiet(np.array([span]), ga[None], da[None], gb[None], db[None], np.array([fa]), np.array([fb]))
    if quiet[0]:
        assert ckernels.surprise(ga, da, gb, db, span, _HERMITE, fa, fb, _BOUND_SLACK) is None
