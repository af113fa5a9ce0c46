"""The compiled core at its edge: memory layouts, malformed buffers, threads, constants."""

from __future__ import annotations

import math
import re
import threading
import types
from typing import NamedTuple

import numpy as np
import pytest

import om_redundant as om
from om_redundant import _core
from om_redundant._core import SolverData
from om_redundant.redundancy.self_motion import self_motion_tangent
from tests.conftest import random_q
from tests.test_reliability import BOUNDARY_CASES

pytestmark = pytest.mark.sanitize  # also run under ASan and UBSan (.ci/sanitize)


@pytest.fixture(scope="module")
def panda() -> om.OMSolver:
    return om.OMSolver("panda")


def _target(solver: om.OMSolver, seed: int) -> tuple[np.ndarray, np.ndarray, om.Configuration]:
    q = random_q(solver.arm, 1, np.random.default_rng(seed))[0]
    return q, solver.arm.fk(q), solver.configuration_of(q)


def _layouts(array: np.ndarray) -> dict[str, np.ndarray]:
    """The same values as a Fortran-order, a read-only, a strided and a list copy."""
    read_only = array.copy()
    read_only.flags.writeable = False
    return {
        "fortran": np.asfortranarray(array),
        "read-only": read_only,
        "strided": np.repeat(array, 2, axis=-1)[..., ::2],
        "list": array.tolist(),
    }


@pytest.mark.parametrize("seed", range(3))
def test_every_layout_of_pose_and_hint_gives_the_same_solution(panda, seed):
    q, T, c = _target(panda, seed)
    hint = q + 0.01
    reference = panda.solve(T, c, q_hint=hint)
    assert reference.ok
    for name, pose in _layouts(T).items():
        for hint_name, h in _layouts(hint).items():
            sol = panda.solve(pose, c, q_hint=h)
            np.testing.assert_array_equal(sol.q, reference.q, err_msg=f"{name} pose, {hint_name} hint")
            assert sol.iterations == reference.iterations
    for name, pose in _layouts(T).items():
        roots = panda.solve_all(pose, c)
        assert [r.q.tolist() for r in roots] == [r.q.tolist() for r in panda.solve_all(T, c)], name


def test_every_layout_of_a_batch_gives_the_same_solutions(panda):
    rng = np.random.default_rng(7)
    Q = random_q(panda.arm, 100, rng)
    T = panda.arm.fk(Q)
    cs = [panda.configuration_of(q) for q in Q]
    signs = np.array([c.signs for c in cs])
    psi = np.array([c.redundancy for c in cs])
    reference = panda.solve_batch(T, signs, psi, q_hint=Q)
    assert reference.ok.all()
    for name, poses in _layouts(T).items():
        for signs_layout in (np.asfortranarray(signs), signs.astype(np.float64), signs[:, ::-1][:, ::-1]):
            batch = panda.solve_batch(
                poses, signs_layout, np.asfortranarray(psi), q_hint=np.asfortranarray(Q)
            )
            np.testing.assert_array_equal(batch.q, reference.q, err_msg=name)
            np.testing.assert_array_equal(batch.iterations, reference.iterations)


def test_batch_equals_one_solve_per_row_across_threads(panda):
    """The thread pool's chunks cover every row once; the answers are the serial ones."""
    rng = np.random.default_rng(3)
    Q = random_q(panda.arm, 300, rng)
    T = panda.arm.fk(Q)
    cs = [panda.configuration_of(q) for q in Q]
    batch = panda.solve_batch(T, np.array([c.signs for c in cs]), np.array([c.redundancy for c in cs]))
    for m in range(len(Q)):
        sol = panda.solve(T[m], cs[m])
        np.testing.assert_array_equal(batch.q[m], sol.q)
        assert batch.status[m] == sol.status and batch.iterations[m] == sol.iterations


