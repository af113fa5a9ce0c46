"""Obstacle shapes in the arm's root frame (:class:`Sphere`, :class:`Capsule`, :class:`Box`)
and the MuJoCo geoms they become in :meth:`Clearance.for_arm
<om_redundant.Clearance.for_arm>`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

from ...exceptions import InvalidInput
from ...validation import as_instance, as_pose, as_positive, as_vector

_PRIMITIVES = {
    mujoco.mjtGeom.mjGEOM_PLANE,
    mujoco.mjtGeom.mjGEOM_SPHERE,
    mujoco.mjtGeom.mjGEOM_CAPSULE,
    mujoco.mjtGeom.mjGEOM_ELLIPSOID,
    mujoco.mjtGeom.mjGEOM_CYLINDER,
    mujoco.mjtGeom.mjGEOM_BOX,
}


@dataclass(frozen=True)
class Geom:
    """A world geom to add to a MuJoCo spec: type, size, position, quaternion (w, x, y, z)."""

    name: str
    type: mujoco.mjtGeom
    size: np.ndarray
    pos: np.ndarray
    quat: np.ndarray


@dataclass(frozen=True, eq=False)
class Sphere:
    """A sphere obstacle, in the arm's root frame (metres).

    Attributes:
        center: (3,) centre.
        radius: Radius, > 0.
        name: Geom name; default ``"obstacle<k>"`` for the k-th obstacle.
    """

    center: Any
    radius: float
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", as_vector(self.center, 3, "Sphere center"))
        object.__setattr__(self, "radius", as_positive(self.radius, "Sphere radius"))

    def geom(self, name: str) -> Geom:
        size = np.array([self.radius, 0.0, 0.0])
        return Geom(name, mujoco.mjtGeom.mjGEOM_SPHERE, size, self.center, np.array([1.0, 0, 0, 0]))


@dataclass(frozen=True, eq=False)
class Capsule:
    """A capsule obstacle: the points within ``radius`` of the segment ``start``-``end``.

    Attributes:
        start, end: (3,) ends of the axis in the arm's root frame, distinct.
        radius: Radius, > 0.
        name: Geom name; default ``"obstacle<k>"``.
    """

    start: Any
    end: Any
    radius: float
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", as_vector(self.start, 3, "Capsule start"))
        object.__setattr__(self, "end", as_vector(self.end, 3, "Capsule end"))
        object.__setattr__(self, "radius", as_positive(self.radius, "Capsule radius"))
        if np.linalg.norm(self.end - self.start) == 0.0:
            raise InvalidInput("Capsule start and end coincide; use a Sphere")

    def geom(self, name: str) -> Geom:
        axis = self.end - self.start
        quat = np.empty(4)
        mujoco.mju_quatZ2Vec(quat, axis)
        size = np.array([self.radius, np.linalg.norm(axis) / 2.0, 0.0])
        return Geom(name, mujoco.mjtGeom.mjGEOM_CAPSULE, size, (self.start + self.end) / 2.0, quat)


@dataclass(frozen=True, eq=False)
class Box:
    """A box obstacle.

    Attributes:
        half_sizes: (3,) half edge lengths along the box's own axes, each > 0.
        pose: Pose of the box centre in the arm's root frame: 4x4 or ``mink.SE3``.
        name: Geom name; default ``"obstacle<k>"``.
    """

    half_sizes: Any
    pose: Any = field(default_factory=lambda: np.eye(4))
    name: str = ""

    def __post_init__(self) -> None:
        half = as_vector(self.half_sizes, 3, "Box half_sizes")
        if not (half > 0.0).all():
            raise InvalidInput(f"Box half_sizes must be positive, got {half.tolist()}")
        object.__setattr__(self, "half_sizes", half)
        object.__setattr__(self, "pose", as_pose(self.pose, "Box pose"))

    def geom(self, name: str) -> Geom:
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, np.ascontiguousarray(self.pose[:3, :3]).ravel())
        return Geom(name, mujoco.mjtGeom.mjGEOM_BOX, self.half_sizes, self.pose[:3, 3], quat)


Shape = Sphere | Capsule | Box


def shape_geoms(obstacles: Sequence[Shape]) -> list[Geom]:
    if isinstance(obstacles, Sphere | Capsule | Box):
        obstacles = [obstacles]
    as_instance(obstacles, Sequence, "obstacles", "shapes (Sphere, Capsule, Box) or a MuJoCo model")
    geoms = []
    for k, shape in enumerate(obstacles):
        if isinstance(shape, mujoco.MjModel):
            geoms += model_geoms(shape)
            continue
        if not isinstance(shape, Sphere | Capsule | Box):
            raise InvalidInput(
                f"obstacle {k} must be a Sphere, Capsule or Box (or pass a MuJoCo model), "
                f"got {type(shape).__name__}"
            )
        geoms.append(shape.geom(shape.name or f"obstacle{k}"))
    return geoms


def model_geoms(model: mujoco.MjModel) -> list[Geom]:
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    geoms = []
    for g in range(model.ngeom):
        kind = mujoco.mjtGeom(model.geom_type[g])
        name = model.geom(g).name or f"obstacle{g}"
        if kind not in _PRIMITIVES:
            raise InvalidInput(
                f"obstacle geom '{name}' is a {kind.name[7:].lower()}; only primitive geoms are copied "
                "(for others, put the arm in your model and use Clearance(model, arm, names))"
            )
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, data.geom_xmat[g])
        geoms.append(Geom(name, kind, model.geom_size[g].copy(), data.geom_xpos[g].copy(), quat))
    return geoms
