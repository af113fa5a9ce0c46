"""The layouts class: Fortran-order, read-only, strided, big-endian and list inputs."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from .answers import answer_key, batch_rows, redundancy_rows
from .arm_run import ArmRun
from .records import HINT_NOISE, Tally


def layouts_of(a: np.ndarray) -> dict[str, Any]:
    """The same array as Fortran-order, read-only, strided, big-endian and list inputs."""
    read_only = a.copy()
    read_only.flags.writeable = False
    strided = np.repeat(a, 2, axis=-1)[..., ::2]
    out = {
        "read-only": read_only,
        "strided": strided,
        "big-endian": a.astype(">f8") if a.dtype.kind == "f" else a.astype(">i8"),
        "list": a.tolist(),
    }
    if a.ndim >= 2:
        out["fortran"] = np.asfortranarray(a)
        out["reversed rows"] = np.ascontiguousarray(a[::-1])[::-1]
    else:
        out["tuple"] = tuple(a.tolist())
    return out


def run_layouts(run: ArmRun, n: int) -> Tally:
    """Every layout of pose, hint, batch signs and redundancy: the C-order call's answer."""
    t = run.tally("layouts")
    solver, start = run.solver, time.perf_counter()
    Q = run.random_q(n)
    if not n:
        return t
    Ts = np.ascontiguousarray(run.arm.fk(Q))
    hints = Q + run.rng.normal(0.0, HINT_NOISE, Q.shape)
    configurations = [solver.configuration_of(q) for q in Q]
    for i in range(n):
        q, T, h, c = Q[i], Ts[i], hints[i], configurations[i]
        t.poses += 1
        calls = {
            "solve": (lambda T_, h_, c=c: solver.solve(T_, c), T, None),
            "hinted solve": (lambda T_, h_, c=c: solver.solve(T_, c, q_hint=h_), T, h),
        }
        if run.solve_all_here(i):
            calls["solve_all"] = (lambda T_, h_, c=c: solver.solve_all(T_, c), T, None)
        for call, (fn, T0, h0) in calls.items():
            done, base = run.attempt(t, call, lambda fn=fn, T0=T0, h0=h0: fn(T0, h0), q=q, T=T, c=c)
            if not done:
                continue
            if call == "solve_all":
                run.judge_all(t, base, T, c, True, q=q, hold_q=True)
            else:
                run.judge(t, call, base, T, c, True, q=q, hint=h0)
            variants = [(f"T {k}", v, h0) for k, v in layouts_of(T).items()]
            if h0 is not None:
                variants += [(f"q_hint {k}", T, v) for k, v in layouts_of(h0).items()]
            for name, Tv, hv in variants:
                done, other = run.attempt(
                    t, f"{call}, {name}", lambda fn=fn, Tv=Tv, hv=hv: fn(Tv, hv), q=q, T=T, c=c
                )
                if done and answer_key(other) != answer_key(base):
                    run.differ(t, f"{call}, {name}", "differs from the C-order call", q=q, T=T, c=c, hint=h0)
    # Batches: the whole sample at once, every argument in every layout.
    signs = np.array([c.signs for c in configurations], dtype=np.int64)
    red = redundancy_rows(configurations)
    base_args = {"T": Ts, "signs": signs, "redundancy": red, "q_hint": hints}
    done, base = run.attempt(t, "solve_batch", lambda: solver.solve_batch(Ts, signs, red, q_hint=hints))
    if done:
        rows = batch_rows(base)
        for k, row in enumerate(rows):
            run.judge(t, "solve_batch", row, Ts[k], configurations[k], True, q=Q[k], hint=hints[k])
        variants = []
        for arg, value in base_args.items():
            if value is None:
                continue
            variants += [(f"{arg} {k}", arg, v) for k, v in layouts_of(value).items()]
            if arg == "redundancy":
                variants.append(("redundancy (M,)", arg, value[:, 0].copy()))
            if arg == "signs" and len({c.signs for c in configurations}) == 1:
                variants.append(("signs (k,)", arg, signs[0].copy()))
        for name, arg, value in variants:
            args = {**base_args, arg: value}
            done, other = run.attempt(
                t,
                f"solve_batch, {name}",
                lambda a=args: solver.solve_batch(a["T"], a["signs"], a["redundancy"], q_hint=a["q_hint"]),
            )
            t.calls += n - 1
            if done:
                for k, (x, y) in enumerate(zip(batch_rows(other), rows, strict=True)):
                    if answer_key(x) != answer_key(y):
                        run.differ(
                            t,
                            f"solve_batch, {name}",
                            f"row {k} differs",
                            q=Q[k],
                            T=Ts[k],
                            c=configurations[k],
                        )
    t.seconds = time.perf_counter() - start
    return t
