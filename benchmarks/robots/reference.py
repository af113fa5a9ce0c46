"""The reference MuJoCo Menagerie models beside the project, compiled without their meshes."""

from __future__ import annotations

from pathlib import Path

import mujoco

import om_redundant as om
from om_redundant.mujoco_io import without_meshes

#: The reference MuJoCo Menagerie models (kinematics only), beside the project.
MENAGERIE = Path(__file__).resolve().parents[3] / "shared" / "reference" / "menagerie"


def reference_spec(relative_path: str) -> mujoco.MjSpec:
    """A Menagerie MJCF under :data:`MENAGERIE` with its meshes stripped (the files ship
    without them), to edit before compiling."""
    return without_meshes(mujoco.MjSpec.from_file(str(MENAGERIE / relative_path)))


def reference_model(relative_path: str) -> mujoco.MjModel:
    """A Menagerie model under :data:`MENAGERIE`, compiled without its missing meshes."""
    return om.load_mujoco_model(MENAGERIE / relative_path)
