"""The mink task that steers a 7-DOF arm's elbow: its arm angle psi to a target."""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt
from mink import Configuration as MinkConfiguration
from mink import TargetNotSet
from mink.exceptions import InvalidTarget

from ..angles import wrap_angle
from ..exceptions import InvalidInput, UnreachableTarget
from ..ik.configuration import Configuration
from ..ik.solver import OMSolver
from ..redundancy.arm_angle import arm_angle_and_gradient, check_arm_angle
from ..validation import as_number
from .arm_task import ArmTask


class ArmAngleTask(ArmTask):
    r"""Steer a 7-DOF arm's elbow: drive its arm angle psi to a target psi*.

    For users who track the hand with mink's ``FrameTask`` and only want to choose the
    elbow's swivel about the shoulder-wrist line. psi is the model's arm angle
    (:mod:`om_redundant.ik.families.srs`, ``solver.configuration_of(q).redundancy[0]``):

    .. math::  e(q) = \mathrm{wrap}\big(\psi(q) - \psi^*\big) \in (-\pi, \pi], \qquad
               J = \partial\psi/\partial q \in \mathbb{R}^{1 \times n_v},

    the gradient derived analytically in :mod:`om_redundant.redundancy.arm_angle` (nonzero on the arm's
    joints 1-4 only). psi is undefined on its singular half-line (the wrist straight below
    the shoulder, inside the base) and jumps by pi where the ELBOW sign flips.

    An arm angle the arm cannot take with its hand where it is (no exact solution at psi* on
    the arm's branch, or only ones that break a joint limit) would pull the hand off its
    ``FrameTask`` target: every ``compute_*`` checks (one exact solve of the hand's pose at
    psi*) and raises :class:`~om_redundant.UnreachableTarget` saying so, as
    :meth:`set_target` does for a target it can check (after the task has seen the arm).

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
        self._q: np.ndarray | None = None  # the arm's joints last seen
        self._attainable: tuple[bytes, float] | None = None  # (joints, psi*) last found attainable

    def set_target(self, psi: float) -> None:
        """Set the target arm angle psi* (rad), a finite number (not text).

        Raises:
            mink.InvalidTarget: psi is not a finite number.
            UnreachableTarget: The arm as last seen cannot take psi* with its hand where it
                is (the class docstring); the previous target is kept.
        """
        try:
            target = as_number(psi, "target")
        except InvalidInput:
            raise InvalidTarget(
                f"ArmAngleTask target must be a finite angle in radians, got {psi!r}"
            ) from None
        if self._q is not None:
            self._check_attainable(self._q, target)
        self.target_psi = target

    def set_target_from_configuration(self, configuration: MinkConfiguration) -> None:
        """Hold the elbow where it is: psi* becomes the arm's current arm angle."""
        self._q = self.arm_q(configuration)
        self.set_target(arm_angle_and_gradient(self.solver, self._q)[0])

    def compute_error(self, configuration: MinkConfiguration) -> np.ndarray:
        r"""The arm-angle error :math:`\mathrm{wrap}(\psi(q) - \psi^*)`, shape (1,)."""
        psi, _ = self._psi(configuration)
        return np.array([wrap_angle(psi - self.target_psi)])

    def compute_jacobian(self, configuration: MinkConfiguration) -> np.ndarray:
        r""":math:`\partial\psi/\partial q` in the arm's dof columns, (1, nv)."""
        _, gradient = self._psi(configuration)
        return self.scatter(gradient[None, :])

    def _psi(self, configuration: MinkConfiguration) -> tuple[float, np.ndarray]:
        q = self.arm_q(configuration)
        self._q = q
        if self.target_psi is None:
            raise TargetNotSet(self.__class__.__name__)
        self._check_attainable(q, self.target_psi)
        return arm_angle_and_gradient(self.solver, q)

    def _check_attainable(self, q: np.ndarray, psi: float) -> None:
        """Raise UnreachableTarget unless the arm can take psi with its hand where it is at q
        (on q's branch, within the joint limits); checked once per joints and target."""
        key = (q.tobytes(), psi)
        if self._attainable == key:
            return
        c = Configuration(self.solver.configuration_of(q).signs, (psi,))
        try:
            self.solve_within_limits(self.solver.arm.fk(q), c, q, "ArmAngleTask")
        except UnreachableTarget as exc:
            raise UnreachableTarget(
                f"{exc}: the arm cannot take psi* = {psi:+.4f} with its hand where it is, and pulling the "
                "elbow there would pull the hand off its target"
            ) from None
        self._attainable = key
