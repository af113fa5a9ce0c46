"""The compiled kernel of an arm near a family (csrc/ik/near.c): the OM system with the nominal
arm as the model's side. Its roots are every root an independent search finds; an arm whose
axis is reversed answers as the arm itself through every compiled entry point (solves, the
optimiser's global choice and tracking steps); micrometre offsets of rounded twists are the
nominal arm's zeros (NEAR_LENGTH), so that the arm keeps its family's search."""

from __future__ import annotations

import numpy as np
import pytest

import om_redundant as om
from benchmarks.near_family import bent, reversed_joint
from om_redundant import _core
from tests.conftest import EXACT, distance, polished_roots, random_q


@pytest.mark.parametrize(
    ("name", "deviation"),
    [("ur5e", 1e-5), ("ur5e", 1e-3), ("panda", 1e-5), ("panda", 1e-3), ("xarm7", 4e-6)],
)
def test_every_root_of_an_independent_search_is_found(name, deviation):
    """Twists bent by +-deviation: at random targets, every root that Gauss-Newton from 400
    random starts reaches is among solve_all's roots in its configuration (the nominal arm's
    scan with windows of the real residual below OM_NEAR_SCAN, the real residual throughout
    above it)."""
    rng = np.random.default_rng(7)
    solver = om.OMSolver(bent(om.load_arm(name), deviation, rng))
    found = 0
    for q in random_q(solver.arm, 4, rng):
        T = solver.arm.fk(q)
        psi = solver.configuration_of(q).redundancy[0] if solver.arm.dof == 7 else 0.0
        for root in polished_roots(solver, T, psi, rng):
            assert np.abs(solver.arm.fk(root) - T).max() < EXACT
            c = solver.configuration_of(root)
            assert any(distance(solver.arm, s.q, root) < 1e-7 for s in solver.solve_all(T, c)), (q, root)
            found += 1
    assert found >= 4


def reversed_pair(name: str, joint: int) -> tuple[om.OMSolver, om.OMSolver]:
    """The arm and the same arm with joint ``joint`` turning about its reversed axis (its
    kinematics the arm's at -q there: an arm near a family, flip -1)."""
    arm = om.load_arm(name)
    return om.OMSolver(arm), om.OMSolver(reversed_joint(arm, joint))


@pytest.mark.parametrize(("name", "joint"), [("ur5e", 2), ("panda", 3)])
def test_a_reversed_axis_answers_as_the_arm_itself(name, joint):
    """solve, the hinted solve, solve_all, the batches, configuration_of and holds of the
    reversed arm are the arm's with q_joint negated."""
    plain, turned = reversed_pair(name, joint)
    assert isinstance(turned.kernel, _core.Solver) and turned.flip[joint] == -1
    flip = turned.flip
    qs = random_q(plain.arm, 12, np.random.default_rng(3))
    for q in qs:
        T = plain.arm.fk(q)
        c = plain.configuration_of(q)
        assert turned.configuration_of(flip * q).isclose(c, 1e-12)
        assert turned.holds(flip * q, c)
        np.testing.assert_allclose(turned.solve(T, c).q, flip * plain.solve(T, c).q, atol=1e-9)
        np.testing.assert_allclose(turned.solve(T, c, flip * q).q, flip * q, atol=1e-9)
        mine, theirs = turned.solve_all(T, c), plain.solve_all(T, c)
        assert len(mine) == len(theirs)
        for r in theirs:
            assert any(distance(plain.arm, m.q, flip * r.q) < 1e-9 for m in mine)
    T = plain.arm.fk(qs)
    cs = [plain.configuration_of(q) for q in qs]
    signs, psi = np.array([c.signs for c in cs]), np.array([c.redundancy for c in cs])
    psi = psi if plain.arm.dof == 7 else None
    batch = turned.solve_batch(T, signs, psi, q_hint=flip * qs)
    assert batch.ok.all() and np.abs(batch.q - flip * qs).max() < 1e-9
    assert (turned.solve_all_batch(T, signs, psi).count == plain.solve_all_batch(T, signs, psi).count).all()


def test_the_optimiser_of_a_reversed_axis_chooses_and_tracks_as_the_arm_itself():
    """The global choice (solve_grid, the compiled follows, link_paths, self-motion tangents)
    and the compiled tracking steps of a Panda whose joint 4 turns about its reversed axis are
    the Panda's with q4 negated."""
    plain, turned = reversed_pair("panda", 3)
    flip = turned.flip
    sphere = [om.Sphere([0.4, 0.2, 0.5], 0.05)]
    choosers = [om.RedundancyOptimizer(s, sphere, max_step=0.01) for s in (plain, turned)]
    T = plain.arm.fk(np.array([0.1, -0.3, 0.2, -2.0, 0.1, 1.8, 0.5]))
    choices = [optimizer.choose(T) for optimizer in choosers]
    for _ in range(5):
        mine, theirs = choices[1], choices[0]
        assert mine.ok and theirs.ok and not mine.rechosen
        assert mine.configuration.isclose(theirs.configuration, 1e-9)
        np.testing.assert_allclose(mine.solution.q, flip * theirs.solution.q, atol=1e-9)
        T = T.copy()
        T[0, 3] += 0.003
        choices = [optimizer.choose(T, choice) for optimizer, choice in zip(choosers, choices, strict=True)]


def test_a_near_arm_tracks_with_the_compiled_step():
    """A Panda with twists bent by 1e-5: its kernel is a _core.Solver, so the optimiser's
    tracking steps are the compiled ones, not fresh choices (before, every tracking call of a
    near arm was refused: "an arm near a family has no compiled tracking step")."""
    solver = om.OMSolver(bent(om.load_arm("panda"), 1e-5, np.random.default_rng(0)))
    assert solver.nominal is not None and isinstance(solver.kernel, _core.Solver)
    optimizer = om.RedundancyOptimizer(solver, [om.Sphere([0.4, 0.2, 0.5], 0.05)], max_step=0.01)
    T = solver.arm.fk(np.array([0.1, -0.3, 0.2, -2.0, 0.1, 1.8, 0.5]))
    choice = optimizer.choose(T)
    for _ in range(5):
        T = T.copy()
        T[1, 3] += 0.003
        choice = optimizer.choose(T, choice)
        assert choice.ok and not choice.rechosen, choice.reason
        assert np.abs(solver.arm.fk(choice.solution.q) - T).max() < EXACT


def test_micrometre_offsets_of_rounded_twists_are_the_nominal_arms_zeros():
    """An xArm7 with twists 3.7e-6 rad off 90 deg and the offsets they leave (d = 1.1e-6 m), as
    its URDF has them: the nominal arm zeros them (NEAR_LENGTH per metre of reach), so it
    keeps the circle search of the xArm7 (the shoulder offset d2 made it a torus arm), and
    solves exactly."""
    arm = bent(om.load_arm("xarm7"), 3.7e-6, np.random.default_rng(1))
    rows = [
        om.DHRow(r.a, r.alpha, r.d + 1.1e-6 if r.d == 0.0 else r.d, r.theta, r.kind) if r.is_joint else r
        for r in arm.chain.rows
    ]
    arm = arm.with_chain(arm.chain.replace_rows(rows), "xarm7-urdf-like")
    solver = om.OMSolver(arm)
    assert solver.solver_data().mode == _core.CIRCLE
    assert 0.0 < solver.nominal.deviation < 1e-4
    for q in random_q(arm, 20, np.random.default_rng(2)):
        T = arm.fk(q)
        c = solver.configuration_of(q)
        assert any(distance(arm, s.q, q) < 1e-7 for s in solver.solve_all(T, c))
