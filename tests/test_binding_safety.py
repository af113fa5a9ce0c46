"""The compiled kernels' entry points are safe for any Python input: a Solver initialised
once, an uninitialised one, lists changed while they are read, malformed solver data, sizes,
signs and indices out of range, tables shorter than q, NaN targets, rotations far from
orthonormal, and a pose written by another thread during a batch. Each case runs in a fresh
interpreter (``run_case``): a crash or a hang fails its test instead of the whole run."""

from __future__ import annotations

import textwrap

import pytest

from tests.conftest import run_python

pytestmark = pytest.mark.sanitize

PREAMBLE = """
import threading
import numpy as np
import om_redundant as om
from om_redundant import _core

solver = om.OMSolver("panda")
kernel, data = solver.kernel, solver.solver_data()
Q = np.array([0.3, -0.4, 0.2, -2.2, 0.3, 1.9, 0.6])
T, c = solver.arm.fk(Q), solver.configuration_of(Q)
SIGNS = np.array(c.signs, dtype=np.int64)


def raises(kind, call, *args):
    try:
        call(*args)
    except kind:
        return
    raise AssertionError(f"{call} {args!r:.200} did not raise {kind.__name__}")


def solves(call=kernel.solve):
    assert call(T, c.signs, c.redundancy, None, np.zeros(7), False).status == _core.OK
"""


def run_case(body: str, timeout: float = 120) -> None:
    """Run PREAMBLE and body in a fresh interpreter, which must reach the body's end (where it
    prints "finished") within timeout (s) and exit 0: a crash, a hang or a failed assertion
    there fails the test."""
    done = run_python("-c", PREAMBLE + textwrap.dedent(body) + "\nprint('finished')", timeout=timeout)
    assert done.returncode == 0 and done.stdout.rstrip().endswith("finished"), (
        f"exit {done.returncode}\n{done.stdout[-2000:]}\n{done.stderr[-4000:]}"
    )


def test_a_solver_is_initialised_once():
    run_case("""
        raises(RuntimeError, kernel.__init__, data._replace(flip=np.ones(3)))  # was a use after free
        raises(RuntimeError, kernel.__init__, data)
        solves()
        fresh = _core.Solver.__new__(_core.Solver)
        raises(ValueError, fresh.__init__, data._replace(flip=np.ones(3)))
        raises(ValueError, fresh.__init__, data._replace(scan_points=3))
        raises(RuntimeError, fresh.solve, T, c.signs, c.redundancy, None, np.zeros(7), False)
        fresh.__init__(data)
        solves(fresh.solve)
    """)


def test_an_uninitialised_solver_raises():
    run_case("""
        bare = _core.Solver.__new__(_core.Solver)
        methods = ["solve", "solve_pose", "solve_rows", "solve_all_rows", "solve_all", "configuration_values",
                   "bounded_search", "torus_bound", "holds"]
        for name in methods:
            raises(RuntimeError, getattr(bare, name))
        raises(RuntimeError, bare.solve, T, (), (), None, np.zeros(0), False)
        raises(RuntimeError, bare.solve_rows, None, 0, 0)
        raises(RuntimeError, _core.follow, _core.FollowWork(bare, *[None] * 7), 0.0, 0.0, 0.0)
        work, roots = _core.FollowWork(bare, *[None] * 7), _core.LinkRoots(*[None] * 4)
        raises(RuntimeError, _core.link_paths, work, roots, _core.LinkRows(*[None] * 5))
        walks = [("self_motion_tangents", 3)]
        for name, arity in walks:
            raises(RuntimeError, getattr(_core, name), bare, *[None] * (arity - 1))
        raises(RuntimeError, _core.track_step, _core.TrackingWork(bare, *[None] * 12), None, None, 0.0)
    """)


