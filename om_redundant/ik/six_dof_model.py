r"""The model of a 6-DOF arm (the paper's Theorem 2) and its closed form's parameters: a
spherical wrist (:math:`a_4, a_5, d_5` zeroed), the position family of joints 1-3 (RRR with
joints 2 and 3 parallel, or RRP), and where the solutions lie of a wrist with :math:`a_4 \ne 0`:
a circle in q1 (joint 4 parallel to joints 2 and 3) or the torus (q5, q6) (a PUMA-like wrist)."""

from __future__ import annotations

import dataclasses

import numpy as np

from .. import _core
from ..exceptions import ModelError
from ..kinematics.arm import Arm
from ..kinematics.chain import DHRow, JointKind, KinematicChain
from .joint_names import joint_name, joints_named
from .model_conditions import (
    RIGHT_ANGLE_EPS,
    check_right_angle,
    off_right_angle,
    refuse_fixed_rows,
    rounding_length,
)
from .model_frames import circle_fit, flange_delta, pose, tail_rotation, torus_fit


def six_dof_model(arm: Arm) -> tuple[KinematicChain, int, str, np.ndarray, np.ndarray | None]:
    """Theorem 2: zero a4, a5, d5 for a spherical wrist.

    Returns:
        The model's chain, its family code, name and parameters, and where the wrist's offsets
        make dp turn with joints 5 and 6 (a PUMA-like wrist, :func:`wrist_torus`) the (3, 3, 3)
        coefficients of dp seen from the flange, None otherwise.
    """
    rows = list(arm.chain.rows)
    jr = arm.chain.joint_rows
    for j in (3, 4, 5):
        if rows[jr[j]].kind is not JointKind.REVOLUTE:
            raise ModelError(f"arm '{arm.name}': Theorem 2 C3 needs {joint_name(arm, j)} revolute")
    refuse_fixed_rows(arm, (3, 4, 5))
    for j in (3, 4):
        check_right_angle(arm, rows[jr[j]], j)
    offsets = (rows[jr[3]].a, rows[jr[4]].d, rows[jr[4]].a)  # a4, d5, a5 of the real arm
    rows[jr[3]] = dataclasses.replace(rows[jr[3]], a=0.0)
    rows[jr[4]] = dataclasses.replace(rows[jr[4]], a=0.0, d=0.0)
    model_chain = arm.chain.replace_rows(rows)
    family, family_name, params = position_family(arm, rows)
    params[_core.SD_WRIST_ROW] = jr[3]
    for key, j in ((_core.SD_SIGMA4, 3), (_core.SD_SIGMA5, 4)):
        params[key] = np.sign(np.sin(rows[jr[j]].alpha))
    for key, j in ((_core.SD_THETA4, 3), (_core.SD_THETA5, 4), (_core.SD_THETA6, 5)):
        params[key] = rows[jr[j]].theta
    params[_core.SD_E_ROT : _core.SD_E_ROT + 9] = tail_rotation(rows, jr[5]).ravel()
    # Wrist centre in the flange frame: origin of joint 5's frame, the same for any q.
    q0 = np.zeros(6)
    _, o4 = pose(model_chain.table[: jr[3] + 1], q0[:4])
    R_fl, p_fl = pose(model_chain.table, q0)
    params[_core.SD_WRIST_CENTRE : _core.SD_WRIST_CENTRE + 3] = R_fl.T @ (o4 - p_fl)
    if offsets[0] == 0.0:
        return model_chain, family, family_name, params, None
    axis4 = joint_4_circle(arm, model_chain)
    if axis4 is not None:
        wrist_offset(arm, model_chain, offsets, params, R_fl, axis4)
        return model_chain, family, family_name + ", wrist offset a4 (dp turns with q1)", params, None
    if family != _core.RRR_SPHERICAL_WRIST:
        raise ModelError(
            f"arm '{arm.name}': a4 = {offsets[0]:g} != 0 with {joint_name(arm, 3)} across "
            f"{joint_name(arm, 1)} (a PUMA-like wrist: dp turns with {joints_named(arm, (4, 5))}) is "
            f"solved on the torus for the RRR family of {joints_named(arm, (0, 1, 2))}, not {family_name}"
        )
    name = f"{family_name}, wrist offsets a4, d5, a5 (dp turns with q5 and q6, on the torus)"
    coefficients = wrist_torus(arm, model_chain)
    params[_core.SD_WRIST_TORUS : _core.SD_WRIST_TORUS + 27] = coefficients.ravel()
    return model_chain, family, name, params, coefficients


def joint_4_circle(arm: Arm, model_chain: KinematicChain) -> np.ndarray | None:
    """Joint 4's axis in DH frame 0 as C0 + C1 cos q1 + C2 sin q1 (rows C0, C1, C2) where it turns
    with q1 alone (parallel to joint 2's, as when joints 2, 3 and 4 are parallel): a wrist offset
    a4's dp then turns with q1 (:func:`wrist_offset`); None where it turns with more."""
    table, jr = model_chain.table, arm.chain.joint_rows
    try:
        return circle_fit(arm, "joint 4's axis", 0, lambda q: pose(table[: jr[3]], q[:3])[0][:, 2])
    except ModelError:
        return None


