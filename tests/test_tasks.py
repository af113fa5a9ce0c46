"""mink tasks fed by exact OM solutions: reach, Jacobians, tracking, joint mapping, bad input.

The reach runs are the full ones of the issue (500 random targets per model and QP solver,
about 2 s each with daqp and 5 s with osqp), since the whole file stays well under 90 s;
``python -m benchmarks.mink_reach`` repeats them beside plain mink.
"""

from __future__ import annotations

import math
from types import SimpleNamespace
from unittest import mock

import mink
import mujoco
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.mink_reach import SETUPS, TOLERANCE, reach
from benchmarks.robots import home_joints, pose_errors, random_joints, reference_spec
from om_redundant import _core
from om_redundant.kinematics import KinematicChain
from tests.conftest import load_reference_model

REACH_TARGETS = 500
DT = 0.002
PANDA_NOHAND = "franka_emika_panda/panda_nohand.xml"
# A comfortable Panda pose, inside every joint range.
Q_PANDA = np.array([0.3, -0.4, 0.2, -2.2, 0.3, 1.9, 0.6])


@pytest.fixture(scope="module")
def panda():
    return om.OMSolver("panda")


@pytest.fixture(scope="module")
def panda_model(panda):
    return om.arm_model(panda.arm)


def step(configuration, tasks, limits, solver="daqp", dt=DT):
    velocity = mink.solve_ik(configuration, tasks, dt, solver, damping=1e-3, limits=limits)
    configuration.integrate_inplace(velocity, dt)


def hand_error(configuration, frame, T):
    hand = configuration.get_transform_frame_to_world(frame, "site").as_matrix()
    position, angle = pose_errors(hand, T)
    return float(position), float(angle)


def frame_task(frame="attachment_site"):
    return mink.FrameTask(frame, "site", position_cost=1.0, orientation_cost=1.0, lm_damping=1.0)


def psi_of(solver, q):
    return solver.configuration_of(q).redundancy[0]


# ---------------------------------------------------------------------------------------
# Reaching random targets in a mink loop


@pytest.mark.parametrize("qp", ["daqp", "osqp"])
@pytest.mark.parametrize("setup", SETUPS, ids=lambda setup: setup.key)
def test_every_target_is_reached_exactly_in_its_configuration(setup, qp):
    """From home to 500 random reachable targets, FrameTask + ExactPoseTask, ConfigurationLimit:
    every one within 1e-6 m and 1e-6 rad, in the requested configuration (signs and psi)."""
    if setup.key == "panda-menagerie":
        load_reference_model(PANDA_NOHAND)  # skips where the reference model is missing
    solver = om.OMSolver(setup.arm)
    Q = random_joints(solver.arm, REACH_TARGETS, np.random.default_rng(5))
    run = reach(solver, setup.model(), Q, qp)
    print(
        f"{setup.label} {qp}: steps median {np.median(run.steps):.0f} max {run.steps.max()}, "
        f"{1e3 * np.median(run.seconds):.2f} ms per target (median)"
    )
    assert run.success().all(), np.flatnonzero(~run.success())[:10]
    assert run.position_error.max() < TOLERANCE and run.orientation_error.max() < TOLERANCE


@pytest.mark.parametrize(
    "name, path", [("iiwa14", "kuka_iiwa_14/iiwa14.xml"), ("xarm7", "ufactory_xarm7/xarm7_nohand.xml")]
)
def test_reference_models_with_their_own_base_frames(name, path):
    """Menagerie's iiwa14 (a base body) and xArm7 (link_base 0.12 m above the world): targets
    in the world frame are reached; the root frame comes from the model."""
    model = load_reference_model(path)
    solver = om.OMSolver(name)
    run = reach(solver, model, random_joints(solver.arm, 40, np.random.default_rng(6)), "daqp")
    assert run.success().all()


class PickConfigurationOf:
    """A stand-in redundancy optimiser: picks the configuration of a known joint vector."""

    def __init__(self, solver):
        self.solver, self.q, self.previous = solver, None, []

    def choose(self, T, previous=None, *, q_current=None, free=None, rechoose=True):
        self.previous.append(previous)
        c = self.solver.configuration_of(self.q)
        sol = self.solver.solve(T, c, q_hint=self.q)
        return SimpleNamespace(
            ok=sol.ok, solution=sol, configuration=c, reason=sol.status, rechosen=False, way_clear=True
        )


def test_optimizer_choice_is_reached(panda, panda_model):
    optimizer = PickConfigurationOf(panda)
    task = om.ExactPoseTask(panda, panda_model, optimizer=optimizer)
    frame = frame_task()
    configuration = mink.Configuration(panda_model)
    limits = [mink.ConfigurationLimit(panda_model)]
    home = home_joints(panda.arm)
    for q in random_joints(panda.arm, 50, np.random.default_rng(8)):
        T = panda.arm.fk(q)
        optimizer.q = q
        configuration.update(home)
        task.set_target(T)
        frame.set_target(mink.SE3.from_matrix(T))
        assert task.choice.configuration.isclose(panda.configuration_of(q))
        for _ in range(300):  # (after a jump the task aims a lead ahead of the hand: more steps)
            step(configuration, [frame, task], limits)
            if max(hand_error(configuration, "attachment_site", T)) < 1e-9:
                break
        assert max(hand_error(configuration, "attachment_site", T)) < 1e-9
        assert panda.configuration_of(configuration.q).isclose(panda.configuration_of(q), 1e-6)
    assert optimizer.previous[0] is None and optimizer.previous[1] is not None


