"""7-DOF arms with a shoulder offset a2 (the common normal of joints 2 and 3: Unitree G1 6.24 mm,
TIAGo Pro 20 mm) or a wrist offset a5 (of joints 5 and 6: Baxter 10 mm), issue 32: the nominal
arm zeroes them and the correction, on the left or the right, solves the OM system (9)
(ik/nominal.py, csrc/ik/near.c); every root exact, q among them and the hinted solve's answer."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant import _core
from om_redundant.ik import derive_model
from om_redundant.kinematics import KinematicChain
from tests.conftest import (
    check_exact,
    check_hinted_nearest,
    distance,
    nearest_distance,
    random_q,
    well_conditioned,
    wrap,
)

G1_OFFSET, TIAGO_PRO_OFFSET, BAXTER_OFFSET = 0.00624, 0.02, 0.01
#: (a2, a5): the G1's, TIAGo Pro's shoulder offset on the G1, Baxter's wrist offset on it, both.
OFFSETS = [(G1_OFFSET, 0.0), (TIAGO_PRO_OFFSET, 0.0), (0.0, BAXTER_OFFSET), (G1_OFFSET, BAXTER_OFFSET)]


@functools.cache
def g1_arm(a2: float, a5: float = 0.0) -> om.Arm:
    """The Unitree G1 29-DoF's left arm (Menagerie's g1_with_hands.xml, from the torso; DH rows
    rounded to the micrometre) with the shoulder offset a2 and the wrist offset a5."""
    right = np.pi / 2
    rows = (
        om.DHRow(a=0.013831, alpha=right, d=0.202648, theta=right),
        om.DHRow(a=a2, alpha=-right, d=0.0, theta=1.2915458),
        om.DHRow(a=-0.015783, alpha=right, d=-0.183718, theta=right),
        om.DHRow(a=-0.01, alpha=-right, d=0.001888, theta=right),
        om.DHRow(a=a5, alpha=right, d=0.138, theta=0.0),
        om.DHRow(a=0.046, alpha=right, d=0.0, theta=right),
        om.DHRow(a=0.0, alpha=0.0, d=0.0, theta=0.0),
    )
    tilt = -1.2915458
    base = np.eye(4)
    base[1:3, 1:3] = [[np.cos(tilt), -np.sin(tilt)], [np.sin(tilt), np.cos(tilt)]]
    base[:3, 3] = [0.003923, -0.058047, 0.202388]
    names = ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow", "wrist_roll", "wrist_pitch")
    names += ("wrist_yaw",)
    return om.Arm(
        name=f"g1-left-a2-{a2:g}-a5-{a5:g}",
        chain=KinematicChain(rows, base, np.eye(4)),
        joint_names=tuple(f"{name}_joint" for name in names),
        lower=np.array([-3.0892, -1.5882, -2.618, -1.0472, -1.97222, -1.61443, -1.61443]),
        upper=np.array([2.6704, 2.2515, 2.618, 2.0944, 1.97222, 1.61443, 1.61443]),
        prefix="left_",
    )


@functools.cache
def solver_of(a2: float, a5: float = 0.0) -> om.OMSolver:
    return om.OMSolver(g1_arm(a2, a5))


@pytest.mark.parametrize(("a2", "a5"), OFFSETS)
def test_the_nominal_arm_zeroes_the_offsets_and_corrects_on_the_larger_ones_side(a2, a5):
    """The model's own families refuse a2 (dp would turn with joints 1, 2 and 7) and a5 (with
    joints 6 and 7), naming the arm's joints; the nominal arm has them zero, the arm keeps its
    table, and the kernel takes the correction on the left (a2, in DH frame 0) or the right (a5,
    in the flange frame), where the larger one is, on the torus."""
    cause = r"shoulder offset a2 = .* \('left_shoulder_roll_joint'\).*nominal arm" if a2 else "depends on"
    with pytest.raises(om.ModelError, match=cause):
        derive_model(g1_arm(a2, a5))
    solver = solver_of(a2, a5)
    assert solver.nominal is not None
    assert (solver.nominal.shoulder_offset, solver.nominal.wrist_offset) == (a2, a5)
    assert solver.nominal.arm.chain.rows[1].a == solver.nominal.arm.chain.rows[4].a == 0.0
    assert (solver.arm.chain.rows[1].a, solver.arm.chain.rows[4].a) == (a2, a5)
    data = solver.solver_data()
    assert solver.nominal.deviation >= a2 + a5 and data.near_mixed and data.near_left == (a2 >= a5)
    assert data.mode == _core.TORUS  # q1 and q7 given, the fixed point in q2 or q6


@settings(max_examples=20, deadline=None)
@given(offsets=st.sampled_from(OFFSETS), q_seed=st.integers(0, 2**32 - 1))
def test_arms_with_shoulder_and_wrist_offsets_are_solved_exactly(offsets, q_seed):
    """At random in-limit q (10 per example, 200 in all): every root of solve_all(fk(q), c) reaches
    the pose in c; q is among them and the hinted solve returns q (on the G1 everywhere, on the
    others away from the singular boundaries)."""
    solver = solver_of(*offsets)
    for q in random_q(solver.arm, 10, np.random.default_rng(q_seed)):
        check_exact(solver, q, strict=offsets == OFFSETS[0] or well_conditioned(solver, q))


@settings(max_examples=12, deadline=None)
@given(
    offsets=st.sampled_from(OFFSETS[:3]), q_seed=st.integers(0, 2**32 - 1), sigma=st.sampled_from((0.01, 0.1))
)
def test_the_hinted_solve_returns_the_root_nearest_the_hint(offsets, q_seed, sigma):
    """The hinted solve's window on the torus (csrc/ik/torus.c: the root found and its fold
    partners sought across the window, a grid on the corrected system as fine as the whole
    torus' where the window is wider than one of its cells, Newton runs that give up beyond it or
    next to a root found) returns a root at least as near the hint (wrapped Euclidean distance) as
    every root of solve_all: at hints sigma from q (5 per example), and between the two roots of
    every close pair (within 0.15 rad), 0.3 and 0.45 of the way from one to the other."""
    solver = solver_of(*offsets)
    rng = np.random.default_rng(q_seed)
    for q in random_q(solver.arm, 5, rng):
        check_hinted_nearest(solver, q, rng, sigma, within=0.15)


def test_a_wide_window_finds_a_root_between_two_others():
    """Four roots of (T, c) strung along q1 on the arm with a wrist offset (0.16 to 1.4 rad apart):
    a hint 0.45 of the way between the first and the third (by q1) lies 0.20 rad from the second,
    q, and 0.26 from the first, which the local solve finds; the window about the hint returns q.
    (A window whose grid sampled the nominal arm's system, whose dips lie off the real arm's roots
    by more than the window's cells, kept the first.)"""
    solver = solver_of(0.0, BAXTER_OFFSET)
    arm = solver.arm
    q = np.array([-0.29129871675560, 1.85170794627972, 1.54211434576463, 1.42754343156551, 1.09277912160636,
                  -0.62652580525152, 1.04756876658342])  # fmt: skip
    T, c = arm.fk(q), solver.configuration_of(q)
    roots = sorted((root.q for root in solver.solve_all(T, c)), key=lambda root: root[0])
    assert len(roots) == 4 and distance(arm, roots[1], q) < 1e-9
    hint = roots[0] + 0.45 * wrap(roots[2] - roots[0])
    hinted = solver.solve(T, c, q_hint=hint)
    assert hinted.ok and distance(arm, hinted.q, q) < 1e-9
    assert np.linalg.norm(wrap(hinted.q - hint)) <= nearest_distance(roots, hint) + 1e-9


def test_the_redundancy_optimiser_chooses_exactly_on_a_shoulder_offset_arm():
    """RedundancyOptimizer on the G1's arm: a global choice at a reachable pose is ok, exact and
    within the limits, and tracking a step along a path stays exact."""
    solver = solver_of(G1_OFFSET)
    arm = solver.arm
    optimizer = om.RedundancyOptimizer(solver)
    q = np.array([0.3, 0.4, -0.2, 1.1, 0.2, -0.3, 0.1])
    T = arm.fk(q)
    choice = optimizer.choose(T)
    assert choice.ok and choice.solution.within_limits
    reached = arm.fk(choice.solution.q)
    assert np.abs(reached - T).max() <= 1e-10
    assert solver.holds(choice.solution.q, choice.configuration)
    T_next = T.copy()
    T_next[:3, 3] += [0.005, 0.0, -0.005]
    tracked = optimizer.choose(T_next, choice)
    assert tracked.ok and np.abs(arm.fk(tracked.solution.q) - T_next).max() <= 1e-10


def test_what_stays_refused_with_a_shoulder_offset():
    """A fixed row with a sideways offset between joints 6 and 7 that merges into neither (the
    bent Sawyer's kind): refused, naming the joints."""
    arm = g1_arm(G1_OFFSET)
    rows = list(arm.chain.rows)
    rows.insert(6, om.DHRow(a=0.01, d=0.05, kind=om.JointKind.FIXED))
    bent = arm.with_chain(
        KinematicChain(tuple(rows), arm.chain.T_root_base, arm.chain.T_flange_tool), "g1-bent"
    )
    cause = r"between joint 6 \('left_wrist_pitch_joint'\) and joint 7 \('left_wrist_yaw_joint'\) need a = 0"
    with pytest.raises(om.ModelError, match=cause):
        om.OMSolver(bent)
