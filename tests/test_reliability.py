"""No wrong answer marked ok, and the same answer to the same question, under adversarial input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks import adversarial as adv
from om_redundant import _core
from om_redundant.ik import BRANCH_BAND
from tests.conftest import random_q, run_python

_SOLVERS: dict[str, om.OMSolver] = {}


def _solver(name: str) -> om.OMSolver:
    if name not in _SOLVERS:
        _SOLVERS[name] = om.OMSolver(name)
    return _SOLVERS[name]


def _assert_exact(solver: om.OMSolver, q: np.ndarray, T: np.ndarray, c: om.Configuration) -> None:
    """q reaches T within the solver's tolerances (1e-10 m, 1e-10 rad), in configuration c (holds)."""
    reached = solver.arm.fk(q)
    position_tolerance, orientation_tolerance = solver.tolerances
    assert np.linalg.norm(reached[:3, 3] - T[:3, 3]) <= position_tolerance
    E = T[:3, :3].T @ reached[:3, :3]
    angle = math.atan2(
        0.5 * np.linalg.norm([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]]),
        0.5 * (np.trace(E) - 1.0),
    )
    assert angle <= orientation_tolerance
    assert solver.holds(q, c)


def _assert_solved(
    solver: om.OMSolver, T: np.ndarray, c: om.Configuration, q_hint: np.ndarray | None = None
) -> None:
    """solve (and, given q_hint, the hinted solve) is ok and exact in c, and solve_all holds
    roots, each exact in c."""
    for hint in (None,) if q_hint is None else (None, q_hint):
        sol = solver.solve(T, c, q_hint=hint)
        assert sol.ok, sol.status
        _assert_exact(solver, sol.q, T, c)
    roots = solver.solve_all(T, c)
    assert roots
    for root in roots:
        _assert_exact(solver, root.q, T, c)


def _branch_joint(solver: om.OMSolver, name: str) -> tuple[int, float] | None:
    """The joint j and offset theta with the branch quantity ``name`` = sin(q_j + theta)
    (None: the branch is not an angle, as the Spherical arm's prismatic elbow)."""
    families, params = om.ik.families, solver.model_arm.params
    srs = solver.model_arm.family == families.SRS
    if name == "WRIST":
        return (5, params[_core.SRS_THETA + 5]) if srs else (4, params[_core.SD_THETA5])
    if srs:
        return 3, params[_core.SRS_THETA + 3] - params[_core.SRS_PHI_STAR]
    if solver.model_arm.family == families.RRR_SPHERICAL_WRIST:
        return 2, params[_core.SD_THETA3] + params[_core.SD_BETA]
    return None


def _at_boundary(solver: om.OMSolver, rng: np.random.Generator, name: str, value: float) -> np.ndarray | None:
    """A random q whose branch quantity ``name`` is about ``value``, within the limits (None: none)."""
    q = random_q(solver.arm, 1, rng)[0]
    found = _branch_joint(solver, name)
    if found is None:
        return None
    joint, theta = found
    candidates = [k * math.pi - theta + (-1) ** k * value for k in range(-2, 3)]
    inside = [v for v in candidates if solver.arm.lower[joint] <= v <= solver.arm.upper[joint]]
    if not inside:
        return None
    q[joint] = inside[int(rng.integers(len(inside)))]
    return q


