r"""Offset modification: the model arm of a real arm, and the position difference dp.

The model keeps every rotation of the real arm (twists and joint offsets theta) and zeroes
the few lengths that stand in the way of a closed form:

* 6-DOF arms satisfying the paper's Theorem 2 (joints 1-3 position joint 4's origin; joints
  4-6 revolute, non-parallel, not intersecting): :math:`a_4, a_5, d_5` (standard DH,
  joint-indexed rows), which makes the wrist spherical.
* 7-DOF arms: :math:`a_1, d_2` (shoulder offsets, Gen3 and Sawyer) and
  :math:`a_5, a_6, d_6` (wrist offsets), which make the shoulder and the wrist spherical
  while the elbow keeps its offsets (a Hollerbach arm, see :mod:`om_redundant.om.families.srs`).

For equal joints the hand orientations agree and the positions differ by

.. math::

    \Delta p(q) = p_{model}(q) - p_{real}(q) = R_{flange}(q)\,\delta(q_J) + a(q_1),

where :math:`\delta`, the wrist offsets' dp seen from the flange, depends on one wrist joint
J: joint 6 of UR5e and the Spherical arm (:math:`a_4 = 0`), joint 7 of the 7-DOF arms (the
iiwa14 has :math:`\delta = 0`). A 6-DOF wrist with :math:`a_4 \ne 0` (Menagerie's ARX L5,
Unitree Z1, i2rt YAM) makes :math:`\delta` depend on joints 5 and 6; where joint 4's axis
turns with q1 alone (joints 2, 3 and 4 parallel), dp at a solution is a function of q1 and
the target's orientation instead (:func:`_wrist_offset`): the solutions again lie on a
circle, in :math:`w = q_1`. The shoulder offsets' dp :math:`a(q_1)`, in DH frame 0,
turns with joint 1 alone, because :math:`a_1` lies along :math:`x_1` and :math:`d_2` along
joint 2's axis, both fixed in frame 1; it is zero when joints 1-3 meet. The solutions of
the OM system (9) then lie on a circle (a torus with shoulder offsets) in the ball
:math:`|p_m - p_d| \le \Delta p_{max}`, which the solver searches exhaustively.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from .. import _core
from ..exceptions import ModelError
from ..kinematics.arm import Arm
from ..kinematics.chain import DHRow, JointKind, KinematicChain
from ..validation import as_instance

_ANGLE_EPS = 1e-9
#: Largest deviation (rad) of a twist from +-90 deg (or from 0 between parallel joints) that
#: the closed forms, which take it to be exact, absorb: the hand then moves by well under the
#: solver's 1e-10 m per metre of reach.
_RIGHT_ANGLE_EPS = 1e-11
#: A DH length within this many metres per metre of the arm's reach of zero, or an angle within
#: ``ANGLE_ROUNDING`` rad of a multiple of 90 deg, is the rounding of the value it is near, not
#: geometry (a URDF written to 11 digits leaves offsets of 5e-13 m where the arm has none): it
#: never changes the method an arm gets. :func:`derive_model` refuses an arm with a nonzero
#: length within it, so that the arm is solved through its nominal arm
#: (:func:`~om_redundant.om.nominal.nominal_arm`), which has it zero, while its exact table
#: verifies every answer.
LENGTH_ROUNDING = 1e-9
#: An angle (rad) within this of a multiple of 90 deg is the rounding of that multiple (see
#: :data:`LENGTH_ROUNDING`).
ANGLE_ROUNDING = 1e-9


@dataclass(frozen=True, eq=False)
class ModelArm:
    """The closed-form model of a real arm.

    Attributes:
        real: The real arm.
        model: The offset-modified arm (same joints, names, limits, base and tool).
        family: Closed-form family code (see :mod:`om_redundant.om.families`).
        family_name: Human-readable family name.
        params: Parameter vector of the family kernel.
        sign_names: Names of the configuration's branch signs.
        redundancy_names: Names of the configuration's redundancy values (``("psi",)`` for a
            7-DOF arm, empty for 6-DOF).
        dp_joint: Index of the joint that :math:`\\delta` depends on, or -1 for none; 0 (q1)
            for a wrist with :math:`a_4 \\ne 0`, whose dp turns with q1 (``SD_WRIST_OFFSET``
            in ``params``; ``delta`` and ``shoulder`` are then zero).
        delta: (3, 3) coefficients of dp seen from the flange, rows :math:`D_0, D_1, D_2`:
            :math:`\\delta(q_J) = D_0 + D_1 \\cos q_J + D_2 \\sin q_J` (a revolute joint's
            angle enters the flange frame through one rotation about z).
        shoulder: (3, 3) coefficients of the shoulder offsets' dp in DH frame 0, rows
            :math:`A_0, A_1, A_2`: :math:`a(q_1) = A_0 + A_1 \\cos q_1 + A_2 \\sin q_1`; zero
            when joints 1-3 meet (every 6-DOF arm here, the Panda, FR3, iiwa14, xArm7).
        dp_max: A bound on :math:`|\\Delta p(q)|` in metres.
    """

    real: Arm
    model: Arm
    family: int
    family_name: str
    params: np.ndarray
    sign_names: tuple[str, ...]
    redundancy_names: tuple[str, ...]
    dp_joint: int
    delta: np.ndarray
    shoulder: np.ndarray
    dp_max: float

    def dp(self, q: np.ndarray) -> np.ndarray:
        """Position difference model minus real, in the root frame: (3,) or (M, 3)."""
        return self.model.fk(q)[..., :3, 3] - self.real.fk(q)[..., :3, 3]


def derive_model(arm: Arm) -> ModelArm:
    """Derive the closed-form model arm of a real arm.

    6-DOF arms get a spherical-wrist model (Theorem 2); 7-DOF arms a Hollerbach model with a
    spherical shoulder and wrist (:mod:`om_redundant.om.families.srs`), keeping the elbow's
    offsets.

    Raises:
        ModelError: The arm matches no family, or dp depends on more than one joint, or a DH
            length is within rounding of zero (:data:`LENGTH_ROUNDING`; its nominal arm has it
            zero); the message names the condition and the arm's joints.
        InvalidInput: arm is not an :class:`~om_redundant.Arm`.
    """
    as_instance(arm, Arm, "arm")
    _refuse_rounding(arm)
    if arm.dof == 6:
        model_chain, family, family_name, params = _six_dof_model(arm)
        shoulderless = arm.chain
        sign_names, redundancy_names = ("ARM", "ELBOW", "WRIST"), ()
    elif arm.dof == 7:
        model_chain, shoulderless, params = _srs_model(arm)
        family, family_name = _core.SRS, "S-R-S: spherical shoulder, elbow, spherical wrist"
        sign_names, redundancy_names = ("SHOULDER", "ELBOW", "WRIST"), ("psi",)
    else:
        above = (
            f"; if the arm starts after {_joint_name(arm, arm.dof - 8)} (joints of a torso or a mobile base "
            "before it), import it from the body that joint moves as the root (import-arm --root BODY)"
            if arm.dof > 7
            else ""
        )
        raise ModelError(f"arm '{arm.name}' has {arm.dof} joints; models exist for 6- and 7-DOF arms{above}")
    model = arm.with_chain(model_chain, f"{arm.name}-model")
    if arm.dof == 6 and params[_core.SD_WRIST_OFFSET] != 0.0:  # dp turns with q1: see _wrist_offset
        a4, d5, a5 = params[_core.SD_WRIST_OFFSET : _core.SD_WRIST_OFFSET + 3]
        dp_joint, delta, shoulder = 0, np.zeros((3, 3)), np.zeros((3, 3))
        dp_max = float(np.hypot(a4, d5) + abs(a5))
    else:
        dp_joint = _dp_joint(arm, shoulderless, model_chain)
        delta = _circle_fit(
            arm, "dp seen from the flange", dp_joint, lambda q: _delta(shoulderless, model_chain, q)
        )
        shoulder = _circle_fit(
            arm,
            "the shoulder offsets' dp",
            0,
            lambda q: _pose(shoulderless.table, q)[1] - _pose(arm.chain.table, q)[1],
        )
        w = np.linspace(-np.pi, np.pi, 3601)
        cs = np.stack([np.ones_like(w), np.cos(w), np.sin(w)], axis=1)
        dp_max = float(np.linalg.norm(cs @ delta, axis=1).max() + np.linalg.norm(cs @ shoulder, axis=1).max())
    return ModelArm(
        arm,
        model,
        family,
        family_name,
        params,
        sign_names,
        redundancy_names,
        dp_joint,
        delta,
        shoulder,
        dp_max,
    )


def reach(chain: KinematicChain) -> float:
    """The chain's reach (m), the sum of its rows' :math:`|(a, d)|`: the scale of its lengths."""
    return sum(math.hypot(row.a, row.d) for row in chain.rows)


def rounding_length(chain: KinematicChain) -> float:
    """The largest DH length (m) that is rounding of zero in this chain: :data:`LENGTH_ROUNDING`
    times its reach."""
    return LENGTH_ROUNDING * reach(chain)


def _refuse_rounding(arm: Arm) -> None:
    """Raise :class:`ModelError` at the first nonzero DH length within rounding of zero: the
    closed forms would take it for geometry (an offset that changes the family or the search)
    or drop it (an answer off by it); the nominal arm has it zero."""
    eps = rounding_length(arm.chain)
    for i, row in enumerate(arm.chain.rows):
        for key, value in (("a", row.a), ("d", row.d)):
            if 0.0 < abs(value) <= eps:
                raise ModelError(
                    f"arm '{arm.name}': {key} = {value:.3g} m in {_row_name(arm, i)} is rounding of 0 "
                    f"(within {LENGTH_ROUNDING:g} m per metre of reach, {eps:.2g} m), not geometry"
                )


def _joint_name(arm: Arm, j: int) -> str:
    """Joint j (0-based) as messages name it: its number on the arm and the model's name."""
    return f"joint {j + 1} ('{arm.prefix}{arm.joint_names[j]}')"


