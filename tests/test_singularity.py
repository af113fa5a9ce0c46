"""The singularity term of the objective: distances that vanish exactly where the model's
branches meet, their derivatives against finite differences, an optimum that moves off a
singular wrist when the term is weighted, bad weights."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.redundancy import Objective, self_motion_tangent
from om_redundant.redundancy.objective.terms import SINGULARITY_CAP
from tests.reference import objective as objective_numpy

ARMS = ("panda", "iiwa14", "gen3", "sawyer", "ur5e", "spherical")
H = 1e-6  # finite-difference step (rad)


@pytest.fixture(scope="module")
def solvers():
    return {name: om.OMSolver(name) for name in ARMS}


def limited_q(arm, unit: np.ndarray) -> np.ndarray:
    """The joint vector at fractions ``unit`` in [0, 1] of the limits ([-pi, pi] where unlimited)."""
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return lower + unit * (upper - lower)


unit_vectors = st.lists(st.floats(0.0, 1.0), min_size=7, max_size=7).map(np.array)


@settings(max_examples=60, deadline=None)
@given(name=st.sampled_from(ARMS), unit=unit_vectors)
def test_distances_vanish_where_the_branch_signs_change(solvers, name, unit):
    """Each distance is |sin x| of the angle whose sign is a branch sign of the model."""
    solver = solvers[name]
    singularity = om.Singularity.of(solver.model_arm)
    q = limited_q(solver.arm, unit[: solver.arm.dof])
    x = q[singularity.joints] + singularity.offsets
    assume(np.abs(np.sin(x)).min() > 1e-6)  # (on a singularity the sign is that of rounding)
    signs = dict(zip(solver.sign_names, solver.configuration_of(q).signs, strict=True))
    for kind, sine in zip(singularity.names, np.sin(x), strict=True):
        assert signs[kind.upper()] == np.sign(sine)
    np.testing.assert_array_equal(singularity.distances(q), np.abs(np.sin(x)))
    np.testing.assert_array_equal(singularity.distances(np.stack([q, q]))[1], np.abs(np.sin(x)))


def test_each_arm_has_the_singularities_of_its_family(solvers):
    names = {name: om.Singularity.of(solver.model_arm).names for name, solver in solvers.items()}
    assert names["panda"] == names["sawyer"] == ("wrist", "elbow", "shoulder")
    assert names["ur5e"] == ("wrist", "elbow")
    assert names["spherical"] == ("wrist",)


@settings(max_examples=60, deadline=None)
@given(name=st.sampled_from(ARMS), unit=unit_vectors, direction=unit_vectors)
def test_gradients_match_finite_differences(solvers, name, unit, direction):
    solver = solvers[name]
    singularity = om.Singularity.of(solver.model_arm)
    dof = solver.arm.dof
    q, v = limited_q(solver.arm, unit[:dof]), direction[:dof] - 0.5
    s, gradient = singularity.distances_and_gradients(q)
    np.testing.assert_array_equal(s, singularity.distances(q))
    near = np.abs(np.sin(q[singularity.joints] + singularity.offsets)) < 1e-4  # |sin| kinks there
    differences = (singularity.distances(q + H * v) - singularity.distances(q - H * v)) / (2 * H)
    np.testing.assert_allclose((gradient @ v)[~near], differences[~near], atol=1e-8)


@pytest.mark.parametrize("name", ["panda", "iiwa14"])
def test_the_objective_group_along_psi_matches_finite_differences(solvers, name):
    """The singularity group's slopes by psi (through the self-motion) against exact solves
    at psi +- h, and Evaluation.singularity is the smallest distance."""
    solver = solvers[name]
    objective = om.RedundancyOptimizer(solver, singularity_weight=0.5).objective
    singularity = objective.singularity
    rng = np.random.default_rng(3)
    for q in limited_q(solver.arm, rng.uniform(0.1, 0.9, (10, 7))):
        T, c = solver.arm.fk(q), solver.configuration_of(q)
        ahead, behind = (
            solver.solve(T, om.Configuration(c.signs, (c.redundancy[0] + s,)), q_hint=q).q for s in (H, -H)
        )
        tangent = self_motion_tangent(solver, q)
        (group,) = [
            g for g in objective_numpy.groups(objective, q, tangent=tangent) if g.kind == "singularity"
        ]
        slopes = group.jacobian[:, 0] * SINGULARITY_CAP
        differences = (singularity.distances(ahead) - singularity.distances(behind)) / (2 * H)
        np.testing.assert_allclose(slopes, differences, atol=1e-5)
        evaluation = objective.evaluate(q)
        assert evaluation.singularity == singularity.distances(q).min()
        assert evaluation.value == pytest.approx(
            evaluation.margin + 0.5 * min(1.0, evaluation.singularity / SINGULARITY_CAP), abs=1e-12
        )


def test_weighted_optimum_moves_off_the_singular_wrist(solvers):
    """The iiwa14 bent in its x-z plane with the hand along the forearm (q6 = 0): the margin
    alone is best at that wrist singularity (joint 2 binds, and every other joint is best at
    mid-range there); weighted 1, the singularity term moves the optimum off it, to the
    weighted objective's best psi on the branch (a dense sweep's best, polished), exact."""
    solver = solvers["iiwa14"]
    T = solver.arm.fk(np.array([0.0, 1.3, 0.0, -0.4, 0.0, 0.0, 0.0]))
    unweighted = om.RedundancyOptimizer(solver, singularity_weight=0.0).choose(T)
    weighted_optimizer = om.RedundancyOptimizer(solver, singularity_weight=1.0)
    weighted = weighted_optimizer.choose(T)
    assert unweighted.ok and weighted.ok
    objective = weighted_optimizer.objective
    assert objective.evaluate(unweighted.solution.q).singularity < 1e-6
    assert objective.evaluate(weighted.solution.q).singularity > 0.3
    for choice in (unweighted, weighted):
        reached = solver.arm.fk(choice.solution.q)
        assert np.abs(reached - T).max() < 1e-10
    assert weighted.value == pytest.approx(objective.evaluate(weighted.solution.q).value, abs=1e-12)
    assert weighted.value > objective.evaluate(unweighted.solution.q).value + 0.1

    n = 4000
    psi = -math.pi + 2.0 * math.pi * np.arange(n) / n
    best = -math.inf
    for signs in weighted_optimizer.branches:
        batch = solver.solve_batch(np.repeat(T[None], n, axis=0), signs, psi)
        for q in batch.q[batch.ok]:
            evaluation = objective.evaluate(q)
            if evaluation.feasible:
                best = max(best, evaluation.value)
    assert weighted.value >= best - 1e-6


@pytest.mark.parametrize("weight", [-0.1, math.nan, math.inf, "1", None])
def test_bad_singularity_weights_are_named(solvers, weight):
    with pytest.raises(om.InvalidInput, match="singularity_weight must be a finite number"):
        om.RedundancyOptimizer(solvers["panda"], singularity_weight=weight)
    with pytest.raises(om.InvalidInput, match="singularity_weight must be a finite number"):
        Objective(solvers["panda"].arm, singularity_weight=weight)


def test_bad_singularities_are_named(solvers):
    with pytest.raises(om.InvalidInput, match="model must be a ModelArm"):
        om.Singularity.of("panda")
    with pytest.raises(om.InvalidInput, match="singularity must be a Singularity"):
        Objective(solvers["panda"].arm, singularity="wrist")
    with pytest.raises(om.InvalidInput, match="the singularity's arm has 6 joints, the arm 7"):
        Objective(solvers["panda"].arm, singularity=om.Singularity.of(solvers["ur5e"].model_arm))
    with pytest.raises(om.InvalidInput, match="q must have shape \\(7,\\)"):
        om.Singularity.of(solvers["panda"].model_arm).distances(np.zeros(6))
