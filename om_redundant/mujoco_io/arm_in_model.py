r"""Where an arm sits inside a user's MuJoCo model: its joints, and its root frame.

A model may hold more than the arm: a gripper's joints, a mobile base, a second arm whose
names carry a prefix such as ``"l_"``. :class:`ArmJoints` finds the arm's joints by name
(``prefix + arm.joint_names[i]``) and gives their qpos and dof addresses;
:class:`ArmRoot` finds the arm's root frame, the frame in which ``arm.fk`` and the OM solver
express poses, so that a target in MuJoCo's world frame can be handed to the solver.
"""

from __future__ import annotations

import mujoco
import numpy as np
from mink import FRAME_TO_POS_ATTR, FRAME_TO_XMAT_ATTR, SUPPORTED_FRAMES, UnsupportedFrame
from scipy.spatial.transform import Rotation

from ..exceptions import JointNotFound, ModelMismatch
from ..kinematics.arm import Arm
from ..validation import as_instance
from .frames import arm_frame_names, find_frame, given_frame_names
from .mjcf import DEFAULT_SITE

#: Largest disagreement (m, rad) accepted between ``arm.fk`` and the model's end-effector frame.
MATCH_TOLERANCE = 1e-6
#: Random joint vectors from which the root and tool offsets are measured and checked.
_CHECKS = 6