def test_lists_emptied_while_they_are_read():
    run_case("""
        class Clears:
            def __init__(self, items, value):
                self.items, self.value = items, value
            def __index__(self):
                self.items.clear()
                return self.value
            def __float__(self):
                self.items.clear()
                return float(self.value)
            def __bool__(self):
                self.items.clear()
                return True

        signs = []
        signs += [Clears(signs, s) for s in c.signs]
        redundancy = []
        redundancy.append(Clears(redundancy, c.redundancy[0]))
        assert kernel.solve(T, signs, redundancy, None, np.zeros(7), False).status == _core.OK
        assert kernel.holds(Q, signs[:] or [Clears(signs, s) for s in c.signs], c.redundancy)
        psi, feasible = [], []
        psi += [Clears(psi, 0.0), 0.1, 0.2]
        feasible += [True, Clears(feasible, True), True]
        q = [Q.copy() for _ in range(3)]
        pieces = [(np.ones(1), np.zeros(1))] * 3
        first = np.zeros(3)
        tangents, bounds, cyclic = [np.ones(7)] * 3, np.array([0, 3]), np.zeros(7, dtype=bool)
        samples = _core.CellSamples(q, tangents, psi, pieces, feasible, bounds, cyclic)
        _core.cell_looks(samples, 1.0, 0.0, np.zeros((4, 3)), first)
    """)


def test_malformed_solver_data_is_refused():
    run_case("""
        ur5e = om.OMSolver("ur5e").solver_data()
        wrist_row = _core.SD_WRIST_ROW
        bad = [
            dict(scan_points=3), dict(scan_points=2**30), dict(scan_points=_core.MAX_SCAN_POINTS + 1),
            dict(dp_joint=-1), dict(dp_joint=7), dict(mode=5), dict(family=9), dict(params=np.zeros(5)),
            dict(model_table=data.model_table[:3]), dict(real_table=data.real_table[:2]),
            dict(nominal_table=data.real_table[:1]), dict(flip=np.zeros(7)), dict(position_tolerance=np.nan),
            dict(orientation_tolerance=0.0), dict(near_deviation=np.inf), dict(lower=np.zeros(9)),
            dict(upper=np.zeros(6)), dict(lower=np.zeros(0)),
        ]
        for change in bad:
            raises(ValueError, _core.Solver, data._replace(**change))
        raises(OverflowError, _core.Solver, data._replace(dp_joint=2**70))
        raises(TypeError, _core.Solver, data._replace(params=list(data.params)))
        for row in [np.nan, 1e9, -1.0, 2.5]:
            params = ur5e.params.copy()
            params[wrist_row] = row
            raises(ValueError, _core.Solver, ur5e._replace(params=params))
            target = _core.FlangeTarget(np.eye(3), np.zeros(3), np.ones(3, dtype=np.int64), np.zeros(0))
            raises(ValueError, _core.model_ik, _core.FamilyModel(0, params, ur5e.model_table), target,
                   np.zeros(6), np.zeros(6), False)
    """)


def test_batch_rows_refuse_signs_and_rows_out_of_range():
    run_case("""
        Ts = np.stack([T, T])
        psi = np.full((2, 1), c.redundancy[0])

        def rows(signs):
            ints = np.zeros(2, dtype=np.int64)
            return _core.SolveBatch(Ts, signs, psi, None, np.zeros((2, 7)), ints, np.zeros(2), np.zeros(2),
                                    ints.copy(), np.zeros(2, dtype=bool))

        def all_rows(signs):
            n = _core.MAX_ROOTS
            ints = np.zeros(2, dtype=np.int64)
            errors = np.zeros((2, n))
            return _core.SolveAllBatch(Ts, signs, psi, np.ones(2, dtype=bool), np.zeros((2, n, 7)), ints,
                                       ints.copy(), errors, errors.copy(), np.zeros((2, n), dtype=bool))

        for sign in [5, 0, -2**63]:
            signs = np.array([c.signs, c.signs], dtype=np.int64)
            signs[1, 1] = sign
            raises(ValueError, kernel.solve_rows, rows(signs), 0, 2)
            raises(ValueError, kernel.solve_all_rows, all_rows(signs), 0, 2)
            kernel.solve_rows(rows(signs), 0, 1)  # the rows asked for are checked
        signs = np.array([c.signs, c.signs], dtype=np.int64)
        for start, stop in [(-1, 1), (0, 3), (2, 1), (2**62, 2**62 + 1)]:
            raises(ValueError, kernel.solve_rows, rows(signs), start, stop)
            raises(ValueError, kernel.solve_all_rows, all_rows(signs), start, stop)
        raises(OverflowError, kernel.solve_rows, rows(signs), 0, 2**70)
        raises(TypeError, kernel.solve_rows, (Ts, signs), 0, 2)  # (not a batch: no named fields)
        raises(ValueError, kernel.solve, T, (1, 2, 1), c.redundancy, None, np.zeros(7), False)
    """)


