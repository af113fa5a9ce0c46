r"""Distance from the singularities of an arm's closed-form model: wrist, elbow, shoulder.

The model arm (:mod:`om_redundant.ik.model`) branches where one of its branch quantities
vanishes; there two branches meet, a joint axis pair aligns and the hand loses a direction
of motion. Each is the sine of one joint angle :math:`x_k = q_{j_k} + c_k`:

* 7-DOF (S-R-S model, :mod:`om_redundant.ik.families.srs`): the wrist,
  :math:`\sin(q_6 + \theta_6)` (axes 5 and 7 align); the elbow,
  :math:`\sin(q_4 + \theta_4 - \varphi^*)` (straight or folded: the shoulder-wrist distance
  is extremal); the shoulder, :math:`\sin(q_2 + \theta_2)` (axes 1 and 3 align). Their
  signs are the WRIST, ELBOW and SHOULDER signs.
* 6-DOF with revolute joints 2 and 3 (RRR): the wrist, :math:`\sin(q_5 + \theta_5)`, and the
  elbow, :math:`\sin(q_3 + \theta_3 + \beta)` (the arm stretched or folded); their signs are
  WRIST and ELBOW. (The shoulder singularity, the wrist centre on axis 1, is no joint angle.)
* 6-DOF RRP: the wrist.

The distance of the singularity k is :math:`s_k(q) = |\sin x_k|`, 0 on it, 1 a quarter turn
away; its derivative by :math:`q_{j_k}` is :math:`\mathrm{sign}(\sin x_k)\cos x_k` (the
branch sign times :math:`\cos x_k`; :math:`+\cos x_k` on the singularity itself, the
derivative from the positive side). The real arm's singularities lie near the model's,
within its offsets.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ... import _core
from ...ik.families import RRR_SPHERICAL_WRIST, SRS
from ...ik.model import ModelArm
from ...validation import as_instance, as_joint_vector


@dataclass(frozen=True)
class Singularity:
    r"""The singularities of one model arm, each where :math:`\sin(q_j + c) = 0`.

    Attributes:
        names: What each singularity is: ``"wrist"``, ``"elbow"``, ``"shoulder"``.
        joints: (k,) the joint index j of each.
        offsets: (k,) the constant c of each (rad).
        dof: The arm's number of joints.
    """

    names: tuple[str, ...]
    joints: np.ndarray
    offsets: np.ndarray
    dof: int

    @classmethod
    def of(cls, model: ModelArm, flip: np.ndarray | None = None) -> Singularity:
        """The singularities of a model arm (module docstring), from its family's parameters.

        Args:
            model: The model arm.
            flip: (dof,) +-1: the model's joint coordinates are ``flip * q`` (an arm near a
                family with a reversed axis, ``OMSolver.flip``); None for all +1.
        """
        P = as_instance(model, ModelArm, "model").params
        if model.family == SRS:
            theta = P[_core.SRS_THETA : _core.SRS_THETA + 7]
            rows = (
                ("wrist", 5, theta[5]),
                ("elbow", 3, theta[3] - P[_core.SRS_PHI_STAR]),
                ("shoulder", 1, theta[1]),
            )
        elif model.family == RRR_SPHERICAL_WRIST:
            rows = (("wrist", 4, P[_core.SD_THETA5]), ("elbow", 2, P[_core.SD_THETA3] + P[_core.SD_BETA]))
        else:
            rows = (("wrist", 4, P[_core.SD_THETA5]),)
        names, joints, offsets = zip(*rows, strict=True)
        joints, offsets = np.array(joints), np.array(offsets, dtype=float)
        if flip is not None:  # |sin(-q + c)| = |sin(q - c)|
            offsets *= np.asarray(flip, dtype=float)[joints]
        return cls(names, joints, offsets, model.real.dof)

    def rows(self) -> tuple[np.ndarray, np.ndarray]:
        """The joints (int64) and offsets as compiled kernels take them (C-contiguous)."""
        return np.ascontiguousarray(self.joints, dtype=np.int64), np.ascontiguousarray(
            self.offsets, dtype=float
        )

    def distances(self, q: np.ndarray) -> np.ndarray:
        r"""The distances :math:`s_k(q) = |\sin(q_{j_k} + c_k)|`.

        Args:
            q: (dof,) or (M, dof) joint vectors.

        Returns:
            (k,) or (M, k): 0 on a singularity, 1 a quarter turn from it.
        """
        q = as_joint_vector(q, self.dof)
        return np.abs(np.sin(q[..., self.joints] + self.offsets))

    def distances_and_gradients(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The distances at one joint vector and their derivatives by q.

        Args:
            q: (dof,) joint vector.

        Returns:
            (k,) distances and (k, dof) their gradients (module docstring).
        """
        x = as_joint_vector(q, self.dof)[self.joints] + self.offsets
        sine, slope = np.sin(x), np.cos(x)
        np.negative(slope, out=slope, where=sine < 0.0)  # sign(sin x) cos x, +cos x where sin x = 0
        gradient = np.zeros(len(self.joints) * self.dof)
        gradient[self._entries] = slope
        return np.abs(sine), gradient.reshape(len(self.joints), self.dof)

    @cached_property
    def _entries(self) -> np.ndarray:
        """Where each singularity's derivative sits in its (k, dof) gradient, flattened: row
        k, column j_k."""
        return np.arange(len(self.joints)) * self.dof + self.joints
