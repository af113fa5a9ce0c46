"""The offset modification method: configurations (:mod:`.configuration`), the model arm
(:mod:`.model`) with its closed-form families (:mod:`.families`), system (9) and the data its
compiled kernels take (:mod:`.kernel_data`), arms near a family (:mod:`.nominal`), and the
solver that fronts them (:mod:`.solver`, its batch entry points in :mod:`.batch` on the
worker threads of :mod:`.threads`)."""

from .batch import BatchRoots, BatchSolution
from .configuration import Configuration
from .model import ModelArm, derive_model
from .model_conditions import ANGLE_ROUNDING, LENGTH_ROUNDING
from .nominal import NEAR_LENGTH, NEAR_TWIST, NominalArm, nominal_arm
from .solver import BRANCH_BAND, OMSolver, Solution

__all__ = [
    "ANGLE_ROUNDING",
    "BRANCH_BAND",
    "LENGTH_ROUNDING",
    "NEAR_LENGTH",
    "NEAR_TWIST",
    "BatchRoots",
    "BatchSolution",
    "Configuration",
    "ModelArm",
    "NominalArm",
    "OMSolver",
    "Solution",
    "derive_model",
    "nominal_arm",
]
