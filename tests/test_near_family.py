"""Arms NEAR a closed-form family (issue 17, item 2): twists off 0/90/180 deg by 1e-8 ... 1e-3
rad, reversed axes, fixed rows between joints; solved exactly through the nominal arm
(ik/nominal.py, csrc/ik/near.c), or refused at construction with a ModelError naming the cause."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.near_family import bent, cases, fixed_row_between, reversed_joint
from om_redundant import _core
from om_redundant.ik.nominal import NEAR_TWIST, nominal_arm
from tests.conftest import EXACT, check_exact, random_q, well_conditioned, wrap


@cache
def bent_solver(name: str, exponent: float, seed: int) -> om.OMSolver:
    return om.OMSolver(bent(om.load_arm(name), 10.0**exponent, np.random.default_rng(seed)))


@settings(max_examples=40, deadline=None)
@given(
    name=st.sampled_from(["ur5e", "panda"]),
    exponent=st.sampled_from([-8.0, -7.0, -6.0, -5.0, -4.0, -3.5, -3.0]),
    seed=st.integers(0, 3),
    q_seed=st.integers(0, 2**32 - 1),
)
def test_twist_deviations_are_solved_exactly(name, exponent, seed, q_seed):
    """Every joint row's twist moved by +-10^exponent rad: accepted through the nominal arm;
    every root exact and in c; away from the singular boundaries q is found (solve_all and the
    hinted solve)."""
    solver = bent_solver(name, exponent, seed)
    arm = solver.arm
    assert solver.nominal is not None
    for q in random_q(arm, 4, np.random.default_rng(q_seed)):
        check_exact(solver, q, well_conditioned(solver, q))


@given(unit=st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6), exponent=st.floats(-8.0, -3.0))
@settings(max_examples=40, deadline=None)
def test_nominal_arm_is_the_arm_in_nominal_coordinates(unit, exponent):
    """The exact chain at flip * q is the real arm at q (bit for bit up to rounding), the
    nominal arm within its snapped twists; every twist of the nominal arm is a right angle."""
    arm = reversed_joint(bent(om.load_arm("ur5e"), 10.0**exponent, np.random.default_rng(0)), 2, 1e-5)
    nominal = nominal_arm(arm)
    q = -np.pi + 2 * np.pi * np.array(unit)
    assert list(nominal.flip) == [1, 1, -1, 1, 1, 1]
    np.testing.assert_allclose(nominal.exact.fk(nominal.flip * q), arm.fk(q), rtol=0, atol=1e-15)
    np.testing.assert_allclose(nominal.arm.fk(nominal.flip * q), arm.fk(q), rtol=0, atol=30 * NEAR_TWIST)
    for row in nominal.arm.chain.rows:
        assert row.alpha in (0.0, np.pi / 2, -np.pi / 2)
    assert nominal.arm.chain.dof == 6 and len(nominal.arm.chain.rows) == 6


@pytest.mark.parametrize(
    "arm",
    [
        reversed_joint(om.load_arm("ur5e"), 2),
        reversed_joint(om.load_arm("ur5e"), 2, 7e-6),
        reversed_joint(om.load_arm("panda"), 3, -7e-6),
        fixed_row_between(om.load_arm("ur5e"), 1, 0.3, 0.02, 1e-4),
        fixed_row_between(om.load_arm("panda"), 1, -0.4, 0.0, 0.0),
        fixed_row_between(om.load_arm("panda"), 1, 0.2, 0.0, 3e-5),
    ],
    ids=lambda arm: arm.name,
)
def test_reversed_axes_and_fixed_rows_between_joints_2_and_3(arm):
    """A reversed joint axis (a 180 deg twist, +- a tilt) and a fixed row between joints 2 and
    3: exact at random in-limit q, q found away from the singular boundaries."""
    solver = om.OMSolver(arm)
    assert solver.nominal is not None
    for q in random_q(arm, 30, np.random.default_rng(4)):
        check_exact(solver, q, well_conditioned(solver, q))


def test_batch_and_single_solves_agree_on_a_near_arm():
    solver = bent_solver("panda", -4.0, 0)
    q = random_q(solver.arm, 12, np.random.default_rng(8))
    T = solver.arm.fk(q)
    configurations = [solver.configuration_of(x) for x in q]
    signs = np.array([c.signs for c in configurations])
    psi = np.array([c.redundancy for c in configurations])
    batch = solver.solve_batch(T, signs, psi, q_hint=q)
    for i, c in enumerate(configurations):
        single = solver.solve(T[i], c, q_hint=q[i])
        assert single.ok == batch.ok[i] and single.status == batch.status[i]
        if single.ok:
            assert np.array_equal(single.q, batch.q[i])


def test_solve_all_batch_equals_solve_all_on_a_near_arm():
    solver = bent_solver("panda", -4.0, 0)
    q = random_q(solver.arm, 6, np.random.default_rng(9))
    T = solver.arm.fk(q)
    configurations = [solver.configuration_of(x) for x in q]
    batch = solver.solve_all_batch(
        T, np.array([c.signs for c in configurations]), np.array([c.redundancy for c in configurations])
    )
    for i, c in enumerate(configurations):
        single = solver.solve_all(T[i], c)
        assert batch.count[i] == len(single) >= 1
        for r, sol in enumerate(single):
            np.testing.assert_array_equal(batch.q[i, r], sol.q)


@pytest.mark.parametrize(
    ("name", "row", "field", "value", "cause"),
    [
        (
            "ur5e",
            3,
            "alpha",
            np.pi / 2 + 2e-3,
            r"joint 4 \('wrist_1_joint'\) and joint 5 \('wrist_2_joint'\) perpendicular .*\(0.002 rad off\)",
        ),
    ],
)
def test_an_arm_that_cannot_be_solved_is_refused_at_construction(name, row, field, value, cause):
    """Beyond what the nominal arm absorbs (a twist 2e-3 rad off, twice NEAR_TWIST): a ModelError
    naming the cause (a4 != 0: tests/test_wrist_offset.py; a 7-DOF shoulder offset a2, which the
    nominal arm zeroes: tests/test_shoulder_offset.py)."""
    arm = om.load_arm(name)
    rows = list(arm.chain.rows)
    old = rows[row]
    values = {"a": old.a, "alpha": old.alpha, "d": old.d, "theta": old.theta, field: value}
    rows[row] = om.DHRow(**values, kind=old.kind)
    changed = arm.with_chain(arm.chain.replace_rows(rows), f"{name}-changed")
    with pytest.raises(om.ModelError, match=cause):
        om.OMSolver(changed)


@pytest.mark.parametrize("joint", [1, 3])
def test_arm_angle_and_singularities_of_a_reversed_joint(joint):
    """A 7-DOF arm with a reversed axis: the redundancy package reads psi and the
    singularities in the model's coordinates flip * q: psi is configuration_of's, its gradient
    the finite difference's, the singularities' distances the model's at flip * q."""
    solver = om.OMSolver(reversed_joint(om.load_arm("panda"), joint))
    assert solver.flip[joint] == -1
    singularity = om.Singularity.of(solver.model_arm, solver.flip)
    for q in random_q(solver.arm, 10, np.random.default_rng(joint)):
        psi, grad = om.arm_angle_and_gradient(solver, q)
        assert abs(wrap(psi - solver.configuration_of(q).redundancy[0])) < 1e-12
        step = 1e-6
        for j in range(7):
            dq = np.zeros(7)
            dq[j] = step
            fd = wrap(om.arm_angle_and_gradient(solver, q + dq)[0] - psi) / step
            assert abs(fd - grad[j]) < 1e-5
        nominal = om.Singularity.of(solver.model_arm).distances(solver.flip * q)
        np.testing.assert_allclose(singularity.distances(q), nominal, rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    "arm",
    [bent(om.load_arm("panda"), 1e-4, np.random.default_rng(0)), reversed_joint(om.load_arm("panda"), 3)],
    ids=lambda a: a.name,
)
def test_the_redundancy_optimizer_tracks_on_a_near_arm(arm):
    """The optimiser's global choice and its tracking steps (the compiled ones, as for every
    arm) give exact answers in their configuration."""
    solver = om.OMSolver(arm)
    optimizer = om.RedundancyOptimizer(solver, [om.Sphere([0.4, 0.2, 0.5], 0.05)])
    T = arm.fk(np.array([0.1, -0.3, 0.2, -2.0, 0.1, 1.8, 0.5]))
    choice = optimizer.choose(T)
    for _ in range(3):
        assert choice.ok and solver.holds(choice.solution.q, choice.configuration)
        assert np.abs(arm.fk(choice.solution.q) - T).max() < EXACT
        T = T.copy()
        T[0, 3] += 0.002
        choice = optimizer.choose(T, choice)


