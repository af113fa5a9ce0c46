"""Angles taken to one turn, the package's one place for it (the compiled core's ``om_wrap``,
``csrc/ik/om_math.h``, rounds alike: not at all)."""

from __future__ import annotations

import math

import numpy as np

#: A full turn (rad).
TURN = 2.0 * math.pi


def wrap_angle(angle: float) -> float:
    """The angle's representative in [-pi, pi): ``angle - k TURN``, exactly (``math.fmod`` is
    exact, and so is r -+ TURN for |r| in [pi, TURN)); NaN for an infinite angle."""
    if -math.pi <= angle < math.pi:
        return angle
    if not math.isfinite(angle):
        return math.nan
    r = math.fmod(angle, TURN)
    return r - TURN if r >= math.pi else r + TURN if r < -math.pi else r


def wrap_angles(angles: np.ndarray) -> np.ndarray:
    """:func:`wrap_angle` of each angle."""
    with np.errstate(invalid="ignore"):  # (an infinite angle: NaN)
        r = np.fmod(angles, TURN)
    return np.where(r >= math.pi, r - TURN, np.where(r < -math.pi, r + TURN, r))
