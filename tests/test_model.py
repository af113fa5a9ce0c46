"""The offset-modified model arm: Theorem 2's conditions, dp, and the model's closed form."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant import _core
from om_redundant._core import flange as flange_kernel
from om_redundant.ik import derive_model
from om_redundant.ik.families import REACH_SLACK, branch_values, model_ik, redundancy_values, srs
from tests.conftest import random_q, wrap


def modified(arm: om.Arm, joint: int, **changes) -> om.Arm:
    rows = list(arm.chain.rows)
    i = arm.chain.joint_rows[joint]
    rows[i] = dataclasses.replace(rows[i], **changes)
    return arm.with_chain(arm.chain.replace_rows(rows), arm.name)


@pytest.mark.parametrize(
    "joint, changes, message",
    [
        (3, {"kind": om.JointKind.PRISMATIC}, r"joint 4 \('wrist_1_joint'\) revolute"),
        (3, {"alpha": 0.0}, "non-parallel"),
        (4, {"alpha": np.pi}, "non-parallel"),
        (4, {"alpha": np.pi / 3}, "alpha_5 = \\+-90"),
        (
            1,
            {"kind": om.JointKind.PRISMATIC},
            r"joint 1 \('shoulder_pan_joint'\) and joint 2 \('shoulder_lift_joint'\) must be revolute",
        ),
        (0, {"alpha": 0.0}, "perpendicular"),
        (2, {"kind": om.JointKind.PRISMATIC}, "no closed-form family"),
    ],
)
def test_arms_outside_theorem_2_are_refused_with_the_reason(joint, changes, message):
    arm = modified(om.load_arm("ur5e"), joint, **changes)
    with pytest.raises(om.ModelError, match=message):
        derive_model(arm)


def test_model_zeroes_only_a4_a5_d5():
    for name in ("spherical", "ur5e"):
        arm = om.load_arm(name)
        model = derive_model(arm).model
        jr = arm.chain.joint_rows
        for i, (real, mod) in enumerate(zip(arm.chain.rows, model.chain.rows, strict=True)):
            if i in (jr[3], jr[4]):
                assert mod.a == 0.0 and (i == jr[3] or mod.d == 0.0)
                assert (mod.alpha, mod.theta) == (real.alpha, real.theta)
            else:
                assert mod == real


@pytest.mark.parametrize("name, dp_max", [("spherical", 0.02), ("ur5e", 0.1)])
def test_dp_depends_on_joint_6_alone_and_its_norm_is_dp_max(name, dp_max):
    om_arm = derive_model(om.load_arm(name))
    assert om_arm.dp_joint == 5
    assert om_arm.dp_max == pytest.approx(dp_max, abs=1e-15)
    Q = random_q(om_arm.real, 300, np.random.default_rng(3))
    np.testing.assert_allclose(np.linalg.norm(om_arm.dp(Q), axis=1), dp_max, atol=1e-14)
    # Orientation is identical for equal joints (condition C1 of Theorem 1).
    np.testing.assert_allclose(om_arm.model.fk(Q)[:, :3, :3], om_arm.real.fk(Q)[:, :3, :3], atol=1e-15)


SOLVABLE = om.arm_names()


@pytest.mark.parametrize("name", SOLVABLE)
@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_model_closed_form_inverts_model_fk(name, seed):
    """IK_model(FK_model(q), c(q)) = q, so the closed form is one-to-one off singularities."""
    om_arm = derive_model(om.load_arm(name))
    dof = om_arm.real.dof
    q = random_q(om_arm.real, 1, np.random.default_rng(seed))[0]
    table = om_arm.model.chain.table
    R, p = np.empty((3, 3)), np.empty(3)
    flange_kernel(table, q, R, p)
    values = np.empty(3)
    branch_values(om_arm.family, om_arm.params, q, values)
    signs = np.where(values < 0, -1, 1)
    redundancy = np.empty(len(om_arm.redundancy_names))
    redundancy_values(om_arm.family, om_arm.params, q, redundancy)
    out = np.empty(dof)
    margin = model_ik(om_arm.family, om_arm.params, table, R, p, signs, redundancy, np.zeros(dof), out)
    assert margin >= -REACH_SLACK
    diff = out - q
    diff[om_arm.real.revolute] = wrap(diff[om_arm.real.revolute])
    # Joint-space agreement is ill-conditioned only within ~1e-5 rad of a singular joint.
    assert np.abs(diff).max() < 1e-8
    if om_arm.family == _core.SRS:  # the searches' IK without the shoulder: the same q4..q7, bit for bit
        wrist = np.full(dof, np.nan)
        model_ik(om_arm.family, om_arm.params, table, R, p, signs, redundancy, np.zeros(dof), wrist, False)
        np.testing.assert_array_equal(wrist[3:], out[3:])
        assert np.isnan(wrist[:3]).all()


@pytest.mark.parametrize("name, zeroed", [("panda", {5: ("a",)}), ("xarm7", {5: ("a",)}), ("iiwa14", {})])
def test_seven_dof_model_zeroes_only_the_offsets_off_the_spherical_joints(name, zeroed):
    arm = om.load_arm(name)
    model = derive_model(arm).model
    jr = arm.chain.joint_rows
    for i, (real, mod) in enumerate(zip(arm.chain.rows, model.chain.rows, strict=True)):
        fields = next((f for j, f in zeroed.items() if jr[j] == i), ())
        for field in ("a", "d", "alpha", "theta"):
            expected = 0.0 if field in fields else getattr(real, field)
            assert getattr(mod, field) == expected


@pytest.mark.parametrize(
    "name, dp_max", [("panda", 0.088), ("fr3", 0.088), ("xarm7", 0.076), ("iiwa14", 0.0)]
)
def test_seven_dof_dp_depends_on_joint_7_alone(name, dp_max):
    om_arm = derive_model(om.load_arm(name))
    assert om_arm.dp_joint == (6 if dp_max else -1)
    assert om_arm.dp_max == pytest.approx(dp_max, abs=1e-15)
    Q = random_q(om_arm.real, 300, np.random.default_rng(4))
    dp = om_arm.dp(Q)
    np.testing.assert_allclose(np.linalg.norm(dp, axis=1), dp_max, atol=1e-14)
    # delta = R_flange^T dp is D0 + D1 cos q7 + D2 sin q7.
    R = om_arm.real.fk(Q)[:, :3, :3] @ np.linalg.inv(om_arm.real.chain.T_flange_tool[:3, :3])
    delta = np.einsum("mji,mj->mi", R, dp @ om_arm.real.chain.T_root_base[:3, :3])
    D = om_arm.delta
    w = Q[:, 6]
    np.testing.assert_allclose(
        delta, D[0] + np.outer(np.cos(w), D[1]) + np.outer(np.sin(w), D[2]), atol=1e-14
    )


@pytest.mark.parametrize(
    "name, shoulder, wrist_min, wrist_max",
    [
        ("gen3", 0.01175, 0.0003501, 0.0003501),
        # The Sawyer's wrist: d6 and 0.11 m times joint 7's tilt of 7.35e-6 rad.
        ("sawyer", np.hypot(0.081, 0.1925), 0.1363, 0.1363 + 0.11 * 7.35e-6),
    ],
)
def test_shoulder_offsets_dp_turns_with_joint_1_alone(name, shoulder, wrist_min, wrist_max):
    """dp = R_flange delta(q7) + a(q1), a(q1) = A0 + A1 cos q1 + A2 sin q1 in DH frame 0."""
    om_arm = derive_model(om.load_arm(name))
    real = om_arm.real
    Q = random_q(real, 300, np.random.default_rng(6))
    base = real.chain.T_root_base
    R = real.fk(Q)[:, :3, :3] @ np.linalg.inv(real.chain.T_flange_tool[:3, :3])
    dp0 = om_arm.dp(Q) @ base[:3, :3]  # in DH frame 0
    A, D = om_arm.shoulder, om_arm.delta
    a = A[0] + np.outer(np.cos(Q[:, 0]), A[1]) + np.outer(np.sin(Q[:, 0]), A[2])
    delta = D[0] + np.outer(np.cos(Q[:, 6]), D[1]) + np.outer(np.sin(Q[:, 6]), D[2])
    R0 = base[:3, :3].T @ R
    np.testing.assert_allclose(dp0, np.einsum("mij,mj->mi", R0, delta) + a, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(a, axis=1), shoulder, atol=1e-15)
    assert shoulder + wrist_min - 1e-12 <= om_arm.dp_max <= shoulder + wrist_max + 1e-12


def test_sawyer_model_moves_the_length_before_joint_7_past_it():
    """The Sawyer's fixed row between joints 6 and 7 (0.11 m along joint 7's axis, which
    Menagerie tilts by 7.35e-6 rad) moves into joint 7's row: joint 7's axis then meets the
    wrist centre and the hand moves by 0.11 m times the tilt, not 0.11 m."""
    arm = om.load_arm("sawyer")
    om_arm = derive_model(arm)
    real_rows, model_rows = arm.chain.rows, om_arm.model.chain.rows
    jr = arm.chain.joint_rows
    fixed = jr[5] + 1
    assert real_rows[fixed].d == 0.11 and model_rows[fixed].d == 0.0
    assert model_rows[jr[6]].d == pytest.approx(0.0245 + 0.11, abs=1e-15)
    for i, (real, model) in enumerate(zip(real_rows, model_rows, strict=True)):
        assert (model.alpha, model.theta) == (real.alpha, real.theta)
        if i not in (jr[0], jr[1], jr[5], fixed, jr[6]):
            assert (model.a, model.d) == (real.a, real.d)
    np.testing.assert_allclose(np.linalg.norm(om_arm.delta[1:], axis=1), 0.1363, atol=1e-6)
    Q = random_q(arm, 100, np.random.default_rng(7))
    np.testing.assert_allclose(om_arm.model.fk(Q)[:, :3, :3], arm.fk(Q)[:, :3, :3], atol=1e-15)


def _lifted_at(om_arm, q):
    """The model's flange pose at q, its configuration, and model_ik_lifted at q's own q1, q7, phi4."""
    P = om_arm.params
    R, p = np.empty((3, 3)), np.empty(3)
    flange_kernel(om_arm.model.chain.table, q, R, p)
    values = np.empty(3)
    branch_values(om_arm.family, P, q, values)
    signs = np.where(values < 0, -1, 1)
    psi = np.empty(1)
    redundancy_values(om_arm.family, P, q, psi)
    out = np.empty(7)
    phi4 = q[3] + P[_core.SRS_THETA + 3]
    residual = srs.model_ik_lifted(P, R, p, signs, psi[0], q[0], q[6], phi4, out)
    return (R, p, signs, psi[0]), np.array(residual), out


@pytest.mark.parametrize("name", ["gen3", "sawyer"])
@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), singular=st.sampled_from(["none", "shoulder", "elbow", "wrist"]))
def test_lifted_model_ik_vanishes_exactly_at_the_model_joints(name, seed, singular):
    """With q1, q7 and phi4 given, the three residuals vanish at the model's own joints and q
    comes back, also exactly at the shoulder, elbow and wrist singularities, where the
    closed form's Euler angles and square root are ill-conditioned."""
    om_arm = derive_model(om.load_arm(name))
    P = om_arm.params
    q = random_q(om_arm.real, 1, np.random.default_rng(seed))[0]
    if singular == "shoulder":
        q[1] = -P[_core.SRS_THETA + 1]
    elif singular == "elbow":
        q[3] = P[_core.SRS_PHI_STAR] - P[_core.SRS_THETA + 3]
    elif singular == "wrist":
        q[5] = -P[_core.SRS_THETA + 5]
    _, residual, out = _lifted_at(om_arm, q)
    assert np.abs(residual).max() < 1e-12
    assert np.abs(wrap(out - q)).max() < 1e-10