def _flipped(solver: om.OMSolver, c: om.Configuration, index: int) -> om.Configuration:
    """c with branch ``index`` flipped (psi read in the flipped ELBOW branch is psi + pi)."""
    signs = list(c.signs)
    signs[index] = -signs[index]
    turn = math.pi if solver.sign_names[index] == "ELBOW" else 0.0
    return om.Configuration(
        tuple(signs), tuple(math.remainder(r + turn, 2.0 * math.pi) for r in c.redundancy)
    )


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(["panda", "ur5e", "gen3", "spherical"]),
    seed=st.integers(0, 2**32 - 1),
    exponent=st.floats(-14.0, -2.0),
    side=st.sampled_from([-1.0, 1.0]),
)
def test_holds_takes_both_sides_within_the_band_and_one_beyond(name, seed, exponent, side):
    """holds(q, c): a branch quantity within BRANCH_BAND of zero holds both signs (psi read in
    the requested ELBOW branch), beyond it only its own."""
    solver = _solver(name)
    q = _at_boundary(solver, np.random.default_rng(seed), "WRIST", side * 10.0**exponent)
    if q is None:
        return
    c = solver.configuration_of(q)
    wrist = solver.sign_names.index("WRIST")
    joint, theta = _branch_joint(solver, "WRIST")
    value = math.sin(q[joint] + theta)
    assert solver.holds(q, c)
    assert solver.holds(q, _flipped(solver, c, wrist)) == (abs(value) <= BRANCH_BAND)


def test_holds_reads_psi_in_the_requested_elbow_branch():
    """A straight elbow holds both ELBOW branches, at psi in one and psi + pi in the other."""
    panda = _solver("panda")
    q = random_q(panda.arm, 1, np.random.default_rng(2))[0]
    q[3] = panda.model_arm.params[_core.SRS_PHI_STAR] - panda.model_arm.params[_core.SRS_THETA + 3]
    c = panda.configuration_of(q)
    elbow = panda.sign_names.index("ELBOW")
    flipped = _flipped(panda, c, elbow)
    assert panda.holds(q, c) and panda.holds(q, flipped)
    assert not panda.holds(q, om.Configuration(flipped.signs, c.redundancy))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(["gen3", "sawyer", "panda", "ur5e"]),
    seed=st.integers(0, 2**32 - 1),
    magnitude=st.floats(1e3, 1e300),
    sign=st.sampled_from([-1.0, 1.0]),
)
def test_a_huge_hint_never_makes_a_wrong_answer_ok(name, seed, magnitude, sign):
    """The 2 pi shift toward the hint is inexact at a huge magnitude: the vector returned is
    the one verified (issue: Gen3 with q_hint = 1e8 returned ok with a 3e-9 m miss), and a
    revolute hint beyond 1e4 rad is reduced exactly first (Sawyer started its local solve at
    a hint of 1.9e6 and returned q1 = 1.9e6, whose rounding MuJoCo's FK read as 1.6e-10 rad)."""
    solver = _solver(name)
    q = random_q(solver.arm, 1, np.random.default_rng(seed))[0]
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    hint = np.full(solver.arm.dof, sign * magnitude)
    sol = solver.solve(T, c, q_hint=hint)
    assert sol.ok
    _assert_exact(solver, sol.q, T, c)
    assert sol.position_error <= 1e-10
    redundancy = [c.redundancy] if c.redundancy else None
    batch = solver.solve_batch(T[None], c.signs, redundancy, q_hint=hint[None])
    assert batch.ok[0]
    _assert_exact(solver, batch.q[0], T, c)
    if magnitude > 1e4:  # such a hint is one angle: its exact reduction gives the same answer
        reduced = np.where(solver.arm.revolute, math.remainder(hint[0], 2.0 * math.pi), hint)
        np.testing.assert_array_equal(sol.q, solver.solve(T, c, q_hint=reduced).q)


