r"""Offset modification: the model arm of a real arm, and the position difference dp.

The model keeps every rotation of the real arm (twists and joint offsets theta) and zeroes
the few lengths that stand in the way of a closed form:

* 6-DOF arms satisfying the paper's Theorem 2 (joints 1-3 position joint 4's origin; joints
  4-6 revolute, non-parallel, not intersecting): :math:`a_4, a_5, d_5` (standard DH,
  joint-indexed rows), which makes the wrist spherical.
* 7-DOF arms: :math:`a_1, d_2` (shoulder offsets, Gen3 and Sawyer) and
  :math:`a_5, a_6, d_6` (wrist offsets), which make the shoulder and the wrist spherical
  while the elbow keeps its offsets (a Hollerbach arm, see :mod:`om_redundant.ik.families.srs`).

For equal joints the hand orientations agree and the positions differ by

.. math::

    \Delta p(q) = p_{model}(q) - p_{real}(q) = R_{flange}(q)\,\delta(q_J) + a(q_1),

where :math:`\delta`, the wrist offsets' dp seen from the flange, depends on one wrist joint
J: joint 6 of UR5e and the Spherical arm (:math:`a_4 = 0`), joint 7 of the 7-DOF arms (the
iiwa14 has :math:`\delta = 0`). A 6-DOF wrist with :math:`a_4 \ne 0` (Menagerie's ARX L5,
Unitree Z1, i2rt YAM) makes :math:`\delta` depend on joints 5 and 6; where joint 4's axis
turns with q1 alone (joints 2, 3 and 4 parallel), dp at a solution is a function of q1 and
the target's orientation instead (:func:`~om_redundant.ik.six_dof_model.wrist_offset`): the
solutions again lie on a circle, in :math:`w = q_1`; where joint 4 lies across joint 2 (a
PUMA-like wrist, the Reach Bravo 7) they lie on the torus :math:`(q_5, q_6)`
(:func:`~om_redundant.ik.six_dof_model.wrist_torus`). The shoulder offsets' dp :math:`a(q_1)`, in DH frame 0,
turns with joint 1 alone, because :math:`a_1` lies along :math:`x_1` and :math:`d_2` along
joint 2's axis, both fixed in frame 1; it is zero when joints 1-3 meet. The solutions of
the OM system (9) then lie on a circle (a torus with shoulder offsets) in the ball
:math:`|p_m - p_d| \le \Delta p_{max}`, which the solver searches exhaustively.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core
from ..exceptions import ModelError
from ..kinematics.arm import Arm
from ..kinematics.chain import KinematicChain
from ..validation import as_instance
from .joint_names import joint_name, joints_named, row_name
from .model_conditions import LENGTH_ROUNDING, rounding_length
from .model_frames import circle_fit, flange_delta, pose
from .six_dof_model import six_dof_model
from .srs_model import srs_model


@dataclass(frozen=True, eq=False)
class ModelArm:
    """The closed-form model of a real arm.

    Attributes:
        real: The real arm.
        model: The offset-modified arm (same joints, names, limits, base and tool).
        family: Closed-form family code (see :mod:`om_redundant.ik.families`).
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
        wrist_torus: (3, 3, 3) coefficients of dp seen from the flange of a PUMA-like 6-DOF wrist
            (:math:`a_4 \\ne 0`, joint 4 across joint 2), which turns with q5 and q6
            (:func:`~om_redundant.ik.six_dof_model.wrist_torus`): its solutions lie on the torus
            :math:`(q_5, q_6)`; ``dp_joint`` is then -1 and ``delta`` and ``shoulder`` zero.
            None for every other arm.
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
    wrist_torus: np.ndarray | None = None

    def dp(self, q: np.ndarray) -> np.ndarray:
        """Position difference model minus real, in the root frame: (3,) or (M, 3)."""
        return self.model.fk(q)[..., :3, 3] - self.real.fk(q)[..., :3, 3]


