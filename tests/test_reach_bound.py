"""The bounded search's proof that no island of reach lies between two samples of the circle
that the model does not reach (``csrc/residual.c``, om_srs_reach_possible): the elbow's x(w)
is a trigonometric polynomial of degree 2, so its curvature bounds how far it can come
between two samples. A coarse search, whose cells hide many islands, still finds every root
that a dense one finds; with the islands left unsearched it would not (the Panda then fails
its own self-check at 16 points)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from tests.conftest import random_q

COARSE, DENSE = 16, 1024


def _root_set(solver: om.OMSolver, T: np.ndarray, c: om.Configuration) -> list[tuple[float, ...]]:
    return sorted(tuple(np.round(r.q, 7)) for r in solver.solve_all(T, c))


@pytest.fixture(scope="module", params=["panda", "xarm7", "fr3"])
def solvers(request) -> tuple[om.OMSolver, om.OMSolver]:
    return om.OMSolver(request.param, scan_points=COARSE), om.OMSolver(request.param, scan_points=DENSE)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_a_coarse_search_finds_every_root_of_a_dense_one(solvers, seed):
    coarse, dense = solvers
    q = random_q(coarse.arm, 1, np.random.default_rng(seed))[0]
    T = coarse.arm.fk(q)
    for c in coarse.configurations(coarse.configuration_of(q).redundancy):
        assert _root_set(coarse, T, c) == _root_set(dense, T, c), c
