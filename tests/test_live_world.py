"""The world moves: obstacles on mocap bodies, a second arm, the arm's own mobile base.

``Clearance.update`` reads them from a ``mujoco.MjData``, and ``ExactPoseTask`` does so every
tick from its ``mink.Configuration``: at every tick of a mink loop, every pair's distance
equals MuJoCo's own ``mj_geomDistance`` in the configuration's data to 1e-9 m, and the task's
choice keeps the optimiser's clearance from the obstacles where they are now.
"""

from __future__ import annotations

import dataclasses

import mink
import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from tests.conftest import in_threads, random_q, solver_of

DT = 0.002
MIN_CLEARANCE = 0.03
Q_PANDA = np.array([0.3, -0.4, 0.2, -2.2, 0.3, 1.9, 0.6])


@pytest.fixture(scope="module")
def panda():
    return om.OMSolver("panda")


def mujoco_distances(clearance: om.Clearance, data: mujoco.MjData) -> np.ndarray:
    """Every pair's distance by MuJoCo in data (its kinematics current), in the pairs' order."""
    model, fromto = clearance.model, np.empty(6)
    ids = [(a, o) for arms, obstacles in clearance.geom_pairs for a in arms for o in obstacles]
    return np.array([mujoco.mj_geomDistance(model, data, a, o, clearance.distmax, fromto) for a, o in ids])


def ball_scene(arm: om.Arm) -> mujoco.MjModel:
    """The arm, a mocap ball and a mocap capsule."""
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(arm))
    ball = spec.worldbody.add_body(name="ball", mocap=True, pos=[0.0, 0.8, 1.0])
    ball.add_geom(name="ball", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.05, 0, 0])
    rod = spec.worldbody.add_body(name="rod", mocap=True, pos=[0.6, -0.6, 0.2])
    rod.add_geom(name="rod", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.03, 0.15, 0])
    return spec.compile()


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_update_reads_where_mocap_obstacles_are(panda, seed):
    """Random joints and random mocap poses: after update, the distances are MuJoCo's."""
    rng = np.random.default_rng(seed)
    model = ball_scene(panda.arm)
    clearance = om.Clearance(model, panda.arm, ["ball", "rod"])
    data = mujoco.MjData(model)
    q = random_q(panda.arm, 1, rng)[0]
    data.qpos[:7] = q
    data.mocap_pos[:] = rng.uniform([0.0, -0.6, 0.0], [0.8, 0.6, 1.0], (2, 3))
    quat = rng.normal(size=(2, 4))
    data.mocap_quat[:] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    mujoco.mj_kinematics(model, data)
    version = clearance.version
    assert clearance.update(data) and clearance.version == version + 1
    assert not clearance.update(data)  # nothing moved since
    np.testing.assert_allclose(clearance.distances(q), mujoco_distances(clearance, data), rtol=0.0, atol=1e-9)


def test_update_refuses_data_of_another_model(panda):
    clearance = om.Clearance(ball_scene(panda.arm), panda.arm, ["ball"])
    with pytest.raises(om.InvalidInput, match="MjData of the clearance's own model"):
        clearance.update(mujoco.MjData(ball_scene(panda.arm)))
    with pytest.raises(om.InvalidInput, match="got ndarray"):
        clearance.update(np.zeros(3))


@pytest.mark.parametrize("where", [[np.nan, 0.0, 0.5], [2e6, 0.0, 0.5], [0.5, -np.inf, 0.5]])
def test_update_refuses_an_obstacle_moved_out_of_the_world(panda, where):
    """A mocap obstacle moved to NaN, infinity or beyond MAX_EXTENT is refused naming the
    geom, and the world read before stays (no distance from it)."""
    model = ball_scene(panda.arm)
    clearance = om.Clearance(model, panda.arm, ["ball", "rod"])
    data = mujoco.MjData(model)
    data.mocap_pos[0] = [0.5, 0.0, 0.5]
    mujoco.mj_kinematics(model, data)
    clearance.update(data)
    before, version = clearance.distances(Q_PANDA), clearance.version
    data.mocap_pos[0] = where
    mujoco.mj_kinematics(model, data)
    with pytest.raises(om.InvalidInput, match="obstacle geom 'ball': its position and sizes must be within"):
        clearance.update(data)
    assert clearance.version == version
    np.testing.assert_array_equal(clearance.distances(Q_PANDA), before)


