"""7-DOF arms: recovery of random joint vectors, exactness, and speed; writes results/seven_dof.md.

For each arm, N joint vectors q uniform within limits (unlimited joints in [-pi, pi]), with
c = configuration_of(q) (SHOULDER, ELBOW, WRIST, psi):

* q among ``solve_all(fk(q), c)``;
* ``solve(fk(q), c, q_hint=q + U(+-0.01))`` returns q, or else another root nearer the hint
  (and how far that root lies from q: a close twin of q in the same configuration);
* every returned solution: position and orientation error, configuration equal to c.

Speed (medians of single calls from Python, and batch throughput) on the first arm.

Run: ``python -m benchmarks.seven_dof [--n 100000] [--arms panda fr3 iiwa14 gen3 xarm7 sawyer]``.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

import om_redundant as om
from om_redundant.angles import wrap_angles

from .report import cpu_model, write_page
from .robots import random_joints


def recovery(name: str, n: int, seed: int) -> dict[str, float]:
    """The issue's checks over n random joint vectors of one arm."""
    solver = om.OMSolver(name)
    rng = np.random.default_rng(seed)
    Q = random_joints(solver.arm, n, rng)
    hints = Q + rng.uniform(-0.01, 0.01, Q.shape)
    T = solver.arm.fk(Q)
    configurations = [solver.configuration_of(q) for q in Q]
    signs = np.array([c.signs for c in configurations])
    psi = np.array([c.redundancy[0] for c in configurations])
    batch = solver.solve_batch(T, signs, psi, q_hint=hints)
    among = hinted_q = nearest = wrong_c = roots_total = 0
    worst_pos = worst_ori = twin = 0.0
    for i, (q, c) in enumerate(zip(Q, configurations, strict=True)):
        roots = solver.solve_all(T[i], c)
        roots_total += len(roots)
        among += any(np.abs(wrap_angles(r.q - q)).max() < 1e-9 for r in roots)
        # Every returned solution: the roots of solve_all and the hinted batch solve.
        returned = [(r.ok, r.q, r.position_error, r.orientation_error) for r in roots]
        returned.append((batch.ok[i], batch.q[i], batch.position_error[i], batch.orientation_error[i]))
        for ok, q_returned, pos, ori in returned:
            worst_pos, worst_ori = max(worst_pos, pos), max(worst_ori, ori)
            wrong_c += not (ok and solver.configuration_of(q_returned).isclose(c))
        returned_q = np.abs(wrap_angles(batch.q[i] - q)).max() < 1e-9
        hinted_q += returned_q
        if not returned_q:  # how far the root returned instead lies from q
            twin = max(twin, np.linalg.norm(wrap_angles(batch.q[i] - q)))
        to_hint = [np.linalg.norm(wrap_angles(r.q - hints[i])) for r in roots]
        nearest += np.linalg.norm(wrap_angles(batch.q[i] - hints[i])) <= min(to_hint, default=np.inf) + 1e-9
    return {
        "arm": name,
        "dp_max": solver.dp_max,
        "n": n,
        "among": among / n,
        "hinted_q": hinted_q / n,
        "nearest": nearest / n,
        "twin": twin,
        "roots": roots_total / n,
        "wrong_c": wrong_c,
        "pos": worst_pos,
        "ori": worst_ori,
    }


def speed(name: str, n: int, seed: int) -> dict[str, float]:
    """Median time of solve and solve_all from Python, and solve_batch throughput."""
    solver = om.OMSolver(name)
    Q = random_joints(solver.arm, n, np.random.default_rng(seed + 1))
    T = solver.arm.fk(Q)
    configurations = [solver.configuration_of(q) for q in Q]
    solver.solve(T[0], configurations[0])
    solver.solve_all(T[0], configurations[0])

    def median_us(call, count):
        times = []
        for i in range(count):
            start = time.perf_counter()
            call(T[i], configurations[i])
            times.append(time.perf_counter() - start)
        return 1e6 * float(np.median(times))

    signs = np.array([c.signs for c in configurations])
    psi = np.array([c.redundancy[0] for c in configurations])
    solver.solve_batch(T[:8], signs[:8], psi[:8])
    start = time.perf_counter()
    solver.solve_batch(T, signs, psi)
    throughput = n / (time.perf_counter() - start)
    return {
        "solve": median_us(solver.solve, n),
        "solve_all": median_us(solver.solve_all, min(n, 5000)),
        "batch": throughput,
    }


def report(rows: list[dict[str, float]], timing: dict[str, float], speed_arm: str, seed: int) -> str:
    lines = [
        f"# 7-DOF arms: {rows[0]['n']:,} random joint vectors per arm (seed {seed})",
        "",
        "| arm | dp_max (m) | q among solve_all | hinted solve returns q | ... or a root nearer the hint "
        "| its largest distance from q (rad) | roots per (pose, c) | wrong configuration "
        "| max position error (m) | max orientation error (rad) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['arm']} | {r['dp_max']:.3f} | {100 * r['among']:.3f} % | {100 * r['hinted_q']:.3f} % "
            f"| {100 * r['nearest']:.3f} % | {r['twin']:.3f} | {r['roots']:.3f} | {r['wrong_c']} "
            f"| {r['pos']:.1e} | {r['ori']:.1e} |"
        )
    lines += [
        "",
        f"Speed, {speed_arm} ({cpu_model()}, {len(os.sched_getaffinity(0))} cores, "
        f"Python {platform.python_version()}):",
        "",
        "| call | measured | goal |",
        "|---|---|---|",
        f"| `solve` median, from Python | {timing['solve']:.1f} us | <= 15 us |",
        f"| `solve_all` median, from Python | {timing['solve_all']:.0f} us | <= 150 us |",
        f"| `solve_batch` | {timing['batch']:,.0f} solves/s | >= 200,000 solves/s |",
    ]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--n", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--arms", nargs="+", default=["panda", "fr3", "iiwa14", "gen3", "xarm7", "sawyer"])
    args = parser.parse_args()
    rows = []
    for name in args.arms:
        start = time.perf_counter()
        rows.append(recovery(name, args.n, args.seed))
        print(rows[-1], f"{time.perf_counter() - start:.0f} s", flush=True)
    timing = speed(args.arms[0], min(args.n, 20_000), args.seed)
    print(timing)
    write_page("seven_dof.md", report(rows, timing, args.arms[0], args.seed))


if __name__ == "__main__":
    main()
