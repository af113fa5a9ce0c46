"""The tracking step (issue 16): along a moving target the hand is exact, the choice feasible
and on its branch every tick; at a fixed pose it converges to the global optimiser's local
optimum; the vectorised clearance agrees with the pair-by-pair one; a singular self-motion
is a typed error."""

from __future__ import annotations

import math
import sys
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.control_rate import (
    ARM_HOMES,
    HOMES,
    MIN_CLEARANCE,
    PSI_GAP,
    VALUE_GAP,
    converged_gap,
    figure_eight,
    obstacles,
    turned,
)
from om_redundant.redundancy.choice.tracking import Tracker
from tests.conftest import in_threads, random_q

TICKS = 200  # of a figure eight, one lap
MAX_STEP = 0.005


@pytest.fixture(scope="module")
def optimizers():
    found = {}
    for name in HOMES:
        solver = om.OMSolver(name)
        hand = solver.arm.fk(HOMES[name])[:3, 3]
        found[name] = om.RedundancyOptimizer(
            solver, obstacles(hand, 3), min_clearance=MIN_CLEARANCE, max_step=MAX_STEP
        )
    return found


@pytest.mark.parametrize("name", list(HOMES))
def test_every_tick_of_a_moving_target_is_exact_feasible_and_on_its_branch(optimizers, name):
    """A figure eight past three obstacles: every tracking choice is ok, on the first
    choice's branch, within max_step of the previous psi, with clearance >= min_clearance,
    margins >= 0 and the hand on the target within the solver's tolerance."""
    optimizer = optimizers[name]
    arm = optimizer.solver.arm
    T_home = arm.fk(HOMES[name])
    choice = optimizer.choose(figure_eight(T_home, 0, TICKS))
    assert choice.ok, choice.reason
    for k in range(1, TICKS):
        T = figure_eight(T_home, k, TICKS)
        step = optimizer.choose(T, choice)
        assert step.ok and not step.branch_flipped, step.reason
        assert step.configuration.signs == choice.configuration.signs
        assert abs(turned(step, choice)) <= MAX_STEP + 1e-12
        assert step.margin >= 0.0 and step.clearance >= MIN_CLEARANCE
        assert arm.within_limits(step.solution.q)
        clearance = optimizer.objective.clearance.minimum(step.solution.q)
        assert clearance == pytest.approx(step.clearance, abs=1e-12)
        assert optimizer.objective.evaluate(step.solution.q).value == pytest.approx(step.value, abs=1e-12)
        reached = arm.fk(step.solution.q)
        assert np.linalg.norm(reached[:3, 3] - T[:3, 3]) < 1e-10
        assert np.abs(reached[:3, :3] - T[:3, :3]).max() < 1e-9
        assert np.abs(step.solution.q - choice.solution.q).max() < 0.1
        choice = step


@pytest.mark.parametrize("name", list(HOMES))
def test_the_steps_solves_are_the_full_solves_nearest_their_hints(optimizers, name):
    """The one-call step takes each exact solve's local root without the windowed scan for
    a nearer one where the root continues its path beyond doubt: its joints are those of the
    full solves (scan and bounded search), at the previous psi hinted by the previous joints,
    then at the new psi hinted by that, tick by tick along the figure eight."""
    optimizer = optimizers[name]
    solver = optimizer.solver
    T_home = solver.arm.fk(HOMES[name])
    choice = optimizer.choose(figure_eight(T_home, 0, TICKS))
    steps = 0
    for k in range(1, TICKS):
        T = figure_eight(T_home, k, TICKS)
        step = optimizer.choose(T, choice)
        if step.intervals == ():  # the one-call step (not the window search)
            steps += 1
            first = solver.solve(T, choice.configuration, q_hint=choice.solution.q)
            second = solver.solve(T, step.configuration, q_hint=first.q)
            assert second.ok
            assert np.abs(step.solution.q - second.q).max() <= 1e-12, k
        choice = step
    assert steps >= TICKS - 5


@pytest.mark.parametrize("name", list(HOMES))
def test_tracking_at_a_fixed_pose_converges_to_the_climbs_local_optimum(optimizers, name):
    """On random poses (from q itself), tracking until psi stops moving ends where the
    global optimiser's climb finds nothing better: within PSI_GAP rad or VALUE_GAP."""
    optimizer = optimizers[name]
    rng = np.random.default_rng(7)
    arm = optimizer.solver.arm
    checked = 0
    for q in rng.uniform(arm.lower, arm.upper, (12, arm.dof)):
        result = converged_gap(optimizer, q)
        if result is None:
            continue
        gap, gain = result
        assert gap <= PSI_GAP or gain <= VALUE_GAP, (q.tolist(), gap, gain)
        checked += 1
    assert checked >= 6