def loop(configuration, tasks, limits, ticks, move, check) -> None:
    """A mink loop: move the world, then a tick, then check; ticks times."""
    for k in range(ticks):
        move(k)
        mujoco.mj_kinematics(configuration.model, configuration.data)
        velocity = mink.solve_ik(configuration, tasks, DT, "daqp", damping=1e-6, limits=limits)
        configuration.integrate_inplace(velocity, DT)
        check(k)


@pytest.mark.parametrize("unclear_ways", [False, True])
def test_a_ball_moving_into_the_arm_is_seen_every_tick(panda, unclear_ways, monkeypatch):
    """A mocap ball moves through the elbow's place while the hand holds its pose: at every
    tick the task's distances are MuJoCo's in the configuration's data, and the task's
    choice keeps the optimiser's clearance from the ball where it is now. Also where every
    fresh choice's joint-space way is reported not clear (the best taken): such a way has no
    floor and is not re-checked (else it blocks itself, tick after tick)."""
    model = ball_scene(panda.arm)
    clearance = om.Clearance(model, panda.arm, ["ball", "rod"])
    optimizer = om.RedundancyOptimizer(panda, clearance, min_clearance=MIN_CLEARANCE, max_step=0.005)
    fresh = []
    if unclear_ways:
        choose = optimizer.choose

        def unclear(*args, **kwargs):
            choice = choose(*args, **kwargs)
            if choice.rechosen or kwargs.get("previous") is None:
                fresh.append(choice)
                return dataclasses.replace(choice, way_clear=False)
            return choice

        monkeypatch.setattr(optimizer, "choose", unclear)
    task = om.ExactPoseTask(panda, model, optimizer=optimizer)
    configuration = mink.Configuration(model)
    configuration.update(np.concatenate([Q_PANDA, configuration.q[7:]]))
    data = configuration.data
    T = panda.arm.fk(Q_PANDA)
    frame = mink.FrameTask("attachment_site", "site", position_cost=1.0, orientation_cost=1.0)
    frame.set_target(mink.SE3.from_matrix(T))
    task.set_target(T)
    elbow = data.xpos[model.body("link4").id].copy()
    start = elbow + np.array([0.0, 0.4, 0.0])
    data.mocap_pos[0] = start
    limits = [
        mink.ConfigurationLimit(model),
        mink.VelocityLimit(model, dict.fromkeys(panda.arm.joint_names, 3.0)),
    ]
    seen = []

    def move(k):
        data.mocap_pos[0] = start + (elbow - start) * min(1.0, k / 400)  # into where the elbow was
        if k in (100, 300):
            task.reset_choice()  # (a fresh choice from the arm's joints: a way, re-checked as the ball moves)

    def check(k):
        task.set_target(T)
        q = configuration.q[:7]
        np.testing.assert_allclose(
            clearance.distances(q), mujoco_distances(clearance, data), rtol=0.0, atol=1e-9
        )
        q_star = task.joint_target
        data_at_star = mujoco.MjData(model)
        data_at_star.qpos[:], data_at_star.mocap_pos[:] = configuration.q, data.mocap_pos
        data_at_star.qpos[:7] = q_star
        mujoco.mj_kinematics(model, data_at_star)
        seen.append(mujoco_distances(clearance, data_at_star).min())

    loop(configuration, [frame, task], limits, 600, move, check)
    assert len(fresh) >= 3 if unclear_ways else not fresh  # (the first choice, and the two afresh)
    assert min(seen) >= MIN_CLEARANCE - 1e-9  # every tick's q* clear of the ball where it was
    assert np.linalg.norm(panda.arm.fk(configuration.q[:7])[:3, 3] - T[:3, 3]) < 1e-6
    assert clearance.minimum(configuration.q[:7]) >= MIN_CLEARANCE - 2e-3  # the arm made room


