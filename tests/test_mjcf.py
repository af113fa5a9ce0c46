"""The generated MJCF models: names and limits, exact kinematics, Menagerie drop-in, physics."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

import om_redundant as om
from om_redundant.mujoco_io.mjcf import DEFAULT_SITE, arm_mjcf, arm_model, scene_mjcf
from tests.conftest import load_reference_model, random_q

ARMS = om.arm_names()
MENAGERIE_ARMS = [name for name in ARMS if om.load_arm(name).mujoco_model]


def frame_poses(model: mujoco.MjModel, kind: str, name: str, Q: np.ndarray):
    """World position (M, 3) and rotation (M, 3, 3) of a site or body for each qpos row of Q."""
    data = mujoco.MjData(model)
    if kind == "site":
        frame, pos, mat = model.site(name).id, data.site_xpos, data.site_xmat
    else:
        frame, pos, mat = model.body(name).id, data.xpos, data.xmat
    position, rotation = np.empty((len(Q), 3)), np.empty((len(Q), 3, 3))
    for i, q in enumerate(Q):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        position[i], rotation[i] = pos[frame], mat[frame].reshape(3, 3)
    return position, rotation


def names(model: mujoco.MjModel, objtype: mujoco.mjtObj, count: int) -> list[str]:
    return [mujoco.mj_id2name(model, objtype, i) for i in range(count)]


@pytest.mark.parametrize("name", ARMS)
def test_joint_names_order_and_limits(name):
    arm = om.load_arm(name)
    model = arm_model(arm)
    assert arm.dof == model.njnt == model.nq == model.nv
    assert tuple(names(model, mujoco.mjtObj.mjOBJ_JOINT, model.njnt)) == arm.joint_names
    np.testing.assert_array_equal(model.jnt_qposadr, np.arange(arm.dof))
    hinge, slide = mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE
    np.testing.assert_array_equal(model.jnt_type, np.where(arm.revolute, hinge, slide))
    limited = model.jnt_limited.astype(bool)
    np.testing.assert_array_equal(arm.lower, np.where(limited, model.jnt_range[:, 0], -np.inf))
    np.testing.assert_array_equal(arm.upper, np.where(limited, model.jnt_range[:, 1], np.inf))


@pytest.mark.parametrize("name", ARMS)
def test_end_effector_pose_equals_fk(name):
    """The end-effector site (and body, for a body frame) is at arm.fk(q) for 1,000 random q."""
    arm = om.load_arm(name)
    model = arm_model(arm)
    Q = random_q(arm, 1000, np.random.default_rng(3))
    T = arm.fk(Q)
    kinds = ["site", "body"] if arm.frame_type == "body" else ["site"]
    for kind in kinds:
        position, rotation = frame_poses(model, kind, arm.frame_name or DEFAULT_SITE, Q)
        np.testing.assert_allclose(position, T[:, :3, 3], rtol=0, atol=1e-9)
        np.testing.assert_allclose(rotation, T[:, :3, :3], rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", MENAGERIE_ARMS)
def test_drops_in_for_the_menagerie_model(name):
    """Same joint names and the same end-effector frame, by name, as the reference model."""
    arm = om.load_arm(name)
    model, reference = arm_model(arm), load_reference_model(arm.mujoco_model)
    joints = names(model, mujoco.mjtObj.mjOBJ_JOINT, model.njnt)
    assert joints == names(reference, mujoco.mjtObj.mjOBJ_JOINT, reference.njnt)
    Q = random_q(arm, 1000, np.random.default_rng(4))
    ours = frame_poses(model, arm.frame_type, arm.frame_name, Q)
    theirs = frame_poses(reference, arm.frame_type, arm.frame_name, Q)
    np.testing.assert_allclose(ours[0], theirs[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(ours[1], theirs[1], rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", ["panda", "spherical", "ur5e"])
def test_prefix_renames_everything_and_keeps_the_kinematics(name):
    arm = om.load_arm(name)
    plain, prefixed = arm_model(arm), arm_model(arm, prefix="l_")
    for objtype, count in [
        (mujoco.mjtObj.mjOBJ_BODY, plain.nbody),
        (mujoco.mjtObj.mjOBJ_JOINT, plain.njnt),
        (mujoco.mjtObj.mjOBJ_GEOM, plain.ngeom),
        (mujoco.mjtObj.mjOBJ_SITE, plain.nsite),
    ]:
        expected = [n if n == "world" else f"l_{n}" for n in names(plain, objtype, count)]
        assert names(prefixed, objtype, count) == expected
    assert 'class="l_collision"' in arm_mjcf(arm, prefix="l_")
    Q = random_q(arm, 100, np.random.default_rng(5))
    site = arm.frame_name or DEFAULT_SITE
    for a, b in zip(
        frame_poses(plain, "site", site, Q), frame_poses(prefixed, "site", f"l_{site}", Q), strict=True
    ):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("name", ARMS)
def test_geoms_are_named_capsules_of_the_radius(name):
    arm = om.load_arm(name)
    model = arm_model(arm, radius=0.02)
    assert model.ngeom > arm.dof  # one per joint at least, plus the segments
    assert (model.geom_type == mujoco.mjtGeom.mjGEOM_CAPSULE).all()
    np.testing.assert_array_equal(model.geom_size[:, 0], 0.02)
    assert (model.geom_contype == 1).all() and (model.geom_conaffinity == 1).all()
    for g in range(model.ngeom):
        assert model.geom(g).name.startswith(f"{model.body(model.geom_bodyid[g]).name}_capsule")
    assert (model.body_mass[model.jnt_bodyid] > 0).all()


@pytest.mark.parametrize("radius", [0.0, -0.01, math.nan, math.inf, "thick"])
def test_bad_radius_is_rejected(radius):
    with pytest.raises(om.InvalidInput, match="radius"):
        arm_mjcf(om.load_arm("panda"), radius=radius)


@pytest.mark.parametrize("name", ARMS)
def test_no_pair_of_links_touches_everywhere(name):
    """The exclusions leave no contact that holds in every configuration (scene included)."""
    arm = om.load_arm(name)
    model = mujoco.MjModel.from_xml_string(scene_mjcf(arm))
    data = mujoco.MjData(model)
    always = None
    for q in random_q(arm, 200, np.random.default_rng(6)):
        data.qpos[:] = q
        mujoco.mj_forward(model, data)
        bodies = model.geom_bodyid[np.array([[c.geom1, c.geom2] for c in data.contact], int).reshape(-1, 2)]
        pairs = {tuple(sorted(p)) for p in bodies.tolist()}
        always = pairs if always is None else always & pairs
    assert always == set()


@pytest.mark.parametrize("name", ARMS)
@pytest.mark.parametrize("build", [arm_mjcf, scene_mjcf])
def test_simulates_under_gravity(name, build):
    arm = om.load_arm(name)
    model = mujoco.MjModel.from_xml_string(build(arm))
    data = mujoco.MjData(model)
    data.qpos[:] = random_q(arm, 1, np.random.default_rng(8))[0]
    start = data.qpos.copy()
    for _ in range(200):
        mujoco.mj_step(model, data)
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()
    assert not np.array_equal(data.qpos, start)  # gravity moved the arm
    assert [w.number for w in data.warning] == [0] * len(data.warning)


def test_a_frame_body_named_like_a_link_keeps_its_name():
    """An arm whose end-effector frame is a body named 'link7' (Flexiv Rizon 4's): the writer's
    seventh link becomes 'link7_body', the frame keeps its name, the kinematics stay."""
    arm = dataclasses.replace(om.load_arm("panda"), frame_name="link7", frame_type="body")
    model = om.arm_model(arm)
    assert model.body("link7").parentid[0] == model.body("link7_body").id
    result = om.compare_mujoco_model(arm, model)
    assert result.ok and result.frame == "body 'link7'", result.differences
