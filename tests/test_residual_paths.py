"""The circle residual's shortcut (``csrc/ik/srs.c``, om_srs_model_q7): q7 alone, without the
wrist's other Euler angles, equals the closed form's q7."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from om_redundant import _core
from om_redundant._core import FlangeTarget, srs_model_q7
from om_redundant._core import flange as flange_kernel
from om_redundant.ik import derive_model
from om_redundant.ik.families import REACH_SLACK, branch_values, model_ik, redundancy_values
from tests.conftest import random_q, wrap


@pytest.mark.parametrize("name", ["panda", "fr3", "xarm7", "sawyer"])
@settings(max_examples=200, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    shift=st.floats(0.0, 0.1),
    wrist=st.sampled_from([None, 0.0, 1e-14, 1e-9, 1e-4, 9e-4, 2e-3, 1e-2]),
)
def test_q7_alone_equals_the_closed_form(name, seed, shift, wrist):
    """At the model's pose of a random q (the wrist at or near its singularity where asked,
    on both sides of the 1e-3 below which the closed form decides), moved by up to 0.1 m as
    the residual moves p_m: the same reach margin, bit for bit, the same q7 to 1e-12 rad,
    and no other joint written."""
    om_arm = derive_model(om.load_arm(name))
    P, table = om_arm.params, om_arm.model.chain.table
    rng = np.random.default_rng(seed)
    q = random_q(om_arm.real, 1, rng)[0]
    if wrist is not None:  # sin(q6 + theta6) = wrist
        q[5] = wrist - P[_core.SRS_THETA + 5]
    R, p = np.empty((3, 3)), np.empty(3)
    flange_kernel(table, q, R, p)
    p = p + shift * rng.standard_normal(3)
    values, psi = np.empty(3), np.empty(1)
    branch_values(om_arm.family, P, q, values)
    redundancy_values(om_arm.family, P, q, psi)
    signs = np.where(values < 0, -1, 1)
    q_prev = rng.uniform(-np.pi, np.pi, 7)
    full, alone = np.empty(7), np.full(7, np.nan)
    margin = model_ik(om_arm.family, P, table, R, p, signs, psi, q_prev, full)
    target = FlangeTarget(R, p, signs.astype(np.int64), psi)
    assert srs_model_q7(P, target, q_prev, alone) == margin
    assert np.isnan(alone[:6]).all()
    if margin >= -REACH_SLACK:
        assert abs(wrap(alone[6] - full[6])) < 1e-12
    else:
        assert np.isnan(alone[6])
