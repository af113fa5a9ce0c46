"""The damped Gauss-Newton refinement on the real arm's chain (``_core.polish``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant import _core
from tests.conftest import random_q

_SOLVERS: dict[str, om.OMSolver] = {}


def _solver(name: str) -> om.OMSolver:
    if name not in _SOLVERS:
        _SOLVERS[name] = om.OMSolver(name)
    return _SOLVERS[name]


def _polish(solver: om.OMSolver, T: np.ndarray, psi: float | None, q: np.ndarray) -> float:
    """polish q in place toward T (and psi) on the solver's real chain; the residual returned."""
    data = solver.solver_data()
    R, p = np.empty(9), np.empty(3)
    _core.flange_target(np.ascontiguousarray(T), data.T_base_root, data.T_tool_flange, R, p)
    if psi is None:
        return _core.polish(data.real_table, R, p, q, 20, None)
    return _core.polish(data.real_table, R, p, q, 20, _core.ArmAngleRow(data.params, data.model_table, psi))


def _psi_distance(solver: om.OMSolver, q: np.ndarray, psi: float) -> float:
    got = solver.configuration_of(q).redundancy[0]
    return abs(math.remainder(got - psi, 2.0 * math.pi))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(["panda", "ur5e", "gen3", "spherical", "xarm7", "sawyer"]),
    seed=st.integers(0, 2**32 - 1),
    offset=st.floats(1e-9, 1e-3),
    singular=st.booleans(),
)
def test_polish_converges_to_the_pose_and_arm_angle(name, seed, offset, singular):
    """From q + noise, FK(polished q) = FK(q) to 1e-12 and the arm angle to 1e-12, also with
    the wrist exactly singular (J loses rank there: the damped minimum-norm step)."""
    solver = _solver(name)
    rng = np.random.default_rng(seed)
    q = random_q(solver.arm, 1, rng)[0]
    if singular:  # the wrist's middle joint at the angle that aligns the outer wrist axes
        families = om.ik.families
        if solver.model_arm.family == families.SRS:
            q[5] = -solver.model_arm.params[_core.SRS_THETA + 5]
        else:
            q[4] = -solver.model_arm.params[_core.SD_THETA5]
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    psi = c.redundancy[0] if c.redundancy else None
    start = q + rng.normal(0.0, offset, q.shape)
    residual = _polish(solver, T, psi, start)
    assert residual <= 1e-12
    assert np.abs(solver.arm.fk(start) - T).max() <= 1e-12
    if psi is not None:
        assert _psi_distance(solver, start, psi) <= 1e-12


def test_polish_never_makes_q_worse():
    """A start it cannot improve (a pose out of reach) is returned no worse than it was."""
    solver = _solver("ur5e")
    q = random_q(solver.arm, 1, np.random.default_rng(3))[0]
    T = solver.arm.fk(q)
    T[:3, 3] *= 10.0  # far out of reach
    start = q.copy()
    before = np.linalg.norm(solver.arm.fk(start)[:3, 3] - T[:3, 3])
    _polish(solver, T, None, start)
    assert np.linalg.norm(solver.arm.fk(start)[:3, 3] - T[:3, 3]) <= before


def test_polish_rejects_a_q_that_does_not_fit_the_table():
    solver = _solver("panda")
    with pytest.raises(ValueError, match="polish"):
        _polish(solver, np.eye(4), None, np.zeros(6))