def test_tables_shorter_than_q_are_refused():
    run_case("""
        table = data.real_table
        raises(ValueError, _core.jacobian, table[:2], np.eye(4), np.eye(4), Q, np.zeros((6, 7)))
        raises(ValueError, _core.flange, table[:2], Q, np.zeros(9), np.zeros(3))
        raises(ValueError, _core.flange, table, Q[:3], np.zeros(9), np.zeros(3))
        raises(ValueError, _core.arm_angle_gradient, data.params, data.model_table[:2], Q, np.zeros(7))
        raises(ValueError, _core.polish, table, np.eye(3), np.zeros(3), Q, 5,
               _core.ArmAngleRow(data.params, data.model_table[:2], 0.0))
        raises(ValueError, _core.polish, table, np.eye(3), np.zeros(3), Q, 2**40, None)
        J = np.zeros((6, 7))
        _core.jacobian(table, np.eye(4), np.eye(4), Q, J)
        assert np.isfinite(J).all()
    """)


def test_a_follow_with_a_nan_target_returns():
    run_case(
        """
        t = np.zeros((1, 7))
        _core.self_motion_tangents(kernel, Q[None], t)
        cyclic, centred = np.zeros(7, dtype=bool), np.zeros(7, dtype=bool)
        psi = c.redundancy[0]
        for target, min_step, start in [(np.nan, 1e-9, psi), (psi + 1, np.nan, psi), (psi + 1, 0.0, psi),
                                        (np.inf, 1e-9, psi), (psi + 1, 1e-9, np.nan), (1e300, -1.0, psi)]:
            work = _core.FollowWork(kernel, T, SIGNS, cyclic, centred, np.zeros(7), Q.copy(), t[0].copy())
            try:
                _core.follow(work, start, target, min_step)
            except ValueError:
                pass
        for signs in [np.array([1, 5, 1]), np.array([1, -(2**63), 1])]:  # (copied and checked)
            work = _core.FollowWork(kernel, T, signs, cyclic, centred, np.zeros(7), Q.copy(), t[0].copy())
            raises(ValueError, _core.follow, work, psi, psi + 1, 1e-9)
    """,
        timeout=60,
    )


@pytest.mark.parametrize("name", ["panda", "ur5e", "gen3", "iiwa14", "sawyer", "xarm7", "spherical"])
def test_a_rotation_far_from_orthonormal_returns(name):
    run_case(
        f"""
        solver = om.OMSolver({name!r})
        kernel, dof = solver.kernel, solver.arm.dof
        arm = solver.arm
        q0 = np.random.default_rng(0).uniform(np.maximum(arm.lower, -3), np.minimum(arm.upper, 3))
        T, c = solver.arm.fk(q0), solver.configuration_of(q0)
        for i in range(3):
            for j in range(4):
                for value in [-1e16, 1e300, np.nan]:
                    bad = T.copy()
                    bad[i, j] = value
                    kernel.solve(bad, c.signs, c.redundancy, None, np.zeros(dof), False)
                    n = _core.MAX_ROOTS
                    roots = _core.Roots(np.zeros((n, dof)), np.zeros(n), np.zeros(n), np.zeros(n, dtype=bool))
                    kernel.solve_all(bad, c.signs, c.redundancy, roots)
                    kernel.bounded_search(bad, c.signs, c.redundancy, roots.q, True)
                    if j < 3 or not np.isfinite(value):  # (a finite position is a pose, out of reach)
                        raises(om.InvalidInput, solver.solve, bad, c)
        for psi in [np.nan, np.inf, 1e300] if dof == 7 else []:
            kernel.solve(T, c.signs, (psi,), None, np.zeros(dof), False)
    """,
        timeout=240,
    )