def test_without_a_lead_a_fresh_choice_is_the_target_at_once(panda, panda_model):
    """``lead=None``: no aims and no joint-space way, q* of the target itself from the first
    tick (it raised TypeError on the first fresh choice), and mink reaches it."""
    task = om.ExactPoseTask(panda, panda_model, optimizer=om.RedundancyOptimizer(panda), lead=None)
    frame = frame_task()
    limits = [mink.ConfigurationLimit(panda_model)]
    configuration = mink.Configuration(panda_model, Q_PANDA)
    task.set_target_from_configuration(configuration)
    for q in random_joints(panda.arm, 3, np.random.default_rng(5)):
        T = panda.arm.fk(q)
        task.reset_choice()
        task.set_target(T)
        frame.set_target(mink.SE3.from_matrix(T))
        assert task.choice.ok and task._way is None
        np.testing.assert_allclose(panda.arm.fk(task.joint_target), T, atol=1e-12)
        for _ in range(1000):
            step(configuration, [frame, task], limits)
            if max(hand_error(configuration, "attachment_site", T)) < 1e-9:
                break
        assert max(hand_error(configuration, "attachment_site", T)) < 1e-9


def test_the_residual_and_objective_read_once_are_minks_of_the_error_and_jacobian(panda, panda_model):
    """compute_qp_residual and compute_qp_objective (the world read once) equal mink's own,
    assembled from compute_error and compute_jacobian, on a joint-space way (the error and
    Jacobian scaled) and at its end."""
    task = om.ExactPoseTask(panda, panda_model, optimizer=om.RedundancyOptimizer(panda))
    configuration = mink.Configuration(panda_model, Q_PANDA)
    task.set_target_from_configuration(configuration)
    q_to = random_joints(panda.arm, 1, np.random.default_rng(11))[0]
    task.reset_choice()
    task.set_target(panda.arm.fk(q_to))
    limits = [
        mink.ConfigurationLimit(panda_model),
        mink.VelocityLimit(panda_model, dict.fromkeys(panda.arm.joint_names, 2.0)),
    ]
    weights = set()
    for _ in range(1500):
        residual = task.compute_qp_residual(configuration)
        expected = mink.Task.compute_qp_residual(task, configuration)
        for got, want in zip(residual, expected, strict=True):
            np.testing.assert_array_equal(got, want)
        objective, want = (
            task.compute_qp_objective(configuration),
            mink.Task.compute_qp_objective(task, configuration),
        )
        np.testing.assert_array_equal(objective.H, want.H)
        np.testing.assert_array_equal(objective.c, want.c)
        weights.add(float(np.abs(task.compute_jacobian(configuration)).max()))
        step(configuration, [task], limits)
    assert len(weights) > 2 and 1.0 in weights  # (scaled on the way, then 1 at its end)


@pytest.mark.parametrize("with_frame_task", [False, True])
def test_a_fresh_choice_is_reached_along_its_joint_space_way(panda, panda_model, with_frame_task):
    """A choice made afresh is reached along the straight joint-space way the optimiser
    certified, not a diagonal cut by mink's velocity limits (the old 0.1 rad lead left the
    way by 0.05 rad), also while a FrameTask pulls the hand straight to the target."""
    optimizer = om.RedundancyOptimizer(panda)
    task = om.ExactPoseTask(panda, panda_model, optimizer=optimizer)
    frame = frame_task()
    limits = [
        mink.ConfigurationLimit(panda_model),
        mink.VelocityLimit(panda_model, dict.fromkeys(panda.arm.joint_names, 2.0)),
    ]
    tasks = [frame, task] if with_frame_task else [task]
    rng = np.random.default_rng(4)
    configuration = mink.Configuration(panda_model, Q_PANDA)
    task.set_target_from_configuration(configuration)  # (the task sees the configuration)
    for q_from, q_to in zip(random_joints(panda.arm, 6, rng), random_joints(panda.arm, 6, rng), strict=True):
        configuration.update(q_from)
        T = panda.arm.fk(q_to)
        task.reset_choice()
        task.set_target(T)
        frame.set_target(mink.SE3.from_matrix(T))
        deviation = 0.0
        for _ in range(3000):
            way = task._way
            step(configuration, tasks, limits, dt=0.002)
            if way is not None:  # the distance (max-norm) of q from the way's segment
                delta = task.joint_target - way.start
                s = np.clip((configuration.q - way.start) @ delta / (delta @ delta), 0.0, 1.0)
                deviation = max(deviation, float(np.abs(configuration.q - way.start - s * delta).max()))
            if max(hand_error(configuration, "attachment_site", T)) < 1e-9:
                break
        assert max(hand_error(configuration, "attachment_site", T)) < 1e-9
        assert deviation < 0.01


def test_the_redundancy_optimizers_choice_is_reached_clear_of_an_obstacle(panda, panda_model):
    """The real optimiser behind the task: a sphere at the elbow of the psi = 0 solution. The
    target set before the task has seen the arm is chosen globally; at the first step the
    task sees the arm and chooses from its joints; mink ends on the pose exactly, in the
    task's final choice, with the clearance kept at every step."""
    T = panda.arm.fk(Q_PANDA)
    c0 = panda.configuration_of(Q_PANDA)
    at_zero = panda.solve(T, om.Configuration(c0.signs, (0.0,)), q_hint=Q_PANDA)
    assert at_zero.ok
    data = mujoco.MjData(panda_model)
    data.qpos[:] = at_zero.q
    mujoco.mj_forward(panda_model, data)
    centre = data.xpos[panda_model.body("link4").id].copy()  # the elbow
    optimizer = om.RedundancyOptimizer(panda, obstacles=[om.Sphere(centre, 0.05)], min_clearance=0.02)
    task = om.ExactPoseTask(panda, panda_model, optimizer=optimizer)
    frame = frame_task()
    task.set_target(T)
    frame.set_target(mink.SE3.from_matrix(T))
    assert task.choice.ok and task.choice.clearance >= 0.02
    configuration = mink.Configuration(panda_model)
    configuration.update(home_joints(panda.arm))
    limits = [mink.ConfigurationLimit(panda_model)]
    for _ in range(300):
        step(configuration, [frame, task], limits)
        assert task.choice.ok and task.choice.clearance >= 0.02
        if max(hand_error(configuration, "attachment_site", T)) < 1e-9:
            break
    assert max(hand_error(configuration, "attachment_site", T)) < 1e-9
    assert panda.configuration_of(configuration.q).isclose(task.choice.configuration, 1e-6)
    assert optimizer.objective.evaluate(configuration.q).clearance >= 0.02 - 1e-9