@pytest.mark.parametrize("name", ["panda", "xarm7", "sawyer"])
@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), stretch=st.floats(0.05, 0.9))
def test_model_ik_at_reach_holds_the_elbow_at_the_edge_beyond_reach(name, seed, stretch):
    """Within reach it is the closed form; with the wrist centre moved beyond the reach, or
    inside the folded elbow's, the elbow is held straight or folded at the edge:
    sin(phi4 - phi*) = 0, a start for the lifted Newton."""
    om_arm = derive_model(om.load_arm(name))
    P = om_arm.params
    q = random_q(om_arm.real, 1, np.random.default_rng(seed))[0]
    (R, p, signs, psi), _, _ = _lifted_at(om_arm, q)
    table, zeros = om_arm.model.chain.table, np.zeros(7)
    closed_form, at_reach = np.empty(7), np.empty(7)
    assert model_ik(om_arm.family, P, table, R, p, signs, np.array([psi]), zeros, closed_form) >= -REACH_SLACK
    assert srs.model_ik_at_reach(P, R, p, signs, psi, zeros, at_reach)
    np.testing.assert_array_equal(at_reach, closed_form)
    S_W = p + R @ P[_core.SRS_WRIST : _core.SRS_WRIST + 3] - P[_core.SRS_SHOULDER : _core.SRS_SHOULDER + 3]
    longest, shortest = np.sqrt(P[_core.SRS_K0] + P[_core.SRS_K]), np.sqrt(P[_core.SRS_K0] - P[_core.SRS_K])
    for distance in (longest * (1.0 + stretch), shortest * (1.0 - stretch)):
        moved = p + (distance / np.linalg.norm(S_W) - 1.0) * S_W
        margin = model_ik(om_arm.family, P, table, R, moved, signs, np.array([psi]), zeros, np.empty(7))
        assert margin < -REACH_SLACK
        assert srs.model_ik_at_reach(P, R, moved, signs, psi, zeros, at_reach)
        values = np.empty(3)
        branch_values(om_arm.family, P, at_reach, values)
        assert abs(values[1]) < 1e-12


