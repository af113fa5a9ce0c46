"""Choices from where the arm is (redundancy/reachable.py): never stuck on a reachable target,
joint travel weighed, the way there certified clear, every revolute joint at its nearest turn."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.redundancy.choice.reachable import WAY_MARGIN, nearest_turns
from tests.conftest import EXACT, random_q

OBSTACLES = [om.Sphere([0.45, 0.25, 0.55], 0.07), om.Capsule([0.3, -0.6, 0.35], [0.3, 0.6, 0.35], 0.03)]
MIN_CLEARANCE = 0.03


@pytest.fixture(scope="module")
def panda():
    return om.OMSolver("panda")


@pytest.fixture(scope="module")
def optimizer(panda):
    return om.RedundancyOptimizer(panda, OBSTACLES, min_clearance=MIN_CLEARANCE, max_step=0.005)


def exact(solver, q, T) -> bool:
    F = solver.arm.fk(q)
    return np.linalg.norm(F[:3, 3] - T[:3, 3]) < EXACT and np.abs(F[:3, :3] - T[:3, :3]).max() < 1e-9


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_a_target_that_jumps_is_never_refused_while_anything_is_feasible(panda, optimizer, seed):
    """Tracking from a choice at one random pose to another far away: the answer is ok exactly
    when the new pose has a feasible arm angle on some branch (intervals(T) not empty), then
    exact, feasible and re-chosen from the arm's joints with the reason said; a refusal names
    every branch, as intervals(T) does by having none."""
    rng = np.random.default_rng(seed)
    q_a, q_b = random_q(panda.arm, 2, rng)
    first = optimizer.choose(panda.arm.fk(q_a))
    if not first.ok:
        return
    T = panda.arm.fk(q_b)
    q_arm = first.solution.q
    choice = optimizer.choose(T, first, q_current=q_arm)
    assert choice.ok == bool(optimizer.intervals(T))
    if not choice.ok:
        assert choice.reason.startswith("no feasible arm angle: branch")
        assert all(f"branch {c.signs}" in choice.reason for c in panda.configurations())
        return
    assert exact(panda, choice.solution.q, T)
    assert panda.arm.within_limits(choice.solution.q) and choice.clearance >= MIN_CLEARANCE
    assert optimizer.clearance.minimum(choice.solution.q) >= MIN_CLEARANCE - 1e-12
    assert choice.travel == pytest.approx(np.linalg.norm(choice.solution.q - q_arm), abs=1e-12)
    if choice.rechosen:
        assert choice.reason.startswith(f"tracking from branch {first.configuration.signs}")
    assert choice.branch_flipped == (choice.configuration.signs != first.configuration.signs)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_a_fresh_choice_weighs_travel_and_certifies_its_way(panda, optimizer, seed):
    """From random joints, the fresh choice's way is clear where it says so (a dense sample of
    the segment keeps the floor); weighing travel more never makes it travel farther."""
    rng = np.random.default_rng(seed)
    q_now, q_target = random_q(panda.arm, 2, rng)
    clearance = optimizer.clearance
    if clearance.minimum(q_now) < 0.0:
        return  # (the arm inside an obstacle: not where it is)
    T = panda.arm.fk(q_target)
    fresh = optimizer.choose(T, q_current=q_now)
    assert fresh.ok == optimizer.choose(T).ok
    if not fresh.ok:
        return
    assert exact(panda, fresh.solution.q, T) and not fresh.rechosen
    frugal = om.RedundancyOptimizer(panda, clearance, min_clearance=MIN_CLEARANCE, travel_weight=10.0)
    thrifty = frugal.choose(T, q_current=q_now)
    if thrifty.way_clear == fresh.way_clear:
        assert thrifty.travel <= fresh.travel + 1e-9
    t = np.linspace(0.0, 1.0, 1001)[:, None]
    dense = clearance.minima(q_now + t * (fresh.solution.q - q_now)).min()
    floor = (
        min(MIN_CLEARANCE + WAY_MARGIN, clearance.minimum(q_now))
        - om.redundancy.objective.segment_clearance.ALONG_TOLERANCE
    )
    if fresh.way_clear:
        assert fresh.way_clearance >= floor and dense >= fresh.way_clearance - 1e-12
    else:
        assert "no candidate has a clear way" in fresh.reason


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_nearest_turns_are_whole_turns_within_the_limits(seed):
    """Every joint of the result is the arm's q moved by whole turns (revolute only), within
    the limits, and no other turn within the limits is nearer q_from."""
    arm = om.load_arm("gen3")  # continuous joints 1, 3, 5, 7 and limited 2, 4, 6
    rng = np.random.default_rng(seed)
    q = random_q(arm, 5, rng)
    q_from = rng.uniform(-10.0, 10.0, arm.dof)
    moved = nearest_turns(arm, q, q_from)
    turns = (moved - q) / (2.0 * math.pi)
    np.testing.assert_allclose(turns, np.round(turns), atol=1e-9)
    assert ((moved >= arm.lower) & (moved <= arm.upper)).all()
    for other in (moved - 2.0 * math.pi, moved + 2.0 * math.pi):
        inside = (other >= arm.lower) & (other <= arm.upper)
        assert (np.abs(moved - q_from) <= np.abs(other - q_from) + 1e-9)[inside].all()


def test_a_grid_sample_at_a_fold_ends_the_paths_beside_it():
    """A Sawyer pose whose sweep of branch (1, -1, -1) meets a solution exactly where psi does
    not move along the self-motion (its elbow folded at q4 = -pi, at a grid psi): the sample
    is left out, as a fold between samples is, and the fresh choice is made (it raised
    SingularSelfMotion out of the task's tick before)."""
    sawyer = om.OMSolver("sawyer")
    optimizer = om.RedundancyOptimizer(sawyer, OBSTACLES, min_clearance=MIN_CLEARANCE, max_step=0.005)
    T = sawyer.arm.fk(np.array([1.1668707874753528, 1.7442127842504407, 1.9643459663071914,
                                -1.9538021705322535, 1.4774805301385858, -2.4601554285576186,
                                -0.6987901064769053]))  # fmt: skip
    q_now = np.array([1.3362565136768723, -2.1003733675248952, -0.11754343633286402, -0.5780018957777315,
                      0.5117865081418325, 0.6578403675600484, 1.584364297195715])  # fmt: skip
    previous = optimizer.choose(sawyer.arm.fk(q_now), q_current=q_now)
    assert previous.ok and previous.configuration.signs == (1, -1, -1)
    choice = optimizer.choose(T, previous, q_current=q_now)
    assert choice.ok == bool(optimizer.intervals(T))
    if choice.ok:
        assert exact(sawyer, choice.solution.q, T)
