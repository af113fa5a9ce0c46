r"""Where an arm's collision geoms sit on its DH chain, and the obstacles' cores: what
``_core.arm_clearance`` reads (``_core.ArmCores``), set up once from a MuJoCo model.

A geom moved by joints 1..l sits at a fixed offset :math:`G` in link l's frame
:math:`F_l(q)` (the chain's frame before joint l+1's row), :math:`X(q) = K F_l(q) G`, with
:math:`K` the world pose of DH frame 0. Both are taken once from the model at its ``qpos0``:
:math:`K` carries the joints' axis lines of the chain onto MuJoCo's (``xaxis``,
``xanchor``), and :math:`G = (K F_l(q_0))^{-1} X(q_0)`; :func:`check_placement` checks the
placement against MuJoCo's ``mj_kinematics`` at random joint vectors.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ... import _core
from ...exceptions import InvalidInput, ModelMismatch
from ...mujoco_io.arm_in_model import MATCH_TOLERANCE, ArmJoints

#: ArmCores.kind: the cores that _core.arm_clearance computes (csrc/redundancy/redundancy.h).
POINT, SEGMENT, BOX = _core.CORE_POINT, _core.CORE_SEGMENT, _core.CORE_BOX
_CHECKS = 3  # random joint vectors at which the geoms' placement is checked against MuJoCo's
#: What ``_core.arm_clearance`` reads: the arm's links and the geoms' cores (``_core.ArmCores``).
ArmCores = _core.ArmCores


def arm_cores(
    model: mujoco.MjModel, data: mujoco.MjData, joints: ArmJoints, arm_geoms: list[int], obstacles: list[int]
) -> ArmCores:
    """The ``_core.ArmCores`` of a model placed at its ``qpos0`` in data: DH frame 0's world
    pose fitted to the joints' axis lines (:func:`_dh_frame_zero`), and each arm geom's
    offset in its link, :math:`G = F_l(q_0)^{-1} X(q_0)` at the arm's joints in ``qpos0``."""
    arm, geoms = joints.arm, arm_geoms + obstacles
    table = np.ascontiguousarray(arm.chain.table)
    slide = np.ascontiguousarray(~arm.revolute, dtype=np.uint8)
    q0 = np.ascontiguousarray(data.qpos[joints.qpos_ids])
    frames = _link_frames(table, np.concatenate([np.eye(3).ravel(), np.zeros(3)]), slide, q0)
    start = _dh_frame_zero(frames, data.xaxis[joints.joint_ids], data.xanchor[joints.joint_ids], arm.revolute)
    frames = _link_frames(table, as_row(start), slide, q0)
    inside = np.array([subtree(model, model.jnt_bodyid[j]) for j in joints.joint_ids])  # (dof, nbody)
    link = inside[:, model.geom_bodyid[arm_geoms]].sum(axis=0)
    for g, n in zip(arm_geoms, link.tolist(), strict=True):
        if not inside[:n, model.geom_bodyid[g]].all():
            raise ModelMismatch(
                f"geom '{geom_label(model, g)}' is moved by joints of arm '{arm.name}' out of the "
                "chain's order"
            )
    offset = np.empty((len(arm_geoms), 12))
    for a, (g, n) in enumerate(zip(arm_geoms, link.tolist(), strict=True)):
        X = np.eye(4)
        X[:3, :3], X[:3, 3] = data.geom_xmat[g].reshape(3, 3), data.geom_xpos[g]
        offset[a] = as_row(np.linalg.solve(frames[n], X))
    kind = np.zeros(len(geoms), dtype=np.int64)
    radius, half = np.zeros(len(geoms)), np.zeros((len(geoms), 3))
    for i, g in enumerate(geoms):
        size = model.geom_size[g]
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:
            kind[i], radius[i] = POINT, size[0]
        elif model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE:
            kind[i], radius[i], half[i, 2] = SEGMENT, size[0], size[1]
        elif model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX:
            kind[i], half[i] = BOX, size
    n_arm = len(arm_geoms)
    pairs = np.array([(a, n_arm + o) for a in range(n_arm) for o in range(len(obstacles))], dtype=np.int64)
    pairs = pairs.reshape(-1, 2)
    # bounding-sphere radii (MuJoCo's rbound; 0 means unbounded, a plane)
    rbound = np.where(model.geom_rbound[geoms] > 0.0, model.geom_rbound[geoms], np.inf)
    return ArmCores(
        table,
        np.ascontiguousarray(as_row(start)),
        np.ascontiguousarray(link, dtype=np.int64),
        offset,
        slide,
        np.ascontiguousarray(data.geom_xpos[obstacles]),
        np.ascontiguousarray(data.geom_xmat[obstacles]),
        kind,
        radius,
        half,
        pairs,
        np.ascontiguousarray(rbound[pairs[:, 0]] + rbound[pairs[:, 1]]),
    )


