"""The redundancy optimiser's global ``choose(T)`` (issue 16): CPU time and, against another
version of the code, the choices themselves.

On POSES random poses per arm (the hand of a joint vector drawn uniformly within the limits)
with 0, 1 and 3 obstacles placed about that hand (``benchmarks.control_rate.obstacles``),
``RedundancyOptimizer(solver, obstacles, min_clearance=0.03).choose(T)`` is timed (process
CPU, and wall) and its choice recorded: ok, branch signs, psi, objective value, margin,
clearance, the feasible intervals and the reason when nothing is feasible.

``--save FILE`` writes the choices as JSON; ``--compare FILE`` checks them against such a
file written by another version (e.g. ``main`` before a change): the answers "feasible or
not" must be identical, and a choice on another branch or farther than PSI_GAP rad in psi
must not be worse than theirs by more than VALUE_GAP (the issue's bars); such choices are
counted as worse, better or ties.

Run: ``python -m benchmarks.global_choose [--poses 50] [--arms panda iiwa14] [--save F | --compare F]``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time

import numpy as np

import om_redundant as om

from .control_rate import MIN_CLEARANCE, obstacles

POSES = 50
COUNTS = (0, 1, 3)
PSI_GAP, VALUE_GAP = 1e-3, 1e-6  # the bars


def record(choice: om.RedundancyChoice) -> dict:
    """The comparable content of a choice."""
    if not choice.ok:
        return {"ok": False, "reason": choice.reason}
    return {
        "ok": True,
        "signs": list(choice.configuration.signs),
        "psi": choice.configuration.redundancy[0],
        "value": choice.value,
        "margin": choice.margin,
        "clearance": choice.clearance if math.isfinite(choice.clearance) else None,
        "intervals": [[list(i.signs), i.lo, i.hi, i.closed] for i in choice.intervals],
    }


def run(name: str, count: int, poses: int, seed: int) -> tuple[list[dict], np.ndarray, np.ndarray]:
    """Choices and CPU / wall times (ms) of the global choose on random poses of one arm."""
    solver = om.OMSolver(name)
    rng = np.random.default_rng(seed)
    choices, cpus, walls = [], [], []
    span = np.where(solver.arm.revolute, np.pi, 1.0)  # an unlimited joint (the Gen3's) within +-pi
    lower = np.where(np.isfinite(solver.arm.lower), solver.arm.lower, -span)
    upper = np.where(np.isfinite(solver.arm.upper), solver.arm.upper, span)
    for q in rng.uniform(lower, upper, (poses, solver.arm.dof)):
        T = solver.arm.fk(q)
        optimizer = om.RedundancyOptimizer(
            solver, obstacles(T[:3, 3], count) or None, min_clearance=MIN_CLEARANCE
        )
        wall, cpu = time.perf_counter(), time.process_time()
        choice = optimizer.choose(T)
        cpus.append(time.process_time() - cpu)
        walls.append(time.perf_counter() - wall)
        choices.append(record(choice))
    return choices, np.array(cpus) * 1e3, np.array(walls) * 1e3


def differences(mine: list[dict], theirs: list[dict]) -> tuple[int, int, int, int, float]:
    """Between two runs over the same poses: (feasibility answers that differ; choices
    elsewhere (another branch, or psi farther than PSI_GAP) whose objective is worse than
    theirs by more than VALUE_GAP, better by more than VALUE_GAP, within VALUE_GAP (ties);
    the largest psi gap among the choices on the same branch within PSI_GAP)."""
    answers = worse = better = ties = 0
    worst = 0.0
    for a, b in zip(mine, theirs[: len(mine)], strict=True):  # (the same seed draws the same first poses)
        if a["ok"] != b["ok"]:
            answers += 1
        if not (a["ok"] and b["ok"]):
            continue
        gap = abs(math.remainder(a["psi"] - b["psi"], 2.0 * math.pi))
        if a["signs"] == b["signs"] and gap <= PSI_GAP:
            worst = max(worst, gap)
        elif a["value"] < b["value"] - VALUE_GAP:
            worse += 1
        elif a["value"] > b["value"] + VALUE_GAP:
            better += 1
        else:
            ties += 1
    return answers, worse, better, ties, worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--poses", type=int, default=POSES)
    parser.add_argument("--arms", nargs="+", default=["panda", "iiwa14"])
    parser.add_argument("--counts", nargs="+", type=int, default=list(COUNTS))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--save", help="write the choices to this JSON file")
    parser.add_argument("--compare", help="compare the choices with this JSON file")
    args = parser.parse_args()
    print(f"load average at the start {os.getloadavg()[0]:.1f}")
    print("| arm | obstacles | poses | feasible | CPU ms median / p99 | wall ms median / p99 | compared |")
    print("|---|---|---|---|---|---|---|")
    reference = {}
    if args.compare:
        with open(args.compare) as f:
            reference = json.load(f)
    saved = {}
    for name in args.arms:
        for count in args.counts:
            key = f"{name}/{count}"
            choices, cpus, walls = run(name, count, args.poses, args.seed)
            saved[key] = choices
            compared = ""
            if key in reference:
                answers, worse, better, ties, worst = differences(choices, reference[key])
                compared = f"answers differ {answers}; elsewhere: worse {worse}, better {better}, "
                compared += f"ties {ties}; psi gap otherwise <= {worst:.1e}"
            feasible = sum(c["ok"] for c in choices)
            stats = [f"{np.median(x):.1f} / {np.percentile(x, 99):.1f}" for x in (cpus, walls)]
            cells = [name, count, len(choices), feasible, *stats, compared]
            print("| " + " | ".join(str(c) for c in cells) + " |")
    print(f"load average at the end {os.getloadavg()[0]:.1f}")
    if args.save:
        with open(args.save, "w") as f:
            json.dump(saved, f)


if __name__ == "__main__":
    main()
