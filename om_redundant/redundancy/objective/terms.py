r"""The objective's parts: its weights and caps, the joint-limit margins, a term's group of
pieces and the evaluation of all terms at a joint vector (:class:`Objective
<om_redundant.redundancy.objective.objective.Objective>` combines them)."""

from __future__ import annotations

import functools
import math
from typing import Any, NamedTuple

import numpy as np

from ...exceptions import InvalidInput
from ...kinematics.arm import Arm
from ...validation import as_instance, as_joint_vector, as_number

#: s_cap: a singularity distance |sin x| beyond this (30 degrees) earns nothing more.
SINGULARITY_CAP = 0.5
#: Default weights: w_m, w_c, w_s (module docstring).
DEFAULT_MARGIN_WEIGHT, DEFAULT_CLEARANCE_WEIGHT, DEFAULT_SINGULARITY_WEIGHT = 1.0, 1.0, 0.1


def joint_margins(arm: Arm, q: np.ndarray) -> np.ndarray:
    """Normalised joint-limit margins m_i(q) (module docstring); +inf for unlimited joints.

    Args:
        arm: The arm.
        q: (dof,) or (M, dof) joint vectors.

    Returns:
        Margins of the same shape as q: 1 at mid-range, 0 on a limit, negative beyond.
    """
    q = as_joint_vector(q, as_instance(arm, Arm, "arm").dof)
    limited = np.isfinite(arm.lower) & np.isfinite(arm.upper)
    half = np.where(limited, (arm.upper - arm.lower) / 2.0, 1.0)
    return np.where(limited, np.minimum(*limit_distances(q, arm.lower, arm.upper, half)), np.inf)


def limit_distances(
    q: np.ndarray, lower: np.ndarray, upper: np.ndarray, half: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The two affine pieces of the margins, (q - l)/h and (u - q)/h."""
    return (q - lower) / half, (upper - q) / half


def check_weights(
    margin_weight: Any,
    clearance_weight: Any,
    clearance_cap: Any,
    min_clearance: Any,
    singularity_weight: Any = DEFAULT_SINGULARITY_WEIGHT,
) -> None:
    """Raise InvalidInput naming the first of the objective's numbers that is out of range."""
    weights = (
        ("margin_weight", margin_weight),
        ("clearance_weight", clearance_weight),
        ("singularity_weight", singularity_weight),
    )
    for name, value in weights:
        if not as_number(value, name) >= 0.0:
            raise InvalidInput(f"{name} must be a finite number >= 0, got {value}")
    if not as_number(clearance_cap, "clearance_cap") > 0.0:
        raise InvalidInput(f"clearance_cap must be a positive number of metres, got {clearance_cap}")
    if not 0.0 <= as_number(min_clearance, "min_clearance") < clearance_cap:
        raise InvalidInput(
            f"min_clearance must be >= 0 and below clearance_cap ({clearance_cap} m), got {min_clearance}"
        )


class Evaluation(NamedTuple):
    """The objective at one joint vector (a named tuple: the path sweep,
    ``paths.sweep_circle``, builds one per sample, and a tuple is built several times faster
    than a frozen dataclass).

    Attributes:
        value: f(q).
        margin: M(q), the smallest normalised joint-limit margin (inf if no joint is limited).
        clearance: D(q) in metres (inf without obstacles).
        slack: The smallest of M(q) and (D(q) - d_min) / d_cap; q is feasible iff >= 0.
        singularity: S(q), the smallest ``|sin|`` of the model's singular angles (inf without
            the term).
    """

    value: float
    margin: float
    clearance: float
    slack: float
    singularity: float = math.inf

    @property
    def feasible(self) -> bool:
        return self.slack >= 0.0


#: An :class:`Evaluation` of a row of ``_core.evaluate``'s five numbers (its fields, in their
#: order: ``_core.Evaluations``): ``Evaluation._make`` without its length check, the cheapest way
#: to build hundreds.
evaluation_of_row = functools.partial(tuple.__new__, Evaluation)
