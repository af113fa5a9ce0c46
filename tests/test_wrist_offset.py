"""6-DOF arms whose wrist has a4 != 0: dp turns with q1 (om.six_dof_model.wrist_offset), solved exactly."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.near_family import bent, reversed_joint
from om_redundant.ik import derive_model
from tests.conftest import check_exact, random_q, well_conditioned, with_offsets

offsets = st.tuples(
    st.sampled_from(["ur5e", "spherical"]),
    st.floats(0.01, 0.15) | st.floats(-0.15, -0.01),
    st.sampled_from([0.0, 0.03, -0.05]),
)


@settings(max_examples=20, deadline=None)
@given(arm_a4_a5=offsets, q_seed=st.integers(0, 2**32 - 1))
def test_dp_of_a_wrist_offset_turns_with_q1_and_is_bounded_by_dp_max(arm_a4_a5, q_seed):
    """dp = -(a4 x4 + d5 z4 + a5 x5) with x4 perpendicular to z4: |dp| <= dp_max =
    hypot(a4, d5) + |a5| everywhere, equal to it without a5 (the model's check at construction
    compares the formula with the FK)."""
    name, a4, a5 = arm_a4_a5
    arm = with_offsets(om.load_arm(name), joint3={"a": a4}, joint4={"a": a5})
    model = derive_model(arm)
    assert model.dp_joint == 0 and "wrist offset a4" in model.family_name
    d5 = arm.chain.rows[arm.chain.joint_rows[4]].d
    assert model.dp_max == pytest.approx(np.hypot(a4, d5) + abs(a5), rel=1e-15)
    norms = np.linalg.norm(model.dp(random_q(arm, 64, np.random.default_rng(q_seed))), axis=1)
    assert norms.max() <= model.dp_max + 1e-15
    if a5 == 0.0:
        np.testing.assert_allclose(norms, model.dp_max, rtol=0, atol=1e-15)


@settings(max_examples=20, deadline=None)
@given(arm_a4_a5=offsets, q_seed=st.integers(0, 2**32 - 1))
def test_arms_with_a_wrist_offset_are_solved_exactly(arm_a4_a5, q_seed):
    """Accepted by OMSolver (its self-check passes); every root exact and in c, and away from
    the singular boundaries q among solve_all's roots and the hinted solve's answer."""
    name, a4, a5 = arm_a4_a5
    solver = om.OMSolver(with_offsets(om.load_arm(name), joint3={"a": a4}, joint4={"a": a5}))
    assert solver.nominal is None
    for q in random_q(solver.arm, 6, np.random.default_rng(q_seed)):
        check_exact(solver, q, well_conditioned(solver, q))


@pytest.mark.parametrize("deviation", [0.0, 1e-6, 1e-4])
def test_a_wrist_offset_near_a_family(deviation):
    """Like Menagerie's ARX L5 and i2rt YAM: a4 = 0.074, joint 3's axis reversed (tilted
    7e-6 rad), every twist moved by +-deviation: solved through the nominal arm, exactly."""
    arm = reversed_joint(with_offsets(om.load_arm("ur5e"), joint3={"a": 0.074}), 2, 7e-6)
    solver = om.OMSolver(bent(arm, deviation, np.random.default_rng(1)) if deviation else arm)
    assert solver.nominal is not None and "wrist offset a4" in solver.model_arm.family_name
    for q in random_q(solver.arm, 30, np.random.default_rng(5)):
        check_exact(solver, q, well_conditioned(solver, q))


def test_an_inner_fold_of_a_near_arm_is_solved():
    """A target where two roots in c meet (Jacobian's smallest singular value 4e-5) and the
    nominal arm's pair begins just farther out: the nominal arm has no root there, nor at the
    target pulled toward the base; pushed away from it, it has the seeds (near.PULL). Without
    them the arm failed its own self-check at this q."""
    arm = reversed_joint(with_offsets(om.load_arm("ur5e"), joint3={"a": 0.074}), 2, 7e-6)
    solver = om.OMSolver(arm)
    q = np.array([1.1850, -2.0369, -0.6810, 4.9043, -3.4286, 1.5480])
    assert np.linalg.svd(arm.jacobian(q), compute_uv=False)[-1] < 1e-4
    check_exact(solver, q, strict=True)


@pytest.mark.parametrize(
    "q",
    [
        [
            -5.4629771446174766,
            4.2095890664587658,
            -0.74255773747212173,
            -2.1922600807444299,
            -1.8530416858418177e-3,
            3.5335467014825577,
        ],
        [
            4.1455391977553235,
            0.30029330676969046,
            2.8671506651523146,
            2.721976349656507,
            3.1418255177434355,
            5.558870545992829,
        ],
        [
            0.75113424000742413,
            -6.0127621125296624,
            0.39370318309646457,
            4.4836991459160638,
            -1.3804595638713365e-3,
            -1.4662528016092553,
        ],
        [
            -1.9845450090520238,
            4.0740510683838425,
            -0.29833270002929213,
            3.641329298322751,
            3.1425235835183423,
            5.060774448800198,
        ],
        [
            5.3521282893960924,
            2.7230052744771323,
            -2.6590719889540089,
            5.5347068569879339,
            -3.6619624474883211e-3,
            1.6118339416996541,
        ],
    ],
)
def test_a_wrist_offset_at_a_nearly_singular_wrist(q):
    """q5 within 4e-3 rad of the wrist singularity (joints 4 and 6 parallel) with a4 = 0.074:
    z4 turns through nearly pi over a few 1e-3 rad of q1, and the target's island of reach on
    the circle is narrower than the scan's cells. Each was missed (no root, or only the other
    one) before the bands around the singular w (wrist_offset_bands.c, om_wrist_offset_candidates)."""
    solver = om.OMSolver(with_offsets(om.load_arm("ur5e"), joint3={"a": 0.074}))
    assert solver.nominal is None
    check_exact(solver, np.array(q), strict=True)


@settings(max_examples=30, deadline=None)
@given(
    a4=st.sampled_from([0.074, -0.05, 0.12]),
    q5=st.floats(-6.0, -1.0).map(lambda e: 10.0**e),
    side=st.sampled_from([1.0, -1.0]),
    flip=st.sampled_from([0.0, np.pi]),
    q_seed=st.integers(0, 2**32 - 1),
)
def test_every_root_is_found_at_a_nearly_singular_wrist(a4, q5, side, flip, q_seed):
    """|q5 - 0 or pi| from 1e-6 to 0.1 rad (joints 4 and 6 nearly parallel) on an exact UR5e
    with a wrist offset a4: q is among solve_all (the bands around the singular w)."""
    solver = _offset_solver(a4)
    q = random_q(solver.arm, 1, np.random.default_rng(q_seed))[0]
    q[4] = flip + side * q5
    check_exact(solver, q, strict=True)


@functools.cache
def _offset_solver(a4: float) -> om.OMSolver:
    return om.OMSolver(with_offsets(om.load_arm("ur5e"), joint3={"a": a4}))
