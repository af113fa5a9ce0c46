"""The mink task that steers a 7-DOF arm's elbow: its arm angle psi to a target."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import numpy.typing as npt
from mink import Configuration as MinkConfiguration
from mink import TargetNotSet
from mink.exceptions import InvalidTarget

from ..exceptions import InvalidInput
from ..om.solver import OMSolver
from ..redundancy.arm_angle import arm_angle_and_gradient, check_arm_angle
from ..validation import as_number
from .arm_task import ArmTask


class ArmAngleTask(ArmTask):
    r"""Steer a 7-DOF arm's elbow: drive its arm angle psi to a target psi*.

    For users who track the hand with mink's ``FrameTask`` and only want to choose the
    elbow's swivel about the shoulder-wrist line. psi is the model's arm angle
    (:mod:`om_redundant.om.families.srs`, ``solver.configuration_of(q).redundancy[0]``):

    .. math::  e(q) = \mathrm{wrap}\big(\psi(q) - \psi^*\big) \in (-\pi, \pi], \qquad
               J = \partial\psi/\partial q \in \mathbb{R}^{1 \times n_v},

    the gradient derived analytically in :mod:`om_redundant.redundancy.arm_angle` (nonzero on the arm's
    joints 1-4 only). psi is undefined on its singular half-line (the wrist straight below
    the shoulder, inside the base) and jumps by pi where the ELBOW sign flips.

    Args:
        solver: The OM solver of a 7-DOF arm.
        model: The MuJoCo model that holds the arm.
        prefix: Prefix of the arm's joint names in the model; default the arm's (``arm.prefix``).
        cost: Cost of the arm angle error (1/rad).
        gain: Task gain in [0, 1].
        lm_damping: Levenberg-Marquardt damping (see ``mink.Task``).

    Raises:
        InvalidInput: The arm has no arm angle.
        JointNotFound, ModelMismatch: The model does not hold the arm as named.
    """

    def __init__(
        self,
        solver: OMSolver,
        model: mujoco.MjModel,
        *,
        prefix: str | None = None,
        cost: npt.ArrayLike = 1.0,
        gain: float = 1.0,
        lm_damping: float = 0.0,
    ):
        check_arm_angle(solver)
        super().__init__(solver, model, 1, prefix, cost, gain, lm_damping)
        self.target_psi: float | None = None

    def set_target(self, psi: float) -> None:
        """Set the target arm angle psi* (rad), a finite number (not text)."""
        try:
            self.target_psi = as_number(psi, "target")
        except InvalidInput:
            raise InvalidTarget(
                f"ArmAngleTask target must be a finite angle in radians, got {psi!r}"
            ) from None

    def set_target_from_configuration(self, configuration: MinkConfiguration) -> None:
        """Hold the elbow where it is: psi* becomes the arm's current arm angle."""
        self.set_target(arm_angle_and_gradient(self.solver, self.arm_q(configuration))[0])

    def compute_error(self, configuration: MinkConfiguration) -> np.ndarray:
        r"""The arm-angle error :math:`\mathrm{wrap}(\psi(q) - \psi^*)`, shape (1,)."""
        psi, _ = self._psi(configuration)
        return np.array([math.remainder(psi - self.target_psi, 2.0 * math.pi)])

    def compute_jacobian(self, configuration: MinkConfiguration) -> np.ndarray:
        r""":math:`\partial\psi/\partial q` in the arm's dof columns, (1, nv)."""
        _, gradient = self._psi(configuration)
        return self.scatter(gradient[None, :])

    def _psi(self, configuration: MinkConfiguration) -> tuple[float, np.ndarray]:
        q = self.arm_q(configuration)
        if self.target_psi is None:
            raise TargetNotSet(self.__class__.__name__)
        return arm_angle_and_gradient(self.solver, q)
