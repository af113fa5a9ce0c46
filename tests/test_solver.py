"""The OM solver: exact solutions in the requested configuration, or a reason why not."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.ik import derive_model, model_conditions
from tests.conftest import random_q, wrap
from tests.ur_closed_form import ur_ik

pytestmark = pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)


@pytest.fixture(scope="module")
def spherical():
    return om.OMSolver("spherical")


@pytest.fixture(scope="module")
def ur5e():
    return om.OMSolver("ur5e")


def spherical_targets(solver, n, seed):
    """The paper's protocol: uniform joint-space targets, q3 in +-0.5 m."""
    rng = np.random.default_rng(seed)
    Q = rng.uniform(-np.pi, np.pi, (n, 6))
    Q[:, 2] = rng.uniform(-0.5, 0.5, n)
    return Q


def assert_exact(solver, sol, T, configuration):
    assert sol.ok, sol.status
    T_reached = solver.arm.fk(sol.q)
    assert np.linalg.norm(T_reached[:3, 3] - T[:3, 3]) < 1e-10
    assert np.abs(T_reached[:3, :3] - T[:3, :3]).sum() < 1e-12  # the paper's |n-n|+|s-s|+|a-a|
    assert sol.position_error < 1e-10 and sol.orientation_error < 1e-12
    assert solver.configuration_of(sol.q) == configuration


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), signs=st.tuples(*[st.sampled_from((-1, 1))] * 3))
def test_spherical_solves_every_configuration_exactly(spherical, seed, signs):
    """FK(IK(T, c)) = T and configuration_of(IK(T, c)) = c, or an honest 'no solution'."""
    q = spherical_targets(spherical, 1, seed)[0]
    T = spherical.arm.fk(q)
    configuration = om.Configuration(signs)
    sol = spherical.solve(T, configuration)
    if configuration == spherical.configuration_of(q) or sol.ok:
        assert_exact(spherical, sol, T, configuration)
    else:
        assert sol.status == "no solution in this configuration"
        assert spherical.solve_all(T, configuration) == []


def test_paper_experiment_sample(spherical):
    """2,000 targets of the paper's experiment, batched: 100 % converged, 0 configuration errors."""
    Q = spherical_targets(spherical, 2000, seed=7)
    T = spherical.arm.fk(Q)
    signs = np.array([spherical.configuration_of(q).signs for q in Q])
    batch = spherical.solve_batch(T, signs)
    assert batch.ok.all()
    reached = spherical.arm.fk(batch.q)
    assert np.linalg.norm(reached[:, :3, 3] - T[:, :3, 3], axis=1).max() < 1e-10
    assert np.abs(reached[:, :3, :3] - T[:, :3, :3]).sum(axis=(1, 2)).max() < 1e-12
    assert all(spherical.configuration_of(q).signs == tuple(s) for q, s in zip(batch.q, signs, strict=True))


def test_batch_equals_single_solves(ur5e):
    Q = random_q(ur5e.arm, 200, np.random.default_rng(11))
    T = ur5e.arm.fk(Q)
    signs = np.array([ur5e.configuration_of(q).signs for q in Q])
    batch = ur5e.solve_batch(T, signs, q_hint=Q)
    for i in range(len(Q)):
        single = ur5e.solve(T[i], om.Configuration(tuple(signs[i])), q_hint=Q[i])
        np.testing.assert_allclose(batch.q[i], single.q, atol=1e-12)
        assert batch.status[i] == single.status


def test_ur5e_recovers_the_original_joint_vector(ur5e):
    """For random q in limits, q is among solve_all(fk(q), c(q)) and solve returns it.

    Where the model's configuration holds two real solutions (the wrist centre within
    about d5 of joint 1's axis), solve needs the hint to tell them apart; without a hint
    it returns q whenever the configuration holds one solution.
    """
    Q = random_q(ur5e.arm, 1500, np.random.default_rng(5))
    unique = 0
    for q in Q:
        T = ur5e.arm.fk(q)
        c = ur5e.configuration_of(q)
        roots = ur5e.solve_all(T, c)
        assert any(np.abs(wrap(r.q - q)).max() < 1e-9 for r in roots)
        for r in roots:
            assert_exact(ur5e, r, T, c)
        hinted = ur5e.solve(T, c, q_hint=q + np.random.default_rng(0).uniform(-0.01, 0.01, 6))
        assert_exact(ur5e, hinted, T, c)
        np.testing.assert_allclose(hinted.q, q, atol=1e-9)  # the hint also picks q's 2 pi shift
        if len(roots) == 1:
            unique += 1
            plain = ur5e.solve(T, c)
            assert np.abs(wrap(plain.q - q)).max() < 1e-9
            assert plain.within_limits == ur5e.arm.within_limits(plain.q)
    assert unique > 0.8 * len(Q)