def test_a_moderate_hint_still_picks_the_turn_nearest_it():
    gen3 = _solver("gen3")
    q = random_q(gen3.arm, 1, np.random.default_rng(4))[0]
    T, c = gen3.arm.fk(q), gen3.configuration_of(q)
    hint = q + 2.0 * np.pi * 1000.0 * gen3.arm.revolute * ~np.isfinite(gen3.arm.upper)
    sol = gen3.solve(T, c, q_hint=hint)
    np.testing.assert_allclose(sol.q, hint, atol=1e-6)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(["panda", "gen3", "sawyer"]),
    seed=st.integers(0, 2**32 - 1),
    turns=st.floats(1e3, 1e15),
)
def test_a_huge_arm_angle_is_one_angle(name, seed, turns):
    """psi and its exact reduction remainder(psi, 2 pi) are the same configuration, however
    large psi (issue: |psi| 1e7 ... 1e16 answered 'unreachable' for a quarter of reachable
    requests). Where psi + 2 pi k is exact (k below 2**20 or so), that is psi itself."""
    solver = _solver(name)
    q = random_q(solver.arm, 1, np.random.default_rng(seed))[0]
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    psi = c.redundancy[0] + 2.0 * math.pi * math.floor(turns)
    huge = om.Configuration(c.signs, (psi,))
    reduced = om.Configuration(c.signs, (math.remainder(psi, 2.0 * math.pi),))
    sol, same = solver.solve(T, huge), solver.solve(T, reduced)
    assert sol.status == same.status
    np.testing.assert_array_equal(sol.q, same.q)
    if turns < 2**20:
        assert sol.ok, sol.status
    if sol.ok:
        assert np.abs(solver.arm.fk(sol.q) - T).max() < 1e-10
        assert solver.holds(sol.q, huge)
        assert any(r.ok for r in solver.solve_all(T, huge))


def test_the_same_question_gets_the_same_answer_in_any_order():
    """Panda at a straight elbow (issue): solve(T, c) answered 'no solution' or ok depending on
    the call before it (memory read before it was written)."""
    panda = _solver("panda")
    q = np.array(
        [
            -1.5788187123196817,
            -1.596696927392707,
            -0.484056342759954,
            -0.4670024236530117,
            -2.0083071166232687,
            3.148148790369281,
            -1.7589137244825643,
        ]
    )
    T, c = panda.arm.fk(q), panda.configuration_of(q)
    first = panda.solve(T, c)
    answers = []
    for before in (lambda: panda.solve(T, c, q_hint=q), lambda: panda.solve_all(T, c), lambda: None):
        before()
        answers.append(panda.solve(T, c))
    for sol in answers:
        assert sol.status == first.status
        np.testing.assert_array_equal(sol.q, first.q)


@pytest.mark.parametrize("name", ["panda", "ur5e", "gen3", "sawyer"])
def test_repeated_random_calls_in_shuffled_order_agree(name):
    solver = _solver(name)
    rng = np.random.default_rng(11)
    Q = random_q(solver.arm, 40, rng)
    questions = []
    for q in Q:
        T, c = solver.arm.fk(q), solver.configuration_of(q)
        questions += [
            (T, c, None),
            (T, c, q + 0.01),
            (T, om.Configuration(tuple(-s for s in c.signs), c.redundancy), None),
        ]
    first = [solver.solve(T, c, q_hint=h) for T, c, h in questions]
    for k in rng.permutation(len(questions)):
        T, c, h = questions[k]
        again = solver.solve(T, c, q_hint=h)
        assert again.status == first[k].status
        np.testing.assert_array_equal(again.q, first[k].q)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(["panda", "fr3", "xarm7", "ur5e", "spherical", "gen3", "iiwa14"]),
    branch=st.sampled_from(["WRIST", "ELBOW"]),
    seed=st.integers(0, 2**32 - 1),
    exponent=st.floats(-14.0, -4.0),
    side=st.sampled_from([-1.0, 1.0]),
)
def test_a_pose_next_to_a_branch_boundary_is_solved(name, branch, seed, exponent, side):
    """T = FK(q) with a branch quantity (the wrist's sin(q6 + theta6) on a 7-DOF arm, sin(q5 +
    theta5) on a 6-DOF one; the elbow's) = +-10**exponent is solved exactly in
    configuration_of(q), and solve_all holds a root (issue: such reachable poses answered 'no
    solution in this configuration'). Within BRANCH_BAND of zero, the boundary contract: also
    in the configuration with that branch flipped (psi + pi across the ELBOW)."""
    solver = _solver(name)
    q = _at_boundary(solver, np.random.default_rng(seed), branch, side * 10.0**exponent)
    if q is None:
        return
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    joint, theta = _branch_joint(solver, branch)
    asked = [c]
    # Inside the band, not on its edge: the root found differs from q by the pose's conditioning
    # (about 1e-9 rad at 1e-7 of a singularity), which may carry it across the edge.
    if abs(math.sin(q[joint] + theta)) <= 0.9 * BRANCH_BAND:
        asked.append(_flipped(solver, c, solver.sign_names.index(branch)))
    for configuration in asked:
        sol = solver.solve(T, configuration)
        assert sol.ok, (configuration, sol.status)
        _assert_exact(solver, sol.q, T, configuration)
        roots = solver.solve_all(T, configuration)
        assert roots
        for root in roots:
            _assert_exact(solver, root.q, T, configuration)


