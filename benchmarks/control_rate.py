"""Redundancy resolution at control rate (issue 16): the optimiser's tracking step inside a
500 Hz mink loop, against plain mink's tick in the same run; writes results/control_rate.md.

For every shipped 7-DOF arm (``--arms``), with 0, 1 and 3 obstacles (a sphere, a capsule, a box), a
target moves along a figure eight around the hand (TICKS ticks of dt = 2 ms, one lap).
Every tick, interleaved:

* **plain mink**: FrameTask + PostureTask (cost 1e-2) + ConfigurationLimit, ``solve_ik``
  with daqp, then ``integrate_inplace``;
* **OM**: FrameTask + ``ExactPoseTask(optimizer=RedundancyOptimizer(...))`` +
  ConfigurationLimit, same solver: ``set_target`` of both tasks (the optimiser's tracking
  ``choose(T, previous)``) + ``solve_ik`` + ``integrate_inplace``;
* **tracking alone**: ``choose(T, previous)`` along the same path.

Times are wall (``perf_counter``) and process CPU (``process_time``), since the machine is
shared. Quality along the path: the hand exact (1e-10 m) on the optimiser's choice every
tick, clearance >= min_clearance and margins >= 0 every tick, branch flips counted. Then
the global ``choose(T)`` on GLOBAL_POSES poses of the path (3 obstacles), and, on
``--quality`` random poses per arm (3 obstacles), the convergence check
(:func:`converged_gap`): the tracked psi after convergence against the global optimiser's
climb from it.

Run: ``python -m benchmarks.control_rate [--ticks 2000] [--quality 200]``; ``--global-only``
times the global choose alone (``results/control_rate_global.md``).
"""

from __future__ import annotations

import argparse
import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass

import mink
import numpy as np

import om_redundant as om
from om_redundant.redundancy.choice.climb import maximise
from om_redundant.redundancy.choice.result import RedundancyChoice
from om_redundant.redundancy.paths.probe import Probe

from .report import cpu_model, write_page
from .robots import random_joints

TICKS = 2000
DT = 0.002
SOLVER = "daqp"
DAMPING = 1e-3
MIN_CLEARANCE = 0.03
MAX_STEP = 0.005  # rad per tick (the realtime example's): 2.5 rad/s at 500 Hz
GLOBAL_POSES = 10
HOMES = {
    "panda": np.array([0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785]),
    "iiwa14": np.array([0.0, 0.6, 0.0, -1.4, 0.0, 1.0, 0.0]),
}
# The other shipped 7-DOF arms' homes (bent elbow and wrist, inside every range): measured with
# --arms, not sampled by the tests that read HOMES.
ARM_HOMES = {
    **HOMES,
    "fr3": HOMES["panda"],
    "gen3": np.array([0.0, 0.26, 3.14, -2.27, 0.0, 0.96, 1.57]),
    "xarm7": np.array([0.0, -0.3, 0.0, 0.9, 0.0, 1.2, 0.0]),
    "sawyer": np.array([0.0, -1.18, 0.0, 2.18, 0.0, 0.57, 1.57]),
}
EXACT = 1e-10  # m: the hand on the choice's target
CONVERGED = 1e-12  # rad: tracking at one pose has converged when psi moves less
MAX_ITERATIONS = 4000  # tracking steps at one pose (2 pi / MAX_STEP = 1257 cross a whole turn)
PSI_GAP, VALUE_GAP = 1e-3, 1e-6  # the bars


def obstacles(hand: np.ndarray, count: int) -> list[om.Sphere | om.Capsule | om.Box]:
    """0, 1 or 3 obstacles placed about the home hand position (root frame)."""
    box_pose = np.eye(4)
    box_pose[:3, 3] = hand + np.array([0.0, -0.35, 0.25])
    shapes = [
        om.Sphere(hand + np.array([0.0, 0.3, 0.2]), 0.05),
        om.Capsule(hand + np.array([-0.25, -0.3, -0.3]), hand + np.array([-0.25, 0.3, -0.3]), 0.03),
        om.Box([0.05, 0.05, 0.05], box_pose),
    ]
    return shapes[:count]


def figure_eight(T_home: np.ndarray, k: int, ticks: int) -> np.ndarray:
    """The target at tick k: a figure eight of 10 x 20 cm about the home hand, one lap."""
    phase = 2.0 * math.pi * k / ticks
    T = T_home.copy()
    T[:3, 3] += [0.05 * math.sin(2.0 * phase), 0.1 * math.sin(phase), 0.03 * math.sin(3.0 * phase)]
    return T


def timed(call: Callable[[], object]) -> tuple[object, float, float]:
    """call()'s result, wall and process CPU time (s)."""
    wall, cpu = time.perf_counter(), time.process_time()
    result = call()
    return result, time.perf_counter() - wall, time.process_time() - cpu


