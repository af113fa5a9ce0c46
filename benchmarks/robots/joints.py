"""Joint vectors: random ones within the limits, their distance, the iterative peers' home."""

from __future__ import annotations

import numpy as np

import om_redundant as om


def random_joints(arm: om.Arm, n: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform joint vectors within limits (unlimited joints in [-pi, pi]), shape (n, dof)."""
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (n, arm.dof))


def joint_distance(arm: om.Arm, a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| over the joints, revolute joints modulo 2 pi."""
    d = a - b
    return float(np.abs(np.where(arm.revolute, np.remainder(d + np.pi, 2 * np.pi) - np.pi, d)).max())


def home_joints(arm: om.Arm) -> np.ndarray:
    """The start of the iterative peers: the middle of each joint's range (0 if unlimited)."""
    middle = (arm.lower + arm.upper) / 2.0
    return np.where(np.isfinite(middle), middle, 0.0)