def test_ur5e_configurations_agree_with_an_independent_closed_form(ur5e):
    """All solutions over the 8 configurations are exactly the UR's closed-form solutions.

    Away from joint 1's axis (|model reach| > 2 d5) each configuration holds one of them.
    """
    rng = np.random.default_rng(9)
    checked = 0
    for q in random_q(ur5e.arm, 300, rng):
        T = ur5e.arm.fk(q)
        expected = ur_ik(ur5e.arm, T)
        found = [s.q for c in ur5e.configurations() for s in ur5e.solve_all(T, c)]
        assert len(found) == len(expected)
        for e in expected:
            assert min(np.abs(wrap(f - e)).max() for f in found) < 1e-9
        values = np.empty(3)
        om.ik.families.branch_values(ur5e.model_arm.family, ur5e.model_arm.params, q, values)
        if len(expected) == 8 and abs(values[0]) > 2 * ur5e.dp_max:
            checked += 1
            for c in ur5e.configurations():
                sol = ur5e.solve(T, c)
                assert_exact(ur5e, sol, T, c)
                assert min(np.abs(wrap(sol.q - e)).max() for e in expected) < 1e-9
    assert checked > 100


def test_joint_limits_and_two_pi_shifts(ur5e):
    """Revolute joints are shifted into the limits nearest the hint; within_limits says so."""
    q = np.array([5.5, -1.0, 1.2, -5.8, 0.9, 6.0])
    T = ur5e.arm.fk(q)
    c = ur5e.configuration_of(q)
    sol = ur5e.solve(T, c, q_hint=q)
    np.testing.assert_allclose(sol.q, q, atol=1e-9)
    assert sol.within_limits
    no_hint = ur5e.solve(T, c)
    assert np.all(np.abs(no_hint.q) <= np.pi + 1e-12)


def test_solve_all_returns_nothing_when_the_configuration_has_no_solution(spherical):
    rng = np.random.default_rng(4)
    for q in spherical_targets(spherical, 200, 3):
        T = spherical.arm.fk(q)
        for c in spherical.configurations():
            sol = spherical.solve(T, c)
            roots = spherical.solve_all(T, c)
            assert sol.ok == bool(roots)
            if not sol.ok:
                assert sol.status == "no solution in this configuration"
    del rng


def test_an_arm_that_cannot_solve_is_refused_at_construction(monkeypatch):
    """A twist 1e-2 rad off 90 deg (beyond the nominal arm's NEAR_TWIST), let through by a
    loosened acceptance check, solves nothing. The solver's own check refuses it, naming q and
    the status. (The issue's 4e-6 rad is near the family: tests/test_near_family.py.)"""
    ur5e = om.load_arm("ur5e")
    rows = list(ur5e.chain.rows)
    rows[3] = om.DHRow(a=rows[3].a, alpha=rows[3].alpha + 1e-2, d=rows[3].d, theta=rows[3].theta)
    bent = ur5e.with_chain(ur5e.chain.replace_rows(rows), "bent")
    with pytest.raises(
        om.ModelError,
        match=r"joint 4 \('wrist_1_joint'\) and joint 5 \('wrist_2_joint'\) perpendicular .*"
        r"got 90.5729578 deg \(0.01 rad off\)",
    ):
        om.OMSolver(bent)
    monkeypatch.setattr(model_conditions, "RIGHT_ANGLE_EPS", 1e-1)
    derive_model(bent)  # accepted by the loosened check ...
    with pytest.raises(
        om.ModelError,
        match=r"arm 'bent' does not solve its own pose at q = \[[-0-9., ]+\] \(configuration ARM [+-]1, "
        r"ELBOW [+-]1, WRIST [+-]1\): (unreachable|no solution in this configuration)",
    ):
        om.OMSolver(bent)  # ... but not by the solver


def test_the_self_check_runs_once_per_arm(monkeypatch):
    arm = om.load_arm("panda")
    om.OMSolver(arm)
    calls = []
    solve = om.OMSolver.solve

    def counted(self, *args, **kwargs):
        calls.append(args)
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(om.OMSolver, "solve", counted)
    om.OMSolver(arm)
    assert calls == []
    om.OMSolver(om.load_arm("panda"))  # another instance is checked again
    assert len(calls) > 0
