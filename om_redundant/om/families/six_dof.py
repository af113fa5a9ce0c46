r"""6-DOF model arms with a spherical wrist: joints 1-3 place the wrist centre, 4-6 orient.

Two position families share one shoulder and one wrist:

* ``RRR_SPHERICAL_WRIST``: joint 1 perpendicular to joint 2, joints 2 and 3 parallel
  (UR, PUMA and most industrial arms).
* ``RRP_SPHERICAL_WRIST``: revolute 1 and 2 with perpendicular axes, prismatic 3
  (the OM paper's Spherical manipulator).

Shoulder. With :math:`\sigma_1 = \sin\alpha_1 = \pm 1`, the wrist centre is
:math:`p_w = R_z(\varphi_1)\,(\rho,\ -\sigma_1 h,\ \cdot) + (0, 0, d_1)`, where
:math:`\varphi_1 = q_1 + \theta_1`, :math:`h` is the lateral offset (sum of the d's along the
parallel axes) and :math:`\rho = a_1 + u` the reach in the arm plane. So
:math:`\rho = \mathrm{ARM}\sqrt{p_x^2 + p_y^2 - h^2}` and
:math:`\varphi_1 = \mathrm{atan2}(p_y, p_x) - \mathrm{atan2}(-\sigma_1 h, \rho)`.

Arm plane. :math:`(u, v) = (\rho - a_1,\ \sigma_1 (p_z - d_1))` is reached by a planar pair:

* RRR: links :math:`a_2` and :math:`\ell_3 = |(a_3, -d_4 \sin\alpha_3)|` (angle :math:`\beta`);
  the elbow angle :math:`\gamma = \varphi_3 + \beta` satisfies
  :math:`\cos\gamma = (D - a_2^2 - \ell_3^2) / (2 a_2 \ell_3)` with :math:`D = u^2 + v^2`;
  :math:`\mathrm{ELBOW} = \mathrm{sign}(\sin\gamma)`.
* RRP: :math:`(u, v) = R(\varphi_2)(a_2, t)`, :math:`t = -\sigma_2 (q_3 + d_3)`,
  :math:`t = -\mathrm{ELBOW}\sqrt{D - a_2^2}` (the sign convention of the paper's Appendix III).

Wrist. With :math:`M = R_{in}^T R_{flange} E^T = R_z(\varphi_4) R_x(\alpha_4) R_z(\varphi_5)
R_x(\alpha_5) R_z(\varphi_6)` and :math:`\sigma_{4,5} = \sin\alpha_{4,5} = \pm 1`:
:math:`M e_z = (\sigma_5 S_5 C_4,\ \sigma_5 S_5 S_4,\ -\sigma_4\sigma_5 C_5)`, so with
:math:`\mathrm{WRIST} = \mathrm{sign}(\sin\varphi_5)`,
:math:`\varphi_4` and :math:`\varphi_5` are atan2s of entries of M, and :math:`\varphi_6` is the angle of the
residual :math:`(R_z(\varphi_4) R_x(\alpha_4) R_z(\varphi_5) R_x(\alpha_5))^T M`.
At :math:`\sin\varphi_5 = 0` (rule 3 of the paper) :math:`q_4` keeps its previous value;
likewise :math:`q_1` (rule 1) when the wrist centre is on the axis of joint 1. Every angle
comes from atan2, never acos, so that precision holds near singular joints.

The parameter vector layout is given by the index constants below.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ...kinematics.kernels import apply_row
from .common import REACH_SLACK, euler_zxzxz, wrap

RRR_SPHERICAL_WRIST = 0
RRP_SPHERICAL_WRIST = 1

# Parameter vector layout.
A1, D1, SIGMA1, THETA1, LATERAL, A2, THETA2 = 0, 1, 2, 3, 4, 5, 6
ELL3, BETA, THETA3 = 7, 8, 9  # RRR
SIGMA2, D3 = 7, 8  # RRP
SIGMA4, SIGMA5, THETA4, THETA5, THETA6 = 10, 11, 12, 13, 14
WRIST_CENTRE = 15  # 3 entries: wrist centre in the flange frame
E_ROT = 18  # 9 entries, row-major: rotation from the frame after Rz(phi6) to the flange
WRIST_ROW = 27  # index in the table of joint 4's row
N_PARAMS = 28


@nb.njit(cache=True)
def model_ik(family, P, table, R, p, signs, q_prev, q):
    """Solve the model arm for the flange pose (R, p) in DH frame 0; write q.

    Returns:
        The reach margin: the smallest normalised argument of the square roots taken.
        Negative (beyond a tiny slack) means the pose is outside the model's reach and q
        is not written; it measures how far, which lets a search find small islands of reach.
    """
    c = P[WRIST_CENTRE : WRIST_CENTRE + 3]
    pw = R @ c
    for k in range(3):  # p may be an array or a tuple
        pw[k] += p[k]
    # Shoulder.
    h = P[LATERAL]
    r2 = pw[0] * pw[0] + pw[1] * pw[1]
    k = r2 - h * h
    margin = k / max(r2, 1.0)
    if margin < -REACH_SLACK:
        return margin
    rho = signs[0] * np.sqrt(max(k, 0.0))
    if r2 < 1e-24:  # rule 1: wrist centre on joint 1's axis
        phi1 = q_prev[0] + P[THETA1]
    else:
        phi1 = np.arctan2(pw[1], pw[0]) - np.arctan2(-P[SIGMA1] * h, rho)
    q[0] = wrap(phi1 - P[THETA1])
    u = np.cos(phi1) * pw[0] + np.sin(phi1) * pw[1] - P[A1]
    v = P[SIGMA1] * (pw[2] - P[D1])
    D = u * u + v * v
    a2 = P[A2]
    if family == RRR_SPHERICAL_WRIST:
        l3 = P[ELL3]
        k = ((abs(a2) + l3) ** 2 - D) * (D - (abs(a2) - l3) ** 2)
        margin = min(margin, k / max(D * D, 1.0))
        if margin < -REACH_SLACK:
            return margin
        gamma = np.arctan2(signs[1] * np.sqrt(max(k, 0.0)), np.sign(a2) * (D - a2 * a2 - l3 * l3))
        if D < 1e-24:  # rule 2: wrist centre on joint 2's axis
            phi2 = q_prev[1] + P[THETA2]
        else:
            phi2 = np.arctan2(v, u) - np.arctan2(l3 * np.sin(gamma), a2 + l3 * np.cos(gamma))
        q[1] = wrap(phi2 - P[THETA2])
        q[2] = wrap(gamma - P[BETA] - P[THETA3])
    else:
        k = D - a2 * a2
        margin = min(margin, k / max(D, 1.0))
        if margin < -REACH_SLACK:
            return margin
        t = -signs[1] * np.sqrt(max(k, 0.0))
        if D < 1e-24:
            phi2 = q_prev[1] + P[THETA2]
        else:
            phi2 = np.arctan2(v, u) - np.arctan2(t, a2)
        q[1] = wrap(phi2 - P[THETA2])
        q[2] = -P[SIGMA2] * t - P[D3]
    # Wrist: M = R_in^T R E^T.
    Rin = np.eye(3)
    pin = np.zeros(3)
    j = 0
    for row in range(int(P[WRIST_ROW])):
        if table[row, 5] == 2.0:
            apply_row(Rin, pin, table[row], 0.0)
        else:
            apply_row(Rin, pin, table[row], q[j])
            j += 1
    E = P[E_ROT : E_ROT + 9].reshape(3, 3)
    M = Rin.T @ R @ E.T
    rows = ((M[0, 0], M[0, 1], M[0, 2]), (M[1, 0], M[1, 1], M[1, 2]), (M[2, 0], M[2, 1], M[2, 2]))
    phi = euler_zxzxz(rows, P[SIGMA4], P[SIGMA5], 0.0, signs[2], q_prev[3] + P[THETA4])
    for k in range(3):
        q[3 + k] = wrap(phi[k] - P[THETA4 + k])
    return margin


@nb.njit(cache=True)
def branch_values(family, P, q, out):
    """Write the quantities whose signs are (ARM, ELBOW, WRIST) at joint vector q."""
    phi2 = q[1] + P[THETA2]
    if family == RRR_SPHERICAL_WRIST:
        gamma = q[2] + P[THETA3] + P[BETA]
        u = P[A2] * np.cos(phi2) + P[ELL3] * np.cos(phi2 + gamma)
        out[1] = np.sin(gamma)
    else:
        t = -P[SIGMA2] * (q[2] + P[D3])
        u = P[A2] * np.cos(phi2) - t * np.sin(phi2)
        out[1] = -t
    out[0] = P[A1] + u
    out[2] = np.sin(q[4] + P[THETA5])
