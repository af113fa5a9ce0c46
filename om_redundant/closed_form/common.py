r"""Pieces every family uses: the reach slack, angle wrapping, and the angles of three
revolute joints with intersecting axes (a spherical shoulder or wrist).

The rotation of such a triple is

.. math::  M = R_z(\varphi_a)\, R_x(\alpha_a)\, R_z(\varphi_b)\, R_x(\alpha_b)\, R_z(\varphi_c),
           \qquad \sigma_{a,b} = \sin\alpha_{a,b} = \pm 1,

so :math:`M e_z = (\sigma_b S_b C_a,\ \sigma_b S_b S_a,\ -\sigma_a \sigma_b C_b)` with
:math:`S = \sin, C = \cos`. With the branch sign :math:`s = \mathrm{sign}(\sin\varphi_b)`,
:math:`\varphi_a` and :math:`\varphi_b` are atan2s of M's last column, and :math:`\varphi_c` is
the angle of the residual :math:`(R_z(\varphi_a) R_x(\alpha_a) R_z(\varphi_b) R_x(\alpha_b))^T M`.
Taking :math:`\varphi_c` from this residual rather than from M's last row makes the three angles
consistent, so that their rounding errors cancel in the product even near the singularity
:math:`\sin\varphi_b = 0`, where axes a and c align and :math:`\varphi_a` keeps a given value.
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


@nb.njit(cache=True)
def euler_zxzxz(M, sigma_a, sigma_b, sign, phi_a_singular):
    """(phi_a, phi_b, phi_c) with M = Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(alpha_b) Rz(phi_c).

    Args:
        M: Rotation, 3x3 as three rows.
        sigma_a, sigma_b: sin(alpha_a), sin(alpha_b), each +-1.
        sign: Branch sign of sin(phi_b).
        phi_a_singular: phi_a used when sin(phi_b) = 0 (axes a and c aligned).
    """
    ax, ay, az = M[0][2], M[1][2], M[2][2]
    sin_b = np.sqrt(ax * ax + ay * ay)
    if sin_b > SINGULAR:
        phi_a = np.arctan2(sigma_b * sign * ay, sigma_b * sign * ax)
        phi_b = np.arctan2(sign * sin_b, -sigma_a * sigma_b * az)
    else:
        phi_a = phi_a_singular
        phi_b = np.arctan2(0.0, -sigma_a * sigma_b * az)
    ca, sa, cb, sb = np.cos(phi_a), np.sin(phi_a), np.cos(phi_b), np.sin(phi_b)
    # Columns 0 and 1 of A = Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(alpha_b), dotted with M's
    # first column, give cos and sin of phi_c (X = A^T M = Rz(phi_c)).
    m0 = col(M, 0)
    x00 = dot((cb * ca, cb * sa, sb * sigma_a), m0)
    x10 = sigma_a * sigma_b * (sa * m0[0] - ca * m0[1])
    return phi_a, phi_b, np.arctan2(x10, x00)
