"""Targets that leave a rotation free: a tool axis to point (any turn about it), a position to
reach (any orientation). The optimiser picks the turn with psi; the task reaches the pose
exactly where it matters (the position, the tool axis), in a mink loop."""

from __future__ import annotations

import mink
import numpy as np
import pytest

import om_redundant as om
from om_redundant.redundancy.free_rotation import rotation
from tests.conftest import random_q

Q_START = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.8])


@pytest.fixture(scope="module")
def panda():
    return om.OMSolver("panda")


def test_a_turn_keeps_the_pivot_and_the_axis(panda):
    rng = np.random.default_rng(0)
    T = panda.arm.fk(random_q(panda.arm, 1, rng)[0])
    free = om.FreeRotation.tool_axis(axis=[0.0, 0.6, 0.8], pivot=[0.01, 0.02, 0.1])
    R = rotation(free.axes[0], 1.1)
    turned = free.turned(T, R)
    pivot = lambda P: (P @ np.append(free.pivot, 1.0))[:3]  # noqa: E731
    np.testing.assert_allclose(pivot(turned), pivot(T), atol=1e-15)
    np.testing.assert_allclose(turned[:3, :3] @ free.axes[0], T[:3, :3] @ free.axes[0], atol=1e-15)
    assert len(free.trials(R, 0.01)) == 2 and len(om.FreeRotation.orientation().trials(R, 0.01)) == 6
    with pytest.raises(om.InvalidInput, match="one axis or three"):
        om.FreeRotation([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    with pytest.raises(om.InvalidInput, match="must not be zero"):
        om.FreeRotation.tool_axis(axis=[0.0, 0.0, 0.0])


@pytest.mark.parametrize("free", ["tool_axis", "orientation"])
def test_the_task_reaches_what_is_asked_and_settles(panda, free):
    """The hand down at three points round a ball; FrameTask costs free the same rotation. The
    position (and the tool axis) exactly, the joints settled on q* (no turn or psi back and
    forth about an optimum), clear of the ball, the choice's pose the solution's."""
    model = om.arm_model(panda.arm)
    optimizer = om.RedundancyOptimizer(panda, [om.Sphere([0.4, 0.2, 0.6], 0.05)], min_clearance=0.02)
    task = om.ExactPoseTask(panda, model, optimizer=optimizer, free=free)
    configuration = mink.Configuration(model, Q_START)
    cost = [1.0, 1.0, 0.0] if free == "tool_axis" else 0.0
    frame = mink.FrameTask("attachment_site", "site", position_cost=1.0, orientation_cost=cost)
    limits = [
        mink.ConfigurationLimit(model),
        mink.VelocityLimit(model, dict.fromkeys(panda.arm.joint_names, 2.0)),
    ]
    for xyz in ([0.5, 0.2, 0.3], [0.45, -0.25, 0.35], [0.6, 0.0, 0.25]):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = np.diag([1.0, -1.0, -1.0]), xyz
        frame.set_target(mink.SE3.from_matrix(T))
        for _ in range(1500):
            task.set_target(T)
            velocity = mink.solve_ik(configuration, [frame, task], 0.002, "daqp", damping=1e-6, limits=limits)
            configuration.integrate_inplace(velocity, 0.002)
        F = panda.arm.fk(configuration.q)
        assert np.linalg.norm(F[:3, 3] - T[:3, 3]) < 1e-9
        if free == "tool_axis":
            assert F[:3, 2] @ T[:3, 2] > 1.0 - 1e-12
        np.testing.assert_allclose(configuration.q, task.joint_target, atol=1e-9)  # settled
        choice = task.choice
        assert choice.ok and choice.clearance >= 0.02 and choice.turn is not None
        np.testing.assert_allclose(panda.arm.fk(choice.solution.q), choice.pose, atol=1e-9)


def test_a_free_rotation_is_an_optimizer_choice(panda):
    model = om.arm_model(panda.arm)
    c = panda.configuration_of(Q_START)
    with pytest.raises(mink.TaskDefinitionError, match="chosen by an optimizer"):
        om.ExactPoseTask(panda, model, arm_configuration=c, free="orientation")
    with pytest.raises(mink.TaskDefinitionError, match="'tool_axis' or 'orientation'"):
        om.ExactPoseTask(panda, model, optimizer=om.RedundancyOptimizer(panda), free="yaw")
    optimizer = om.RedundancyOptimizer(panda)
    T = panda.arm.fk(Q_START)
    previous = optimizer.choose(T)
    with pytest.raises(om.InvalidInput, match="another free rotation"):
        optimizer.choose(T, previous, free=om.FreeRotation.tool_axis())