def test_tracking_at_a_held_pose_weighs_each_step_where_the_obstacles_are_now(panda):
    """The hand held at one pose while a ball comes at the elbow, 1 mm a tick: every tracked
    choice is weighed in the world as it is at that call (its clearance D(q*) where the ball
    is now, at least min_clearance). A step that loses value at the same pose is refused only
    where the obstacles have not moved: the previous choice's value was of a world gone (it
    held psi while the ball came within 4.8 mm of q*)."""
    model = ball_scene(panda.arm)
    clearance = om.Clearance(model, panda.arm, ["ball", "rod"])
    optimizer = om.RedundancyOptimizer(panda, clearance, min_clearance=MIN_CLEARANCE, max_step=0.005)
    data = mujoco.MjData(model)
    data.qpos[:7] = Q_PANDA
    mujoco.mj_kinematics(model, data)
    elbow = data.xpos[model.body("link4").id].copy()
    start = elbow + np.array([0.0, 0.4, 0.0])
    T = panda.arm.fk(Q_PANDA)
    choice, psi = None, []
    for k in range(401):
        data.mocap_pos[0] = start + (elbow - start) * k / 400
        mujoco.mj_kinematics(model, data)
        clearance.update(data)
        q = Q_PANDA if choice is None else choice.solution.q
        choice = optimizer.choose(T, previous=choice, q_current=q)
        assert choice.ok and choice.clearance_version == clearance.version
        assert choice.clearance == pytest.approx(clearance.minimum(choice.solution.q), abs=1e-12)
        assert choice.clearance >= MIN_CLEARANCE - 1e-9
        psi.append(choice.configuration.redundancy[0])
    assert np.ptp(psi) > 0.5  # (the elbow made way)


def two_arms(arm: om.Arm) -> mujoco.MjModel:
    """Two copies of the arm facing each other 1.1 m apart, joints prefixed l_ and r_."""
    spec = mujoco.MjSpec()
    for prefix, x, yaw in (("l_", 0.0, 0.0), ("r_", 1.1, np.pi)):
        frame = spec.worldbody.add_frame(pos=[x, 0, 0], quat=[np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)])
        child = mujoco.MjSpec.from_string(om.arm_mjcf(arm))
        frame.attach_body(child.body("base"), prefix, "")
    return spec.compile()


def test_a_second_arm_moving_toward_the_first_is_seen_every_tick(panda):
    model = two_arms(panda.arm)
    other = [model.geom(g).name for g in range(model.ngeom) if model.geom(g).name.startswith("r_")]
    clearance = om.Clearance(model, panda.arm, other, prefix="l_")
    optimizer = om.RedundancyOptimizer(panda, clearance, min_clearance=MIN_CLEARANCE, max_step=0.005)
    task = om.ExactPoseTask(panda, model, optimizer=optimizer, prefix="l_")
    configuration = mink.Configuration(model)
    q_other = np.array([0.0, 0.2, 0.0, -1.6, 0.0, 1.8, 0.0])
    configuration.update(np.concatenate([Q_PANDA, q_other]))
    data = configuration.data
    T = task.root.pose(data) @ panda.arm.fk(Q_PANDA)
    frame = mink.FrameTask("l_attachment_site", "site", position_cost=1.0, orientation_cost=1.0)
    frame.set_target(mink.SE3.from_matrix(T))
    task.set_target(T)
    right = slice(7, 14)
    reaching = np.array([0.0, 0.9, 0.0, -1.0, 0.0, 1.9, 0.0])  # the right arm reaches across
    limits = [mink.ConfigurationLimit(model)]
    errors = []

    def move(k):
        data.qpos[right] = q_other + (reaching - q_other) * min(1.0, k / 300)

    def check(k):
        task.set_target(T)
        q = configuration.q[:7]
        errors.append(np.abs(clearance.distances(q) - mujoco_distances(clearance, data)).max())

    loop(configuration, [frame, task], limits, 400, move, check)
    assert max(errors) < 1e-9
    assert clearance.version > 300  # every move was read


@settings(max_examples=6, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(["panda", "sawyer"]))
def test_a_pose_swept_again_after_the_obstacles_moved_answers_as_a_fresh_sweep(seed, name):
    """The optimiser keeps a swept pose's linked paths (they depend on the pose alone): a
    pose chosen again after the ball and the rod moved, from the paths it kept, chooses
    exactly as an optimiser that never saw the pose (its intervals, psi and joints bit for
    bit), globally and from the arm's joints."""
    solver = solver_of(name)
    rng = np.random.default_rng(seed)
    model = ball_scene(solver.arm)
    clearances = [om.Clearance(model, solver.arm, ["ball", "rod"]) for _ in range(2)]
    kept, fresh = (om.RedundancyOptimizer(solver, c, min_clearance=MIN_CLEARANCE) for c in clearances)
    q = random_q(solver.arm, 2, rng)
    T = solver.arm.fk(q[0])
    kept.choose(T), kept.choose(T, q_current=q[1])  # (the obstacles at the model's qpos0)
    data = mujoco.MjData(model)
    hand = T[:3, 3]
    data.mocap_pos[:] = hand + rng.uniform(-0.3, 0.3, (2, 3))  # (near the hand, where they matter)
    mujoco.mj_kinematics(model, data)
    for clearance in clearances:
        clearance.update(data)
    for q_current in (None, q[1]):
        again, first = (o.choose(T, q_current=q_current) for o in (kept, fresh))
        assert again.ok == first.ok and again.reason == first.reason
        assert again.intervals == first.intervals
        if first.ok:
            assert again.configuration == first.configuration
            np.testing.assert_array_equal(again.solution.q, first.solution.q)
            assert again.value == first.value