def wrist_torus(arm: Arm, model_chain: KinematicChain) -> np.ndarray:
    r"""dp seen from the flange of a PUMA-like wrist with :math:`a_4 \ne 0` (joint 4 across joint 2):
    the (3, 3, 3) coefficients :math:`C_{ij}` of

    .. math::

        \delta(q_5, q_6) = R_{flange}^T (p_{model} - p_{real})
        = \sum_{ij} C_{ij}\, t_i(q_5)\, t_j(q_6), \qquad t = (1, \cos, \sin).

    Since :math:`A_i(q; a, d) = R_z(q) T_z(d) T_x(a) R_x(\alpha)` and :math:`T_z(d)` commutes
    with :math:`R_z(q)`, the real arm is the model followed by a translation that the rotations
    of joints 5 and 6 turn, :math:`T_{real}(q) = T_{model}(q)\,\mathrm{Trans}(-\delta(q_5, q_6))`.
    At a solution :math:`p_{model} = p_d + R_d\,\delta(q_5, q_6)`: the solutions of system (9)
    lie on the torus :math:`(w_5, w_6) = (q_5, q_6)`, lifted by the elbow angle (``csrc/ik/six_dof.c``,
    ``om_six_dof_model_ik_lifted``).

    Raises:
        ModelError: dp seen from the flange does not turn with joints 5 and 6 alone.
    """
    return torus_fit(
        arm, "dp seen from the flange", (4, 5), lambda q: flange_delta(arm.chain, model_chain, q)
    )


def position_family(arm: Arm, rows: list[DHRow]) -> tuple[int, str, np.ndarray]:
    """The family of joints 1-3 (RRR with joints 2 and 3 parallel, or RRP): its code, name and
    parameter vector with the position joints' entries filled."""
    jr = arm.chain.joint_rows
    r1, r2, r3, r4 = (rows[jr[j]] for j in range(4))
    P = np.zeros(_core.SD_N_PARAMS)
    if r1.kind is not JointKind.REVOLUTE or r2.kind is not JointKind.REVOLUTE:
        raise ModelError(
            f"arm '{arm.name}': {joint_name(arm, 0)} and {joint_name(arm, 1)} must be revolute for a "
            "closed-form model"
        )
    if jr[0] != 0:
        raise ModelError(
            f"arm '{arm.name}': the closed forms need the row of {joint_name(arm, 0)} first (no fixed row "
            "before it)"
        )
    refuse_fixed_rows(arm, (0, 1, 2))
    if off_right_angle(r1.alpha) > RIGHT_ANGLE_EPS:
        raise ModelError(
            f"arm '{arm.name}': {joint_name(arm, 0)} must be perpendicular to {joint_name(arm, 1)} "
            "(alpha_1 = +-90 deg), got "
            f"{np.degrees(r1.alpha):.10g} deg"
        )
    P[_core.SD_A1], P[_core.SD_D1], P[_core.SD_THETA1] = r1.a, r1.d, r1.theta
    P[_core.SD_SIGMA1] = np.sign(np.sin(r1.alpha))
    P[_core.SD_A2], P[_core.SD_THETA2] = r2.a, r2.theta
    between = rows[jr[2] + 1 : jr[3]]
    if any(r.a != 0.0 or r.d != 0.0 for r in between):
        raise ModelError(
            f"arm '{arm.name}': fixed rows between {joint_name(arm, 2)} and {joint_name(arm, 3)} must be "
            "pure rotations"
        )
    # Joints 2 and 3 parallel within what the closed form absorbs (a twist off by more goes
    # through the nominal arm, which snaps it).
    if r3.kind is JointKind.REVOLUTE and abs(np.sin(r2.alpha)) <= RIGHT_ANGLE_EPS and not between:
        if r2.a == 0.0:  # a nonzero a2 within rounding of 0 was refused first (derive_model)
            raise ModelError(
                f"arm '{arm.name}': a2 = 0 leaves {joint_name(arm, 1)} and {joint_name(arm, 2)} "
                "without a link"
            )
        lateral = np.cos(r2.alpha) * r2.d + r3.d + r4.d * np.cos(r3.alpha)
        # (cos(90 deg) d4 = 1e-17 m is rounding, not an offset: the shoulder's edge of reach is
        # then the axis itself, which the torus search of a PUMA-like wrist takes as such)
        P[_core.SD_LATERAL] = 0.0 if abs(lateral) <= rounding_length(arm.chain) else lateral
        planar = np.array([r3.a, -r4.d * np.sin(r3.alpha)])
        P[_core.SD_ELL3] = np.linalg.norm(planar)
        P[_core.SD_BETA] = np.arctan2(planar[1], planar[0])
        P[_core.SD_THETA3] = r3.theta
        if np.cos(r2.alpha) < 0.0:
            raise ModelError(
                f"arm '{arm.name}': alpha_2 = 180 deg ({joint_name(arm, 2)} turning against "
                f"{joint_name(arm, 1)}) is not supported"
            )
        return _core.RRR_SPHERICAL_WRIST, "RRR + spherical wrist (parallel joints 2, 3)", P
    if r3.kind is JointKind.PRISMATIC and off_right_angle(r2.alpha) <= RIGHT_ANGLE_EPS:
        if r3.a != 0.0 or r4.d != 0.0:
            raise ModelError(
                f"arm '{arm.name}': the RRP family needs a3 = 0 and d4 = 0 (the axis of "
                f"{joint_name(arm, 3)} through that of {joint_name(arm, 2)})"
            )
        P[_core.SD_LATERAL] = r2.d
        P[_core.SD_SIGMA2] = np.sign(np.sin(r2.alpha))
        P[_core.SD_D3] = r3.d
        return _core.RRP_SPHERICAL_WRIST, "RRP + spherical wrist", P
    raise ModelError(
        f"arm '{arm.name}': {joints_named(arm, (0, 1, 2))} match no closed-form family (RRR with "
        "joints 2 and 3 parallel, or RRP); Theorem 2 C2 cannot be used here"
    )


