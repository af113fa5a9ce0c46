"""OMSolver.solve_from (csrc/redundancy/solve_from.c): the solution the arm moves to from its
previous joints, exact and in the configuration, the hinted solve's answer along a control
loop's small steps and after a jump, on arms of every search (fixed, circle, torus, an arm near
a family with a shoulder offset, a 6-DOF arm)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from tests.test_reach_envelope import solver

pytestmark = pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)

ARMS = ["panda", "iiwa14", "sawyer", "gen3", "ur5e", "tiago pro-like"]


@settings(max_examples=40, deadline=None)
@given(
    name=st.sampled_from(ARMS), seed=st.integers(0, 2**32 - 1), step=st.sampled_from([1e-4, 3e-3, 0.05, 1.0])
)
def test_a_step_from_the_previous_joints_is_exact_and_the_hinted_solves(name, seed, step):
    """From q_previous, the solve for the pose of joints moved by ``step`` (rad, a control
    tick's to a jump): ok exactly where the hinted solve is, exact to 1e-10 and in the
    configuration, and the hinted solve's root (the nearest to q_previous) but where another
    lies as near within rounding."""
    s = solver(name)
    arm = s.arm
    rng = np.random.default_rng(seed)
    q_previous = rng.uniform(np.maximum(arm.lower, -np.pi), np.minimum(arm.upper, np.pi))
    direction = rng.normal(size=arm.dof)
    q = q_previous + step * direction / np.linalg.norm(direction)
    T, c = arm.fk(q), s.configuration_of(q)
    moved, hinted = s.solve_from(T, c, q_previous), s.solve(T, c, q_hint=q_previous)
    assert moved.ok == hinted.ok
    if not moved.ok:
        return
    assert np.abs(arm.fk(moved.q) - T).max() < 1e-10 and s.holds(moved.q, c)
    if not np.allclose(moved.q, hinted.q, atol=1e-9):
        gap = np.linalg.norm(moved.q - q_previous) - np.linalg.norm(hinted.q - q_previous)
        assert 0.0 <= gap < 1e-9 or step == 1.0  # (a jump: the prediction's root, also beyond doubt)


def test_a_control_loop_follows_its_path():
    """Along a path of 200 small steps, each solve from the previous answer is exact and moves
    the joints no more than the path's own step does (twice, with room): no jump to another
    sheet. (It is the path's own joints but where two roots lie closer than a step: the Sawyer
    here at t = 0.56, 4e-4 rad apart, where it takes the one nearer the previous joints.)"""
    for name in ARMS:
        s = solver(name)
        arm = s.arm
        rng = np.random.default_rng(1)
        start = rng.uniform(np.maximum(arm.lower, -np.pi) + 0.3, np.minimum(arm.upper, np.pi) - 0.3)
        end = start + rng.uniform(-0.3, 0.3, arm.dof)
        c = s.configuration_of(start)
        previous = start
        for t in np.linspace(0.0, 1.0, 201)[1:]:
            q = (1.0 - t) * start + t * end
            if s.configuration_of(q).signs != c.signs:
                break
            moved = s.solve_from(
                arm.fk(q), om.Configuration(c.signs, s.configuration_of(q).redundancy), previous
            )
            assert moved.ok and np.abs(arm.fk(moved.q) - arm.fk(q)).max() < 1e-10, (name, t)
            assert np.abs(moved.q - previous).max() <= 2.0 * np.abs(end - start).max() / 200 + 1e-9, (name, t)
            previous = moved.q


def test_the_previous_joints_are_checked():
    s = solver("panda")
    T = s.arm.fk(np.zeros(7))
    c = s.configuration_of(np.full(7, 0.3))
    for bad, message in ((np.zeros(6), "q_previous"), (np.full(7, np.nan), "q_previous")):
        with pytest.raises(om.InvalidInput, match=message):
            s.solve_from(T, c, bad)
