"""Bad input raises an error that names the problem; never a silently wrong answer."""

from __future__ import annotations

import dataclasses
import math

import mink
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant.ik import derive_model


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


@pytest.mark.parametrize("method", ["solve_batch", "solve_all_batch"])
def test_batch_input_is_checked(solver, pose, method):
    batch = getattr(solver, method)
    with pytest.raises(om.InvalidInput, match=r"\(M, 4, 4\)"):
        batch(pose, (1, 1, 1))
    poses = np.stack([pose, pose])
    poses[1, 2, 3] = np.nan
    with pytest.raises(om.InvalidInput, match=r"T\[1\] contains NaN"):
        batch(poses, (1, 1, 1))
    with pytest.raises(om.InvalidInput, match="-1 or \\+1"):
        batch(np.stack([pose]), (1, 0, 1))
    with pytest.raises(om.InvalidInput, match=r"signs must be one row or one row per pose \(2\), got 3 rows"):
        batch(np.stack([pose, pose]), [(1, 1, 1)] * 3)


_DEFECTS = {
    "not orthonormal": lambda T: T.__setitem__((0, 0), T[0, 0] + 1e-6),
    "determinant -1": lambda T: T.__setitem__((slice(None, 3), 2), -T[:3, 2]),
    r"last row": lambda T: T.__setitem__((3, 0), 1e-12),
    "NaN or inf": lambda T: T.__setitem__((1, 1), np.inf),
}


@settings(max_examples=40, deadline=None)
@given(m=st.integers(1, 300), data=st.data(), defect=st.sampled_from(sorted(_DEFECTS)))
def test_one_bad_pose_in_a_batch_is_named(solver, pose, m, data, defect):
    """The batch's check (one compiled pass over every pose) lets no bad pose through, and the
    message names the first bad one."""
    k = data.draw(st.integers(0, m - 1))
    poses = np.repeat(pose[None], m, axis=0)
    _DEFECTS[defect](poses[k])
    where = rf"T\[{k}\]" if m > 1 and defect != "last row" else "T"
    with pytest.raises(om.InvalidInput, match=rf"{where}.*{defect}"):
        solver.solve_batch(poses, (1, 1, 1))


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


# ---------------------------------------------------------------------------------------
# Issue 18, items 7 and 9: every malformed argument raises the library's error naming it,
# never another exception and never a silent conversion.


@pytest.fixture(scope="module")
def panda():
    return om.OMSolver("panda")


@pytest.mark.parametrize(
    "T, message",
    [
        ("abc", "got str 'abc'"),
        ({"R": 1}, "got a dict"),
        (None, "got None"),
        (np.eye(4, dtype=complex), "got complex numbers"),
        (np.eye(4, dtype=bool), "got booleans"),
        (np.zeros((4, 4), dtype=[("a", "f8")]), "got a structured array"),
        ([[1, 0, 0, 0], [0, 1, 0]], "got a list"),
        (np.full((4, 4), "1"), "got text"),
    ],
    ids=["str", "dict", "None", "complex", "bool", "structured", "ragged", "text"],
)
def test_a_pose_that_is_not_numbers_is_named(solver, T, message):
    with pytest.raises(om.InvalidInput, match="T must be a \\(4, 4\\) homogeneous transform.*" + message):
        solver.solve(T, C)
    with pytest.raises(om.InvalidInput, match=r"^T must be"):
        solver.solve_all(T, C)
    with pytest.raises(om.InvalidInput, match=r"^T must"):
        solver.solve_batch([T], C.signs)


def test_complex_poses_are_refused_not_truncated(solver, pose):
    """The imaginary part was dropped with a ComplexWarning; now refused, even when it is zero."""
    with pytest.raises(om.InvalidInput, match="complex numbers"):
        solver.solve(pose.astype(complex), C)
    with pytest.raises(om.InvalidInput, match="complex numbers"):
        solver.solve_batch(pose[None].astype(complex), C.signs)
    with pytest.raises(om.InvalidInput, match="complex numbers"):
        solver.arm.fk(np.zeros(6, dtype=complex))
    with pytest.raises(om.InvalidInput, match=r"q must be .* got a boolean among the numbers"):
        solver.arm.fk([0.1, True, 0.0, 0.0, 0.0, 0.0])


