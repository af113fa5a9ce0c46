"""The threads class: threads sharing a solver agree with serial calls; batches equal rows."""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from .answers import answer_key, batch_rows, redundancy_rows
from .arm_run import ArmRun
from .questions import answer_all, ask, questions
from .records import THREADS, Tally


def run_threads(run: ArmRun, n: int) -> Tally:
    """4 threads sharing the solver agree bit for bit with serial calls; batches equal rows."""
    t = run.tally("threads")
    solver, start = run.solver, time.perf_counter()
    qs = questions(run, n, singular=False)
    t.poses = len(qs)
    serial = answer_all(run, t, qs)
    orders = [run.rng.permutation(len(qs)) for _ in range(THREADS)]

    def worker(order: np.ndarray) -> list[tuple[int, Any]]:
        found = []
        for i in order:
            call, T, c, hint, _ = qs[i]
            try:
                found.append((int(i), answer_key(ask(solver, call, T, c, hint))))
            except Exception as error:  # compared with the serial answer below
                found.append((int(i), f"{type(error).__name__}: {error}"))
        return found

    with ThreadPoolExecutor(THREADS) as pool:
        for found in pool.map(worker, orders):
            for i, key in found:
                t.calls += 1
                if key != serial[i]:
                    call, T, c, hint, q = qs[i]
                    run.differ(
                        t, f"{call} in a thread", "differs from the serial call", q=q, T=T, c=c, hint=hint
                    )
    # solve_batch equals per-row solve, with and without hints; also 4 batches at once.
    rows = [i for i, x in enumerate(qs) if x[0] == "solve"]
    for hinted in (False, True):
        idx = [i for i in rows if (qs[i][3] is not None) == hinted]
        if not idx:
            continue
        Ts = np.stack([qs[i][1] for i in idx])
        cs = [qs[i][2] for i in idx]
        signs, red = np.array([c.signs for c in cs]), redundancy_rows(cs)
        hints = np.stack([qs[i][3] for i in idx]) if hinted else None
        batches = []
        done, batch = run.attempt(
            t, "solve_batch", lambda Ts=Ts, s=signs, r=red, h=hints: solver.solve_batch(Ts, s, r, q_hint=h)
        )
        if not done:
            continue
        batches.append(("solve_batch", batch))
        with ThreadPoolExecutor(THREADS) as pool:
            futures = [pool.submit(solver.solve_batch, Ts, signs, red, hints) for _ in range(THREADS)]
            batches += [("solve_batch in a thread", f.result()) for f in futures]
        for name, b in batches:
            t.calls += len(idx) - (name == "solve_batch")
            for k, row in enumerate(batch_rows(b)):
                if answer_key(row) != serial[idx[k]]:
                    call, T, c, hint, q = qs[idx[k]]
                    run.differ(t, name, "row differs from the per-row solve", q=q, T=T, c=c, hint=hint)
    t.seconds = time.perf_counter() - start
    return t
