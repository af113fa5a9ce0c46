r"""Pieces every family uses: the reach slack, angle wrapping, and the angles of three
revolute joints with intersecting axes (a spherical shoulder or wrist).

The rotation of such a triple is

.. math::  M = R_z(\varphi_a)\, R_x(\alpha_a)\, R_z(\varphi_b)\, R_x(\beta)\, R_z(\varphi_c),
           \qquad \sigma_a = \sin\alpha_a = \pm 1,

so with :math:`S = \sin, C = \cos`, :math:`M e_z = R_z(\varphi_a)\,(S_\beta S_b,\
-\sigma_a C_\beta)` in x and y and :math:`-\sigma_a S_\beta C_b` in z. Axes a and b are
perpendicular; :math:`\beta` is :math:`\pm 90°` on most arms but may differ (the Sawyer's
joint 7 leans by :math:`7 \cdot 10^{-6}` rad), which leaves a cone of half-angle
:math:`|C_\beta|` around axis a that axis c cannot reach. With the branch sign
:math:`s = \mathrm{sign}(\sin\varphi_b)`, :math:`\varphi_b` and :math:`\varphi_a` follow from M's
last column, and :math:`\varphi_c` is the angle of the residual
:math:`(R_z(\varphi_a) R_x(\alpha_a) R_z(\varphi_b) R_x(\beta))^T M`. Taking :math:`\varphi_c`
from this residual rather than from M's last row makes the three angles consistent, so that
their rounding errors cancel in the product even near the singularity
:math:`\sin\varphi_b = 0`, where axes a and c align (up to :math:`C_\beta`) and
:math:`\varphi_a` keeps a given value.
"""

from __future__ import annotations

import numba as nb
import numpy as np

SINGULAR = 1e-12
# Relative slack under a square root before a target counts as outside the model's reach.
REACH_SLACK = 1e-12


@nb.njit(cache=True, inline="always")
def wrap(x):
    """x wrapped into [-pi, pi)."""
    return x - 2.0 * np.pi * np.floor((x + np.pi) / (2.0 * np.pi))


# Small vectors and matrices as tuples (3-vectors, and 3x3 as three rows): numba keeps them
# in registers, where arrays would cost a heap allocation each and ``@`` a BLAS call.


@nb.njit(cache=True, inline="always")
def vec(P, i):
    """The 3-vector P[i:i+3]."""
    return (P[i], P[i + 1], P[i + 2])


@nb.njit(cache=True, inline="always")
def mat(P, i):
    """The row-major 3x3 matrix P[i:i+9]."""
    return ((P[i], P[i + 1], P[i + 2]), (P[i + 3], P[i + 4], P[i + 5]), (P[i + 6], P[i + 7], P[i + 8]))


@nb.njit(cache=True, inline="always")
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@nb.njit(cache=True, inline="always")
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@nb.njit(cache=True, inline="always")
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@nb.njit(cache=True, inline="always")
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@nb.njit(cache=True, inline="always")
def scale(k, a):
    return (k * a[0], k * a[1], k * a[2])


@nb.njit(cache=True, inline="always")
def unit(a):
    return scale(1.0 / np.sqrt(dot(a, a)), a)


@nb.njit(cache=True, inline="always")
def col(A, j):
    return (A[0][j], A[1][j], A[2][j])


@nb.njit(cache=True, inline="always")
def transpose(A):
    return (col(A, 0), col(A, 1), col(A, 2))


@nb.njit(cache=True, inline="always")
def mv(A, v):
    """A @ v."""
    return (dot(A[0], v), dot(A[1], v), dot(A[2], v))


@nb.njit(cache=True, inline="always")
def mm(A, B):
    """A @ B."""
    Bt = transpose(B)
    return (mv(Bt, A[0]), mv(Bt, A[1]), mv(Bt, A[2]))


@nb.njit(cache=True, inline="always")
def mmt(A, B):
    """A @ B.T."""
    return (mv(B, A[0]), mv(B, A[1]), mv(B, A[2]))


@nb.njit(cache=True, inline="always")
def mtm(A, B):
    """A.T @ B."""
    return mm(transpose(A), B)


@nb.njit(cache=True, inline="always")
def rz_times(phi, X):
    """Rz(phi) @ X."""
    c, s = np.cos(phi), np.sin(phi)
    return (sub(scale(c, X[0]), scale(s, X[1])), add(scale(s, X[0]), scale(c, X[1])), X[2])


