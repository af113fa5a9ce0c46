"""The mixed questions that the threads and repeated classes ask, and their first answers."""

from __future__ import annotations

from typing import Any

import numpy as np

import om_redundant as om

from .answers import answer_key, flipped
from .arm_run import ArmRun
from .records import HINT_NOISE, Tally


def questions(
    run: ArmRun, n: int, singular: bool
) -> list[tuple[str, np.ndarray, om.Configuration, Any, Any]]:
    """(call, T, c, hint, q) mixes: random, other branches, hinted, near-singular, solve_all."""
    solver, rng = run.solver, run.rng
    out = []
    k = len(solver.sign_names)
    while len(out) < n:
        q = None
        if singular and rng.random() < 0.3:
            q = run.boundary_q(
                int(rng.integers(k)), float(rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-14, -3))
            )
        if q is None:
            q = run.random_q(1)[0]
        T = run.arm.fk(q)
        c = solver.configuration_of(q)
        r = rng.random()
        if r < 0.2:
            c = flipped(c, int(rng.integers(k)), solver.sign_names)
        hint = q + rng.normal(0.0, HINT_NOISE, q.shape) if rng.random() < 0.4 else None
        call = "solve"
        if rng.random() < 0.15 and (not run.torus or rng.random() < 0.1):
            call, hint = "solve_all", None
        out.append((call, T, c, hint, q))
    return out


def ask(solver: om.OMSolver, call: str, T: np.ndarray, c: om.Configuration, hint: Any) -> Any:
    if call == "solve_all":
        return solver.solve_all(T, c)
    return solver.solve(T, c, q_hint=hint)


def answer_all(run: ArmRun, t: Tally, qs: list) -> list[Any]:
    """Ask every question once, judging each answer; returns their keys (None where a call
    raised), the reference that later answers must equal."""
    keys: list[Any] = []
    for call, T, c, hint, q in qs:
        done, answer = run.attempt(
            t, call, lambda call=call, T=T, c=c, h=hint: ask(run.solver, call, T, c, h), q=q, T=T, c=c
        )
        keys.append(answer_key(answer) if done else None)
        if done and call == "solve_all":
            run.judge_all(t, answer, T, c, False, q=q)
        elif done:
            run.judge(t, call, answer, T, c, False, q=q, hint=hint)
    return keys