def _assert_rows_are_solve_all(solver: om.OMSolver, T, signs, redundancy, batch: om.BatchRoots) -> None:
    """Row i of a solve_all_batch is solve_all of row i: the same roots in the same order."""
    for i in range(len(T)):
        single = solver.solve_all(
            T[i], om.Configuration(tuple(signs[i]), tuple(np.atleast_1d(redundancy[i])))
        )
        assert batch.count[i] == len(single)
        assert np.isnan(batch.q[i, len(single) :]).all()
        for r, sol in enumerate(single):
            np.testing.assert_array_equal(batch.q[i, r], sol.q)
            assert batch.position_error[i, r] == sol.position_error
            assert batch.orientation_error[i, r] == sol.orientation_error
            assert batch.within_limits[i, r] == sol.within_limits
            assert batch.iterations[i] == sol.iterations


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("shoulder_pairs", [False, True])
def test_solve_all_batch_equals_solve_all_per_row(panda, threads, shoulder_pairs):
    """Every configuration of random poses on a psi grid (rows with 0, 1 and several roots);
    also with the rows that differ in the SHOULDER sign alone next to each other, where the
    second takes the first's circle search (om_scan_cache)."""
    T = panda.arm.fk(random_q(panda.arm, 3, np.random.default_rng(6)))
    branches = [c.signs for c in panda.configurations()]
    psi = np.linspace(-np.pi, np.pi, 8, endpoint=False)
    rows = [(t, s, x) for t in T for s in branches for x in psi]
    if shoulder_pairs:
        paired = sorted(branches, key=lambda s: (s[1:], s[0]))
        rows = [(t, s, x) for t in T for x in psi for s in paired]
    Ts, signs, redundancy = (np.array(column) for column in zip(*rows, strict=True))
    batch = panda.solve_all_batch(Ts, signs, redundancy, threads=threads)
    assert (batch.count == 0).any() and (batch.count > 1).any()
    _assert_rows_are_solve_all(panda, Ts, signs, redundancy, batch)


def test_solve_grid_searches_the_band_only_where_asked(panda):
    """solve_grid's rows marked for the band are solve_all's; the others are solve_all's
    wherever the bounded search finds a root (solve_all searches further only where it finds
    none), and empty elsewhere. The FR3's close pair inside one scan cell, a reproducer that
    only the band's dip search solves, is found only where the band is searched."""
    T = panda.arm.fk(random_q(panda.arm, 3, np.random.default_rng(6)))
    branches = [c.signs for c in panda.configurations()]
    psi = np.linspace(-np.pi, np.pi, 8, endpoint=False)
    rows = [(t, s, x) for t in T for s in branches for x in psi]
    Ts, signs, redundancy = (np.array(column) for column in zip(*rows, strict=True))
    band = np.random.default_rng(0).random(len(Ts)) < 0.5
    grid = panda.solve_grid(Ts, signs, redundancy, band)
    every = panda.solve_all_batch(Ts, signs, redundancy)
    same = band | (grid.count > 0)
    assert (every.count[~band] == 0).any() and (every.count[~band] > 0).any()
    assert (grid.count[~same] == 0).all()
    for field in ("q", "count", "position_error", "orientation_error", "iterations", "within_limits"):
        np.testing.assert_array_equal(getattr(grid, field)[same], getattr(every, field)[same])
    with pytest.raises(om.InvalidInput, match="band must have one entry per row"):
        panda.solve_grid(Ts, signs, redundancy, band[1:])
    fr3 = om.OMSolver("fr3")
    q = np.array(BOUNDARY_CASES["dip inside a cell"][1])
    c = fr3.configuration_of(q)
    T, c_signs, c_psi = fr3.arm.fk(q)[None], np.array([c.signs]), np.array([c.redundancy])
    assert fr3.solve_grid(T, c_signs, c_psi, np.array([False])).count[0] == 0
    found = fr3.solve_grid(T, c_signs, c_psi, np.array([True]))
    assert found.count[0] == 1
    np.testing.assert_allclose(found.q[0, 0], q, atol=1e-8)


def test_solve_all_batch_of_a_6dof_arm_and_an_empty_batch_refused():
    ur5e = om.OMSolver("ur5e")
    Q = random_q(ur5e.arm, 6, np.random.default_rng(7))
    T = ur5e.arm.fk(Q)
    signs = np.array([ur5e.configuration_of(q).signs for q in Q])
    batch = ur5e.solve_all_batch(T, signs)
    assert (batch.count >= 1).all()
    _assert_rows_are_solve_all(ur5e, T, signs, np.zeros((6, 0)), batch)
    with pytest.raises(om.InvalidInput, match="T holds no poses"):
        ur5e.solve_all_batch(np.zeros((0, 4, 4)), np.zeros((0, 3)))


