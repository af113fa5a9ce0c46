"""The check of an answer against MuJoCo's FK of the project's MJCF of the arm."""

from __future__ import annotations

import math
import threading

import mujoco
import numpy as np

import om_redundant as om
from om_redundant.ik import BRANCH_BAND
from om_redundant.ik.families import branch_values, redundancy_values
from om_redundant.mujoco_io.mjcf import DEFAULT_SITE

from .records import (
    FK_ROUNDING,
    ORIENTATION_TOLERANCE,
    POSITION_TOLERANCE,
    REDUNDANCY_TOLERANCE,
    TURN,
    WITHIN_SOLVER,
)


class Checker:
    """Judges a returned joint vector with MuJoCo's FK of the project's MJCF of the arm."""

    def __init__(self, solver: om.OMSolver):
        self.solver = solver
        self.arm = solver.arm
        self.model = om.arm_model(solver.arm)
        self.data = mujoco.MjData(self.model)
        self.site = self.model.site(solver.arm.frame_name or DEFAULT_SITE).id
        self.family, self.params = int(solver.model_arm.family), np.ascontiguousarray(solver.model_arm.params)
        self.n_signs = len(solver.sign_names)
        self.n_redundancy = len(solver.redundancy_names)
        self._lock = threading.Lock()

    def mujoco_pose(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        with self._lock:
            self.data.qpos[:] = q
            mujoco.mj_kinematics(self.model, self.data)
            return self.data.site_xpos[self.site].copy(), self.data.site_xmat[self.site].reshape(3, 3).copy()

    def branch(self, q: np.ndarray) -> np.ndarray:
        out = np.empty(self.n_signs)
        branch_values(self.family, self.params, np.ascontiguousarray(q, dtype=np.float64), out)
        return out

    def redundancy(self, q: np.ndarray) -> np.ndarray:
        out = np.empty(self.n_redundancy)
        if self.n_redundancy:
            redundancy_values(self.family, self.params, np.ascontiguousarray(q, dtype=np.float64), out)
        return out

    def screen(
        self, Q: np.ndarray, Ts: np.ndarray, signs: np.ndarray, red: np.ndarray, within: np.ndarray
    ) -> np.ndarray:
        """Rows that may be wrong, vectorised, at half the tolerances (:meth:`wrong` decides)."""
        m = len(Q)
        P, R = np.empty((m, 3)), np.empty((m, 9))
        for i in range(m):
            self.data.qpos[:] = Q[i]
            mujoco.mj_kinematics(self.model, self.data)
            P[i], R[i] = self.data.site_xpos[self.site], self.data.site_xmat[self.site]
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(Q).all(axis=1)
            bad |= ~(np.linalg.norm(P - Ts[:, :3, 3], axis=1) <= position_tolerance(Ts[:, :3, 3]) / 2)
            chord = np.linalg.norm(R.reshape(m, 3, 3) - Ts[:, :3, :3], axis=(1, 2)) / (2.0 * math.sqrt(2.0))
            bad |= ~(2.0 * np.arcsin(np.minimum(chord, 1.0)) <= ORIENTATION_TOLERANCE / 2)
            B = np.array([self.branch(q) for q in Q]).reshape(m, self.n_signs)
            bad |= ((np.abs(B) > BRANCH_BAND / 2) & (np.where(B > 0, 1, -1) != signs)).any(axis=1)
            if self.n_redundancy:
                got = np.array([self.redundancy(q) for q in Q]).reshape(m, self.n_redundancy)
                d = np.abs(np.remainder(got - red + math.pi, TURN) - math.pi)
                bad |= ~(d <= REDUNDANCY_TOLERANCE / 2).all(axis=1)
            inside = ((self.arm.lower <= Q) & (self.arm.upper >= Q)).all(axis=1)
            bad |= inside != within
        return bad

    def wrong(self, q: np.ndarray, T: np.ndarray, c: om.Configuration, within: bool) -> str | None:
        """Why an ok answer is wrong, or None if it is right."""
        q = np.asarray(q, dtype=np.float64)
        if not np.isfinite(q).all():
            return "q is not finite"
        p, R = self.mujoco_pose(q)
        dp = float(np.linalg.norm(p - T[:3, 3]))
        solver_position, orientation_tolerance = self.solver.tolerances
        if not dp <= position_tolerance(T[:3, 3]):
            size = float(np.linalg.norm(T[:3, 3]))
            within = f"; {WITHIN_SOLVER}" if dp <= solver_position else ""
            return f"MuJoCo's FK misses the position by {dp:.3e} m (|p| = {size:.3g} m{within})"
        chord = float(np.linalg.norm(R - T[:3, :3])) / (2.0 * math.sqrt(2.0))
        angle = 2.0 * math.asin(min(1.0, chord))
        if not angle <= ORIENTATION_TOLERANCE:
            within = (
                f" ({WITHIN_SOLVER} {orientation_tolerance:g} rad)" if angle <= orientation_tolerance else ""
            )
            return f"MuJoCo's FK misses the orientation by {angle:.3e} rad{within}"
        for i, (b, s) in enumerate(zip(self.branch(q), c.signs, strict=True)):
            if abs(b) > BRANCH_BAND and (1 if b > 0 else -1) != s:
                return f"branch {self.solver.sign_names[i]} is {b:.3e}, sign {s:+d} requested"
        if not self.solver.holds(q, c):  # the branches hold: psi, read in the requested ELBOW branch
            got = self.redundancy(q)
            return f"redundancy is {list(map(float, got))} (q's own branch), {list(c.redundancy)} requested"
        inside = bool(np.all((self.arm.lower <= q) & (q <= self.arm.upper)))
        if bool(within) != inside:
            return f"within_limits is {bool(within)}, q is {'inside' if inside else 'outside'} the limits"
        return None


def position_tolerance(p: np.ndarray) -> np.ndarray | float:
    """The check's position tolerance at the target position(s) p (last axis 3), in m."""
    return np.maximum(POSITION_TOLERANCE, FK_ROUNDING * np.linalg.norm(p, axis=-1))


def angle_distance(a: float, b: float) -> float:
    """|a - b| modulo 2 pi, each angle reduced exactly first."""
    return abs(math.remainder(math.remainder(a, TURN) - math.remainder(b, TURN), TURN))
