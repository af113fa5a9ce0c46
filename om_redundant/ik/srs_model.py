"""The model of a 7-DOF arm and its closed form's parameters: a Hollerbach arm with a spherical
shoulder and wrist (:mod:`om_redundant.ik.families.srs`), the elbow's offsets kept."""

from __future__ import annotations

import dataclasses

import numpy as np

from .. import _core
from ..exceptions import ModelError
from ..kinematics.arm import Arm
from ..kinematics.chain import JointKind, KinematicChain
from .joint_names import joint_name
from .model_conditions import check_concurrent, check_right_angle, refuse_fixed_rows
from .model_frames import pose, rotx, rotz, tail_rotation


def srs_model(arm: Arm) -> tuple[KinematicChain, KinematicChain, np.ndarray]:
    r"""Zero the offsets that keep joints 1-3 (a1, a2, d2) or joints 5-7 (a5, a6, d6) from meeting.

    In standard DH, joint i+1 turns about :math:`z_i` through :math:`o_i`. Axes 1 and 2 meet
    (at S = :math:`o_1`) iff :math:`a_1 = 0`; axis 3 passes through S iff :math:`d_2 = a_2 = 0`;
    likewise :math:`a_5 = 0` and :math:`d_6 = a_6 = 0` put axes 5-7 through W = :math:`o_5`.
    The elbow's offsets (:math:`a_3, d_4, a_4`) are kept. :math:`a_2` would make dp depend on
    q2 as well and is refused here; the arm's nominal arm zeroes it
    (:mod:`~om_redundant.ik.nominal`), whose correction solves it.

    Returns:
        The model chain, the real chain with only its shoulder offsets zeroed, and the
        closed form's parameters.
    """
    rows = list(arm.chain.rows)
    jr = arm.chain.joint_rows
    if any(rows[r].kind is not JointKind.REVOLUTE for r in jr):
        raise ModelError(f"arm '{arm.name}': the 7-DOF model needs revolute joints")
    if rows[jr[1]].a != 0.0:
        raise ModelError(
            f"arm '{arm.name}': the shoulder offset a2 = {rows[jr[1]].a:g} m (from the axis of "
            f"{joint_name(arm, 1)} to that of {joint_name(arm, 2)}, which then miss the shoulder's "
            f"centre) makes dp depend on {joint_name(arm, 1)}; the model's bounded searches take offsets "
            f"that turn with {joint_name(arm, 0)} or {joint_name(arm, 6)} only (OMSolver solves the "
            "arm through its nominal arm, which zeroes a2: om.nominal_arm)"
        )
    refuse_fixed_rows(arm, (0, 1, 2, 3, 4, 5))
    if any(rows[r].a != 0.0 for r in range(jr[5] + 1, jr[6])):
        raise ModelError(
            f"arm '{arm.name}': fixed rows between {joint_name(arm, 5)} and {joint_name(arm, 6)} need a = 0"
        )
    for j in (0, 1, 4, 5):
        check_right_angle(arm, rows[jr[j]], j)
    for j, fields in ((0, ("a",)), (1, ("d",))):
        rows[jr[j]] = dataclasses.replace(rows[jr[j]], **dict.fromkeys(fields, 0.0))
    shoulderless = arm.chain.replace_rows(rows)
    for j, fields in ((4, ("a",)), (5, ("a", "d"))):
        rows[jr[j]] = dataclasses.replace(rows[jr[j]], **dict.fromkeys(fields, 0.0))
    # Lengths along joint 7's axis between joints 6 and 7 move past joint 7 (its row's d):
    # joint 7's axis then meets W, and the hand moves by no more than their tilt.
    moved = sum(rows[r].d for r in range(jr[5] + 1, jr[6]))
    for r in range(jr[5] + 1, jr[6]):
        rows[r] = dataclasses.replace(rows[r], d=0.0)
    rows[jr[6]] = dataclasses.replace(rows[jr[6]], d=rows[jr[6]].d + moved)
    chain = arm.chain.replace_rows(rows)
    table = chain.table

    def frame(k: int, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return pose(table[: jr[0] + k], q[:k])  # frame k, after joint k's row

    check_concurrent(arm, chain, "shoulder", (0, 1, 2))
    check_concurrent(arm, chain, "wrist", (4, 5, 6))
    q0 = np.zeros(7)
    (_, S), (R3, o3), (_, W) = (frame(k, q0) for k in (1, 3, 5))
    R_fl, p_fl = pose(table, q0)
    s3 = R3.T @ (S - o3)
    u = rotz(-rows[jr[3]].theta) @ R3.T @ (W - o3)
    k0 = u @ u + s3 @ s3 - 2.0 * s3[2] * u[2]
    k1 = -2.0 * (s3[0] * u[0] + s3[1] * u[1])
    k2 = -2.0 * (s3[1] * u[0] - s3[0] * u[1])
    if np.hypot(k1, k2) < 1e-9:
        raise ModelError(
            f"arm '{arm.name}': {joint_name(arm, 3)} does not change the shoulder-wrist distance"
        )
    P = np.zeros(_core.SRS_N_PARAMS)
    P[_core.SRS_SIGMA1], P[_core.SRS_SIGMA2], P[_core.SRS_SIGMA5] = (
        np.sign(np.sin(rows[jr[j]].alpha)) for j in (0, 1, 4)
    )
    P[_core.SRS_THETA : _core.SRS_THETA + 7] = [rows[r].theta for r in jr]
    # The wrist's middle rotation Rx(alpha_6) F = Rz(a) Rx(beta) Rz(b), F the fixed rows'.
    middle = rotx(rows[jr[5]].alpha) @ pose(table[jr[5] + 1 : jr[6]], q0[:0])[0]
    sin_beta = np.sign(np.sin(rows[jr[5]].alpha)) * np.sqrt(max(1.0 - middle[2, 2] ** 2, 0.0))
    P[_core.SRS_SIN_BETA], P[_core.SRS_COS_BETA] = sin_beta, middle[2, 2]
    P[_core.SRS_THETA + 5] += np.arctan2(middle[0, 2] / sin_beta, -middle[1, 2] / sin_beta)
    P[_core.SRS_THETA + 6] += np.arctan2(middle[2, 0] / sin_beta, middle[2, 1] / sin_beta)
    P[_core.SRS_SHOULDER : _core.SRS_SHOULDER + 3] = S
    P[_core.SRS_WRIST : _core.SRS_WRIST + 3] = R_fl.T @ (W - p_fl)
    P[_core.SRS_S3 : _core.SRS_S3 + 3] = s3
    P[_core.SRS_U : _core.SRS_U + 3] = u
    P[_core.SRS_K0], P[_core.SRS_K], P[_core.SRS_PHI_STAR] = k0, np.hypot(k1, k2), np.arctan2(k2, k1)
    P[_core.SRS_COS_PHI_STAR], P[_core.SRS_SIN_PHI_STAR] = k1 / P[_core.SRS_K], k2 / P[_core.SRS_K]
    P[_core.SRS_R_PRE : _core.SRS_R_PRE + 9] = pose(table[: jr[0]], q0[:0])[0].ravel()
    P[_core.SRS_X3 : _core.SRS_X3 + 9] = rotx(rows[jr[2]].alpha).ravel()
    P[_core.SRS_X4 : _core.SRS_X4 + 9] = rotx(rows[jr[3]].alpha).ravel()
    P[_core.SRS_E_ROT : _core.SRS_E_ROT + 9] = tail_rotation(rows, jr[6]).ravel()
    R_base = chain.T_root_base[:3, :3]
    # sigma: with the elbow bent (phi4 = phi* + pi/2, ELBOW = +1), b3 points to the elbow -s3.
    v = rotz(P[_core.SRS_PHI_STAR] + np.pi / 2) @ u - s3
    P[_core.SRS_BEND] = np.sign(np.cross([0.0, 0.0, 1.0], v) @ -s3)
    P[_core.SRS_UP : _core.SRS_UP + 3] = R_base.T @ np.array([0.0, 0.0, 1.0])
    P[_core.SRS_REF : _core.SRS_REF + 3] = R_base.T @ np.array([-1.0, 0.0, 0.0])
    return chain, shoulderless, P
