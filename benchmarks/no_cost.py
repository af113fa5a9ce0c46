"""What a "no" costs: ``solve`` and ``solve_all`` where the answer is that there is none.

Run: ``python -m benchmarks.no_cost [--arms ...] [--n 200] [--seed 0]``; writes
``results/no_cost.md``. Per arm, ``n`` random q within limits (unlimited joints in
[-pi, pi]), T = FK(q), and three kinds of question:

* **yes**: ``solve_all(T, c)`` in c = configuration_of(q), which holds q (for scale);
* **no in c'**: ``solve(T, c')`` and ``solve_all(T, c')`` for every other configuration c'
  (the signs flipped, psi + pi across the ELBOW) whose ``solve_all`` is empty: the answer
  "no solution in this configuration", which must search before it says so;
* **unreachable**: ``solve(T, c)`` with T moved 10 m away.

Each figure is the median over the questions of the best of :data:`REPEATS` timed calls, in
microseconds (``time.perf_counter_ns``), measured in one process; the machine is shared, so
compare figures of one run, and the load average is printed with them.
"""

from __future__ import annotations

import argparse
import itertools
import math
import os
import time
from collections.abc import Callable

import numpy as np

import om_redundant as om

from .adversarial import flipped
from .report import cpu_model, write_page
from .robots import random_joints

REPEATS = 3  # timed calls per question; the fastest counts
FAR = 10.0  # m: the unreachable pose's translation


def best_us(fn: Callable[[], object]) -> float:
    """The fastest of REPEATS calls of fn, in microseconds."""
    best = math.inf
    for _ in range(REPEATS):
        start = time.perf_counter_ns()
        fn()
        best = min(best, time.perf_counter_ns() - start)
    return best / 1e3


def others(solver: om.OMSolver, c: om.Configuration) -> list[om.Configuration]:
    """Every configuration but c (the branches flipped one by one, :func:`adversarial.flipped`)."""
    found = []
    for flips in itertools.product((False, True), repeat=len(c.signs)):
        other = c
        for index in np.flatnonzero(flips):
            other = flipped(other, int(index), solver.sign_names)
        if any(flips):
            found.append(other)
    return found


def measure(name: str, n: int, seed: int) -> dict[str, float]:
    """Median microseconds per kind of question on one arm."""
    solver = om.OMSolver(name)
    rng = np.random.default_rng(seed)
    Q = random_joints(solver.arm, n, rng)
    kinds = ("yes solve_all", "no solve", "no solve_all", "unreachable")
    times: dict[str, list[float]] = {kind: [] for kind in kinds}
    for q in Q:
        T, c = solver.arm.fk(q), solver.configuration_of(q)
        solver.solve_all(T, c)  # warm
        times["yes solve_all"].append(best_us(lambda T=T, c=c: solver.solve_all(T, c)))
        for other in others(solver, c):
            if solver.solve_all(T, other):
                continue
            times["no solve"].append(best_us(lambda T=T, c=other: solver.solve(T, c)))
            times["no solve_all"].append(best_us(lambda T=T, c=other: solver.solve_all(T, c)))
        far = T.copy()
        far[:3, 3] += FAR
        times["unreachable"].append(best_us(lambda T=far, c=c: solver.solve(T, c)))
    result = {kind: float(np.median(v)) if v else math.nan for kind, v in times.items()}
    result["no questions"] = len(times["no solve"])
    return result


def main(argv: list[str] | None = None) -> dict[str, dict[str, float]]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", nargs="+", default=om.arm_names(), choices=om.arm_names())
    parser.add_argument("--n", type=int, default=200, help="random poses per arm")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    results = {name: measure(name, args.n, args.seed) for name in args.arms}
    kinds = ["yes solve_all", "no solve", "no solve_all", "unreachable"]
    lines = [
        '# What a "no" costs',
        "",
        f"Machine: {cpu_model()}, {os.cpu_count()} cores; load average {load:.2f} at the start, "
        f"{os.getloadavg()[0]:.2f} at the end (shared machine: compare figures of one run).  ",
        f"Run: `python -m benchmarks.no_cost --n {args.n} --seed {args.seed}`. Median of the best of "
        f"{REPEATS} calls, microseconds.",
        "",
        "| arm | " + " | ".join(kinds) + " | no questions |",
        "|---" * (len(kinds) + 2) + "|",
    ]
    for name, r in results.items():
        cells = " | ".join(f"{r[k]:.1f}" for k in kinds)
        lines.append(f"| {name} | {cells} | {int(r['no questions'])} |")
    write_page("no_cost.md", "\n".join(lines) + "\n")
    return results


if __name__ == "__main__":
    main()
