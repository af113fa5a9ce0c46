"""The inputs of the attack classes: random q, q at a branch boundary, next to psi's half-line, at limits."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from om_redundant import _core

from ..robots import random_joints
from .records import CROSSING_GRID, TURN


class PoseDraws:
    """The poses an :class:`~benchmarks.adversarial.arm_run.ArmRun` draws: random, at a branch
    boundary, next to the arm angle's singular half-line, at the joint limits. Needs ``solver``,
    ``arm``, ``checker``, ``rng`` and ``limited`` (the joints with both limits) on the instance."""

    def random_q(self, n: int) -> np.ndarray:
        return random_joints(self.arm, n, self.rng)

    def boundary_q(self, index: int, value: float) -> np.ndarray | None:
        """A random q moved along one joint so that branch quantity ``index`` is ``value``.

        The joints are tried in order of the quantity's slope at q. On each, b_index - value is
        sampled at :data:`CROSSING_GRID` points over the joint's range (its limits; one turn
        around q_j for an unlimited joint), one of the sign changes is drawn at random and
        bisected down to adjacent doubles, and the end whose branch quantity has value's sign
        and is nearest it is kept. So every crossing within the limits can be drawn (also
        those next to a limit), and the branch quantity is value to its last bits (at 1e-14 a
        joint near pi resolves it to 4 %: the decade table reads the value made). None if no
        joint crosses value within its limits (a new random q is drawn then).
        """
        q = self.random_q(1)[0]
        slopes = np.empty(self.arm.dof)
        for j in range(self.arm.dof):
            e = np.zeros(self.arm.dof)
            e[j] = 1e-6
            slopes[j] = abs(self.checker.branch(q + e)[index] - self.checker.branch(q - e)[index])
        for j in np.argsort(-slopes, kind="stable"):
            if not slopes[j] > 0.0:
                break
            found = self._crossing(q, int(j), index, value)
            if found is not None:
                return found
        return None

    def _crossing(self, q: np.ndarray, j: int, index: int, value: float) -> np.ndarray | None:
        """q with joint j at a random crossing of b_index = value within j's range, or None."""
        lo = self.arm.lower[j] if math.isfinite(self.arm.lower[j]) else q[j] - math.pi
        hi = self.arm.upper[j] if math.isfinite(self.arm.upper[j]) else q[j] + math.pi
        x = q.copy()

        def f(t: float) -> float:
            x[j] = t
            return float(self.checker.branch(x)[index]) - value

        grid = np.linspace(lo, hi, CROSSING_GRID)
        fs = np.array([f(t) for t in grid])
        cells = np.flatnonzero(np.sign(fs[:-1]) * np.sign(fs[1:]) <= 0.0)
        if not len(cells):
            return None
        k = int(self.rng.choice(cells))
        a, b, fa = float(grid[k]), float(grid[k + 1]), float(fs[k])
        ends = [(abs(fa), a), (abs(float(fs[k + 1])), b)]
        while True:
            m = 0.5 * (a + b)
            if not a < m < b:
                break
            fm = f(m)
            ends.append((abs(fm), m))
            if fm == 0.0:
                break
            if (fm < 0.0) == (fa < 0.0):
                a, fa = m, fm
            else:
                b = m
        for _, t in sorted(ends):
            x[j] = t
            if float(self.checker.branch(x)[index]) * value > 0.0:
                return x
        return None

    def near_arm_angle_line(self, delta: float, side: float) -> np.ndarray | None:
        """A random q (7-DOF) whose model's shoulder-wrist direction w_hat is at the angle delta
        from the arm angle's singular half-line w_hat = -up (``side`` -1: the wrist centre
        straight below the shoulder, where the reference n(w_hat) = R(up -> w_hat) r is
        undefined) or from w_hat = +up (``side`` +1). Gauss-Newton on joints 2-7, within the
        limits, for the part of w across up equal to delta |w| in a random direction; None if
        it does not get within half of that.
        """
        up, across, w = self._arm_angle_frame()
        q = self.random_q(1)[0]
        angle = self.rng.uniform(0.0, TURN)
        direction = np.array([math.cos(angle), math.sin(angle)])
        steps = 1e-7 * np.eye(self.arm.dof)[1:]
        for _ in range(40):
            v = w(q)
            length = float(np.linalg.norm(v))
            miss = across @ v - delta * length * direction
            if np.abs(miss).max() <= 0.5 * delta * length:
                return q if side * float(v @ up) > 0.0 else None
            J = (across @ (w(q + steps) - w(q - steps)).T) / 2e-7
            q[1:] = np.clip(
                q[1:] + np.linalg.lstsq(J, -miss, rcond=None)[0], self.arm.lower[1:], self.arm.upper[1:]
            )
        return None

    def _arm_angle_frame(self) -> tuple[np.ndarray, np.ndarray, Callable[[np.ndarray], np.ndarray]]:
        """The model's up axis, two unit vectors across it, and w(Q): W - S of the model at Q,
        all in DH frame 0 (where the kernels' up, shoulder and flange-frame wrist offset are;
        the model's FK is in the root frame, turned on the Gen3: z down)."""
        model, P, data = self.solver.model_arm.model, self.solver.model_arm.params, self.solver.solver_data()
        up = P[_core.SRS_UP : _core.SRS_UP + 3]
        e1 = np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        wrist = P[_core.SRS_WRIST : _core.SRS_WRIST + 3]
        shoulder = P[_core.SRS_SHOULDER : _core.SRS_SHOULDER + 3]

        def w(Q: np.ndarray) -> np.ndarray:
            T = data.T_base_root @ model.fk(Q) @ data.T_tool_flange  # the flange in DH frame 0
            return T[..., :3, 3] + T[..., :3, :3] @ wrist - shoulder

        return up, np.array([e1, np.cross(up, e1)]), w

    def arm_angle_line_angle(self, q: np.ndarray, side: float) -> float:
        """The angle of the model's w_hat at q from side * up."""
        up, across, w = self._arm_angle_frame()
        v = w(q)
        return math.atan2(float(np.linalg.norm(across @ v)), side * float(v @ up))

    def at_limits(self) -> np.ndarray | None:
        """A random q with some limited joints at a limit +- 1e-12."""
        if not len(self.limited):
            return None
        q = self.random_q(1)[0]
        joints = self.rng.choice(
            self.limited, size=int(self.rng.integers(1, len(self.limited) + 1)), replace=False
        )
        for j in joints:
            limit = self.arm.lower[j] if self.rng.random() < 0.5 else self.arm.upper[j]
            q[j] = limit + (1e-12 if self.rng.random() < 0.5 else -1e-12)
        return q
