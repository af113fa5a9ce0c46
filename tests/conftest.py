"""Shared fixtures: the reference Menagerie models (kinematics only) beside the project."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from benchmarks.robots import MENAGERIE, reference_model


def load_reference_model(relative_path: str) -> mujoco.MjModel:
    """Load a Menagerie MJCF with its meshes stripped; skip the test where it is missing."""
    path = MENAGERIE / relative_path
    if not path.is_file():
        pytest.skip(f"reference model {path} not available")
    return reference_model(relative_path)


def wrap(angle: np.ndarray) -> np.ndarray:
    """Wrap angles into [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def random_q(arm, n: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform joint vectors within limits; unlimited revolute joints in [-pi, pi]."""
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (n, arm.dof))
