"""The singular class: branch boundaries, joint limits, psi's singular half-line, the other side."""

from __future__ import annotations

import math
import time
from collections import Counter

import numpy as np

from om_redundant.ik import BRANCH_BAND

from .answers import flipped
from .arm_run import ArmRun
from .records import Tally


def run_singular(run: ArmRun, n: int, n_limits: int, n_line: int = 0) -> Tally:
    """Poses at 1e-14 ... 1e-3 from a branch boundary, joints at their limits +- 1e-12, and
    (7-DOF) the wrist centre 1e-14 ... 1e-3 rad from the arm angle's singular half-line."""
    t = run.tally("singular")
    solver, start = run.solver, time.perf_counter()
    decades = run.result.decades
    other = run.result.other_side
    k = len(solver.sign_names)
    made = tries = 0
    while made < n and tries < 4 * n:
        tries += 1
        index = made % k
        value = float(run.rng.choice([-1.0, 1.0]) * 10.0 ** run.rng.uniform(-14.0, -3.0))
        q = run.boundary_q(index, value)
        if q is None:
            t.notes["no crossing within the limits (a new random q)"] += 1
            continue
        made += 1
        b = run.checker.branch(q)[index]
        column = str(math.floor(math.log10(abs(b)))) if b != 0.0 else "0"
        context = f"branch {solver.sign_names[index]} = {b:.3e}"
        bad = singular_case(run, t, q, decades.setdefault(column, Counter()), context)
        decades[column]["cases"] += 1
        decades[column]["any"] += bad
        if abs(b) <= BRANCH_BAND:
            other_side(run, t, q, index, other, context)
    if made < n:
        t.notes["branch poses short of the size asked"] += n - made
    for _ in range(n_limits):
        q = run.at_limits()
        if q is None:
            break
        counts = decades.setdefault("limits", Counter())
        counts["cases"] += 1
        at = np.flatnonzero(np.minimum(np.abs(q - run.arm.lower), np.abs(q - run.arm.upper)) < 1e-9)
        counts["any"] += singular_case(
            run, t, q, counts, f"joints {[int(j) + 1 for j in at]} at a limit +- 1e-12"
        )
    made = tries = 0
    while solver.redundancy_names and made < n_line and tries < 20 * n_line:
        tries += 1
        side = -1.0 if made % 4 else 1.0  # three of four below the shoulder
        q = run.near_arm_angle_line(float(10.0 ** run.rng.uniform(-14.0, -3.0)), side)
        if q is None:
            continue
        made += 1
        delta = run.arm_angle_line_angle(q, side)
        column = f"{'below' if side < 0 else 'above'} {math.floor(math.log10(delta)) if delta > 0 else '0'}"
        counts = run.result.arm_angle_line.setdefault(column, Counter())
        counts["cases"] += 1
        counts["any"] += singular_case(
            run, t, q, counts, f"wrist centre {delta:.3e} rad from straight {column.split()[0]} the shoulder"
        )
    if solver.redundancy_names and made < n_line:
        t.notes["arm angle line poses short of the size asked"] += n_line - made
    t.seconds = time.perf_counter() - start
    return t


def singular_case(run: ArmRun, t: Tally, q: np.ndarray, counts: Counter, context: str) -> bool:
    """solve, hinted solve and solve_all of T = FK(q) in configuration_of(q); whether any failed."""
    solver = run.solver
    T = run.arm.fk(q)
    c = solver.configuration_of(q)
    t.poses += 1
    before = (t.false_no, t.wrong_ok, t.foreign)
    calls = [("solve", lambda: solver.solve(T, c)), ("hinted solve", lambda: solver.solve(T, c, q_hint=q))]
    for call, fn in calls:
        done, sol = run.attempt(t, call, fn, q=q, T=T, c=c, context=context)
        if done:
            hint = q if call == "hinted solve" else None
            verdict = run.judge(t, call, sol, T, c, True, q=q, hint=hint, context=context)
            counts[f"false no ({call})"] += verdict is None
            counts["wrong ok"] += verdict is False
    if run.solve_all_here(t.poses):
        done, roots = run.attempt(
            t, "solve_all", lambda: solver.solve_all(T, c), q=q, T=T, c=c, context=context
        )
        if done:
            verdict = run.judge_all(t, roots, T, c, True, q=q, context=context)
            counts["false no (solve_all)"] += verdict is None
            counts["wrong ok"] += verdict is False
    return (t.false_no, t.wrong_ok, t.foreign) != before


def other_side(run: ArmRun, t: Tally, q: np.ndarray, index: int, counts: Counter, context: str) -> None:
    """The flipped sign of the branch at |offset| <= BRANCH_BAND: by the band contract the pose
    belongs to both configurations, so "no" there is a false no."""
    solver = run.solver
    T = run.arm.fk(q)
    c = flipped(solver.configuration_of(q), index, solver.sign_names)
    counts["cases"] += 1
    for call, fn in (
        ("solve", lambda: solver.solve(T, c)),
        ("hinted solve", lambda: solver.solve(T, c, q_hint=q)),
    ):
        done, sol = run.attempt(t, f"other side {call}", fn, q=q, T=T, c=c, context=context)
        if done:
            verdict = run.judge(t, f"other side {call}", sol, T, c, True, q=q, context=context)
            counts[f"ok ({call})"] += verdict is not None
            counts[f"false no ({call})"] += verdict is None
            counts["wrong ok"] += verdict is False
