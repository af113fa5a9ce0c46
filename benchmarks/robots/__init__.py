"""The peers' robots, generated from one om_redundant arm file, and checks of their FK.

Every peer gets its robot from the same joint placements,
``T_root_ee(q) = P[0] Rz(q0) P[1] Rz(q1) ... P[n-1] Rz(q_{n-1}) P_tail``
(:meth:`om_redundant.KinematicChain.joint_placements`):

* :func:`urdf_text` for TRAC-IK and ikpy (mink uses the library's :func:`om_redundant.arm_model`);
* :class:`ScrewChain`, the joints as lines in the zero configuration (axes ``H``, points
  ``P``), for EAIK and ik-geo; :class:`SixAxisView` holds a 7-DOF arm's last joint at a
  given value so that those 6-DOF solvers apply; :func:`ik_geo_layout` picks ik-geo's
  decomposition and moves the points to the axis intersections it needs.

:func:`check_fk` compares a peer's forward kinematics with ``arm.fk`` on random joint
vectors; the suite refuses a peer whose FK disagrees.
"""

# One module per idea: transforms, joints (random, distance, home), reference (Menagerie models),
# urdf, screws (ScrewChain, SixAxisView, EAIK's robot), decompositions (ik-geo's), fk_check.

from __future__ import annotations

from .decompositions import IK_GEO_FAMILIES, IkGeoLayout, ik_geo_layout
from .fk_check import FKCheck, check_fk
from .joints import home_joints, joint_distance, random_joints
from .reference import MENAGERIE, reference_model, reference_spec
from .screws import ScrewChain, SixAxisView, eaik_robot
from .transforms import pose_errors, rot_z
from .urdf import EE_LINK, ROOT_LINK, urdf_text

__all__ = [
    "EE_LINK",
    "IK_GEO_FAMILIES",
    "MENAGERIE",
    "ROOT_LINK",
    "FKCheck",
    "IkGeoLayout",
    "ScrewChain",
    "SixAxisView",
    "check_fk",
    "eaik_robot",
    "home_joints",
    "ik_geo_layout",
    "joint_distance",
    "pose_errors",
    "random_joints",
    "reference_model",
    "reference_spec",
    "rot_z",
    "urdf_text",
]
