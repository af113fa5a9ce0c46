"""Exceptions specific to om_redundant."""

from __future__ import annotations

import mujoco
from mink.exceptions import InvalidFrame, InvalidTarget, MinkError


class OMError(Exception):
    """Base class for om_redundant exceptions."""


class InvalidInput(OMError, ValueError):
    """A pose, joint vector or configuration given to the library is malformed.

    Raised for wrong shapes, NaN or inf entries, rotations that are not orthonormal,
    branch signs outside {-1, +1} and the like. The message names the argument and
    the problem.
    """


class UnknownArm(OMError, KeyError):
    """An arm name matches no arm file shipped with the package."""

    def __init__(self, name: str, available: list[str]):
        self.name = name
        super().__init__(f"unknown arm '{name}'; available arms: {', '.join(available)}")

    def __str__(self) -> str:  # KeyError would quote the message.
        return self.args[0]


class ArmFileError(OMError, ValueError):
    """An arm file is malformed. The message names the file, the field and the problem."""

    def __init__(self, path: str, field: str, problem: str):
        self.path, self.field, self.problem = path, field, problem
        super().__init__(f"{path}: field '{field}': {problem}")


class ModelError(OMError, ValueError):
    """No offset-modified model arm with a closed form exists for this arm.

    Raised when an arm violates a condition of the OM method's Theorem 2 (or the
    redundant-arm equivalent) or matches none of the closed-form families.
    """


class ModelMismatch(OMError, MinkError):
    """A MuJoCo model does not hold the arm as a task needs it.

    Raised when a joint of the arm is missing from the model or has another type, when the
    end-effector frame does not move like the arm's, or when a task meets a
    ``mink.Configuration`` of another model than the one it was built for. The message names
    the joint, frame or model. Also a ``mink.MinkError``.
    """


class JointNotFound(ModelMismatch):
    """A joint of the arm (with the prefix applied) is not in the MuJoCo model."""

    def __init__(self, joint_name: str, arm_name: str, model: mujoco.MjModel):
        self.joint_name = joint_name
        available = [model.joint(i).name for i in range(model.njnt)]
        super().__init__(
            f"joint '{joint_name}' of arm '{arm_name}' does not exist in the model. "
            f"Available joint names: {available}"
        )


class FrameNotFound(ModelMismatch, InvalidFrame):
    """The end-effector frame named for the arm is not in the MuJoCo model.

    Also a ``mink.InvalidFrame``, whose message (listing the model's frames) it keeps, adding
    the other names tried (``also``: the name with or without the arm's prefix) and why a
    URDF's link may be missing.
    """

    def __init__(self, frame_name: str, frame_type: str, model: mujoco.MjModel, also: tuple[str, ...] = ()):
        self.frame_name, self.frame_type = frame_name, frame_type
        InvalidFrame.__init__(self, frame_name, frame_type, model)
        tried = "".join(f" (nor '{name}')" for name in also)
        self.args = (
            self.args[0].replace(f"'{frame_name}'", f"'{frame_name}'{tried}", 1)
            + ". A URDF's link on a fixed joint (such as tool0) is a body only where the model is compiled "
            "with fusestatic off, as om.load_mujoco_model does; MuJoCo's URDF loader fuses it into its "
            "parent by default",
        )


class UnreachableTarget(OMError, InvalidTarget):
    """A task's target has no exact solution it may pull the arm to.

    The pose is out of reach, the requested configuration has no solution for it, or every
    solution breaks a joint limit; the message says which. Also a ``mink.InvalidTarget``.
    """


class SingularSelfMotion(OMError, ArithmeticError):
    """The arm angle does not move along the self-motion at this joint vector (a fold of the
    solution path, or a Jacobian that lost rank, e.g. a stretched arm), so dq/dpsi does not
    exist there. The message names the joint vector."""
