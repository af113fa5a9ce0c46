r"""Offset modification: the model arm of a real arm, and the position difference dp.

For a 6-DOF arm satisfying the paper's Theorem 2 (joints 1-3 position joint 4's origin;
joints 4-6 revolute, non-parallel, not intersecting) the model zeroes :math:`a_4, a_5, d_5`
(standard DH, joint-indexed rows), which makes the wrist spherical. Both arms share all
rotations, so for equal joints the hand orientations agree and the positions differ by

.. math::

    \Delta p(q) = p_{model}(q) - p_{real}(q) = R_{flange}(q)\,\delta(q_J),

where :math:`\delta`, dp seen from the flange, depends on a few wrist joints J only. For
Theorem-2 arms with :math:`a_4 = 0` (UR5e, the Spherical arm), J is joint 6 alone and
:math:`|\delta| = \sqrt{d_5^2 + a_5^2}`: the solutions of the OM system (9) lie on a circle
in the ball :math:`|p_m - p_d| \le \Delta p_{max}`, which the solver scans exhaustively.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .arm import Arm
from .closed_form import six_dof
from .exceptions import ModelError
from .kinematics import DHRow, JointKind, KinematicChain, flange_kernel

_ANGLE_EPS = 1e-9


@dataclass(frozen=True, eq=False)
class ModelArm:
    """The closed-form model of a real arm.

    Attributes:
        real: The real arm.
        model: The offset-modified arm (same joints, names, limits, base and tool).
        family: Closed-form family code (see :mod:`om_redundant.closed_form`).
        family_name: Human-readable family name.
        params: Parameter vector of the family kernel.
        sign_names: Names of the configuration's branch signs.
        dp_joint: Index of the joint that :math:`\\delta` depends on, or -1 for none.
        dp_max: :math:`\\max_q |\\Delta p(q)|` in metres.
    """

    real: Arm
    model: Arm
    family: int
    family_name: str
    params: np.ndarray
    sign_names: tuple[str, ...]
    dp_joint: int
    dp_max: float

    def dp(self, q: np.ndarray) -> np.ndarray:
        """Position difference model minus real, in the root frame: (3,) or (M, 3)."""
        return self.model.fk(q)[..., :3, 3] - self.real.fk(q)[..., :3, 3]


def derive_model(arm: Arm) -> ModelArm:
    """Derive the closed-form model arm of a real arm.

    Raises:
        ModelError: The arm violates a condition of Theorem 2 or matches no family; the
            message names the condition.
    """
    if arm.dof != 6:
        raise ModelError(
            f"arm '{arm.name}' has {arm.dof} joints; the offset-modified model is built for "
            "6-DOF arms (Theorem 2)"
        )
    rows = list(arm.chain.rows)
    jr = arm.chain.joint_rows
    for j in (3, 4, 5):
        if rows[jr[j]].kind is not JointKind.REVOLUTE:
            raise ModelError(f"arm '{arm.name}': Theorem 2 C3 needs joint {j + 1} revolute")
    if jr[5] - jr[3] != 2:
        raise ModelError(f"arm '{arm.name}': fixed rows between the wrist joints are not supported")
    for j in (3, 4):
        if abs(np.sin(rows[jr[j]].alpha)) < _ANGLE_EPS:
            raise ModelError(
                f"arm '{arm.name}': Theorem 2 C3 needs wrist joints {j + 1} and {j + 2} non-parallel "
                f"(alpha_{j + 1} = {np.degrees(rows[jr[j]].alpha):g} deg)"
            )
        if abs(abs(np.sin(rows[jr[j]].alpha)) - 1.0) > _ANGLE_EPS:
            raise ModelError(
                f"arm '{arm.name}': the spherical-wrist closed form needs alpha_{j + 1} = +-90 deg, "
                f"got {np.degrees(rows[jr[j]].alpha):g} deg"
            )
    if abs(rows[jr[3]].a) > 0.0:
        raise ModelError(
            f"arm '{arm.name}': a4 = {rows[jr[3]].a:g} != 0 makes dp depend on joints 5 and 6; "
            "the bounded search handles arms whose dp depends on one wrist joint"
        )
    rows[jr[3]] = dataclasses.replace(rows[jr[3]], a=0.0)
    rows[jr[4]] = dataclasses.replace(rows[jr[4]], a=0.0, d=0.0)
    model_chain = arm.chain.replace_rows(rows)
    family, family_name, params = _position_family(arm.name, rows, jr)
    params[six_dof.WRIST_ROW] = jr[3]
    for key, j in ((six_dof.SIGMA4, 3), (six_dof.SIGMA5, 4)):
        params[key] = np.sign(np.sin(rows[jr[j]].alpha))
    for key, j in ((six_dof.THETA4, 3), (six_dof.THETA5, 4), (six_dof.THETA6, 5)):
        params[key] = rows[jr[j]].theta
    # E: from the frame after Rz(phi6) to the flange (row 6's twist and fixed rows after it).
    tail = [dataclasses.replace(rows[jr[5]], theta=0.0, d=0.0, kind=JointKind.FIXED), *rows[jr[5] + 1 :]]
    R_tail, _ = _pose(KinematicChain(tuple(tail)).table, np.zeros(0))
    params[six_dof.E_ROT : six_dof.E_ROT + 9] = R_tail.ravel()
    # Wrist centre in the flange frame: origin of joint 5's frame, the same for any q.
    q0 = np.zeros(6)
    _, o4 = _pose(model_chain.table[: jr[3] + 1], q0[:4])
    R_fl, p_fl = _pose(model_chain.table, q0)
    params[six_dof.WRIST_CENTRE : six_dof.WRIST_CENTRE + 3] = R_fl.T @ (o4 - p_fl)

    model = arm.with_chain(model_chain, f"{arm.name}-model")
    dp_joint = _dp_joint(arm.chain, model_chain)
    dp_max = _dp_max(arm.chain, model_chain, dp_joint)
    return ModelArm(arm, model, family, family_name, params, ("ARM", "ELBOW", "WRIST"), dp_joint, dp_max)


def _position_family(name: str, rows: list[DHRow], jr: list[int]) -> tuple[int, str, np.ndarray]:
    r1, r2, r3, r4 = (rows[jr[j]] for j in range(4))
    P = np.zeros(six_dof.N_PARAMS)
    if r1.kind is not JointKind.REVOLUTE or r2.kind is not JointKind.REVOLUTE:
        raise ModelError(f"arm '{name}': joints 1 and 2 must be revolute for a closed-form model")
    if abs(abs(np.sin(r1.alpha)) - 1.0) > _ANGLE_EPS or jr[1] != jr[0] + 1 or jr[0] != 0:
        raise ModelError(f"arm '{name}': joint 1 must be perpendicular to joint 2 (alpha_1 = +-90 deg)")
    P[six_dof.A1], P[six_dof.D1], P[six_dof.THETA1] = r1.a, r1.d, r1.theta
    P[six_dof.SIGMA1] = np.sign(np.sin(r1.alpha))
    P[six_dof.A2], P[six_dof.THETA2] = r2.a, r2.theta
    between = rows[jr[2] + 1 : jr[3]]
    if any(r.a != 0.0 or r.d != 0.0 for r in between):
        raise ModelError(f"arm '{name}': fixed rows between joints 3 and 4 must be pure rotations")
    if r3.kind is JointKind.REVOLUTE and abs(np.sin(r2.alpha)) < _ANGLE_EPS and not between:
        if abs(r2.a) < _ANGLE_EPS:
            raise ModelError(f"arm '{name}': a2 = 0 leaves joints 2 and 3 without a link")
        P[six_dof.LATERAL] = np.cos(r2.alpha) * r2.d + r3.d + r4.d * np.cos(r3.alpha)
        planar = np.array([r3.a, -r4.d * np.sin(r3.alpha)])
        P[six_dof.ELL3] = np.linalg.norm(planar)
        P[six_dof.BETA] = np.arctan2(planar[1], planar[0])
        P[six_dof.THETA3] = r3.theta
        if np.cos(r2.alpha) < 0.0:
            raise ModelError(f"arm '{name}': alpha_2 = 180 deg is not supported")
        return six_dof.RRR_SPHERICAL_WRIST, "RRR + spherical wrist (parallel joints 2, 3)", P
    if r3.kind is JointKind.PRISMATIC and abs(abs(np.sin(r2.alpha)) - 1.0) < _ANGLE_EPS:
        if r3.a != 0.0 or r4.d != 0.0:
            raise ModelError(f"arm '{name}': RRP family needs a3 = 0 and d4 = 0")
        P[six_dof.LATERAL] = r2.d
        P[six_dof.SIGMA2] = np.sign(np.sin(r2.alpha))
        P[six_dof.D3] = r3.d
        return six_dof.RRP_SPHERICAL_WRIST, "RRP + spherical wrist", P
    raise ModelError(
        f"arm '{name}': joints 1-3 match no closed-form family (RRR with parallel joints 2 and 3, "
        "or RRP); Theorem 2 C2 cannot be used here"
    )


def _pose(table: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    R, p = np.empty((3, 3)), np.empty(3)
    flange_kernel(np.ascontiguousarray(table), q, R, p)
    return R, p


def _delta(real: KinematicChain, model: KinematicChain, q: np.ndarray) -> np.ndarray:
    R, p_real = _pose(real.table, q)
    _, p_model = _pose(model.table, q)
    return R.T @ (p_model - p_real)


def _dp_joint(real: KinematicChain, model: KinematicChain) -> int:
    """The joint that delta (dp in the flange frame) depends on; -1 if it is constant."""
    rng = np.random.default_rng(0)
    dependent = set()
    for _ in range(8):
        q = rng.uniform(-np.pi, np.pi, real.dof)
        base = _delta(real, model, q)
        for j in range(real.dof):
            moved = q.copy()
            moved[j] += rng.uniform(0.3, 2.0)
            if np.abs(_delta(real, model, moved) - base).max() > 1e-12:
                dependent.add(j)
    if len(dependent) > 1:
        raise ModelError(f"dp depends on joints {sorted(d + 1 for d in dependent)}; one is supported")
    return dependent.pop() if dependent else -1


def _dp_max(real: KinematicChain, model: KinematicChain, dp_joint: int) -> float:
    q = np.zeros(real.dof)
    if dp_joint < 0:
        return float(np.linalg.norm(_delta(real, model, q)))
    norms = []
    for w in np.linspace(-np.pi, np.pi, 721):
        q[dp_joint] = w
        norms.append(np.linalg.norm(_delta(real, model, q)))
    return float(max(norms))
