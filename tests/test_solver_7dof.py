"""The OM solver on 7-DOF arms: exact solutions for (SHOULDER, ELBOW, WRIST, psi)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.ik.families import REACH_SLACK, model_ik
from om_redundant.ik.kernel_data import flange_target
from tests.conftest import random_q, wrap

pytestmark = pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)

ARMS = ["panda", "fr3", "iiwa14", "gen3", "xarm7", "sawyer"]


@pytest.fixture(scope="module", params=ARMS)
def solver(request):
    return om.OMSolver(request.param)


@pytest.fixture(scope="module")
def panda():
    return om.OMSolver("panda")


def assert_exact(solver, sol, T, configuration):
    assert sol.ok, sol.status
    T_reached = solver.arm.fk(sol.q)
    assert np.linalg.norm(T_reached[:3, 3] - T[:3, 3]) < 1e-10
    assert np.abs(T_reached[:3, :3] - T[:3, :3]).max() < 1e-10
    assert sol.position_error < 1e-10 and sol.orientation_error < 1e-10
    assert solver.configuration_of(sol.q).isclose(configuration)


def distance(a, b):
    return np.linalg.norm(wrap(a - b))


def test_the_original_joint_vector_is_recovered(solver):
    """q is among solve_all(fk(q), c(q)); solve with a hint returns the root nearest it.

    That root is q itself unless another root of the same configuration lies nearer the
    hint (a close pair of roots near a singular elbow or wrist). Without a hint, solve
    prefers a root within the joint limits.
    """
    rng = np.random.default_rng(21)
    Q = random_q(solver.arm, 300, rng)
    recovered = 0
    for q in Q:
        T = solver.arm.fk(q)
        c = solver.configuration_of(q)
        roots = solver.solve_all(T, c)
        assert min(distance(r.q, q) for r in roots) < 1e-9
        for r in roots:
            assert_exact(solver, r, T, c)
        hint = q + rng.uniform(-0.01, 0.01, 7)
        hinted = solver.solve(T, c, q_hint=hint)
        assert_exact(solver, hinted, T, c)
        assert distance(hinted.q, hint) <= min(distance(r.q, hint) for r in roots) + 1e-9
        recovered += distance(hinted.q, q) < 1e-9
        plain = solver.solve(T, c)  # without a hint, a root within the limits comes first
        assert_exact(solver, plain, T, c)
        assert plain.within_limits or not any(r.within_limits for r in roots)
    assert recovered >= len(Q) - 3


@settings(max_examples=150, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), signs=st.tuples(*[st.sampled_from((-1, 1))] * 3))
def test_every_configuration_is_solved_exactly_or_refused_with_the_reason(panda, seed, signs):
    rng = np.random.default_rng(seed)
    T = panda.arm.fk(random_q(panda.arm, 1, rng)[0])
    c = om.Configuration(signs, (rng.uniform(-np.pi, np.pi),))
    sol = panda.solve(T, c)
    if sol.ok:
        assert_exact(panda, sol, T, c)
    else:
        assert sol.status in ("no solution in this configuration", "unreachable")
        assert panda.solve_all(T, c) == []


def test_batch_equals_single_solves(panda):
    Q = random_q(panda.arm, 200, np.random.default_rng(12))
    T = panda.arm.fk(Q)
    configurations = [panda.configuration_of(q) for q in Q]
    signs = np.array([c.signs for c in configurations])
    psi = np.array([c.redundancy[0] for c in configurations])
    batch = panda.solve_batch(T, signs, psi, q_hint=Q)
    assert batch.ok.all()
    for i, c in enumerate(configurations):
        single = panda.solve(T[i], c, q_hint=Q[i])
        np.testing.assert_allclose(batch.q[i], single.q, atol=1e-12)


def test_sweeping_psi_gives_a_continuous_solution_path(panda):
    """At a fixed pose and signs, psi steps of 0.01 rad move the joints continuously."""
    q0 = np.array([0.2, 0.4, -0.3, -1.8, 0.5, 1.9, 0.6])
    T = panda.arm.fk(q0)
    c0 = panda.configuration_of(q0)
    psis = c0.redundancy[0] + np.arange(0.0, 2.0 * np.pi, 0.01)
    previous, steps, solved = q0, [], 0
    for psi in psis:
        c = om.Configuration(c0.signs, (psi,))
        sol = panda.solve(T, c, q_hint=previous)
        if not sol.ok:
            previous = None if previous is None else previous
            continue
        assert_exact(panda, sol, T, c)
        roots = panda.solve_all(T, c)
        assert distance(sol.q, previous) <= min(distance(r.q, previous) for r in roots) + 1e-9
        steps.append(distance(sol.q, previous))
        previous = sol.q
        solved += 1
    assert solved > 0.5 * len(psis)
    assert max(steps[1:]) < 0.1  # no jump to another root


def test_unreachable_pose_says_so(panda):
    T = np.eye(4)
    T[:3, 3] = [2.0, 0.0, 0.5]
    sol = panda.solve(T, om.Configuration((1, -1, 1), (0.0,)))
    assert not sol.ok and sol.status == "unreachable"
    assert np.isnan(sol.q).all()


def test_bad_configurations_are_named(panda):
    T = panda.arm.fk(np.zeros(7) + 0.3)
    with pytest.raises(om.InvalidInput, match=r"needs 1 redundancy values \('psi',\)"):
        panda.solve(T, om.Configuration((1, 1, 1)))
    with pytest.raises(om.InvalidInput, match="needs 3 configuration signs"):
        panda.solve(T, om.Configuration((1, 1), (0.0,)))
    for bad in (np.nan, np.inf):
        with pytest.raises(om.InvalidInput, match="redundancy values must be finite"):
            om.Configuration((1, 1, 1), (bad,))
    Ts = np.stack([T, T])
    with pytest.raises(om.InvalidInput, match="redundancy value psi is nan in row 1"):
        panda.solve_batch(Ts, (1, 1, 1), [0.0, np.nan])
    with pytest.raises(om.InvalidInput, match="needs redundancy values"):
        panda.solve_batch(Ts, (1, 1, 1))
    with pytest.raises(om.InvalidInput, match="redundancy must have shape"):
        panda.solve_batch(Ts, (1, 1, 1), np.zeros((3, 2)))


def test_a_root_beside_a_gap_of_reach_between_two_samples_is_found():
    """xArm7, 1 in 100,000 (benchmark seed 0): both neighbouring samples of q7 are in reach,
    but the model's elbow straightens and bends back between them; the root sits 0.0013 rad
    from that hidden gap, and the bracket's refinement must step around it."""
    solver = om.OMSolver("xarm7")
    q = np.array(
        [
            2.0858335553764524,
            -1.2087949878456372,
            0.5026803745558182,
            2.7474387374400795,
            3.01375038722163,
            -1.261211858524415,
            -2.8638560035539866,
        ]
    )
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    roots = solver.solve_all(T, c)
    assert min(distance(r.q, q) for r in roots) < 1e-9
    hinted = solver.solve(T, c, q_hint=q + 0.005)
    assert_exact(solver, hinted, T, c)


