"""The redundancy optimiser: QP optimum and feasible intervals against a dense brute-force
sweep, obstacle avoidance, tracking a path, derivatives, bad input."""

from __future__ import annotations

import math
import re

import mujoco
import numpy as np
import pytest

import om_redundant as om
from benchmarks.control_rate import MIN_CLEARANCE, obstacles
from om_redundant.redundancy import self_motion_tangent
from tests.conftest import random_q, wrap
from tests.reference import objective as objective_numpy

DENSE = 10_000  # psi values per branch of the brute-force sweep
DENSE_STEP = 2.0 * math.pi / DENSE
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@pytest.fixture(scope="module")
def panda():
    return om.OMSolver("panda")


@pytest.fixture(scope="module")
def iiwa14():
    return om.OMSolver("iiwa14")


def exact(solver, q, T):
    reached = solver.arm.fk(q)
    return (
        np.linalg.norm(reached[:3, 3] - T[:3, 3]) < 1e-10
        and np.abs(reached[:3, :3] - T[:3, :3]).max() < 1e-10
    )


# -- brute force --------------------------------------------------------------------------


def dense_sweep(optimizer, T):
    """Every branch at DENSE psi values, solved without hints (the solver then prefers a
    root within the limits): psi, q, feasibility and objective per psi."""
    psi = -math.pi + DENSE_STEP * np.arange(DENSE)
    sweep = {}
    for signs in optimizer.branches:
        batch = optimizer.solver.solve_batch(np.repeat(T[None], DENSE, axis=0), signs, psi)
        value = np.full(DENSE, -np.inf)
        for k in np.flatnonzero(batch.ok):
            ev = optimizer.objective.evaluate(batch.q[k])
            value[k] = ev.value if ev.feasible else -np.inf
        sweep[signs] = (psi, batch.q, np.isfinite(value), value)
    return sweep


def brute_force_optimum(optimizer, T, sweep, candidates=4):
    """The best psi of the dense sweep: its best local maxima, each polished by a golden
    section search over +-1 dense step with exact solutions continued from the sample."""
    starts = []
    for signs, (psi, Q, feasible, value) in sweep.items():
        for k in np.flatnonzero(feasible):
            if value[k] >= value[k - 1] and value[k] >= value[(k + 1) % DENSE]:
                starts.append((value[k], signs, psi[k], Q[k]))
    starts.sort(key=lambda s: -s[0])
    best = (-math.inf, None, None)
    for value, signs, psi, q in starts[:candidates]:

        def f(x, signs=signs, q=q):
            sol = optimizer.solver.solve(T, om.Configuration(signs, (x,)), q_hint=q)
            if not sol.ok or np.abs(sol.q - q).max() > 0.1:
                return -math.inf
            ev = optimizer.objective.evaluate(sol.q)
            return ev.value if ev.feasible else -math.inf

        a, b = psi - DENSE_STEP, psi + DENSE_STEP
        c, d = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
        fc, fd = f(c), f(d)
        while b - a > 1e-10:
            if fc >= fd:
                b, d, fd = d, c, fc
                c = b - GOLDEN * (b - a)
                fc = f(c)
            else:
                a, c, fc = c, d, fd
                d = a + GOLDEN * (b - a)
                fd = f(d)
        best = max(best, (f((a + b) / 2.0), signs, (a + b) / 2.0), (value, signs, psi), key=lambda x: x[0])
    return best


def agreement_cases():
    """(arm, seed, obstacle): random poses of the Panda and the iiwa14; with ``obstacle``, a
    sphere of radius 6 cm at the elbow of the pose's own joints and 2 cm required clearance."""
    return [(arm, seed, seed == 3) for arm in ("panda", "iiwa14") for seed in (1, 2, 3)]


@pytest.fixture(scope="module")
def swept(panda, iiwa14):
    """Optimiser, pose, choice and dense sweep per case, computed once for two tests."""
    solvers, cache = {"panda": panda, "iiwa14": iiwa14}, {}

    def get(arm, seed, obstacle):
        if (arm, seed) not in cache:
            solver = solvers[arm]
            q = random_q(solver.arm, 1, np.random.default_rng(seed))[0]
            T = solver.arm.fk(q)
            # The Panda's wrist-flipped branches have no solution at these poses; proving that
            # costs the solver ~0.3 ms per psi (a solve ~15 us), ~15 s per pose at 10,000 psi,
            # so its sweep keeps the pose's own WRIST sign. The iiwa14 sweeps all 8 branches.
            wrist = solver.configuration_of(q).signs[2]
            branches = [c.signs for c in solver.configurations() if arm != "panda" or c.signs[2] == wrist]
            spheres = [om.Sphere(elbow(solver, q), 0.06)] if obstacle else None
            optimizer = om.RedundancyOptimizer(
                solver, spheres, branches=branches, min_clearance=0.02 * obstacle
            )
            cache[arm, seed] = optimizer, T, optimizer.choose(T), dense_sweep(optimizer, T)
        return cache[arm, seed]

    return get


