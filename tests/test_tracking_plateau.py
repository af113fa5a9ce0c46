"""Tracking on a flat objective: psi stays where it was (the tracking step's model has no
gain to take there), so that the joints, which follow one tick's step, are not sent across
the plateau by rounding (the iiwa14 example's 1.4 mm lag)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.redundancy.choice.result import RedundancyChoice

PLATEAU = 1e-6  # objective values within this of each other are flat
WINDOW = 41  # psi samples across the tracking window, checked against the choice
TURN = 2.0 * math.pi
STEP = 0.25  # rad: a larger joint step between neighbouring samples leaves the path
STEPS = 5  # ticks of a short path


@pytest.fixture(scope="module")
def optimizers():
    return {"iiwa14": om.RedundancyOptimizer(om.OMSolver("iiwa14"))}


def window_values(optimizer, T: np.ndarray, choice: RedundancyChoice) -> np.ndarray:
    """The objective (-inf where infeasible) on WINDOW psi across the tracking window around
    a choice at pose T: its solution path, continued outwards sample by sample, ending
    where a joint jumps by more than STEP (another path)."""
    solver, (centre,) = optimizer.solver, choice.configuration.redundancy
    psi = centre + np.linspace(-optimizer.max_step, optimizer.max_step, WINDOW)
    values = np.full(WINDOW, -np.inf)
    for side in (range(WINDOW // 2, -1, -1), range(WINDOW // 2, WINDOW)):
        hint = choice.solution.q
        for k in side:
            s = solver.solve(T, om.Configuration(choice.configuration.signs, (psi[k],)), q_hint=hint)
            if not s.ok or np.abs(s.q - hint).max() > STEP:
                break
            evaluation, hint = optimizer.objective.evaluate(s.q), s.q
            values[k] = evaluation.value if evaluation.feasible else -np.inf
    return values


def tracked_from(optimizer, q: np.ndarray) -> tuple[RedundancyChoice, RedundancyChoice, np.ndarray]:
    """The previous choice at q itself (its configuration, the exact solve of q's pose), the
    tracking choice from it at the same pose, and the window's values around q."""
    solver = optimizer.solver
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    solution = solver.solve(T, c, q_hint=q)
    assert solution.ok and np.abs(solution.q - q).max() < 1e-9
    ev = optimizer.objective.evaluate(solution.q)
    previous = RedundancyChoice(True, c, solution, ev.margin, ev.clearance, ev.value, ())
    return previous, optimizer.choose(T, previous), window_values(optimizer, T, previous)


def assert_exact(solver, choice, T):
    """The hand on T within the solver's tolerances (position 1e-10 m, orientation 1e-9)."""
    reached = solver.arm.fk(choice.solution.q)
    assert np.linalg.norm(reached[:3, 3] - T[:3, 3]) < solver.tolerances[0]
    assert np.abs(reached[:3, :3] - T[:3, :3]).max() < solver.tolerances[1]


@settings(max_examples=12, deadline=None)
@given(
    q4=st.floats(-2.0, -1.8),
    bent=st.tuples(st.floats(0.7, 1.2), st.floats(0.7, 1.2), st.sampled_from([-1.0, 1.0])),
    turns=st.lists(st.floats(-0.5, 0.5), min_size=4, max_size=4),
)
def test_on_a_flat_objective_psi_stays(optimizers, q4, bent, turns):
    """iiwa14 with its elbow (joint 4, which the self-motion does not move) binding the
    margin and every singularity beyond the term's cap: the objective is flat across the
    window, and tracking at the same pose returns the previous psi and joints."""
    optimizer = optimizers["iiwa14"]
    q2, q6, sign = bent
    q = np.array([turns[0], sign * q2, turns[1], q4, turns[2], sign * q6, turns[3]])
    previous, tracked, values = tracked_from(optimizer, q)
    assume(np.isfinite(values).all() and np.ptp(values) <= PLATEAU)  # flat
    assert tracked.ok and tracked.configuration.signs == previous.configuration.signs
    assert tracked.configuration.redundancy[0] == pytest.approx(
        previous.configuration.redundancy[0], abs=1e-12
    )
    assert np.abs(tracked.solution.q - q).max() < 1e-9
    assert_exact(optimizer.solver, tracked, optimizer.solver.arm.fk(q))


@settings(max_examples=12, deadline=None)
@given(
    q4=st.floats(-2.0, -1.8),
    bent=st.tuples(st.floats(0.7, 1.2), st.floats(0.7, 1.2), st.sampled_from([-1.0, 1.0])),
    turns=st.lists(st.floats(-0.5, 0.5), min_size=4, max_size=4),
    direction=st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3),
)
def test_along_a_path_on_a_plateau_psi_stays(optimizers, q4, bent, turns, direction):
    """The iiwa14 example's case: the hand moves (STEPS ticks of 1 mm) from a pose where the
    objective is flat in psi; tracking keeps psi wherever the window is still flat (within
    PLATEAU), puts the hand exactly on every target, and moves the joints a little."""
    optimizer = optimizers["iiwa14"]
    solver = optimizer.solver
    q2, q6, sign = bent
    q = np.array([turns[0], sign * q2, turns[1], q4, turns[2], sign * q6, turns[3]])
    move = np.array(direction)
    assume(np.linalg.norm(move) > 0.1)
    _, tracked, values = tracked_from(optimizer, q)
    assume(np.isfinite(values).all() and np.ptp(values) <= PLATEAU)  # flat at the start
    for k in range(1, STEPS + 1):
        T = solver.arm.fk(q)
        T[:3, 3] += 1e-3 * k * move / np.linalg.norm(move)
        step = optimizer.choose(T, tracked)
        assert step.ok and step.configuration.signs == tracked.configuration.signs
        moved = math.remainder(step.configuration.redundancy[0] - tracked.configuration.redundancy[0], TURN)
        assert abs(moved) < 1e-12 or np.ptp(window_values(optimizer, T, tracked)) > PLATEAU
        assert np.abs(step.solution.q - tracked.solution.q).max() < 0.05
        assert_exact(solver, step, T)
        tracked = step
