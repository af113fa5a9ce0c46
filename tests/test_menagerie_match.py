"""Every arm file against its MuJoCo Menagerie model (kinematics only).

``arm.fk(q)`` must equal the pose of the model's end-effector frame for q = qpos (same
joint order, zero and sign) to 1e-9, and joint names and limits must be the model's.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import om_redundant as om
from tests.conftest import load_reference_model, random_q

ARMS = [name for name in om.arm_names() if om.load_arm(name).mujoco_model]


@pytest.fixture(scope="module", params=ARMS)
def arm_and_model(request):
    arm = om.load_arm(request.param)
    return arm, load_reference_model(arm.mujoco_model)


def test_every_real_arm_names_its_reference_model():
    assert set(ARMS) == {"ur5e", "panda", "fr3", "iiwa14", "gen3", "xarm7", "sawyer"}


def test_joint_names_order_and_limits(arm_and_model):
    arm, model = arm_and_model
    assert arm.dof == model.njnt == model.nq
    assert arm.joint_names == tuple(model.joint(j).name for j in range(model.njnt))
    np.testing.assert_array_equal(model.jnt_qposadr, np.arange(arm.dof))
    limited = model.jnt_limited.astype(bool)
    np.testing.assert_array_equal(arm.lower, np.where(limited, model.jnt_range[:, 0], -np.inf))
    np.testing.assert_array_equal(arm.upper, np.where(limited, model.jnt_range[:, 1], np.inf))


def test_fk_equals_the_reference_frame(arm_and_model):
    """arm.fk(q) is the frame's world pose for 1,000 random q within limits."""
    arm, model = arm_and_model
    data = mujoco.MjData(model)
    if arm.frame_type == "site":
        frame = model.site(arm.frame_name).id
        pos, mat = data.site_xpos, data.site_xmat
    else:
        frame = model.body(arm.frame_name).id
        pos, mat = data.xpos, data.xmat
    Q = random_q(arm, 1000, np.random.default_rng(7))
    T = arm.fk(Q)
    position, rotation = np.empty((len(Q), 3)), np.empty((len(Q), 3, 3))
    for i, q in enumerate(Q):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        position[i], rotation[i] = pos[frame], mat[frame].reshape(3, 3)
    np.testing.assert_allclose(T[:, :3, 3], position, rtol=0, atol=1e-9)
    np.testing.assert_allclose(T[:, :3, :3], rotation, rtol=0, atol=1e-9)