def elbow(solver, q):
    """The origin of link4 (the elbow joint) at joints q, by the project's MuJoCo model."""
    model = om.arm_model(solver.arm)
    data = mujoco.MjData(model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    return data.body("link4").xpos.copy()


# -- the must-show items ---------------------------------------------------------------------


@pytest.mark.parametrize("arm, seed, obstacle", agreement_cases())
def test_qp_optimum_matches_a_dense_brute_force_sweep(swept, arm, seed, obstacle):
    optimizer, T, choice, sweep = swept(arm, seed, obstacle)
    assert choice.ok, choice.reason
    assert exact(optimizer.solver, choice.solution.q, T)
    assert optimizer.solver.configuration_of(choice.solution.q).isclose(choice.configuration)
    value, signs, psi = brute_force_optimum(optimizer, T, sweep)
    grid_best = max(v.max() for *_, v in sweep.values())
    assert choice.value >= grid_best - 1e-12  # never below any of the 10,000 samples per branch
    same_point = (
        choice.configuration.signs == signs and abs(wrap(choice.configuration.redundancy[0] - psi)) < 1e-3
    )
    assert same_point or abs(choice.value - value) < 1e-6, (choice, value, signs, psi)


@pytest.mark.parametrize("arm, seed, obstacle", agreement_cases())
def test_feasible_intervals_agree_with_the_dense_sweep(swept, arm, seed, obstacle):
    """Each dense psi is feasible exactly when it lies in an interval of its branch, except
    within one dense step of an interval's end; so the ends are refined far below the
    optimiser's own grid (2 pi / 64)."""
    _, _, choice, sweep = swept(arm, seed, obstacle)
    assert choice.intervals
    assert_intervals_match(choice.intervals, sweep)


def assert_intervals_match(intervals, sweep):
    for signs, (psi, _, feasible, _) in sweep.items():
        mine = [i for i in intervals if i.signs == signs]
        inside = np.array([any(i.contains(p) for i in mine) for p in psi])
        ends = np.array([i.lo for i in mine if not i.closed] + [i.hi for i in mine if not i.closed])
        near_end = np.array([len(ends) > 0 and np.abs(wrap(p - ends)).min() <= DENSE_STEP for p in psi])
        disagree = (inside != feasible) & ~near_end
        assert not disagree.any(), (signs, psi[disagree][:5], mine)
        # Each end sits on a change of the dense sweep's feasibility, unless another interval
        # covers it (two solution paths) or another end is within a dense step (a dip or an
        # island narrower than the dense step).
        for end in ends:
            k = int(np.floor((wrap(end) + math.pi) / DENSE_STEP)) % DENSE
            covered = sum(i.contains(end) for i in mine) > 1
            narrow = np.sort(np.abs(wrap(ends - end)))[1] <= DENSE_STEP if len(ends) > 1 else False
            assert covered or narrow or feasible[k] != feasible[(k + 1) % DENSE], (signs, end)


@pytest.mark.parametrize("seed, pose, count", [(0, 48, 0), (7, 67, 1)])
def test_a_maximum_next_to_a_fold_is_climbed_to(seed, pose, count):
    """FR3, the poses of benchmarks.global_choose's draws where a run ends at a fold (its
    path turns back in psi) and the objective's maximum lies inside the cell between the
    fold and the run's next sample: seed 0's 49th pose, where the fold is the best sample (a
    climb from it cannot move: no follow leaves a fold), and seed 7's 68th with 1 obstacle,
    where a climb from inside the cell stepped past the maximum onto the fold, gaining, and
    was stuck there. The choice is at least as good as every feasible solution of its branch
    (every root, solve_all) sampled every 2e-5 rad next to it."""
    solver = om.OMSolver("fr3")
    q = np.random.default_rng(seed).uniform(solver.arm.lower, solver.arm.upper, (pose + 1, 7))[pose]
    T = solver.arm.fk(q)
    optimizer = om.RedundancyOptimizer(
        solver, obstacles(T[:3, 3], count) or None, min_clearance=MIN_CLEARANCE
    )
    choice = optimizer.choose(T)
    assert choice.ok, choice.reason
    signs, psi = choice.configuration.signs, choice.configuration.redundancy[0]
    sampled = -math.inf
    for x in psi + np.arange(-0.01, 0.01, 2e-5):
        for root in solver.solve_all(T, om.Configuration(signs, (x,))):
            evaluation = optimizer.objective.evaluate(root.q)
            if evaluation.feasible:
                sampled = max(sampled, evaluation.value)
    assert math.isfinite(sampled)
    assert choice.value >= sampled - 1e-12, (choice.value, sampled)


def test_a_sphere_at_the_elbow_of_psi_zero_is_avoided_exactly(panda):
    """A sphere at the elbow (joint 4) of the psi = 0 solution: the choice keeps the required
    clearance, checked three ways (shapes, an obstacle MuJoCo model, the user's own scene
    with prefixed names), and is exact."""
    for q in random_q(panda.arm, 50, np.random.default_rng(7)):  # a pose whose psi = 0 is within limits
        T = panda.arm.fk(q)
        blocked = panda.solve(T, om.Configuration(panda.configuration_of(q).signs, (0.0,)))
        if blocked.ok and blocked.within_limits:
            break
    sphere = om.Sphere(elbow(panda, blocked.q), 0.06, name="ball")
    required = 0.03
    optimizer = om.RedundancyOptimizer(panda, [sphere], min_clearance=required)
    assert optimizer.objective.clearance.minimum(blocked.q) < 0.0  # psi = 0 collides

    choice = optimizer.choose(T)
    assert choice.ok, choice.reason
    assert exact(panda, choice.solution.q, T) and choice.solution.position_error < 1e-10
    assert panda.configuration_of(choice.solution.q).isclose(choice.configuration)
    assert choice.clearance >= required and choice.margin >= 0.0

    position = " ".join(str(float(x)) for x in sphere.center)
    ball = f'<geom name="ball" type="sphere" size="0.06" pos="{position}"/>'
    obstacle_model = mujoco.MjModel.from_xml_string(f"<mujoco><worldbody>{ball}</worldbody></mujoco>")
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(panda.arm, prefix="l_"))
    spec.worldbody.add_geom(
        name="ball", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.06, 0, 0], pos=sphere.center
    )
    clearances = [
        om.Clearance.for_arm(panda.arm, [sphere]).minimum(choice.solution.q),
        om.Clearance.for_arm(panda.arm, obstacle_model).minimum(choice.solution.q),
        om.Clearance(spec.compile(), panda.arm, ["ball"], prefix="l_").minimum(choice.solution.q),
    ]
    assert np.allclose(clearances, choice.clearance, rtol=0.0, atol=1e-12)


