"""Solvers across processes and signals: pickled (spawned workers, Dask, Ray), used in a forked
child after a threaded batch, and a long batch stopped by Ctrl-C within about a second."""

from __future__ import annotations

import multiprocessing
import os
import pickle
import signal
import subprocess
import sys
import time

import mujoco
import numpy as np
import pytest

import om_redundant as om
from tests.conftest import ROOT, checkout_env, random_q

Q_PANDA = np.array([0.3, -0.4, 0.2, -2.2, 0.3, 1.9, 0.6])


@pytest.mark.parametrize("name", ["ur5e", "panda", "gen3"])
def test_a_pickled_solver_solves_as_the_original(name):
    solver = om.OMSolver(name, scan_points=48)
    copy = pickle.loads(pickle.dumps(solver))
    assert copy.scan_points == 48 and copy.tolerances == solver.tolerances
    q = random_q(solver.arm, 20, np.random.default_rng(0))
    T, c = solver.arm.fk(q), [solver.configuration_of(row) for row in q]
    signs, redundancy = [x.signs for x in c], [x.redundancy for x in c] if solver.arm.dof == 7 else None
    mine, theirs = solver.solve_batch(T, signs, redundancy), copy.solve_batch(T, signs, redundancy)
    assert mine.ok.all() and theirs.ok.all()
    np.testing.assert_array_equal(mine.q, theirs.q)


def test_a_pickled_optimizer_chooses_as_the_original_with_the_world_it_read():
    solver = om.OMSolver("panda")
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(solver.arm))
    ball = spec.worldbody.add_body(name="ball", mocap=True, pos=[0.0, 0.8, 1.0])
    ball.add_geom(name="ball", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.05, 0, 0])
    model = spec.compile()
    clearance = om.Clearance(model, solver.arm, ["ball"])
    data = mujoco.MjData(model)
    data.mocap_pos[0] = [0.1, 0.3, 0.6]  # moved: the copy keeps where it was read
    mujoco.mj_kinematics(model, data)
    clearance.update(data)
    optimizer = om.RedundancyOptimizer(
        solver, clearance, min_clearance=0.02, max_step=0.01, travel_weight=0.5
    )
    copy = pickle.loads(pickle.dumps(optimizer))
    assert (copy.max_step, copy.travel_weight, copy.min_clearance) == (0.01, 0.5, 0.02)
    np.testing.assert_array_equal(copy.clearance.distances(Q_PANDA), clearance.distances(Q_PANDA))
    T = solver.arm.fk(Q_PANDA)
    mine, theirs = optimizer.choose(T), copy.choose(T)
    assert mine.ok and theirs.ok and mine.configuration == theirs.configuration and mine.value == theirs.value
    np.testing.assert_array_equal(mine.solution.q, theirs.solution.q)


def _solve_in_worker(solver_and_T):
    solver, T = solver_and_T
    return solver.solve(T, solver.configuration_of(Q_PANDA)).q


def test_a_solver_goes_to_a_spawned_worker():
    solver = om.OMSolver("panda")
    T = solver.arm.fk(Q_PANDA)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        (q,) = pool.map(_solve_in_worker, [(solver, T)])
    np.testing.assert_allclose(q, Q_PANDA, atol=1e-9)


def test_a_forked_child_solves_after_a_threaded_batch():
    """The parent's pool threads are not in the child: it makes its own (it waited forever)."""
    solver = om.OMSolver("panda")
    q = random_q(solver.arm, 300, np.random.default_rng(1))
    c = [solver.configuration_of(row) for row in q]
    T, signs, psi = solver.arm.fk(q), [x.signs for x in c], [x.redundancy for x in c]
    assert solver.solve_batch(T, signs, psi).ok.all()  # threads (more rows than one chunk)
    pid = os.fork()
    if pid == 0:  # the child: exit 0 if the batch completes
        os._exit(0 if solver.solve_batch(T, signs, psi).ok.all() else 1)
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            assert os.waitstatus_to_exitcode(status) == 0
            return
        time.sleep(0.05)
    os.kill(pid, signal.SIGKILL)
    pytest.fail("the forked child's batch never returned")


def test_ctrl_c_stops_a_long_batch_within_a_second():
    """SIGINT a second into a batch of many seconds: KeyboardInterrupt within ~1 s of it."""
    script = (
        "import signal, numpy as np, om_redundant as om\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"  # (a parent run in the background
        # without job control, as CI may be, leaves SIGINT ignored, and Python then keeps it so)
        "s = om.OMSolver('sawyer')\n"
        "q = np.random.default_rng(0).uniform(s.arm.lower, s.arm.upper, (20000, 7))\n"
        "c = s.configuration_of(q[0])\n"
        "T, signs, psi = s.arm.fk(q), [c.signs] * len(q), [c.redundancy] * len(q)\n"
        "print('start', flush=True)\n"
        "try:\n"
        "    s.solve_all_batch(T, signs, psi)\n"
        "    print('finished')\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", script], cwd=ROOT, env=checkout_env(), stdout=subprocess.PIPE, text=True
    )
    assert child.stdout.readline().strip() == "start"
    time.sleep(1.0)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    waited = time.monotonic() - sent
    assert out.strip() == "interrupted" and waited < 2.0, (out, waited)
