"""Time per solve of arms near a closed-form family, beside the exact family's.

Run: ``python -m benchmarks.near_timing [--n 300] [--dir DIR] [--json FILE] [--before FILE]``;
writes ``results/near_timing.md``. For each arm, N random in-limit q (seed 1): T = fk(q), c its
configuration; the median (and 90th percentile) wall time of ``solve(T, c)``, of the hinted
``solve(T, c, q_hint)`` (q moved by N(0, 0.01) rad per joint), of ``solve_from(T, c, q_hint)``
(the same joints as the previous pose's, a control tick's) and of ``solve_all(T, c)``, one
call at a time from Python. The arms: UR5e, Panda and iiwa14 with every joint row's twist bent
by +-eps (``benchmarks.near_family.bent``, seed 0), eps = 1e-6 ... 1e-3; the Menagerie near arms
(Piper, Lite6); with ``--dir`` the URDF arms that go through their nominal arm
(``benchmarks.urdf_arms``); and the shipped arms they are near, for reference. ``--json`` keeps
the medians; ``--before`` takes such a file (the same command run in a checkout of another
commit) as the table's "before" column; ``--note`` adds a line on the runs.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import om_redundant as om

from . import menagerie, urdf_arms
from .near_family import _random_q, bent
from .report import write_page

EXACT = ("ur5e", "panda", "iiwa14", "xarm7")
BENT = tuple((name, eps) for name in ("ur5e", "panda", "iiwa14") for eps in (1e-6, 1e-5, 1e-4, 1e-3))
MENAGERIE_NEAR = ("piper", "lite6")
URDF_NEAR = (
    "xArm7",
    "Kinova Jaco2 (j2s6s200)",
    "TIAGo",
    "TIAGo Pro (left)",
    "Unitree G1 (left)",
    "Baxter (left)",
    "iCub (left)",
    "ANYmal B + Kinova",
    "Reach Bravo 7",
)


def arms(folder: Path | None) -> dict[str, Callable[[], om.Arm]]:
    """The arms by their row name, each loaded when measured."""
    found: dict[str, Callable[[], om.Arm]] = {name: lambda name=name: om.load_arm(name) for name in EXACT}
    for name, eps in BENT:
        found[f"{name} bent {eps:g}"] = lambda name=name, eps=eps: bent(
            om.load_arm(name), eps, np.random.default_rng(0)
        )
    for name in MENAGERIE_NEAR:
        found[f"Menagerie {name}"] = lambda name=name: menagerie.import_arm(menagerie.REFERENCE[name])[0]
    for name in URDF_NEAR if folder else ():
        entry = urdf_arms.URDF_ARMS[name]
        if (folder / entry.path).is_file():
            found[f"URDF {name}"] = lambda entry=entry: menagerie.import_arm(entry, folder)[0]
    return found


def _timed(call: Callable[[], object]) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def measure(arm: om.Arm, n: int) -> dict[str, float]:
    """Median and 90th percentile (us) of solve, the hinted solve, the solve from the same
    joints taken as the previous pose's (a control tick's) and solve_all over n targets."""
    solver = om.OMSolver(arm)
    rng = np.random.default_rng(1)
    times: dict[str, list[float]] = {"solve": [], "hinted": [], "from": [], "solve_all": []}
    for q in _random_q(arm, n, rng):
        T = arm.fk(q)
        c = solver.configuration_of(q)
        hint = q + rng.normal(0.0, 0.01, arm.dof)
        times["solve"].append(_timed(lambda T=T, c=c: solver.solve(T, c)))
        times["hinted"].append(_timed(lambda T=T, c=c, hint=hint: solver.solve(T, c, q_hint=hint)))
        times["from"].append(_timed(lambda T=T, c=c, hint=hint: solver.solve_from(T, c, hint)))
        times["solve_all"].append(_timed(lambda T=T, c=c: solver.solve_all(T, c)))
    row = {"near": solver.nominal is not None}
    for key, values in times.items():
        row[key] = 1e6 * float(np.median(values))
        row[f"{key} p90"] = 1e6 * float(np.quantile(values, 0.9))
    return row


def _cell(row: dict, key: str, before: dict | None) -> str:
    now = f"{row[key]:,.1f} ({row[f'{key} p90']:,.0f})"
    if before is None or key not in before:
        return now
    return f"{before[key]:,.1f} ({before[f'{key} p90']:,.0f}) -> {now}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=300, help="random targets per arm")
    parser.add_argument("--dir", type=Path, help="folder of the URDFs (benchmarks.urdf_arms)")
    parser.add_argument("--json", type=Path, help="write the medians here")
    parser.add_argument("--before", type=Path, help="medians of another run: the 'before' column")
    parser.add_argument("--note", default="", help="a line on the runs (commits, load) for the page")
    args = parser.parse_args()
    before = json.loads(args.before.read_text()) if args.before else {}
    rows = {}
    for name, load in arms(args.dir).items():
        rows[name] = measure(load(), args.n)
        print(name, rows[name], flush=True)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    keys = ("solve", "hinted", "from", "solve_all")
    arrow = " (before -> now)" if before else ""
    lines = [
        f"# Time per solve near a closed-form family ({args.n} random targets per arm, seed 1)",
        "",
        f"Median (90th percentile) wall time in microseconds, one call at a time from Python{arrow}.",
        *([args.note] if args.note else []),
        "",
        "`" + " ".join(["python -m benchmarks.near_timing", *sys.argv[1:]]) + "`",
        "",
        "| arm | through the nominal arm | solve | hinted solve | solve from the hint as previous joints "
        "| solve_all |",
        "|---|---|---|---|---|---|",
    ]
    for name, row in rows.items():
        cells = [_cell(row, key, before.get(name)) for key in keys]
        lines.append(f"| {name} | {'yes' if row['near'] else 'no'} | " + " | ".join(cells) + " |")
    write_page("near_timing.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
