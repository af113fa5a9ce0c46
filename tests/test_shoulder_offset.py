"""7-DOF arms with a shoulder offset a2 (the common normal of joints 2 and 3: Unitree G1 6.24 mm,
TIAGo Pro 20 mm), issue 32: the nominal arm zeroes it and the correction on the left solves the
OM system (9) (om/nominal.py, csrc/near.c); every root exact, q among them and the hinted
solve's answer."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.om import system
from tests.conftest import check_exact, random_q, well_conditioned

G1_OFFSET, TIAGO_PRO_OFFSET = 0.00624, 0.02


@functools.cache
def g1_arm(a2: float) -> om.Arm:
    """The Unitree G1 29-DoF's left arm (Menagerie's g1_with_hands.xml, from the torso; DH rows
    rounded to the micrometre) with the shoulder offset a2."""
    right = np.pi / 2
    rows = (
        om.DHRow(a=0.013831, alpha=right, d=0.202648, theta=right),
        om.DHRow(a=a2, alpha=-right, d=0.0, theta=1.2915458),
        om.DHRow(a=-0.015783, alpha=right, d=-0.183718, theta=right),
        om.DHRow(a=-0.01, alpha=-right, d=0.001888, theta=right),
        om.DHRow(a=0.0, alpha=right, d=0.138, theta=0.0),
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
        name=f"g1-left-a2-{a2:g}",
        chain=om.KinematicChain(rows, base, np.eye(4)),
        joint_names=tuple(f"{name}_joint" for name in names),
        lower=np.array([-3.0892, -1.5882, -2.618, -1.0472, -1.97222, -1.61443, -1.61443]),
        upper=np.array([2.6704, 2.2515, 2.618, 2.0944, 1.97222, 1.61443, 1.61443]),
        prefix="left_",
    )


@functools.cache
def solver_of(a2: float) -> om.OMSolver:
    return om.OMSolver(g1_arm(a2))


@pytest.mark.parametrize("a2", [G1_OFFSET, TIAGO_PRO_OFFSET])
def test_the_nominal_arm_zeroes_the_shoulder_offset_and_corrects_on_the_left(a2):
    """The model's own families refuse a2 (dp would turn with joints 1, 2 and 7), naming the arm's
    joints; the nominal arm has it zero, the arm keeps its table, and the kernel takes the
    correction on the left."""
    cause = r"shoulder offset a2 = .* \('left_shoulder_roll_joint'\).*nominal arm"
    with pytest.raises(om.ModelError, match=cause):
        om.derive_model(g1_arm(a2))
    solver = solver_of(a2)
    assert solver.nominal is not None and solver.nominal.shoulder_offset == a2
    assert solver.nominal.arm.chain.rows[1].a == 0.0 and solver.arm.chain.rows[1].a == a2
    assert solver.nominal.deviation >= a2 and solver.solver_data().near_left
    assert solver.solver_data().mode == system.TORUS  # a1 turns with q1, a6 with q7


@settings(max_examples=20, deadline=None)
@given(a2=st.sampled_from([G1_OFFSET, TIAGO_PRO_OFFSET]), q_seed=st.integers(0, 2**32 - 1))
def test_arms_with_a_shoulder_offset_are_solved_exactly(a2, q_seed):
    """At random in-limit q (10 per example, 200 in all): every root of solve_all(fk(q), c) reaches
    the pose in c, q is among them, and the hinted solve returns q."""
    solver = solver_of(a2)
    for q in random_q(solver.arm, 10, np.random.default_rng(q_seed)):
        check_exact(solver, q, strict=a2 == G1_OFFSET or well_conditioned(solver, q))


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
    """A shoulder offset with a wrist offset that makes dp turn with joints 6 and 7 (a5, Baxter's
    kind): refused, naming those joints."""
    arm = g1_arm(G1_OFFSET)
    rows = list(arm.chain.rows)
    rows[4] = dataclasses.replace(rows[4], a=0.01)
    bent = arm.with_chain(arm.chain.replace_rows(rows), "g1-a5")
    cause = r"depends on joint 6 \('left_wrist_pitch_joint'\), joint 7 \('left_wrist_yaw_joint'\)"
    with pytest.raises(om.ModelError, match=cause):
        om.OMSolver(bent)
