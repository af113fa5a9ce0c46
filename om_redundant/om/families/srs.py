r"""7-DOF model arms: spherical shoulder, one elbow joint, spherical wrist (Hollerbach arms).

Joints 1-3 intersect at the shoulder centre S (fixed in DH frame 0), joints 5-7 at the wrist
centre W (fixed in the flange frame), and joint 4 is the elbow. Offsets between S and W
(an offset elbow, as on the Panda and xArm7) are allowed; the pure S-R-S arm (iiwa) is the
special case without them.

Elbow. With :math:`R_{03}` the rotation of DH frame 3 and :math:`s_3` the shoulder centre
in frame 3, :math:`W - S = R_{03}\,v(\varphi_4)` with :math:`v = R_z(\varphi_4)\,u - s_3`
(:math:`u` constant), so

.. math::  |W - S|^2 = k_0 + k_1 \cos\varphi_4 + k_2 \sin\varphi_4
                     = k_0 + K \cos(\varphi_4 - \varphi^*),

and :math:`\varphi_4 = \varphi^* + \mathrm{atan2}(\mathrm{ELBOW}\sqrt{1 - x^2},\ x)`,
:math:`x = (|W - S|^2 - k_0)/K`. :math:`\varphi^*` is the model's straight elbow, so the
ELBOW sign is :math:`\mathrm{sign}\,\sin(\varphi_4 - \varphi^*)`, not the sign of :math:`q_4`.

Arm angle. The arm angle :math:`\psi` is the angle about the shoulder-wrist line of the
elbow's bend direction :math:`b = \mathrm{ELBOW}\,\sigma\,(z_4 \times \hat w)`, where
:math:`z_4` is joint 4's axis, :math:`\hat w = (W - S)/|W - S|` and the constant
:math:`\sigma = \pm 1` makes b point from the line to the elbow. (On the arms here S, the
elbow and W lie in a plane normal to :math:`z_4`, so b is the direction of the elbow point;
unlike the elbow point, b stays defined at the straight elbow.) It is measured from a
reference direction :math:`n(\hat w)` perpendicular to :math:`\hat w`:

.. math::  \psi = \mathrm{atan2}\big((\hat w \times n)\cdot b,\ n\cdot b\big),
           \qquad n(\hat w) = R(\hat z \to \hat w)\, r,

where :math:`R(\hat z \to \hat w) = I + [\hat z \times \hat w]_\times
+ [\hat z \times \hat w]_\times^2 / (1 + \hat z\cdot\hat w)` is the shortest rotation taking
the root frame's up axis :math:`\hat z` to :math:`\hat w`, and :math:`r = -\hat x` (root
frame). This is the stereographic shoulder-elbow-wrist angle of Elias and Wen (2023): it is
continuous everywhere except on the half-line :math:`\hat w = -\hat z`, the wrist straight
below the shoulder, inside the base. With the wrist in front of the shoulder (+x),
:math:`\psi = 0` puts the elbow above the shoulder-wrist line; :math:`\psi` turns the elbow
right-handedly about :math:`\hat w`.

Shoulder and wrist. Given :math:`\psi`, :math:`R_{03}` maps the frame-3 triad
:math:`(\hat v, \hat b_3, \hat v \times \hat b_3)`, :math:`b_3 = \mathrm{ELBOW}\,\sigma\,
(e_z \times v)` (the shoulder-wrist direction and the bend direction in frame 3) onto
:math:`(\hat w, m, \hat w \times m)`, :math:`m = \cos\psi\, n + \sin\psi\, (\hat w \times n)`.
Joints 1-3 and 5-7 then follow from :func:`~om_redundant.om.families.common.euler_zxzxz`
with the SHOULDER and WRIST signs
(:math:`\mathrm{sign}\sin\varphi_2`, :math:`\mathrm{sign}\sin\varphi_6`).

Angles :math:`\varphi_i = q_i + \theta_i` are DH joint angles with their offsets. Fixed
rows between joints 6 and 7 (the Sawyer's) fold into the wrist's middle rotation,
:math:`R_x(\alpha_6) F = R_z(a) R_x(\beta) R_z(b)`: a joins :math:`\theta_6`, b joins
:math:`\theta_7`, and :math:`\beta` is the twist between joints 6 and 7 (see
:func:`~om_redundant.om.families.common.euler_zxzxz`).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .common import (
    REACH_SLACK,
    add,
    col,
    cross,
    dot,
    euler_zxzxz,
    euler_zxzxz_given_first,
    mat,
    mm,
    mmt,
    mtm,
    mv,
    rz_times,
    scale,
    sub,
    transpose,
    unit,
    vec,
    wrap,
)

SRS = 2

# Parameter vector layout.
SIGMA1, SIGMA2, SIGMA5 = 0, 1, 2
SIN_BETA = 3  # sin(beta), the wrist's middle twist (joints 6 to 7); +-1 on most arms
THETA = 4  # 7 entries: theta_1..theta_7 (theta_6, theta_7 with a, b of the wrist twist)
SHOULDER = 11  # 3: S in DH frame 0
WRIST = 14  # 3: W in the flange frame
S3 = 17  # 3: S in DH frame 3
U = 20  # 3: v(phi4) = Rz(phi4) u - s3
K0, K, PHI_STAR = 23, 24, 25
R_PRE = 26  # 9 (row-major): DH frame 0 to the frame joint 1 turns
X3 = 35  # 9: Rx(alpha_3)
X4 = 44  # 9: Rx(alpha_4)
E_ROT = 53  # 9: from the frame after Rz(phi7) to the flange
UP = 62  # 3: the root frame's up axis, in DH frame 0
REF = 65  # 3: the reference direction r, in DH frame 0
BEND = 68  # sigma: the bend direction's sign
COS_BETA = 69  # cos(beta); 0 on most arms
N_PARAMS = 70

_DEGENERATE = 1e-12


@nb.njit(cache=True, inline="always")
def _rx(sigma):
    """Rx(alpha) with sin(alpha) = sigma = +-1."""
    return ((1.0, 0.0, 0.0), (0.0, 0.0, -sigma), (0.0, sigma, 0.0))


@nb.njit(cache=True)
def reference_direction(P, w_hat):
    """The arm angle's reference direction n(w_hat), and w_hat x n."""
    up, r = vec(P, UP), vec(P, REF)
    v = cross(up, w_hat)
    vr = cross(v, r)
    n = unit(add(add(r, vr), scale(1.0 / max(1.0 + dot(up, w_hat), 1e-300), cross(v, vr))))
    return n, cross(w_hat, n)


