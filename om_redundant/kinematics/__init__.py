"""Kinematics of real arms: DH chains (:mod:`.chain`, with C kernels in ``csrc/ik/kinematics.c``),
arms (:mod:`.arm`), read from and written to arm files (:mod:`.arm_file`), and the poses
those files hold (:mod:`.poses`)."""

from .arm import Arm
from .arm_file import arm_file_text, arm_names, load_arm, write_arm_file
from .chain import DHRow, JointKind, KinematicChain, standard_rows_from_modified
from .poses import pose_from_xyz_quat, rotation_from_quat

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