def wrist_offset(
    arm: Arm,
    model_chain: KinematicChain,
    offsets: tuple[float, ...],
    params: np.ndarray,
    R_fl: np.ndarray,
    axis4: np.ndarray,
) -> None:
    r"""The dp circle of a 6-DOF wrist with :math:`a_4 \ne 0`, into ``params`` (``SD_WRIST_OFFSET``).

    Seen from the flange, dp then turns with joints 5 and 6; in DH frame 0 it turns with q1
    alone. Joint 5's axis :math:`z_4` is normal to joint 4's, :math:`z_3`, and to joint 6's,
    :math:`z_5`: :math:`z_3 \times z_5 = -\sigma_4 \sigma_5 \sin\varphi_5\, z_4`. The offsets
    lie along :math:`x_4 = \sigma_4\, z_3 \times z_4` (:math:`a_4`), :math:`z_4` (:math:`d_5`)
    and :math:`x_5 = \sigma_5\, z_4 \times z_5` (:math:`a_5`), so for equal joints

    .. math::

        \Delta p = -(a_4 x_4 + d_5 z_4 + a_5 x_5), \quad
        z_4 = -\sigma_4 \sigma_5\,\mathrm{WRIST}\,\frac{z_3 \times z_5}{|z_3 \times z_5|}.

    At a solution :math:`z_5 = R_d\,a_6` (:math:`a_6` joint 6's axis in the flange frame) is the
    target's, and where joints 2, 3 and 4 are parallel :math:`z_3 = C_0 + C_1 \cos q_1 + C_2
    \sin q_1`: the solutions of system (9) in a configuration lie on the circle
    :math:`p_m = p_d + \Delta p(w)`, :math:`w = q_1` (``csrc/ik/wrist_offset.c``), undefined only
    at the singular wrist :math:`\sin\varphi_5 = 0`.

    Raises:
        ModelError: The formula does not give the arm's dp (checked at random joint vectors).
    """
    jr = arm.chain.joint_rows
    table = model_chain.table
    axis6 = R_fl.T @ pose(table[: jr[5]], np.zeros(5))[0][:, 2]  # R_fl: the flange's rotation at q = 0
    params[_core.SD_WRIST_OFFSET : _core.SD_WRIST_OFFSET + 3] = offsets
    params[_core.SD_AXIS4 : _core.SD_AXIS4 + 9] = axis4.ravel()
    params[_core.SD_AXIS6 : _core.SD_AXIS6 + 3] = axis6
    a4, d5, a5 = offsets
    s4, s5 = params[_core.SD_SIGMA4], params[_core.SD_SIGMA5]
    rng = np.random.default_rng(2)
    for _ in range(16):
        q = rng.uniform(-np.pi, np.pi, 6)
        R, p_model = pose(table, q)
        z3 = axis4.T @ [1.0, np.cos(q[0]), np.sin(q[0])]
        z5 = R @ axis6
        n = np.cross(z3, z5)
        z4 = -s4 * s5 * np.sign(np.sin(q[4] + params[_core.SD_THETA5])) * n / np.linalg.norm(n)
        dp = -(a4 * s4 * np.cross(z3, z4) + d5 * z4 + a5 * s5 * np.cross(z4, z5))
        if np.abs(dp - (p_model - pose(arm.chain.table, q)[1])).max() > 1e-12:
            raise ModelError(
                f"arm '{arm.name}': the wrist offsets' dp does not turn with {joint_name(arm, 0)} alone"
            )
