"""The batched evaluations behind the global optimiser's sweep (issue 16): each agrees with
the one-at-a-time evaluation it replaces, and the bounds that let a cell of a solution path
skip its clearance gradients hold."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.control_rate import HOMES, MIN_CLEARANCE, obstacles
from om_redundant.redundancy.self_motion import self_motion_tangents


@functools.cache
def optimizer_of(name: str, count: int) -> om.RedundancyOptimizer:
    """The arm's optimiser with count obstacles about its home hand (cached)."""
    solver = om.OMSolver(name)
    shapes = obstacles(solver.arm.fk(HOMES[name])[:3, 3], count)
    return om.RedundancyOptimizer(solver, shapes or None, min_clearance=MIN_CLEARANCE)


def joints(optimizer, seed, n=40):
    arm = optimizer.solver.arm
    return np.random.default_rng(seed).uniform(arm.lower - 0.3, arm.upper + 0.3, (n, arm.dof))


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)), count=st.sampled_from([0, 1, 3]))
def test_batched_evaluations_equal_the_single_ones(seed, name, count):
    """Objective.evaluations and Clearance.minima give exactly evaluate(q) and minimum(q)
    row by row (the global sweep's feasibility and values are unchanged by the batch)."""
    optimizer = optimizer_of(name, count)
    q = joints(optimizer, seed)
    objective = optimizer.objective
    assert objective.evaluations(q) == [objective.evaluate(row) for row in q]
    if objective.clearance is not None:
        assert objective.clearance.minima(q).tolist() == [objective.clearance.minimum(row) for row in q]


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)))
def test_batched_tangents_equal_the_single_ones(seed, name):
    """self_motion_tangents gives self_motion_tangent's dq/dpsi row by row (to rounding: the
    batched determinants may round differently), and it keeps the hand still (J t = 0) and
    moves psi at unit rate."""
    solver = optimizer_of(name, 0).solver
    q = joints(optimizer_of(name, 0), seed, 20)
    tangents = self_motion_tangents(solver, q)
    for row, t in zip(q, tangents, strict=True):
        np.testing.assert_allclose(t, om.self_motion_tangent(solver, row), rtol=1e-12, atol=1e-15)
        assert np.abs(solver.arm.jacobian(row) @ t).max() < 1e-9 * max(1.0, np.abs(t).max())
        assert om.arm_angle_and_gradient(solver, row)[1] @ t[:, 0] == pytest.approx(1.0, abs=1e-9)


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(list(HOMES)), count=st.sampled_from([1, 3]))
def test_constraint_bounds_bound_the_feasibility_functions_and_their_rates(seed, name, count):
    """Objective.constraint_bounds: the margin entries are the margin feasibility functions
    and their rates' sizes exactly; the clearance entry is at most every clearance function,
    and its rate bound (Clearance.lever) at least every clearance function's rate."""
    optimizer = optimizer_of(name, count)
    objective, solver = optimizer.objective, optimizer.solver
    for row in joints(optimizer, seed, 10):
        t = om.self_motion_tangent(solver, row)
        groups = [g.along(t) for g in objective.groups(row, jacobian=True)]
        values, rates, exact = objective.constraint_bounds(row, t, objective.evaluation(groups))
        margin, clearance = (g.constraints() for g in groups[:2])
        np.testing.assert_allclose(values[exact], margin[0], rtol=0, atol=1e-15)
        np.testing.assert_allclose(rates[exact], np.abs(margin[1]), rtol=1e-15, atol=0)
        ((value,), (rate,)) = values[~exact], rates[~exact]
        assert (clearance[0] >= value - 1e-15).all()
        assert (np.abs(clearance[1]) <= rate).all()
