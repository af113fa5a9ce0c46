"""The hinted solve's window on the circle (csrc/ik/search.c, om_nearest_in_window): sampled as
finely as the whole circle's scan (3 points at least), the root found not refined to again; the
root returned is at least as near the hint as every root of solve_all. (The torus' window:
tests/test_shoulder_wrist_offsets.py.)"""

from __future__ import annotations

from functools import cache

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.near_family import bent
from tests.conftest import check_hinted_nearest, random_q

ARMS = (("ur5e", None), ("panda", None), ("xarm7", None), ("ur5e", 1e-3), ("panda", 1e-3))


@cache
def solver_of(name: str, twist: float | None) -> om.OMSolver:
    arm = om.load_arm(name)
    return om.OMSolver(arm if twist is None else bent(arm, twist, np.random.default_rng(0)))


@settings(max_examples=15, deadline=None)
@given(arm=st.sampled_from(ARMS), q_seed=st.integers(0, 2**32 - 1), sigma=st.sampled_from((0.01, 0.1, 0.5)))
def test_the_hinted_solve_returns_the_root_nearest_the_hint(arm, q_seed, sigma):
    """At random q (5 per example): hints sigma from q, and 0.3 and 0.45 of the way from each
    root of solve_all(fk(q), c) to each other root within 0.8 rad (the window then reaches past
    the root found, whose neighbours it must find)."""
    solver = solver_of(*arm)
    rng = np.random.default_rng(q_seed)
    for q in random_q(solver.arm, 5, rng):
        check_hinted_nearest(solver, q, rng, sigma, within=0.8)
