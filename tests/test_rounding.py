"""Rounding is not geometry: URDFs written to 11-12 digits leave DH offsets of ~5e-13 m where
the arm has none (a Kinova Jaco2 refused for a d5 of 5.08e-13 m, TIAGo and Baxter for an a2
of 4.4e-13 m). A length within ``LENGTH_ROUNDING`` per metre of reach of zero never
changes the method an arm gets: the arm is solved through its nominal arm, which has it zero,
while its exact table verifies every answer. Refusals name the arm's own joints."""

from __future__ import annotations

import dataclasses
import math
import re
from functools import cache

import numpy as np
import pytest

import om_redundant as om
from om_redundant.ik import LENGTH_ROUNDING, derive_model
from om_redundant.ik.model_conditions import rounding_length
from om_redundant.kinematics import KinematicChain
from tests.conftest import check_exact, random_q, well_conditioned, with_offsets

#: (arm, joint row (0-based joint), field, the rounding, the value it stands for); the old code
#: gave each another method or a refusal.
ROUNDED = {
    "a4 (the wrist offset method)": ("ur5e", 3, "a", 3e-13, 0.0),
    "d5 of a spherical wrist (Jaco2)": ("ur5e", 4, "d", 5.08e-13, 0.0),
    "a2 of a 7-DOF shoulder (TIAGo, Baxter)": ("panda", 1, "a", 4.38e-13, 0.0),
    "a5 (dp on two wrist joints)": ("panda", 4, "a", -5e-13, 0.0),
    "a1 (the shoulder's torus)": ("panda", 0, "a", 2e-13, 0.0),
}


@cache
def solvers(case: str) -> tuple[om.OMSolver, om.OMSolver]:
    """The solver of the arm with the rounding, and of the same arm with the exact value."""
    name, joint, field, rounding, value = ROUNDED[case]
    arm = om.load_arm(name)
    return tuple(om.OMSolver(with_offsets(arm, **{f"joint{joint}": {field: v}})) for v in (rounding, value))


def method(solver: om.OMSolver) -> tuple:
    """What the arm gets: the family, the joint dp turns with, and whether the shoulder turns it."""
    return solver.model_arm.family_name, solver.model_arm.dp_joint, bool(solver.model_arm.shoulder.any())


@pytest.mark.parametrize("case", ROUNDED)
def test_rounding_never_changes_the_method(case):
    rounded, exact = solvers(case)
    assert method(rounded) == method(exact)
    _, joint, field, _, _ = ROUNDED[case]
    row = rounded.nominal.arm.chain.rows[rounded.nominal.arm.chain.joint_rows[joint]]
    assert getattr(row, field) == 0.0  # the nominal arm's
    row = rounded.arm.chain.rows[rounded.arm.chain.joint_rows[joint]]
    assert getattr(row, field) == ROUNDED[case][3]  # the real arm keeps its exact table


@pytest.mark.parametrize("case", ROUNDED)
def test_an_arm_with_rounding_solves_exactly(case):
    """Every root reaches the pose of the EXACT table (1e-10 m and rad) in c; q is found where
    well conditioned."""
    solver, _ = solvers(case)
    for q in random_q(solver.arm, 12, np.random.default_rng(7)):
        check_exact(solver, q, well_conditioned(solver, q))


def test_the_rounding_scales_with_the_arm():
    """A UR5e ten times its size: an a4 of 2e-9 m is rounding (within 1e-9 per metre of its
    reach, 16 m), on the UR5e itself geometry (its reach 1.6 m: the wrist offset method)."""
    ur5e = om.load_arm("ur5e")
    rows = [dataclasses.replace(r, a=10 * r.a, d=10 * r.d) for r in ur5e.chain.rows]
    large = ur5e.with_chain(ur5e.chain.replace_rows(rows), "ur5e-x10")
    assert rounding_length(large.chain) == pytest.approx(10 * rounding_length(ur5e.chain), rel=1e-12)
    assert rounding_length(ur5e.chain) == pytest.approx(
        LENGTH_ROUNDING * sum(math.hypot(r.a, r.d) for r in ur5e.chain.rows), rel=1e-12
    )
    offset = {"joint3": {"a": 2e-9}}
    assert "wrist offset" not in om.OMSolver(with_offsets(large, **offset)).model_arm.family_name
    assert "wrist offset a4" in om.OMSolver(with_offsets(ur5e, **offset)).model_arm.family_name


def test_derive_model_names_the_rounding_it_leaves_to_the_nominal_arm():
    arm = with_offsets(om.load_arm("panda"), joint1={"a": 4.38e-13})
    cause = r"a = 4.38e-13 m in the row of joint 2 \('joint2'\) is rounding of 0 \(within 1e-09 m per metre"
    with pytest.raises(om.ModelError, match=cause):
        derive_model(arm)


@pytest.mark.parametrize(
    "joint, value, cause",
    [
        # A twist 2e-3 rad off 90 deg, twice what the nominal arm snaps.
        (
            1,
            {"alpha": np.pi / 2 + 2e-3},
            r"joint 2 \('arm_left_joint2'\) and joint 3 \('arm_left_joint3'\) perpendicular .*"
            r"\(0.002 rad off\)",
        ),
    ],
)
def test_refusals_name_the_arms_own_joints(joint, value, cause):
    """With the model's prefix, never an internal index such as q0 or q2."""
    arm = with_offsets(om.load_arm("panda"), **{f"joint{joint}": value})
    arm = dataclasses.replace(arm, prefix="arm_left_")
    with pytest.raises(om.ModelError, match=cause) as refused:
        om.OMSolver(arm)
    assert not re.search(r"\bq\d", str(refused.value))


def test_rounding_left_by_merging_fixed_rows_is_zero_too():
    """A fixed row d = 0.2 m before joint 2, whose own row has d = -0.2 + 1e-13 m: merged, the
    nominal arm's d2 is 1e-13 m of rounding, which it zeroes (else its own model refused it)."""
    ur5e = om.load_arm("ur5e")
    rows = list(ur5e.chain.rows)
    rows[1] = dataclasses.replace(rows[1], d=-0.2 + 1e-13)
    rows.insert(1, om.DHRow(d=0.2, kind=om.JointKind.FIXED))
    arm = ur5e.with_chain(
        KinematicChain(tuple(rows), ur5e.chain.T_root_base, ur5e.chain.T_flange_tool), "merged"
    )
    solver = om.OMSolver(arm)
    assert solver.nominal.arm.chain.rows[1].d == 0.0 and method(solver) == method(om.OMSolver("ur5e"))
    for q in random_q(arm, 8, np.random.default_rng(3)):
        check_exact(solver, q, well_conditioned(solver, q))