class ArmJoints:
    """The arm's joints in a MuJoCo model, found by name.

    Args:
        arm: The arm.
        model: A MuJoCo model that holds the arm, possibly among other joints.
        prefix: Prepended to the arm's joint names, e.g. ``"l_"``; default the arm's
            (``arm.prefix``, from its arm file).

    Attributes:
        arm: The arm.
        model: The model.
        prefix: The name prefix.
        names: The arm's joint names in the model, prefix included.
        joint_ids: (dof,) joint ids in the model.
        qpos_ids: (dof,) addresses of the arm's joints in ``qpos``.
        qpos_index: The same as a slice where they are consecutive (reads and writes
            faster than the index array).
        dof_ids: (dof,) addresses of the arm's joints in the tangent space (columns of an
            ``(k, nv)`` task Jacobian).
        lower, upper: (dof,) joint limits, the tighter of the arm's and the model's.

    Raises:
        JointNotFound: A joint is not in the model; the message names it.
        ModelMismatch: A joint has another type (a revolute joint must be a hinge, a
            prismatic one a slide).
        InvalidInput: arm is not an :class:`Arm`, model not a ``mujoco.MjModel`` or prefix not
            a string.
    """

    def __init__(self, arm: Arm, model: mujoco.MjModel, prefix: str | None = None):
        as_instance(arm, Arm, "arm")
        as_instance(model, mujoco.MjModel, "model", "a mujoco.MjModel")
        prefix = arm.prefix if prefix is None else as_instance(prefix, str, "prefix")
        self.arm, self.model, self.prefix = arm, model, prefix
        self.names = tuple(prefix + name for name in arm.joint_names)
        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) for name in self.names]
        for name, joint_id in zip(self.names, ids, strict=True):
            if joint_id == -1:
                raise JointNotFound(name, arm.name, model)
        self.joint_ids = np.array(ids)
        wanted = np.where(arm.revolute, mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
        for name, joint_id, kind in zip(self.names, ids, wanted, strict=True):
            if model.jnt_type[joint_id] != kind:
                found = mujoco.mjtJoint(model.jnt_type[joint_id]).name
                raise ModelMismatch(
                    f"joint '{name}' of arm '{arm.name}' is a {found} in the model; "
                    f"the arm needs a {mujoco.mjtJoint(kind).name}"
                )
        self.qpos_ids = model.jnt_qposadr[self.joint_ids]
        first, count = int(self.qpos_ids[0]), len(self.qpos_ids)
        consecutive = np.array_equal(self.qpos_ids, np.arange(first, first + count))
        self.qpos_index = slice(first, first + count) if consecutive else self.qpos_ids
        self.dof_ids = model.jnt_dofadr[self.joint_ids]
        limited = model.jnt_limited[self.joint_ids].astype(bool)
        ranges = model.jnt_range[self.joint_ids]
        self.lower = np.where(limited, np.maximum(arm.lower, ranges[:, 0]), arm.lower)
        self.upper = np.where(limited, np.minimum(arm.upper, ranges[:, 1]), arm.upper)

    def q(self, qpos: np.ndarray) -> np.ndarray:
        """The arm's joint vector (dof,) out of a model's qpos."""
        return qpos[self.qpos_index].copy()

    def qpos_with(self, qpos: np.ndarray, q: np.ndarray) -> np.ndarray:
        """A copy of qpos with the arm's joints set to q."""
        out = np.array(qpos, dtype=np.float64)
        out[self.qpos_ids] = q
        return out

    def within_limits(self, q: np.ndarray) -> bool:
        """Whether the arm's joint vector q is within :attr:`lower` and :attr:`upper`."""
        return bool(((q >= self.lower) & (q <= self.upper)).all())

    def nearest_turn(self, q_target: np.ndarray, q: np.ndarray) -> np.ndarray:
        """q_target with each revolute joint shifted by a multiple of 2 pi to the value nearest
        q, where that value is within the limits (else the joint keeps q_target's value)."""
        if np.abs(q - q_target).max() < np.pi:  # every joint within half a turn: no shift
            return q_target
        turns = np.round((q - q_target) / (2.0 * np.pi))
        shifted = q_target + 2.0 * np.pi * np.where(self.arm.revolute, turns, 0.0)
        inside = (shifted >= self.lower) & (shifted <= self.upper)
        return np.where(inside, shifted, q_target)

    def check_model(self, model: mujoco.MjModel, who: str) -> None:
        """Raise :class:`ModelMismatch` unless ``model`` is the model these joints were found in."""
        if model is not self.model:
            raise ModelMismatch(
                f"{who} was built for another MjModel than this configuration's; build it with "
                "configuration.model"
            )


class ArmRoot:
    r"""The arm's root frame in a MuJoCo model, located through an end-effector frame.

    ``arm.fk(q)`` is the pose of the arm's end-effector frame F in the root frame. Nothing
    moves between the root and the body B that carries the arm's first joint's body (its
    parent), nor between F and the frame E named here (the arm's own frame, or any frame
    fixed to its last link: a hand, a TCP site), so

    .. math::  T_{world,E}(q) = T_{world,B}\, C\, \mathrm{fk}(q)\, X

    with constants C (the root in B) and X (E in F). Both are measured from the model at
    random joint vectors :math:`q_i`: with :math:`M_i = T_{world,B}^{-1} T_{world,E}(q_i)` and
    :math:`F_i = \mathrm{fk}(q_i)`, the relative motions :math:`A_i = F_0^{-1} F_i` and
    :math:`B_i = M_0^{-1} M_i` satisfy :math:`A_i X = X B_i` (the hand-eye equation): X's
    rotation carries each :math:`B_i`'s rotation axis onto :math:`A_i`'s (Kabsch, weighted by
    the angle), its translation solves :math:`(R_{A_i} - I)\, t = R_X t_{B_i} - t_{A_i}` by least
    squares, and :math:`C = M_0 X^{-1} F_0^{-1}`. The fit is then checked at every sample: a
    frame that does not move rigidly with the arm's last link (another arm's, a finger's) is
    refused. This holds wherever the arm is mounted: on the world (any pose), on a mobile
    base, on a mocap body.

    Args:
        joints: The arm's joints in the model.
        frame_name: The end-effector frame E in the model: the arm's own (the frame
            ``arm.fk`` gives) or any frame fixed to its last link; as given, else with the
            prefix. Default: the arm's frame name (``arm.frame_name``, Menagerie's, else
            ``"end_effector"``) with the prefix, else as it is.
        frame_type: ``"site"``, ``"body"`` or ``"geom"``; default the arm's (``"site"`` if it
            names none).

    Attributes:
        frame_name, frame_type: The end-effector frame E.
        body: Id of B.
        offset: (4, 4) C, the root frame in B.
        tool: (4, 4) X, E in the arm's end-effector frame (the identity for the arm's own).
        fixed_pose: (4, 4) world pose of the root when B is welded to the world, else None
            (the root moves with other joints or a mocap body; see :meth:`pose`).

    Raises:
        FrameNotFound: No frame of that name and type, with or without the prefix.
        mink.UnsupportedFrame: frame_type is none of the above.
        ModelMismatch: The frame is not below the arm's joints, or does not move rigidly with
            the arm's end effector.
    """

    def __init__(self, joints: ArmJoints, frame_name: str | None = None, frame_type: str | None = None):
        arm, model = joints.arm, joints.model
        for name, value in (("frame_name", frame_name), ("frame_type", frame_type)):
            if value is not None:
                as_instance(value, str, name)
        self.joints = joints
        self.frame_type = frame_type or arm.frame_type or "site"
        if self.frame_type not in SUPPORTED_FRAMES:
            raise UnsupportedFrame(self.frame_type, SUPPORTED_FRAMES)
        if frame_name:
            names = given_frame_names(frame_name, joints.prefix)
        else:
            names = arm_frame_names(arm.frame_name or DEFAULT_SITE, joints.prefix)
        self._frame, self.frame_name = find_frame(model, self.frame_type, names)
        self._pos, self._xmat = FRAME_TO_POS_ATTR[self.frame_type], FRAME_TO_XMAT_ATTR[self.frame_type]
        self.body = int(model.body_parentid[model.jnt_bodyid[joints.joint_ids[0]]])
        self._check_path()
        data = mujoco.MjData(model)
        low = np.where(np.isfinite(joints.lower), joints.lower, -np.pi)
        high = np.where(np.isfinite(joints.upper), joints.upper, np.pi)
        samples = np.random.default_rng(0).uniform(low, high, (_CHECKS, arm.dof))
        seen = np.array([self._in_body(data, q) for q in samples])  # M_i
        flange = arm.fk(samples)  # F_i
        self.tool = _tool_offset(flange, seen)
        self.offset = seen[0] @ np.linalg.inv(self.tool) @ np.linalg.inv(flange[0])
        for q, F, M in zip(samples, flange, seen, strict=True):
            position, angle = _distance(self.offset @ F @ self.tool, M)
            if max(position, angle) > MATCH_TOLERANCE:
                raise ModelMismatch(
                    f"{self.frame_type} '{self.frame_name}' does not move rigidly with the end effector of "
                    f"arm '{arm.name}' ({position:.2g} m, {angle:.2g} rad off at q = "
                    f"{np.round(q, 3).tolist()}): the model holds another arm, or this frame is moved by "
                    f"more than the arm's joints (Menagerie's frame is {arm.frame_type} '{arm.frame_name}')"
                )
        self.fixed_pose: np.ndarray | None = None
        if model.body_weldid[self.body] == 0:
            self.fixed_pose = self.pose(data)
        self._world_to_fixed = None if self.fixed_pose is None else inverse(self.fixed_pose)
        self._at_origin = self.fixed_pose is not None and np.array_equal(self.fixed_pose, np.eye(4))
        self._to_flange = None if np.array_equal(self.tool, np.eye(4)) else inverse(self.tool)

    def in_root(self, T_world: np.ndarray, root_pose: np.ndarray) -> np.ndarray:
        """The pose of the arm's end-effector frame in its root frame, for the frame E at
        world pose T_world with the root at root_pose: :math:`T_{root}^{-1} T_{world} X^{-1}`."""
        if root_pose is self.fixed_pose:
            T_root = T_world if self._at_origin else self._world_to_fixed @ T_world
        else:
            R, p = root_pose[:3, :3], root_pose[:3, 3]
            T_root = np.eye(4)
            T_root[:3, :3] = R.T @ T_world[:3, :3]
            T_root[:3, 3] = R.T @ (T_world[:3, 3] - p)
        return T_root if self._to_flange is None else T_root @ self._to_flange

    def pose(self, data: mujoco.MjData) -> np.ndarray:
        """World pose (4, 4) of the arm's root frame: :attr:`fixed_pose`, or from data's
        current kinematics where the root moves."""
        if self.fixed_pose is not None:
            return self.fixed_pose
        return _body_pose(data, self.body) @ self.offset

    def frame_pose(self, data: mujoco.MjData) -> np.ndarray:
        """World pose (4, 4) of the end-effector frame E in data's kinematics as last computed."""
        frame = np.eye(4)
        frame[:3, :3] = getattr(data, self._xmat)[self._frame].reshape(3, 3)
        frame[:3, 3] = getattr(data, self._pos)[self._frame]
        return frame

    def _in_body(self, data: mujoco.MjData, q: np.ndarray) -> np.ndarray:
        """The frame's pose in body B at the arm's joints q (the model's other joints at qpos0)."""
        data.qpos[:] = self.joints.qpos_with(self.joints.model.qpos0, q)
        mujoco.mj_kinematics(self.joints.model, data)
        return np.linalg.solve(_body_pose(data, self.body), self.frame_pose(data))

    def _check_path(self) -> None:
        """The frame must hang below body B through the arm's joints only."""
        model = self.joints.model
        bodyid = {"site": model.site_bodyid, "geom": model.geom_bodyid}
        body = int(bodyid[self.frame_type][self._frame]) if self.frame_type in bodyid else self._frame
        arm_joints = set(self.joints.joint_ids.tolist())
        while body not in (self.body, 0):
            start, count = model.body_jntadr[body], model.body_jntnum[body]
            others = [model.joint(j).name for j in range(start, start + count) if j not in arm_joints]
            if others:
                raise ModelMismatch(
                    f"joints {others} move {self.frame_type} '{self.frame_name}' besides the joints of arm "
                    f"'{self.joints.arm.name}'"
                )
            body = int(model.body_parentid[body])
        if body != self.body:
            raise ModelMismatch(
                f"{self.frame_type} '{self.frame_name}' is not moved by the joints of arm "
                f"'{self.joints.arm.name}' ({', '.join(self.joints.names)})"
            )


def _body_pose(data: mujoco.MjData, body: int) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = data.xmat[body].reshape(3, 3)
    T[:3, 3] = data.xpos[body]
    return T


def _tool_offset(flange: np.ndarray, seen: np.ndarray) -> np.ndarray:
    """X of :class:`ArmRoot`'s hand-eye equation :math:`A_i X = X B_i` from the poses
    F_i (flange) and M_i (seen), (n, 4, 4) each (:class:`ArmRoot`'s docstring)."""
    A = np.linalg.solve(flange[0], flange[1:])  # F_0^-1 F_i
    B = np.linalg.solve(seen[0], seen[1:])
    axes_a = Rotation.from_matrix(A[:, :3, :3]).as_rotvec()
    axes_b = Rotation.from_matrix(B[:, :3, :3]).as_rotvec()
    U, _, Vt = np.linalg.svd(axes_b.T @ axes_a)  # R_X axis(B_i) = axis(A_i): Kabsch
    R = Vt.T @ np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))]) @ U.T
    lhs = (A[:, :3, :3] - np.eye(3)).reshape(-1, 3)
    rhs = (B[:, :3, 3] @ R.T - A[:, :3, 3]).reshape(-1)
    X = np.eye(4)
    X[:3, :3], X[:3, 3] = R, np.linalg.lstsq(lhs, rhs, rcond=None)[0]
    return X


def inverse(pose: np.ndarray) -> np.ndarray:
    """The inverse of a homogeneous transform, [[R^T, -R^T p], [0, 1]]."""
    out = np.eye(4)
    out[:3, :3] = pose[:3, :3].T
    out[:3, 3] = -pose[:3, :3].T @ pose[:3, 3]
    return out


def _distance(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    """Position (m) and rotation angle (rad) between two poses."""
    cos = (np.trace(A[:3, :3].T @ B[:3, :3]) - 1.0) / 2.0
    return float(np.linalg.norm(A[:3, 3] - B[:3, 3])), float(np.arccos(np.clip(cos, -1.0, 1.0)))
