"""frankik, the closed form of the Franka arms."""

from __future__ import annotations

from typing import Any

import numpy as np

import om_redundant as om

from ..robots import (
    home_joints,
    rot_z,
)
from .base import Method, Peer, Unavailable, _rows


def frankik_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """frankik (He and Liu's analytic Franka IK, q7 given), Franka arms only.

    frankik's ``fk`` returns the hand's TCP (flange, Rz(-45 deg), 0.1034 m along z) but its
    ``ik`` takes the flange pose: the adapter maps both to the arm file's frame, with the
    constant offset measured once at q = 0 and then checked on random q.
    """
    try:
        import frankik
    except ImportError as exc:
        raise Unavailable(f"not installed ({exc})") from exc
    if arm.name not in ("panda", "fr3"):
        raise Unavailable("Franka arms only")
    is_fr3 = arm.name == "fr3"
    kinematics = frankik.FrankaKinematics(frankik.RobotType.FR3 if is_fr3 else frankik.RobotType.PANDA)
    hand = rot_z(-np.pi / 4) @ _translation_z(0.1034)
    zero = np.zeros(7)
    # ik frame in the arm file's end-effector frame.
    offset = np.linalg.inv(arm.fk(zero)) @ frankik.fk(zero) @ np.linalg.inv(hand)
    home = home_joints(arm)

    def exact_rows(_: Any, result: np.ndarray) -> np.ndarray:
        return _rows(result, 7)

    exact = Method(
        lambda T, q: (T @ offset, home, float(q[6])),
        lambda argument: frankik.ik_full(*argument, is_fr3=is_fr3),
        exact_rows,
    )
    return Peer(
        "frankik",
        arm,
        lambda q: frankik.fk(np.asarray(q, dtype=float)) @ np.linalg.inv(hand) @ np.linalg.inv(offset),
        "ik_full with q7 given (returns in-limit solutions only); any: FrankaKinematics.inverse "
        "(q7 sampled by the library), q0 = home",
        exact=exact,
        any=Method(
            lambda T, _: T @ offset,
            lambda target: kinematics.inverse(target, q0=home),
            lambda _, q: _rows(q, 7),
        ),
        every=exact,
    )


def _translation_z(z: float) -> np.ndarray:
    T = np.eye(4)
    T[2, 3] = z
    return T
