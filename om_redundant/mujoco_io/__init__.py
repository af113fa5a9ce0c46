"""MuJoCo: the project's MJCF of an arm (:mod:`.mjcf`), the arm's joints and root inside a
larger model (:mod:`.arm_in_model`), the check of a model against an arm file
(:mod:`.model_match`), and the arm file of a model (:mod:`.arm_import`)."""

from .arm_import import arm_from_mujoco
from .arm_in_model import ArmJoints, ArmRoot
from .loading import load_mujoco_model, without_meshes
from .mjcf import DEFAULT_SITE, arm_mjcf, arm_model, scene_mjcf
from .model_match import ModelComparison, compare_mujoco_model

__all__ = [
    "DEFAULT_SITE",
    "ArmJoints",
    "ArmRoot",
    "ModelComparison",
    "arm_from_mujoco",
    "arm_mjcf",
    "arm_model",
    "compare_mujoco_model",
    "load_mujoco_model",
    "scene_mjcf",
    "without_meshes",
]