@pytest.mark.parametrize("name", ["gen3", "sawyer"])
def test_lifted_residuals_detect_a_wrong_q1_q7_or_elbow(name):
    om_arm = derive_model(om.load_arm(name))
    P = om_arm.params
    rng = np.random.default_rng(8)
    for q in random_q(om_arm.real, 50, rng):
        (R, p, signs, psi), _, _ = _lifted_at(om_arm, q)
        x = np.array([q[0], q[6], q[3] + P[_core.SRS_THETA + 3]])
        for k in range(3):
            moved = x.copy()
            moved[k] += 0.1
            residual = srs.model_ik_lifted(P, R, p, signs, psi, *moved, np.empty(7))
            assert np.abs(residual).max() > 1e-6


@pytest.mark.parametrize("name", ["panda", "iiwa14", "gen3", "xarm7", "sawyer"])
def test_arm_angle_is_the_elbow_bend_direction_about_the_shoulder_wrist_line(name):
    """psi from the closed form's parameters equals psi computed from FK points directly."""
    om_arm = derive_model(om.load_arm(name))
    chain = om_arm.model.chain
    Q = random_q(om_arm.real, 200, np.random.default_rng(5))
    for q in Q:
        frames = [np.eye(4)]
        joints = iter(q)
        for row in chain.rows:  # the Sawyer's fixed row comes after joint 6
            frames.append(frames[-1] @ _row(row, 0.0 if row.kind is om.JointKind.FIXED else next(joints)))
        T = chain.T_root_base
        S, W = (T @ frames[1])[:3, 3], (T @ frames[5])[:3, 3]
        z4 = (T @ frames[3])[:3, 2]  # joint 4 turns about z of frame 3
        w_hat = (W - S) / np.linalg.norm(W - S)
        values = np.empty(3)
        branch_values(om_arm.family, om_arm.params, q, values)
        bend = np.cross(z4, w_hat) * (1 if values[1] >= 0 else -1)
        elbow = (T @ frames[3])[:3, 3] - S  # the elbow point lies on the bend side
        assert np.dot(bend, elbow - np.dot(elbow, w_hat) * w_hat) * om_arm.params[_core.SRS_BEND] > 0
        up, ref = np.array([0.0, 0.0, 1.0]), np.array([-1.0, 0.0, 0.0])
        v, c = np.cross(up, w_hat), np.dot(up, w_hat)
        K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
        n = (np.eye(3) + K + K @ K / (1 + c)) @ ref
        bend = bend * om_arm.params[_core.SRS_BEND]
        psi = np.arctan2(np.dot(np.cross(w_hat, n), bend), np.dot(n, bend))
        out = np.empty(1)
        redundancy_values(om_arm.family, om_arm.params, q, out)
        assert abs(wrap(out[0] - psi)) < 1e-12


