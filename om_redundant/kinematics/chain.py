r"""Denavit-Hartenberg kinematic chains: forward kinematics and the geometric Jacobian.

A chain is a list of DH rows between a base transform and a tool transform:

.. math::

    T_{root,ee}(q) = T_{root,0} \; \prod_i A_i(q) \; T_{flange,ee}

Rows are stored in the standard convention,
:math:`A_i = R_z(\theta_i) T_z(d_i) T_x(a_i) R_x(\alpha_i)`, with the joint variable added
to :math:`\theta_i` (revolute) or :math:`d_i` (prismatic); a fixed row has no variable.
A table in the modified (Craig) convention,
:math:`A_i = R_x(\alpha_{i-1}) T_x(a_{i-1}) R_z(\theta_i) T_z(d_i)`, is converted exactly by
:func:`standard_rows_from_modified`: since :math:`R_x` and :math:`T_x` commute, the product
regroups into a fixed row :math:`T_x(a_0) R_x(\alpha_0)` followed by standard rows. One
internal convention keeps one code path for FK, Jacobians and the OM model.

The numeric kernels are C (``csrc/ik/kinematics.c``, in :mod:`om_redundant.ckernels`);
:class:`KinematicChain` is the typed front.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from functools import cached_property

import numpy as np

from .. import _core
from ..validation import as_joint_vector


class JointKind(StrEnum):
    """What a DH row's variable is."""

    REVOLUTE = "revolute"
    PRISMATIC = "prismatic"
    FIXED = "fixed"


#: A row's kind as the kernels' tables hold it (the codes are C's: csrc/ik/om_kernels.h, OM_JOINT_*).
_KIND_CODE = {
    JointKind.REVOLUTE: _core.JOINT_REVOLUTE,
    JointKind.PRISMATIC: _core.JOINT_PRISMATIC,
    JointKind.FIXED: _core.JOINT_FIXED,
}


@dataclass(frozen=True)
class DHRow:
    """One standard-convention DH row: ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``.

    Attributes:
        a: Link length along x (m).
        alpha: Link twist about x (rad).
        d: Link offset along z (m); the joint variable is added to it for prismatic rows.
        theta: Joint angle offset about z (rad); the variable is added for revolute rows.
        kind: Revolute, prismatic or fixed.
    """

    a: float = 0.0
    alpha: float = 0.0
    d: float = 0.0
    theta: float = 0.0
    kind: JointKind = JointKind.REVOLUTE

    @property
    def is_joint(self) -> bool:
        return self.kind is not JointKind.FIXED


def standard_rows_from_modified(rows: list[DHRow]) -> list[DHRow]:
    """Convert rows read in the modified convention into equivalent standard rows.

    Each input row holds ``(a_{i-1}, alpha_{i-1}, d_i, theta_i)`` as ``(a, alpha, d, theta)``.
    The result starts with the fixed row ``Tx(a_0) Rx(alpha_0)`` (omitted when zero) and
    then row i becomes ``(a_i, alpha_i, d_i, theta_i)``, taking ``a_i, alpha_i`` from the
    next input row (zero after the last).
    """
    out: list[DHRow] = []
    if rows and (rows[0].a != 0.0 or rows[0].alpha != 0.0):
        out.append(DHRow(a=rows[0].a, alpha=rows[0].alpha, kind=JointKind.FIXED))
    for i, row in enumerate(rows):
        nxt = rows[i + 1] if i + 1 < len(rows) else DHRow()
        out.append(DHRow(a=nxt.a, alpha=nxt.alpha, d=row.d, theta=row.theta, kind=row.kind))
    return out