def test_an_empty_batch_is_refused(solver, panda):
    for T in (np.zeros((0, 4, 4)), [], np.zeros((0,))):
        with pytest.raises(om.InvalidInput, match=r"T holds no poses \(shape \(0,"):
            solver.solve_batch(T, C.signs)
    with pytest.raises(om.InvalidInput, match="T holds no poses"):
        panda.solve_batch(np.zeros((0, 4, 4)), (1, -1, 1), [0.3], q_hint=np.zeros((0, 7)))


def test_batch_rows_must_match_the_poses(solver, panda, pose):
    poses = np.stack([pose, pose, pose])
    with pytest.raises(om.InvalidInput, match=r"signs must be one row or one row per pose \(3\), got 2 rows"):
        solver.solve_batch(poses, [(1, 1, 1), (1, -1, 1)])
    with pytest.raises(om.InvalidInput, match="q_hint must have 3 rows, got 2"):
        solver.solve_batch(poses, C.signs, q_hint=np.zeros((2, 6)))
    T = panda.arm.fk(np.full(7, 0.3))
    with pytest.raises(om.InvalidInput, match=r"redundancy must have shape \(3, 1\)"):
        panda.solve_batch(np.stack([T, T, T]), (1, 1, 1), [[0.1], [0.2]])
    one_row = solver.solve_batch(poses, [(1, 1, 1)])  # one row holds for every pose
    np.testing.assert_array_equal(one_row.q, solver.solve_batch(poses, (1, 1, 1)).q)


def test_mink_se3_in_a_batch_is_refused_with_the_fix(solver, pose):
    """solve takes one SE3; a batch is an array, one np.stack away (the message says so)."""
    for poses in (
        [mink.SE3.from_matrix(pose), pose],
        (mink.SE3.from_matrix(pose),),
        mink.SE3.from_matrix(pose),
    ):
        with pytest.raises(om.InvalidInput, match=r"T must be \(M, 4, 4\) poses, got .*np\.stack"):
            solver.solve_batch(poses, C.signs)
    batch = solver.solve_batch([pose, pose], C.signs)  # a sequence of arrays is a batch
    np.testing.assert_array_equal(batch.q, solver.solve_batch(np.stack([pose, pose]), C.signs).q)


def test_a_6dof_batch_refuses_redundancy_values_like_solve(solver, pose):
    poses = np.stack([pose, pose])
    with pytest.raises(om.InvalidInput, match="needs 0 redundancy values"):
        solver.solve(pose, om.Configuration(C.signs, (0.5,)))
    for redundancy in (np.zeros((2, 1)), [0.5, 0.5], 0.5):
        with pytest.raises(om.InvalidInput, match=r"redundancy must have shape \(2, 0\) \(the arm has no"):
            solver.solve_batch(poses, C.signs, redundancy)
    assert solver.solve_batch(poses, C.signs, np.zeros((2, 0))).ok.all()


@pytest.mark.parametrize(
    "signs, message",
    [
        (1, "a sequence of -1 and \\+1, got int 1"),
        (None, "got None"),
        ("111", "got str"),
        ((np.True_, 1, 1), "-1 or \\+1, got a boolean among the numbers"),
        ((1, np.True_, 1), "-1 or \\+1, got a boolean among the numbers"),
        (np.array([True, True, True]), "got booleans"),
        ((1j, 1, 1), "got complex numbers"),
        (((1, 1), (1, 1)), "a sequence of -1 and \\+1, got shape \\(2, 2\\)"),
    ],
)
def test_configuration_signs_must_be_plus_or_minus_one(signs, message):
    with pytest.raises(om.InvalidInput, match="configuration signs must .*" + message):
        om.Configuration(signs)


