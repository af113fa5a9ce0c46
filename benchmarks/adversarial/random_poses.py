"""The random class: solve, hinted solve, solve_batch and solve_all of T = FK(q)."""

from __future__ import annotations

import time

import numpy as np

import om_redundant as om

from .answers import batch_rows, redundancy_rows
from .arm_run import ArmRun
from .records import BATCH_CHUNK, HINT_NOISE, Tally


def run_random(run: ArmRun, n: int) -> Tally:
    """solve, hinted solve, solve_batch and solve_all of T = FK(q) in c = configuration_of(q)."""
    t = run.tally("random")
    solver, start = run.solver, time.perf_counter()
    run.pending = []
    Q = run.random_q(n)
    Ts = run.arm.fk(Q) if n else np.empty((0, 4, 4))
    hints = Q + run.rng.normal(0.0, HINT_NOISE, Q.shape)
    configurations: list[om.Configuration] = []
    for i in range(n):
        q, T = Q[i], Ts[i]
        c = solver.configuration_of(q)
        configurations.append(c)
        t.poses += 1
        done, sol = run.attempt(t, "solve", lambda T=T, c=c: solver.solve(T, c), q=q, T=T, c=c)
        if done:
            run.judge(t, "solve", sol, T, c, True, q=q)
        h = hints[i]
        done, sol = run.attempt(
            t, "hinted solve", lambda T=T, c=c, h=h: solver.solve(T, c, q_hint=h), q=q, T=T, c=c
        )
        if done:
            run.judge(t, "hinted solve", sol, T, c, True, q=q, hint=h)
        if run.solve_all_here(i):
            done, roots = run.attempt(t, "solve_all", lambda T=T, c=c: solver.solve_all(T, c), q=q, T=T, c=c)
            if done:
                run.judge_all(t, roots, T, c, True, q=q, hold_q=True)
    for lo in range(0, n, BATCH_CHUNK):
        hi = min(n, lo + BATCH_CHUNK)
        cs = configurations[lo:hi]
        signs = np.array([c.signs for c in cs])
        red = redundancy_rows(cs)
        t.calls += hi - lo - 1  # attempt counts one
        done, batch = run.attempt(
            t, "solve_batch", lambda s=signs, r=red, lo=lo, hi=hi: solver.solve_batch(Ts[lo:hi], s, r)
        )
        if done:
            for k, row in enumerate(batch_rows(batch)):
                run.judge(t, "solve_batch", row, Ts[lo + k], cs[k], True, q=Q[lo + k])
    run.flush()
    t.seconds = time.perf_counter() - start
    return t
