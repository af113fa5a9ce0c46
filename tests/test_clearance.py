"""The clearance's compiled distances (``ckernels.geom_distances``, sphere and capsule arm geoms
against sphere, capsule and box obstacles) against MuJoCo's ``mj_geomDistance``, and their
gradients (``ckernels.distance_gradients``) against finite differences."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om

KINDS = {
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
    "box": mujoco.mjtGeom.mjGEOM_BOX,
}
unit = st.floats(-1.0, 1.0)


@pytest.fixture(scope="module")
def panda() -> om.OMSolver:
    return om.OMSolver("panda")


def scene(
    arm: om.Arm, kind: str, size: list[float], position: list[float], quat: list[float]
) -> om.Clearance:
    """The project's MJCF of the arm, a sphere on link 4 (an arm geom that is no capsule) and
    one obstacle in the world."""
    spec = mujoco.MjSpec.from_string(om.arm_mjcf(arm))
    spec.body("link4").add_geom(name="knob", type=KINDS["sphere"], size=[0.05, 0, 0], pos=[0.05, 0.0, 0.1])
    spec.worldbody.add_geom(name="obstacle", type=KINDS[kind], size=size, pos=position, quat=quat)
    return om.Clearance(spec.compile(), arm, ["obstacle"])


@settings(max_examples=150, deadline=None)
@given(
    kind=st.sampled_from(sorted(KINDS)),
    size=st.lists(st.floats(0.005, 0.3), min_size=3, max_size=3),
    position=st.lists(unit, min_size=3, max_size=3),
    quat=st.lists(unit, min_size=4, max_size=4).filter(lambda x: np.linalg.norm(x) > 0.1),
    joints=st.lists(st.floats(0.0, 1.0), min_size=7, max_size=7),
    reach=st.sampled_from([0.05, 0.2, 1.0]),
)
def test_compiled_distances_are_mujocos(panda, kind, size, position, quat, joints, reach):
    """Every pair's distance as mj_geomDistance gives it (capped at reach), apart, touching
    or overlapping (those left to MuJoCo), for obstacles of every compiled kind anywhere
    about the arm; and the gradients match central differences of the distances."""
    arm = panda.arm
    clearance = scene(arm, kind, size, [0.6 * position[0], 0.6 * position[1], 0.5 + 0.5 * position[2]], quat)
    q = arm.lower + np.array(joints) * (arm.upper - arm.lower)
    d, grad = clearance.distances_within(q, reach, gradient=True)

    model, data = clearance.model, mujoco.MjData(clearance.model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    for k, (a, o) in enumerate(clearance.pairs):
        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name) for name in (a, o)]
        expected = mujoco.mj_geomDistance(model, data, *ids, reach, None)
        assert d[k] == pytest.approx(expected, abs=1e-12), (a, o)

    h = 1e-7
    direction = np.random.default_rng(0).normal(size=arm.dof)
    ahead, behind = (clearance.distances_within(q + s * direction, reach)[0] for s in (h, -h))
    smooth = (d > 1e-4) & (d < reach - 1e-4) & (ahead < reach) & (behind < reach)
    np.testing.assert_allclose(grad[smooth] @ direction, ((ahead - behind) / (2 * h))[smooth], atol=1e-6)
    assert not grad[d >= reach].any()
