"""MuJoCo models as users bring them, compiled for their kinematics (inertial data, meshes
and textures replaced or skipped where they stop a model from compiling)."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco

from ..exceptions import InvalidInput


def load_mujoco_model(path: str | Path) -> mujoco.MjModel:
    """Compile an MJCF (.xml) or URDF (.urdf) file for its kinematics: as it is if it compiles,
    else with its inertial data replaced, then also without its meshes and textures.

    Kinematics depend on none of them, and models as they come often miss mesh files (like the
    reference Menagerie copies) or hold inertias that MuJoCo refuses (URDFs with
    ``A + B < C`` or negative eigenvalues: PR2, TIAGo, iCub). A URDF is read by MuJoCo's own
    URDF loader, with its bodies kept apart (``fusestatic`` off: a link on a fixed joint, such
    as ``tool0``, stays a body, usable as an end-effector frame).

    Raises:
        InvalidInput: The file cannot be read or does not compile; the message is one line
            and names the error that remains once inertials, meshes and textures are
            replaced or skipped, and the first one.
    """
    path = Path(path)
    if not path.is_file():
        raise InvalidInput(f"cannot read MuJoCo model '{path}': no such file")
    suffix = path.suffix.lower()
    if suffix not in (".xml", ".urdf"):  # MuJoCo picks its reader by the suffix, and warns without one
        raise InvalidInput(
            f"MuJoCo model '{path}' must be an MJCF file ending in .xml or a URDF ending in .urdf"
        )
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:
        raise InvalidInput(f"cannot load MuJoCo model '{path}': {one_line(exc)}") from None
    if suffix == ".urdf":
        spec.compiler.fusestatic = False
    try:
        return spec.compile()
    except ValueError as exc:
        first = error = exc
    # Each step keeps what the previous one changed; the meshes go last, as a model that
    # compiles without them loses its look.
    steps = [("its inertial data replaced", _kinematic_inertia)]
    if spec.meshes or spec.textures:
        steps.append(("its meshes and textures skipped", without_meshes))
    done = []
    for what, change in steps:
        done.append(what)
        try:
            return change(spec).compile()
        except ValueError as exc:
            error = exc
    raise InvalidInput(
        f"cannot load MuJoCo model '{path}': {one_line(error)} (with {' and '.join(done)}, which "
        f"failed first: {one_line(first)})"
    ) from None


def _kinematic_inertia(spec: mujoco.MjSpec) -> mujoco.MjSpec:
    """Give every body the same valid inertia (in place; returns the spec).

    MuJoCo refuses a model whose inertias break the triangle inequality or are not positive
    definite, and one whose moving bodies have no mass; the pose of every frame is the same
    whatever the masses, so the kinematics are the model's.
    """
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    for body in spec.bodies[1:]:  # the world's first
        body.explicitinertial = True
        body.mass, body.ipos, body.iquat = 1.0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]
        body.inertia, body.fullinertia = [1e-3] * 3, [math.nan] * 6
    return spec


def without_meshes(spec: mujoco.MjSpec) -> mujoco.MjSpec:
    """Delete the spec's meshes and textures and what needs them (in place; returns the spec).

    Deleted: geoms of type mesh, and geoms of other types fitted to a mesh (a ``mesh``
    attribute, e.g. a collision capsule sized by its mesh); meshes; textures, and the
    references of materials to them.
    """
    for geom in list(spec.geoms):
        if geom.type == mujoco.mjtGeom.mjGEOM_MESH or geom.meshname:
            spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    for material in spec.materials:
        material.textures = [""] * len(material.textures)
    for texture in list(spec.textures):
        spec.delete(texture)
    return spec


def one_line(exc: BaseException) -> str:
    """An exception's message on one line (MuJoCo's span several)."""
    return " ".join(str(exc).split())
