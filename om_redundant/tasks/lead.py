r"""Where :class:`~om_redundant.ExactPoseTask` aims while the hand is far from its target:
a pose a short lead ahead of the hand on the straight way to the target.

With hand pose :math:`H` and target :math:`T`, position gap :math:`d = |p_T - p_H|` and
rotation gap :math:`\theta` (the angle of :math:`R_H^T R_T`), the aim is the pose a fraction

.. math::  s = \min\big(1,\ \ell_p / d,\ \ell_r / \theta\big)

of the way from H to T: the position on the straight line, the rotation turned about the
fixed axis of :math:`R_H^T R_T` (spherical interpolation). The target itself where
:math:`s = 1`.
"""

from __future__ import annotations

import math

import numpy as np

#: Default leads of :class:`~om_redundant.ExactPoseTask`'s aims: of the hand on its straight
#: way (m, rad), and of the joints on a joint-space way (rad, max-norm).
DEFAULT_LEAD = (0.05, 0.25, 0.1)


def pose_gap(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    """Position (m) and rotation angle (rad) between two poses."""
    cos = (np.trace(A[:3, :3].T @ B[:3, :3]) - 1.0) / 2.0
    return float(np.linalg.norm(B[:3, 3] - A[:3, 3])), math.acos(min(1.0, max(-1.0, cos)))


def lead_pose(hand: np.ndarray, target: np.ndarray, lead: tuple[float, ...]) -> np.ndarray:
    """The aim (module docstring): ``target`` itself (the same object) when it lies within
    the lead of the hand, else the pose a fraction s of the way there."""
    distance, angle = pose_gap(hand, target)
    s = min(1.0, lead[0] / distance if distance > 0.0 else 1.0, lead[1] / angle if angle > 0.0 else 1.0)
    if s >= 1.0:
        return target
    aim = np.eye(4)
    aim[:3, :3] = hand[:3, :3] @ _turned(hand[:3, :3].T @ target[:3, :3], angle, s)
    aim[:3, 3] = hand[:3, 3] + s * (target[:3, 3] - hand[:3, 3])
    return aim


def _turned(R: np.ndarray, angle: float, s: float) -> np.ndarray:
    """The rotation by s times the angle of R about R's axis (Rodrigues' formula)."""
    if angle == 0.0:
        return np.eye(3)
    if angle < math.pi - 1e-6:
        axis = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / (2.0 * math.sin(angle))
    else:  # a half turn: the axis from R + I, whose columns are multiples of it
        column = R + np.eye(3)
        axis = column[:, int(np.argmax(np.linalg.norm(column, axis=0)))]
    axis = axis / np.linalg.norm(axis)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    t = s * angle
    return np.eye(3) + math.sin(t) * K + (1.0 - math.cos(t)) * (K @ K)
