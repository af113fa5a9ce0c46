r"""The nominal arm: the closed-form structure an arm is NEAR, and the arm in its coordinates.

Arms brought from CAD or from MuJoCo models miss the closed-form families by little:
twists of 90 deg +- 4e-6 rad from rounded quaternions, offsets of 5e-13 m from a URDF's
11-digit numbers, a joint whose axis is reversed (a twist of 180 deg), fixed rows between
joints. The nominal arm is the OM method's *model side* of such an arm:

* every twist within :data:`NEAR_TWIST` of 0, +-90 or 180 deg is snapped to that value;
* every length within :data:`NEAR_LENGTH` per metre of reach of zero (rounding of zero,
  :data:`~om_redundant.ik.model_conditions.LENGTH_ROUNDING`, and the micrometres a rounded twist moves a
  common normal by) is zero, and every joint offset theta within
  :data:`~om_redundant.ik.model_conditions.ANGLE_ROUNDING` of a multiple of 90 deg is that multiple:
  rounding is not geometry, and never changes the method an arm gets;
* a twist of (about) 180 deg becomes 0 and the next joint flips: since
  :math:`R_x(\pi) R_z(\theta + q) T_z(d) T_x(a) R_x(\alpha) =
  R_z(-\theta - q) T_z(-d) T_x(a) R_x(\alpha + \pi) R_x(\pi)`, the half turn moves past the
  row (to the tool at the end), the row's :math:`\theta, d` change sign and the joint's
  nominal coordinate is :math:`q_n = -q`;
* fixed rows before joint 1 go into the base; a fixed row that is a pure :math:`R_z T_z`
  merges into the next row (:math:`\theta, d` add, they commute with the joint's motion),
  one that is a pure :math:`T_x R_x` into the previous row (:math:`a, \alpha` add);
* a 7-DOF arm's shoulder offset :math:`a_2` (the common normal of joints 2 and 3: Unitree
  G1 6.24 mm, TIAGo Pro 20 mm) and wrist offset :math:`a_5` (of joints 5 and 6: Baxter
  10 mm), which are geometry, not rounding, are zero: :math:`a_2` moves the joints after it by
  :math:`a_2 x_2(q_1, q_2)` in DH frame 0, :math:`a_5` the flange by :math:`a_5 x_5`, which
  seen from the flange turns with q6 and q7, so the S-R-S model's dp would turn with q2 or q6
  besides q1 and q7, where its bounded searches take a circle or a torus; with them zeroed
  the nominal arm is searched on the torus :math:`(q_1, q_7)`, and the correction (below) is
  that translation, the OM system (9) itself, solved at every model IK by the fixed point of
  ``csrc/ik/near.c``: with q1 and q7 given, it turns with q2 alone (taken on the left, in DH frame
  0) or q6 alone (on the right, in the flange frame), at a rate of about
  :math:`a / |W - S|` away from the model's singular set.

The real arm keeps its exact table: :attr:`NominalArm.exact` is the same chain as the real
arm's, only re-expressed in the nominal joint coordinates :math:`q_n = f \odot q`
(:attr:`NominalArm.flip`, the half turns moved but not snapped), so its FK at :math:`q_n`
is the real arm's at q. The solver solves the OM system with the nominal arm as the model's
side, the exact chain's difference from it corrected at every model IK (``csrc/ik/near.c``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..angles import wrap_angles
from ..exceptions import ModelError
from ..kinematics.arm import Arm
from ..kinematics.chain import DHRow, JointKind, KinematicChain, row_transform
from .model import ModelArm, derive_model
from .model_conditions import ANGLE_ROUNDING, reach

#: Largest deviation (rad) of a twist from 0, +-90 or 180 deg that the nominal arm snaps.
NEAR_TWIST = 1e-3
#: A DH length within this many metres per metre of the arm's reach of zero is zero in the
#: nominal arm: rounding, and the common normal's shift by a twist rounded in the arm's source
#: (an xArm7 URDF's rpy 1.5708 is 3.7e-6 rad off 90 deg and leaves d = 1.1e-6 m over 0.29 m),
#: which the correction of ``csrc/ik/near.c`` absorbs like the twist; it would otherwise make the
#: nominal arm another family's (the shoulder offset d2 of the torus). Genuine offsets are
#: millimetres (the Piper's d5 = 1.4e-3 m, 1.8e-3 per metre of its reach, is kept).
NEAR_LENGTH = 1e-5

_HALF_TURN = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0, 0, 0, 1.0]])


@dataclass(frozen=True, eq=False)
class NominalArm:
    r"""An arm and the closed-form structure it is near.

    Attributes:
        real: The real arm.
        arm: The nominal arm, in nominal joint coordinates (limits mapped).
        exact: The real arm's chain in nominal joint coordinates (its FK at ``flip * q`` is
            the real arm's at q).
        flip: (dof,) +1, or -1 where a joint's axis is reversed.
        differs: Whether the nominal arm's table differs from the real one.
        deviation: A bound (m, to first order) on how far the nominal arm's flange frame is
            from the real one's at any q, over the points within reach: the snapped angles'
            changes times the reach plus the zeroed lengths, summed (``csrc/ik/near.c``'s scale
            of the correction).
        shoulder_offset: The 7-DOF shoulder offset a2 (m) the nominal arm zeroes; 0 if none.
            Where it is the larger of the two, the correction is taken on the left, in DH frame
            0 (``csrc/ik/near.c``): :math:`T_{nom}(q) = L(q) T_{real}(q)` with :math:`L` the
            translation by :math:`\Delta p(q_1, q_2)`, so that the model's target is the OM
            system's :math:`p_d + \Delta p` and the fixed point, with :math:`q_1` given on the
            torus, turns with :math:`q_2` alone.
        wrist_offset: The 7-DOF wrist offset a5 (m) the nominal arm zeroes; 0 if none. Where
            it is the larger, the correction is on the right, in the flange frame, a
            translation that turns with q6 and q7 (q7 given on the torus).
    """

    real: Arm
    arm: Arm
    exact: KinematicChain
    flip: np.ndarray
    differs: bool
    deviation: float
    shoulder_offset: float = 0.0
    wrist_offset: float = 0.0


def nominal_arm(arm: Arm) -> NominalArm:
    """The nominal arm of a real arm (see the module)."""
    exact, flip = _flipped(arm.chain, snap=False)
    snapped, _ = _flipped(arm.chain, snap=True)
    # Rounding goes before the merge, which needs exact zeros, and after it, as a merged row
    # can sum to rounding (d = 0.1 carried into a row with d = -0.1 + 1e-13).
    scale = reach(arm.chain)
    eps = NEAR_LENGTH * scale
    rounded = _rounded(snapped.rows, eps)
    merged = _merged(rounded)
    rows = _rounded(merged, eps)
    shoulder_offset, wrist_offset, rows = _offsets_zeroed(rows)
    nominal = KinematicChain(tuple(rows), snapped.T_root_base, snapped.T_flange_tool)
    # each change is a small rotation or translation of the frames after it (merges are exact)
    changes = [_change(exact.rows, snapped.rows), _change(snapped.rows, rounded), _change(merged, rows)]
    deviation = sum(angles * scale + lengths for angles, lengths in changes)
    lower = np.where(flip < 0, -arm.upper, arm.lower)
    upper = np.where(flip < 0, -arm.lower, arm.upper)
    differs = (
        nominal.table.shape != arm.chain.table.shape
        or not np.array_equal(nominal.table, arm.chain.table)
        or not np.array_equal(nominal.T_root_base, arm.chain.T_root_base)
        or not np.array_equal(nominal.T_flange_tool, arm.chain.T_flange_tool)
    )
    model = dataclasses.replace(arm, chain=nominal, lower=lower, upper=upper)
    return NominalArm(arm, model, exact, flip, bool(differs), float(deviation), shoulder_offset, wrist_offset)


def closed_form(arm: Arm) -> tuple[ModelArm, NominalArm | None]:
    """The closed-form model of an arm: of the arm itself where a family takes it exactly,
    else of its nominal arm, returned too (None in the first case).

    Raises:
        ModelError: Neither the arm nor its nominal arm has a model; the message names what
            stands in the way (in the nominal arm, where it differs from the arm).
    """
    try:
        return derive_model(arm), None
    except ModelError:
        nominal = nominal_arm(arm)
        if not nominal.differs:
            raise
    return derive_model(nominal.arm), nominal


def _nearest_right_angle(alpha: float) -> float:
    """The multiple of 90 deg nearest to alpha, in (-180, 180] deg."""
    k = int(np.round(alpha / (np.pi / 2))) % 4
    return (0.0, np.pi / 2, np.pi, -np.pi / 2)[k]


def _off(alpha: float, nominal: float) -> float:
    return abs(float(wrap_angles(alpha - nominal)))


def _flipped(chain: KinematicChain, snap: bool) -> tuple[KinematicChain, np.ndarray]:
    """Leading fixed rows into the base, half turns moved past the rows that follow them (the
    joints flipped), twists snapped if ``snap``."""
    rows = list(chain.rows)
    base = chain.T_root_base.copy()
    while rows and not rows[0].is_joint:
        base = base @ row_transform(rows.pop(0))
    out, flip, half_turn = [], [], False
    for row in rows:
        alpha = row.alpha
        if half_turn:
            row = DHRow(a=row.a, alpha=alpha + np.pi, d=-row.d, theta=-row.theta, kind=row.kind)
        if row.is_joint:
            flip.append(-1.0 if half_turn else 1.0)
        nominal = _nearest_right_angle(row.alpha)
        near = _off(row.alpha, nominal) <= NEAR_TWIST
        half_turn = near and nominal == np.pi
        if half_turn:
            alpha = 0.0 if snap else row.alpha - np.pi
        else:
            alpha = nominal if snap and near else row.alpha
        out.append(DHRow(a=row.a, alpha=alpha, d=row.d, theta=row.theta, kind=row.kind))
    tool = _HALF_TURN @ chain.T_flange_tool if half_turn else chain.T_flange_tool
    return KinematicChain(tuple(out), base, tool), np.array(flip)


def _rounded(rows: Sequence[DHRow], eps: float) -> list[DHRow]:
    """The rows with each length within ``eps`` of 0 zero and each theta within
    ``ANGLE_ROUNDING`` of a multiple of 90 deg that multiple."""
    return [
        DHRow(_length(row.a, eps), row.alpha, _length(row.d, eps), _right_angle(row.theta), row.kind)
        for row in rows
    ]


def _change(before: Sequence[DHRow], after: Sequence[DHRow]) -> tuple[float, float]:
    """The rows' total change of angle (twists, thetas: rad) and of length (m)."""
    angles = sum(_off(b.alpha, a.alpha) + _off(b.theta, a.theta) for b, a in zip(before, after, strict=True))
    lengths = sum(abs(b.a - a.a) + abs(b.d - a.d) for b, a in zip(before, after, strict=True))
    return angles, lengths