@dataclass(frozen=True, eq=False)
class KinematicChain:
    """Standard DH rows between a base and a tool transform.

    Attributes:
        rows: The rows, standard convention, fixed rows included.
        T_root_base: Pose of DH frame 0 in the arm's root frame (4x4).
        T_flange_tool: Pose of the end-effector frame in the last DH frame (4x4).
    """

    rows: tuple[DHRow, ...]
    T_root_base: np.ndarray = field(default_factory=lambda: np.eye(4))
    T_flange_tool: np.ndarray = field(default_factory=lambda: np.eye(4))
    table: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        # the kernels' table: its columns are C's (csrc/ik/om_kernels.h, OM_DH_*), read from _core
        rows = self.rows
        table = np.empty((len(rows), _core.DH_COLUMNS))
        table[:, _core.DH_A] = [r.a for r in rows]
        table[:, _core.DH_D] = [r.d for r in rows]
        table[:, _core.DH_THETA] = [r.theta for r in rows]
        table[:, _core.DH_COS_ALPHA] = [np.cos(r.alpha) for r in rows]
        table[:, _core.DH_SIN_ALPHA] = [np.sin(r.alpha) for r in rows]
        table[:, _core.DH_KIND] = [_KIND_CODE[r.kind] for r in rows]
        object.__setattr__(self, "table", table)
        for name in ("T_root_base", "T_flange_tool"):
            object.__setattr__(self, name, np.ascontiguousarray(getattr(self, name), dtype=np.float64))

    @cached_property
    def dof(self) -> int:
        """Number of joints (rows that are not fixed); computed once, the rows are frozen."""
        return len(self.joint_rows)

    @cached_property
    def joint_rows(self) -> tuple[int, ...]:
        """Index in :attr:`rows` of each joint's row, in joint order; computed once."""
        return tuple(i for i, r in enumerate(self.rows) if r.is_joint)

    def replace_rows(self, rows: list[DHRow]) -> KinematicChain:
        """The same chain with other rows (same base and tool)."""
        return KinematicChain(tuple(rows), self.T_root_base, self.T_flange_tool)

    def joint_placements(self) -> tuple[np.ndarray, np.ndarray]:
        r"""The chain as joint motions between constant transforms, as MJCF and URDF want it.

        A revolute row is :math:`R_z(q)\,C` and a prismatic one :math:`T_z(q)\,C` with
        :math:`C = R_z(\theta) T_z(d) T_x(a) R_x(\alpha)` (:math:`T_z` commutes with
        :math:`R_z`), so

        .. math::  T_{root,ee}(q) = P_1\, M_1(q_1)\, P_2\, M_2(q_2) \cdots P_n\, M_n(q_n)\, P_{tail},

        where :math:`M_i` moves about or along the local z-axis and every :math:`P` is
        constant (fixed rows, base and tool folded in).

        Returns:
            ``(P, P_tail)``: (dof, 4, 4) placements of each joint frame in the previous
            joint's moving frame (the first in the root frame), and (4, 4) the end-effector
            frame in the last joint's moving frame.
        """
        placements = []
        current = self.T_root_base.copy()
        for row in self.rows:
            if row.is_joint:
                placements.append(current)
                current = np.eye(4)
            current = current @ row_transform(row)
        return np.array(placements).reshape(-1, 4, 4), current @ self.T_flange_tool

    def fk(self, q: np.ndarray) -> np.ndarray:
        """Pose of the end-effector frame in the root frame.

        Args:
            q: Joint vector (dof,) or stack (M, dof).

        Returns:
            (4, 4) transform, or (M, 4, 4) for a stack.
        """
        q = np.ascontiguousarray(as_joint_vector(q, self.dof))
        out = np.empty((*q.shape[:-1], 4, 4))
        _core.fk(self.table, self.T_root_base, self.T_flange_tool, q, out)
        return out

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        r"""Geometric Jacobian of the end-effector frame, in the root frame.

        Rows are ``[v; omega]`` (linear velocity of the end-effector origin, then angular
        velocity): :math:`J_i = [z_i \times (p_{ee} - o_i);\ z_i]` for a revolute joint and
        :math:`[z_i;\ 0]` for a prismatic one, with :math:`z_i, o_i` the joint's axis and origin.

        Args:
            q: Joint vector (dof,).

        Returns:
            (6, dof) array.
        """
        q = as_joint_vector(q, self.dof, stack=False)
        J = np.empty((6, self.dof))
        _core.jacobian(self.table, self.T_root_base, self.T_flange_tool, np.ascontiguousarray(q), J)
        return J


def row_transform(row: DHRow) -> np.ndarray:
    """The constant part :math:`R_z(\\theta) T_z(d) T_x(a) R_x(\\alpha)` of a row (4x4)."""
    ct, st, ca, sa = np.cos(row.theta), np.sin(row.theta), np.cos(row.alpha), np.sin(row.alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, row.a * ct],
            [st, ct * ca, -ct * sa, row.a * st],
            [0.0, sa, ca, row.d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )
