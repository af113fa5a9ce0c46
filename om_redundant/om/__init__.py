"""The offset modification method: configurations (:mod:`.configuration`), the model arm
(:mod:`.model`) with its closed-form families (:mod:`.families`), system (9) and its bounded
search (:mod:`.system`), and the solver that fronts them (:mod:`.solver`)."""

from .configuration import Configuration
from .model import ModelArm, derive_model
from .solver import BRANCH_BAND, BatchSolution, OMSolver, Solution

__all__ = [
    "BRANCH_BAND",
    "BatchSolution",
    "Configuration",
    "ModelArm",
    "OMSolver",
    "Solution",
    "derive_model",
]