@dataclass
class Run:
    """One arm and obstacle count: times (ms) per tick and the quality counts."""

    arm: str
    obstacles: int
    track_wall: np.ndarray
    track_cpu: np.ndarray
    om_wall: np.ndarray
    om_cpu: np.ndarray
    mink_wall: np.ndarray
    mink_cpu: np.ndarray
    not_exact: int
    infeasible: int
    flips: int
    failed: int


def run(name: str, count: int, ticks: int) -> Run:
    solver = om.OMSolver(name)
    arm = solver.arm
    T_home = arm.fk(ARM_HOMES[name])
    shapes = obstacles(T_home[:3, 3], count)

    def optimizer() -> om.RedundancyOptimizer:
        return om.RedundancyOptimizer(solver, shapes or None, min_clearance=MIN_CLEARANCE, max_step=MAX_STEP)

    model = om.arm_model(arm)
    frame = arm.frame_name
    path = [figure_eight(T_home, k, ticks) for k in range(ticks)]

    # tracking alone, with the quality checks
    tracker = optimizer()
    choice = tracker.choose(path[0])
    walls, cpus = [], []
    not_exact = infeasible = flips = failed = 0
    for T in path[1:]:
        previous = choice
        choice, wall, cpu = timed(lambda T=T, previous=previous: tracker.choose(T, previous))
        walls.append(wall)
        cpus.append(cpu)
        if not choice.ok:
            failed += 1
            choice = tracker.choose(T)
            continue
        flips += choice.branch_flipped
        reached = arm.fk(choice.solution.q)
        not_exact += np.linalg.norm(reached[:3, 3] - T[:3, 3]) > EXACT
        infeasible += choice.margin < 0.0 or choice.clearance < MIN_CLEARANCE

    # the mink loops, interleaved tick by tick
    plain_conf, om_conf = mink.Configuration(model), mink.Configuration(model)
    home = ARM_HOMES[name]
    plain_conf.update(home.copy())
    om_conf.update(home.copy())
    plain_hand = mink.FrameTask(frame, "site", position_cost=1.0, orientation_cost=1.0, lm_damping=1.0)
    posture = mink.PostureTask(model, cost=1e-2)
    posture.set_target(home)
    om_hand = mink.FrameTask(frame, "site", position_cost=1.0, orientation_cost=1.0, lm_damping=1.0)
    exact = om.ExactPoseTask(solver, model, optimizer=optimizer())
    plain_limits, om_limits = [mink.ConfigurationLimit(model)], [mink.ConfigurationLimit(model)]
    exact.set_target(path[0])
    exact.seed(om_conf)

    def plain_tick(target: mink.SE3) -> None:
        plain_hand.set_target(target)
        v = mink.solve_ik(plain_conf, [plain_hand, posture], DT, SOLVER, damping=DAMPING, limits=plain_limits)
        plain_conf.integrate_inplace(v, DT)

    def om_tick(target: mink.SE3) -> None:
        om_hand.set_target(target)
        exact.set_target(target)
        v = mink.solve_ik(om_conf, [om_hand, exact], DT, SOLVER, damping=DAMPING, limits=om_limits)
        om_conf.integrate_inplace(v, DT)

    times = {"om": ([], []), "mink": ([], [])}
    for T in path[1:]:
        target = mink.SE3.from_matrix(T)
        for key, tick in (("mink", plain_tick), ("om", om_tick)):
            _, wall, cpu = timed(lambda tick=tick, target=target: tick(target))
            times[key][0].append(wall)
            times[key][1].append(cpu)
    ms = lambda x: np.array(x) * 1e3  # noqa: E731
    return Run(
        name,
        count,
        ms(walls),
        ms(cpus),
        ms(times["om"][0]),
        ms(times["om"][1]),
        ms(times["mink"][0]),
        ms(times["mink"][1]),
        not_exact,
        infeasible,
        flips,
        failed,
    )


