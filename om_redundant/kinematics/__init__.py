"""Kinematics of real arms: DH chains (:mod:`.chain`, with C kernels in ``csrc/kinematics.c``),
and arms read from arm files (:mod:`.arm`)."""

from .arm import (
    Arm,
    arm_file_text,
    arm_names,
    load_arm,
    pose_from_xyz_quat,
    rotation_from_quat,
    write_arm_file,
)
from .chain import DHRow, JointKind, KinematicChain, standard_rows_from_modified

__all__ = [
    "Arm",
    "DHRow",
    "JointKind",
    "KinematicChain",
    "arm_file_text",
    "arm_names",
    "load_arm",
    "pose_from_xyz_quat",
    "rotation_from_quat",
    "standard_rows_from_modified",
    "write_arm_file",
]
