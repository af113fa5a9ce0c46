"""The reach envelope (om_redundant/ik/reach_envelope.py): a pose it refuses has no solution in
any branch at any arm angle (checked by solve_all), a pose the arm takes is never refused, and
the optimiser answers an out-of-reach target at once, as its sweep would."""

from __future__ import annotations

import functools
import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.ik.kernel_data import flange_target
from om_redundant.ik.reach_envelope import COARSE, ReachEnvelope
from tests.test_shoulder_wrist_offsets import BAXTER_OFFSET, TIAGO_PRO_OFFSET
from tests.test_shoulder_wrist_offsets import solver_of as offset_solver

ARMS = ["panda", "iiwa14", "xarm7", "gen3", "sawyer", "tiago pro-like", "baxter-like"]


@functools.cache
def solver(name: str) -> om.OMSolver:
    if name == "tiago pro-like":  # a shoulder offset a2, near its nominal arm
        return offset_solver(TIAGO_PRO_OFFSET)
    if name == "baxter-like":  # a wrist offset a5
        return offset_solver(0.0, BAXTER_OFFSET)
    return om.OMSolver(name)


def random_q(arm: om.Arm, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(np.maximum(arm.lower, -np.pi), np.minimum(arm.upper, np.pi))


@settings(max_examples=60, deadline=None)
@given(name=st.sampled_from(ARMS), seed=st.integers(0, 2**32 - 1))
def test_a_pose_the_arm_takes_is_never_refused(name, seed):
    s = solver(name)
    assert ReachEnvelope(s).beyond(s.arm.fk(random_q(s.arm, seed))) is None


@settings(max_examples=25, deadline=None)
@given(name=st.sampled_from(ARMS), seed=st.integers(0, 2**32 - 1), push=st.floats(0.05, 0.6))
def test_a_refused_pose_has_no_solution_anywhere(name, seed, push):
    """A pose moved off one the arm takes: where the envelope refuses it, solve_all finds no
    root in any branch at 8 arm angles, and the optimiser says why, with no interval."""
    s = solver(name)
    T = s.arm.fk(random_q(s.arm, seed))
    direction = np.random.default_rng(seed).normal(size=3)
    T[:3, 3] += push * direction / np.linalg.norm(direction)
    beyond = ReachEnvelope(s).beyond(T)
    if beyond is None:
        return
    for signs, psi in itertools.product(itertools.product((1, -1), repeat=3), np.linspace(-3.0, 3.0, 8)):
        assert s.solve_all(T, om.Configuration(signs, (float(psi),))) == []
    choice = om.RedundancyOptimizer(s).choose(T)
    assert not choice.ok and "out of reach" in choice.reason and choice.intervals == ()


@settings(max_examples=40, deadline=None)
@given(name=st.sampled_from(ARMS), seed=st.integers(0, 2**32 - 1), push=st.floats(0.0, 1.5))
def test_the_coarse_look_answers_as_every_node_does(name, seed, push):
    """beyond looks at every COARSE-th node first; its answer is the whole grid's, reachable
    poses and poses pushed out alike (the whole grid's gap is at most the coarse one's)."""
    s = solver(name)
    envelope = ReachEnvelope(s)
    T = s.arm.fk(random_q(s.arm, seed))
    direction = np.random.default_rng(seed).normal(size=3)
    T[:3, 3] += push * direction / np.linalg.norm(direction)
    data = s.solver_data()
    R, p = flange_target(T, data.T_base_root, data.T_tool_flange)
    gap = envelope.gap(R, p)
    assert gap <= envelope.gap(R, p, COARSE)
    assert envelope.beyond(T) == (gap if gap > envelope.slack else None)


def test_a_pose_far_out_is_refused_on_every_arm_and_the_sweep_agrees(monkeypatch):
    """A target 2 m beyond the hand's home pose is refused by every 7-DOF arm's envelope; the
    optimiser's answer is the same with the envelope taken away (its sweep then finds no
    feasible arm angle either), only slower."""
    for name in ARMS:
        s = solver(name)
        T = s.arm.fk(random_q(s.arm, 0))
        T[:3, 3] *= 1.0 + 2.0 / np.linalg.norm(T[:3, 3])
        optimizer = om.RedundancyOptimizer(s)
        assert optimizer._reach.beyond(T) > optimizer._reach.slack
        quick = optimizer.choose(T)
        monkeypatch.setattr(optimizer._reach, "beyond", lambda T: None)
        swept = optimizer.choose(T)
        monkeypatch.undo()
        assert not quick.ok and not swept.ok and quick.intervals == swept.intervals == ()
        assert "out of reach" in quick.reason and "no solution at any" in swept.reason


def test_a_six_dof_arm_is_left_to_its_solver():
    far = np.eye(4)
    far[:3, 3] = 10.0
    assert ReachEnvelope(om.OMSolver("ur5e")).beyond(far) is None