def _joints_named(arm: Arm, joints: Iterable[int]) -> str:
    return ", ".join(_joint_name(arm, j) for j in joints)


def _row_name(arm: Arm, i: int) -> str:
    """DH row i as messages name it: the row of a joint, or a fixed row after one."""
    jr = arm.chain.joint_rows
    if i in jr:
        return f"the row of {_joint_name(arm, jr.index(i))}"
    before = [k for k, r in enumerate(jr) if r < i]
    return f"a fixed row after {_joint_name(arm, before[-1])}" if before else "a fixed row before joint 1"


def _six_dof_model(arm: Arm) -> tuple[KinematicChain, int, str, np.ndarray]:
    """Theorem 2: zero a4, a5, d5 for a spherical wrist."""
    rows = list(arm.chain.rows)
    jr = arm.chain.joint_rows
    for j in (3, 4, 5):
        if rows[jr[j]].kind is not JointKind.REVOLUTE:
            raise ModelError(f"arm '{arm.name}': Theorem 2 C3 needs {_joint_name(arm, j)} revolute")
    _refuse_fixed_rows(arm, (3, 4, 5))
    for j in (3, 4):
        _check_right_angle(arm, rows[jr[j]], j)
    offsets = (rows[jr[3]].a, rows[jr[4]].d, rows[jr[4]].a)  # a4, d5, a5 of the real arm
    rows[jr[3]] = dataclasses.replace(rows[jr[3]], a=0.0)
    rows[jr[4]] = dataclasses.replace(rows[jr[4]], a=0.0, d=0.0)
    model_chain = arm.chain.replace_rows(rows)
    family, family_name, params = _position_family(arm, rows)
    params[_core.SD_WRIST_ROW] = jr[3]
    for key, j in ((_core.SD_SIGMA4, 3), (_core.SD_SIGMA5, 4)):
        params[key] = np.sign(np.sin(rows[jr[j]].alpha))
    for key, j in ((_core.SD_THETA4, 3), (_core.SD_THETA5, 4), (_core.SD_THETA6, 5)):
        params[key] = rows[jr[j]].theta
    params[_core.SD_E_ROT : _core.SD_E_ROT + 9] = _tail_rotation(rows, jr[5]).ravel()
    # Wrist centre in the flange frame: origin of joint 5's frame, the same for any q.
    q0 = np.zeros(6)
    _, o4 = _pose(model_chain.table[: jr[3] + 1], q0[:4])
    R_fl, p_fl = _pose(model_chain.table, q0)
    params[_core.SD_WRIST_CENTRE : _core.SD_WRIST_CENTRE + 3] = R_fl.T @ (o4 - p_fl)
    if offsets[0] != 0.0:
        _wrist_offset(arm, model_chain, offsets, params, R_fl)
        family_name += ", wrist offset a4 (dp turns with q1)"
    return model_chain, family, family_name, params