def lever_arms(model: mujoco.MjModel, cores: ArmCores, arm_geoms: list[int], joints: ArmJoints) -> np.ndarray:
    r"""(dof,) for each joint j a bound :math:`r_j` on how fast any point of an arm geom moves
    with it: :math:`|\partial x / \partial q_j| \le r_j` at every q, so that every pair's
    distance changes by at most :math:`\sum_j r_j |\Delta q_j|` along a joint-space segment
    (distances are 1-Lipschitz in the points' displacement).

    A revolute joint moves a point at its distance from the joint's axis, at most its distance
    from the axis's origin :math:`o_j`: the lengths of the rows from joint j's row to the geom's
    link frame (:math:`|a_k| + |d_k|`, a slide's d at its farthest limit), plus the geom's
    offset in its link and its bounding radius. A slide moves every point it carries at unit
    rate. Joints with no geom beyond them get 0; an unlimited slide inside the chain, inf.
    """
    arm = joints.arm
    rows, joint_rows = arm.chain.rows, arm.chain.joint_rows
    starts = [*joint_rows, len(rows)]  # each joint's row, then the end: link l ends before starts[l]
    length = np.array([abs(row.a) + abs(row.d) for row in rows])
    for j in np.flatnonzero(~arm.revolute).tolist():  # a slide's d moves with it, up to its limit
        length[joint_rows[j]] += max(abs(joints.lower[j]), abs(joints.upper[j]))
    size = model.geom_rbound[arm_geoms] + np.linalg.norm(cores.offset[:, 9:], axis=1)
    r = np.zeros(arm.dof)
    for j in range(arm.dof):
        for l_geom, extent in zip(cores.link.tolist(), size.tolist(), strict=True):
            if l_geom <= j:  # not moved by joint j
                continue
            if not arm.revolute[j]:
                r[j] = max(r[j], 1.0)
                continue
            r[j] = max(r[j], float(length[starts[j] : starts[l_geom]].sum()) + extent)
    return r


