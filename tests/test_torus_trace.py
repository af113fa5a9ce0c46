"""The traced self-motion (csrc/ik/torus_trace.c): a batch's searches of the whole torus of one
pose (an S-R-S arm with shoulder offsets: the Sawyer) start from where the self-motion, traced
once per pose and ELBOW sign, crosses their arm angle, instead of from the grid's starts at each.
They must find every root within the joint limits that the grid's starts find (a single
``solve_all``), and nothing else but exact roots."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.control_rate import ARM_HOMES, MIN_CLEARANCE, obstacles
from om_redundant.redundancy.paths import linking
from om_redundant.redundancy.paths.linking import LinkedMemo, sweep_circle
from om_redundant.redundancy.paths.probe import Probe
from tests.conftest import distance, solver_of
from tests.test_torus_search import NEAR_DOUBLE_Q, talos_left_arm

GRID = 64  # arm angles of the redundancy optimiser's sweep

# (seed, pose, grid rows) of poses where a version of the trace missed a root that the grid's
# starts find, each drawn as _drawn_pose draws it:
# 11, 18: a contour across edges whose nodes' elbow residual is rounding (not exactly zero);
# 3, 10: a loop inside a cell whose corners all have Phi > 0, seen by a node near the curve;
# 4, 51: a path hugging the straight elbow, seen from the edge of reach alone;
# 3, 16: a fold of psi at the point a component's trace started from;
# 4, 15: a row's psi next to a fold, where psi is quadratic in the arc;
# 8, 17: an island 0.3 rad wide in psi, 0.28 rad in the elbow from the nearest node's root.
MISSED_ONCE = [
    (11, 18, (72, 104)),
    (3, 10, (141, 197)),
    (4, 51, (58, 98)),
    (3, 16, (284,)),
    (4, 15, (192,)),
    (8, 17, (115, 123)),
]


def _drawn_pose(arm: om.Arm, seed: int, index: int) -> np.ndarray:
    """Pose `index` of a sequence drawn from `seed`: the hand at uniform joints within the
    limits, every fifth pushed out by up to 2 % toward the reach."""
    rng = np.random.default_rng(seed)
    lo, hi = np.maximum(arm.lower, -np.pi), np.minimum(arm.upper, np.pi)
    for k in range(index + 1):
        T = arm.fk(rng.uniform(lo, hi))
        if k % 5 == 0:
            T[:3, 3] *= 1.0 + 0.02 * rng.random()
    return T


def _sweep(solver: om.OMSolver, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, om.BatchRoots]:
    """Every branch at GRID arm angles of pose T, one batch: the rows' signs and psi, and roots."""
    branches = np.array([c.signs for c in solver.configurations()])
    psi = -np.pi + 2.0 * np.pi * np.arange(GRID) / GRID
    signs, grid_psi = np.tile(branches, (GRID, 1)), np.repeat(psi, len(branches))
    batch = solver.solve_all_batch(np.repeat(T[None], len(signs), axis=0), signs, grid_psi, threads=1)
    return signs, grid_psi, batch


def _assert_rows_hold_the_grid_roots(solver: om.OMSolver, T: np.ndarray, rows) -> None:
    """Each row of the batch holds the roots of a single solve_all within the limits, and holds
    nothing but exact roots of its configuration."""
    arm = solver.arm
    signs, psi, batch = _sweep(solver, T)
    for r in rows:
        c = om.Configuration(tuple(signs[r]), (psi[r],))
        found = batch.q[r, : batch.count[r]]
        for q in found:
            assert np.abs(arm.fk(q) - T).max() <= 1e-10 and solver.holds(q, c)
        single = [root.q for root in solver.solve_all(T, c)]
        for q in single:
            if arm.within_limits(q):
                assert any(distance(arm, q, p) < 1e-7 for p in found), (r, q)
        for q in found:
            if arm.within_limits(q):
                assert any(distance(arm, q, p) < 1e-7 for p in single), (r, q)


@pytest.mark.parametrize(("seed", "index", "rows"), MISSED_ONCE)
def test_the_trace_finds_the_roots_it_once_missed(seed, index, rows):
    solver = solver_of("sawyer")
    _assert_rows_hold_the_grid_roots(solver, _drawn_pose(solver.arm, seed, index), rows)