def _wrist_offset(
    arm: Arm, model_chain: KinematicChain, offsets: tuple[float, ...], params: np.ndarray, R_fl: np.ndarray
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
    :math:`p_m = p_d + \Delta p(w)`, :math:`w = q_1` (``csrc/wrist_offset.c``), undefined only
    at the singular wrist :math:`\sin\varphi_5 = 0`.

    Raises:
        ModelError: Joint 4 is not parallel to joint 2 (dp would turn with two joints), or
            the formula does not give the arm's dp (checked at random joint vectors).
    """
    jr = arm.chain.joint_rows
    table = model_chain.table
    try:
        axis4 = _circle_fit(arm, "joint 4's axis", 0, lambda q: _pose(table[: jr[3]], q[:3])[0][:, 2])
    except ModelError:
        raise ModelError(
            f"arm '{arm.name}': a4 = {offsets[0]:g} != 0 (the wrist offset from the axis of "
            f"{_joint_name(arm, 3)} to that of {_joint_name(arm, 4)}) makes dp depend on "
            f"{_joints_named(arm, (4, 5))}; the bounded search handles a4 != 0 where joint 4's axis turns "
            f"with {_joint_name(arm, 0)} alone (parallel to joint 2's, as when joints 2, 3 and 4 are "
            "parallel): dp then turns with joint 1"
        ) from None
    axis6 = R_fl.T @ _pose(table[: jr[5]], np.zeros(5))[0][:, 2]  # R_fl: the flange's rotation at q = 0
    params[_core.SD_WRIST_OFFSET : _core.SD_WRIST_OFFSET + 3] = offsets
    params[_core.SD_AXIS4 : _core.SD_AXIS4 + 9] = axis4.ravel()
    params[_core.SD_AXIS6 : _core.SD_AXIS6 + 3] = axis6
    a4, d5, a5 = offsets
    s4, s5 = params[_core.SD_SIGMA4], params[_core.SD_SIGMA5]
    rng = np.random.default_rng(2)
    for _ in range(16):
        q = rng.uniform(-np.pi, np.pi, 6)
        R, p_model = _pose(table, q)
        z3 = axis4.T @ [1.0, np.cos(q[0]), np.sin(q[0])]
        z5 = R @ axis6
        n = np.cross(z3, z5)
        z4 = -s4 * s5 * np.sign(np.sin(q[4] + params[_core.SD_THETA5])) * n / np.linalg.norm(n)
        dp = -(a4 * s4 * np.cross(z3, z4) + d5 * z4 + a5 * s5 * np.cross(z4, z5))
        if np.abs(dp - (p_model - _pose(arm.chain.table, q)[1])).max() > 1e-12:
            raise ModelError(
                f"arm '{arm.name}': the wrist offsets' dp does not turn with {_joint_name(arm, 0)} alone"
            )


def _srs_model(arm: Arm) -> tuple[KinematicChain, KinematicChain, np.ndarray]:
    r"""Zero the offsets that keep joints 1-3 (a1, a2, d2) or joints 5-7 (a5, a6, d6) from meeting.

    In standard DH, joint i+1 turns about :math:`z_i` through :math:`o_i`. Axes 1 and 2 meet
    (at S = :math:`o_1`) iff :math:`a_1 = 0`; axis 3 passes through S iff :math:`d_2 = a_2 = 0`;
    likewise :math:`a_5 = 0` and :math:`d_6 = a_6 = 0` put axes 5-7 through W = :math:`o_5`.
    The elbow's offsets (:math:`a_3, d_4, a_4`) are kept. :math:`a_2` would make dp depend on
    q2 as well and is refused here; the arm's nominal arm zeroes it
    (:mod:`~om_redundant.om.nominal`), whose correction solves it.

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
            f"{_joint_name(arm, 1)} to that of {_joint_name(arm, 2)}, which then miss the shoulder's "
            f"centre) makes dp depend on {_joint_name(arm, 1)}; the model's bounded searches take offsets "
            f"that turn with {_joint_name(arm, 0)} or {_joint_name(arm, 6)} only (OMSolver solves the "
            "arm through its nominal arm, which zeroes a2: om.nominal_arm)"
        )
    _refuse_fixed_rows(arm, (0, 1, 2, 3, 4, 5))
    if any(rows[r].a != 0.0 for r in range(jr[5] + 1, jr[6])):
        raise ModelError(
            f"arm '{arm.name}': fixed rows between {_joint_name(arm, 5)} and {_joint_name(arm, 6)} need a = 0"
        )
    for j in (0, 1, 4, 5):
        _check_right_angle(arm, rows[jr[j]], j)
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
        return _pose(table[: jr[0] + k], q[:k])  # frame k, after joint k's row

    _check_concurrent(arm, chain, "shoulder", (0, 1, 2))
    _check_concurrent(arm, chain, "wrist", (4, 5, 6))
    q0 = np.zeros(7)
    (_, S), (R3, o3), (_, W) = (frame(k, q0) for k in (1, 3, 5))
    R_fl, p_fl = _pose(table, q0)
    s3 = R3.T @ (S - o3)
    u = _rotz(-rows[jr[3]].theta) @ R3.T @ (W - o3)
    k0 = u @ u + s3 @ s3 - 2.0 * s3[2] * u[2]
    k1 = -2.0 * (s3[0] * u[0] + s3[1] * u[1])
    k2 = -2.0 * (s3[1] * u[0] - s3[0] * u[1])
    if np.hypot(k1, k2) < 1e-9:
        raise ModelError(
            f"arm '{arm.name}': {_joint_name(arm, 3)} does not change the shoulder-wrist distance"
        )
    P = np.zeros(_core.SRS_N_PARAMS)
    P[_core.SRS_SIGMA1], P[_core.SRS_SIGMA2], P[_core.SRS_SIGMA5] = (
        np.sign(np.sin(rows[jr[j]].alpha)) for j in (0, 1, 4)
    )
    P[_core.SRS_THETA : _core.SRS_THETA + 7] = [rows[r].theta for r in jr]
    # The wrist's middle rotation Rx(alpha_6) F = Rz(a) Rx(beta) Rz(b), F the fixed rows'.
    middle = _rotx(rows[jr[5]].alpha) @ _pose(table[jr[5] + 1 : jr[6]], q0[:0])[0]
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
    P[_core.SRS_R_PRE : _core.SRS_R_PRE + 9] = _pose(table[: jr[0]], q0[:0])[0].ravel()
    P[_core.SRS_X3 : _core.SRS_X3 + 9] = _rotx(rows[jr[2]].alpha).ravel()
    P[_core.SRS_X4 : _core.SRS_X4 + 9] = _rotx(rows[jr[3]].alpha).ravel()
    P[_core.SRS_E_ROT : _core.SRS_E_ROT + 9] = _tail_rotation(rows, jr[6]).ravel()
    R_base = chain.T_root_base[:3, :3]
    # sigma: with the elbow bent (phi4 = phi* + pi/2, ELBOW = +1), b3 points to the elbow -s3.
    v = _rotz(P[_core.SRS_PHI_STAR] + np.pi / 2) @ u - s3
    P[_core.SRS_BEND] = np.sign(np.cross([0.0, 0.0, 1.0], v) @ -s3)
    P[_core.SRS_UP : _core.SRS_UP + 3] = R_base.T @ np.array([0.0, 0.0, 1.0])
    P[_core.SRS_REF : _core.SRS_REF + 3] = R_base.T @ np.array([-1.0, 0.0, 0.0])
    return chain, shoulderless, P