@settings(max_examples=30, deadline=None)
@given(u=st.lists(st.floats(0.0, 1.0), min_size=7, max_size=7), reach=st.floats(0.01, 1.0))
def test_distances_within_are_the_distances_capped_at_reach(optimizers, u, reach):
    """Clearance.distances_within(q, reach) = min(d_k(q), reach), and the gradients of the
    pairs nearer than reach are those of distances_and_gradients."""
    clearance = optimizers["panda"].objective.clearance
    arm = clearance.arm
    q = arm.lower + np.array(u) * (arm.upper - arm.lower)
    d, grad = clearance.distances_and_gradients(q)
    near, near_grad = clearance.distances_within(q, reach, gradient=True)
    assert np.allclose(near, np.minimum(d, reach), rtol=0.0, atol=1e-12)
    inside = d < reach
    assert np.allclose(near_grad[inside], grad[inside], rtol=0.0, atol=1e-12)
    assert not near_grad[~inside].any()


def test_a_stretched_arm_has_no_self_motion_tangent_and_says_so():
    """iiwa14 at the pose of q = 0 (straight up): choose meets a solution where psi does not
    move along the self-motion, and names it by a typed error (not numpy's LinAlgError)."""
    solver = om.OMSolver("iiwa14")
    with pytest.raises(om.SingularSelfMotion, match="does not move along the self-motion"):
        om.RedundancyOptimizer(solver).choose(solver.arm.fk(np.zeros(7)))


def test_the_tracking_step_carries_its_curvature(optimizers):
    """The step's curvature estimate is positive and finite, and is taken by the next step."""
    optimizer = optimizers["panda"]
    T = optimizer.solver.arm.fk(HOMES["panda"])
    first = optimizer.choose(T)
    assert math.isnan(first.curvature)
    step = optimizer.choose(T, first)
    assert step.ok and 0.0 < step.curvature < math.inf


def test_threads_sharing_an_optimiser_track_as_one(optimizers):
    """Four threads that share one optimiser (its tracking step's work arrays) each get, for
    their poses, exactly the tracking step it gives one call at a time; the interpreter
    switches threads as often as it can."""
    optimizer = optimizers["panda"]
    arm = optimizer.solver.arm
    poses = [arm.fk(q) for q in random_q(arm, 12, np.random.default_rng(5))]
    first = [optimizer.choose(T) for T in poses]
    cases = [(T, c) for T, c in zip(poses, first, strict=True) if c.ok]

    def step(T, previous):
        c = optimizer.choose(T, previous)
        return c.ok, c.configuration.redundancy, None if c.solution is None else c.solution.q.tobytes()

    alone = [step(T, c) for T, c in cases]
    differ = []

    def work(rows: range) -> None:
        for _ in range(200):
            differ.extend(i for i in rows if step(*cases[i]) != alone[i])

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        in_threads(work, len(cases))
    finally:
        sys.setswitchinterval(interval)
    assert len(cases) >= 8 and not differ


@pytest.mark.parametrize("joint", [7.0, -1.0, 2.5, math.nan, 1e300])
def test_the_tracking_kernel_refuses_a_singularity_that_is_not_a_joint(optimizers, joint):
    """ckernels.track_step reads q and dq/dpsi at each singularity's joint: an index outside
    [0, 7), or not an integer, is a named ValueError (not a read past the arrays); the
    optimiser's own arrays pass."""
    optimizer = optimizers["panda"]
    T = optimizer.solver.arm.fk(HOMES["panda"])
    first = optimizer.choose(T)
    tracker = Tracker(optimizer.solver, optimizer.objective, MAX_STEP)
    assert tracker.work.singular_joints.size  # (the term is weighted: its joints are read)
    args = (first.configuration.signs, first.configuration.redundancy[0], first.solution.q, math.nan)
    assert tracker.step(T, *args) is not None
    tracker.work.singular_joints[0] = joint
    with pytest.raises(ValueError, match="not a joint index"):
        tracker.step(T, *args)


KINKS = {  # u in [0, 1]^7 of the joint ranges: optima at a kink of the objective
    "panda": [0.5, 0.25, 0.8984375, 0.9, 0.25, 0.5, 0.5],
    "iiwa14": [0.5, 0.375, 0.375, 0.375, 0.375, 0.30859375, 0.30561921527085234],
}
SCAN_STEP, SCAN_POINTS = 2.5e-5, 400  # rad: the dense scan on each side of the optimum


