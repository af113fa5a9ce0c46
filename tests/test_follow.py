"""The compiled path following (``_core.follow``, csrc/redundancy/follow.c) against the Python loop of
tests/reference/follow.py: the same point reached, the same answer whether it arrived, on
random poses and steps; and the compiled linking of a branch's grid roots into paths
(``_core.link_paths``, csrc/redundancy/link.c) against the reference's loop: the same paths, to the bit."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.control_rate import MIN_CLEARANCE, obstacles
from om_redundant import _core
from om_redundant.redundancy.paths import linking as paths
from om_redundant.redundancy.paths.points import Point
from om_redundant.redundancy.paths.probe import END_TOLERANCE, Probe
from tests.conftest import solver_of
from tests.reference import follow as reference
from tests.test_redundancy_batch import optimizer_of


@settings(max_examples=12, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    name=st.sampled_from(["panda", "iiwa14"]),
    step=st.floats(-3.0, 3.0),
    wrapped=st.booleans(),
)
def test_compiled_follow_reaches_what_the_python_loop_reaches(seed, name, step, wrapped):
    optimizer = optimizer_of(name, 1)
    solver = optimizer.solver
    arm = solver.arm
    q = np.random.default_rng(seed).uniform(arm.lower, arm.upper)
    configuration = solver.configuration_of(q)
    (psi,) = configuration.redundancy
    T = arm.fk(q)
    probe = Probe(solver, optimizer.objective, T, configuration.signs, wrapped)
    starts = [probe.point(psi, q) for _ in range(2)]
    (fast, fast_arrived), (slow, slow_arrived) = (
        probe.follow(starts[0], psi + step),
        reference.follow(probe, starts[1], psi + step),
    )
    assert fast_arrived == slow_arrived
    assert fast.psi == pytest.approx(slow.psi, abs=1e-12)
    np.testing.assert_allclose(fast.q, slow.q, atol=1e-9)
    np.testing.assert_allclose(fast.tangent, slow.tangent, rtol=1e-9, atol=1e-9)
    assert (fast is starts[0]) == (slow is starts[1])  # no step taken: the start itself
    assert fast.evaluation.value == pytest.approx(slow.evaluation.value, abs=1e-9)
    if fast is not starts[0]:  # the point reached is an exact solution on the branch
        assert np.abs(arm.fk(fast.q) - T).max() < 1e-9
        assert om.OMSolver(name).holds(fast.q, om.Configuration(configuration.signs, (fast.psi,)))


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(["panda", "iiwa14"]), step=st.floats(-0.5, 0.5))
def test_compiled_next_is_the_python_next(seed, name, step):
    """Probe.next (one attempt of the loop, the climb's trial step) and the reference's: the
    same answer, the same point."""
    optimizer = optimizer_of(name, 3)
    solver = optimizer.solver
    q = np.random.default_rng(seed).uniform(solver.arm.lower, solver.arm.upper)
    configuration = solver.configuration_of(q)
    (psi,) = configuration.redundancy
    probe = Probe(solver, optimizer.objective, solver.arm.fk(q), configuration.signs)
    fast, slow = (
        probe.next(probe.point(psi, q), psi + step),
        reference.next_point(probe, probe.point(psi, q), psi + step),
    )
    assert (fast is None) == (slow is None)
    if fast is not None:
        assert fast.psi == slow.psi
        np.testing.assert_allclose(fast.q, slow.q, atol=1e-9)
        np.testing.assert_allclose(fast.tangent, slow.tangent, rtol=1e-9, atol=1e-9)
        assert fast.evaluation.value == pytest.approx(slow.evaluation.value, abs=1e-9)


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(["panda", "iiwa14"]), compiled=st.booleans())
def test_a_path_ends_where_follow_says(seed, name, compiled):
    """A path that ends on the way (a fold, or a branch quantity leaving its sign beyond the
    band) ends at the point reached, to END_TOLERANCE: no step of 2 END_TOLERANCE beyond it
    continues the path. The end is aimed at from the end measures of the last points, not
    halved towards: this checks that the aim does not stop short."""
    optimizer = optimizer_of(name, 0)
    solver = optimizer.solver
    q = np.random.default_rng(seed).uniform(solver.arm.lower, solver.arm.upper)
    configuration = solver.configuration_of(q)
    (psi,) = configuration.redundancy
    probe = Probe(solver, optimizer.objective, solver.arm.fk(q), configuration.signs)
    follow, next_point = (
        (probe.follow, probe.next)
        if compiled
        else (
            lambda start, psi: reference.follow(probe, start, psi),
            lambda point, psi: reference.next_point(probe, point, psi),
        )
    )
    for side in (1.0, -1.0):
        end, arrived = follow(probe.point(psi, q), psi + side * np.pi)
        if not arrived:
            assert next_point(end, end.psi + side * 2.0 * END_TOLERANCE) is None


def grid_roots(name: str, seed: int) -> list[tuple[Probe, np.ndarray, list[list[Point]]]]:
    """Every branch's (probe, grid psi, roots at each grid psi) that ``sweep_circle`` links,
    at the pose of random joints of the arm (each joint within its limits and a turn)."""
    solver = solver_of(name)
    arm = solver.arm
    q = np.random.default_rng(seed).uniform(np.maximum(arm.lower, -np.pi), np.minimum(arm.upper, np.pi))
    T = arm.fk(q)
    optimizer = om.RedundancyOptimizer(solver, obstacles(T[:3, 3], 1), min_clearance=MIN_CLEARANCE)
    linked, link = [], Probe.link

    def recorded(probe, psi, roots):
        linked.append((probe, psi, [list(points) for points in roots]))
        return link(probe, psi, roots)

    with mock.patch.object(Probe, "link", recorded):
        paths.sweep_circle(
            [optimizer._probe(T, signs) for signs in optimizer.branches], optimizer.grid_points
        )
    return linked


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(["panda", "iiwa14", "sawyer", "xarm7", "fr3"]))
def test_compiled_link_makes_the_python_loops_paths(seed, name):
    """On random poses of several arms, every branch's paths linked in one call are those of
    the Python loop: the same paths, turns and points (psi, joints and tangents to the bit),
    the grid roots themselves where the loop has them."""
    for probe, psi, roots in grid_roots(name, seed):
        fast = [paths.Path(points, turns) for points, turns in probe.link(psi, [list(p) for p in roots])]
        slow = reference.link(probe, psi, [list(points) for points in roots])
        grid = {id(p) for points in roots for p in points}
        assert [path.turns for path in fast] == [path.turns for path in slow]
        for a, b in zip(fast, slow, strict=True):
            assert len(a.points) == len(b.points)
            for p, r in zip(a.points, b.points, strict=True):
                assert p.psi == r.psi and np.array_equal(p.q, r.q) and np.array_equal(p.tangent, r.tangent)
                assert (p is r) == (id(r) in grid)


def link_rows(probe: Probe, psi: np.ndarray, flat: list[Point], counts: np.ndarray, capacity: int):
    """``_core.link_paths`` of the roots ``flat`` (counts[k] at psi[k]) with room for
    ``capacity`` added rows: (status, rows added, paths), members, the paths' (end, turns),
    the added rows' psi."""
    q = np.array([p.q for p in flat], dtype=float).reshape(-1, 7)
    t = np.array([p.tangent[:, 0] for p in flat], dtype=float).reshape(-1, 7)
    members, ends = np.empty((2, len(flat) + capacity, 2), dtype=np.int64)
    rows = _core.LinkRows(np.empty(capacity), np.empty((capacity, 7)), np.empty((capacity, 7)), members, ends)
    linked = _core.link_paths(probe._work, _core.LinkRoots(psi, counts, q, t), rows)
    return tuple(linked), members, ends, rows.psi


def test_link_paths_puts_every_row_on_one_path_and_says_when_it_has_no_room():
    """With room for the points that following adds, every row (the roots, then those
    points) is on exactly one path, in increasing psi along it; without room, LINK_FULL (the
    caller's loop decides) and no path. On every branch of a pose whose linking adds points."""
    added_somewhere = False
    for probe, psi, roots in grid_roots("panda", 0):
        flat = [p for points in roots for p in points]
        counts = np.array([len(points) for points in roots], dtype=np.int64)
        (status, added, n_paths), members, ends, new_psi = link_rows(
            probe, psi, flat, counts, 2 * len(flat) + len(psi)
        )
        assert status == _core.LINK_DONE
        on_paths = members[: ends[n_paths - 1, 0] if n_paths else 0]
        assert sorted(on_paths[:, 0].tolist()) == list(range(len(flat) + added))
        row_psi = np.concatenate([[p.psi for p in flat], new_psi[:added]])
        for begin, end in zip([0, *ends[: n_paths - 1, 0]], ends[:n_paths, 0], strict=True):
            along = row_psi[members[begin:end, 0]] + 2.0 * np.pi * members[begin:end, 1]
            assert (np.diff(along) > 0.0).all()
        if added:
            added_somewhere = True
            assert link_rows(probe, psi, flat, counts, 0)[0] == (_core.LINK_FULL, 0, 0)
    assert added_somewhere


# The Panda's hand at its q = 0 as an ExactPoseTask on MuJoCo's model saw it (root pose and
# site composed: 1e-16 off the arm's own FK), bit for bit.
_HEX = """
    -0x1.6a09e73c0e1efp-1 -0x1.6a09e593d95a1p-1 0x1.38e98a512f0d3p-53 0x1.6872b020c49bbp-4
    -0x1.6a09e593d959bp-1 0x1.6a09e73c0e1f1p-1 -0x1.6e419b7b26038p-51 0x1.ae77e7d024800p-53
    0x1.f0d5d466b28cfp-52 -0x1.2f09b938723fdp-51 -0x1.ffffffffffffcp-1 0x1.da1cac0831269p-1
    0x0p+0 0x0p+0 0x0p+0 0x1p+0"""
T_PANDA_ZERO_ROUNDED = np.array([float.fromhex(x) for x in _HEX.split()]).reshape(4, 4)


def test_a_path_within_rounding_of_a_singular_set_stalls_rather_than_crawls():
    """Within rounding of the Panda's q = 0 pose, the branch of q = 0 has a solution path
    along q2 = q4 = q6 = 0 that is accepted only in steps of ~1e-6 rad (before the bound: hours
    in one ``link_paths`` call, the GIL released). The follow stalls with SingularSelfMotion;
    the optimiser sweeps that branch alone and answers from the others, saying so, the
    intervals those of the other branches."""
    solver = solver_of("panda")
    optimizer = om.RedundancyOptimizer(solver)
    alone = [optimizer._sweep_alone(T_PANDA_ZERO_ROUNDED, signs) for signs in optimizer.branches]
    stalled = [branch.signs for branch in alone if branch.unswept]
    assert stalled and all("the self-motion crawls" in b.unswept for b in alone if b.unswept)
    for q_current in (np.zeros(7), None):
        choice = optimizer.choose(T_PANDA_ZERO_ROUNDED, q_current=q_current)
        assert choice.ok and choice.configuration.signs not in stalled
        assert np.abs(solver.arm.fk(choice.solution.q) - T_PANDA_ZERO_ROUNDED).max() < 1e-10
        assert choice.intervals == tuple(optimizer.intervals(T_PANDA_ZERO_ROUNDED))
        assert all(interval.signs not in stalled for interval in choice.intervals)
    with pytest.raises(om.SingularSelfMotion, match="crawls"):  # (the branch alone: nothing else answers)
        om.RedundancyOptimizer(solver, branches=[stalled[0]]).choose(T_PANDA_ZERO_ROUNDED)


def test_a_link_without_room_is_made_again_with_more():
    """Where following adds more rows than Probe.link's first call has room for (LINK_FULL),
    it calls again with more room and links the paths the Python loop links (the rows of
    the first call given none here)."""
    link_paths, calls = _core.link_paths, []

    def cramped(work, roots, rows):
        calls.append(len(rows.psi))
        if len(calls) == 1:  # (no room at all: full as soon as a follow adds a row)
            members, ends = np.empty((2, len(roots.q), 2), np.int64)
            rows = _core.LinkRows(np.empty(0), np.empty((0, 7)), np.empty((0, 7)), members, ends)
        return link_paths(work, roots, rows)

    for probe, psi, roots in grid_roots("panda", 0):
        calls.clear()
        with mock.patch.object(_core, "link_paths", cramped):
            linked = probe.link(psi, [list(points) for points in roots])
        slow = reference.link(probe, psi, [list(points) for points in roots])
        assert [turns for _, turns in linked] == [path.turns for path in slow]
        for (points, _), path in zip(linked, slow, strict=True):
            assert [(p.psi, p.q.tolist()) for p in points] == [(p.psi, p.q.tolist()) for p in path.points]
        if len(calls) > 1:
            assert calls[1] > calls[0]
            return
    raise AssertionError("no branch whose linking adds rows")