def _link_frames(table: np.ndarray, start: np.ndarray, slide: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The (dof + 1, 4, 4) poses of links 0..dof at q, DH frame 0 at ``start`` (csrc/redundancy/clearance.c):
    ``_core.arm_geom_poses`` of a geom at the origin of every link."""
    links = np.arange(len(q) + 1, dtype=np.int64)
    identity = np.tile(np.concatenate([np.eye(3).ravel(), np.zeros(3)]), (len(links), 1))
    xpos, xmat = np.empty((len(links), 3)), np.empty((len(links), 9))
    _core.arm_geom_poses(_core.ArmLinks(table, start, links, identity, slide), q, xpos, xmat)
    frames = np.tile(np.eye(4), (len(links), 1, 1))
    frames[:, :3, :3], frames[:, :3, 3] = xmat.reshape(-1, 3, 3), xpos
    return frames


def _dh_frame_zero(
    frames: np.ndarray, axes: np.ndarray, anchors: np.ndarray, revolute: np.ndarray
) -> np.ndarray:
    r"""The world pose (4, 4) of the arm's DH frame 0 that carries the joints' axis lines in
    DH frame 0 (z axes and origins of ``frames``, links 0..dof-1 at the same q) onto the
    model's (MuJoCo's ``xaxis`` and ``xanchor``): the rotation by the SVD of
    :math:`\sum_j a_j w_j^T` (Kabsch), the translation by least squares of
    :math:`(I - w_j w_j^T)(R o_j + t - x_j) = 0` over the revolute joints (a slide's line may
    lie anywhere along its axis)."""
    a, o = frames[:-1, :3, 2], frames[:-1, :3, 3]
    U, _, Vt = np.linalg.svd(a.T @ axes)
    R = Vt.T @ np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))]) @ U.T
    across = np.eye(3) - axes[revolute, :, None] * axes[revolute, None, :]  # (n, 3, 3)
    rhs = np.einsum("nij,nj->ni", across, anchors[revolute] - o[revolute] @ R.T)
    t = np.linalg.lstsq(across.reshape(-1, 3), rhs.reshape(-1), rcond=None)[0]
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def check_placement(model: mujoco.MjModel, joints: ArmJoints, arm_ids: np.ndarray, geom_poses) -> None:
    """The arm geoms' poses from the arm's chain (``geom_poses(q)``, as
    :meth:`~om_redundant.Clearance.geom_poses`) must be MuJoCo's at random joint vectors
    within the limits, to :data:`MATCH_TOLERANCE`."""
    data = mujoco.MjData(model)
    low = np.where(np.isfinite(joints.lower), joints.lower, -np.pi)
    high = np.where(np.isfinite(joints.upper), joints.upper, np.pi)
    for q in np.random.default_rng(0).uniform(low, high, (_CHECKS, joints.arm.dof)):
        data.qpos[:] = joints.qpos_with(model.qpos0, q)
        mujoco.mj_kinematics(model, data)
        xpos, xmat = geom_poses(q)
        position = np.abs(xpos - data.geom_xpos[arm_ids]).max(initial=0.0)
        rotation = np.abs(xmat.reshape(-1, 9) - data.geom_xmat[arm_ids]).max(initial=0.0)
        if max(position, rotation) > MATCH_TOLERANCE:
            raise ModelMismatch(
                f"the collision geoms of arm '{joints.arm.name}' in the model do not move like its "
                f"kinematic chain ({position:.2g} m, {rotation:.2g} off at q = {np.round(q, 3).tolist()})"
            )


def body_pose(data: mujoco.MjData, body: int) -> np.ndarray:
    """World pose (4, 4) of a body in data (its kinematics as last computed)."""
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = data.xmat[body].reshape(3, 3), data.xpos[body]
    return T


def as_row(T: np.ndarray) -> np.ndarray:
    """A pose (4, 4) as (12,): rotation row-major, then position (csrc/redundancy/clearance.c)."""
    return np.concatenate([T[:3, :3].ravel(), T[:3, 3]])


def geom_label(model: mujoco.MjModel, geom: int) -> str:
    """A geom's name, or for an unnamed one its body's name and its place among the body's
    geoms (``"link3/geom1"``; an unnamed body is ``"body<id>"``)."""
    name = model.geom(geom).name
    if name:
        return name
    body = int(model.geom_bodyid[geom])
    return f"{model.body(body).name or f'body{body}'}/geom{geom - int(model.body_geomadr[body])}"


def subtree(model: mujoco.MjModel, root: int) -> np.ndarray:
    """Whether each body is ``root`` or one of its descendants."""
    inside = np.zeros(model.nbody, dtype=bool)
    for b in range(model.nbody):  # parents come before their children
        inside[b] = b == root or (b > 0 and inside[model.body_parentid[b]])
    return inside


#: The largest coordinate or size (m) of an obstacle geom: distances are computed in doubles to
#: about 1e-16 of the largest coordinates, 1e-10 m at this extent; beyond about 1e154 their
#: squares overflow (a sphere of radius 1e155 about the arm was reported clear).
MAX_EXTENT = 1e6


def find_geom(model: mujoco.MjModel, name: str) -> int:
    """The id of the model's geom named ``name``; InvalidInput if there is none (saying so
    where a body of that name has no geom: a URDF's, whose geoms without contacts MuJoCo's
    compiler drops)."""
    index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
    if index < 0:
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        hint = ""
        if body >= 0 and model.body_geomnum[body] == 0:
            hint = (
                f": body '{name}' has none (a model compiled from a URDF drops the geoms that take "
                "no contacts unless its compiler's discardvisual is off)"
            )
        raise InvalidInput(f"the MuJoCo model has no geom named '{name}'{hint}")
    return index


def check_extent(model: mujoco.MjModel, obstacles: np.ndarray, position: np.ndarray) -> None:
    """Every obstacle's position (O, 3) and sizes within :data:`MAX_EXTENT` (m) (all at once:
    :meth:`Clearance.update <om_redundant.Clearance.update>` checks them every tick)."""
    sizes = model.geom_size[obstacles]
    if np.abs(position).max(initial=0.0) <= MAX_EXTENT and sizes.max(initial=0.0) <= MAX_EXTENT:
        return  # (NaN is not)
    extent = np.maximum(np.abs(position).max(axis=1), sizes.max(axis=1))
    k = int(np.flatnonzero(~(extent <= MAX_EXTENT))[0])
    raise InvalidInput(
        f"obstacle geom '{geom_label(model, int(obstacles[k]))}': its position and sizes must be "
        f"within {MAX_EXTENT:g} m, got {extent[k]:.3g} m"
    )
