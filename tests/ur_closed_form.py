"""An independent closed-form IK of UR-type arms, used to check the OM solver.

It does not use the OM model: it decomposes the REAL arm through its parallel joints 2-4
(the classic UR solution): joint 1 from the lateral offset d4 of joint 5's origin, joint 5
from the approach vector, joint 6 from the normal and sliding vectors, joints 2-4 from a
planar two-link problem. Written for the Menagerie UR5e table (d6 = 0).
"""

from __future__ import annotations

import numpy as np


def ur_ik(arm, T: np.ndarray) -> list[np.ndarray]:
    """All real solutions (up to 8) of a UR arm for the end-effector pose T."""
    rows = [arm.chain.rows[i] for i in arm.chain.joint_rows]
    d1, a2, a3, d4, d5 = rows[0].d, rows[1].a, rows[2].a, rows[3].d, rows[4].d
    F = np.linalg.inv(arm.chain.T_root_base) @ T @ np.linalg.inv(arm.chain.T_flange_tool)
    R, p = F[:3, :3], F[:3, 3]  # p is joint 5's origin, since d6 = 0
    solutions = []
    r = np.hypot(p[0], p[1])
    if r < abs(d4):
        return solutions
    phi = np.arctan2(p[1], p[0])
    for t1 in (phi + np.arcsin(d4 / r), phi + np.pi - np.arcsin(d4 / r)):
        z1 = np.array([np.sin(t1), -np.cos(t1), 0.0])
        c5 = np.clip(z1 @ R[:, 2], -1.0, 1.0)
        for t5 in (np.arccos(c5), -np.arccos(c5)):
            s5 = np.sin(t5)
            if abs(s5) < 1e-9:
                continue
            t6 = np.arctan2(-(z1 @ R[:, 1]) / s5, (z1 @ R[:, 0]) / s5)
            R1 = rz(t1) @ rx(np.pi / 2)
            R46 = rz(t5) @ rx(-np.pi / 2) @ rz(t6)
            Rz234 = R1.T @ R @ R46.T @ rx(np.pi / 2).T
            t234 = np.arctan2(Rz234[1, 0], Rz234[0, 0])
            z4 = R1 @ rz(t234) @ rx(np.pi / 2) @ np.array([0.0, 0.0, 1.0])
            o4 = R1.T @ (p - d5 * z4 - np.array([0.0, 0.0, d1]))
            x, y = o4[0], o4[1]
            c3 = (x * x + y * y - a2 * a2 - a3 * a3) / (2 * a2 * a3)
            if abs(c3) > 1.0:
                continue
            for t3 in (np.arccos(c3), -np.arccos(c3)):
                t2 = np.arctan2(y, x) - np.arctan2(a3 * np.sin(t3), a2 + a3 * np.cos(t3))
                q = np.array([t1, t2, t3, t234 - t2 - t3, t5, t6])
                solutions.append((q + np.pi) % (2 * np.pi) - np.pi)
    return solutions


def rz(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rx(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