@pytest.mark.parametrize("threads", [1, 2, 3, 64.0])
def test_batch_answers_do_not_depend_on_the_threads(panda, threads):
    """threads=1 solves on the calling thread; more take chunks from a shared queue: same rows."""
    Q = random_q(panda.arm, 200, np.random.default_rng(4))
    T = panda.arm.fk(Q)
    cs = [panda.configuration_of(q) for q in Q]
    signs, psi = np.array([c.signs for c in cs]), np.array([c.redundancy for c in cs])
    reference = panda.solve_batch(T, signs, psi)
    batch = panda.solve_batch(T, signs, psi, threads=threads)
    np.testing.assert_array_equal(batch.q, reference.q)
    np.testing.assert_array_equal(batch.status_code, reference.status_code)
    np.testing.assert_array_equal(batch.iterations, reference.iterations)


@pytest.mark.parametrize("threads", [0, -1, 2.5, "2", True, 1025])
def test_batch_refuses_a_bad_thread_count(panda, threads):
    T = panda.arm.fk(np.zeros(7))[None]
    c = panda.configuration_of(np.zeros(7))
    with pytest.raises(om.InvalidInput, match="threads"):
        panda.solve_batch(T, c.signs, c.redundancy, threads=threads)


def test_threads_sharing_one_solver_agree_with_serial_calls(panda):
    targets = [_target(panda, seed) for seed in range(40)]
    serial = [panda.solve(T, c).q for _, T, c in targets]
    results: dict[int, list[np.ndarray]] = {}

    def work(k: int) -> None:
        results[k] = [panda.solve(T, c).q for _, T, c in targets]

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for k in range(4):
        for a, b in zip(results[k], serial, strict=True):
            np.testing.assert_array_equal(a, b)


def test_the_binding_rejects_malformed_buffers_with_a_named_error(panda):
    _, T, c = _target(panda, 0)
    kernel = _core.Solver(panda.solver_data())
    out = np.empty(7)
    with pytest.raises(TypeError, match="T must be float64"):
        kernel.solve(T.astype(np.float32), c.signs, c.redundancy, None, out, False)
    with pytest.raises(TypeError, match="T must be a C-contiguous"):
        kernel.solve(np.asfortranarray(T), c.signs, c.redundancy, None, out, False)
    with pytest.raises(ValueError, match="T must have 16 entries"):
        kernel.solve(T[:3], c.signs, c.redundancy, None, out, False)
    with pytest.raises(ValueError, match="q_hint must have 7 entries"):
        kernel.solve(T, c.signs, c.redundancy, np.zeros(6), out, False)
    with pytest.raises(TypeError, match="q_out must be a C-contiguous writable"):
        read_only = np.empty(7)
        read_only.flags.writeable = False
        kernel.solve(T, c.signs, c.redundancy, None, read_only, False)
    with pytest.raises(ValueError, match="signs must be -1 or"):
        kernel.solve(T, (1, 0, 1), c.redundancy, None, out, False)
    with pytest.raises(ValueError, match="redundancy must have 1 entries"):
        kernel.solve(T, c.signs, (), None, out, False)

    def batch(m: int, **changed: np.ndarray) -> _core.SolveBatch:
        rows = _core.SolveBatch(
            np.stack([T] * m),
            np.ones((m, 3), np.int64),
            np.zeros((m, 1)),
            None,
            q=np.empty((m, 7)),
            status=np.empty(m, np.int64),
            position_error=np.empty(m),
            orientation_error=np.empty(m),
            evaluations=np.empty(m, np.int64),
            within_limits=np.empty(m, bool),
        )
        return rows._replace(**changed)

    with pytest.raises(ValueError, match=r"T must be \(M, 4, 4\)"):
        kernel.solve_rows(batch(1), 0, 2)
    with pytest.raises(ValueError, match="position_error must have 3 entries"):
        kernel.solve_rows(batch(3, position_error=np.empty(0)), 0, 3)
    with pytest.raises(TypeError, match="within_limits must be bool"):
        kernel.solve_rows(batch(3, within_limits=np.empty(3)), 0, 3)
    with pytest.raises(TypeError, match="must have a field 'T'"):
        kernel.solve_rows(_core.Roots(*batch(3)[:4]), 0, 3)