@pytest.mark.parametrize(
    ("branch", "q"),
    [
        (0, [-3.726494, -2.316568, 1.573041, -2.759467, -0.186096, 6.041126]),
        (0, [-4.343524, -0.54011, -2.23673, 2.731576, -2.810936, -4.597611]),
        (0, [-3.802659, -1.229439, -0.717211, 1.431248, -3.138834, -5.020617]),
        (0, [4.922068, -0.86922, -1.477057, -6.033637, -2.654594, 3.527687]),
        (1, [0.148555, 5.660698, -3.136687, 5.637899, -2.364597, -0.963509]),
        (1, [-4.424345, 4.016551, -3.136629, 3.607769, -3.875267, 3.799623]),
        (1, [-3.878941, -5.258369, -3.141461, 4.540026, 4.731708, -0.352993]),
    ],
)
def test_targets_at_a_branch_boundary_of_a_near_arm(branch, q):
    """A branch quantity within 5e-3 of zero on UR5e with twists 2e-4 rad off (as on the
    Doosan M1013): the ARM's (the wrist centre at the cylinder of the lateral offset about
    joint 1's axis), the ELBOW's (a folded elbow, an inner edge of reach). c may hold two real
    roots where the nominal arm has one in c and one in the neighbouring configuration, one
    far away, or none at all: the corrected system's roots in c are the real ones (csrc/ik/near.c).
    Each of these q was missed by the first near-family solver."""
    solver = bent_solver("ur5e", np.log10(2e-4), 0)
    q = np.array(q)
    values = np.empty(3)
    _core.branch_values(solver.model_arm.family, solver.model_arm.params, solver.flip * q, values)
    assert abs(values[branch]) < 5e-3
    check_exact(solver, q, strict=True)


