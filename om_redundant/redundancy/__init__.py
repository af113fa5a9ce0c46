"""The redundancy of 7-DOF arms: the arm angle (:mod:`.arm_angle`) and the self-motion
(:mod:`.self_motion`), the objective (:mod:`.objective`, :mod:`.clearance`,
:mod:`.singularity`), solution paths along psi (:mod:`.paths`), feasible intervals
(:mod:`.intervals`), the climb (:mod:`.climb`), the optimiser that combines them
(:mod:`.optimizer`), and the sweep of psi for a pose or a path that ``om-redundant sweep``
shows (:mod:`.sweep`)."""

from .arm_angle import arm_angle_and_gradient
from .arm_geoms import MAX_EXTENT
from .choice import RedundancyChoice
from .clearance import Clearance
from .free_rotation import FreeRotation
from .intervals import PsiInterval
from .objective import Objective
from .objective_terms import Evaluation, joint_margins
from .optimizer import RedundancyOptimizer
from .self_motion import self_motion_tangent
from .shapes import Box, Capsule, Sphere
from .singularity import Singularity
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