@settings(max_examples=3, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_a_sweep_holds_the_grid_roots_within_the_limits(seed):
    """Random poses, 24 random rows of each sweep."""
    solver = solver_of("sawyer")
    rng = np.random.default_rng(seed)
    T = _drawn_pose(solver.arm, seed, 0)
    _assert_rows_hold_the_grid_roots(solver, T, rng.choice(8 * GRID, 24, replace=False))


def test_a_batch_keeps_a_near_double_root_pair():
    """A fold's pair of roots 1.8e-5 rad apart (test_torus_search): the search at their psi
    starts from the traced fold and seeks its partner from there."""
    arm = talos_left_arm()
    solver = om.OMSolver(arm)
    T, c = arm.fk(NEAR_DOUBLE_Q), solver.configuration_of(NEAR_DOUBLE_Q)
    branches = [b.signs for b in solver.configurations()]
    batch = solver.solve_all_batch(
        np.repeat(T[None], len(branches), 0), branches, np.full(len(branches), c.redundancy[0])
    )
    row = branches.index(c.signs)
    pair = [q for q in batch.q[row, : batch.count[row]] if distance(arm, q, NEAR_DOUBLE_Q) < 1e-4]
    assert len(pair) == 2
    for q in pair:
        assert np.abs(arm.fk(q) - T).max() <= 1e-10 and solver.holds(q, c)


def _optimizer(name: str, count: int) -> om.RedundancyOptimizer:
    """The arm's optimiser with count obstacles about its home hand (benchmarks.control_rate's)."""
    solver = solver_of(name)
    shapes = obstacles(solver.arm.fk(ARM_HOMES[name])[:3, 3], count)
    return om.RedundancyOptimizer(solver, shapes, min_clearance=MIN_CLEARANCE)


def _swept(optimizer: om.RedundancyOptimizer, T: np.ndarray, memo: LinkedMemo | None = None):
    """Every branch's paths of pose T as the optimiser's sweep links them, and its probes."""
    probes = [Probe(optimizer.solver, optimizer.objective, T, signs) for signs in optimizer.branches]
    return sweep_circle(probes, GRID, memo=memo), probes


@settings(max_examples=4, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 6))
@example(1031, 3)  # (a path's end at a fold, |dq/dpsi| 3.8e5: its joints 5.9e-9 apart)
def test_follows_from_the_kept_traces_link_what_the_windows_link(seed, index):
    """A sweep's follows scan for a root nearer each step's start from the self-motion that the
    grid's rows traced (kept in ``_core.torus_traces``) instead of sampling a window of the
    torus: the same paths, the same samples (random poses, 3 obstacles), each an exact root.
    The same psi to 1e-12; the same joints to 1e-12 rad per unit of |dq/dpsi| (at least 1): at
    a fold, where |dq/dpsi| grows without bound, two Newton runs to one root agree only so far
    (the path's end located to END_TOLERANCE in psi moves its joints that much)."""
    optimizer = _optimizer("sawyer", 3)
    T = _drawn_pose(optimizer.solver.arm, seed, index)
    (kept, probes) = _swept(optimizer, T)
    assert all(probe._work.traces is not None for probe in probes)
    with mock.patch.object(linking._core, "torus_traces", return_value=None):
        (sampled, probes) = _swept(optimizer, T)
    assert all(probe._work.traces is None for probe in probes)
    assert [[len(path.points) for path in paths] for paths in kept] == [
        [len(path.points) for path in paths] for paths in sampled
    ]
    for paths_a, paths_b in zip(kept, sampled, strict=True):
        for a, b in zip(paths_a, paths_b, strict=True):
            assert a.turns == b.turns
            for p, r in zip(a.points, b.points, strict=True):
                assert abs(p.psi - r.psi) <= 1e-12
                assert np.abs(p.q - r.q).max() <= 1e-12 * max(1.0, np.abs(p.tangent).max())
                assert np.abs(optimizer.solver.arm.fk(p.q) - T).max() <= 1e-9


@pytest.mark.sanitize
def test_a_pose_swept_again_follows_from_the_traces_kept_with_its_paths():
    """A sweep that takes its linked paths from the LinkedMemo (the pose held while the
    obstacles move) takes the traces its first sweep kept too; a panda's sweep keeps none."""
    optimizer = _optimizer("sawyer", 1)
    T, memo = _drawn_pose(optimizer.solver.arm, 5, 0), LinkedMemo()
    _, first = _swept(optimizer, T, memo)
    _, again = _swept(optimizer, T, memo)
    assert first[0]._work.traces is not None
    assert all(probe._work.traces is first[0]._work.traces for probe in again)
    panda = _optimizer("panda", 1)
    _, probes = _swept(panda, panda.solver.arm.fk(ARM_HOMES["panda"]))
    assert all(probe._work.traces is None for probe in probes)


@pytest.mark.sanitize
def test_traces_of_another_pose_are_not_taken():
    """A follow at a pose whose self-motion the traces do not hold (a batch of another pose
    filled them first: they are written once) samples its windows, as without traces."""
    optimizer = _optimizer("sawyer", 1)
    solver, arm = optimizer.solver, optimizer.solver.arm
    T_a, T_b = _drawn_pose(arm, 2, 0), _drawn_pose(arm, 3, 0)
    stale = linking._core.torus_traces(solver.kernel)
    with mock.patch.object(linking._core, "torus_traces", return_value=stale):
        _swept(optimizer, T_a)  # (fills them at T_a)
        (at_b, probes) = _swept(optimizer, T_b)  # (the batch at T_b finds them filled)
    assert all(probe._work.traces is stale for probe in probes)
    with mock.patch.object(linking._core, "torus_traces", return_value=None):
        (sampled, _) = _swept(optimizer, T_b)
    assert [[len(p.points) for p in paths] for paths in at_b] == [
        [len(p.points) for p in paths] for paths in sampled
    ]
    for paths_a, paths_b in zip(at_b, sampled, strict=True):
        for a, b in zip(paths_a, paths_b, strict=True):
            assert [p.psi for p in a.points] == [p.psi for p in b.points]
            assert all((p.q == r.q).all() for p, r in zip(a.points, b.points, strict=True))
