"""The repeated class: a question asked again, after another call, gets the same answer."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

import om_redundant as om

from .answers import Row, answer_key, batch_rows
from .arm_run import ArmRun
from .questions import answer_all, ask, questions
from .records import Tally


def run_repeated(run: ArmRun, n: int) -> Tally:
    """The same question, asked again in random order after another call: the same answer."""
    t = run.tally("repeated")
    solver, rng, start = run.solver, run.rng, time.perf_counter()
    qs = questions(run, n, singular=True)
    t.poses = len(qs)

    def batch_ask(T: np.ndarray, c: om.Configuration, hint: Any) -> Row:
        red = [c.redundancy] if c.redundancy else None
        return batch_rows(
            solver.solve_batch(T[None], c.signs, red, q_hint=None if hint is None else hint[None])
        )[0]

    first = answer_all(run, t, qs)
    for i in rng.permutation(len(qs)):
        j = int(rng.integers(len(qs)))  # another question first, by another call
        call, T, c, hint, q = qs[j]
        before = rng.choice(["solve", "hinted", "solve_all", "batch"])
        if before == "solve_all" and run.torus and rng.random() > 0.1:
            before = "batch"
        try:
            if before == "solve":
                solver.solve(T, c)
            elif before == "hinted":
                solver.solve(T, c, q_hint=q)
            elif before == "solve_all":
                solver.solve_all(T, c)
            else:
                batch_ask(T, c, hint)
        except Exception:
            pass  # only the answer to question i is compared
        call, T, c, hint, q = qs[i]
        done, again = run.attempt(
            t, call, lambda call=call, T=T, c=c, h=hint: ask(solver, call, T, c, h), q=q, T=T, c=c
        )
        if done and answer_key(again) != first[i]:
            run.differ(t, call, f"asked again after a {before} call: differs", q=q, T=T, c=c, hint=hint)
        if call == "solve":  # the same question as a batch row
            done, row = run.attempt(
                t, "solve_batch row", lambda T=T, c=c, h=hint: batch_ask(T, c, h), q=q, T=T, c=c
            )
            if done and answer_key(row) != first[i]:
                run.differ(t, "solve_batch row", "differs from solve", q=q, T=T, c=c, hint=hint)
    t.seconds = time.perf_counter() - start
    return t
