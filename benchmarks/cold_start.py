"""First answers from a cold start: each case in a fresh process, with an empty cache.

Run: ``python -m benchmarks.cold_start [--arms panda ur5e ...]``; writes
``results/cold_start.md``. Every case runs in a new Python process with ``NUMBA_CACHE_DIR``
set to a new empty folder (the project compiles no kernel at run time; the variable keeps
the protocol of the figures measured before its compiled core), and reports wall-clock
seconds from the process's own clock:

* import: ``import om_redundant`` (numpy, scipy, mujoco, mink, the compiled core);
* first solve: ``OMSolver(arm)``, the pose's FK and configuration, and the first ``solve``;
* first batch: the first ``solve_batch`` (two targets) after that;
* odd layouts: one ``solve`` each with a Fortran-order, a read-only and a strided pose and
  a strided hint, after a warm call;
* the default ``om-redundant`` run, as a command.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

from om_redundant import arm_names

from .report import write_page

_CASE = r"""
import json, sys, time
t0 = time.perf_counter()
import numpy as np
import om_redundant as om
t_import = time.perf_counter()
solver = om.OMSolver(sys.argv[1])
q = np.where(np.isfinite(solver.arm.lower), (solver.arm.lower + solver.arm.upper) / 2, 0.3) + 0.1
T = solver.arm.fk(q)
c = solver.configuration_of(q)
assert solver.solve(T, c).ok
t_solve = time.perf_counter()
redundancy = np.array(c.redundancy) if c.redundancy else None
assert solver.solve_batch(np.stack([T, T]), c.signs, redundancy).ok.all()
t_batch = time.perf_counter()
layouts = {
    "fortran": (np.asfortranarray(T), None),
    "read-only": (T.copy(), None),
    "strided": (np.repeat(T, 2, axis=1)[:, ::2], None),
    "strided hint": (T, np.repeat(q, 2)[::2]),
}
layouts["read-only"][0].flags.writeable = False
odd = {}
for name, (pose, hint) in layouts.items():
    t = time.perf_counter()
    assert solver.solve(pose, c, q_hint=hint).ok
    odd[name] = time.perf_counter() - t
print(json.dumps({
    "import": t_import - t0, "first solve": t_solve - t_import, "first batch": t_batch - t_solve,
    "odd layout, worst": max(odd.values()),
}))
"""


def run_case(arm: str) -> dict[str, float]:
    """One arm's case in a fresh process with an empty cache folder."""
    cache = tempfile.mkdtemp(prefix="om_cold_")
    try:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        out = subprocess.run(
            [sys.executable, "-c", _CASE, arm], env=env, capture_output=True, text=True, check=True
        )
        return json.loads(out.stdout.strip().splitlines()[-1])
    finally:
        shutil.rmtree(cache, ignore_errors=True)


def default_command_seconds() -> float:
    """Wall time of the default ``om-redundant`` run, from a fresh process and empty cache."""
    cache = tempfile.mkdtemp(prefix="om_cold_")
    try:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        start = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "om_redundant.cli", "-q"], env=env, capture_output=True, check=True
        )
        return time.perf_counter() - start
    finally:
        shutil.rmtree(cache, ignore_errors=True)


def _seconds(value: float) -> str:
    return f"{value:.2f} s" if value >= 1.0 else f"{value * 1e3:.1f} ms"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", nargs="+", default=arm_names(), choices=arm_names())
    args = parser.parse_args()
    rows = []
    for arm in args.arms:
        case = run_case(arm)
        rows.append((arm, case))
        print(arm, " ".join(f"{k}={v:.4f}s" for k, v in case.items()), flush=True)
    command = default_command_seconds()
    print(f"om-redundant (default run) {command:.2f}s", flush=True)
    keys = list(rows[0][1])
    lines = [
        "| arm | " + " | ".join(keys) + " |",
        "|---" * (len(keys) + 1) + "|",
        *(f"| {arm} | " + " | ".join(_seconds(case[k]) for k in keys) + " |" for arm, case in rows),
        "",
        f"Default `om-redundant` run, whole command from a fresh process: {command:.2f} s.",
    ]
    write_page("cold_start.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
