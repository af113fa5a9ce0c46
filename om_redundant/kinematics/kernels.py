"""The numba kernels of DH chains: forward kinematics, joint axes and the geometric Jacobian.

They take a chain's ``table`` (:attr:`~om_redundant.kinematics.chain.KinematicChain.table`),
one row per DH row, standard convention, columns: a, d, theta, cos(alpha), sin(alpha),
kind code (0 revolute, 1 prismatic, 2 fixed). :class:`~.chain.KinematicChain` is the typed
front.
"""

from __future__ import annotations

import numba as nb
import numpy as np


@nb.njit(cache=True, inline="always")
def apply_row(R, p, row, qi):
    """Right-multiply the frame (R, p) in place by the standard DH row with variable qi."""
    kind = row[5]
    theta = row[2] + qi if kind == 0.0 else row[2]
    d = row[1] + qi if kind == 1.0 else row[1]
    ct, st, ca, sa, a = np.cos(theta), np.sin(theta), row[3], row[4], row[0]
    for i in range(3):
        r0, r1, r2 = R[i, 0], R[i, 1], R[i, 2]
        p[i] += r0 * a * ct + r1 * a * st + r2 * d
        R[i, 0] = r0 * ct + r1 * st
        R[i, 1] = -r0 * st * ca + r1 * ct * ca + r2 * sa
        R[i, 2] = r0 * st * sa - r1 * ct * sa + r2 * ca


@nb.njit(cache=True)
def flange_kernel(table, q, R, p):
    """Write the pose of the last DH frame in DH frame 0 into (R, p)."""
    R[:, :] = 0.0
    R[0, 0] = R[1, 1] = R[2, 2] = 1.0
    p[:] = 0.0
    j = 0
    for k in range(table.shape[0]):
        if table[k, 5] == 2.0:
            apply_row(R, p, table[k], 0.0)
        else:
            apply_row(R, p, table[k], q[j])
            j += 1


@nb.njit(cache=True)
def fk_kernel(table, base, tool, q):
    R = np.empty((3, 3))
    p = np.empty(3)
    flange_kernel(table, q, R, p)
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return base @ T @ tool


@nb.njit(cache=True, parallel=True)
def fk_batch_kernel(table, base, tool, Q):
    out = np.empty((Q.shape[0], 4, 4))
    for m in nb.prange(Q.shape[0]):
        out[m] = fk_kernel(table, base, tool, Q[m])
    return out


@nb.njit(cache=True)
def joint_axes_kernel(table, q, axes, origins, R, p):
    """Write the axis and origin, in DH frame 0, of joints 1..n (n = ``len(axes)``); R and p
    end as the frame after every row before joint n+1's (the flange for n = dof).

    A standard row's joint acts about the z-axis of the frame it starts from.
    """
    R[:] = np.eye(3)
    p[:] = 0.0
    j = 0
    for k in range(table.shape[0]):
        if table[k, 5] == 2.0:
            apply_row(R, p, table[k], 0.0)
            continue
        if j == axes.shape[0]:
            break
        axes[j] = R[:, 2]
        origins[j] = p
        apply_row(R, p, table[k], q[j])
        j += 1


@nb.njit(cache=True)
def jacobian_kernel(table, base, tool, q):
    dof = q.shape[0]
    axes = np.empty((dof, 3))
    origins = np.empty((dof, 3))
    R = np.empty((3, 3))
    p = np.empty(3)
    joint_axes_kernel(table, q, axes, origins, R, p)
    kinds = np.empty(dof)
    j = 0
    for k in range(table.shape[0]):
        if table[k, 5] != 2.0:
            kinds[j] = table[k, 5]
            j += 1
    Rb = np.ascontiguousarray(base[:3, :3])
    p_ee = Rb @ (p + R @ np.ascontiguousarray(tool[:3, 3])) + base[:3, 3]
    J = np.zeros((6, dof))
    for j in range(dof):
        z = Rb @ axes[j]
        if kinds[j] == 1.0:
            J[:3, j] = z
        else:
            o = Rb @ origins[j] + base[:3, 3]
            J[:3, j] = np.cross(z, p_ee - o)
            J[3:, j] = z
    return J
