"""The circle search at few scan points against a dense one: roots a coarse search misses.

Run: ``python -m benchmarks.coarse_search [--arms panda fr3 xarm7] [--n 4000] [--points 8 16]
[--seed 0]``; writes ``results/coarse_search.md``. Per arm, ``n`` random q within limits
(unlimited joints in [-pi, pi]), T = FK(q), and in each of the configurations of T (the signs
of every branch, q's redundancy) ``solve_all`` at each coarse ``scan_points`` and at
:data:`DENSE`. Counted per coarse size: configurations whose coarse roots are not one to one
those of the dense search (within :data:`SAME` rad), the dense roots missed, roots found
only by the coarse search, and targets whose coarse ``solve_all`` in c = configuration_of(q)
does not hold q.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import om_redundant as om

from .report import cpu_model, write_page
from .robots import joint_distance, random_joints

DENSE = 1024  # scan points of the reference search
SAME = 1e-9  # rad: two roots are one (the same root refined from other samples differs in its last digits)


def _matches(arm: om.Arm, a: list[om.Solution], b: list[om.Solution]) -> int:
    """How many roots of a have one of b (within SAME, revolute joints modulo 2 pi)."""
    return sum(any(joint_distance(arm, x.q, y.q) < SAME for y in b) for x in a)


def measure(name: str, n: int, points: list[int], seed: int) -> dict[int, dict[str, int]]:
    """Counts per coarse size on one arm (see the module's docstring)."""
    dense = om.OMSolver(name, scan_points=DENSE)
    coarse = {p: om.OMSolver(name, scan_points=p) for p in points}
    counts = {p: {"configurations": 0, "differ": 0, "missed": 0, "extra": 0, "q missed": 0} for p in points}
    for q in random_joints(dense.arm, n, np.random.default_rng(seed)):
        T, own = dense.arm.fk(q), dense.configuration_of(q)
        for c in dense.configurations(own.redundancy):
            reference = dense.solve_all(T, c)
            for p, solver in coarse.items():
                found = solver.solve_all(T, c)
                missed = len(reference) - _matches(dense.arm, reference, found)
                extra = len(found) - _matches(dense.arm, found, reference)
                row = counts[p]
                row["configurations"] += 1
                row["differ"] += int(missed > 0 or extra > 0)
                row["missed"] += missed
                row["extra"] += extra
                if c == own:
                    row["q missed"] += int(not any(joint_distance(dense.arm, r.q, q) < SAME for r in found))
    return counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", nargs="+", default=["panda", "fr3", "xarm7"])
    parser.add_argument("--n", type=int, default=4000, help="random targets per arm")
    parser.add_argument("--points", type=int, nargs="+", default=[8, 16], help="coarse scan_points")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    start, load = time.time(), os.getloadavg()[0]
    lines = [
        "# A coarse circle search against a dense one",
        "",
        f"Machine: {cpu_model()}; load average {load:.2f} at the start.  ",
        f"Run: `python -m benchmarks.coarse_search --arms {' '.join(args.arms)} --n {args.n} "
        f"--points {' '.join(map(str, args.points))} --seed {args.seed}`; reference: scan_points={DENSE}.",
        "",
        "| arm | scan_points | configurations | differ | dense roots missed | coarse-only roots | q missed |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in args.arms:
        for p, row in measure(name, args.n, args.points, args.seed).items():
            lines.append(
                f"| {name} | {p} | {row['configurations']:,} | {row['differ']} | {row['missed']} | "
                f"{row['extra']} | {row['q missed']} of {args.n:,} |"
            )
    lines += ["", f"{time.time() - start:.0f} s in all."]
    write_page("coarse_search.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
