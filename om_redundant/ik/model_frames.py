"""DH frames for the model's derivation: the pose after a run of DH rows, the elementary
rotations, and the exact fit of a quantity that turns with one joint or two."""

from __future__ import annotations

import numpy as np

from .. import _core
from ..exceptions import ModelError
from ..kinematics.arm import Arm
from ..kinematics.chain import DHRow, JointKind, KinematicChain
from .joint_names import joint_name


def pose(table: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation and position of the frame after the rows of a DH table at joint values q."""
    R, p = np.empty((3, 3)), np.empty(3)
    _core.flange(np.ascontiguousarray(table), np.ascontiguousarray(q, dtype=np.float64), R, p)
    return R, p


def rotx(alpha: float) -> np.ndarray:
    """Rotation by alpha about x."""
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotz(theta: float) -> np.ndarray:
    """Rotation by theta about z."""
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def tail_rotation(rows: list[DHRow], last: int) -> np.ndarray:
    """Rotation from the frame after the last joint's Rz(phi) to the flange."""
    tail = [DHRow(alpha=rows[last].alpha, kind=JointKind.FIXED), *rows[last + 1 :]]
    return pose(KinematicChain(tuple(tail)).table, np.zeros(0))[0]


def flange_delta(real: KinematicChain, model: KinematicChain, q: np.ndarray) -> np.ndarray:
    """dp seen from the flange: the model's flange position less the real arm's, in the real
    flange's frame, at q."""
    R, p_real = pose(real.table, q)
    _, p_model = pose(model.table, q)
    return R.T @ (p_model - p_real)


def _harmonics(at) -> np.ndarray:
    """C0, C1, C2 of f(w) = C0 + C1 cos w + C2 sin w from f at 0, 90, 180 and -90 deg."""
    d0, d1, d2, d3 = (at(w) for w in (0.0, np.pi / 2, np.pi, -np.pi / 2))
    return np.array([(d0 + d2) / 2, (d0 - d2) / 2, (d1 - d3) / 2])


def _trig(w: float) -> np.ndarray:
    return np.array([1.0, np.cos(w), np.sin(w)])


def circle_fit(arm: Arm, what: str, joint: int, f) -> np.ndarray:
    """Fit f(q) = C0 + C1 cos q_J + C2 sin q_J exactly from four angles of joint J (f constant
    for J = -1), and check it at random joint vectors."""
    rng = np.random.default_rng(1)
    q = rng.uniform(-np.pi, np.pi, arm.dof)

    def at(w: float) -> np.ndarray:
        if joint >= 0:
            q[joint] = w
        return f(q)

    C = _harmonics(at)
    joints = (joint,) if joint >= 0 else ()
    _check_fit(arm, what, joints, f, lambda q: _trig(q[joint] if joint >= 0 else 0.0) @ C)
    return C


def torus_fit(arm: Arm, what: str, joints: tuple[int, int], f) -> np.ndarray:
    r"""Fit :math:`f(q) = \sum_{ij} C_{ij}\, t_i(q_J)\, t_j(q_K)`, :math:`t = (1, \cos, \sin)`,
    exactly from four angles of each of joints J and K, and check it at random joint vectors:
    (3, 3, ...) coefficients, ``C[i, j]``."""
    J, K = joints
    q = np.random.default_rng(1).uniform(-np.pi, np.pi, arm.dof)

    def at(w: float, v: float) -> np.ndarray:
        q[J], q[K] = w, v
        return f(q)

    C = _harmonics(lambda w: _harmonics(lambda v: at(w, v)))
    _check_fit(arm, what, joints, f, lambda q: np.einsum("i,j,ij...->...", _trig(q[J]), _trig(q[K]), C))
    return C


def _check_fit(arm: Arm, what: str, joints: tuple[int, ...], f, fit) -> None:
    rng = np.random.default_rng(1)
    rng.uniform(-np.pi, np.pi, arm.dof)  # (the draw the fit's q took)
    for _ in range(16):
        q = rng.uniform(-np.pi, np.pi, arm.dof)
        misfit = np.abs(fit(q) - f(q)).max()
        if misfit > 1e-13:
            shape = (
                "constant"
                if not joints
                else "affine in cos and sin of " + " and of ".join(joint_name(arm, j) for j in joints)
            )
            raise ModelError(f"arm '{arm.name}': {what} is not {shape} (off by {misfit:.2g})")
