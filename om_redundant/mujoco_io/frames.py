"""The arm's end-effector frame in a MuJoCo model, named with or without the arm's prefix.

A model's names carry a prefix for the arm's joints (``"l_"``, ``"arm_left_"``) that its
frames may or may not share: PR2's ``l_gripper_tool_frame`` does, Talos's
``gripper_left_base_link`` under the joints ``arm_left_*`` does not. So a frame is looked up
under two names, in an order that depends on who named it: a name the user gives is tried as
given, then with the prefix; the arm's own frame (``arm.frame_name``, stored without the
prefix where the model's name has it) with the prefix first, then as it is.
"""

from __future__ import annotations

import mujoco

from ..exceptions import FrameNotFound

FRAME_OBJECTS = {
    "site": mujoco.mjtObj.mjOBJ_SITE,
    "body": mujoco.mjtObj.mjOBJ_BODY,
    "geom": mujoco.mjtObj.mjOBJ_GEOM,
}


def given_frame_names(name: str, prefix: str) -> tuple[str, ...]:
    """The names a user's frame name is tried under, in order: as given, then with the prefix."""
    return (name, prefix + name) if prefix else (name,)


def arm_frame_names(name: str, prefix: str) -> tuple[str, ...]:
    """The names the arm's own frame is tried under, in order: with the prefix, then as it is."""
    return (prefix + name, name) if prefix else (name,)


def find_frame(model: mujoco.MjModel, frame_type: str, names: tuple[str, ...]) -> tuple[int, str]:
    """The id and name of the first of ``names`` that is a frame of that type in the model.

    Raises:
        FrameNotFound: None is; the message names the first and the others tried.
    """
    for name in names:
        frame_id = mujoco.mj_name2id(model, FRAME_OBJECTS[frame_type], name)
        if frame_id >= 0:
            return frame_id, name
    raise FrameNotFound(names[0], frame_type, model, also=names[1:])