def test_a_path_of_200_poses_is_tracked_without_jumps_or_needless_flips(panda):
    """Tracking stays on its branch, psi moves at most max_step per pose and the joints move
    continuously; where it stops it chooses afresh, on its branch unless that has no feasible
    psi, and says so."""
    rng = np.random.default_rng(3)
    start = random_q(panda.arm, 1, rng)[0]
    end = np.clip(start + rng.uniform(-0.5, 0.5, 7), panda.arm.lower + 0.1, panda.arm.upper - 0.1)
    path = panda.arm.fk(start + np.linspace(0.0, 1.0, 200)[:, None] * (end - start))
    optimizer = om.RedundancyOptimizer(panda, max_step=0.05)
    choices = [optimizer.choose(path[0])]
    for T in path[1:]:
        choices.append(optimizer.choose(T, choices[-1]))
    for T, before, after in zip(path[1:], choices[:-1], choices[1:], strict=True):
        assert after.ok, after.reason
        assert exact(panda, after.solution.q, T)
        assert after.configuration.signs == before.configuration.signs
        if after.rechosen:
            assert after.reason.startswith(f"tracking from branch {before.configuration.signs}")
        else:
            assert after.reason == ""
            moved = wrap(after.configuration.redundancy[0] - before.configuration.redundancy[0])
            assert abs(moved) <= 0.05 + 1e-12
            assert np.abs(after.solution.q - before.solution.q).max() < 0.1
    assert sum(c.rechosen for c in choices) <= 2  # tracking goes on along a smooth path

    # A pose where the tracked branch has no feasible psi: the flip is taken and named.
    signs = choices[-1].configuration.signs
    alone = om.RedundancyOptimizer(panda, branches=[signs])
    for q in random_q(panda.arm, 200, rng):
        T = panda.arm.fk(q)
        if not alone.intervals(T) and optimizer.choose(T).ok:
            break
    else:
        pytest.fail("no pose without a feasible psi on the tracked branch")
    flipped = optimizer.choose(T, choices[-1])
    assert flipped.ok and flipped.rechosen and flipped.branch_flipped and flipped.configuration.signs != signs
    assert f"branch {signs} has no feasible arm angle at this pose" in flipped.reason
    assert exact(panda, flipped.solution.q, T)


