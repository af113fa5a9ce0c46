"""Poses: a rotation about z, and the distance and angle between two poses."""

from __future__ import annotations

import numpy as np


def rot_z(angle: float) -> np.ndarray:
    """Homogeneous rotation about z (4x4)."""
    c, s = np.cos(angle), np.sin(angle)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    return T


def pose_errors(T_a: np.ndarray, T_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position distance (m) and rotation angle (rad) between poses (..., 4, 4)."""
    position = np.linalg.norm(T_a[..., :3, 3] - T_b[..., :3, 3], axis=-1)
    R = np.swapaxes(T_a[..., :3, :3], -1, -2) @ T_b[..., :3, :3]
    # The angle from the skew part: accurate for small angles, unlike arccos of the trace.
    skew = np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1
    )
    trace = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    angle = np.arctan2(np.linalg.norm(skew, axis=-1) / 2.0, (trace - 1.0) / 2.0)
    return position, angle