def test_np_true_is_refused_as_a_sign_everywhere(solver, pose, panda):
    with pytest.raises(om.InvalidInput, match="boolean"):
        solver.solve_batch(pose[None], (np.True_, 1, 1))
    with pytest.raises(om.InvalidInput, match="booleans"):
        solver.solve_batch(pose[None], np.array([True, True, True]))
    with pytest.raises(om.InvalidInput, match="boolean"):
        om.RedundancyOptimizer(panda, branches=[(1, np.True_, 1)])


def test_redundancy_values_are_a_sequence_of_numbers():
    """The rule: a sequence of finite real numbers; a bare number and None are refused."""
    assert om.Configuration((1, 1, 1), (0.5,)).redundancy == (0.5,)
    assert om.Configuration((1, 1, 1), [np.float64(0.5)]).redundancy == (0.5,)
    assert om.Configuration((1, 1, 1), ()).redundancy == ()
    assert om.Configuration((1, 1, 1), np.array([0.5])).redundancy == (0.5,)
    for bad, message in [
        (0.5, "a sequence of real numbers \\(\\(\\) for none\\), got float 0.5; e.g. \\(0.5,\\)"),
        (np.float64(0.5), "got float64"),
        (None, "got None"),
        (True, "got True"),
        (np.array(0.5), "a sequence of numbers, got shape \\(\\)"),
        ("0.5", "got str '0.5'"),
        (("0.5",), "got text"),
        ((1j,), "got complex numbers"),
        (1j, "got complex"),
        ((True,), "got booleans"),
        ((0.5, True), "got a boolean among the numbers"),
        (((0.1,), (0.2,)), "a sequence of numbers, got shape \\(2, 1\\)"),
        ((np.inf,), "values must be finite"),
    ]:
        with pytest.raises(om.InvalidInput, match="configuration redundancy .*" + message):
            om.Configuration((1, 1, 1), bad)


def test_batch_redundancy_is_an_array_of_numbers(panda):
    T = panda.arm.fk(np.full(7, 0.3))
    for bad, message in [
        ("0.5", "got str '0.5'"),
        (["0.5"], "got text"),
        ([1j], "got complex numbers"),
        (0.5, "got float 0.5; e.g. \\(0.5,\\)"),
        (np.float64(0.5), "got float64"),
    ]:
        with pytest.raises(om.InvalidInput, match="redundancy must .*" + message):
            panda.solve_batch(T[None], (1, 1, 1), bad)
    one = panda.solve(T, om.Configuration((1, 1, 1), (0.5,))).q
    for good in ([0.5], (0.5,), np.array([0.5]), np.array([[0.5]])):
        np.testing.assert_array_equal(panda.solve_batch(T[None], (1, 1, 1), good).q[0], one)


def test_isclose_takes_a_configuration():
    with pytest.raises(om.InvalidInput, match="other must be a Configuration, got None"):
        C.isclose(None)
    with pytest.raises(om.InvalidInput, match="atol must be a finite number, got str"):
        C.isclose(C, atol="1e-9")


@pytest.mark.parametrize(
    "make, message",
    [
        (
            lambda: om.OMSolver(None),
            "arm must be an om.Arm, an arm name or the path of an arm file, got None",
        ),
        (lambda: om.OMSolver(123), "arm must be an om.Arm.*got int 123"),
        (lambda: om.load_arm(None), "arm must be an arm name or the path of an arm file, got None"),
        (
            lambda: om.OMSolver("ur5e", position_tolerance="1e-10"),
            "position_tolerance must be a finite number",
        ),
        (lambda: om.OMSolver("ur5e", orientation_tolerance=True), "orientation_tolerance .* got True"),
        (lambda: om.OMSolver("ur5e", scan_points="x"), "scan_points must be a finite number, got str 'x'"),
        (lambda: om.OMSolver("ur5e", scan_points=8.9), "scan_points must be a whole number, got 8.9"),
        (lambda: om.OMSolver("ur5e", scan_points=100_000), "scan_points must be at least 8 and at most 1024"),
        (lambda: om.OMSolver("ur5e", scan_points=10**400), "too large for a float"),
    ],
)
def test_solver_arguments_are_named(make, message):
    with pytest.raises(om.InvalidInput, match=message):
        make()


