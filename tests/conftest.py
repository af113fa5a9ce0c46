"""Shared fixtures: the reference Menagerie models (kinematics only) beside the project."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

MENAGERIE = Path(__file__).resolve().parents[2] / "shared" / "reference" / "menagerie"


def load_reference_model(relative_path: str) -> mujoco.MjModel:
    """Load a Menagerie MJCF with its meshes stripped (the files ship without them)."""
    path = MENAGERIE / relative_path
    if not path.is_file():
        pytest.skip(f"reference model {path} not available")
    spec = mujoco.MjSpec.from_file(str(path))
    for geom in list(spec.geoms):
        if geom.type == mujoco.mjtGeom.mjGEOM_MESH:
            spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    return spec.compile()


def wrap(angle: np.ndarray) -> np.ndarray:
    """Wrap angles into [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def random_q(arm, n: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform joint vectors within limits; unlimited revolute joints in [-pi, pi]."""
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (n, arm.dof))
