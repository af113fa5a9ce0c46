"""A user's MuJoCo model against an arm: compare joints and end-effector frame.

:func:`compare_mujoco_model` answers "is this MJCF the arm of this arm file?": it finds the
arm's joints by name (with an optional prefix) and compares, in this order,

1. names: every arm joint exists in the model;
2. types: hinge for a revolute joint, slide for a prismatic one;
3. order: each joint lies after the previous one on the model's kinematic tree;
4. limits: limited exactly where the arm is, with the same range;
5. kinematics over random joint vectors within the limits (other joints of the model at
   ``qpos0``): each joint's axis and anchor against the arm's joint axis, then the
   end-effector frame (a site or a body) against ``arm.fk(q)``.

Poses are compared in the arm's root frame: the world, or a body of the model given as
``root`` (an arm mounted somewhere in a scene; default the arm's own, ``arm.root``). Every
difference is named; the first one is the reason a command line gives, and where the arm's
joints lie off their axes because its chain starts at another body, it names that body.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..exceptions import FrameNotFound, InvalidInput
from ..kinematics.arm import Arm
from ..validation import as_count, as_instance, as_positive
from .frames import arm_frame_names, find_frame, given_frame_names
from .mjcf import DEFAULT_SITE

#: Default largest accepted difference: metres for positions and limits, radians for angles.
DEFAULT_TOLERANCE = 1e-9
MAX_SAMPLES = 100_000  # random joint vectors of the kinematic comparison


@dataclass(frozen=True)
class ModelComparison:
    """The outcome of :func:`compare_mujoco_model`.

    Attributes:
        differences: One sentence per difference found, first the structural ones (names,
            types, order, limits), then the first joint whose axis differs, then the frame.
            Empty when the model matches.
        frame: The end-effector frame compared, e.g. ``"site 'attachment_site'"``.
        samples: Random joint vectors compared (0 when a structural difference prevents it).
        max_axis_error: Largest angle between a model joint axis and the arm's (rad).
        max_anchor_error: Largest distance of a model hinge anchor from the arm's axis (m).
        max_position_error: Largest ``|p_model - p_arm|`` of the frame (m).
        max_orientation_error: Largest rotation angle between the frames (rad).
    """

    differences: tuple[str, ...]
    frame: str
    samples: int
    max_axis_error: float = math.nan
    max_anchor_error: float = math.nan
    max_position_error: float = math.nan
    max_orientation_error: float = math.nan

    @property
    def ok(self) -> bool:
        return not self.differences


def compare_mujoco_model(
    arm: Arm,
    model: mujoco.MjModel,
    *,
    frame: str | None = None,
    prefix: str | None = None,
    root: str | None = None,
    samples: int = 100,
    seed: int = 0,
    tolerance: float = DEFAULT_TOLERANCE,
) -> ModelComparison:
    """Compare a MuJoCo model with an arm (see the module docstring for what is compared).

    Args:
        arm: The arm.
        model: The compiled model, e.g. from :func:`~om_redundant.load_mujoco_model`.
        frame: Name of the end-effector site, or body, in the model: as given, else with the
            prefix; default the arm's frame (``arm.frame_name``, else ``"end_effector"``) with
            the prefix, else as it is.
        prefix: Prepended to the arm's joint names (and tried on the frame's); default the
            arm's (``arm.prefix``).
        root: Body of the model whose frame is the arm's root frame; default the arm's
            (``arm.root``), else the world (``"world"`` names it).
        samples: Random joint vectors for the kinematic comparison.
        seed: Seed of those joint vectors.
        tolerance: Largest accepted difference (m for positions and limits, rad for angles).

    Raises:
        InvalidInput: An argument of the wrong type; samples (1 to 100,000), seed or tolerance
            out of range; the root body does not exist.
    """
    as_instance(arm, Arm, "arm")
    as_instance(model, mujoco.MjModel, "model", "a mujoco.MjModel")
    for name, value in (("frame", frame), ("prefix", prefix), ("root", root)):
        if value is not None:
            as_instance(value, str, name)
    samples = as_count(samples, "samples", 1, MAX_SAMPLES)
    seed = as_count(seed, "seed", 0, 2**63 - 1)
    tolerance = as_positive(tolerance, "tolerance")
    prefix = arm.prefix if prefix is None else prefix
    root = root or arm.root
    root_id = 0
    if root is not None:
        root_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, root)
        if root_id < 0:
            raise InvalidInput(f"root body '{root}' is not in the model")
    frame_kind, frame_id, frame_text = _frame(arm, model, prefix, frame)
    differences = _structure(arm, model, prefix, tolerance)
    if frame_id < 0:
        differences.append(f"{frame_text} is not in the model")
    if differences:
        return ModelComparison(tuple(differences), frame_text, 0)

    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, prefix + n) for n in arm.joint_names]
    differences += _order(arm, model, ids, frame_kind, frame_id, frame_text)
    if differences:
        return ModelComparison(tuple(differences), frame_text, 0)
    frame_at = (ids, frame_kind, frame_id, frame_text)
    result = _kinematics(arm, model, *frame_at, root_id, samples, seed, tolerance)
    if result.ok:
        return result
    first, *others = result.differences
    first += _root_hint(arm, model, frame_at, root_id, tolerance)
    return dataclasses.replace(result, differences=(first, *others))


def _frame(arm: Arm, model: mujoco.MjModel, prefix: str, frame: str | None) -> tuple[str, int, str]:
    """Kind ("site" or "body"), id (-1 if absent) and description of the end-effector frame."""
    if frame is None:
        names = arm_frame_names(arm.frame_name or DEFAULT_SITE, prefix)
        kinds = ["body", "site"] if arm.frame_type == "body" else ["site", "body"]
    else:
        names, kinds = given_frame_names(frame, prefix), ["site", "body"]
    for kind in kinds:
        try:
            frame_id, name = find_frame(model, kind, names)
        except FrameNotFound:
            continue
        return kind, frame_id, f"{kind} '{name}'"
    return kinds[0], -1, f"{kinds[0]} '{names[0]}'"


def _root_hint(arm: Arm, model: mujoco.MjModel, frame_at: tuple, root_id: int, tolerance: float) -> str:
    """Where the arm matches the model from another root body (one above its first joint's
    body: the chain starts elsewhere than the root compared), a sentence naming it; else ""."""
    body = int(model.body_parentid[model.jnt_bodyid[frame_at[0][0]]])
    while True:
        if body != root_id and _kinematics(arm, model, *frame_at, body, 8, 0, tolerance).ok:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body)
            return f"; the arm matches the model from root body '{name}' (--root {name}, root='{name}')"
        if body == 0:
            return ""
        body = int(model.body_parentid[body])


def _structure(arm: Arm, model: mujoco.MjModel, prefix: str, tolerance: float) -> list[str]:
    """Names, types and limits of the arm's joints in the model."""
    differences = []
    model_joints = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    for k, name in enumerate(arm.joint_names):
        full = prefix + name
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, full)
        if j < 0:
            shown = ", ".join(n or "?" for n in model_joints[:12]) + (
                ", ..." if len(model_joints) > 12 else ""
            )
            differences.append(
                f"joint '{full}' (arm joint {k + 1}) is not in the model; model joints: {shown}"
            )
            continue
        want = mujoco.mjtJoint.mjJNT_HINGE if arm.revolute[k] else mujoco.mjtJoint.mjJNT_SLIDE
        if model.jnt_type[j] != want:
            got = mujoco.mjtJoint(model.jnt_type[j]).name.removeprefix("mjJNT_").lower()
            differences.append(
                f"joint '{full}' is a {got} joint in the model, {want.name.removeprefix('mjJNT_').lower()} "
                "in the arm"
            )
            continue
        arm_limited = bool(np.isfinite(arm.lower[k]) and np.isfinite(arm.upper[k]))
        if bool(model.jnt_limited[j]) != arm_limited:
            differences.append(
                f"joint '{full}' is {'limited' if model.jnt_limited[j] else 'unlimited'} in the model, "
                f"{'limited' if arm_limited else 'unlimited'} in the arm"
            )
        elif arm_limited:
            lo, hi = model.jnt_range[j]
            if max(abs(lo - arm.lower[k]), abs(hi - arm.upper[k])) > tolerance:
                differences.append(
                    f"joint '{full}' range differs: model [{lo:.6g}, {hi:.6g}], "
                    f"arm [{arm.lower[k]:.6g}, {arm.upper[k]:.6g}]"
                )
    return differences


