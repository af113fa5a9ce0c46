"""The clearance's compiled kernel (``_core.arm_clearance``): the arm geoms placed by the arm's
DH chain against MuJoCo's ``mj_kinematics``, the distances (sphere and capsule arm geoms against
sphere, capsule and box obstacles, box arm geoms against sphere and capsule obstacles) against
MuJoCo's ``mj_geomDistance``, and their gradients against finite differences."""

from __future__ import annotations

import math
import warnings
from unittest import mock

import mink
import mujoco
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant import _core
from om_redundant.exceptions import ModelMismatch
from om_redundant.ik.threads import BATCH_CHUNK, run_rows
from om_redundant.redundancy.objective import segment_clearance
from om_redundant.redundancy.objective.arm_geoms import find_geom
from tests.conftest import in_threads, random_q
from tests.reference import segment_clearance as segment_numpy

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
    """The project's MJCF of the arm, a sphere on link 4 and a box on link 7 (arm geoms that
    are no capsule: a gripper's pad) and one obstacle in the world."""
    spec = mujoco.MjSpec.from_string(om.arm_mjcf(arm))
    spec.body("link4").add_geom(name="knob", type=KINDS["sphere"], size=[0.05, 0, 0], pos=[0.05, 0.0, 0.1])
    pad = dict(size=[0.04, 0.01, 0.03], pos=[0.0, 0.03, 0.1], quat=[0.9, 0.1, 0.3, 0.2])
    spec.body("link7").add_geom(name="pad", type=KINDS["box"], **pad)
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
@example(  # (a tie: at q1 = 0 link 2's capsule and the box both symmetric about the xz plane)
    kind="box",
    size=[0.25, 0.25, 0.0625],
    position=[0.0, 0.0, 0.0],
    quat=[0.0, 0.25, 0.0, 1.0],
    joints=[0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    reach=1.0,
)
def test_compiled_distances_are_mujocos(panda, kind, size, position, quat, joints, reach):
    """Every pair's distance as mj_geomDistance gives it (capped at reach), apart, touching
    or overlapping (those left to MuJoCo), for obstacles of every compiled kind anywhere
    about the arm; and the gradients match central differences of the distances, or at a
    kink (two nearest points tied) one of its one-sided differences."""
    arm = panda.arm
    clearance = scene(arm, kind, size, [0.6 * position[0], 0.6 * position[1], 0.5 + 0.5 * position[2]], quat)
    q = arm.lower + np.array(joints) * (arm.upper - arm.lower)
    d, grad = clearance.distances_within(q, reach, gradient=True)

    model, data = clearance.model, mujoco.MjData(clearance.model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    for k, (a, o) in enumerate(clearance.pairs):
        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name) for name in (a, o)]
        check_against_mujoco(model, data, *ids, reach, d[k])

    h = 1e-7
    direction = np.random.default_rng(0).normal(size=arm.dof)
    ahead, behind = (clearance.distances_within(q + s * direction, reach)[0] for s in (h, -h))
    inside = (d > 1e-4) & (d < reach - 1e-4) & (ahead < reach) & (behind < reach)
    # Where two nearest points tie (mirror images: the arm's geom and the obstacle symmetric
    # about one plane) the distance, the least of two smooth ones, has a kink: the one-sided
    # slopes differ, and the gradient is one of them.
    rate, forward, backward = grad @ direction, (ahead - d) / h, (d - behind) / h
    kink = np.abs(forward - backward) > 1e-4
    smooth = inside & ~kink
    np.testing.assert_allclose(rate[smooth], ((ahead - behind) / (2 * h))[smooth], atol=1e-6)
    sided = np.minimum(np.abs(rate - forward), np.abs(rate - backward))
    assert (sided[inside & kink] < 1e-6).all(), (rate[inside & kink], forward, backward)
    assert not grad[d >= reach].any()


def check_against_mujoco(
    model: mujoco.MjModel, data: mujoco.MjData, a: int, o: int, reach: float, found: float
):
    """found is mj_geomDistance's distance of arm geom a and obstacle o (capped at reach),
    except where MuJoCo says a sphere or capsule is apart from a box that its core overlaps
    (either of them the arm's)
    (test_a_capsule_through_a_thin_box_overlaps): there the core's distance from the box less
    the radius where the core stays outside, else at most minus the radius (the core inside)."""
    expected = mujoco.mj_geomDistance(model, data, a, o, reach, None)
    round_kinds = (int(KINDS["sphere"]), int(KINDS["capsule"]))
    core, box = (a, o) if model.geom_type[o] == KINDS["box"] else (o, a)  # (an arm box: a pad)
    cored = model.geom_type[core] in round_kinds and model.geom_type[box] == KINDS["box"]
    if cored and expected > 0.0 and (gap := _core_box_gap(model, data, core, box)) <= 0.0:
        radius = model.geom_size[core][0]
        assert found == pytest.approx(gap, abs=1e-6) if gap > -radius else found <= -radius + 1e-15
    else:
        assert found == pytest.approx(expected, abs=1e-12)