@nb.njit(cache=True, inline="always")
def _angle(y, x, fallback):
    """atan2(y, x) with its cos and sin; the fallback angle where x = y = 0."""
    r = np.sqrt(x * x + y * y)
    if r > 0.0:
        return np.arctan2(y, x), x / r, y / r
    return fallback, np.cos(fallback), np.sin(fallback)


@nb.njit(cache=True)
def euler_zxzxz(M, sigma_a, sin_b, cos_b, sign, phi_a_singular):
    """(phi_a, phi_b, phi_c) with M = Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(beta) Rz(phi_c).

    Args:
        M: Rotation, 3x3 as three rows.
        sigma_a: sin(alpha_a) = +-1.
        sin_b, cos_b: sin(beta) and cos(beta), with |cos(beta)| small (0 on most arms).
        sign: Branch sign of sin(phi_b).
        phi_a_singular: phi_a used when sin(phi_b) = 0 (axes a and c aligned). Inside the
            cone that axis c cannot reach, sin(phi_b) is taken as 0 too.
    """
    ax, ay, az = M[0][2], M[1][2], M[2][2]
    # |S_beta S_b| from the length of M e_z's xy part, (S_beta S_b, -sigma_a C_beta) turned.
    radial = np.sqrt(max(ax * ax + ay * ay - cos_b * cos_b, 0.0))
    sb_sign = 1.0 if sin_b > 0.0 else -1.0
    # Each angle's cos and sin come from its atan2's arguments, normalised: no more trig.
    phi_b, cb, sb = _angle(sign * radial, -sigma_a * sb_sign * az, 0.0)
    if radial > SINGULAR:
        px, py = sin_b * sb, -sigma_a * cos_b
        phi_a, ca, sa = _angle(px * ay - py * ax, px * ax + py * ay, phi_a_singular)
    else:
        phi_a, ca, sa = phi_a_singular, np.cos(phi_a_singular), np.sin(phi_a_singular)
    # Columns 0 and 1 of A = Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(beta), dotted with M's
    # first column, give cos and sin of phi_c (X = A^T M = Rz(phi_c)).
    m0 = col(M, 0)
    x00 = dot((cb * ca, cb * sa, sb * sigma_a), m0)
    x10 = dot(
        (
            sa * sigma_a * sin_b - ca * sb * cos_b,
            -ca * sigma_a * sin_b - sa * sb * cos_b,
            sigma_a * cb * cos_b,
        ),
        m0,
    )
    return phi_a, phi_b, np.arctan2(x10, x00)


@nb.njit(cache=True)
def euler_zxzxz_given_first(M, sin_a, cos_a, sigma_b, phi_a):
    """(phi_b, phi_c, residual) for M = Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(alpha_b) Rz(phi_c)
    with phi_a given.

    :math:`N = R_x(\\alpha_a)^T R_z(-\\varphi_a) M` must equal
    :math:`R_z(\\varphi_b) R_x(\\alpha_b) R_z(\\varphi_c)`, whose last column is
    :math:`\\sigma_b (S_b, -C_b, 0)` and last row :math:`\\sigma_b (S_c, C_c, 0)`; the angles are
    their atan2s and the residual is :math:`N_{22}`, zero iff phi_a is consistent with M. Unlike
    :func:`euler_zxzxz`, all three are smooth in M and phi_a, also where axes a and c align.

    Args:
        M: Rotation, 3x3 as three rows.
        sin_a, cos_a: sin and cos of alpha_a.
        sigma_b: sin(alpha_b) = +-1.
        phi_a: The first angle.
    """
    ca, sa = np.cos(phi_a), np.sin(phi_a)
    # Rz(-phi_a) M, rows 0-2; then Rx(alpha_a)^T mixes rows 1 and 2.
    r0 = add(scale(ca, M[0]), scale(sa, M[1]))
    r1 = sub(scale(ca, M[1]), scale(sa, M[0]))
    n1 = add(scale(cos_a, r1), scale(sin_a, M[2]))
    n2 = sub(scale(cos_a, M[2]), scale(sin_a, r1))
    phi_b = np.arctan2(sigma_b * r0[2], -sigma_b * n1[2])
    phi_c = np.arctan2(sigma_b * n2[0], sigma_b * n2[1])
    return phi_b, phi_c, n2[2]
