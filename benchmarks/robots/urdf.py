"""A URDF of an arm from its joint placements, for TRAC-IK and ikpy."""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

import om_redundant as om

#: Names of the generated URDF links that the peers chain between.
ROOT_LINK = "root"
EE_LINK = "ee"


def _numbers(values: Any) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def urdf_text(arm: om.Arm) -> str:
    """A URDF of the arm: one link per joint frame, revolute joints about z, a fixed ``ee`` link.

    Joint origins are the placements ``P[i]`` (xyz and roll-pitch-yaw, full precision),
    limits are the arm's (``continuous`` where unlimited). Links carry a small inertia so
    that parsers which want one are satisfied, except the root (KDL refuses an inertial
    root link). Only revolute arms are supported.
    """
    if not arm.revolute.all():
        raise ValueError(f"arm '{arm.name}' has a prismatic joint; the URDF writer takes revolute arms")
    P, tail = arm.chain.joint_placements()
    links = [ROOT_LINK, *(f"link{i + 1}" for i in range(arm.dof)), EE_LINK]
    inertial = (
        '<inertial><mass value="0.1"/>'
        '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>'
    )
    lines = ['<?xml version="1.0"?>', f'<robot name="{arm.name}">']
    lines.append(f'  <link name="{ROOT_LINK}"/>')
    lines += [f'  <link name="{name}">{inertial}</link>' for name in links[1:]]
    for i, (placement, joint) in enumerate(zip(P, arm.joint_names, strict=True)):
        lo, hi = float(arm.lower[i]), float(arm.upper[i])
        kind = "revolute" if np.isfinite(lo) and np.isfinite(hi) else "continuous"
        limit = (
            f'<limit lower="{lo!r}" upper="{hi!r}" effort="100" velocity="10"/>' if kind == "revolute" else ""
        )
        lines.append(
            f'  <joint name="{joint}" type="{kind}"><parent link="{links[i]}"/><child link="{links[i + 1]}"/>'
            f'{_urdf_origin(placement)}<axis xyz="0 0 1"/>{limit}</joint>'
        )
    lines.append(
        f'  <joint name="{EE_LINK}_joint" type="fixed"><parent link="{links[-2]}"/>'
        f'<child link="{EE_LINK}"/>{_urdf_origin(tail)}</joint>'
    )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def _urdf_origin(T: np.ndarray) -> str:
    # URDF's rpy is R = Rz(yaw) Ry(pitch) Rx(roll): scipy's extrinsic "xyz".
    rpy = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")
    return f'<origin xyz="{_numbers(T[:3, 3])}" rpy="{_numbers(rpy)}"/>'
