"""Bad input raises an error that names the problem; never a silently wrong answer."""

from __future__ import annotations

import mink
import numpy as np
import pytest

import om_redundant as om


@pytest.fixture(scope="module")
def solver():
    return om.OMSolver("ur5e")


@pytest.fixture(scope="module")
def pose(solver):
    return solver.arm.fk(np.array([0.3, -1.2, 1.0, -0.5, 0.8, 0.2]))


C = om.Configuration((1, 1, 1))


def bad(pose, fn):
    T = pose.copy()
    fn(T)
    return T


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda T: T[:3], r"\(4, 4\)"),
        (lambda T: bad(T, lambda X: X.__setitem__((0, 3), np.nan)), "NaN or inf"),
        (lambda T: bad(T, lambda X: X.__setitem__((1, 1), np.inf)), "NaN or inf"),
        (lambda T: bad(T, lambda X: X.__setitem__((0, 0), X[0, 0] + 1e-6)), "not orthonormal"),
        (lambda T: bad(T, lambda X: X.__setitem__((slice(None, 3), 0), -X[:3, 0])), "reflection"),
        (lambda T: bad(T, lambda X: X.__setitem__((3, 0), 1.0)), "last row"),
    ],
)
def test_bad_pose(solver, pose, make, message):
    with pytest.raises(om.InvalidInput, match=message):
        solver.solve(make(pose), C)


def test_mink_se3_is_accepted(solver, pose):
    sol_matrix = solver.solve(pose, C)
    sol_se3 = solver.solve(mink.SE3.from_matrix(pose), C)
    np.testing.assert_allclose(sol_matrix.q, sol_se3.q, atol=1e-12)


@pytest.mark.parametrize("signs", [(1, 0, 1), (1, 2, 1), (1.5, 1, 1), (True, 1, 1)])
def test_signs_outside_plus_minus_one(signs):
    with pytest.raises(om.InvalidInput, match="-1 or \\+1"):
        om.Configuration(signs)


def test_wrong_number_of_signs_or_redundancy(solver, pose):
    with pytest.raises(om.InvalidInput, match="needs 3 configuration signs"):
        solver.solve(pose, om.Configuration((1, 1)))
    with pytest.raises(om.InvalidInput, match=r"needs 0 redundancy values"):
        solver.solve(pose, om.Configuration((1, 1, 1), (0.3,)))
    with pytest.raises(om.InvalidInput, match="finite"):
        om.Configuration((1, 1, 1), (np.nan,))


@pytest.mark.parametrize(
    "q, message",
    [(np.zeros(5), r"shape \(6,\)"), (np.full(6, np.nan), "NaN or inf"), (np.zeros((2, 3)), "shape")],
)
def test_bad_joint_vectors(solver, pose, q, message):
    with pytest.raises(om.InvalidInput, match=message):
        solver.arm.fk(q)
    with pytest.raises(om.InvalidInput, match=message):
        solver.solve(pose, C, q_hint=q)


def test_batch_input_is_checked(solver, pose):
    with pytest.raises(om.InvalidInput, match=r"\(M, 4, 4\)"):
        solver.solve_batch(pose, (1, 1, 1))
    poses = np.stack([pose, pose])
    poses[1, 2, 3] = np.nan
    with pytest.raises(om.InvalidInput, match=r"T\[1\] contains NaN"):
        solver.solve_batch(poses, (1, 1, 1))
    with pytest.raises(om.InvalidInput, match="-1 or \\+1"):
        solver.solve_batch(np.stack([pose]), (1, 0, 1))


def test_unreachable_pose_says_so(solver, pose):
    far = pose.copy()
    far[:3, 3] = (3.0, 0.0, 0.5)
    for configuration in solver.configurations():
        sol = solver.solve(far, configuration)
        assert not sol.ok and sol.status == "unreachable"
        assert np.isnan(sol.q).all()
    batch = solver.solve_batch(np.stack([far, pose]), (1, 1, 1))
    assert batch.status[0] == "unreachable" and not batch.ok[0]


def test_bad_solver_settings():
    with pytest.raises(om.InvalidInput, match="position_tolerance"):
        om.OMSolver("ur5e", position_tolerance=-1.0)
    with pytest.raises(om.InvalidInput, match="scan_points"):
        om.OMSolver("ur5e", scan_points=2)