def derive_model(arm: Arm) -> ModelArm:
    """Derive the closed-form model arm of a real arm.

    6-DOF arms get a spherical-wrist model (Theorem 2); 7-DOF arms a Hollerbach model with a
    spherical shoulder and wrist (:mod:`om_redundant.ik.families.srs`), keeping the elbow's
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
        model_chain, family, family_name, params, wrist_torus = six_dof_model(arm)
        shoulderless = arm.chain
        sign_names, redundancy_names = ("ARM", "ELBOW", "WRIST"), ()
    elif arm.dof == 7:
        model_chain, shoulderless, params = srs_model(arm)
        wrist_torus = None
        family, family_name = _core.SRS, "S-R-S: spherical shoulder, elbow, spherical wrist"
        sign_names, redundancy_names = ("SHOULDER", "ELBOW", "WRIST"), ("psi",)
    else:
        above = (
            f"; if the arm starts after {joint_name(arm, arm.dof - 8)} (joints of a torso or a mobile base "
            "before it), import it from the body that joint moves as the root (import-arm --root BODY)"
            if arm.dof > 7
            else ""
        )
        raise ModelError(f"arm '{arm.name}' has {arm.dof} joints; models exist for 6- and 7-DOF arms{above}")
    model = arm.with_chain(model_chain, f"{arm.name}-model")
    if arm.dof == 6 and (params[_core.SD_WRIST_OFFSET] != 0.0 or wrist_torus is not None):
        # a4 != 0: dp turns with q1 (see wrist_offset) or with q5 and q6 (see wrist_torus);
        # dp = -(a4 x4 + d5 z4 + a5 x5), x4 normal to z4
        rows, jr = arm.chain.rows, arm.chain.joint_rows
        dp_joint, delta, shoulder = 0 if wrist_torus is None else -1, np.zeros((3, 3)), np.zeros((3, 3))
        dp_max = float(np.hypot(rows[jr[3]].a, rows[jr[4]].d) + abs(rows[jr[4]].a))
    else:
        dp_joint = _dp_joint(arm, shoulderless, model_chain)
        delta = circle_fit(
            arm, "dp seen from the flange", dp_joint, lambda q: flange_delta(shoulderless, model_chain, q)
        )
        shoulder = circle_fit(
            arm,
            "the shoulder offsets' dp",
            0,
            lambda q: pose(shoulderless.table, q)[1] - pose(arm.chain.table, q)[1],
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
        wrist_torus,
    )


def _refuse_rounding(arm: Arm) -> None:
    """Raise :class:`ModelError` at the first nonzero DH length within rounding of zero: the
    closed forms would take it for geometry (an offset that changes the family or the search)
    or drop it (an answer off by it); the nominal arm has it zero."""
    eps = rounding_length(arm.chain)
    for i, row in enumerate(arm.chain.rows):
        for key, value in (("a", row.a), ("d", row.d)):
            if 0.0 < abs(value) <= eps:
                raise ModelError(
                    f"arm '{arm.name}': {key} = {value:.3g} m in {row_name(arm, i)} is rounding of 0 "
                    f"(within {LENGTH_ROUNDING:g} m per metre of reach, {eps:.2g} m), not geometry"
                )


def _dp_joint(arm: Arm, real: KinematicChain, model: KinematicChain) -> int:
    """The joint that delta (dp in the flange frame) depends on; -1 if it is constant."""
    rng = np.random.default_rng(0)
    dependent = set()
    for _ in range(8):
        q = rng.uniform(-np.pi, np.pi, real.dof)
        base = flange_delta(real, model, q)
        for j in range(real.dof):
            moved = q.copy()
            moved[j] += rng.uniform(0.3, 2.0)
            if np.abs(flange_delta(real, model, moved) - base).max() > 1e-12:
                dependent.add(j)
    if len(dependent) > 1:
        zeroed = [
            f"{key} = {getattr(row, key):g} m in {row_name(arm, i)}"
            for i, (row, kept) in enumerate(zip(real.rows, model.rows, strict=True))
            for key in ("a", "d")
            if getattr(row, key) != getattr(kept, key)
        ]
        raise ModelError(
            f"arm '{arm.name}': dp seen from the flange (of the offsets the model zeroes: "
            f"{', '.join(zeroed)}) depends on {joints_named(arm, sorted(dependent))}; the bounded search "
            "handles one"
        )
    return dependent.pop() if dependent else -1