@pytest.mark.parametrize("name", ["panda", "xarm7"])
def test_targets_beyond_the_models_reach_are_solved_by_the_lifted_newton(name):
    """Where p_m = p_d lies beyond the model's reach (its elbow would have to be more than
    straight or folded), the secant has no start, and the root sits near the edge of reach,
    where g has a square root. Newton on the lifted system (q1, q7, phi4), started with the
    elbow held at the edge, solves them exactly without the bounded search: a few dozen
    residual evaluations (median 8 here) rather than the bounded search's hundreds."""
    solver = om.OMSolver(name)
    chain, model = solver.arm.chain, solver.model_arm
    base_inv, tool_inv = np.linalg.inv(chain.T_root_base), np.linalg.inv(chain.T_flange_tool)
    table = model.model.chain.table
    evaluations = []
    for q in random_q(solver.arm, 4000, np.random.default_rng(5)):
        T, c = solver.arm.fk(q), solver.configuration_of(q)
        R, p = flange_target(T, base_inv, tool_inv)
        signs, psi = np.array(c.signs), np.array(c.redundancy)
        if model_ik(model.family, model.params, table, R, p, signs, psi, q, np.empty(7)) >= -REACH_SLACK:
            continue
        sol = solver.solve(T, c)
        assert_exact(solver, sol, T, c)
        assert sol.within_limits
        evaluations.append(sol.iterations)
    assert len(evaluations) > 40
    assert np.median(evaluations) < 20


def test_arm_without_a_model_is_refused_with_the_reason(arm_without_a_model):
    cause = r"arm 'bent': fixed rows between joint 6 \('right_j5'\) and joint 7 \('right_j6'\) need a = 0"
    with pytest.raises(om.ModelError, match=cause):
        om.OMSolver(om.load_arm(str(arm_without_a_model)))