def test_the_bindings_refuse_indices_out_of_range(panda):
    """pieces, evaluate and linearise (limited and singularity joints), arm_geom_poses and arm_clearance
    (the geoms' links, the pairs' arm geoms and obstacles) check every index they read arrays
    at against its range: the values at either end of it are read, those just outside are a
    ValueError naming the sizes, never a read past an end."""

    def pieces(limited):
        q, g = np.zeros((1, 7)), np.empty((1, 1))
        half, numbers = np.full(1, 0.5), np.array([0.2, 0.1, 0.5])
        lower, upper = np.zeros(1), np.ones(1)
        rows = _core.PieceRows(q, q, np.empty((1, 0)), np.empty((1, 0, 7)))
        _core.pieces(7, rows, _core.PieceLimits(limited, lower, upper, half), numbers, g, g)

    def terms(limited, joints):
        one = np.ones(1)
        weights = dict(margin_weight=1.0, clearance_weight=1.0, singularity_weight=1.0)
        caps = dict(clearance_cap=0.1, min_clearance=0.03, singularity_cap=0.1)
        return _core.ObjectiveTerms(7, limited, one - 1.0, one, one, joints, one, **weights, **caps)

    def evaluate(limited, joints):
        q, out = np.zeros((1, 7)), _core.Evaluations(*np.empty((5, 1)))
        _core.evaluate(terms(limited, joints), q, np.empty((1, 0)), out)

    def linearise(limited, joints):
        q, pieces = np.zeros((1, 7)), np.empty((2, 1, 3))
        rows = _core.PieceRows(q, q, np.empty((1, 0)), np.empty((1, 0, 7)))
        _core.linearise(terms(limited, joints), rows, *pieces)

    clearance = om.Clearance.for_arm(panda.arm, [om.Sphere([0.4, 0.1, 0.5], 0.05)])
    cores = clearance._cores
    q, n_arm, n_pairs = np.zeros(7), len(cores.link), len(clearance.pairs)
    out = _core.PairDistances(np.empty(n_pairs), np.empty((n_pairs, 6)), np.empty((n_pairs, 7)))

    def poses(link):
        xpos, xmat = np.empty((n_arm, 3)), np.empty((n_arm, 9))
        _core.arm_geom_poses(cores._replace(link=link), q, xpos, xmat)

    def clear(link, pairs):
        _core.arm_clearance(cores._replace(link=link, pairs=pairs), q, 1.0, 1.0, out, False)

    def index(k):
        return np.array([k], dtype=np.int64)

    def link_at(value):
        link = cores.link.copy()
        link[0] = value
        return link

    def pair_at(side, value):
        pairs = cores.pairs.copy()
        pairs[0, side] = value
        return pairs

    pieces_sizes = "pieces: sizes of q, t, the pairs, the joints and g disagree"
    terms_sizes = "{}: sizes of the limits or the singularities' joints disagree"
    chain_sizes = "{}: sizes of the chain, geoms and joint vectors disagree"
    pair_sizes = "arm_clearance: sizes of the geoms, pairs and outputs disagree"
    refused = [
        *[(pieces, (index(k),), pieces_sizes) for k in (-1, 7)],
        *[
            (call, (index(k), index(0)), terms_sizes.format(call.__name__))
            for call in (evaluate, linearise)
            for k in (-1, 7)
        ],
        *[
            (call, (index(0), index(k)), terms_sizes.format(call.__name__))
            for call in (evaluate, linearise)
            for k in (-1, 7)
        ],
        *[(poses, (link_at(k),), chain_sizes.format("arm_geom_poses")) for k in (-1, 8)],
        *[(clear, (link_at(k), cores.pairs), chain_sizes.format("arm_clearance")) for k in (-1, 8)],
        *[(clear, (cores.link, pair_at(0, k)), pair_sizes) for k in (-1, n_arm)],
        *[(clear, (cores.link, pair_at(1, k)), pair_sizes) for k in (n_arm - 1, n_arm + 1)],
    ]
    for call, args in [
        *[(pieces, (index(k),)) for k in (0, 6)],
        *[(call, (index(k), index(j))) for call in (evaluate, linearise) for k in (0, 6) for j in (0, 6)],
        *[(poses, (link_at(k),)) for k in (0, 7)],
        *[(clear, (link_at(k), cores.pairs)) for k in (0, 7)],
        *[(clear, (cores.link, pair_at(0, k))) for k in (0, n_arm - 1)],
        (clear, (cores.link, pair_at(1, n_arm))),
    ]:
        call(*args)
    for call, args, message in refused:
        with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
            call(*args)