def _row(row: om.DHRow, qi: float) -> np.ndarray:
    theta = row.theta + qi
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(row.alpha), np.sin(row.alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, row.a * ct],
            [st, ct * ca, -ct * sa, row.a * st],
            [0, sa, ca, row.d],
            [0, 0, 0, 1],
        ]
    )


@pytest.mark.parametrize("name", ["gen3", "sawyer"])
@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_lifted_terms_give_the_lifted_residuals_at_every_arm_angle(name, seed):
    """The torus memo's terms (model_lifted_terms), evaluated at an arm angle, are
    model_ik_lifted's residuals there with phi4 the elbow's root, in either ELBOW branch, at a
    random (q1, q7) and hand position (within and beyond the model's reach); and phi4 is the
    root it solves."""
    om_arm = derive_model(om.load_arm(name))
    P = om_arm.params
    rng = np.random.default_rng(seed)
    q = random_q(om_arm.real, 1, rng)[0]
    (R, p, signs, _), _, _ = _lifted_at(om_arm, q)
    p = p * rng.uniform(0.5, 1.5)
    q1, q7 = rng.uniform(-np.pi, np.pi, 2)
    for elbow in (-1, 1):
        signs = np.array([signs[0], elbow, signs[2]])
        terms = srs.model_lifted_terms(P, R, p, signs, q1, q7)
        for psi in rng.uniform(-np.pi, np.pi, 4):
            out = np.empty(7)
            residual = srs.model_ik_lifted(P, R, p, signs, psi, q1, q7, np.nan, out)
            c, s = np.cos(psi), np.sin(psi)
            shoulder = terms.shoulder[0] + terms.shoulder[1] * c + terms.shoulder[2] * s
            wrist = terms.wrist[0] + terms.wrist[1] * c + terms.wrist[2] * s
            np.testing.assert_allclose([shoulder, wrist, terms.elbow], residual, rtol=0, atol=1e-14)
            assert abs(wrap(terms.phi4 - P[_core.SRS_THETA + 3] - out[3])) < 1e-14


def test_lifted_terms_are_none_where_the_wrist_centre_is_the_shoulder():
    om_arm = derive_model(om.load_arm("sawyer"))
    P = om_arm.params
    R = np.eye(3)
    p = P[_core.SRS_SHOULDER : _core.SRS_SHOULDER + 3] - R @ P[_core.SRS_WRIST : _core.SRS_WRIST + 3]
    signs = np.array([1, 1, 1])
    assert srs.model_lifted_terms(P, R, p, signs, 0.0, 0.0) is None
    assert np.isnan(srs.model_ik_lifted(P, R, p, signs, 0.0, 0.0, 0.0, np.nan, np.empty(7)).shoulder)