# -- derivatives ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["panda", "iiwa14"])
def test_derivatives_match_finite_differences_of_exact_solutions(name, request):
    """dq/dpsi (implicit: null space of J over the arm angle's change) against central
    differences of exact solutions; clearance gradients against differences of MuJoCo
    distances; and the QP's whole linearisation of every piece along psi."""
    solver = request.getfixturevalue(name)
    rng = np.random.default_rng(5)
    obstacles = [om.Sphere([0.4, 0.1, 0.5], 0.1), om.Box([0.05, 0.2, 0.1], np.eye(4), name="box")]
    objective = om.RedundancyOptimizer(solver, obstacles, clearance_cap=0.5).objective
    h = 1e-6
    for q in random_q(solver.arm, 10, rng):
        T, c = solver.arm.fk(q), solver.configuration_of(q)
        tangent = self_motion_tangent(solver, q)[:, 0]
        ahead, behind = (
            solver.solve(T, om.Configuration(c.signs, (c.redundancy[0] + s,)), q_hint=q).q for s in (h, -h)
        )
        np.testing.assert_allclose(tangent, (ahead - behind) / (2 * h), rtol=1e-6, atol=1e-6)
        assert np.abs(solver.arm.jacobian(q) @ tangent).max() < 1e-9  # the hand stays still

        d, grad = objective.clearance.distances_and_gradients(q)
        direction = rng.normal(size=solver.arm.dof)
        differences = (
            objective.clearance.distances(q + h * direction)
            - objective.clearance.distances(q - h * direction)
        ) / (2 * h)
        near = d < objective.clearance.distmax
        np.testing.assert_allclose(grad[near] @ direction, differences[near], atol=1e-6)

        for group, ahead_group, behind_group in zip(
            objective_numpy.groups(objective, q, tangent=tangent[:, None]),
            objective_numpy.groups(objective, ahead),
            objective_numpy.groups(objective, behind),
            strict=True,
        ):
            slopes = group.jacobian[:, 0]
            np.testing.assert_allclose(
                slopes, (ahead_group.values - behind_group.values) / (2 * h), atol=1e-5
            )


# -- bad input --------------------------------------------------------------------------------