def _core_box_gap(model: mujoco.MjModel, data: mujoco.MjData, a: int, o: int, points: int = 20001) -> float:
    """The distance of geom a's core (a capsule's segment, a sphere's centre) from box o, less
    a's radius, by sampling the core: <= 0 where they overlap."""
    R, half = data.geom_xmat[o].reshape(3, 3), model.geom_size[o]
    axis = data.geom_xmat[a].reshape(3, 3)[:, 2] * (
        model.geom_size[a][1] if model.geom_type[a] == KINDS["capsule"] else 0.0
    )
    core = data.geom_xpos[a] + np.linspace(-1.0, 1.0, points)[:, None] * axis
    local = (core - data.geom_xpos[o]) @ R
    return float(np.linalg.norm(local - np.clip(local, -half, half), axis=1).min()) - model.geom_size[a][0]


def test_a_capsule_through_a_thin_box_overlaps(panda):
    """A scene hypothesis found: link 5's capsule passes through a thin box (its core crosses
    the box's slab) and MuJoCo's mj_geomDistance says 0.0015 m apart. The clearance says they
    overlap by the depth of the core in the box plus the radius: the least distance the core
    must move along a separating axis n to leave the box, which no direction of a dense sample
    beats."""
    arm = panda.arm
    clearance = scene(arm, "box", [0.25, 0.03125, 0.25], [0.0, 0.1875, 0.5], [0.0, 0.0, 0.5, 0.375])
    q = arm.lower + np.array([0.0, 0.625, 0.0, 0.0, 0.0, 0.0, 0.0]) * (arm.upper - arm.lower)
    k = clearance.pairs.index(("link5_capsule1", "obstacle"))
    found = clearance.distances_within(q, 0.05)[0][k]
    model, data = clearance.model, mujoco.MjData(clearance.model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    a, o = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in clearance.pairs[k])
    assert mujoco.mj_geomDistance(model, data, a, o, 0.05, None) > 0.0  # (MuJoCo's answer)
    assert _core_box_gap(model, data, a, o) <= -model.geom_size[a][0]  # the core touches the box
    # The depth: the least over directions n of how far the core must move along n to leave
    # the box (its ends' projections against the box's), which for a segment and a box is
    # taken on the box's axes e_i or on u x e_i (u the segment's direction), the normals of
    # their Minkowski difference's faces; no direction of a dense sample needs less.
    R, half, radius, length = data.geom_xmat[o].reshape(3, 3), model.geom_size[o], *model.geom_size[a][:2]
    u = data.geom_xmat[a].reshape(3, 3)[:, 2]
    ends = data.geom_xpos[a] + np.outer([-1.0, 1.0], u * length)

    def overlaps(n: np.ndarray) -> np.ndarray:
        n = n / np.linalg.norm(n, axis=1, keepdims=True)
        projected, extent = (ends - data.geom_xpos[o]) @ n.T, np.abs(n @ R) @ half
        return np.minimum(projected.max(axis=0) + extent, extent - projected.min(axis=0))

    depth = overlaps(np.vstack([R.T, np.cross(u, R.T)])).min()
    assert found == pytest.approx(-(depth + radius), abs=1e-12)
    assert depth <= overlaps(np.random.default_rng(0).normal(size=(200_000, 3))).min() + 1e-12
    assert_overlap_gradient(clearance, q, k)


def assert_overlap_gradient(clearance: om.Clearance, q: np.ndarray, k: int) -> None:
    """Pair k's gradient at q is that of central differences of its distance along random
    directions: for a depth across an edge of the box (the axis u x e_j, on which the whole
    core projects to one point), from the core's point nearest that edge (an end of the core
    gave a gradient off by 5x: 0.015 against 0.217)."""
    grad = clearance.distances_and_gradients(q)[1][k]
    h = 1e-7
    for direction in np.random.default_rng(3).normal(size=(5, len(q))):
        ahead, behind = (clearance.distances(q + s * direction)[k] for s in (h, -h))
        assert grad @ direction == pytest.approx((ahead - behind) / (2 * h), abs=1e-6)


