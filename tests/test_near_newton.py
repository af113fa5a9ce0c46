"""An arm near a family solves at about its family's cost (csrc/ik/near.c, om_near_secant): the
local root is the nominal arm's, then Newton's steps on the exact chain from it, not the secant
on G, each of whose evaluations is a fixed point of the correction. So an arm bent 1e-6 rad
takes as many residual evaluations per solve as the exact arm it is near, and its answers are
the real arm's, to rounding, in the requested configuration."""

from __future__ import annotations

import numpy as np
import pytest

import om_redundant as om
from benchmarks.near_family import bent
from tests.conftest import random_q

N = 100


def _pose_errors(arm: om.Arm, q: np.ndarray, T: np.ndarray) -> tuple[float, float]:
    reached = arm.fk(q)
    E = T[:3, :3].T @ reached[:3, :3]
    s = 0.5 * np.linalg.norm([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
    return float(np.linalg.norm(reached[:3, 3] - T[:3, 3])), float(np.arctan2(s, 0.5 * (np.trace(E) - 1.0)))


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_bent_arm_solves_with_its_family_s_evaluations(name: str) -> None:
    arm = om.load_arm(name)
    near = bent(arm, 1e-6, np.random.default_rng(0))
    exact, solver = om.OMSolver(arm), om.OMSolver(near)
    assert solver.nominal is not None and exact.nominal is None
    rng = np.random.default_rng(3)
    exact_evaluations, near_evaluations = [], []
    for q in random_q(arm, N, rng):
        exact_evaluations.append(exact.solve(arm.fk(q), exact.configuration_of(q)).iterations)
        T, c = near.fk(q), solver.configuration_of(q)
        solution = solver.solve(T, c)
        assert solution.ok
        position, orientation = _pose_errors(near, solution.q, T)
        assert position < 1e-13 and orientation < 1e-13
        assert solver.holds(solution.q, c)
        near_evaluations.append(solution.iterations)
    assert np.median(near_evaluations) <= np.median(exact_evaluations)