def test_scan_points_bounds_are_whole_numbers():
    assert om.OMSolver("ur5e", scan_points=64.0).scan_points == 64
    assert om.OMSolver("ur5e", scan_points=np.int32(om.ik.solver.MAX_SCAN_POINTS)).scan_points == 1024


def test_numbers_are_numbers(panda):
    with pytest.raises(om.InvalidInput, match="margin_weight must be a finite number, got str '1'"):
        om.RedundancyOptimizer(panda, margin_weight="1")
    with pytest.raises(om.InvalidInput, match="max_step must be a finite number, got str 'x'"):
        om.RedundancyOptimizer(panda, max_step="x")
    with pytest.raises(om.InvalidInput, match=r"grid_points must be a whole number, got 20\.5"):
        om.RedundancyOptimizer(panda, grid_points=20.5)
    with pytest.raises(om.InvalidInput, match="grid_points must be at least 16 and at most 100000"):
        om.RedundancyOptimizer(panda, grid_points=10**9)
    with pytest.raises(om.InvalidInput, match="Sphere center must be 3 finite numbers, got str 'abc'"):
        om.Sphere(center="abc", radius=0.1)
    with pytest.raises(om.InvalidInput, match="Sphere radius must be a finite number, got str"):
        om.Sphere([0, 0, 1], "0.1")
    with pytest.raises(om.InvalidInput, match="tolerance must be a finite number"):
        panda.arm.within_limits(np.zeros(7), tolerance="0")


def test_objects_of_the_wrong_type_are_named(panda):
    with pytest.raises(om.InvalidInput, match="arm must be an Arm, got str"):
        om.arm_mjcf("panda")
    with pytest.raises(om.InvalidInput, match="arm must be an Arm, got None"):
        derive_model(None)
    with pytest.raises(om.InvalidInput, match=r"model must be a mujoco\.MjModel, got str"):
        om.compare_mujoco_model(panda.arm, "panda.xml")
    with pytest.raises(om.InvalidInput, match="obstacles must be shapes"):
        om.Clearance.for_arm(panda.arm, 5)
    with pytest.raises(om.InvalidInput, match="obstacle_geoms must be a sequence of geom names"):
        om.Clearance(om.arm_model(panda.arm), panda.arm, "link7_capsule0")
    with pytest.raises(om.InvalidInput, match="configuration must be a Configuration, got a tuple"):
        panda.solve(panda.arm.fk(np.zeros(7)), (1, 1, 1))


# ---------------------------------------------------------------------------------------
# Hypothesis: malformed shapes and dtypes of poses, signs, joint vectors and redundancy
# values raise InvalidInput, never another exception.

_DTYPES = [np.float64, np.float32, np.int64, np.uint8, bool, complex, "U3", object, [("a", "f8")]]


@st.composite
def arrays_of_any_kind(draw):
    shape = tuple(draw(st.lists(st.integers(0, 5), max_size=3)))
    dtype = draw(st.sampled_from(_DTYPES))
    values = draw(st.lists(st.floats(-2, 2), min_size=int(np.prod(shape)), max_size=int(np.prod(shape))))
    array = np.zeros(shape, dtype=dtype)
    if array.dtype.names is None and array.size:
        flat = np.asarray(values).astype(array.dtype) if array.dtype != object else values
        array.reshape(-1)[:] = flat
    return array


_SCALARS = st.one_of(
    st.integers(-2, 2),
    st.floats(allow_nan=True, allow_infinity=True),
    st.complex_numbers(max_magnitude=2),
    st.booleans(),
    st.none(),
    st.text(max_size=3),
    st.just(np.True_),
    st.just(np.int64(-1)),
)
_NESTED = st.recursive(
    _SCALARS, lambda inner: st.lists(inner, max_size=4) | st.tuples(inner, inner), max_leaves=20
)
_ANYTHING = st.one_of(
    arrays_of_any_kind(), _NESTED, st.dictionaries(st.text(max_size=2), _SCALARS, max_size=2)
)