def test_an_arm_box_pierced_by_a_capsule_is_the_capsule_through_a_box_turned_round(panda):
    """The scene above with the roles swapped: the thin box on link 5 (a gripper's pad) where
    it was, and the capsule fixed in the world where link 5 put it. The kernel computes an
    arm box against a sphere or capsule (the obstacle's core against the box), and where the
    core overlaps the box, MuJoCo's positive distance is replaced by the exact depth, as for
    the capsule through the box: the same distance to rounding, its gradient that of central
    differences. Moved apart, the kernel's distance is MuJoCo's and its gradient that of
    central differences (the nearest points turned round: the arm's first)."""
    arm = panda.arm
    clearance = scene(arm, "box", [0.25, 0.03125, 0.25], [0.0, 0.1875, 0.5], [0.0, 0.0, 0.5, 0.375])
    q = arm.lower + np.array([0.0, 0.625, 0.0, 0.0, 0.0, 0.0, 0.0]) * (arm.upper - arm.lower)
    model, data = clearance.model, mujoco.MjData(clearance.model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    a, o = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in ("link5_capsule1", "obstacle"))
    link5 = model.geom_bodyid[a]
    R5, p5 = data.xmat[link5].reshape(3, 3), data.xpos[link5]
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, (R5.T @ data.geom_xmat[o].reshape(3, 3)).ravel())
    spec = mujoco.MjSpec.from_string(om.arm_mjcf(arm))
    spec.body("link5").add_geom(
        name="plate",
        type=KINDS["box"],
        size=model.geom_size[o],
        pos=R5.T @ (data.geom_xpos[o] - p5),
        quat=quat,
    )
    mujoco.mju_mat2Quat(quat, data.geom_xmat[a])
    rod = dict(size=model.geom_size[a], pos=data.geom_xpos[a], quat=quat)
    spec.worldbody.add_geom(name="rod", type=KINDS["capsule"], **rod)
    turned = om.Clearance(spec.compile(), arm, ["rod"])
    d = clearance.distances(q)
    d_turned = turned.distances(q)
    k, k_turned = clearance.pairs.index(("link5_capsule1", "obstacle")), turned.pairs.index(("plate", "rod"))
    turned_data = mujoco.MjData(turned.model)
    turned_data.qpos[:] = q
    mujoco.mj_kinematics(turned.model, turned_data)
    plate, rod_id = (mujoco.mj_name2id(turned.model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in ("plate", "rod"))
    assert mujoco.mj_geomDistance(turned.model, turned_data, plate, rod_id, 0.05, None) > 0.0  # (MuJoCo's)
    assert d[k] < 0.0 and d_turned[k_turned] == pytest.approx(d[k], abs=1e-12)
    assert_overlap_gradient(turned, q, k_turned)
    q_apart = q + np.array([0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0])  # (joint 3 turned: the plate off the rod)
    d_apart, grad_apart = turned.distances_and_gradients(q_apart)
    assert d_apart[k_turned] > 0.01
    turned_data.qpos[:] = q_apart
    mujoco.mj_kinematics(turned.model, turned_data)
    check_against_mujoco(turned.model, turned_data, plate, rod_id, turned.distmax, d_apart[k_turned])
    h, direction = 1e-7, np.random.default_rng(1).normal(size=arm.dof)
    ahead, behind = (turned.distances(q_apart + s * direction)[k_turned] for s in (h, -h))
    assert grad_apart[k_turned] @ direction == pytest.approx((ahead - behind) / (2 * h), abs=1e-6)


@pytest.mark.parametrize(
    ("pos", "half", "distance", "arm_point", "box_point"),
    [
        ([0.9, 0.0, 0.0], [0.0, 0.0, 0.0], -0.15, [0.85, 0.0, 0.0], [1.0, 0.0, 0.0]),  # centre inside
        ([1.02, 0.0, 0.0], [0.0, 0.0, 0.5], -0.03, [0.97, 0.0, -0.5], [1.0, 0.0, -0.5]),  # core outside
        ([0.0, 0.0, 0.0], [0.0, 0.0, 2.0], -1.05, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),  # through the box
    ],
)
def test_box_overlap_is_the_exact_signed_distance(pos, half, distance, arm_point, box_point):
    """_core.box_overlap (the pairs whose overlap MuJoCo contradicts) on shapes whose answer
    is known, rotated and moved together: a sphere whose centre is 0.1 inside a face (radius
    0.05), a capsule along a face 0.02 outside it, a capsule through the box (its core leaves
    by 1 along x or y, its depth 1 + the radius); wrong sizes are named."""
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, 0.6, -0.8], [0.0, 0.8, 0.6]]
    )
    shift = np.array([0.3, -0.2, 0.5])
    fromto = np.empty(6)
    geom = _core.GeomPose(turn @ pos + shift, turn.ravel(), np.array(half), 0.05)
    found = _core.box_overlap(geom, _core.GeomPose(shift, turn.ravel(), np.ones(3)), fromto)
    assert found == pytest.approx(distance, abs=1e-15)
    if arm_point != box_point:  # (through the box: either of the faces it ties on)
        np.testing.assert_allclose(
            fromto, np.concatenate([turn @ arm_point, turn @ box_point]) + np.tile(shift, 2), atol=1e-15
        )
    with pytest.raises(ValueError, match="box_half"):
        _core.box_overlap(geom, _core.GeomPose(shift, turn.ravel(), np.ones(2)), fromto)