def global_times(name: str, poses: int, ticks: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Wall and CPU times (ms) of the global choose(T) with 3 obstacles on poses of the path,
    and each wall time in plain mink's ticks (:func:`plain_ticks`) timed just before it: the
    machine's speed drifts within minutes, and the ratio moves less with it."""
    solver = om.OMSolver(name)
    T_home = solver.arm.fk(ARM_HOMES[name])
    optimizer = om.RedundancyOptimizer(solver, obstacles(T_home[:3, 3], 3), min_clearance=MIN_CLEARANCE)
    tick = plain_ticks(solver, ticks)
    walls, cpus, in_ticks = [], [], []
    for k in np.linspace(0, ticks, poses, endpoint=False).astype(int):
        T = figure_eight(T_home, int(k), ticks)
        yardstick = tick(YARDSTICK_TICKS)
        _, wall, cpu = timed(lambda T=T: optimizer.choose(T))
        walls.append(wall)
        cpus.append(cpu)
        in_ticks.append(wall / yardstick)
    return np.array(walls) * 1e3, np.array(cpus) * 1e3, np.array(in_ticks)


def plain_ticks(solver: om.OMSolver, ticks: int) -> Callable[[int], float]:
    """A plain mink loop on the arm's figure eight (FrameTask + PostureTask +
    ConfigurationLimit, daqp, as in :func:`run`): a call runs n ticks on along the path and
    returns their median wall time (s)."""
    arm = solver.arm
    model = om.arm_model(arm)
    configuration = mink.Configuration(model)
    home = ARM_HOMES[arm.name]
    configuration.update(home.copy())
    hand = mink.FrameTask(arm.frame_name, "site", position_cost=1.0, orientation_cost=1.0, lm_damping=1.0)
    posture = mink.PostureTask(model, cost=1e-2)
    posture.set_target(home)
    limits = [mink.ConfigurationLimit(model)]
    T_home, at = arm.fk(home), [0]

    def run_ticks(n: int) -> float:
        walls = []
        for _ in range(n):
            hand.set_target(mink.SE3.from_matrix(figure_eight(T_home, at[0] % ticks, ticks)))
            at[0] += 1
            wall = time.perf_counter()
            v = mink.solve_ik(configuration, [hand, posture], DT, SOLVER, damping=DAMPING, limits=limits)
            configuration.integrate_inplace(v, DT)
            walls.append(time.perf_counter() - wall)
        return float(np.median(walls))

    return run_ticks


def converged_gap(optimizer: om.RedundancyOptimizer, q: np.ndarray) -> tuple[float, float] | None:
    """Tracking at pose fk(q) from q itself until psi stops moving, against the global
    optimiser's climb (:func:`~om_redundant.redundancy.choice.climb.maximise`) from the tracked
    optimum on the same branch: (|psi gap|, value gain of the climb over the tracked value).
    None where q is infeasible (outside the limits or too near an obstacle) or tracking
    leaves it (the branch has nothing feasible within reach of q's psi)."""
    solver = optimizer.solver
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    solution = solver.solve(T, c, q_hint=q)
    ev = optimizer.objective.evaluate(solution.q)
    if not (solution.ok and ev.feasible):
        return None
    choice = RedundancyChoice(True, c, solution, ev.margin, ev.clearance, ev.value, ())
    for _ in range(MAX_ITERATIONS):
        step = optimizer.choose(T, choice)
        if not step.ok or step.branch_flipped:
            return None
        moved = abs(turned(step, choice))
        choice = step
        if moved <= CONVERGED:
            break
    probe = Probe(solver, optimizer.objective, T, choice.configuration.signs, wrapped=False)
    start = probe.point(choice.configuration.redundancy[0], choice.solution.q, choice.solution)
    climbed = maximise(probe, start, -math.inf, math.inf, optimizer.max_step)
    gap = abs(math.remainder(climbed.psi - start.psi, 2 * math.pi))
    return gap, climbed.evaluation.value - start.evaluation.value


def turned(a: RedundancyChoice, b: RedundancyChoice) -> float:
    """psi of a less psi of b, in [-pi, pi]."""
    return math.remainder(a.configuration.redundancy[0] - b.configuration.redundancy[0], 2 * math.pi)


def quality(name: str, n: int, seed: int) -> tuple[int, int, float, float]:
    """(poses checked, poses failing both bars, worst psi gap, worst value gain)."""
    solver = om.OMSolver(name)
    T_home = solver.arm.fk(ARM_HOMES[name])
    optimizer = om.RedundancyOptimizer(solver, obstacles(T_home[:3, 3], 3), min_clearance=MIN_CLEARANCE)
    rng = np.random.default_rng(seed)
    checked = bad = 0
    worst_gap = worst_gain = 0.0
    for q in random_joints(solver.arm, n, rng):
        result = converged_gap(optimizer, q)
        if result is None:
            continue
        gap, gain = result
        checked += 1
        bad += gap > PSI_GAP and gain > VALUE_GAP
        worst_gap, worst_gain = max(worst_gap, gap), max(worst_gain, gain)
    return checked, bad, worst_gap, worst_gain


GLOBAL_HEADER = ["| arm | poses | wall | CPU | wall in plain mink ticks |", "|---|---|---|---|---|"]
YARDSTICK_TICKS = 25  # plain mink ticks timed before each global choose


def global_row(name: str, poses: int, ticks: int) -> str:
    """One arm's row of the global choose's table (:func:`global_times`), printed as well."""
    walls, cpus, in_ticks = global_times(name, poses, ticks)
    in_mink = f"{np.median(in_ticks):.0f} / {np.percentile(in_ticks, 99):.0f}"
    row = f"| {name} | {len(walls)} | {_stats(walls)} | {_stats(cpus)} | {in_mink} |"
    print(row, flush=True)
    return row


def global_page(arms: list[str], poses: int, ticks: int) -> str:
    """The global choose alone (``--global-only``): its table, with the load."""
    load = os.getloadavg()
    rows = [global_row(name, poses, ticks) for name in arms]
    return "\n".join(
        [
            "# Redundancy resolution at control rate: the global choose",
            "",
            f"CPU: {cpu_model()}; load average {load[0]:.1f} at the start, "
            f"{os.getloadavg()[0]:.1f} at the end. Global `choose(T)`, 3 obstacles, "
            f"min_clearance {MIN_CLEARANCE} m, poses of the path (ms, median / p99; and each "
            f"wall time over the median of {YARDSTICK_TICKS} plain mink ticks timed just before it):",
            "",
            *GLOBAL_HEADER,
            *rows,
            "",
        ]
    )


def _stats(x: np.ndarray) -> str:
    return f"{np.median(x):.3f} / {np.percentile(x, 99):.3f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=TICKS)
    parser.add_argument(
        "--quality", type=int, default=200, help="random poses per arm for the convergence check"
    )
    parser.add_argument("--globals", type=int, default=GLOBAL_POSES, help="poses timed for the global choose")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--arms", nargs="+", choices=list(ARM_HOMES), default=list(ARM_HOMES))
    parser.add_argument("--quality-only", action="store_true", help="only the convergence check")
    parser.add_argument(
        "--global-only", action="store_true", help="only the global choose (writes control_rate_global.md)"
    )
    args = parser.parse_args()
    if args.global_only:
        write_page("control_rate_global.md", global_page(args.arms, args.globals, args.ticks))
        return
    load = os.getloadavg()
    rows, global_rows, quality_rows = [], [], []
    for name in args.arms:
        for count in () if args.quality_only else (0, 1, 3):
            r = run(name, count, args.ticks)
            ratio_wall = np.median(r.om_wall) / np.median(r.mink_wall)
            ratio_cpu = np.median(r.om_cpu) / np.median(r.mink_cpu)
            cells = [name, count, *(_stats(x) for x in (r.track_wall, r.track_cpu, r.om_wall, r.om_cpu))]
            cells += [_stats(r.mink_wall), _stats(r.mink_cpu), f"{ratio_wall:.2f}", f"{ratio_cpu:.2f}"]
            cells += [r.not_exact, r.infeasible, r.flips, r.failed]
            rows.append("| " + " | ".join(str(c) for c in cells) + " |")
            print(rows[-1], flush=True)
        if not args.quality_only:
            global_rows.append(global_row(name, args.globals, args.ticks))
        if args.quality:
            checked, bad, gap, gain = quality(name, args.quality, args.seed)
            quality_rows.append(f"| {name} | {args.quality} | {checked} | {bad} | {gap:.2e} | {gain:.2e} |")
            print(quality_rows[-1], flush=True)
    load_after = os.getloadavg()
    text = "\n".join(
        [
            "# Redundancy resolution at control rate",
            "",
            f"CPU: {cpu_model()}; load average {load[0]:.1f} at the start, {load_after[0]:.1f} at the end. "
            f"{args.ticks} ticks of dt = {DT * 1e3:.0f} ms, QP solver {SOLVER}, "
            f"min_clearance {MIN_CLEARANCE} m, max_step {MAX_STEP} rad. Times in ms, median / p99; "
            "wall and process CPU.",
            "",
            "| arm | obstacles | tracking wall | tracking CPU | OM tick wall | OM tick CPU | "
            "mink tick wall | mink tick CPU | OM / mink wall | OM / mink CPU | not exact | infeasible | "
            "flips | failed |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
            "",
            "Global `choose(T)`, 3 obstacles, poses of the path (ms, median / p99):",
            "",
            *GLOBAL_HEADER,
            *global_rows,
            "",
            f"Convergence (3 obstacles): tracking from q at fk(q) until psi moves < {CONVERGED} rad, "
            "then the global optimiser's climb from there; a pose fails if the climb moves psi > "
            f"{PSI_GAP} rad and gains > {VALUE_GAP}.",
            "",
            "| arm | random poses | feasible, checked | failing | worst psi gap | worst value gain |",
            "|---|---|---|---|---|---|",
            *quality_rows,
            "",
        ]
    )
    write_page("control_rate_quality.md" if args.quality_only else "control_rate.md", text)


if __name__ == "__main__":
    main()