def test_bad_input_is_named_and_nothing_feasible_says_why(panda):
    ur5e = om.OMSolver("ur5e")
    with pytest.raises(om.InvalidInput, match="the optimiser needs one"):
        om.RedundancyOptimizer(ur5e)
    with pytest.raises(om.InvalidInput, match="solver must be an OMSolver"):
        om.RedundancyOptimizer("panda")
    with pytest.raises(om.InvalidInput, match="branches must be -1 or \\+1"):
        om.RedundancyOptimizer(panda, branches=[(1, 2, 1)])
    with pytest.raises(om.InvalidInput, match="branches must have 3 entries"):
        om.RedundancyOptimizer(panda, branches=[(1, 1)])
    with pytest.raises(om.InvalidInput, match="grid_points must be at least 16"):
        om.RedundancyOptimizer(panda, grid_points=4)
    with pytest.raises(om.InvalidInput, match="max_step must be in"):
        om.RedundancyOptimizer(panda, max_step=0.0)
    with pytest.raises(om.InvalidInput, match="margin_weight must be a finite number >= 0"):
        om.RedundancyOptimizer(panda, margin_weight=-1.0)
    with pytest.raises(om.InvalidInput, match="min_clearance must be >= 0 and below clearance_cap"):
        om.RedundancyOptimizer(panda, [om.Sphere([0, 0, 1], 0.1)], min_clearance=0.2, clearance_cap=0.1)
    with pytest.raises(om.InvalidInput, match="obstacle 1 must be a Sphere, Capsule or Box"):
        om.RedundancyOptimizer(panda, [om.Sphere([0, 0, 1], 0.1), "a wall"])
    with pytest.raises(om.InvalidInput, match="Sphere radius must be a positive finite number"):
        om.Sphere([0, 0, 1], -0.1)
    with pytest.raises(om.InvalidInput, match="Sphere center must be 3 finite numbers"):
        om.Sphere([0, np.nan, 1], 0.1)
    with pytest.raises(om.InvalidInput, match="Capsule start and end coincide"):
        om.Capsule([0, 0, 1], [0, 0, 1], 0.1)
    with pytest.raises(om.InvalidInput, match="Box half_sizes must be positive"):
        om.Box([0.1, 0.0, 0.1])
    with pytest.raises(om.InvalidInput, match="Box pose: rotation is not orthonormal"):
        om.Box([0.1, 0.1, 0.1], np.diag([1.0, 2.0, 1.0, 1.0]))
    with pytest.raises(om.JointNotFound, match="joint 'r_joint1' of arm 'panda' does not exist"):
        om.Clearance(om.arm_model(panda.arm, prefix="l_"), panda.arm, ["l_link1_capsule0"], prefix="r_")
    with pytest.raises(om.InvalidInput, match="no geom named 'wall'"):
        om.Clearance(om.arm_model(panda.arm), panda.arm, ["wall"])
    with pytest.raises(om.InvalidInput, match="obstacle geom 'link7_capsule0' moves with the arm"):
        om.Clearance(om.arm_model(panda.arm), panda.arm, ["link7_capsule0"])
    with pytest.raises(om.InvalidInput, match="obstacle name 'link4_capsule0' is already taken"):
        om.Clearance.for_arm(panda.arm, [om.Sphere([0, 0, 1], 0.1, name="link4_capsule0")])
    # Beyond om.MAX_EXTENT distances lose their precision (a sphere of radius 1e155 about the arm
    # was reported clear: the squares overflow); within it they are kept.
    within = 0.5 * om.MAX_EXTENT
    om.Clearance.for_arm(panda.arm, [om.Sphere([within, 0, 0], 0.1), om.Box([within, within, 0.1])])
    for huge in (
        om.Sphere([0.4, 0.0, 0.5 + 1e155], 1e155),
        om.Sphere([2.0 * om.MAX_EXTENT, 0.0, 0.0], 0.1),
        om.Box([2.0 * om.MAX_EXTENT, 1.0, 1.0]),
        om.Capsule([0.4, 0.0, 0.5], [0.4, 0.0, 1e12], 0.05),
    ):
        with pytest.raises(
            om.InvalidInput, match="obstacle geom 'obstacle0': its position and sizes must be within"
        ):
            om.RedundancyOptimizer(panda, [huge])

    optimizer = om.RedundancyOptimizer(panda)
    T = panda.arm.fk(np.array([0.2, 0.4, -0.3, -1.8, 0.5, 1.9, 0.6]))
    with pytest.raises(om.InvalidInput, match="T: rotation is not orthonormal"):
        optimizer.choose(T @ np.diag([1.0, 1.0, 1.1, 1.0]))
    with pytest.raises(om.InvalidInput, match="previous must be a RedundancyChoice"):
        optimizer.choose(T, previous="psi = 0")
    first = optimizer.choose(T)
    with pytest.raises(om.InvalidInput, match="is not among the allowed branches"):
        om.RedundancyOptimizer(panda, branches=[(-1, 1, -1)]).choose(T, first)

    far = np.eye(4)
    far[:3, 3] = [2.0, 0.0, 0.5]
    unreachable = optimizer.choose(far)
    assert not unreachable.ok and unreachable.solution is None and unreachable.configuration is None
    assert re.match(
        r"no feasible arm angle: the target is out of reach: its wrist centre lies 1\.\d{4} m beyond "
        r"where the arm's elbow reaches \(more than the 0\.\d{4} m its offsets can make up\), at every "
        r"arm angle and branch$",
        unreachable.reason,
    )
    engulfed = om.RedundancyOptimizer(panda, [om.Sphere([0.0, 0.0, 0.5], 0.3)]).choose(T)
    assert not engulfed.ok and "clearance below 0.0 m wherever within the limits" in engulfed.reason
