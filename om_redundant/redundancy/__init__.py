"""The redundancy of 7-DOF arms: the arm angle (:mod:`.arm_angle`), the self-motion
(:mod:`.self_motion`), targets with a free rotation (:mod:`.free_rotation`), and the global
choice's path: a branch's solution paths along psi and their feasible intervals
(:mod:`.paths`), what is maximised along them (:mod:`.objective`), and the optimiser that
chooses and tracks (:mod:`.choice`); the sweep of psi for a pose or a path that
``om-redundant sweep`` shows is :mod:`.sweep`."""

from .arm_angle import arm_angle_and_gradient
from .choice.optimizer import RedundancyOptimizer
from .choice.result import RedundancyChoice
from .free_rotation import FreeRotation
from .objective.arm_geoms import MAX_EXTENT
from .objective.clearance import Clearance
from .objective.objective import Objective
from .objective.shapes import Box, Capsule, Sphere
from .objective.singularity import Singularity
from .objective.terms import Evaluation, joint_margins
from .paths.intervals import PsiInterval
from .self_motion import self_motion_tangent
from .sweep import (
    BranchSweep,
    Choice,
    Obstacle,
    PoseSweep,
    SweepRequest,
    SweepResult,
    compute_sweep,
    optimizer_for,
)

__all__ = [
    "MAX_EXTENT",
    "Box",
    "BranchSweep",
    "Capsule",
    "Choice",
    "Clearance",
    "Evaluation",
    "FreeRotation",
    "Objective",
    "Obstacle",
    "PoseSweep",
    "PsiInterval",
    "RedundancyChoice",
    "RedundancyOptimizer",
    "Singularity",
    "Sphere",
    "SweepRequest",
    "SweepResult",
    "arm_angle_and_gradient",
    "compute_sweep",
    "joint_margins",
    "optimizer_for",
    "self_motion_tangent",
]
