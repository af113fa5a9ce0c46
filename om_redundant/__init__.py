"""om_redundant: exact inverse kinematics with configuration control by offset modification.

The folders follow the data path: an arm file becomes a kinematic chain
(:mod:`.kinematics`), the offset modification method derives the model arm and solves
system (9) (:mod:`.ik`), the arm angle of a 7-DOF arm is chosen by the redundancy optimiser
(:mod:`.redundancy`), MuJoCo models hold the arm (:mod:`.mujoco_io`), and mink tasks
(:mod:`.tasks`) and the command line (:mod:`.cli`) use the result.
"""

from .exceptions import (
    ArmFileError,
    FrameNotFound,
    InvalidInput,
    JointNotFound,
    ModelError,
    ModelMismatch,
    OMError,
    SingularSelfMotion,
    UnknownArm,
    UnreachableTarget,
)
from .ik import (
    BatchRoots,
    BatchSolution,
    Configuration,
    OMSolver,
    Solution,
)
from .kinematics import Arm, DHRow, JointKind, arm_names, load_arm, write_arm_file
from .mujoco_io import (
    ArmJoints,
    ArmRoot,
    ModelComparison,
    arm_from_mujoco,
    arm_mjcf,
    arm_model,
    compare_mujoco_model,
    load_mujoco_model,
    scene_mjcf,
)
from .redundancy import (
    MAX_EXTENT,
    Box,
    Capsule,
    Clearance,
    FreeRotation,
    PsiInterval,
    RedundancyChoice,
    RedundancyOptimizer,
    Singularity,
    Sphere,
    arm_angle_and_gradient,
    joint_margins,
)
from .tasks import ArmAngleTask, ExactPoseTask

__version__ = "0.1.0"

__all__ = [
    "MAX_EXTENT",
    "Arm",
    "ArmAngleTask",
    "ArmFileError",
    "ArmJoints",
    "ArmRoot",
    "BatchRoots",
    "BatchSolution",
    "Box",
    "Capsule",
    "Clearance",
    "Configuration",
    "DHRow",
    "ExactPoseTask",
    "FrameNotFound",
    "FreeRotation",
    "InvalidInput",
    "JointKind",
    "JointNotFound",
    "ModelComparison",
    "ModelError",
    "ModelMismatch",
    "OMError",
    "OMSolver",
    "PsiInterval",
    "RedundancyChoice",
    "RedundancyOptimizer",
    "SingularSelfMotion",
    "Singularity",
    "Solution",
    "Sphere",
    "UnknownArm",
    "UnreachableTarget",
    "arm_angle_and_gradient",
    "arm_from_mujoco",
    "arm_mjcf",
    "arm_model",
    "arm_names",
    "compare_mujoco_model",
    "joint_margins",
    "load_arm",
    "load_mujoco_model",
    "scene_mjcf",
    "write_arm_file",
]