def _is_real_array(value, shape):
    try:
        array = np.asarray(value)
    except ValueError:
        return False
    return array.dtype.kind in "iuf" and array.shape == shape


@settings(max_examples=300, deadline=None)
@given(_ANYTHING)
def test_any_malformed_pose_raises_invalid_input(solver, value):
    try:
        solver.solve(value, C)
    except om.InvalidInput:
        return
    assert _is_real_array(value, (4, 4))  # accepted: it was a valid pose


@settings(max_examples=300, deadline=None)
@given(_ANYTHING)
def test_any_malformed_batch_raises_invalid_input(solver, pose, value):
    """In every argument of solve_batch: accepted only if None (redundancy, hint) or real numbers."""
    for args in (
        (value, C.signs),
        (pose[None], value),
        (pose[None], C.signs, value),
        (pose[None], C.signs, None, value),
    ):
        try:
            solver.solve_batch(*args)
        except om.InvalidInput:
            continue
        assert value is None or _is_real_array(value, np.shape(value))


@settings(max_examples=300, deadline=None)
@given(_ANYTHING)
def test_any_malformed_joint_vector_raises_invalid_input(solver, pose, value):
    for call in (solver.arm.fk, solver.configuration_of, lambda q: solver.solve(pose, C, q_hint=q)):
        try:
            call(value)
        except om.InvalidInput:
            continue
        valid = _is_real_array(value, np.shape(value)) and np.shape(value)[-1:] == (6,)
        assert valid or value is None  # q_hint=None: no hint


@settings(max_examples=300, deadline=None)
@given(_NESTED, _NESTED)
def test_any_malformed_configuration_raises_invalid_input(signs, redundancy):
    try:
        c = om.Configuration(signs, redundancy)
    except om.InvalidInput:
        return
    assert all(type(s) is int and s in (-1, 1) for s in c.signs)
    assert all(type(r) is float and math.isfinite(r) for r in c.redundancy)


@settings(max_examples=300, deadline=None)
@given(_SCALARS | _NESTED)
def test_any_malformed_number_raises_invalid_input(value):
    for call in (lambda x: om.Sphere([0, 0, 0], x), lambda x: C.isclose(C, x)):
        try:
            call(value)
        except om.InvalidInput:
            continue
        number = isinstance(value, int | float | np.integer) and not isinstance(value, bool)
        assert number and math.isfinite(value)


def test_stray_exceptions_of_odd_values_are_named():
    """Values that reached numpy or MuJoCo unchecked: each now an InvalidInput naming it."""
    arm = om.load_arm("panda")
    with pytest.raises(om.InvalidInput, match="configuration redundancy"):
        om.Configuration((1, 1, 1), (10**400,))
    for radius in (1e300, 1e-300):
        with pytest.raises(om.InvalidInput, match="radius must be from"):
            om.Clearance.for_arm(arm, [om.Sphere([0.5, 0.0, 0.5], 0.05)], radius=radius)
    clearance = om.Clearance.for_arm(arm, [om.Sphere([0.5, 0.0, 0.5], 0.05)])
    with pytest.raises(om.InvalidInput, match=r"q must have shape \(7,\)"):
        clearance.minimum(np.zeros((0, 7)))
    lower, upper = arm.lower.copy(), arm.upper.copy()
    lower[2], upper[3] = np.nan, -3.5
    with pytest.raises(om.InvalidInput, match="lower limits must be 7 numbers"):
        dataclasses.replace(arm, lower=lower)
    with pytest.raises(om.InvalidInput, match=r"joint 'joint4' has its lower limit -3\.0718 above"):
        dataclasses.replace(arm, upper=upper)
    with pytest.raises(om.InvalidInput, match="upper limits must be 7 numbers"):
        dataclasses.replace(arm, upper=arm.upper[:3])