@pytest.mark.parametrize("name", list(KINKS))
def test_at_a_kink_climb_and_tracking_find_the_local_optimum(name):
    """Poses whose optimum sits at a kink (two pieces of the objective crossing): the global
    choice and tracking from it at the same pose both end within PSI_GAP of the best psi of
    a dense scan of exact solutions along the path (SCAN_STEP apart), or within VALUE_GAP."""
    solver = om.OMSolver(name)
    arm = solver.arm
    T = arm.fk(arm.lower + np.array(KINKS[name]) * (arm.upper - arm.lower))
    optimizer = om.RedundancyOptimizer(solver)
    choice = optimizer.choose(T)
    assert choice.ok
    (psi,) = choice.configuration.redundancy
    best_value, best_psi = choice.value, psi
    for side in (-1.0, 1.0):
        hint = choice.solution.q
        for k in range(1, SCAN_POINTS):
            at = psi + side * k * SCAN_STEP
            s = solver.solve(T, om.Configuration(choice.configuration.signs, (at,)), q_hint=hint)
            if not s.ok or np.abs(s.q - hint).max() > 0.05:
                break
            evaluation, hint = optimizer.objective.evaluate(s.q), s.q
            if evaluation.feasible and evaluation.value > best_value:
                best_value, best_psi = evaluation.value, at
    tracked = choice
    for _ in range(200):
        step = optimizer.choose(T, tracked)
        assert step.ok and step.configuration.signs == choice.configuration.signs
        done = abs(turned(step, tracked)) <= 1e-12
        tracked = step
        if done:
            break
    for found in (choice, tracked):
        gap = abs(math.remainder(found.configuration.redundancy[0] - best_psi, 2 * math.pi))
        assert gap <= PSI_GAP or best_value - found.value <= VALUE_GAP, (gap, best_value - found.value)


def test_tracking_reaches_a_maximum_on_a_joint_limit():
    """The Panda, three obstacles: the objective rises along psi up to where a joint meets its
    limit. The full step there lands outside by rounding (margin -3.6e-10), and so does one
    more from it; the step within half of max_step, and so on, lands inside. Tracking ends on
    the limit, where the global climb from it gains nothing (before: 0.019 rad short, 0.012
    of value lost, re-choosing the same point afresh every tick)."""
    solver = om.OMSolver("panda")
    T_home = solver.arm.fk(HOMES["panda"])
    optimizer = om.RedundancyOptimizer(solver, obstacles(T_home[:3, 3], 3), min_clearance=MIN_CLEARANCE)
    q = np.array([-0.98568561, 1.56423033, -1.74244584, -1.53425468, -2.75815311, 0.5983977, 2.22175819])
    gap, gain = converged_gap(optimizer, q)
    assert gap < 1e-6 and gain < 1e-6


def test_tracking_holds_a_maximum_where_the_path_ends():
    """The xArm7, three obstacles: the objective rises along psi to where the solution path
    ends (a fold). Steps past it leave the path; shorter ones approach it and the last try,
    at psi itself, holds it (before: refused, the optimiser chose afresh 0.016 rad back and
    tracked up to the fold again, every five calls, for ever)."""
    solver = om.OMSolver("xarm7")
    T_home = solver.arm.fk(ARM_HOMES["xarm7"])
    optimizer = om.RedundancyOptimizer(solver, obstacles(T_home[:3, 3], 3), min_clearance=MIN_CLEARANCE)
    q = np.array([2.88593761, -1.32943195, 4.56384435, 2.03828794, -2.51689649, 0.35053673, -5.92731425])
    gap, gain = converged_gap(optimizer, q)
    assert gap < 1e-6 and gain < 1e-6


def test_without_rechoose_tracking_that_stops_says_so_and_sweeps_nothing(optimizers):
    """choose(..., rechoose=False): where tracking from the previous choice cannot follow a
    target that jumped, a choice that is not ok, saying why, without the fresh choice's sweep;
    where it can, the same choice as with rechoose."""
    optimizer = optimizers["panda"]
    T = optimizer.solver.arm.fk(HOMES["panda"])
    previous = optimizer.choose(T)
    jumped = T.copy()
    jumped[:3, 3] += [0.0, 0.3, -0.2]
    with mock.patch.object(type(optimizer), "_from_joints", side_effect=AssertionError("swept")):
        stopped = optimizer.choose(jumped, previous=previous, rechoose=False)
        near = T.copy()
        near[:3, 3] += [0.0, 0.001, 0.0]
        tracked = optimizer.choose(near, previous=previous, rechoose=False)
    signs = previous.configuration.signs
    assert not stopped.ok and stopped.reason.startswith(f"tracking from branch {signs}")
    assert stopped.intervals == () and stopped.solution is None
    again = optimizer.choose(jumped, previous=previous)
    assert again.ok and again.rechosen and again.reason.startswith(stopped.reason)
    with_rechoose = optimizer.choose(near, previous=previous)
    assert tracked.ok and not tracked.rechosen
    np.testing.assert_array_equal(tracked.solution.q, with_rechoose.solution.q)