@pytest.mark.parametrize(
    ("name", "q"),
    [
        (
            "ur5e-bent-1e-05",
            [
                -4.582842622328123,
                -4.860425891087513,
                0.13977119647540492,
                0.8638580690895061,
                0.2348096306534755,
                1.4215676905502797,
            ],
        ),
        (
            "ur5e-bent-0.0001",
            [
                -3.8085543980652363,
                -6.170986027399788,
                3.137129346204689,
                -2.938373093094823,
                5.884473904863648,
                -0.02431357390123523,
            ],
        ),
        (
            "ur5e-bent-0.001",
            [
                0.97625557877857627,
                1.2847763412734015,
                2.9054042941004865,
                -5.3750772125506669,
                -3.4150823280931775e-4,
                3.0674216817078852,
            ],
        ),
        (
            "ur5e-bent-0.001",
            [
                5.190723627211129,
                4.150721825171179,
                1.4972916465879504,
                2.646798314502308,
                -6.1862165885094935,
                -0.8073034706757785,
            ],
        ),
        (
            "ur5e-reversed-3",
            [
                6.181410753669776,
                -5.461800289662156,
                -1.8996899902268356,
                1.180034261919607,
                -3.0724521323575242,
                5.896422989931524,
            ],
        ),
    ],
)
def test_targets_beside_a_fold_of_the_real_arms_roots(name, q):
    """benchmarks.near_family's arms (seed 0) at q the first near-family solver missed: no
    nominal root polishes to q, those nearest it stall where the exact chain's Jacobian is
    nearly singular (a fold of the real arm's roots that the nominal arm lacks, as on the
    Doosan M1013 at the shoulder's): a close
    pair of zeros of the corrected system's residual, found by its search (csrc/ik/near.c); the
    first near-family solver missed q."""
    arm = next(arm for arm in cases(0) if arm.name == name)
    solver = om.OMSolver(arm)
    assert solver.nominal is not None
    check_exact(solver, np.array(q), strict=True)
