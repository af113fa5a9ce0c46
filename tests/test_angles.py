"""The package's one angle wrap (om_redundant/angles.py, csrc/ik/om_math.h's om_wrap): exact,
into [-pi, pi), the same bits from Python, numpy and the compiled core."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from om_redundant import _core
from om_redundant.angles import TURN, wrap_angle, wrap_angles

pytestmark = pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)

angles = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.floats(-20.0, 20.0),
    st.sampled_from([math.pi, -math.pi, TURN, -TURN, 3 * math.pi, -3 * math.pi, 0.0, -0.0, 5e-324]),
    st.integers(-1000, 1000).map(lambda k: k * math.pi),
    st.integers(-1000, 1000).map(lambda k: math.nextafter(k * math.pi, math.inf)),
)


@given(angles)
def test_an_angle_is_wrapped_exactly_into_one_turn(x):
    """wrap_angle(x) is in [-pi, pi) and differs from x by a whole number of turns (TURN, the
    double 2 pi), exactly; x itself where it is in range; wrap_angles gives the same bits, and
    so does the compiled core (joint_step of one cyclic joint: |wrap(b - a)| for a = 0)."""
    w = wrap_angle(x)
    assert -math.pi <= w < math.pi
    turns = (Fraction(x) - Fraction(w)) / Fraction(TURN)
    assert turns.denominator == 1
    if -math.pi <= x < math.pi:
        assert w == x and math.copysign(1.0, w) == math.copysign(1.0, x)
    (v,) = wrap_angles(np.array([x]))
    assert v == w
    assert _core.joint_step(np.array([True]), np.zeros(1), np.array([x])) == abs(w)


def test_an_angle_that_is_not_finite_wraps_to_nan():
    assert all(math.isnan(wrap_angle(x)) for x in (math.inf, -math.inf, math.nan))
    assert np.isnan(wrap_angles(np.array([math.inf, -math.inf, math.nan]))).all()