def test_threads_sharing_a_clearance_get_its_answers():
    """Four threads that share one Clearance (whose MuJoCo pairs are computed in one MjData)
    get, row by row, exactly the distances and gradients it gives one call at a time."""
    arm = om.load_arm("gen3")
    clearance = mounted(arm)
    Q = within_limits(arm, np.random.default_rng(0), 200)
    alone = [clearance.distances_and_gradients(q) for q in Q]
    shared = [None] * len(Q)

    def work(rows: range) -> None:
        for _ in range(5):
            for i in rows:
                shared[i] = clearance.distances_and_gradients(Q[i])

    in_threads(work, len(Q))
    for (d, g), (d_shared, g_shared) in zip(alone, shared, strict=True):
        np.testing.assert_array_equal(d, d_shared)
        np.testing.assert_array_equal(g, g_shared)


def test_a_batch_split_across_the_pool_is_its_rows_one_by_one():
    """A batch of rows is split across the pool's threads in chunks (the pairs the kernel
    leaves to MuJoCo filled after): it gives exactly each row's answer alone, the same batch
    made inside a pool thread's chunk (run there in one call, its helpers never queued behind
    it) too."""
    arm = om.load_arm("gen3")
    clearance = mounted(arm)
    Q = within_limits(arm, np.random.default_rng(1), 300)
    d, g = clearance.distances_and_gradients(Q)
    assert len(Q) > 2 * BATCH_CHUNK  # (split)
    for k, q in enumerate(Q):
        alone = clearance.distances_and_gradients(q)
        np.testing.assert_array_equal(d[k], alone[0])
        np.testing.assert_array_equal(g[k], alone[1])
    inside = []
    run_rows(lambda start, stop: inside.append(clearance.distances_and_gradients(Q)), 2 * BATCH_CHUNK + 1)
    for d_inside, g_inside in inside:
        np.testing.assert_array_equal(d_inside, d)
        np.testing.assert_array_equal(g_inside, g)


SHIPPED = om.arm_names()  # every 7-DOF arm, and a 6-DOF one with a prismatic joint


def within_limits(arm: om.Arm, rng: np.random.Generator, rows: int) -> np.ndarray:
    """Joint vectors drawn within the limits (within +-pi where a joint has none)."""
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (rows, arm.dof))


def mounted(arm: om.Arm) -> om.Clearance:
    """The project's MJCF of the arm with its base moved and turned in the world, a sphere on
    its last link and a box on link 5, and about it a capsule, a sphere, a box and a sphere that
    overlaps link 3 near q = 0, as a user's scene."""
    spec = mujoco.MjSpec.from_string(om.arm_mjcf(arm, prefix="l_"))
    base = spec.body("l_base")
    base.pos, base.quat = [0.3, -0.2, 0.1], [0.9, 0.1, -0.3, 0.2]
    last = spec.body(f"l_link{arm.dof}")
    last.add_geom(name="knob", type=KINDS["sphere"], size=[0.04, 0, 0], pos=[0.02, 0.03, 0.05])
    # an arm geom the kernel leaves to MuJoCo (it gives the gradients of its pairs)
    spec.body("l_link5").add_geom(
        name="plate", type=KINDS["box"], size=[0.03, 0.05, 0.01], pos=[0.0, 0.05, 0.0]
    )
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    world = spec.worldbody
    world.add_geom(name="pole", type=KINDS["capsule"], size=[0.05, 0.3, 0], pos=[0.7, -0.1, 0.5])
    world.add_geom(name="ball", type=KINDS["sphere"], size=[0.1, 0, 0], pos=[0.4, 0.3, 0.7])
    world.add_geom(name="crate", type=KINDS["box"], size=[0.1, 0.2, 0.1], pos=[0.6, -0.6, 0.2])
    near = data.body("l_link3").xpos + np.array([0.03, 0.04, 0.05])
    world.add_geom(name="touch", type=KINDS["sphere"], size=[0.1, 0, 0], pos=near)
    return om.Clearance(spec.compile(), arm, ["pole", "ball", "crate", "touch"], prefix="l_")


@pytest.mark.parametrize("name", SHIPPED)
def test_geoms_are_placed_as_mujoco_places_them(name):
    """Every arm geom's pose from the arm's DH chain (Clearance.geom_poses) is MuJoCo's
    mj_kinematics of the model to 1e-12, the arm's base moved and turned in the world and a
    geom added to the last link, on random joint vectors; and the distances are MuJoCo's."""
    arm = om.load_arm(name)
    clearance = mounted(arm)
    model, data = clearance.model, mujoco.MjData(clearance.model)
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in clearance.arm_geoms]
    assert "knob" in clearance.arm_geoms and len(ids) == len(set(ids)) > arm.dof
    Q = within_limits(arm, np.random.default_rng(1), 40)
    D = clearance.distances(Q)
    for q, dist in zip(Q, D, strict=True):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        xpos, xmat = clearance.geom_poses(q)
        np.testing.assert_allclose(xpos, data.geom_xpos[ids], rtol=0.0, atol=1e-12)
        np.testing.assert_allclose(xmat.reshape(-1, 9), data.geom_xmat[ids], rtol=0.0, atol=1e-12)
        for k, (a, o) in enumerate(clearance.pairs):
            ab = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in (a, o)]
            expected = mujoco.mj_geomDistance(model, data, *ab, clearance.distmax, None)
            assert dist[k] == pytest.approx(expected, abs=1e-12), (a, o)


@pytest.mark.parametrize("name", SHIPPED)
def test_gradients_are_finite_differences_on_every_arm(name):
    """The gradients of all rows in one call (random joint vectors, and some near q = 0 where
    a sphere overlaps link 3) match central differences of the distances (apart, and
    overlapping but for the box: MuJoCo's depth of a capsule in a box is not smooth), and
    equal the row-by-row ones."""
    arm = om.load_arm(name)
    clearance = mounted(arm)
    rng = np.random.default_rng(2)
    Q = np.vstack([within_limits(arm, rng, 25), rng.uniform(-0.1, 0.1, (5, arm.dof))])
    D, grad = clearance.distances_and_gradients(Q)
    in_box = np.array([o == "crate" for _, o in clearance.pairs])
    h, checked = 1e-7, 0
    for q, d, g in zip(Q, D, grad, strict=True):
        single = clearance.distances_and_gradients(q)
        np.testing.assert_array_equal(single[0], d)
        np.testing.assert_array_equal(single[1], g)
        direction = rng.normal(size=arm.dof)
        ahead, behind = clearance.distances(q + h * direction), clearance.distances(q - h * direction)
        smooth = (np.abs(d) > 1e-4) & (d < clearance.distmax - 1e-4) & ((d > 0.0) | ~in_box)
        checked += smooth.sum()
        np.testing.assert_allclose(g[smooth] @ direction, ((ahead - behind) / (2 * h))[smooth], atol=1e-6)
    assert checked > D.size // 2
    assert (D < 0.0).any() and (D > 0.0).any()  # overlapping pairs and pairs apart both checked


@pytest.mark.parametrize("name", SHIPPED)
def test_gradients_near_are_the_full_ones_where_the_objective_reads_them(name):
    """distances_and_gradients(q, near): the same distances, and in a row with a pair nearer
    than near the gradients of those pairs (the others zero), else all; also in the rows
    whose pairs MuJoCo computed (the overlapping sphere and the box touched). The arm geoms'
    poses of many rows in one _core.arm_geom_poses call are each row's."""
    arm = om.load_arm(name)
    clearance = mounted(arm)
    rng = np.random.default_rng(3)
    Q = np.vstack([within_limits(arm, rng, 25), rng.uniform(-0.1, 0.1, (5, arm.dof))])
    every, full = clearance.distances_and_gradients(Q)
    cores = clearance._cores
    left = np.empty(every.shape)  # which pairs the kernel leaves to MuJoCo
    out = _core.PairDistances(left, np.empty((*every.shape, 6)), None)
    _core.arm_clearance(cores, Q, clearance.distmax, math.inf, out, False)
    assert np.isnan(left).any()
    model, data = clearance.model, mujoco.MjData(clearance.model)
    for q, dist, row in zip(Q, every, left, strict=True):  # MuJoCo's pairs as mj_kinematics places the arm
        if not np.isnan(row).any():
            continue
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        for k in np.flatnonzero(np.isnan(row)).tolist():
            ab = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in clearance.pairs[k]]
            check_against_mujoco(model, data, *ab, clearance.distmax, dist[k])
    for near in (0.05, 0.2, 0.5):
        d, grad = clearance.distances_and_gradients(Q, near)
        np.testing.assert_array_equal(d, every)
        read = (every < near) | (every.min(axis=1) >= near)[:, None]
        assert read.any() and not read.all()
        np.testing.assert_array_equal(grad, np.where(read[..., None], full, 0.0))
    xpos, xmat = (
        np.empty((len(Q), len(clearance.arm_geoms), 3)),
        np.empty((len(Q), len(clearance.arm_geoms), 9)),
    )
    _core.arm_geom_poses(cores, Q, xpos, xmat)
    for q, x, m in zip(Q, xpos, xmat, strict=True):
        single = clearance.geom_poses(q)
        np.testing.assert_array_equal(x, single[0])
        np.testing.assert_array_equal(m, single[1].reshape(-1, 9))


