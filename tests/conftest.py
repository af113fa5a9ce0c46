"""Shared helpers: the reference Menagerie models (kinematics only) beside the project, and
running the checkout's code in a fresh interpreter."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
from hypothesis import settings

from om_redundant.mujoco_io.model_match import load_mujoco_model

# The suite's property tests draw the same examples on every run, so that CI answers for the
# code and not for the draw; HYPOTHESIS_PROFILE=explore draws new ones (run it to hunt bugs:
# the known gaps it can find are listed under "Status" in the README).
settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))

ROOT = Path(__file__).resolve().parents[1]
MENAGERIE = ROOT.parent / "shared" / "reference" / "menagerie"


def load_reference_model(relative_path: str) -> mujoco.MjModel:
    """Load a Menagerie MJCF, without its meshes (the files ship without them)."""
    path = MENAGERIE / relative_path
    if not path.is_file():
        pytest.skip(f"reference model {path} not available")
    return load_mujoco_model(path)


def checkout_env() -> dict[str, str]:
    """The environment in which a fresh interpreter imports this checkout's package."""
    path = os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])
    return {**os.environ, "PYTHONPATH": path}


def run_python(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    """``python ARGS`` in a fresh interpreter, as a user runs it (``-m om_redundant.cli ...`` or a
    script), importing this checkout's package; output captured as text."""
    return subprocess.run(
        [sys.executable, *args], cwd=ROOT, env=checkout_env(), capture_output=True, text=True, timeout=timeout
    )


def wrap(angle: np.ndarray) -> np.ndarray:
    """Wrap angles into [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def random_q(arm, n: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform joint vectors within limits; unlimited revolute joints in [-pi, pi]."""
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (n, arm.dof))


@pytest.fixture
def arm_without_a_model(tmp_path) -> Path:
    """An arm file the OM method refuses: the Sawyer with a sideways offset (a = 0.01 m) in its
    fixed row between joints 6 and 7, which would make dp depend on q6 as well."""
    text = (ROOT / "arms" / "sawyer.toml").read_text()
    text = text.replace('name = "sawyer"', 'name = "bent"').replace("d = 0.11\n", "d = 0.11\na = 0.01\n")
    path = tmp_path / "bent.toml"
    path.write_text(text)
    return path
