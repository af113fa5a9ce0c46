"""The redundancy of 7-DOF arms: the arm angle (:mod:`.arm_angle`) and the self-motion
(:mod:`.self_motion`), the objective (:mod:`.objective`, :mod:`.clearance`), solution paths
along psi (:mod:`.paths`), feasible intervals (:mod:`.intervals`), the climb (:mod:`.climb`)
and the optimiser that combines them (:mod:`.optimizer`)."""

from .arm_angle import arm_angle_and_gradient
from .clearance import Box, Capsule, Clearance, Sphere
from .intervals import PsiInterval
from .objective import Evaluation, Objective, joint_margins
from .optimizer import RedundancyChoice, RedundancyOptimizer
from .self_motion import self_motion_tangent

__all__ = [
    "Box",
    "Capsule",
    "Clearance",
    "Evaluation",
    "Objective",
    "PsiInterval",
    "RedundancyChoice",
    "RedundancyOptimizer",
    "Sphere",
    "arm_angle_and_gradient",
    "joint_margins",
    "self_motion_tangent",
]