@nb.njit(cache=True, inline="always")
def _elbow_vector(P, phi4):
    """v(phi4) = Rz(phi4) u - s3: W - S in frame 3."""
    c4, s4 = np.cos(phi4), np.sin(phi4)
    u, s3 = vec(P, U), vec(P, S3)
    return (c4 * u[0] - s4 * u[1] - s3[0], s4 * u[0] + c4 * u[1] - s3[1], u[2] - s3[2])


@nb.njit(cache=True, inline="always")
def _wrist_centre(P, R, p):
    """R as three rows, and W - S in DH frame 0 for the flange pose (R, p)."""
    Rt = ((R[0, 0], R[0, 1], R[0, 2]), (R[1, 0], R[1, 1], R[1, 2]), (R[2, 0], R[2, 1], R[2, 2]))
    return Rt, sub(add((p[0], p[1], p[2]), mv(Rt, vec(P, WRIST))), vec(P, SHOULDER))


@nb.njit(cache=True)
def model_ik(P, R, p, signs, psi, q_prev, q, shoulder):
    """Solve the model for the flange pose (R, p) in DH frame 0, branch signs and arm angle.

    With ``shoulder`` False, joints 1-3 are not written: the wrist's angles follow from the
    elbow and the arm angle alone, and the OM residual needs only q7 (a third of the cost).

    Returns:
        The reach margin, ``1 - x^2`` of the elbow equation; negative (beyond a tiny slack)
        means the wrist centre is out of the model's reach and q is not written.
    """
    Rt, w = _wrist_centre(P, R, p)
    L2 = dot(w, w)
    if L2 < _DEGENERATE:  # wrist centre at the shoulder centre
        return -1.0
    x = (L2 - P[K0]) / P[K]
    margin = 1.0 - x * x
    if margin < -REACH_SLACK:
        return margin
    _ik_with_elbow(P, Rt, w, L2, _elbow_root(P, x, signs[1]), signs, psi, q_prev, q, shoulder)
    return margin