def test_the_climb_bindings_refuse_groups_and_indices_out_of_range():
    """step_1d reads the pieces of each group between its ends: ends that do not
    start at 0, end at the pieces' count and increase are a ValueError, with no groups too;
    start_bound reads the samples a..b of its start k: k, a and b out of order or out of
    range, a group column out of range, or a reach that is not >= 0, are a ValueError; start_cones
    reads the samples of its starts: a start out of range is a ValueError."""
    v, a, z = np.arange(5.0), np.ones(5), np.empty(5)
    one, none = np.ones(1), np.empty(0)

    def groups(ends, w=one, n=5):
        pieces = _core.Pieces(v[:n], a[:n], np.array(ends, dtype=np.int64), w, -w, w)
        _core.step_1d(pieces, 1.0, -1.0, 1.0, z[:n])

    groups([0, 5])
    groups([0], none, 0)
    for ends, w, n in (([0], none, 5), ([1, 5], one, 5), ([0, 4], one, 5), ([0, 5, 5], np.ones(2), 5)):
        with pytest.raises(ValueError, match="sizes of the pieces, the groups and z disagree"):
            groups(ends, w, n)

    psi, values, slopes = np.linspace(0.0, 1.0, 4), np.zeros((4, 3)), np.ones((4, 3))

    def bound(k, first, last, reach=0.5, columns=(1, 2)):
        group_columns = np.array(columns, dtype=np.int64)
        weights = np.ones(len(columns))
        samples = _core.StartSamples(psi, values, slopes, group_columns, weights, weights)
        return _core.start_bound(samples, k, first, last, reach)

    assert all(bound(k, 0, 3) >= values[k, 0] for k in range(4))  # (at least f_k, read at either end)
    samples = _core.StartSamples(psi, values, slopes, np.array([1, 2]), np.ones(2), np.ones(2))
    out = np.empty(2)
    _core.start_cones(samples, np.array([0, 3]), np.ones(2), out)  # (read at either end)
    for starts, reach in (([-1, 0], np.ones(2)), ([0, 4], np.ones(2)), ([0, 1], np.ones(3))):
        with pytest.raises(ValueError, match="start_cones: sizes or indices of the starts disagree"):
            _core.start_cones(samples, np.array(starts), reach, out)
    for k, first, last, reach, columns in (
        (-1, 0, 3, 0.5, (1, 2)),
        (2, 3, 3, 0.5, (1, 2)),
        (1, 0, 4, 0.5, (1, 2)),
        (1, 0, 3, -1.0, (1, 2)),
        (1, 0, 3, math.nan, (1, 2)),
        (1, 0, 3, 0.5, (0, 2)),
        (1, 0, 3, 0.5, (1, 3)),
        (1, 0, 3, 0.5, (2, 1)),
    ):
        with pytest.raises(ValueError, match="start_bound: sizes or indices of the samples disagree"):
            bound(k, first, last, reach, columns)


class _Reordered(NamedTuple):
    """_core.StartSamples' fields in another order."""

    caps: np.ndarray
    weights: np.ndarray
    groups: np.ndarray
    slopes: np.ndarray
    values: np.ndarray
    psi: np.ndarray


class _Overridden(_core.StartSamples):
    """_core.StartSamples whose caps getattr does not read from the tuple."""

    __slots__ = ()

    @property
    def caps(self) -> np.ndarray:
        return np.zeros(len(self.weights))


def test_records_are_read_by_their_fields_names():
    """The kernels read a record's fields by name (the record's field indices resolved from its
    type's _fields, else getattr): the same answer from a NamedTuple of the fields in another
    order and from an object with those attributes; a subclass's property is what is read; a
    record without a field is a TypeError naming it."""
    psi, values = np.linspace(0.0, 1.0, 4), np.arange(12.0).reshape(4, 3)
    fields = dict(psi=psi, values=values, slopes=np.ones((4, 3)), groups=np.array([1, 2]), weights=np.ones(2))
    samples = _core.StartSamples(**fields, caps=np.full(2, 0.5))
    want = [_core.start_bound(samples, k, 0, 3, 0.4) for k in range(4)]
    for record in (
        _Reordered(**fields, caps=samples.caps),
        types.SimpleNamespace(**fields, caps=samples.caps),
    ):
        for _ in range(2):  # (the second read: by the indices resolved at the first)
            assert [_core.start_bound(record, k, 0, 3, 0.4) for k in range(4)] == want
    overridden = _Overridden(*samples)
    capped = [_core.start_bound(overridden, k, 0, 3, 0.4) for k in range(4)]
    assert capped != want and capped == [
        _core.start_bound(samples._replace(caps=np.zeros(2)), k, 0, 3, 0.4) for k in range(4)
    ]
    with pytest.raises(TypeError, match="must have a field 'caps'"):
        _core.start_bound(types.SimpleNamespace(**fields), 0, 0, 3, 0.4)


