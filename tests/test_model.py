"""The offset-modified model arm: Theorem 2's conditions, dp, and the model's closed form."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.closed_form import branch_values, model_ik
from om_redundant.kinematics import flange_kernel
from tests.conftest import random_q, wrap


def modified(arm: om.Arm, joint: int, **changes) -> om.Arm:
    rows = list(arm.chain.rows)
    i = arm.chain.joint_rows[joint]
    rows[i] = dataclasses.replace(rows[i], **changes)
    return arm.with_chain(arm.chain.replace_rows(rows), arm.name)


@pytest.mark.parametrize(
    "joint, changes, message",
    [
        (3, {"kind": om.JointKind.PRISMATIC}, "joint 4 revolute"),
        (3, {"alpha": 0.0}, "non-parallel"),
        (4, {"alpha": np.pi}, "non-parallel"),
        (4, {"alpha": np.pi / 3}, "alpha_5 = \\+-90"),
        (3, {"a": 0.05}, "a4 = 0.05"),
        (1, {"kind": om.JointKind.PRISMATIC}, "joints 1 and 2 must be revolute"),
        (0, {"alpha": 0.0}, "perpendicular"),
        (2, {"kind": om.JointKind.PRISMATIC}, "no closed-form family"),
    ],
)
def test_arms_outside_theorem_2_are_refused_with_the_reason(joint, changes, message):
    arm = modified(om.load_arm("ur5e"), joint, **changes)
    with pytest.raises(om.ModelError, match=message):
        om.derive_model(arm)


def test_model_zeroes_only_a4_a5_d5():
    for name in ("spherical", "ur5e"):
        arm = om.load_arm(name)
        model = om.derive_model(arm).model
        jr = arm.chain.joint_rows
        for i, (real, mod) in enumerate(zip(arm.chain.rows, model.chain.rows, strict=True)):
            if i in (jr[3], jr[4]):
                assert mod.a == 0.0 and (i == jr[3] or mod.d == 0.0)
                assert (mod.alpha, mod.theta) == (real.alpha, real.theta)
            else:
                assert mod == real


@pytest.mark.parametrize("name, dp_max", [("spherical", 0.02), ("ur5e", 0.1)])
def test_dp_depends_on_joint_6_alone_and_its_norm_is_dp_max(name, dp_max):
    om_arm = om.derive_model(om.load_arm(name))
    assert om_arm.dp_joint == 5
    assert om_arm.dp_max == pytest.approx(dp_max, abs=1e-15)
    Q = random_q(om_arm.real, 300, np.random.default_rng(3))
    np.testing.assert_allclose(np.linalg.norm(om_arm.dp(Q), axis=1), dp_max, atol=1e-14)
    # Orientation is identical for equal joints (condition C1 of Theorem 1).
    np.testing.assert_allclose(om_arm.model.fk(Q)[:, :3, :3], om_arm.real.fk(Q)[:, :3, :3], atol=1e-15)


@pytest.mark.parametrize("name", ["spherical", "ur5e"])
@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_model_closed_form_inverts_model_fk(name, seed):
    """IK_model(FK_model(q), c(q)) = q, so the closed form is one-to-one off singularities."""
    om_arm = om.derive_model(om.load_arm(name))
    q = random_q(om_arm.real, 1, np.random.default_rng(seed))[0]
    table = om_arm.model.chain.table
    R, p = np.empty((3, 3)), np.empty(3)
    flange_kernel(table, q, R, p)
    values = np.empty(3)
    branch_values(om_arm.family, om_arm.params, q, values)
    signs = np.where(values < 0, -1, 1)
    out = np.empty(6)
    assert model_ik(om_arm.family, om_arm.params, table, R, p, signs, np.zeros(6), out) >= 0.0
    diff = out - q
    diff[om_arm.real.revolute] = wrap(diff[om_arm.real.revolute])
    assert np.abs(diff).max() < 1e-9
