"""A peer's forward kinematics checked against ``arm.fk`` before any of its numbers is trusted."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

import om_redundant as om

from .joints import random_joints
from .transforms import pose_errors


@dataclass(frozen=True)
class FKCheck:
    """A peer's forward kinematics against ``arm.fk`` on random joint vectors.

    Attributes:
        peer: Peer name.
        arm: Arm name.
        samples: Number of joint vectors compared.
        position_error: Largest position difference (m).
        orientation_error: Largest rotation angle between the frames (rad).
        tolerance: The bound both must meet.
    """

    peer: str
    arm: str
    samples: int
    position_error: float
    orientation_error: float
    tolerance: float

    @property
    def passed(self) -> bool:
        return bool(self.position_error <= self.tolerance and self.orientation_error <= self.tolerance)

    def line(self) -> str:
        verdict = "ok" if self.passed else "REFUSED"
        return (
            f"FK {self.peer} on {self.arm}: max |dp| {self.position_error:.1e} m, max angle "
            f"{self.orientation_error:.1e} rad over {self.samples} q (tol {self.tolerance:.0e}): {verdict}"
        )


def check_fk(
    peer: str,
    arm: om.Arm,
    fk: Callable[[np.ndarray], np.ndarray],
    rng: np.random.Generator,
    samples: int = 64,
    tolerance: float = 1e-9,
) -> FKCheck:
    """Compare ``fk(q)`` (a 4x4 pose of the arm's end effector in its root) with ``arm.fk(q)``."""
    Q = random_joints(arm, samples, rng)
    peer_T = np.array([fk(q) for q in Q])
    position, angle = pose_errors(peer_T, arm.fk(Q))
    return FKCheck(peer, arm.name, samples, float(position.max()), float(angle.max()), tolerance)