def test_equal_costs_get_stuck_where_the_default_cost_does_not(panda, panda_model):
    """Why the default cost is 10: with the FrameTask's weight equal to the joint task's, the
    sum has stationary points away from q* (the docstring's claim, on a few targets)."""
    Q = random_joints(panda.arm, 40, np.random.default_rng(0))
    stuck = {}
    for cost in (1.0, om.tasks.EXACT_POSE_COST):
        task = om.ExactPoseTask(panda, panda_model, arm_configuration=panda.configuration_of(Q[0]), cost=cost)
        frame = frame_task()
        configuration = mink.Configuration(panda_model)
        limits = [mink.ConfigurationLimit(panda_model)]
        stuck[cost] = 0
        for q in Q:
            T = panda.arm.fk(q)
            task.set_target(T, panda.configuration_of(q))
            frame.set_target(mink.SE3.from_matrix(T))
            configuration.update(home_joints(panda.arm))
            for _ in range(60):
                step(configuration, [frame, task], limits)
            stuck[cost] += max(hand_error(configuration, "attachment_site", T)) > 1e-6
    assert stuck[1.0] > 0 and stuck[om.tasks.EXACT_POSE_COST] == 0


# ---------------------------------------------------------------------------------------
# Jacobians


def finite_difference_jacobian(task, configuration, h=1e-6):
    """Central differences of compute_error over every dof (hinge and slide joints only)."""
    q0 = configuration.q
    columns = []
    for j in range(configuration.nv):
        plus, minus = q0.copy(), q0.copy()
        plus[j] += h
        minus[j] -= h
        configuration.update(plus)
        e_plus = task.compute_error(configuration)
        configuration.update(minus)
        e_minus = task.compute_error(configuration)
        columns.append((e_plus - e_minus) / (2 * h))
    configuration.update(q0)
    return np.array(columns).T


@pytest.fixture(scope="module")
def panda_with_hand():
    """Menagerie's Panda with its hand (two finger joints) and the arm's end-effector site added."""
    load_reference_model("franka_emika_panda/panda.xml")  # skips where missing
    spec = reference_spec("franka_emika_panda/panda.xml")
    spec.body("link7").add_site(name="attachment_site", pos=[0, 0, 0.107], quat=[0.3826834, 0, 0, 0.9238795])
    return spec.compile()


def test_both_jacobians_match_finite_differences(panda, panda_with_hand):
    model = panda_with_hand
    configuration = mink.Configuration(model)
    exact = om.ExactPoseTask(panda, model, arm_configuration=panda.configuration_of(Q_PANDA))
    angle = om.ArmAngleTask(panda, model)
    exact.set_target(panda.arm.fk(Q_PANDA))
    rng = np.random.default_rng(2)
    for q in random_joints(panda.arm, 20, rng):
        q = np.clip(q, angle.joints.lower, angle.joints.upper)  # (the model's limits are tighter)
        configuration.update(np.concatenate([q, rng.uniform(0.0, 0.04, 2)]))
        angle.set_target_from_configuration(configuration)  # (one the arm can take there)
        for task in (exact, angle):
            J = task.compute_jacobian(configuration)
            assert J.shape == (task.k, model.nv)
            np.testing.assert_allclose(J, finite_difference_jacobian(task, configuration), atol=1e-7)
            assert not J[:, 7:].any()  # the finger joints


def singular_margins(solver, q):
    """Distance of psi's singular half-line (1 + up . w_hat) and of the straight elbow."""
    chain = solver.model.chain
    rows, first = chain.rows, chain.joint_rows

    def origin(j):  # DH origin after joint j's row, in the root frame
        return KinematicChain(rows[: first[j] + 1], chain.T_root_base).fk(q[: j + 1])[:3, 3]

    w = origin(4) - origin(0)
    P = solver.model_arm.params
    return 1.0 + w[2] / np.linalg.norm(w), abs(
        math.sin(q[3] + P[_core.SRS_THETA + 3] - P[_core.SRS_PHI_STAR])
    )


SOLVERS_7DOF = {name: om.OMSolver(name) for name in ("panda", "fr3", "iiwa14", "xarm7")}


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(sorted(SOLVERS_7DOF)), st.lists(st.floats(0.0, 1.0), min_size=7, max_size=7))
def test_arm_angle_gradient_matches_finite_differences(name, u):
    """d psi/dq (analytic, from the model's kinematics) against central differences of
    configuration_of(q).redundancy[0], away from psi's singular half-line and the straight
    elbow (where psi jumps by pi)."""
    solver = SOLVERS_7DOF[name]
    lower = np.where(np.isfinite(solver.arm.lower), solver.arm.lower, -np.pi)
    upper = np.where(np.isfinite(solver.arm.upper), solver.arm.upper, np.pi)
    q = lower + np.array(u) * (upper - lower)
    half_line, elbow = singular_margins(solver, q)
    assume(half_line > 1e-2 and elbow > 1e-3)
    psi, gradient = om.arm_angle_and_gradient(solver, q)
    assert abs(math.remainder(psi - psi_of(solver, q), 2 * math.pi)) < 1e-12
    h = 1e-6
    numeric = np.empty(7)
    for j in range(7):
        plus, minus = q.copy(), q.copy()
        plus[j] += h
        minus[j] -= h
        numeric[j] = math.remainder(psi_of(solver, plus) - psi_of(solver, minus), 2 * math.pi) / (2 * h)
    np.testing.assert_allclose(gradient, numeric, atol=1e-6 * (1 + np.abs(gradient).max()))
    assert not gradient[4:].any()


# ---------------------------------------------------------------------------------------
# Tracking a moving target