def test_link_paths_refuses_grids_counts_and_outputs_that_disagree(panda):
    """link_paths reads counts[k] roots at grid[k] from q and t and writes its rows and paths
    into outputs sized by the roots and the room given: counts that are negative or do not
    add up to the roots, roots, tangents or outputs of other sizes, and a grid that is not
    finite, increasing and within a turn are a ValueError, never a read or write past an
    end; a consistent call links (status 0)."""
    q0 = np.array([0.3, -0.4, 0.2, -2.0, 0.1, 1.6, 0.5])
    configuration = panda.configuration_of(q0)
    (psi0,) = configuration.redundancy
    work = _core.FollowWork(
        panda.kernel,
        panda.arm.fk(q0),
        np.array(configuration.signs, dtype=np.int64),
        np.ones(7, dtype=np.uint8),
        np.zeros(7, dtype=np.uint8),
        np.zeros(7),
        np.empty(7),
        np.empty(7),
    )
    tangent = self_motion_tangent(panda, q0)[:, 0]

    def link(
        grid=(0.0, 0.1, 0.2), counts=(1, 0, 0), roots=1, tangents=1, room=8, q_out=8, members=9, paths=9
    ):
        grid_roots = _core.LinkRoots(
            psi0 + np.array(grid),
            np.array(counts, dtype=np.int64),
            np.tile(q0, (roots, 1)),
            np.tile(tangent, (tangents, 1)),
        )
        rows = _core.LinkRows(
            np.empty(room),
            np.empty((q_out, 7)),
            np.empty((room, 7)),
            np.empty((members, 2), dtype=np.int64),
            np.empty((paths, 2), dtype=np.int64),
        )
        return _core.link_paths(work, grid_roots, rows)

    linked = link()
    assert (
        linked.status == _core.LINK_DONE and linked.paths == 1 and 2 <= linked.added <= 4
    )  # (0.1, 0.2 unlisted)
    assert tuple(link(counts=(0, 0, 0), roots=0, tangents=0, members=8, paths=8)) == (_core.LINK_DONE, 0, 0)
    message = (
        "link_paths: sizes of the grid, counts, roots and outputs disagree, or the grid is not "
        "increasing within a turn"
    )
    for bad in [
        {"counts": (1, 0)},
        {"counts": (2, -1, 0)},
        {"counts": (0, 0, 0)},
        {"counts": (1, 1, 0)},
        {"tangents": 2},
        {"roots": 2, "counts": (1, 1, 0)},
        {"q_out": 7},
        {"members": 8},
        {"paths": 10},
        {"grid": (0.0, 0.2, 0.1)},
        {"grid": (0.0, 0.0, 0.1)},
        {"grid": (0.0, 0.1, np.nan)},
        {"grid": (0.0, 0.1, 2.0 * np.pi)},
        {"grid": (), "counts": (), "roots": 0, "tangents": 0, "members": 8, "paths": 8},
    ]:
        with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
            link(**bad)


def test_the_parameter_layouts_fit_the_models_parameter_vectors():
    """The families' layouts are written once, in C (csrc/ik/om_kernels.h), and read from _core:
    every index lies within its vector, and each family's model has a vector of its size."""
    for prefix in ("SD_", "SRS_"):
        size = getattr(_core, prefix + "N_PARAMS")
        indices = [getattr(_core, name) for name in dir(_core) if name.startswith(prefix)]
        assert len(indices) > 10 and all(0 <= i <= size for i in indices), prefix
    sizes = {
        _core.RRR_SPHERICAL_WRIST: _core.SD_N_PARAMS,
        _core.RRP_SPHERICAL_WRIST: _core.SD_N_PARAMS,
        _core.SRS: _core.SRS_N_PARAMS,
    }
    families = set()
    for name in ("ur5e", "spherical", "panda"):
        model = om.OMSolver(name).model_arm
        assert model.params.shape == (sizes[model.family],), name
        families.add(model.family)
    assert families == set(sizes)
    assert set(SolverData._fields) >= {"family", "mode", "params", "dp_coefficients"}
