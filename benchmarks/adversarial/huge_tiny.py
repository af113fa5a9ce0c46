"""The huge/tiny class: huge hints and arm angles, poses far away, tiny translations."""

from __future__ import annotations

import math
import time

import numpy as np

import om_redundant as om

from .answers import answer_key, batch_rows, reduced
from .arm_run import ArmRun
from .checker import angle_distance
from .records import REDUNDANCY_TOLERANCE, TURN, Tally


def run_huge_tiny(run: ArmRun, n: int) -> Tally:
    """Huge hints, huge arm angles, poses translated far away, tiny translations."""
    t = run.tally("huge/tiny")
    solver, arm, rng, start = run.solver, run.arm, run.rng, time.perf_counter()
    Q = run.random_q(n)
    Ts = arm.fk(Q) if n else np.empty((0, 4, 4))
    for i in range(n):
        q, T = Q[i], Ts[i]
        c = solver.configuration_of(q)
        red = np.array([c.redundancy]) if c.redundancy else None
        t.poses += 1
        # A hint of magnitude 1e3 ... 1e300: every ok exact, and still ok.
        if i % 2:
            hint = np.full(arm.dof, rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(3.0, 300.0))
        else:
            hint = rng.choice([-1.0, 1.0], arm.dof) * 10.0 ** rng.uniform(3.0, 300.0, arm.dof)
        done, sol = run.attempt(
            t, "huge hint", lambda T=T, c=c, h=hint: solver.solve(T, c, q_hint=h), q=q, T=T, c=c, hint=hint
        )
        if done:
            run.judge(t, "huge hint", sol, T, c, True, q=q, hint=hint)
        done, batch = run.attempt(
            t,
            "huge hint batch",
            lambda T=T, c=c, r=red, h=hint: solver.solve_batch(T[None], c.signs, r, q_hint=h[None]),
            q=q,
            T=T,
            c=c,
            hint=hint,
        )
        if done:
            run.judge(t, "huge hint batch", batch_rows(batch)[0], T, c, True, q=q, hint=hint)
        # psi + 2 pi k, k huge: the same answer as for its exact reduction.
        if c.redundancy:
            huge_psi(run, t, q, T, c)
        # Translated by 1e3 ... 1e300 m: ok False, "unreachable".
        far = T.copy()
        far[:3, 3] += unit(rng) * 10.0 ** rng.uniform(3.0, 300.0)
        for call, fn in (
            ("far solve", lambda far=far, c=c: solver.solve(far, c)),
            ("far hinted solve", lambda far=far, c=c, q=q: solver.solve(far, c, q_hint=q)),
            (
                "far solve_batch",
                lambda far=far, c=c, r=red: batch_rows(solver.solve_batch(far[None], c.signs, r))[0],
            ),
        ):
            done, sol = run.attempt(t, call, fn, T=far, c=c, T_is_fk=False)
            if done:
                run.judge(t, call, sol, far, c, False, T_is_fk=False)
                if sol.status != "unreachable":
                    t.notes["far: status not 'unreachable'"] += 1
                    run.record(
                        t, "far: not unreachable", call, f"status '{sol.status}'", T=far, c=c, T_is_fk=False
                    )
        done, roots = run.attempt(
            t, "far solve_all", lambda far=far, c=c: solver.solve_all(far, c), T=far, c=c, T_is_fk=False
        )
        if done:
            run.judge_all(t, roots, far, c, False, T_is_fk=False)
        # Translation changed by 1e-300 (the same reachable pose) and a translation of size 1e-300.
        near = T.copy()
        near[:3, 3] += unit(rng) * 1e-300
        done, sol = run.attempt(t, "tiny shift", lambda n_=near, c=c: solver.solve(n_, c), q=q, T=near, c=c)
        if done:
            run.judge(t, "tiny shift", sol, near, c, True, q=q)
        tiny = T.copy()
        tiny[:3, 3] = unit(rng) * 1e-300
        for call, fn in (
            ("tiny position solve", lambda x=tiny, c=c: solver.solve(x, c)),
            (
                "tiny position batch",
                lambda x=tiny, c=c, r=red: batch_rows(solver.solve_batch(x[None], c.signs, r))[0],
            ),
        ):
            done, sol = run.attempt(t, call, fn, T=tiny, c=c, T_is_fk=False)
            if done:
                run.judge(t, call, sol, tiny, c, False, T_is_fk=False)
    t.seconds = time.perf_counter() - start
    return t


def huge_psi(run: ArmRun, t: Tally, q: np.ndarray, T: np.ndarray, c: om.Configuration) -> None:
    solver, rng = run.solver, run.rng
    # Half the draws keep psi + 2 pi k within 1e-9 of psi (k <= 1e5 or so), half do not.
    exponent = rng.uniform(3.0, 16.0) if rng.random() < 0.5 else rng.uniform(16.0, 300.0)
    k = math.floor(10.0**exponent)
    psi = c.redundancy[0] + TURN * k
    huge = om.Configuration(c.signs, (psi,))
    small = reduced(huge)
    exact = angle_distance(small.redundancy[0], c.redundancy[0]) <= REDUNDANCY_TOLERANCE
    t.notes["huge psi within 1e-9 of psi"] += exact
    done_h, a = run.attempt(t, "huge psi", lambda: solver.solve(T, huge), q=q, T=T, c=huge)
    done_r, b = run.attempt(t, "reduced psi", lambda: solver.solve(T, small), q=q, T=T, c=small)
    if done_h:
        run.judge(t, "huge psi", a, T, huge, exact, q=q)
    if done_h and done_r and answer_key(a) != answer_key(b):
        run.differ(t, "huge psi", f"'{a.status}' vs reduced '{b.status}'", q=q, T=T, c=huge)
    rows = []
    for cfg in (huge, small):
        done, batch = run.attempt(
            t,
            "huge psi batch",
            lambda cfg=cfg: solver.solve_batch(T[None], cfg.signs, [cfg.redundancy]),
            q=q,
            T=T,
            c=cfg,
        )
        rows.append(batch_rows(batch)[0] if done else None)
    if rows[0] is not None:
        run.judge(t, "huge psi batch", rows[0], T, huge, exact, q=q)
    if rows[0] is not None and rows[1] is not None and answer_key(rows[0]) != answer_key(rows[1]):
        run.differ(t, "huge psi batch", f"'{rows[0].status}' vs reduced '{rows[1].status}'", q=q, T=T, c=huge)


def unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)
