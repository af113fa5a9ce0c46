"""Screw axes: an arm's joints as lines (H and P) for EAIK and ik-geo, and a 7-DOF arm as six joints."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

import om_redundant as om

from .transforms import rot_z


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation about a unit axis (3x3)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


@dataclass(frozen=True, eq=False)
class ScrewChain:
    r"""Revolute joints as lines in the zero configuration (product of exponentials).

    :math:`T(q) = g_0(q_0) \cdots g_{n-1}(q_{n-1})\, M`, where :math:`g_i` rotates by
    :math:`q_i` about the line through ``points[i]`` along ``axes[i]``. Any point of each
    line will do; :meth:`hp` turns them into EAIK's and ik-geo's ``(H, P)``.

    Attributes:
        axes: (n, 3) unit joint axes.
        points: (n, 3) a point of each joint axis.
        home: (4, 4) end-effector pose at q = 0.
    """

    axes: np.ndarray
    points: np.ndarray
    home: np.ndarray

    @classmethod
    def from_placements(cls, P: np.ndarray, tail: np.ndarray) -> ScrewChain:
        """The chain ``P[0] Rz(q0) ... P[n-1] Rz(q_{n-1}) tail`` (joints about local z)."""
        frames = []
        current = np.eye(4)
        for placement in P:
            current = current @ placement
            frames.append(current)
        frames = np.array(frames)
        return cls(frames[:, :3, 2].copy(), frames[:, :3, 3].copy(), current @ tail)

    @classmethod
    def from_arm(cls, arm: om.Arm) -> ScrewChain:
        """The chain of a revolute arm."""
        if not arm.revolute.all():
            raise ValueError(f"arm '{arm.name}' has a prismatic joint; H and P describe revolute chains")
        return cls.from_placements(*arm.chain.joint_placements())

    @property
    def dof(self) -> int:
        return len(self.axes)

    def fk(self, q: np.ndarray) -> np.ndarray:
        """End-effector pose (4x4) at joint vector q."""
        T = np.eye(4)
        for h, o, angle in zip(self.axes, self.points, q, strict=True):
            g = np.eye(4)
            g[:3, :3] = _rotation(h, angle)
            g[:3, 3] = o - g[:3, :3] @ o
            T = T @ g
        return T @ self.home

    def hp(self) -> tuple[np.ndarray, np.ndarray]:
        """``(H, P)``: (n, 3) axes and (n + 1, 3) offsets base -> point 0 -> ... -> end effector."""
        ends = np.vstack([np.zeros(3), self.points, self.home[:3, 3]])
        return self.axes.copy(), np.diff(ends, axis=0)

    def reversed(self) -> ScrewChain:
        r"""The chain of :math:`T(q)^{-1}` with the joints in reverse order and the same angles.

        :math:`T^{-1} = M^{-1} g_{n-1}^{-1} \cdots g_0^{-1}`; conjugating each factor by
        :math:`M` moves it in front, and negating the axis keeps the sign of the angle.
        """
        M_inv = np.linalg.inv(self.home)
        axes = -(M_inv[:3, :3] @ self.axes[::-1].T).T
        points = (M_inv[:3, :3] @ self.points[::-1].T).T + M_inv[:3, 3]
        return ScrewChain(axes, points, M_inv)


@dataclass(frozen=True, eq=False)
class SixAxisView:
    """An arm as six revolute joints: a 7-DOF arm with its last joint held at a given value.

    With the last joint held at ``q_last``,
    ``T = T6(q[:6]) Rz(q_last) P_tail``, so the 6-DOF chain ending at the last joint's
    frame must reach ``target(T, q_last) = T P_tail^-1 Rz(-q_last)``.

    Attributes:
        chain: The six free joints, ending at the last joint's frame (7-DOF) or at the
            end effector (6-DOF).
        held: Whether a last joint is held.
        tail_inv: Inverse of the last placement ``P_tail`` (identity for 6-DOF arms).
    """

    chain: ScrewChain
    held: bool
    tail_inv: np.ndarray

    @classmethod
    def of(cls, arm: om.Arm) -> SixAxisView:
        """The view of a 6-DOF or 7-DOF revolute arm."""
        if not arm.revolute.all() or arm.dof not in (6, 7):
            raise ValueError(f"arm '{arm.name}': EAIK and ik-geo take 6 or 7 revolute joints")
        P, tail = arm.chain.joint_placements()
        if arm.dof == 6:
            return cls(ScrewChain.from_placements(P, tail), False, np.eye(4))
        return cls(ScrewChain.from_placements(P[:6], P[6]), True, np.linalg.inv(tail))

    def target(self, T: np.ndarray, q_last: float = 0.0) -> np.ndarray:
        """The pose the six free joints must reach for end-effector pose T."""
        return T @ self.tail_inv @ rot_z(-q_last) if self.held else T

    def pose(self, T6: np.ndarray, q_last: float = 0.0) -> np.ndarray:
        """The end-effector pose when the six free joints reach T6: the inverse of :meth:`target`."""
        return T6 @ rot_z(q_last) @ np.linalg.inv(self.tail_inv) if self.held else T6

    def full(self, q6: np.ndarray, q_last: float = 0.0) -> np.ndarray:
        """The arm's joint vectors (k, dof) from six-joint solutions (k, 6)."""
        q6 = np.asarray(q6, dtype=float).reshape(-1, 6)
        return np.hstack([q6, np.full((len(q6), 1), q_last)]) if self.held else q6


def eaik_robot(chain: ScrewChain) -> Any:
    """An EAIK robot of the chain, from ``(H, P)`` and the end-effector orientation at q = 0."""
    from eaik.pybindings import EAIK

    H, P = chain.hp()
    return EAIK.Robot(H.T, P.T, chain.home[:3, :3], [], True)
