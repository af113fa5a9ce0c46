"""OMSolver.solve's one-call path (``_core.Solver.solve_pose``): the same answers and the
same errors as the general path it short-cuts."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant import _core
from tests.conftest import random_q

pytestmark = pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)

ARMS = ("panda", "iiwa14", "gen3", "ur5e", "spherical")


@pytest.fixture(scope="module")
def solvers() -> dict[str, om.OMSolver]:
    return {name: om.OMSolver(name) for name in ARMS}


def _fields(solution: om.Solution) -> dict:
    values = {f.name: getattr(solution, f.name) for f in dataclasses.fields(solution)}
    values["q"] = values["q"].tolist()
    return values


@pytest.mark.parametrize("name", ARMS)
@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), flip=st.integers(0, 7))
def test_the_one_call_path_answers_as_the_general_path(solvers, name, seed, flip):
    """Every field equal, bit for bit, to the answer for the same pose in Fortran order (which
    the general path takes), in the configuration of a random q or another one; the same
    types; ok answers reach T."""
    solver = solvers[name]
    q = random_q(solver.arm, 1, np.random.default_rng(seed))[0]
    T = solver.arm.fk(q)
    c = solver.configuration_of(q)
    signs = tuple(s if (flip >> i) & 1 == 0 else -s for i, s in enumerate(c.signs))
    c = om.Configuration(signs, c.redundancy)
    one_call, general = solver.solve(T, c), solver.solve(np.asfortranarray(T), c)
    assert type(one_call) is om.Solution
    np.testing.assert_equal(_fields(one_call), _fields(general))  # NaN equals NaN here
    assert one_call.configuration is c
    assert type(one_call.q) is np.ndarray and one_call.q.dtype == np.float64 and one_call.q.flags.writeable
    for name_ in ("ok", "within_limits"):
        assert type(getattr(one_call, name_)) is bool
    assert type(one_call.iterations) is int and type(one_call.status) is str
    if one_call.ok:
        reached = solver.arm.fk(one_call.q)
        assert np.abs(reached[:3, 3] - T[:3, 3]).max() <= solver.tolerances[0]


def test_the_one_call_path_raises_what_the_general_path_raises(solvers):
    """A pose or configuration the one-call path does not take goes to the general path,
    which names the problem: same exception types and messages as with a hint given."""
    solver = solvers["panda"]
    q = random_q(solver.arm, 1, np.random.default_rng(0))[0]
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    skewed = T.copy()
    skewed[0, 1] += 1e-6
    reflected = T.copy()
    reflected[:3, 0] *= -1.0
    nan = T.copy()
    nan[1, 2] = np.nan
    bad_row = T.copy()
    bad_row[3, 0] = 1e-3
    cases = [
        (skewed, c, "rotation is not orthonormal"),
        (reflected, c, "determinant -1"),
        (nan, c, "NaN or inf"),
        (bad_row, c, "last row"),
        (T[:3], c, "shape"),
        (T.astype(np.complex128), c, "complex"),
        ("pose", c, "homogeneous transform"),
        (T, (1, 1, 1), "configuration must be a Configuration"),
        (T, om.Configuration((1, 1), (0.0,)), "needs 3 configuration signs"),
        (T, om.Configuration((1, 1, 1)), "needs 1 redundancy values"),
    ]
    for pose, configuration, message in cases:
        with pytest.raises(om.InvalidInput, match=message) as one_call:
            solver.solve(pose, configuration)
        with pytest.raises(om.InvalidInput) as general:
            solver.solve(pose, configuration, q_hint=q)
        assert str(one_call.value) == str(general.value)


def test_orthonormality_is_checked_with_the_one_tolerance(solvers):
    """The one-call path and validation.py take the same tolerance, defined once in C."""
    assert om.validation.ORTHONORMALITY_TOLERANCE == _core.ORTHONORMALITY_TOLERANCE == 1e-9
    solver = solvers["iiwa14"]
    q = random_q(solver.arm, 1, np.random.default_rng(1))[0]
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    for scale, accepted in ((1.0 + 0.4e-9, True), (1.0 + 0.6e-9, False)):
        scaled = T.copy()
        scaled[:3, 0] *= scale  # |R^T R - I|_00 = scale^2 - 1 (about 0.8e-9, 1.2e-9)
        if accepted:
            assert solver.solve(scaled, c).ok
        else:
            with pytest.raises(om.InvalidInput, match="not orthonormal"):
                solver.solve(scaled, c)


def test_a_solver_without_result_types_answers_none(solvers):
    """_core.Solver(data) alone (as other wrappers build it) leaves every solve to the
    caller; with the result types it answers a Solution, and None for a layout it does not take."""
    solver = solvers["panda"]
    q = random_q(solver.arm, 1, np.random.default_rng(2))[0]
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    assert _core.Solver(solver.solver_data()).solve_pose(T, c) is None
    typed = _core.Solver(solver.solver_data(), solution_type=om.Solution, configuration_type=om.Configuration)
    assert type(typed.solve_pose(T, c)) is om.Solution
    assert typed.solve_pose(np.asfortranarray(T), c) is None  # the general path's
    with pytest.raises(TypeError, match="both be types"):
        _core.Solver(solver.solver_data(), solution_type=om.Solution)
    with pytest.raises(TypeError, match="slot 'q'"):
        _core.Solver(solver.solver_data(), solution_type=int, configuration_type=om.Configuration)
