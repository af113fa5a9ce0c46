"""The conditions the closed forms put on an arm's joints, each refused with a
:class:`~om_redundant.exceptions.ModelError` that names the joints and by how much they miss it:
perpendicular twists, no fixed rows between the joints of a triple, concurrent axes."""

from __future__ import annotations

import math

import numpy as np

from ..exceptions import ModelError
from ..kinematics.arm import Arm
from ..kinematics.chain import DHRow, KinematicChain
from .joint_names import joint_name, joints_named
from .model_frames import pose

#: A twist whose sine is below this makes two joints parallel (no spherical triple).
PARALLEL_EPS = 1e-9
#: Largest deviation (rad) of a twist from +-90 deg (or from 0 between parallel joints) that
#: the closed forms, which take it to be exact, absorb: the hand then moves by well under the
#: solver's 1e-10 m per metre of reach.
RIGHT_ANGLE_EPS = 1e-11

#: A DH length within this many metres per metre of the arm's reach of zero, or an angle within
#: ``ANGLE_ROUNDING`` rad of a multiple of 90 deg, is the rounding of the value it is near, not
#: geometry (a URDF written to 11 digits leaves offsets of 5e-13 m where the arm has none): it
#: never changes the method an arm gets. :func:`~om_redundant.ik.model.derive_model` refuses an
#: arm with a nonzero length within it, so that the arm is solved through its nominal arm
#: (:func:`~om_redundant.ik.nominal.nominal_arm`), which has it zero, while its exact table
#: verifies every answer.
LENGTH_ROUNDING = 1e-9
#: An angle (rad) within this of a multiple of 90 deg is the rounding of that multiple (see
#: :data:`LENGTH_ROUNDING`).
ANGLE_ROUNDING = 1e-9


def check_right_angle(arm: Arm, row: DHRow, j: int) -> None:
    """Raise :class:`ModelError` unless joints j and j + 1 (0-based) are perpendicular: the twist
    of joint j's row within :data:`RIGHT_ANGLE_EPS` of +-90 deg."""
    if abs(np.sin(row.alpha)) < PARALLEL_EPS:
        raise ModelError(
            f"arm '{arm.name}': {joint_name(arm, j)} and {joint_name(arm, j + 1)} are parallel; the "
            "spherical joint triple needs them non-parallel (Theorem 2 C3)"
        )
    if off_right_angle(row.alpha) > RIGHT_ANGLE_EPS:
        raise ModelError(
            f"arm '{arm.name}': the closed form needs {joint_name(arm, j)} and {joint_name(arm, j + 1)} "
            "perpendicular "
            f"(alpha_{j + 1} = +-90 deg), got {np.degrees(row.alpha):.10g} deg "
            f"({off_right_angle(row.alpha):.2g} rad off)"
        )


def refuse_fixed_rows(arm: Arm, joints: tuple[int, ...]) -> None:
    """Raise :class:`ModelError` if fixed rows lie between these consecutive joints (0-based),
    naming each row and, between joints whose axes it turns nearly parallel or perpendicular,
    by how much."""
    rows, jr = arm.chain.rows, arm.chain.joint_rows
    found = []
    for k in joints[:-1]:
        between = rows[jr[k] + 1 : jr[k + 1]]
        if not between:
            continue
        values = [
            f"{key} {value:.10g}{unit}"
            for row in between
            for key, value, unit in (
                ("a", row.a, " m"),
                ("d", row.d, " m"),
                ("alpha", np.degrees(row.alpha), " deg"),
                ("theta", np.degrees(row.theta), " deg"),
            )
            if value != 0.0
        ]
        twist = pose(KinematicChain((rows[jr[k]], *between)).table, np.zeros(1))[0][2, 2]
        angle = float(np.arccos(np.clip(twist, -1.0, 1.0)))
        nominal = np.pi / 2 * round(angle / (np.pi / 2))
        off = f", {abs(angle - nominal):.2g} rad from {np.degrees(nominal):g} deg" if angle != nominal else ""
        found.append(
            f"after {joint_name(arm, k)} ({', '.join(values) or 'identity'}; axes {k + 1} and {k + 2} "
            f"{np.degrees(angle):.10g} deg apart{off})"
        )
    if found:
        raise ModelError(
            f"arm '{arm.name}': the closed form needs the rows of {joints_named(arm, joints)} to follow "
            f"one another; fixed rows {'; '.join(found)}"
        )


def off_right_angle(alpha: float) -> float:
    """How far (rad) the twist alpha is from +-90 deg."""
    return float(np.arctan2(abs(np.cos(alpha)), abs(np.sin(alpha))))


def check_concurrent(arm: Arm, chain: KinematicChain, what: str, joints: tuple[int, ...]) -> None:
    """Check that the axes of three consecutive joints pass through one point for any q.

    The point is the origin of the first joint's DH frame; joint j turns about the z-axis of
    the frame that ends the row before it.
    """
    jr = chain.joint_rows
    rng = np.random.default_rng(0)
    for _ in range(4):
        q = rng.uniform(-np.pi, np.pi, chain.dof)
        point = pose(chain.table[: jr[joints[0]] + 1], q[: joints[0] + 1])[1]
        for j in joints:
            R, p = pose(chain.table[: jr[j]], q[:j])
            if np.linalg.norm(np.cross(point - p, R[:, 2])) > 1e-9:
                raise ModelError(
                    f"arm '{arm.name}': the model's {what} axes ({joints_named(arm, joints)}) do not meet "
                    "in one point"
                )


def reach(chain: KinematicChain) -> float:
    """The chain's reach (m), the sum of its rows' :math:`|(a, d)|`: the scale of its lengths."""
    return sum(math.hypot(row.a, row.d) for row in chain.rows)


def rounding_length(chain: KinematicChain) -> float:
    """The largest DH length (m) that is rounding of zero in this chain: :data:`LENGTH_ROUNDING`
    times its reach."""
    return LENGTH_ROUNDING * reach(chain)