def _order(
    arm: Arm, model: mujoco.MjModel, ids: list[int], frame_kind: str, frame_id: int, frame_text: str
) -> list[str]:
    """Each joint after the previous one on the tree, the frame after the last joint."""

    def after(body: int, joint_before: int, same_body_ok: bool) -> bool:
        before = model.jnt_bodyid[joint_before]
        if body == before:
            return same_body_ok
        while body > 0:
            body = model.body_parentid[body]
            if body == before:
                return True
        return False

    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in ids]
    for k in range(1, len(ids)):
        if not after(model.jnt_bodyid[ids[k]], ids[k - 1], ids[k] > ids[k - 1]):
            return [
                f"joint '{names[k]}' does not follow joint '{names[k - 1]}' on the model's kinematic chain"
            ]
    body = frame_id if frame_kind == "body" else model.site_bodyid[frame_id]
    if not after(body, ids[-1], True):
        return [f"{frame_text} does not follow the last joint '{names[-1]}' on the model's kinematic chain"]
    return []


def _arm_joint_axes(arm: Arm, placements: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Origins (dof, 3) and unit axes (dof, 3) of the arm's joints at q, in the root frame."""
    T = np.eye(4)
    origins, axes = np.empty((arm.dof, 3)), np.empty((arm.dof, 3))
    for i in range(arm.dof):
        T = T @ placements[i]
        origins[i], axes[i] = T[:3, 3], T[:3, 2]
        motion = np.eye(4)
        if arm.revolute[i]:
            c, s = math.cos(q[i]), math.sin(q[i])
            motion[:2, :2] = [[c, -s], [s, c]]
        else:
            motion[2, 3] = q[i]
        T = T @ motion
    return origins, axes


def _kinematics(
    arm: Arm,
    model: mujoco.MjModel,
    ids: list[int],
    frame_kind: str,
    frame_id: int,
    frame_text: str,
    root_id: int,
    samples: int,
    seed: int,
    tolerance: float,
) -> ModelComparison:
    data = mujoco.MjData(model)
    placements, _ = arm.chain.joint_placements()
    span = np.where(arm.revolute, np.pi, 1.0)
    lower = np.where(np.isfinite(arm.lower), arm.lower, -span)
    upper = np.where(np.isfinite(arm.upper), arm.upper, span)
    Q = np.random.default_rng(seed).uniform(lower, upper, (int(samples), arm.dof))
    qpos = model.jnt_qposadr[ids]
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in ids]
    axis_error = np.zeros(arm.dof)  # worst over the samples, per joint
    anchor_error = np.zeros(arm.dof)
    position_error = orientation_error = 0.0
    for q in Q:
        data.qpos[:] = model.qpos0
        data.qpos[qpos] = q
        mujoco.mj_kinematics(model, data)
        R_root, p_root = data.xmat[root_id].reshape(3, 3), data.xpos[root_id]
        origins, axes = _arm_joint_axes(arm, placements, q)
        model_axes = data.xaxis[ids] @ R_root  # rows R_root^T axis
        model_anchors = (data.xanchor[ids] - p_root) @ R_root
        chord = np.linalg.norm(model_axes - axes, axis=1)
        axis_error = np.maximum(axis_error, 2.0 * np.arcsin(np.minimum(chord / 2.0, 1.0)))
        off_axis = np.linalg.norm(np.cross(model_anchors - origins, axes), axis=1)
        anchor_error = np.maximum(anchor_error, np.where(arm.revolute, off_axis, 0.0))
        if frame_kind == "site":
            R, p = data.site_xmat[frame_id].reshape(3, 3), data.site_xpos[frame_id]
        else:
            R, p = data.xmat[frame_id].reshape(3, 3), data.xpos[frame_id]
        T = arm.fk(q)
        position_error = max(position_error, float(np.linalg.norm(R_root.T @ (p - p_root) - T[:3, 3])))
        orientation_error = max(orientation_error, _angle(T[:3, :3].T @ R_root.T @ R))

    differences = []
    for k in range(arm.dof):
        if axis_error[k] > tolerance:
            differences.append(
                f"joint '{names[k]}' axis differs from the arm's by up to {axis_error[k]:.3g} rad"
                + (" (reversed)" if axis_error[k] > np.pi - 1e-6 else "")
            )
            break
        if anchor_error[k] > tolerance:
            differences.append(
                f"joint '{names[k]}' lies up to {anchor_error[k]:.3g} m off the arm's joint axis"
            )
            break
    if position_error > tolerance or orientation_error > tolerance:
        differences.append(
            f"{frame_text} differs from the arm's end-effector frame by up to {position_error:.3g} m "
            f"and {orientation_error:.3g} rad"
        )
    return ModelComparison(
        tuple(differences),
        frame_text,
        len(Q),
        float(axis_error.max()),
        float(anchor_error.max()),
        position_error,
        orientation_error,
    )


def _angle(R: np.ndarray) -> float:
    """Angle of a rotation matrix, accurate for small angles too."""
    sin_angle = 0.5 * np.linalg.norm([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return float(math.atan2(sin_angle, (np.trace(R) - 1.0) / 2.0))
