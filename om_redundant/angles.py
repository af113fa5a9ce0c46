"""Angles taken to one turn, the package's one place for it.

Two roundings, each kept where answers are compared to the bit: :func:`wrap_angle` is exact
(``math.remainder``) for one angle; :func:`wrap_angles` is numpy's ``remainder(x + pi, 2 pi) -
pi`` for arrays, which the compiled core's ``om_wrap_angle`` rounds alike (the paths it follows
and the ones Python checks must agree). They differ in the last bits only.
"""

from __future__ import annotations

import math

import numpy as np

#: A full turn (rad).
TURN = 2.0 * math.pi


def wrap_angle(angle: float) -> float:
    """The angle's representative in [-pi, pi) (``math.remainder`` gives [-pi, pi])."""
    angle = math.remainder(angle, TURN)
    return -math.pi if angle >= math.pi else angle


def wrap_angles(angles: np.ndarray) -> np.ndarray:
    """Each angle taken to [-pi, pi), as ``numpy.remainder(x + pi, 2 pi) - pi`` rounds it."""
    return np.remainder(angles + math.pi, TURN) - math.pi
