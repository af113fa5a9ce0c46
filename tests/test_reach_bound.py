"""The bounded search's proof that no island of reach lies between two samples of the circle
that the model does not reach (``csrc/ik/residual.c``, om_srs_reach_possible): the elbow's x(w)
is a trigonometric polynomial of degree 2, so its curvature bounds how far it can come
between two samples. A coarse search, whose cells hide many islands, still finds every root
that a dense one finds; with the islands left unsearched it would not (the Panda then fails
its own self-check at 16 points).

Close roots inside one cell (``csrc/ik/circle_runs.c``, _cell_roots): a cell is halved where the
curvature of g estimated from the samples allows g to turn back to zero inside it, so a
search at 16 points holds q where close pairs and triples share its cells."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from tests.conftest import random_q

COARSE, DENSE = 16, 1024

#: random_q(arm, 1, default_rng(seed)) whose root shared a 16-point cell with one or two
#: others (a pair 3e-3 rad apart next to a third root; a root 0.08 rad from another): the
#: search at 16 points missed q before cells were halved by their curvature.
CLOSE_ROOTS = [
    ("xarm7", 68382241),
    ("xarm7", 2703885895),
    ("xarm7", 182082446),
    ("panda", 3235945719),
    ("fr3", 2557913823),
    ("fr3", 3671483605),
    ("fr3", 1851247954),
]


def _same_roots(a: list[om.Solution], b: list[om.Solution]) -> bool:
    """One to one within 1e-9 rad (the same root refined from other samples differs in its
    last digits)."""
    return len(a) == len(b) and all(
        any(np.abs(np.remainder(x.q - y.q + np.pi, 2 * np.pi) - np.pi).max() < 1e-9 for y in b) for x in a
    )


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
        assert _same_roots(coarse.solve_all(T, c), dense.solve_all(T, c)), c


def _holds(solver: om.OMSolver, seed: int) -> bool:
    """Whether solve_all at q's pose and configuration holds q (to 1e-8 rad)."""
    q = random_q(solver.arm, 1, np.random.default_rng(seed))[0]
    roots = solver.solve_all(solver.arm.fk(q), solver.configuration_of(q))
    return any(np.abs(np.remainder(r.q - q + np.pi, 2 * np.pi) - np.pi).max() < 1e-8 for r in roots)


@pytest.mark.parametrize(("name", "seed"), CLOSE_ROOTS)
def test_a_coarse_search_holds_q_among_close_roots(name, seed):
    assert _holds(om.OMSolver(name, scan_points=COARSE), seed)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_a_coarse_search_holds_q(solvers, seed):
    assert _holds(solvers[0], seed)


#: xArm7 joints at a fold of the residual (benchmarks.seven_dof, seed 0, row 59153): two
#: halved cells refined the root twice, 5e-9 rad apart, the second copy 7.6e-11 m off.
FOLD_Q = [-5.601047109041344, -0.1676911858728567, -1.5299160010102657, 2.7418260873462583,
          -4.235738466416173, 2.4179389976273047, -4.07003619128778]  # fmt: skip


def test_a_root_found_twice_at_a_fold_is_returned_once_at_its_most_accurate():
    solver, q = om.OMSolver("xarm7"), np.array(FOLD_Q)
    roots = solver.solve_all(solver.arm.fk(q), solver.configuration_of(q))
    for i, a in enumerate(roots):
        for b in roots[:i]:
            assert np.abs(np.remainder(a.q - b.q + np.pi, 2 * np.pi) - np.pi).max() > 1e-6
    held = [r for r in roots if np.abs(np.remainder(r.q - q + np.pi, 2 * np.pi) - np.pi).max() < 1e-9]
    assert len(held) == 1 and held[0].position_error < 1e-12