# Reproducers of the full adversarial run on main (each a class of its own): T = FK(q) in
# configuration_of(q) (or with the branch `flip` flipped, inside the band) answered "no", or an
# empty solve_all, where a hinted solve succeeded.
BOUNDARY_CASES = {
    # UR5e wrist aligned to 4e-14: the model's q4 -+ q6 split is arbitrary there, the real arm's
    # is not (answered "unreachable"); refined from 16 splits.
    "aligned wrist": (
        "ur5e",
        [
            4.08800395442982,
            2.923436137458343,
            0.21681834660455035,
            -2.2927333383969364,
            3.7088968357278846e-14,
            -5.588953129439896,
        ],
        "WRIST",
    ),
    # UR5e wrist 1e-8, the root next to an edge of reach; FR3 wrist 1.2e-5, a close pair inside
    # one scan cell: a dip of the wrist's branch quantity between the touch samples.
    "dip at an edge of reach": (
        "ur5e",
        [
            -2.4666420879118114,
            4.733214997551882,
            -0.05475889758788943,
            -1.0985490913468254,
            -9.75347444178886e-09,
            -5.363831517637159,
        ],
        None,
    ),
    "dip inside a cell": (
        "fr3",
        [
            1.077230874552109,
            0.6560991050277667,
            0.9627056538586558,
            -0.26114008328784655,
            -1.5655766720082973,
            3.141605064305839,
            -1.8070379730078754,
        ],
        None,
    ),
    # xArm7 elbow straight to 2e-9: solve found it, solve_all did not.
    "straight elbow": (
        "xarm7",
        [
            -5.189328325861904,
            -0.4892420692385884,
            -1.1669504881461084,
            2.7417633021045806,
            0.08601718519443935,
            -1.3145989157792055,
            -3.8393949469980475,
        ],
        None,
    ),
    # Spherical arm, wrist centre 8e-13 from joint 1's axis (q1 arbitrary in the model), in the
    # flipped ARM configuration: refined from 16 starts of q1.
    "wrist centre on joint 1's axis": (
        "spherical",
        [
            2.349451607640476,
            -1.7834780187107178,
            0.0032392136219184684,
            0.29741663367015203,
            -1.720864743167523,
            -2.2766360998304513,
        ],
        "ARM",
    ),
    # UR5e ARM 5e-5: found by a secant from a touch sample, as a hint there would start it.
    "shoulder near its boundary": (
        "ur5e",
        [
            -1.1302200194054501,
            -1.9194882625861016,
            0.7283031793594419,
            4.943626336775099,
            -3.1346445042954687,
            -2.804784995894582,
        ],
        None,
    ),
}


@pytest.mark.parametrize("case", list(BOUNDARY_CASES))
def test_boundary_reproducers_are_solved(case):
    name, q, flip = BOUNDARY_CASES[case]
    solver = _solver(name)
    q = np.array(q)
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    if flip is not None:
        c = _flipped(solver, c, solver.sign_names.index(flip))
    _assert_solved(solver, T, c)


