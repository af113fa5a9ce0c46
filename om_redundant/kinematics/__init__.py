"""Kinematics of real arms: DH chains (:mod:`.chain`, with C kernels in ``csrc/kinematics.c``),
and arms read from arm files (:mod:`.arm`)."""

from .arm import Arm, arm_names, load_arm, pose_from_xyz_quat, rotation_from_quat
from .chain import DHRow, JointKind, KinematicChain, standard_rows_from_modified

__all__ = [
    "Arm",
    "DHRow",
    "JointKind",
    "KinematicChain",
    "arm_names",
    "load_arm",
    "pose_from_xyz_quat",
    "rotation_from_quat",
    "standard_rows_from_modified",
]
