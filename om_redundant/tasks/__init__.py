"""mink tasks fed by exact OM solutions (:mod:`.exact_pose`)."""

from .exact_pose import EXACT_POSE_COST, ArmAngleTask, ExactPoseTask

__all__ = ["EXACT_POSE_COST", "ArmAngleTask", "ExactPoseTask"]