def test_the_wrist_centre_straight_below_the_shoulder_is_solved():
    """xArm7 with the model's wrist centre 4.7e-5 rad from straight below the shoulder (where
    psi's reference n(w_hat) = R(up -> w_hat) r is undefined), q within limits, T = FK(q):
    every configuration answered "unreachable" (python -m benchmarks.adversarial, the arm
    angle's singular half-line), as g turned by 2 pi between two scan samples. The circle
    search now splits such cells where the azimuth of w_hat about up turns fast."""
    xarm7 = _solver("xarm7")
    q = np.array(
        [
            1.3722485557456992,
            1.5276914922859586,
            1.4734833117554082e-05,
            0.30781086335256397,
            0.004579983274622279,
            2.6015994113708873,
            -2.444255838945311,
        ]
    )
    T, c = xarm7.arm.fk(q), xarm7.configuration_of(q)
    _assert_solved(xarm7, T, c)


_LINE_RUNS: dict[str, adv.ArmRun] = {}


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(["xarm7", "sawyer", "panda", "fr3"]),
    seed=st.integers(0, 2**32 - 1),
    exponent=st.floats(-14.0, -3.0),
    below=st.booleans(),
)
def test_a_pose_next_to_the_arm_angles_singular_half_line_is_solved(name, seed, exponent, below):
    """T = FK(q), q within limits with the model's wrist centre 10**exponent rad from straight
    below (or above) the shoulder, where psi's reference is undefined (the generator of
    ``python -m benchmarks.adversarial``): solve in configuration_of(q) is ok, exact by the
    real FK and holds the configuration (psi within its own rounding there, see
    OMSolver.holds), and solve_all holds a solution."""
    if name not in _LINE_RUNS:
        _LINE_RUNS[name] = adv.ArmRun(name, seed=0)
    run = _LINE_RUNS[name]
    run.rng = np.random.default_rng(seed)
    q = run.near_arm_angle_line(10.0**exponent, -1.0 if below else 1.0)
    assume(q is not None)
    solver = run.solver
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    _assert_solved(solver, T, c)


@pytest.mark.parametrize(
    ("name", "q"),
    [
        (  # 1.0e-11 rad from the line: the circle's root lay in the split pass's wide outer cell
            "xarm7",
            [
                0.7726982207265092,
                1.2524356149198066,
                4.0265196822346827e-13,
                0.03400481199607115,
                -1.4805740759432284,
                3.014254660235763,
                -1.6647416489432354,
            ],
        ),
        (  # 5.2e-11 rad (seed 5): a scan cell 7e-11 wide next to the pass held a root and a wrap
            "xarm7",
            [
                0.9476753339042272,
                1.0131117008836665,
                -6.283185307122622,
                -0.11547719716815809,
                1.6882915320043015,
                0.4185215822150059,
                1.9828976510300498,
            ],
        ),
        (  # 6.7e-14 rad: the torus chart's ends missed psi by 2.3-2.7 rad
            "sawyer",
            [
                1.2615779100692732,
                1.8741937259176593,
                -0.7836548171058206,
                -0.4364460456437585,
                1.0394722802208896,
                -2.0046151449996263,
                2.5900651816138875,
            ],
        ),
        (  # 9.7e-12 rad
            "sawyer",
            [
                -1.6440081759849647,
                1.8741083086082735,
                -0.7839024386647164,
                -0.43621510983980627,
                2.7842944172186286,
                0.9171589294783161,
                -0.6554943708260135,
            ],
        ),
        (  # 5.0e-13 rad
            "sawyer",
            [
                1.6749776632765085,
                -3.1589802113293373,
                -1.85557997279084,
                3.0179609294544916,
                1.1636204680862394,
                2.088779909413381,
                -2.008096640944234,
            ],
        ),
    ],
)
def test_a_pose_within_1e_11_rad_of_the_half_line_is_solved(name, q):
    """T = FK(q), q within limits, the model's wrist centre 1e-14 ... 1e-11 rad from straight
    below the shoulder (python -m benchmarks.adversarial, seed 0, 1,000 poses next to psi's
    half-line; the second xArm7 pose: seed 5): "no solution in this configuration" and
    solve_all empty. On the xArm7's circle the pass's split points covered only the azimuth's
    turn (offsets rho / v tan(k pi / 8)), and the cell beyond them, 1e11 times wider, held
    both the root and g's wrap, so its ends looked like a wrap: the split now goes on by
    doubling offsets out to the cell's ends; and a cell whose halving showed a wrap in one
    half went to the bracket whole (ends 3.11 and 0.06 rad: neither a root nor a wrap), now
    each half on its own. On
    the Sawyer's torus the chart's ends missed psi by 2-3 rad, out of the refinement's reach:
    psi is now searched along the real arm's self-motion (the closest pass, a scan in the
    azimuth, bisection to the last bit)."""
    solver = _solver(name)
    q = np.array(q)
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    _assert_solved(solver, T, c, q_hint=q)