def _check_right_angle(arm: Arm, row: DHRow, j: int) -> None:
    if abs(np.sin(row.alpha)) < _ANGLE_EPS:
        raise ModelError(
            f"arm '{arm.name}': {_joint_name(arm, j)} and {_joint_name(arm, j + 1)} are parallel; the "
            "spherical joint triple needs them non-parallel (Theorem 2 C3)"
        )
    if _off_right_angle(row.alpha) > _RIGHT_ANGLE_EPS:
        raise ModelError(
            f"arm '{arm.name}': the closed form needs {_joint_name(arm, j)} and {_joint_name(arm, j + 1)} "
            "perpendicular "
            f"(alpha_{j + 1} = +-90 deg), got {np.degrees(row.alpha):.10g} deg "
            f"({_off_right_angle(row.alpha):.2g} rad off)"
        )


def _refuse_fixed_rows(arm: Arm, joints: tuple[int, ...]) -> None:
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
        twist = _pose(KinematicChain((rows[jr[k]], *between)).table, np.zeros(1))[0][2, 2]
        angle = float(np.arccos(np.clip(twist, -1.0, 1.0)))
        nominal = np.pi / 2 * round(angle / (np.pi / 2))
        off = f", {abs(angle - nominal):.2g} rad from {np.degrees(nominal):g} deg" if angle != nominal else ""
        found.append(
            f"after {_joint_name(arm, k)} ({', '.join(values) or 'identity'}; axes {k + 1} and {k + 2} "
            f"{np.degrees(angle):.10g} deg apart{off})"
        )
    if found:
        raise ModelError(
            f"arm '{arm.name}': the closed form needs the rows of {_joints_named(arm, joints)} to follow "
            f"one another; fixed rows {'; '.join(found)}"
        )