def path(T0, t):
    """A 10 s hand path: a 0.1 m circle in x-z (period 5 s) while the hand turns +-0.3 rad about z."""
    T = T0.copy()
    a, turn = 2 * np.pi * t / 5.0, 0.3 * np.sin(2 * np.pi * t / 10.0)
    T[:3, 3] += 0.1 * np.array([np.sin(a), 0.0, 1.0 - np.cos(a)])
    c, s = np.cos(turn), np.sin(turn)
    T[:3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ T0[:3, :3]
    return T


class SwingElbow:
    """A stand-in optimiser: keeps the previous branch and moves psi along a given schedule."""

    def __init__(self, solver, signs, psi):
        self.solver, self.signs, self.psi = solver, signs, psi

    def choose(self, T, previous=None, *, q_current=None, free=None, rechoose=True):
        c = om.Configuration(self.signs if previous is None else previous.configuration.signs, (self.psi,))
        sol = self.solver.solve(T, c, q_hint=None if previous is None else previous.solution.q)
        return SimpleNamespace(
            ok=sol.ok, solution=sol, configuration=c, reason=sol.status, rechosen=False, way_clear=True
        )


@pytest.mark.parametrize("mode", ["fixed configuration", "optimizer"])
def test_tracking_a_moving_target_keeps_branch_and_psi_continuous(panda, panda_model, mode):
    """10 s at 100 Hz, one solve_ik per tick, with joint and velocity limits: the branch never
    flips and psi moves continuously (held, or swung by the optimiser)."""
    dt = 0.01
    configuration = mink.Configuration(panda_model, Q_PANDA)
    c0 = panda.configuration_of(Q_PANDA)
    psi0 = c0.redundancy[0]
    T0 = panda.arm.fk(Q_PANDA)
    if mode == "optimizer":
        optimizer = SwingElbow(panda, c0.signs, psi0)
        task = om.ExactPoseTask(panda, panda_model, optimizer=optimizer)
    else:
        task = om.ExactPoseTask(panda, panda_model, arm_configuration=c0)
    frame = frame_task()
    limits = [
        mink.ConfigurationLimit(panda_model),
        mink.VelocityLimit(panda_model, {name: 2.0 for name in panda.arm.joint_names}),
    ]
    task.set_target_from_configuration(configuration)
    psi, targets, errors = [], [], []
    for tick in range(1, 1001):
        t = tick * dt
        T = path(T0, t)
        if mode == "optimizer":
            optimizer.psi = psi0 + 0.4 * np.sin(2 * np.pi * t / 10.0)
        task.set_target(T)
        frame.set_target(mink.SE3.from_matrix(T))
        step(configuration, [frame, task], limits, dt=dt)
        c = panda.configuration_of(configuration.q)
        assert c.signs == c0.signs, f"branch flip at t = {t:.2f} s"
        psi.append(c.redundancy[0])
        targets.append(task.joint_target)
        errors.append(hand_error(configuration, "attachment_site", T)[0])
    steps_psi = np.abs(np.diff(np.unwrap([psi0, *psi])))
    assert steps_psi.max() < 0.01  # rad per 10 ms tick
    assert np.abs(np.diff(targets, axis=0)).max() < 0.05  # q* never jumps to another root
    assert max(errors) < 1e-5  # the hand is on its moving target at every tick (measured ~1e-7)
    if mode == "fixed configuration":
        assert np.abs(np.array(psi) - psi0).max() < 1e-5


@pytest.mark.parametrize("given", ["array", "SE3"])
def test_a_target_is_solved_once_per_tick_and_an_array_changed_in_place_is_a_new_target(
    panda, panda_model, given
):
    """set_target solves; mink's compute_error and compute_jacobian of the same world ask the
    optimiser nothing more (an SE3 made of an array does not give it back bit for bit: a
    target read back from it was solved again, a second tracking step in the same tick). A
    caller's one array changed in place is the target when given again, not before, and
    does as fresh arrays do, a jump included."""
    c0 = panda.configuration_of(Q_PANDA)
    T0 = panda.arm.fk(Q_PANDA)
    frame, limits = frame_task(), [mink.ConfigurationLimit(panda_model)]
    runs = []
    for in_place in (True, False):
        optimizer = SwingElbow(panda, c0.signs, c0.redundancy[0])
        task = om.ExactPoseTask(panda, panda_model, optimizer=optimizer)
        configuration = mink.Configuration(panda_model, Q_PANDA)
        task.set_target_from_configuration(configuration)
        T, targets = T0.copy(), []
        with mock.patch.object(optimizer, "choose", wraps=optimizer.choose) as choose:
            for tick in range(1, 41):
                pose = path(T0, 0.02 * tick)
                if tick == 40:  # a jump: the task leads the hand there
                    pose[:3, 3] += [0.0, 0.0, 0.15]
                if in_place:
                    T[:] = pose
                else:
                    T = pose.copy()
                task.set_target(T if given == "array" else mink.SE3.from_matrix(T))
                targets.append(task.joint_target)
                calls = choose.call_count
                frame.set_target(mink.SE3.from_matrix(pose))
                T[:3, 3] += 1.0  # (changed after it was given: not the target until given again)
                step(configuration, [frame, task], limits)
                assert choose.call_count == calls  # the error and Jacobian took the target as solved
        hand = panda.arm.fk(task.joint_target)
        assert 0.01 < np.linalg.norm(hand[:3, 3] - pose[:3, 3]) < 0.15  # led: q* of an aim on the way
        runs.append(np.array(targets))
    np.testing.assert_array_equal(runs[0], runs[1])


# ---------------------------------------------------------------------------------------
# The arm angle task


def test_arm_angle_task_swings_the_elbow_while_the_frame_task_holds_the_hand(panda, panda_model):
    configuration = mink.Configuration(panda_model, Q_PANDA)
    frame = frame_task()
    frame.set_target_from_configuration(configuration)
    angle = om.ArmAngleTask(panda, panda_model)
    angle.set_target_from_configuration(configuration)
    assert angle.compute_error(configuration)[0] == pytest.approx(0.0, abs=1e-12)
    psi_target = psi_of(panda, Q_PANDA) + 0.5
    angle.set_target(psi_target)
    limits = [mink.ConfigurationLimit(panda_model)]
    for _ in range(100):
        step(configuration, [frame, angle], limits)
    assert abs(math.remainder(psi_of(panda, configuration.q) - psi_target, 2 * math.pi)) < 1e-6
    assert max(hand_error(configuration, "attachment_site", panda.arm.fk(Q_PANDA))) < 1e-6


def test_an_arm_angle_the_arm_cannot_take_is_refused_not_pulled_to(panda, panda_model):
    """An arm angle with no exact solution within the Panda's limits at Q_PANDA's hand pose:
    the elbow cannot go there without pulling the hand off its target (0.6 m in the issue).
    The task says so at set_target (it has seen the arm) and keeps its target, and at
    compute_* when it had not."""
    configuration = mink.Configuration(panda_model, Q_PANDA)
    T = panda.arm.fk(Q_PANDA)
    signs = panda.configuration_of(Q_PANDA).signs
    grid = np.linspace(-np.pi, np.pi, 73)
    ok = []
    for psi in grid:
        s = panda.solve(T, om.Configuration(signs, (psi,)), q_hint=Q_PANDA)
        ok.append(s.ok and panda.arm.within_limits(s.q))
    attainable = grid[np.flatnonzero(ok)]
    gap = [k for k in range(1, len(grid) - 1) if not (ok[k - 1] or ok[k] or ok[k + 1])]
    assert len(attainable) and gap  # some psi is, some (with its neighbours) is not
    out = float(grid[gap[len(gap) // 2]])
    angle = om.ArmAngleTask(panda, panda_model)
    angle.set_target_from_configuration(configuration)
    held = angle.target_psi
    with pytest.raises(om.UnreachableTarget, match=rf"cannot take psi\* = {out:+.4f}"):
        angle.set_target(out)
    assert angle.target_psi == held
    fresh = om.ArmAngleTask(panda, panda_model)
    fresh.set_target(out)  # not seen the arm yet: checked at the first compute
    with pytest.raises(om.UnreachableTarget, match="pull the hand off its target"):
        fresh.compute_error(configuration)
    fresh.set_target(float(attainable[len(attainable) // 2]))
    assert np.isfinite(fresh.compute_error(configuration)).all()


# ---------------------------------------------------------------------------------------
# The arm inside larger models


def dual_arm_model(arm):
    """Two arms from the project's MJCF, prefixed l_ and r_, on turned and raised bases."""
    spec = mujoco.MjSpec()
    for prefix, y, yaw in (("l_", 0.4, 0.5), ("r_", -0.4, -0.5)):
        child = mujoco.MjSpec.from_string(om.arm_mjcf(arm))
        frame = spec.worldbody.add_frame(pos=[0.1, y, 0.3], quat=[np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)])
        frame.attach_body(child.body("base"), prefix, "")
    return spec.compile()


def test_dual_arm_with_prefixes(panda):
    model = dual_arm_model(panda.arm)
    configuration = mink.Configuration(model)
    rng = np.random.default_rng(9)
    tasks, goals = [], {}
    for prefix in ("l_", "r_"):
        exact = om.ExactPoseTask(
            panda, model, arm_configuration=panda.configuration_of(Q_PANDA), prefix=prefix
        )
        assert exact.joints.names[0] == prefix + "joint1"
        q = random_joints(panda.arm, 1, rng)[0]
        T = exact.root.fixed_pose @ panda.arm.fk(q)
        exact.set_target(T, panda.configuration_of(q))
        frame = frame_task(prefix + "attachment_site")
        frame.set_target(mink.SE3.from_matrix(T))
        tasks += [frame, exact]
        goals[prefix] = (exact, q, T)
    limits = [mink.ConfigurationLimit(model)]
    for _ in range(20):
        step(configuration, tasks, limits)
    for prefix, (exact, q, T) in goals.items():
        assert max(hand_error(configuration, prefix + "attachment_site", T)) < 1e-9
        assert panda.configuration_of(exact.joints.q(configuration.q)).isclose(
            panda.configuration_of(q), 1e-6
        )


def test_gripper_joints_are_left_alone(panda, panda_with_hand):
    model = panda_with_hand
    configuration = mink.Configuration(model)
    exact = om.ExactPoseTask(panda, model, arm_configuration=panda.configuration_of(Q_PANDA))
    np.testing.assert_array_equal(exact.joints.qpos_ids, np.arange(7))
    frame = frame_task()
    limits = [mink.ConfigurationLimit(model)]
    for q in random_joints(panda.arm, 10, np.random.default_rng(10)):
        configuration.update(np.concatenate([home_joints(panda.arm), [0.02, 0.03]]))
        T = panda.arm.fk(q)
        exact.set_target(T, panda.configuration_of(q))
        frame.set_target(mink.SE3.from_matrix(T))
        for _ in range(10):
            step(configuration, [frame, exact], limits)
        assert max(hand_error(configuration, "attachment_site", T)) < 1e-9
        np.testing.assert_allclose(configuration.q[7:], [0.02, 0.03], atol=1e-12)


def mobile_base_model(arm):
    """The project's arm, names prefixed "arm_", on a planar cart (slides x, y and a hinge about z)."""
    spec = mujoco.MjSpec()
    cart = spec.worldbody.add_body(name="cart", pos=[0, 0, 0.2])
    for name, kind, axis in (
        ("cart_x", mujoco.mjtJoint.mjJNT_SLIDE, [1, 0, 0]),
        ("cart_y", mujoco.mjtJoint.mjJNT_SLIDE, [0, 1, 0]),
        ("cart_yaw", mujoco.mjtJoint.mjJNT_HINGE, [0, 0, 1]),
    ):
        cart.add_joint(name=name, type=kind, axis=axis)
    cart.add_geom(size=[0.2, 0.2, 0.05], type=mujoco.mjtGeom.mjGEOM_BOX)
    child = mujoco.MjSpec.from_string(om.arm_mjcf(arm))
    cart.add_frame().attach_body(child.body("base"), "arm_", "")
    return spec.compile()


def test_mobile_base_moves_the_root_and_the_task_follows(panda):
    model = mobile_base_model(panda.arm)
    configuration = mink.Configuration(model, np.concatenate([[0.3, -0.2, 0.4], Q_PANDA]))
    exact = om.ExactPoseTask(panda, model, arm_configuration=panda.configuration_of(Q_PANDA), prefix="arm_")
    assert exact.root.fixed_pose is None
    np.testing.assert_array_equal(exact.joints.dof_ids, np.arange(3, 10))
    T = exact.root.pose(configuration.data) @ panda.arm.fk(Q_PANDA)
    T[:3, 3] += [0.15, 0.1, -0.05]  # a target the arm reaches from here, and the cart may help
    c = om.Configuration(panda.configuration_of(Q_PANDA).signs, (0.2,))
    exact.set_target(T, c)
    assert exact.joint_target is None  # the root moves: solved at the next compute
    frame = frame_task("arm_attachment_site")
    frame.set_target(mink.SE3.from_matrix(T))
    for _ in range(30):
        step(configuration, [frame, exact], [mink.ConfigurationLimit(model)])
    assert max(hand_error(configuration, "arm_attachment_site", T)) < 1e-9
    assert panda.configuration_of(configuration.q[3:]).isclose(c, 1e-6)
    # q* is the exact solution for the root where the cart now stands.
    T_root = np.linalg.inv(exact.root.pose(configuration.data)) @ T
    assert max(pose_errors(panda.arm.fk(exact.joint_target), T_root)) < 1e-9


def test_a_target_out_of_reach_of_a_moving_root_is_refused_and_the_old_one_kept(panda):
    """Issue 18, item 5: on the cart's slide joints, set_target of a pose 5 m away raises and
    keeps the previous target (it used to take it, and every later compute_error raised)."""
    model = mobile_base_model(panda.arm)
    configuration = mink.Configuration(model, np.concatenate([[0.3, -0.2, 0.4], Q_PANDA]))
    c = panda.configuration_of(Q_PANDA)
    exact = om.ExactPoseTask(panda, model, arm_configuration=c, prefix="arm_")
    T = exact.root.pose(configuration.data) @ panda.arm.fk(Q_PANDA)
    exact.set_target(T)
    error = exact.compute_error(configuration)  # the task has seen where the root is
    far = T.copy()
    far[:3, 3] += [5.0, 0.0, 0.0]
    with pytest.raises(om.UnreachableTarget, match="unreachable"):
        exact.set_target(far)
    np.testing.assert_allclose(exact.transform_target_to_world.as_matrix(), T, atol=1e-15)
    np.testing.assert_array_equal(exact.compute_error(configuration), error)  # the old target holds
    configuration.update(np.concatenate([[5.3, -0.2, 0.4], Q_PANDA]))  # the cart drove 5 m along x
    exact.set_target(far)  # solved for the root where it now stands
    assert np.abs(exact.compute_error(configuration)).max() < 1e-9


def test_a_target_set_before_the_root_was_seen_is_dropped_when_out_of_reach(panda):
    """A target set before any compute_* is solved at the first: if it fails there, the task
    raises and goes back to its previous target (here none), instead of raising ever after."""
    model = mobile_base_model(panda.arm)
    configuration = mink.Configuration(model, np.concatenate([[0.3, -0.2, 0.4], Q_PANDA]))
    c = panda.configuration_of(Q_PANDA)
    exact = om.ExactPoseTask(panda, model, arm_configuration=c, prefix="arm_")
    far = exact.root.pose(configuration.data) @ panda.arm.fk(Q_PANDA)
    far[:3, 3] += [5.0, 0.0, 0.0]
    exact.set_target(far, om.Configuration(c.signs, (0.1,)))
    with pytest.raises(om.UnreachableTarget, match="the target is dropped"):
        exact.compute_error(configuration)
    assert exact.transform_target_to_world is None and exact.arm_configuration == c
    with pytest.raises(mink.TargetNotSet):
        exact.compute_error(configuration)


# ---------------------------------------------------------------------------------------
# Helpers


def test_seed_puts_the_arm_at_the_exact_solution(panda, panda_with_hand):
    model = panda_with_hand
    configuration = mink.Configuration(model)
    q = random_joints(panda.arm, 1, np.random.default_rng(11))[0]
    c = panda.configuration_of(q)
    exact = om.ExactPoseTask(panda, model, arm_configuration=c)
    exact.set_target(mink.SE3.from_matrix(panda.arm.fk(q)))
    exact.seed(configuration)
    assert max(hand_error(configuration, "attachment_site", panda.arm.fk(q))) < 1e-12
    assert panda.configuration_of(configuration.q[:7]).isclose(c)
    np.testing.assert_array_equal(configuration.q[7:], model.qpos0[7:])
    np.testing.assert_allclose(exact.compute_error(configuration), 0.0, atol=1e-15)


def test_set_target_from_configuration_holds_the_arm(panda, panda_model):
    configuration = mink.Configuration(panda_model, Q_PANDA)
    exact = om.ExactPoseTask(panda, panda_model, arm_configuration=om.Configuration((1, 1, 1), (0.0,)))
    exact.set_target_from_configuration(configuration)
    assert exact.arm_configuration.isclose(panda.configuration_of(Q_PANDA))
    np.testing.assert_allclose(exact.joint_target, Q_PANDA, atol=1e-9)
    frame = frame_task()
    frame.set_target_from_configuration(configuration)
    velocity = mink.solve_ik(configuration, [frame, exact], DT, "daqp", damping=1e-3)
    assert np.abs(velocity).max() < 1e-6


# ---------------------------------------------------------------------------------------
# Bad input


def test_a_missing_joint_is_named(panda):
    model = om.arm_model(panda.arm, prefix="l_")
    with pytest.raises(om.JointNotFound, match="joint 'joint1' of arm 'panda' does not exist") as caught:
        om.ExactPoseTask(panda, model, arm_configuration=panda.configuration_of(Q_PANDA))
    assert isinstance(caught.value, mink.MinkError) and isinstance(caught.value, om.OMError)
    assert "l_joint1" in str(caught.value)  # the model's joints are listed
    with pytest.raises(om.JointNotFound, match="'x_joint1'"):
        om.ArmAngleTask(panda, model, prefix="x_")
    om.ArmAngleTask(panda, model, prefix="l_")  # found with the right prefix


def test_a_frame_that_does_not_exist_is_named(panda, panda_model):
    c = panda.configuration_of(Q_PANDA)
    with pytest.raises(om.FrameNotFound, match="site 'gripper_tcp' does not exist") as caught:
        om.ExactPoseTask(panda, panda_model, arm_configuration=c, frame_name="gripper_tcp")
    assert isinstance(caught.value, mink.InvalidFrame)
    with pytest.raises(mink.UnsupportedFrame):
        om.ExactPoseTask(panda, panda_model, arm_configuration=c, frame_type="joint")


def test_a_frame_fixed_to_the_last_link_takes_the_targets(panda):
    """Menagerie's panda.xml as it is (no attachment_site): the hand body, and a TCP site on it,
    sit at the flange turned and moved by constants, which the task measures (ArmRoot.tool);
    mink ends exactly on targets given for them, in the requested configuration."""
    load_reference_model("franka_emika_panda/panda.xml")  # skips where missing
    spec = reference_spec("franka_emika_panda/panda.xml")
    spec.body("hand").add_site(name="tcp", pos=[0.01, -0.02, 0.1034], quat=[0.9, 0.1, -0.2, 0.3])
    model = spec.compile()
    rng = np.random.default_rng(12)
    limits = [mink.ConfigurationLimit(model)]
    for name, kind in (("hand", "body"), ("tcp", "site")):
        exact = om.ExactPoseTask(
            panda, model, arm_configuration=panda.configuration_of(Q_PANDA), frame_name=name, frame_type=kind
        )
        frame = mink.FrameTask(name, kind, position_cost=1.0, orientation_cost=1.0, lm_damping=1.0)
        configuration = mink.Configuration(model)
        for q in random_joints(panda.arm, 5, rng):
            configuration.update(np.concatenate([q, [0.0, 0.0]]))
            T = configuration.get_transform_frame_to_world(name, kind)  # the frame's pose at q
            configuration.update(np.concatenate([home_joints(panda.arm), [0.0, 0.0]]))
            exact.set_target(T, panda.configuration_of(q))
            frame.set_target(T)
            np.testing.assert_allclose(exact.joint_target, q, atol=1e-9)
            for _ in range(10):
                step(configuration, [frame, exact], limits)
            hand = configuration.get_transform_frame_to_world(name, kind).as_matrix()
            assert max(pose_errors(hand, T.as_matrix())) < 1e-9
            assert panda.configuration_of(configuration.q[:7]).isclose(panda.configuration_of(q), 1e-6)


def test_a_frame_that_does_not_move_with_the_last_link_is_refused(panda, panda_with_hand):
    c = panda.configuration_of(Q_PANDA)
    with pytest.raises(om.ModelMismatch, match="not moved by the joints of arm 'panda'"):
        om.ExactPoseTask(panda, panda_with_hand, arm_configuration=c, frame_name="world", frame_type="body")
    with pytest.raises(om.ModelMismatch, match=r"joints \['finger_joint1'\] move body 'left_finger'"):
        om.ExactPoseTask(
            panda, panda_with_hand, arm_configuration=c, frame_name="left_finger", frame_type="body"
        )
    with pytest.raises(om.ModelMismatch, match="does not move rigidly with the end effector of arm 'panda'"):
        om.ExactPoseTask(panda, panda_with_hand, arm_configuration=c, frame_name="link6", frame_type="body")


def test_the_model_of_another_arm_is_refused(panda):
    """iiwa14 joint names (joint1..joint7) on a Panda model: mapped by name, but not the same
    arm: no frame fixed to its last link moves like the iiwa14's flange. (The FR3's chain is
    the Panda's, its frame turned: a Panda model serves it, through its tool offset.)"""
    iiwa14 = om.OMSolver("iiwa14")
    model = om.arm_model(panda.arm)
    with pytest.raises(om.ModelMismatch, match="does not move rigidly with the end effector of arm 'iiwa14'"):
        om.ExactPoseTask(iiwa14, model, arm_configuration=iiwa14.configuration_of(np.full(7, 0.3)))
    fr3 = om.OMSolver("fr3")
    task = om.ExactPoseTask(
        fr3,
        om.arm_model(panda.arm, prefix="fr3_"),
        arm_configuration=fr3.configuration_of(Q_PANDA),
        frame_name="fr3_attachment_site",
    )
    assert not np.allclose(task.root.tool, np.eye(4))


def test_targets_and_configurations_of_another_model(panda, panda_model):
    """A target must be set before the task is used, and a task matched to one model refuses
    a mink.Configuration of another (its joint addresses would be wrong)."""
    exact = om.ExactPoseTask(panda, panda_model, arm_configuration=panda.configuration_of(Q_PANDA))
    configuration = mink.Configuration(panda_model, Q_PANDA)
    with pytest.raises(mink.TargetNotSet):
        exact.compute_error(configuration)
    angle = om.ArmAngleTask(panda, panda_model)
    with pytest.raises(mink.TargetNotSet):
        angle.compute_jacobian(configuration)
    exact.set_target(panda.arm.fk(Q_PANDA))
    other = mink.Configuration(om.arm_model(panda.arm), Q_PANDA)
    with pytest.raises(om.ModelMismatch, match="ExactPoseTask was built for another MjModel"):
        exact.compute_error(other)


def test_an_unreachable_target_raises_and_keeps_the_old_target(panda, panda_model):
    c = panda.configuration_of(Q_PANDA)
    exact = om.ExactPoseTask(panda, panda_model, arm_configuration=c)
    exact.set_target(panda.arm.fk(Q_PANDA))
    far = panda.arm.fk(Q_PANDA)
    far[:3, 3] = [3.0, 0.0, 0.5]
    with pytest.raises(om.UnreachableTarget, match="unreachable") as caught:
        exact.set_target(far)
    assert isinstance(caught.value, mink.InvalidTarget)
    np.testing.assert_allclose(exact.joint_target, Q_PANDA, atol=1e-9)
    np.testing.assert_allclose(exact.transform_target_to_world.as_matrix(), panda.arm.fk(Q_PANDA), atol=1e-12)
    # A configuration whose only solutions break the joint limits (q4 > 0 is outside the Panda's range).
    elbow_flipped = om.Configuration((c.signs[0], -c.signs[1], c.signs[2]), c.redundancy)
    with pytest.raises(om.UnreachableTarget, match=r"joint limit|no solution"):
        exact.set_target(panda.arm.fk(Q_PANDA), elbow_flipped)
    assert exact.arm_configuration == c


def test_bad_task_definitions(panda, panda_model):
    c = panda.configuration_of(Q_PANDA)
    with pytest.raises(mink.TaskDefinitionError, match="either arm_configuration"):
        om.ExactPoseTask(panda, panda_model)
    with pytest.raises(mink.TaskDefinitionError, match="either arm_configuration"):
        om.ExactPoseTask(panda, panda_model, arm_configuration=c, optimizer=PickConfigurationOf(panda))
    with pytest.raises(mink.TaskDefinitionError, match="cost"):
        om.ExactPoseTask(panda, panda_model, arm_configuration=c, cost=-1.0)
    with pytest.raises(mink.TaskDefinitionError, match="cost"):
        om.ArmAngleTask(panda, panda_model, cost=[1.0, 2.0])
    with pytest.raises(om.InvalidInput, match="needs 3 configuration signs"):
        om.ExactPoseTask(panda, panda_model, arm_configuration=om.Configuration((1, 1)))
    with pytest.raises(om.InvalidInput, match="no arm angle"):
        om.ArmAngleTask(om.OMSolver("ur5e"), om.arm_model(om.load_arm("ur5e")))
    with pytest.raises(mink.InvalidTarget, match="finite angle"):
        om.ArmAngleTask(panda, panda_model).set_target(float("nan"))
    task = om.ExactPoseTask(panda, panda_model, optimizer=PickConfigurationOf(panda))
    with pytest.raises(mink.TaskDefinitionError, match="optimizer"):
        task.set_target(panda.arm.fk(Q_PANDA), c)


def test_task_arguments_of_the_wrong_type_are_named(panda, panda_model):
    """Issue 18, item 7: the library's errors, never an AttributeError or a MuJoCo TypeError."""
    c = panda.configuration_of(Q_PANDA)
    with pytest.raises(om.InvalidInput, match=r"model must be a mujoco\.MjModel, got str 'model'"):
        om.ExactPoseTask(panda, "model", arm_configuration=c)
    with pytest.raises(om.InvalidInput, match="solver must be an OMSolver, got None"):
        om.ExactPoseTask(None, panda_model, arm_configuration=c)
    with pytest.raises(om.InvalidInput, match=r"model must be a mujoco\.MjModel"):
        om.ArmAngleTask(panda, None)
    with pytest.raises(om.InvalidInput, match="frame_name must be a str, got int 5"):
        om.ExactPoseTask(panda, panda_model, arm_configuration=c, frame_name=5)
    with pytest.raises(om.InvalidInput, match="configuration must be a Configuration, got a tuple"):
        om.ExactPoseTask(panda, panda_model, arm_configuration=(1, 1, 1))
    with pytest.raises(mink.TaskDefinitionError, match="gain must be a finite number, got str"):
        om.ExactPoseTask(panda, panda_model, arm_configuration=c, gain="1")
    with pytest.raises(mink.TaskDefinitionError, match="cost must be numbers, got str"):
        om.ArmAngleTask(panda, panda_model, cost="1")
    task = om.ExactPoseTask(panda, panda_model, arm_configuration=c)
    with pytest.raises(om.InvalidInput, match="transform_target_to_world must be a \\(4, 4\\)"):
        task.set_target("pose")
    with pytest.raises(mink.InvalidTarget, match="finite angle"):
        om.ArmAngleTask(panda, panda_model).set_target("0.5")


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), s=st.floats(0.0, 1.0), horizon=st.floats(1e-3, 3.0))
def test_a_ways_part_ahead_lies_on_its_rest_within_the_horizon(seed, s, horizon):
    """JointWay.ahead: from the arm's projection (fraction s of the way) along the way's rest,
    at most ``horizon`` (max-norm) further, the whole rest where it is nearer."""
    from om_redundant.tasks.approach import JointWay

    rng = np.random.default_rng(seed)
    start, q_target = rng.uniform(-3.0, 3.0, (2, 7))
    way = JointWay(start, s=s)
    here, ahead = way.ahead(q_target, horizon)
    delta = q_target - start
    np.testing.assert_allclose(here, start + s * delta, atol=1e-12)
    rest = float(np.abs(q_target - here).max())
    assert float(np.abs(ahead - here).max()) == pytest.approx(min(rest, horizon), abs=1e-12)
    u = (ahead - start) @ delta / (delta @ delta)  # on the segment, not before here
    np.testing.assert_allclose(ahead, start + u * delta, atol=1e-9)
    assert s - 1e-12 <= u <= 1.0 + 1e-12