def test_a_shoulder_start_may_need_the_flipped_wrist():
    """Spherical arm, wrist centre 3.2e-14 from joint 1's axis (ARM = -3.238e-14), the wrist
    at q5 = -3.08 (python -m benchmarks.adversarial, singular class, seed 0): solve said "no
    solution in this configuration" and solve_all was empty, as every start of q1 kept the
    model's wrist, from which the refinement crossed into the other WRIST sign. Each start
    of q1 now also tries the flipped wrist."""
    spherical = _solver("spherical")
    q = np.array(
        [
            -2.931959233290574,
            -0.9377734131111519,
            -0.011006323352723703,
            2.517356508937157,
            -3.0817076239277292,
            2.53662045303836,
        ]
    )
    T, c = spherical.arm.fk(q), spherical.configuration_of(q)
    _assert_solved(spherical, T, c)


@pytest.mark.parametrize(
    "name, q",
    [
        (  # the model's wrist centre 1.4e-11 rad straight below the shoulder
            "panda",
            [
                2.5322766795321816,
                1.2918364845492474,
                -1.3925042270764227e-11,
                -3.0428150134486214,
                1.5710014579302713,
                0.20106223384117075,
                -1.0528010010011744,
            ],
        ),
        (  # 2.0e-5 rad below
            "sawyer",
            [
                2.5235809388599737,
                1.260947568218835,
                2.375996532511514,
                -0.4537392172704337,
                -0.06513001537355505,
                1.8770479999918128,
                2.6019643612305865,
            ],
        ),
        (  # 6.0e-7 rad below; the hinted solve fails too
            "sawyer",
            [
                1.5892063303101063,
                1.8986574592233114,
                -0.7204169771390664,
                -0.5005292450411228,
                -1.6144795568825436,
                2.1767149092763836,
                -1.7232618128951618,
            ],
        ),
        (  # 4.6e-4 rad below: the loop's pass lay between its last trace point and its first
            "sawyer",
            [
                -2.208513976127911,
                1.8088456476318062,
                -1.0768487877746784,
                -0.22990247872155845,
                2.02126459993233,
                1.3086270522598,
                -3.117355677633442,
            ],
        ),
        (  # 3.6e-4 rad below: the same
            "sawyer",
            [
                -2.345416170247093,
                -3.8095,
                -0.4026951905978393,
                -1.7232469283637164,
                -2.9551461361113107,
                0.09312666680291232,
                3.5877880459184803,
            ],
        ),
    ],
)
def test_the_last_false_no_next_to_the_half_line(name, q):
    """The full adversarial run of session 11 (seed 0): 1 of 1,000 Panda and 5 of 1,000 Sawyer
    poses next to psi's singular half-line still answered "no solution in this configuration"
    in configuration_of(q) (the second Sawyer pose also hinted with q itself), and solve_all
    was empty: the model's search gave no candidate within 1e-2 rad of the line, or only
    candidates of another branch, and the Panda's loop folds back at 1e-11 rad from the line
    (psi turns by 2 pi there, unseen between points 0.05 rad apart). The configuration is now
    searched along the real arm's self-motion loops through its roots at other arm angles
    (csrc/ik/loop_search.c), where psi's crossings are bisected to the last bit. The two last
    Sawyer poses (the first full run with the loop search, seed 0) were "no" with it:
    the loop's pass by the line lay between the trace's last point and its start, where it
    closed, a step that was not searched."""
    solver = _solver(name)
    q = np.array(q)
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    _assert_solved(solver, T, c, q_hint=q)


