r"""MuJoCo models of the arms, built from their kinematic chains with primitive geoms.

The chain's joint placements (:meth:`~om_redundant.kinematics.KinematicChain.joint_placements`)

.. math::  T_{root,ee}(q) = P_0\, M_0(q_0)\, P_1\, M_1(q_1) \cdots P_{n-1}\, M_{n-1}(q_{n-1})\, P_{tail}

map one to one onto MJCF: body ``link{i+1}`` sits at :math:`P_i` in its parent and carries
joint i (hinge or slide, axis ``0 0 1`` at the body origin, range ``[lower, upper]`` where
both are finite, else unlimited), so MuJoCo's pose of the end-effector frame equals
``arm.fk(q)`` for ``qpos = q``. Numbers are written in full
precision (shortest round-trip repr), so the XML text is exact.

Names match the MuJoCo Menagerie model the arm matches, so either model drops in for the
other: joints are ``arm.joint_names``; the end-effector frame is a site at :math:`P_{tail}`
in the last link named ``arm.frame_name`` (``"end_effector"`` for an arm that names none);
when the Menagerie frame is a body (UR5e's ``wrist_3_link``), that site sits in a jointless
body of the same name, so body and site lookups both work. Bodies are ``base`` (welded to
the world; named after the arm's root body, ``arm.root``, where it has one, as an imported
arm's) and ``link1`` ... ``link{n}``.

Geometry: capsules of one radius r (default: ``RADIUS_PER_REACH`` times the stretched
length of the chain, :math:`\sum_k |p_{k+1} - p_k|` over the joint origins and the
end-effector, rounded to 0.1 mm), one along the joint axis (half-length r) at each joint and
one along each non-zero segment to the next joint origin or the end-effector. They are the
collision geoms, named ``"<body>_capsule<k>"`` and of the default class ``"collision"``
(``contype = conaffinity = 1``, as in Menagerie). Masses and inertias follow from the geoms
(MuJoCo's default density, 1000 kg/m^3). MuJoCo ignores parent-child contacts; the other
pairs of bodies whose geoms touch in every configuration, because the chain between them
(e.g. across a spherical wrist) is shorter than 2r, are excluded with ``<exclude>``. Every
name, class included, starts with ``prefix`` (default the arm's, ``arm.prefix``), but the
root body's.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import mujoco
import numpy as np

from ..exceptions import InvalidInput
from ..kinematics.arm import Arm
from ..validation import as_instance, as_positive

DEFAULT_SITE = "end_effector"
RADIUS_PER_REACH = 0.03  # default capsule radius over the stretched length of the chain
MIN_RADIUS, MAX_RADIUS = 1e-4, 10.0  # m: the capsules' radius


def arm_mjcf(arm: Arm, *, prefix: str | None = None, radius: float | None = None) -> str:
    """MJCF text of the arm alone (no floor, no light), its base at the world origin.

    Args:
        arm: The arm.
        prefix: Prepended to every body, joint, geom, site and class name, e.g. ``"l_"``;
            default the arm's (``arm.prefix``).
        radius: Capsule radius in metres; default ``RADIUS_PER_REACH`` times the
            stretched length of the chain (see the module docstring).

    Returns:
        A ``<mujoco>`` document.

    Raises:
        InvalidInput: arm is not an :class:`~om_redundant.Arm`, prefix not a string, or radius
            not a number from :data:`MIN_RADIUS` to :data:`MAX_RADIUS` m.
    """
    return _text(_arm_tree(arm, prefix, radius, scene=False))


def arm_model(arm: Arm, *, prefix: str | None = None, radius: float | None = None) -> mujoco.MjModel:
    """The compiled model of :func:`arm_mjcf` (same arguments)."""
    return mujoco.MjModel.from_xml_string(arm_mjcf(arm, prefix=prefix, radius=radius))


def scene_mjcf(arm: Arm, *, prefix: str | None = None, radius: float | None = None) -> str:
    """:func:`arm_mjcf` plus a light and a floor plane through the base (z = 0).

    The world is excluded from contact with the links that touch it in every
    configuration (by the rule for pairs of links, the world standing for the base origin),
    e.g. link1 of an arm whose first joint origin is the base origin.
    """
    return _text(_arm_tree(arm, prefix, radius, scene=True))


def _arm_tree(arm: Arm, prefix: str | None, radius: float | None, scene: bool) -> ET.Element:
    as_instance(arm, Arm, "arm")
    prefix = arm.prefix if prefix is None else as_instance(prefix, str, "prefix")
    P, P_tail = arm.chain.joint_placements()
    n = arm.dof
    ends = np.vstack([P[:, :3, 3], P_tail[:3, 3]])  # segment of body k: origin -> ends[k]
    lengths = np.linalg.norm(ends, axis=1)
    r = as_positive(
        max(round(RADIUS_PER_REACH * lengths.sum(), 4), 1e-4) if radius is None else radius, "radius (m)"
    )
    if not MIN_RADIUS <= r <= MAX_RADIUS:  # (MuJoCo refuses the geoms and bodies beyond them)
        raise InvalidInput(f"radius must be from {MIN_RADIUS} to {MAX_RADIUS} m, got {r:g}")
    cls = f"{prefix}collision"
    names = {-1: "world", 0: arm.root or f"{prefix}base"} | {k: f"{prefix}link{k}" for k in range(1, n + 1)}
    frame = prefix + (arm.frame_name or DEFAULT_SITE)
    for k, name in names.items():
        if arm.frame_type == "body" and name == frame:  # the frame body keeps its model's name
            names[k] = f"{name}_body"

    root = ET.Element("mujoco", model=f"{prefix}{arm.name}")
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    default = ET.SubElement(ET.SubElement(root, "default"), "default", {"class": cls})
    ET.SubElement(default, "geom", type="capsule", size=_f([r]), contype="1", conaffinity="1")
    ET.SubElement(default, "site", size=_f([r / 2]), rgba="1 0.2 0.2 1")
    world = ET.SubElement(root, "worldbody")
    if scene:
        ET.SubElement(world, "light", pos="0 0 3", dir="0 0 -1", directional="true")
        ET.SubElement(world, "geom", name="floor", type="plane", size="0 0 0.05", rgba="0.8 0.8 0.8 1")
    body = ET.SubElement(world, "body", name=names[0], childclass=cls)
    for k in range(n + 1):
        if k > 0:
            body = ET.SubElement(body, "body", name=names[k], **_pose(P[k - 1]))
            joint = {"name": prefix + arm.joint_names[k - 1], "axis": "0 0 1"}
            joint["type"] = "hinge" if arm.revolute[k - 1] else "slide"
            if np.isfinite(arm.lower[k - 1]) and np.isfinite(arm.upper[k - 1]):
                joint.update(limited="true", range=_f([arm.lower[k - 1], arm.upper[k - 1]]))
            ET.SubElement(body, "joint", joint)
        segments = ([[0, 0, -r], [0, 0, r]],) if k > 0 else ()
        segments += ([[0, 0, 0], ends[k]],) if lengths[k] > 1e-6 else ()
        for j, (a, b) in enumerate(segments):
            ET.SubElement(body, "geom", name=f"{names[k]}_capsule{j}", fromto=_f([*a, *b]))
    site = {"name": frame, **_pose(P_tail)}
    if arm.frame_type == "body":
        body = ET.SubElement(body, "body", name=site["name"], **_pose(P_tail))
        site = {"name": site["name"]}
    ET.SubElement(body, "site", site)

    # Bodies a < b touch in every configuration if the chain between them is shorter than
    # 2r: the end of a's last segment and b's joint capsule are then closer than 2r (a
    # slide joint in between makes that distance unbounded). Consecutive bodies are listed
    # too, as MuJoCo filters parent-child pairs but not the world-welded base and link1.
    # Body -1, the world (floor) at the base origin, only in the scene.
    slide = np.concatenate([[False], ~arm.revolute])  # slide[k]: body k moves along z
    contact = ET.SubElement(root, "contact")
    for a in range(-1 if scene else 0, n + 1):
        for b in range(max(a + 1, 1), n + 1):
            chain = lengths[a + 1 : b].sum() + (math.inf if slide[a + 1 : b + 1].any() else 0.0)
            if b == a + 1 or chain <= 2 * r:
                ET.SubElement(contact, "exclude", body1=names[a], body2=names[b])
    return root


def _pose(T: np.ndarray) -> dict[str, str]:
    """MJCF ``pos`` and ``quat`` (w, x, y, z) attributes of a (4, 4) transform."""
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).ravel())
    return {"pos": _f(T[:3, 3]), "quat": _f(quat)}


def _f(values) -> str:
    """Numbers as exact shortest round-trip text, entries below 1e-15 written as 0."""
    return " ".join(repr(0.0 if abs(x) < 1e-15 else float(x)) for x in values)


def _text(root: ET.Element) -> str:
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"
