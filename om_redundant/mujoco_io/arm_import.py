r"""An arm file from a MuJoCo model (MJCF or URDF): the DH rows of its kinematic tree.

The arm's joints are the hinge and slide joints on the path from a root body (default the
world) down to the end-effector frame, a site or a body. At ``qpos = 0`` (other joints at
``qpos0``), ``mj_kinematics`` gives every joint's axis line in the world frame
(``data.xaxis``, ``data.xanchor``), expressed here in the root frame. A hinge turns about
its line by q, a slide moves along its axis by q, each by the right-hand rule about the
axis as MuJoCo has it.

Standard DH rows reproduce any sequence of such lines: joint i turns about the z-axis of
frame i-1, so frame i-1's z-axis is joint i's axis, pointing the same way (an axis opposite
to the previous one is a twist of 180 deg), and row i,
:math:`R_z(\theta_i + q_i) T_z(d_i) T_x(a_i) R_x(\alpha_i)`, carries frame i-1 to frame i
along the common normal of lines i and i+1:

* skew lines: :math:`x_i` along the common normal, :math:`d_i` the foot's height on line i,
  :math:`a_i` the distance, :math:`\alpha_i` the twist; a twist within ``NEAR_RIGHT_ANGLE``
  of a multiple of 90 deg (a model's rounded quaternions) is that multiple, and a fixed row
  :math:`R_x(\alpha_i - \alpha_{nominal})` follows;
* intersecting lines: the same with :math:`a_i = 0` and :math:`x_i` along
  :math:`z_{i-1} \times z_i`;
* parallel lines: the normal through frame i-1's origin (:math:`d_i = 0`); coincident lines
  keep :math:`x_{i-1}` (:math:`\theta_i = 0`);
* lines so close to parallel that their common normal lies far from the arm (its feet more
  than ``FAR_PER_SPAN`` times the arm's stretched length, at least 1 m, from frame i-1's
  origin and the joint's anchor): a joint row to the point of
  line i+1 nearest frame i-1's origin, then a fixed row that tilts z onto line i+1, so that
  no length is large and cancels.

Of the two directions of :math:`x_i`, the one with :math:`|\theta_i| \le 90` deg is taken.
Frame 0 lies on joint 1's axis at the foot of the root origin, its x-axis the root's x (or
y) turned perpendicular to the axis: the base transform. The last row keeps only
:math:`d_n`, the end-effector origin's height along the last axis; the tool transform holds
the rest. Lengths below ``SNAP`` metres become 0 and angles within ``SNAP`` radians of a
multiple of 90 deg become that multiple (round-off of the model's own numbers; the arm's
pose moves by less than 1e-13 m), every angle and transform is one that an arm file's
numbers give exactly (:func:`~om_redundant.kinematics.poses.exact_angle`), and the result is
checked against the model with :func:`~.model_match.compare_mujoco_model` at 1e-12.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np

from ..exceptions import FrameNotFound, InvalidInput, ModelMismatch
from ..kinematics.arm import Arm
from ..kinematics.chain import DHRow, JointKind, KinematicChain, row_transform
from ..kinematics.poses import exact_angle, exact_pose
from .frames import FRAME_OBJECTS, find_frame, given_frame_names
from .loading import load_mujoco_model
from .model_match import compare_mujoco_model

#: Largest length (m) and angle (rad) taken for round-off of 0 or of a multiple of 90 deg.
SNAP = 1e-14
#: A twist this close (rad) to a multiple of 90 deg, but not within SNAP, is written as that
#: multiple and a fixed row that adds the rest: the rows show the arm's nominal structure.
NEAR_RIGHT_ANGLE = 1e-3
#: A common normal whose feet lie farther than this many stretched lengths of the arm from
#: the joints' anchors is replaced by a joint row and a fixed row (nearly parallel axes).
FAR_PER_SPAN = 10.0
#: Largest difference (m, rad) accepted between the derived arm and the model.
IMPORT_TOLERANCE = 1e-12


def arm_from_mujoco(
    model: mujoco.MjModel | str | Path,
    frame_name: str,
    frame_type: str = "site",
    prefix: str = "",
    root: str | None = None,
    *,
    name: str | None = None,
    description: str | None = None,
    model_path: str | None = None,
) -> Arm:
    """The arm of a MuJoCo model: DH rows, limits and names of the joints from root to frame.

    Args:
        model: A compiled model, or the path of an MJCF (.xml) or URDF (.urdf) file, loaded
            by :func:`~.loading.load_mujoco_model` (missing meshes and textures skipped).
        frame_name: The end-effector site or body: its name as given, else with the prefix.
        frame_type: ``"site"`` or ``"body"``.
        prefix: Prefix of the model's names of the arm's joints (e.g. ``"wx250s/"``), which
            the frame's name may share; the arm's names are without it, and the arm keeps it
            (``arm.prefix``), as :func:`compare_mujoco_model` and
            :class:`~.arm_in_model.ArmJoints` take it.
        root: Body whose frame is the arm's root frame (the frame of ``arm.fk``); default the
            world. Joints above it (a mobile base, a torso) are not the arm's. The arm keeps
            it (``arm.root``).
        name: The arm's name; default the file's stem, else the model's name.
        description: Default: where the arm was imported from.
        model_path: The ``[mujoco] model`` of the arm file; default, for a file, its folder
            and name (Menagerie's layout, e.g. ``"agilex_piper/piper.xml"``).

    Returns:
        The arm; its forward kinematics equals the frame's pose in the root frame to 1e-12.
        Its frame name is the model's, without the prefix where it has it.

    Raises:
        FrameNotFound: No site or body of that name, with or without the prefix.
        InvalidInput: No joint, or a joint the arm cannot have (ball, free, unnamed, without
            the prefix) between root and frame (the message names the root to give); root is
            not above the frame; a file that does not load.
        ModelMismatch: The derived arm does not reproduce the model (a bug; the message
            says by how much).
    """
    if isinstance(model, (str, Path)):
        path = Path(model)
        model = load_mujoco_model(path)
        name = name or path.stem
        model_path = model_path or f"{path.resolve().parent.name}/{path.name}"
    if frame_type not in ("site", "body"):
        raise InvalidInput(f"frame_type must be 'site' or 'body', got '{frame_type}'")
    frame_id, full_frame_name = _frame(model, frame_name, frame_type, prefix)
    root_id = _body_id(model, root)
    joints = _chain_joints(model, frame_type, frame_id, root_id, root)
    joint_names = _arm_joint_names(model, joints, prefix)

    lines, T_ee = _lines_at_zero(model, joints, frame_type, frame_id, root_id)
    kinds = [
        JointKind.REVOLUTE if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE else JointKind.PRISMATIC
        for j in joints
    ]
    chain = dh_chain(lines, kinds, T_ee)
    limited = model.jnt_limited[joints].astype(bool)
    ranges = model.jnt_range[joints]
    model_name = model.names.split(b"\0", 1)[0].decode()  # the model's own name comes first
    arm = Arm(
        name=name or model_name or "imported",
        chain=chain,
        joint_names=joint_names,
        lower=np.where(limited, ranges[:, 0], -np.inf),
        upper=np.where(limited, ranges[:, 1], np.inf),
        description=description
        or f"imported from {model_path or 'a MuJoCo model'} ({frame_type} '{full_frame_name}')",
        mujoco_model=model_path,
        frame_name=full_frame_name.removeprefix(prefix),
        frame_type=frame_type,
        prefix=prefix,
        root=root,
    )
    check = compare_mujoco_model(arm, model, samples=16, tolerance=IMPORT_TOLERANCE)
    if not check.ok:
        raise ModelMismatch(f"the arm derived from the model does not reproduce it: {check.differences[0]}")
    return arm


def dh_chain(lines: np.ndarray, kinds: list[JointKind], T_ee: np.ndarray) -> KinematicChain:
    """Standard DH rows through joint axis lines (see the module docstring).

    Args:
        lines: (n, 2, 3) a point on each joint's axis and its unit direction, in the root
            frame, at q = 0.
        kinds: Revolute or prismatic, per joint.
        T_ee: (4, 4) the end-effector frame in the root frame at q = 0.

    Returns:
        A chain whose joint i moves about or along line i and whose ``fk(0)`` is T_ee.
    """
    n = len(lines)
    points = np.vstack([lines[:, 0], T_ee[:3, 3]])
    far = FAR_PER_SPAN * max(1.0, float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum()))
    F = exact_pose(_base_frame(*lines[0]))
    T_root_base = F
    rows = []
    for i in range(n):
        R, o = F[:3, :3], F[:3, 3]
        if i + 1 < n:
            p, u = R.T @ (lines[i + 1, 0] - o), R.T @ lines[i + 1, 1]  # in frame i-1
            new = _rows_to_line(p, u, kinds[i], far)
        else:
            new = [DHRow(d=_snap_length((R.T @ (T_ee[:3, 3] - o))[2]), kind=kinds[i])]
        for row in new:
            F = F @ row_transform(row)
        rows += new
    T_flange_tool = exact_pose(np.linalg.solve(F, T_ee))
    return KinematicChain(tuple(rows), T_root_base, T_flange_tool)


def _rows_to_line(p: np.ndarray, u: np.ndarray, kind: JointKind, far: float) -> list[DHRow]:
    """Rows from frame i-1 (the axes of the coordinates of p and u) to a frame on the line
    through p along u: one joint row, or a joint row and a fixed row."""
    sin_twist = math.hypot(u[0], u[1])
    if sin_twist <= SNAP:  # parallel: the normal through the origin
        theta, a = _normal_direction(p[0], p[1])
        return [_row(a, math.atan2(sin_twist, u[2]) if u[2] < 0.0 else 0.0, 0.0, theta, kind)]
    theta, _ = _normal_direction(-u[1], u[0])  # along z x u, turned to |theta| <= 90 deg
    x = np.array([math.cos(theta), math.sin(theta), 0.0])
    y = np.array([-x[1], x[0], 0.0])
    s = -(p @ y) / (u @ y)  # the foot on the line: p + s u - t z is along x
    t = p[2] + s * u[2]
    if max(abs(t), abs(s)) <= far:
        alpha = _snap_angle(math.atan2(-(u @ y), u[2]))
        nominal = _snap_angle(alpha, NEAR_RIGHT_ANGLE)
        if nominal == alpha:
            return [_row(p @ x, alpha, t, theta, kind)]
        return [_row(p @ x, nominal, t, theta, kind), _row(0.0, alpha - nominal, 0.0, 0.0, JointKind.FIXED)]
    # Nearly parallel: to the point of the line nearest the origin, then tilt z onto u.
    c = p - (p @ u) * u
    theta, a = _normal_direction(c[0], c[1])
    tilt, _ = _normal_direction(-u[1], u[0])
    tilt -= theta
    x = np.array([math.cos(theta + tilt), math.sin(theta + tilt), 0.0])
    y = np.array([-x[1], x[0], 0.0])
    return [
        _row(a, 0.0, c[2], theta, kind),
        _row(0.0, math.atan2(-(u @ y), u[2]), 0.0, tilt, JointKind.FIXED),
    ]


def _normal_direction(x: float, y: float) -> tuple[float, float]:
    """Angle theta of the direction +-(x, y) with |theta| <= 90 deg, and the signed length
    of (x, y) along it; (0, 0) for a zero vector."""
    length = math.hypot(x, y)
    if length <= SNAP:
        return 0.0, 0.0
    if x < 0.0 or (x == 0.0 and y < 0.0):
        return math.atan2(-y, -x), -length
    return math.atan2(y, x), length


def _row(a: float, alpha: float, d: float, theta: float, kind: JointKind) -> DHRow:
    return DHRow(
        a=_snap_length(a), alpha=_snap_angle(alpha), d=_snap_length(d), theta=_snap_angle(theta), kind=kind
    )


def _snap_length(value: float) -> float:
    return 0.0 if abs(value) <= SNAP else float(value)


def _snap_angle(angle: float, within: float = SNAP) -> float:
    """The nearest multiple of 90 deg if angle is within that many radians of it, else the angle
    (both exact for the file's degrees)."""
    quarter = round(angle / (math.pi / 2))
    if abs(angle - quarter * math.pi / 2) <= within:
        return math.radians(90.0 * quarter) + 0.0  # exact for the file's degrees; no -0.0
    return exact_angle(angle)


def _base_frame(point: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Frame 0: on joint 1's axis at the foot of the root origin, z along the axis, x the
    root's x (y if x is along the axis) made perpendicular to it."""
    T = np.eye(4)
    z = axis / np.linalg.norm(axis)
    reference = np.eye(3)[0] if abs(z[0]) < 0.9 else np.eye(3)[1]
    x = reference - (reference @ z) * z
    x /= np.linalg.norm(x)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = point - (point @ z) * z
    return T


def _lines_at_zero(
    model: mujoco.MjModel, joints: list[int], frame_type: str, frame_id: int, root_id: int
) -> tuple[np.ndarray, np.ndarray]:
    """Joint axis lines (n, 2, 3) and the frame's pose, in the root frame, at q = 0."""
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    data.qpos[model.jnt_qposadr[joints]] = 0.0
    mujoco.mj_kinematics(model, data)
    R_root, p_root = data.xmat[root_id].reshape(3, 3), data.xpos[root_id]
    axes = data.xaxis[joints] @ R_root
    lines = np.stack(
        [(data.xanchor[joints] - p_root) @ R_root, axes / np.linalg.norm(axes, axis=1)[:, None]], 1
    )
    T_ee = np.eye(4)
    if frame_type == "site":
        R, p = data.site_xmat[frame_id].reshape(3, 3), data.site_xpos[frame_id]
    else:
        R, p = data.xmat[frame_id].reshape(3, 3), data.xpos[frame_id]
    T_ee[:3, :3], T_ee[:3, 3] = R_root.T @ R, R_root.T @ (p - p_root)
    return lines, T_ee


def _frame(model: mujoco.MjModel, frame_name: str, frame_type: str, prefix: str) -> tuple[int, str]:
    """Id and model's name of the frame: the name as given, else with the prefix."""
    names = given_frame_names(frame_name, prefix)
    try:
        return find_frame(model, frame_type, names)
    except FrameNotFound:
        other = "body" if frame_type == "site" else "site"
        for name in names:
            if mujoco.mj_name2id(model, FRAME_OBJECTS[other], name) >= 0:
                raise InvalidInput(
                    f"the model has no {frame_type} '{name}' but a {other} of that name: give "
                    f"frame_type='{other}' (--frame-type {other})"
                ) from None
        raise


def _body_id(model: mujoco.MjModel, root: str | None) -> int:
    if root is None:
        return 0
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, root)
    if body < 0:
        raise InvalidInput(f"root body '{root}' is not in the model")
    return body


def _chain_joints(
    model: mujoco.MjModel, frame_type: str, frame_id: int, root_id: int, root: str | None
) -> list[int]:
    """The joints from the root body (exclusive) down to the frame's body, in order."""
    body = int(model.site_bodyid[frame_id]) if frame_type == "site" else frame_id
    joints: list[int] = []
    while body != root_id:
        if body == 0:
            raise InvalidInput(
                f"{frame_type} '{_name(model, frame_type, frame_id)}' is not below root body '{root}'"
            )
        start = model.body_jntadr[body]
        joints[:0] = range(start, start + model.body_jntnum[body])
        body = int(model.body_parentid[body])
    for j in joints:
        kind = mujoco.mjtJoint(model.jnt_type[j])
        if kind not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            where = _root_hint(model, j) if kind == mujoco.mjtJoint.mjJNT_FREE else "give another frame"
            raise InvalidInput(
                f"joint '{_name(model, 'joint', j)}' between the root and the {frame_type} is a "
                f"{kind.name.removeprefix('mjJNT_').lower()} joint; an arm has hinge and slide joints: "
                + where
            )
    if not joints:
        raise InvalidInput(
            f"no joint moves {frame_type} '{_name(model, frame_type, frame_id)}' relative to the root body"
        )
    return joints


def _arm_joint_names(model: mujoco.MjModel, joints: list[int], prefix: str) -> tuple[str, ...]:
    """The joints' names without the prefix, which each must have."""
    names = []
    for j in joints:
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        if not name:
            raise InvalidInput(
                f"joint {j} (in body '{_name(model, 'body', model.jnt_bodyid[j])}') "
                "has no name; an arm file names its joints"
            )
        names.append(name)
    outside = [k for k, name in enumerate(names) if not name.startswith(prefix)]
    if outside:  # the last one: the arm's joints may come after it (below a torso, a mobile base)
        k = outside[-1]
        hint = f"; if it is not the arm's, {_root_hint(model, joints[k])}" if k + 1 < len(joints) else ""
        raise InvalidInput(
            f"joint '{names[k]}' between the root and the frame does not start with the prefix "
            f"'{prefix}'{hint}"
        )
    return tuple(name.removeprefix(prefix) for name in names)


def _root_hint(model: mujoco.MjModel, joint: int) -> str:
    """Advice to start the arm below a joint: the body it moves as the root."""
    body = _name(model, "body", model.jnt_bodyid[joint])
    return f"give the body it moves, '{body}', as the root (--root {body}, root='{body}')"


def _name(model: mujoco.MjModel, kind: str, index: int) -> str:
    objtype = {
        "site": mujoco.mjtObj.mjOBJ_SITE,
        "body": mujoco.mjtObj.mjOBJ_BODY,
        "joint": mujoco.mjtObj.mjOBJ_JOINT,
    }
    return mujoco.mj_id2name(model, objtype[kind], int(index)) or f"#{index}"
