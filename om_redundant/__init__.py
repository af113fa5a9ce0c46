"""om_redundant: exact inverse kinematics with configuration control by offset modification."""

from .arm import Arm as Arm
from .arm import arm_names as arm_names
from .arm import load_arm as load_arm
from .arm_angle import arm_angle_and_gradient as arm_angle_and_gradient
from .arm_in_model import ArmJoints as ArmJoints
from .arm_in_model import ArmRoot as ArmRoot
from .clearance import Box as Box
from .clearance import Capsule as Capsule
from .clearance import Clearance as Clearance
from .clearance import Sphere as Sphere
from .configuration import Configuration as Configuration
from .exceptions import ArmFileError as ArmFileError
from .exceptions import FrameNotFound as FrameNotFound
from .exceptions import InvalidInput as InvalidInput
from .exceptions import JointNotFound as JointNotFound
from .exceptions import ModelError as ModelError
from .exceptions import ModelMismatch as ModelMismatch
from .exceptions import OMError as OMError
from .exceptions import UnknownArm as UnknownArm
from .exceptions import UnreachableTarget as UnreachableTarget
from .intervals import PsiInterval as PsiInterval
from .kinematics import DHRow as DHRow
from .kinematics import JointKind as JointKind
from .kinematics import KinematicChain as KinematicChain
from .mjcf import arm_mjcf as arm_mjcf
from .mjcf import arm_model as arm_model
from .mjcf import scene_mjcf as scene_mjcf
from .model import ModelArm as ModelArm
from .model import derive_model as derive_model
from .mujoco_match import ModelComparison as ModelComparison
from .mujoco_match import compare_mujoco_model as compare_mujoco_model
from .mujoco_match import load_mujoco_model as load_mujoco_model
from .mujoco_match import without_meshes as without_meshes
from .objective import Evaluation as Evaluation
from .objective import Objective as Objective
from .objective import joint_margins as joint_margins
from .redundancy import RedundancyChoice as RedundancyChoice
from .redundancy import RedundancyOptimizer as RedundancyOptimizer
from .self_motion import self_motion_tangent as self_motion_tangent
from .solver import BatchSolution as BatchSolution
from .solver import OMSolver as OMSolver
from .solver import Solution as Solution
from .tasks import ArmAngleTask as ArmAngleTask
from .tasks import ExactPoseTask as ExactPoseTask

__version__ = "0.1.0"