#: A pose whose loop search split one segment without end (see the test below).
_FR3_LOOP_SPLIT = [
    0.15245130410114172,
    1.5150947881153707,
    -4.191332515613095e-06,
    -2.7908040309548,
    0.8969632085911192,
    4.198786440547809,
    1.1369654024446558,
]


def test_a_loop_segment_the_corrector_cannot_split_ends_its_search():
    """FR3 next to psi's singular half-line (the fourth pose of benchmarks.adversarial's
    ``ArmRun("fr3", 5).near_arm_angle_line``), configuration (1, 1, 1) at psi = 3 pi / 4:
    the loop search met a 0.87 rad segment whose chord midpoint the corrector took back to
    an end, and split that same segment again, one recursion deeper each time, until the
    process crashed (a stack overflow, before the budget of 1e5 midpoints). A midpoint that
    the corrector moves by more than a quarter of its segment is no split now. Run in a fresh
    interpreter (a crash must not take the suite with it): the roots of that configuration
    and of q's own are exact and hold their configuration, and q's own holds q."""
    script = f"""
import math
import numpy as np
import om_redundant as om
from om_redundant import _core
from tests.test_reliability import _assert_exact
solver = om.OMSolver("fr3")
q = np.array({_FR3_LOOP_SPLIT!r})
T = solver.arm.fk(q)
own = solver.configuration_of(q)
for c in (om.Configuration((1, 1, 1), (3.0 * math.pi / 4.0,)), own):
    for root in solver.solve_all(T, c):
        _assert_exact(solver, root.q, T, c)
assert any(np.abs(np.angle(np.exp(1j * (r.q - q)))).max() < 1e-6 for r in solver.solve_all(T, own))
print("solved")
"""
    result = run_python("-c", script)
    assert result.returncode == 0 and result.stdout.strip() == "solved", (
        result.returncode,
        result.stderr[-2000:],
    )


def test_psi_is_loose_where_the_model_wrist_centre_is_at_the_shoulder():
    """The Sawyer's model has equal upper arm and forearm (d3 = d5 = 0.4 m): folded, q4 = pi,
    its wrist centre is at the shoulder, psi's other singular point, beyond the joint limits.
    There |W - S| is rounding and psi's own rounding (|grad psi|_1 2^-51) spans tenths of a
    radian, so `holds` takes psi 1e-2 rad off; 1e-6 rad off the fold psi is pinned again."""
    solver = _solver("sawyer")
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = rng.uniform(solver.arm.lower, solver.arm.upper)
        q[3] = math.pi
        assert not solver.arm.within_limits(q)
        c = solver.configuration_of(q)
        assert solver.holds(q, om.Configuration(c.signs, (c.redundancy[0] + 1e-2,)))
        q[3] -= 1e-6
        c = solver.configuration_of(q)
        assert not solver.holds(q, om.Configuration(c.signs, (c.redundancy[0] + 1e-2,)))


def test_the_hinted_solve_returns_the_nearest_root_beyond_the_window():
    """FR3 at a straight elbow (benchmarks.seven_dof, seed 0): the hint 0.016 rad from q, the
    local root's twin 3.5 rad away, beyond the window's reach; the nearest root is q."""
    solver = _solver("fr3")
    q = np.array([0.52432708, 0.04154357, 0.22528842, -0.46925744, -1.64917994, 4.303563, -1.33344394])
    hint = np.array([0.51730921, 0.04767133, 0.23419927, -0.46371029, -1.65409267, 4.3084661, -1.33072576])
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    sol = solver.solve(T, c, q_hint=hint)
    assert sol.ok, sol.status
    _assert_exact(solver, sol.q, T, c)
    distance = [np.linalg.norm(np.angle(np.exp(1j * (r.q - hint)))) for r in solver.solve_all(T, c)]
    assert np.linalg.norm(np.angle(np.exp(1j * (sol.q - hint)))) <= min(distance) + 1e-9