def test_threads_sharing_an_optimiser_take_its_kept_paths_as_one(panda):
    """Four threads choose among the same poses again and again (their linked paths taken
    from the optimiser's memo, and put there, at once): every answer is the one an optimiser
    alone gives."""
    model = ball_scene(panda.arm)
    shared, alone = (
        om.RedundancyOptimizer(
            panda, om.Clearance(model, panda.arm, ["ball", "rod"]), min_clearance=MIN_CLEARANCE
        )
        for _ in range(2)
    )
    poses = [panda.arm.fk(q) for q in random_q(panda.arm, 3, np.random.default_rng(2))]
    expected = [alone.choose(T) for T in poses]
    cases = [k % len(poses) for k in range(24)]
    found: list = [None] * len(cases)

    def work(rows: range) -> None:
        for k in rows:
            found[k] = shared.choose(poses[cases[k]])

    in_threads(work, len(cases))
    for k, choice in enumerate(found):
        want = expected[cases[k]]
        assert choice.ok == want.ok and choice.intervals == want.intervals
        if want.ok:
            np.testing.assert_array_equal(choice.solution.q, want.solution.q)


def test_the_arms_own_mobile_base_is_followed_by_the_clearance(panda):
    """The arm on a cart driven around a fixed pole: the distances are MuJoCo's every tick."""
    spec = mujoco.MjSpec()
    cart = spec.worldbody.add_body(name="cart", pos=[0, 0, 0.2])
    for name, kind, axis in (
        ("cart_x", mujoco.mjtJoint.mjJNT_SLIDE, [1, 0, 0]),
        ("cart_yaw", mujoco.mjtJoint.mjJNT_HINGE, [0, 0, 1]),
    ):
        cart.add_joint(name=name, type=kind, axis=axis)
    cart.add_geom(size=[0.2, 0.2, 0.05], type=mujoco.mjtGeom.mjGEOM_BOX)
    cart.add_frame().attach_body(mujoco.MjSpec.from_string(om.arm_mjcf(panda.arm)).body("base"), "arm_", "")
    spec.worldbody.add_geom(
        name="pole",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        size=[0.04, 0, 0],
        fromto=[0.9, 0.3, 0, 0.9, 0.3, 1.2],
    )
    model = spec.compile()
    clearance = om.Clearance(model, panda.arm, ["pole"], prefix="arm_")
    optimizer = om.RedundancyOptimizer(panda, clearance, min_clearance=MIN_CLEARANCE, max_step=0.005)
    task = om.ExactPoseTask(panda, model, optimizer=optimizer, prefix="arm_")
    configuration = mink.Configuration(model, np.concatenate([[0.0, 0.0], Q_PANDA]))
    data = configuration.data
    T = task.root.pose(data) @ panda.arm.fk(Q_PANDA)
    frame = mink.FrameTask("arm_attachment_site", "site", position_cost=1.0, orientation_cost=1.0)
    frame.set_target(mink.SE3.from_matrix(T))
    task.set_target(T)
    limits = [mink.ConfigurationLimit(model)]
    errors, clear = [], []

    def move(k):  # the cart drives on, turning (the hand's target stays in the world)
        data.qpos[:2] = [0.2 * min(1.0, k / 200), 0.3 * min(1.0, k / 200)]

    def check(k):
        task.set_target(T)
        q = configuration.q[2:9]
        errors.append(np.abs(clearance.distances(q) - mujoco_distances(clearance, data)).max())
        clear.append(task.choice.clearance)

    loop(configuration, [frame, task], limits, 300, move, check)
    assert max(errors) < 1e-9
    assert min(clear) >= MIN_CLEARANCE