def _off_right_angle(alpha: float) -> float:
    """How far (rad) the twist alpha is from +-90 deg."""
    return float(np.arctan2(abs(np.cos(alpha)), abs(np.sin(alpha))))


def _check_concurrent(arm: Arm, chain: KinematicChain, what: str, joints: tuple[int, ...]) -> None:
    """Check that the axes of three consecutive joints pass through one point for any q.

    The point is the origin of the first joint's DH frame; joint j turns about the z-axis of
    the frame that ends the row before it.
    """
    jr = chain.joint_rows
    rng = np.random.default_rng(0)
    for _ in range(4):
        q = rng.uniform(-np.pi, np.pi, chain.dof)
        point = _pose(chain.table[: jr[joints[0]] + 1], q[: joints[0] + 1])[1]
        for j in joints:
            R, p = _pose(chain.table[: jr[j]], q[:j])
            if np.linalg.norm(np.cross(point - p, R[:, 2])) > 1e-9:
                raise ModelError(
                    f"arm '{arm.name}': the model's {what} axes ({_joints_named(arm, joints)}) do not meet "
                    "in one point"
                )


def _rotx(alpha: float) -> np.ndarray:
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rotz(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _tail_rotation(rows: list[DHRow], last: int) -> np.ndarray:
    """Rotation from the frame after the last joint's Rz(phi) to the flange."""
    tail = [DHRow(alpha=rows[last].alpha, kind=JointKind.FIXED), *rows[last + 1 :]]
    return _pose(KinematicChain(tuple(tail)).table, np.zeros(0))[0]


def _position_family(arm: Arm, rows: list[DHRow]) -> tuple[int, str, np.ndarray]:
    jr = arm.chain.joint_rows
    r1, r2, r3, r4 = (rows[jr[j]] for j in range(4))
    P = np.zeros(_core.SD_N_PARAMS)
    if r1.kind is not JointKind.REVOLUTE or r2.kind is not JointKind.REVOLUTE:
        raise ModelError(
            f"arm '{arm.name}': {_joint_name(arm, 0)} and {_joint_name(arm, 1)} must be revolute for a "
            "closed-form model"
        )
    if jr[0] != 0:
        raise ModelError(
            f"arm '{arm.name}': the closed forms need the row of {_joint_name(arm, 0)} first (no fixed row "
            "before it)"
        )
    _refuse_fixed_rows(arm, (0, 1, 2))
    if _off_right_angle(r1.alpha) > _RIGHT_ANGLE_EPS:
        raise ModelError(
            f"arm '{arm.name}': {_joint_name(arm, 0)} must be perpendicular to {_joint_name(arm, 1)} "
            "(alpha_1 = +-90 deg), got "
            f"{np.degrees(r1.alpha):.10g} deg"
        )
    P[_core.SD_A1], P[_core.SD_D1], P[_core.SD_THETA1] = r1.a, r1.d, r1.theta
    P[_core.SD_SIGMA1] = np.sign(np.sin(r1.alpha))
    P[_core.SD_A2], P[_core.SD_THETA2] = r2.a, r2.theta
    between = rows[jr[2] + 1 : jr[3]]
    if any(r.a != 0.0 or r.d != 0.0 for r in between):
        raise ModelError(
            f"arm '{arm.name}': fixed rows between {_joint_name(arm, 2)} and {_joint_name(arm, 3)} must be "
            "pure rotations"
        )
    # Joints 2 and 3 parallel within what the closed form absorbs (a twist off by more goes
    # through the nominal arm, which snaps it).
    if r3.kind is JointKind.REVOLUTE and abs(np.sin(r2.alpha)) <= _RIGHT_ANGLE_EPS and not between:
        if r2.a == 0.0:  # a nonzero a2 within rounding of 0 was refused first (_refuse_rounding)
            raise ModelError(
                f"arm '{arm.name}': a2 = 0 leaves {_joint_name(arm, 1)} and {_joint_name(arm, 2)} "
                "without a link"
            )
        P[_core.SD_LATERAL] = np.cos(r2.alpha) * r2.d + r3.d + r4.d * np.cos(r3.alpha)
        planar = np.array([r3.a, -r4.d * np.sin(r3.alpha)])
        P[_core.SD_ELL3] = np.linalg.norm(planar)
        P[_core.SD_BETA] = np.arctan2(planar[1], planar[0])
        P[_core.SD_THETA3] = r3.theta
        if np.cos(r2.alpha) < 0.0:
            raise ModelError(
                f"arm '{arm.name}': alpha_2 = 180 deg ({_joint_name(arm, 2)} turning against "
                f"{_joint_name(arm, 1)}) is not supported"
            )
        return _core.RRR_SPHERICAL_WRIST, "RRR + spherical wrist (parallel joints 2, 3)", P
    if r3.kind is JointKind.PRISMATIC and _off_right_angle(r2.alpha) <= _RIGHT_ANGLE_EPS:
        if r3.a != 0.0 or r4.d != 0.0:
            raise ModelError(
                f"arm '{arm.name}': the RRP family needs a3 = 0 and d4 = 0 (the axis of "
                f"{_joint_name(arm, 3)} through that of {_joint_name(arm, 2)})"
            )
        P[_core.SD_LATERAL] = r2.d
        P[_core.SD_SIGMA2] = np.sign(np.sin(r2.alpha))
        P[_core.SD_D3] = r3.d
        return _core.RRP_SPHERICAL_WRIST, "RRP + spherical wrist", P
    raise ModelError(
        f"arm '{arm.name}': {_joints_named(arm, (0, 1, 2))} match no closed-form family (RRR with "
        "joints 2 and 3 parallel, or RRP); Theorem 2 C2 cannot be used here"
    )


def _pose(table: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    R, p = np.empty((3, 3)), np.empty(3)
    _core.flange(np.ascontiguousarray(table), np.ascontiguousarray(q, dtype=np.float64), R, p)
    return R, p


def _delta(real: KinematicChain, model: KinematicChain, q: np.ndarray) -> np.ndarray:
    R, p_real = _pose(real.table, q)
    _, p_model = _pose(model.table, q)
    return R.T @ (p_model - p_real)


def _dp_joint(arm: Arm, real: KinematicChain, model: KinematicChain) -> int:
    """The joint that delta (dp in the flange frame) depends on; -1 if it is constant."""
    rng = np.random.default_rng(0)
    dependent = set()
    for _ in range(8):
        q = rng.uniform(-np.pi, np.pi, real.dof)
        base = _delta(real, model, q)
        for j in range(real.dof):
            moved = q.copy()
            moved[j] += rng.uniform(0.3, 2.0)
            if np.abs(_delta(real, model, moved) - base).max() > 1e-12:
                dependent.add(j)
    if len(dependent) > 1:
        zeroed = [
            f"{key} = {getattr(row, key):g} m in {_row_name(arm, i)}"
            for i, (row, kept) in enumerate(zip(real.rows, model.rows, strict=True))
            for key in ("a", "d")
            if getattr(row, key) != getattr(kept, key)
        ]
        raise ModelError(
            f"arm '{arm.name}': dp seen from the flange (of the offsets the model zeroes: "
            f"{', '.join(zeroed)}) depends on {_joints_named(arm, sorted(dependent))}; the bounded search "
            "handles one"
        )
    return dependent.pop() if dependent else -1


def _circle_fit(arm: Arm, what: str, joint: int, f) -> np.ndarray:
    """Fit f(q) = C0 + C1 cos q_J + C2 sin q_J exactly from four angles of joint J (f constant
    for J = -1), and check it at random joint vectors."""
    rng = np.random.default_rng(1)
    q = rng.uniform(-np.pi, np.pi, arm.dof)

    def at(w: float) -> np.ndarray:
        if joint >= 0:
            q[joint] = w
        return f(q)

    d0, d1, d2, d3 = (at(w) for w in (0.0, np.pi / 2, np.pi, -np.pi / 2))
    C = np.array([(d0 + d2) / 2, (d0 - d2) / 2, (d1 - d3) / 2])
    for _ in range(16):
        q = rng.uniform(-np.pi, np.pi, arm.dof)
        w = q[joint] if joint >= 0 else 0.0
        misfit = np.abs(C[0] + C[1] * np.cos(w) + C[2] * np.sin(w) - f(q)).max()
        if misfit > 1e-13:
            shape = "constant" if joint < 0 else f"affine in cos and sin of {_joint_name(arm, joint)}"
            raise ModelError(f"arm '{arm.name}': {what} is not {shape} (off by {misfit:.2g})")
    return C