def test_a_model_whose_links_are_not_the_arms_is_refused(panda):
    """A link moved by 1 cm in the model: the geoms do not move like the arm's chain."""
    spec = mujoco.MjSpec.from_string(om.arm_mjcf(panda.arm))
    spec.body("link4").pos = spec.body("link4").pos + np.array([0.01, 0.0, 0.0])
    spec.worldbody.add_geom(name="ball", type=KINDS["sphere"], size=[0.1, 0, 0], pos=[0.4, 0.3, 0.7])
    with pytest.raises(ModelMismatch, match="do not move like its kinematic chain"):
        om.Clearance(spec.compile(), panda.arm, ["ball"])


def test_the_kernel_refuses_arrays_of_other_sizes(panda):
    """_core.arm_clearance and arm_geom_poses check every array's size against the others: a
    ValueError, never a read past an end."""
    clearance = om.Clearance.for_arm(panda.arm, [om.Sphere([0.4, 0.1, 0.5], 0.05)])
    cores = clearance._cores
    q, n_pairs = np.zeros(7), len(clearance.pairs)
    out = _core.PairDistances(np.empty(n_pairs), np.empty((n_pairs, 6)), np.empty((n_pairs, 7)))
    assert _core.arm_clearance(cores, q, 1.0, math.inf, out, False) == 0
    short = [
        (cores, q[:6]),
        (cores._replace(obstacle_pos=cores.obstacle_pos[:0]), q),
        (cores._replace(offset=cores.offset[:-1]), q),
    ]
    for c, x in short:
        with pytest.raises(ValueError, match="disagree"):
            _core.arm_clearance(c, x, 1.0, math.inf, out, False)
    with pytest.raises(ValueError, match="disagree"):
        _core.arm_clearance(cores, q, 1.0, math.inf, out._replace(dist=out.dist[:-1]), False)
    # arm_geom_poses: A poses for each of the M rows of q
    rows, n_arm = np.zeros((3, 7)), len(clearance.arm_geoms)
    _core.arm_geom_poses(cores, rows, np.empty((3, n_arm, 3)), np.empty((3, n_arm, 9)))
    with pytest.raises(ValueError, match="poses per joint vector"):
        _core.arm_geom_poses(cores, rows, np.empty((2, n_arm, 3)), np.empty((3, n_arm, 9)))
    with pytest.raises(ValueError, match="poses per joint vector"):
        _core.arm_geom_poses(cores, rows, np.empty((3, n_arm, 3)), np.empty((3, n_arm - 1, 9)))


# -- along a way, names, errors and mink's pairs ------------------------------------------


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), floor=st.floats(-0.05, 0.15))
def test_the_clearance_along_a_way_is_bounded_from_below(panda, seed, floor):
    """minimum_along(q_a, q_b, floor) against 2,001 points of the straight segment: where it
    says clear (>= floor) every point is at least that far; where not, the segment does come
    below the floor (to within the 1 mm tolerance and the dense samples' spacing)."""
    rng = np.random.default_rng(seed)
    obstacles = [
        om.Sphere(rng.uniform([0.2, -0.5, 0.1], [0.7, 0.5, 0.9]), 0.08),
        om.Capsule([0.5, -0.6, 0.3], [0.5, 0.6, 0.3], 0.03),
    ]
    clearance = om.Clearance.for_arm(panda.arm, obstacles)
    q_a, q_b = random_q(panda.arm, 2, rng)
    along = clearance.minimum_along(q_a, q_b, floor)
    t = np.linspace(0.0, 1.0, 2001)[:, None]
    dense = clearance.minima(q_a + t * (q_b - q_a)).min()
    spacing = float(clearance._lever @ np.abs(q_b - q_a)) / 2000  # a distance's change between samples
    if along >= floor:
        assert dense >= along - 1e-12  # certified: no point of the segment is nearer
    else:
        assert dense < floor + om.redundancy.objective.segment_clearance.ALONG_TOLERANCE + spacing / 2
    # with a budget of samples: the same answer where it suffices, else undecided (NaN) and
    # only where the unbounded check needed more; never a wrong "clear"
    for budget in (0, 1, 8, 64):
        bounded = clearance.minimum_along(q_a, q_b, floor, max_samples=budget)
        if math.isnan(bounded):
            continue
        assert bounded == along
    assert clearance.minimum_along(q_a, q_b, floor, max_samples=10**6) == along
    with pytest.raises(om.InvalidInput, match="max_samples"):
        clearance.minimum_along(q_a, q_b, floor, max_samples=-1)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    kind=st.sampled_from(sorted(KINDS)),
    floor=st.floats(-0.05, 0.15),
    budget=st.sampled_from([math.inf, 0, 3, 128]),
    room=st.sampled_from([1, 256]),
)
def test_the_compiled_way_check_is_the_references(panda, seed, kind, floor, budget, room):
    """minimum_along (``_core.segment_minimum``, one call, its rounds' distances compiled)
    gives the numpy bisection's answer to the bit (tests/reference/segment_clearance.py, on
    the clearance's distances), with pairs MuJoCo computes (the box pad against a box), a
    budget of samples (NaN alike where it runs out), and samples outgrowing the first call's
    room (then called again with twice it)."""
    rng = np.random.default_rng(seed)
    position = [rng.uniform(0.2, 0.6), rng.uniform(-0.4, 0.4), rng.uniform(0.2, 0.8)]
    clearance = scene(panda.arm, kind, [0.05, 0.08, 0.1], position, [1.0, 0.2, 0.0, 0.1])
    q_a, q_b = random_q(panda.arm, 2, rng)
    lipschitz = float(clearance._lever @ np.abs(q_b - q_a))
    want = segment_numpy.segment_minimum(clearance.distances, q_a, q_b, lipschitz, floor, budget)
    with mock.patch.object(segment_clearance, "_FIRST_ROOM", room):
        got = clearance.minimum_along(q_a, q_b, floor, None if budget == math.inf else budget)
    assert got == want or (math.isnan(got) and math.isnan(want))


@pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)
def test_the_compiled_way_check_refuses_what_it_cannot_read(panda):
    """_core.segment_minimum: rows or outputs of other sizes, a negative budget and a fill that
    is not callable are refused with the error named; a fill that raises raises through; rows
    too few even for the ends (0 or 1) are answered None, nothing written past them."""
    clearance = scene(panda.arm, "box", [0.05, 0.08, 0.1], [0.3, 0.0, 0.6], [1.0, 0.0, 0.0, 0.0])
    cores, P = clearance._cores, len(clearance.pairs)
    q_a, q_b = random_q(panda.arm, 2, np.random.default_rng(3))

    def check(rows=8, budget=math.inf, fill=lambda start, stop: None, q_to=q_b, pairs=P):
        segment = _core.Segment(
            q_a, q_to, np.empty((rows, 7)), np.empty((rows, pairs)), np.empty((rows, pairs, 6))
        )
        return _core.segment_minimum(cores, segment, _core.SegmentCheck(10.0, 1.0, budget, 2e-4, 1.0), fill)

    for rows in (0, 1, 2):  # (the samples outgrow the rows: the caller gives more)
        assert check(rows=rows) is None
    for bad in (dict(q_to=q_b[:6]), dict(pairs=P - 1), dict(budget=-1.0)):
        with pytest.raises(ValueError, match="segment_minimum: sizes"):
            check(**bad)
    with pytest.raises(TypeError, match="fill must be callable"):
        check(fill=None)

    def broken(start, stop):
        raise RuntimeError("fill failed")

    with pytest.raises(RuntimeError, match="fill failed"):  # (the pad against the box: MuJoCo's)
        _core.segment_minimum(
            cores,
            _core.Segment(q_a, q_a, np.empty((8, 7)), np.empty((8, P)), np.empty((8, P, 6))),
            _core.SegmentCheck(0.0, -1.0, math.inf, 2e-4, 1.0),
            broken,
        )


def test_lever_arms_bound_how_fast_the_geoms_move(panda):
    """Every geom point's speed per unit joint rate stays below the joint's lever arm
    (finite differences of the geoms' placements and their bounding radii, random q)."""
    clearance = om.Clearance.for_arm(panda.arm, [om.Sphere([0.5, 0.0, 0.5], 0.05)])
    lever = clearance._lever
    rbound = clearance.model.geom_rbound[clearance._arm_ids]
    rng, h = np.random.default_rng(5), 1e-6
    for q in random_q(panda.arm, 50, rng):
        xpos, xmat = clearance.geom_poses(q)
        for j in range(7):
            dq = np.zeros(7)
            dq[j] = h
            moved, turned = clearance.geom_poses(q + dq)
            speed = (
                np.linalg.norm(moved - xpos, axis=1) / h
                + rbound * np.abs(turned - xmat).reshape(-1, 9).max(axis=1) / h
            )
            assert (speed <= lever[j] + 1e-6).all()


def test_an_arm_without_collision_geoms_is_named(panda):
    """Menagerie models loaded without their meshes have no collision geoms on the arm."""
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(panda.arm))
    for geom in list(spec.geoms):
        if geom.name.startswith("link"):
            geom.contype, geom.conaffinity = 0, 0
    spec.worldbody.add_geom(
        name="ball", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.05, 0, 0], pos=[0.5, 0, 0.5]
    )
    with pytest.raises(om.InvalidInput, match=r"carry no collision geoms .* om\.arm_model"):
        om.Clearance(spec.compile(), panda.arm, ["ball"])