def _length(length: float, eps: float) -> float:
    return 0.0 if abs(length) <= eps else length


def _right_angle(angle: float) -> float:
    nominal = _nearest_right_angle(angle)
    return nominal if _off(angle, nominal) <= ANGLE_ROUNDING else angle


def _offsets_zeroed(rows: list[DHRow]) -> tuple[float, float, list[DHRow]]:
    """A 7-DOF arm's shoulder offset a2 and wrist offset a5 (in the rows of joints 2 and 5; 0 for
    other arms), and the rows with them zero (see the module)."""
    joints = [i for i, row in enumerate(rows) if row.is_joint]
    if len(joints) != 7:
        return 0.0, 0.0, rows
    offsets = [rows[joints[j]].a for j in (1, 4)]
    for j in (1, 4):
        rows[joints[j]] = dataclasses.replace(rows[joints[j]], a=0.0)
    return offsets[0], offsets[1], rows


def _merged(rows: list[DHRow]) -> list[DHRow]:
    """Fixed rows merged into their neighbours where the product allows it (see the module)."""
    out: list[DHRow] = []
    carry = DHRow(kind=JointKind.FIXED)  # a pure Rz Tz waiting for the next row
    for row in rows:
        row = DHRow(row.a, row.alpha, row.d + carry.d, row.theta + carry.theta, row.kind)
        carry = DHRow(kind=JointKind.FIXED)
        if row.is_joint:
            out.append(row)
        elif row.a == 0.0 and row.alpha == 0.0:
            carry = row
        elif row.d == 0.0 and row.theta == 0.0 and out:  # Tx and Rx commute
            last = out[-1]
            out[-1] = DHRow(last.a + row.a, last.alpha + row.alpha, last.d, last.theta, last.kind)
        else:
            out.append(row)
    if carry.d != 0.0 or carry.theta != 0.0:
        out.append(carry)
    return out