@nb.njit(cache=True)
def model_ik_at_reach(P, R, p, signs, psi, q_prev, q):
    """:func:`model_ik`, but where the wrist centre lies beyond the model's reach the elbow is
    held at the edge (straight or folded): a start for :func:`model_ik_lifted`, which is
    smooth across that edge. Returns False, and leaves q, only where W = S."""
    Rt, w = _wrist_centre(P, R, p)
    L2 = dot(w, w)
    if L2 < _DEGENERATE:
        return False
    _ik_with_elbow(P, Rt, w, L2, _elbow_root(P, (L2 - P[K0]) / P[K], signs[1]), signs, psi, q_prev, q, True)
    return True


@nb.njit(cache=True, inline="always")
def _elbow_root(P, x, elbow):
    """The root phi4 of x = cos(phi4 - phi*) in the ELBOW branch, x clamped into [-1, 1]."""
    xc = min(max(x, -1.0), 1.0)
    return P[PHI_STAR] + np.arctan2(elbow * np.sqrt(1.0 - xc * xc), xc)


@nb.njit(cache=True)
def model_ik_lifted(P, R, p, signs, psi, q1, q7, phi4, q):
    r"""The model IK with q1, q7 and the elbow angle phi4 given rather than solved for
    (phi4 NaN: the elbow equation's root in the ELBOW branch, the edge of reach beyond it).

    Writes q (q1 and q7 as given) and returns the residuals of the three equations they
    must satisfy: the shoulder's and the wrist's consistency (see
    :func:`~om_redundant.om.families.common.euler_zxzxz_given_first`) and the elbow's,
    :math:`x - \cos(\varphi_4 - \varphi^*)`. Unlike :func:`model_ik`, this is smooth
    everywhere but at W = S (NaN): across the straight elbow, where the two ELBOW branches
    meet in a square root, and at the shoulder and wrist singularities, where the Euler
    angles are ill-conditioned. Its roots are the model's IK in every SHOULDER and WRIST
    branch at once (each angle pair's branch follows from q1 or q7).
    """
    Rt, w = _wrist_centre(P, R, p)
    L2 = dot(w, w)
    if L2 < _DEGENERATE:
        return np.nan, np.nan, np.nan
    x = (L2 - P[K0]) / P[K]
    if np.isnan(phi4):
        phi4 = _elbow_root(P, x, signs[1])
    th = P[THETA : THETA + 7]
    R03 = _rotation_03_at(P, w, L2, phi4, signs[1], psi)
    phi2, phi3, shoulder = euler_zxzxz_given_first(
        mmt(mtm(mat(P, R_PRE), R03), mat(P, X3)), P[SIGMA1], 0.0, P[SIGMA2], q1 + th[0]
    )
    R04 = mm(R03, rz_times(phi4, mat(P, X4)))
    M = mmt(mtm(R04, Rt), mat(P, E_ROT))
    # The wrist's M^T = Rz(-phi7) Rx(-beta) Rz(-phi6) Rx(-alpha5) Rz(-phi5): phi7 comes first.
    neg6, neg5, wrist = euler_zxzxz_given_first(
        transpose(M), -P[SIN_BETA], P[COS_BETA], -P[SIGMA5], -(q7 + th[6])
    )
    q[0], q[1], q[2], q[3] = q1, wrap(phi2 - th[1]), wrap(phi3 - th[2]), wrap(phi4 - th[3])
    q[4], q[5], q[6] = wrap(-neg5 - th[4]), wrap(-neg6 - th[5]), q7
    return shoulder, wrist, x - np.cos(phi4 - P[PHI_STAR])


@nb.njit(cache=True, inline="always")
def _rotation_03_at(P, w, L2, phi4, elbow, psi):
    """R03 for W - S = w, the elbow angle phi4 and the arm angle psi.

    It maps the frame-3 triad (v_hat, b3_hat, v_hat x b3_hat) onto (w_hat, m, w_hat x m):
    the shoulder-wrist direction and the bend direction, in frame 3 and in frame 0.
    """
    w_hat = scale(1.0 / np.sqrt(L2), w)
    n, nw = reference_direction(P, w_hat)
    m = add(scale(np.cos(psi), n), scale(np.sin(psi), nw))
    v = _elbow_vector(P, phi4)
    v_hat = unit(v)
    b3 = unit(scale(elbow * P[BEND], (-v[1], v[0], 0.0)))
    return mtm((w_hat, m, cross(w_hat, m)), (v_hat, b3, cross(v_hat, b3)))


@nb.njit(cache=True, inline="always")
def _ik_with_elbow(P, Rt, w, L2, phi4, signs, psi, q_prev, q, shoulder):
    """Joints 1-3 (if ``shoulder``) and 5-7 for the elbow angle phi4, W - S = w and the arm
    angle psi."""
    th = P[THETA : THETA + 7]
    R03 = _rotation_03_at(P, w, L2, phi4, signs[1], psi)
    if shoulder:
        phi = euler_zxzxz(
            mmt(mtm(mat(P, R_PRE), R03), mat(P, X3)), P[SIGMA1], P[SIGMA2], 0.0, signs[0], q_prev[0] + th[0]
        )
        q[0], q[1], q[2] = wrap(phi[0] - th[0]), wrap(phi[1] - th[1]), wrap(phi[2] - th[2])
    q[3] = wrap(phi4 - th[3])
    R04 = mm(R03, rz_times(phi4, mat(P, X4)))
    M = mmt(mtm(R04, Rt), mat(P, E_ROT))
    phi = euler_zxzxz(M, P[SIGMA5], P[SIN_BETA], P[COS_BETA], signs[2], q_prev[4] + th[4])
    q[4], q[5], q[6] = wrap(phi[0] - th[4]), wrap(phi[1] - th[5]), wrap(phi[2] - th[6])


@nb.njit(cache=True)
def _rotation_03(P, q):
    th = P[THETA : THETA + 7]
    R = mm(mat(P, R_PRE), rz_times(q[0] + th[0], _rx(P[SIGMA1])))
    R = mm(R, rz_times(q[1] + th[1], _rx(P[SIGMA2])))
    return mm(R, rz_times(q[2] + th[2], mat(P, X3)))


@nb.njit(cache=True)
def arm_angle(P, q):
    """The model's arm angle psi at joint vector q."""
    R03 = _rotation_03(P, q)
    phi4 = q[3] + P[THETA + 3]
    w_hat = unit(mv(R03, _elbow_vector(P, phi4)))
    n, nw = reference_direction(P, w_hat)
    elbow = -1.0 if np.sin(phi4 - P[PHI_STAR]) < 0.0 else 1.0
    b = scale(elbow * P[BEND], cross(col(R03, 2), w_hat))
    return np.arctan2(dot(nw, b), dot(n, b))


@nb.njit(cache=True)
def branch_values(P, q, out):
    """Write the quantities whose signs are (SHOULDER, ELBOW, WRIST) at joint vector q."""
    th = P[THETA : THETA + 7]
    out[0] = np.sin(q[1] + th[1])
    out[1] = np.sin(q[3] + th[3] - P[PHI_STAR])
    out[2] = np.sin(q[5] + th[5])