@pytest.mark.parametrize("discard", [True, False])
def test_an_obstacle_a_urdf_dropped_is_named_with_why(tmp_path, discard):
    """A URDF's scene: MuJoCo's compiler drops the geoms that take no contacts (its
    discardvisual, on for a URDF), so a mocap ball added without contacts, an obstacle mink
    should not push, is gone: the error says that its body has no geom, and why. With
    discardvisual off the geom is there."""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(
        '<robot name="r"><link name="base"/><link name="l1"><collision><geometry><sphere radius="0.05"/>'
        '</geometry></collision></link><joint name="j1" type="revolute"><parent link="base"/>'
        '<child link="l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
        "</joint></robot>"
    )
    spec = mujoco.MjSpec.from_file(str(urdf))
    spec.compiler.discardvisual = discard
    ball = spec.worldbody.add_body(name="ball", mocap=True, pos=[0.5, 0.0, 0.5])
    ball.add_geom(name="ball", type=KINDS["sphere"], size=[0.05, 0, 0], contype=0, conaffinity=0)
    model = spec.compile()
    if discard:
        with pytest.raises(
            om.InvalidInput, match=r"no geom named 'ball': body 'ball' has none .*discardvisual"
        ):
            find_geom(model, "ball")
    else:
        assert model.geom(find_geom(model, "ball")).name == "ball"


def test_unnamed_geoms_are_named_by_their_body_and_pairs_go_to_mink(panda):
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(panda.arm))
    spec.body("link4").add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.04, 0, 0])
    post = spec.worldbody.add_body(name="post", pos=[0.6, 0.2, 0.0])
    post.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.03, 0, 0], fromto=[0, 0, 0, 0, 0, 0.8])
    post.add_geom(name="cap", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.05, 0, 0], pos=[0, 0, 0.8])
    model = spec.compile()
    clearance = om.Clearance(model, panda.arm, ["cap"])
    assert f"link4/geom{len(spec.body('link4').geoms) - 1}" in clearance.arm_geoms  # the sphere added last
    limit = mink.CollisionAvoidanceLimit(model, clearance.geom_pairs, minimum_distance_from_collisions=0.01)
    pairs = {tuple(sorted(p)) for p in limit.geom_id_pairs}
    ours = {
        tuple(sorted((a, o))) for arms, obstacles in clearance.geom_pairs for a in arms for o in obstacles
    }
    # mink keeps every pair but those of the first link (a child of the world's weld, as the post is)
    first = model.body("link1").id
    assert pairs <= ours and {p for p in ours if first not in model.geom_bodyid[list(p)]} <= pairs
    assert dropped_by_mink(model, clearance) == set(clearance.mink_drops)
    with pytest.raises(om.InvalidInput, match="moves with the arm"):
        om.Clearance(model, panda.arm, ["link4_capsule0"])


def dropped_by_mink(model: mujoco.MjModel, clearance: om.Clearance) -> set[tuple[str, str]]:
    """The clearance's pairs that mink's own CollisionAvoidanceLimit leaves out, by name."""
    limit = mink.CollisionAvoidanceLimit(model, clearance.geom_pairs, minimum_distance_from_collisions=0.01)
    kept = {tuple(sorted(p)) for p in limit.geom_id_pairs}
    pairs = [(a, o) for arms, obstacles in clearance.geom_pairs for a in arms for o in obstacles]
    return {(model.geom(a).name, model.geom(o).name) for a, o in pairs if tuple(sorted((a, o))) not in kept}


@pytest.mark.parametrize("contype, conaffinity", [(0, 0), (2, 2), (1, 0)])
def test_pairs_mink_leaves_out_are_named(panda, contype, conaffinity):
    """A mocap ball whose contype and conaffinity cannot meet the arm's (a contact-free marker,
    another collision group): mink's CollisionAvoidanceLimit leaves its pairs out, and the
    clearance says so with a warning naming them; its mink_drops are exactly the pairs mink
    leaves out (those of the first link and the world's table too, which warn of nothing)."""
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(panda.arm))
    spec.worldbody.add_geom(
        name="table", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.3, 0.4, 0.02], pos=[0.6, 0, 0]
    )
    ball = spec.worldbody.add_body(name="ball", mocap=True, pos=[0.5, 0.0, 0.6])
    ball.add_geom(
        name="ball",
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[0.05, 0, 0],
        contype=contype,
        conaffinity=conaffinity,
    )
    model = spec.compile()
    collides = bool(contype & 1 or conaffinity & 1)  # (the arm's geoms: contype = conaffinity = 1)
    if collides:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            clearance = om.Clearance(model, panda.arm, ["table", "ball"])
    else:
        with pytest.warns(UserWarning, match=r"ignores \d+ of its pairs, \(link1_capsule0, ball\)") as caught:
            clearance = om.Clearance(model, panda.arm, ["table", "ball"])
        assert f"ignores {len(clearance.arm_geoms)} of its pairs" in str(
            caught[0].message
        )  # (every arm geom's)
    assert set(clearance.mink_drops) == dropped_by_mink(model, clearance)
    assert {o for _, o in clearance.mink_drops} == ({"table"} if collides else {"table", "ball"})