def test_a_pose_written_during_a_batch_is_solved_as_checked():
    run_case(
        """
        rng = np.random.default_rng(1)
        q = rng.uniform(solver.arm.lower, solver.arm.upper, (400, 7))
        Ts, configurations = solver.arm.fk(q), [solver.configuration_of(row) for row in q]
        signs, psi = [x.signs for x in configurations], [x.redundancy for x in configurations]
        Ts[:, :3, 3] *= 0.5  # poses nearer the base: mostly reachable, none on the edge of reach
        reference = solver.solve_batch(Ts, signs, psi, threads=2)
        stop, good = threading.Event(), Ts.copy()

        def write():  # the rotations' first entries far from orthonormal, and back
            while not stop.is_set():
                Ts[:, 0, 1] = -1e16
                Ts[:, 0, 1] = good[:, 0, 1]

        writer = threading.Thread(target=write)
        writer.start()
        try:
            answered = 0
            for _ in range(20):
                try:
                    batch = solver.solve_batch(Ts, signs, psi, threads=2)
                except om.InvalidInput:
                    continue
                answered += 1
                np.testing.assert_array_equal(batch.status, reference.status)
        finally:
            stop.set()
            writer.join()
        print("answered", answered)
    """,
        timeout=300,
    )


def test_kept_traces_are_checked_and_outlive_their_solver():
    """torus_traces: None for an arm whose searches trace none, a capsule for the Sawyer that a
    batch fills and follow and link_paths read; another object, or another solver's traces (one
    the capsule alone keeps alive), are refused by name."""
    run_case("""
        import gc
        raises(TypeError, _core.torus_traces, None)
        raises(RuntimeError, _core.torus_traces, _core.Solver.__new__(_core.Solver))
        assert _core.torus_traces(kernel) is None
        sawyer = om.OMSolver("sawyer")
        traces = _core.torus_traces(sawyer.kernel)
        orphan = _core.torus_traces(om.OMSolver("sawyer").kernel)  # (its solver: the capsule's alone)
        gc.collect()
        q0 = np.array([0.1, -0.8, 0.2, 1.6, 0.1, 0.6, 1.5])
        Ts, cs = sawyer.arm.fk(q0), sawyer.configuration_of(q0)
        rows = [np.repeat(Ts[None], 8, 0), np.tile(cs.signs, (8, 1)), np.linspace(-3, 3, 8), np.ones(8, bool)]
        for bad, kind in [(object(), TypeError), ("traces", TypeError), (orphan, ValueError)]:
            raises(kind, sawyer.solve_grid, *rows, None, 64, bad)
        sawyer.solve_grid(*rows, traces=traces)
        t = np.zeros((1, 7))
        _core.self_motion_tangents(sawyer.kernel, q0[None], t)
        flags, signs = np.zeros(7, dtype=np.uint8), np.array(cs.signs, dtype=np.int64)
        roots = _core.LinkRoots(np.zeros(1), np.zeros(1, dtype=np.int64), np.zeros((0, 7)), np.zeros((0, 7)))
        pairs = np.zeros((1, 2), dtype=np.int64)
        added = _core.LinkRows(np.zeros(1), np.zeros((1, 7)), np.zeros((1, 7)), pairs, pairs.copy())
        psi = cs.redundancy[0]
        for kept, kind in [(object(), TypeError), (orphan, ValueError), (traces, None), (None, None)]:
            start = (q0.copy(), t[0].copy())
            work = _core.FollowWork(sawyer.kernel, Ts, signs, flags, flags, np.zeros(7), *start, kept)
            if kind is None:
                _core.follow(work, psi, psi + 0.5, 1e-9)
            else:
                raises(kind, _core.follow, work, psi, psi + 0.5, 1e-9)
                raises(kind, _core.link_paths, work, roots, added)
    """)
