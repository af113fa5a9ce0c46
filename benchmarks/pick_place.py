"""Pick and place with mink, the optimiser-fed ExactPoseTask against plain mink, in one run.

Each arm (the project's MJCF: capsules, Menagerie's joint and frame names) stands at the
back of a table, a pole beside its base where the elbow goes when it reaches left, and a ball
that sweeps to and fro above the workspace (a mocap body: the obstacles move). The hand
visits WAYPOINTS poses of pick-and-place cycles (above the pick, down, up, above the place,
down, up; the hand pointing down, a random turn about it), each held until the hand is on it
within 1 mm and 1 deg, or HOLD seconds. Targets jump to each waypoint (``step``) or move
there along a straight line at SPEED (``interpolated``).

Both controllers run mink at 500 Hz with the same FrameTask and limits (ConfigurationLimit,
VelocityLimit, CollisionAvoidanceLimit on the pairs the optimiser's Clearance declares):
plain mink adds a PostureTask (cost 1e-2), OM an ``om.ExactPoseTask`` whose
``om.RedundancyOptimizer`` keeps MIN_CLEARANCE from the table, the pole and the moving ball,
reading where the ball is every tick. Printed per arm, mode and controller: waypoints reached,
ticks where the task raised, ticks that chose afresh (the first tick's and every one where
tracking stopped or the way on was blocked), the smallest clearance along the motion
(MuJoCo's own ``mj_geomDistance`` over the pairs, every tick), the smallest joint-limit
margin, branch flips, and the controller's time per tick (median, p99).

Run: python -m benchmarks.pick_place [--arms panda fr3 iiwa14 gen3 xarm7 sawyer] [--modes step interpolated]
     [--waypoints 20] [--seed 0] [--out benchmarks/results/pick_place.md] [--video docs/pick_place.mp4]
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import mink
import mujoco
import numpy as np

import om_redundant as om

from .pages import write_block

RATE = 500.0  # Hz
DT = 1.0 / RATE
WAYPOINTS = 20
HOLD = 3.0  # s a waypoint is held at most
SPEED = 0.5  # m/s of an interpolated target
REACHED = (1e-3, np.deg2rad(1.0))  # m, rad
MIN_CLEARANCE = 0.03  # m the optimiser keeps
#: m: mink's CollisionAvoidanceLimit keeps MIN_CLEARANCE less this (its safety layer under the
#: optimiser's choices)
MINK_MARGIN = 0.005
MAX_STEP = 0.005  # rad of psi per tick at 500 Hz
GAIN = 0.5
VELOCITY = 2.0  # rad/s, every joint
BALL = dict(centre=np.array([0.45, 0.0, 0.72]), amplitude=0.3, period=10.0, radius=0.05)
POLE = ([0.2, 0.45, 0.0], [0.2, 0.45, 0.9], 0.03)
TABLE = dict(pos=[0.6, 0.0, -0.02], size=[0.3, 0.6, 0.04])  # its top 2 cm above the floor
GRASP, ABOVE = 0.15, 0.32  # m: flange heights at and above a pick or place
CAMERA = dict(lookat=[0.4, 0.0, 0.35], distance=1.7, azimuth=145.0, elevation=-22.0)
ARMS = ("panda", "fr3", "iiwa14", "gen3", "xarm7", "sawyer")  # every shipped 7-DOF arm


def scene(arm: om.Arm) -> mujoco.MjModel:
    """The arm on a floor, the table, the pole, the moving ball and the target marker."""
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(arm))
    colour = [0.9, 0.4, 0.1, 0.6]
    spec.worldbody.add_geom(name="table", type=mujoco.mjtGeom.mjGEOM_BOX, rgba=[0.6, 0.5, 0.4, 1], **TABLE)
    start, end, radius = POLE
    spec.worldbody.add_geom(
        name="pole", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[radius, 0, 0], fromto=start + end, rgba=colour
    )
    ball = spec.worldbody.add_body(name="ball", mocap=True, pos=BALL["centre"])
    ball.add_geom(name="ball", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[BALL["radius"], 0, 0], rgba=colour)
    target = spec.worldbody.add_body(name="target", mocap=True)
    target.add_site(name="target", size=[0.015, 0, 0], rgba=[0.1, 0.8, 0.1, 0.8])
    return spec.compile()


def ball_at(t: float) -> np.ndarray:
    centre = BALL["centre"].copy()
    centre[1] += BALL["amplitude"] * np.sin(2.0 * np.pi * t / BALL["period"])
    return centre


def hand_down(x: float, y: float, z: float, yaw: float) -> np.ndarray:
    """The flange at (x, y, z) pointing down, turned by yaw about the vertical."""
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:3, :3] = [[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]]
    T[:3, 3] = [x, y, z]
    return T


def waypoints(optimizer: om.RedundancyOptimizer, n: int, rng: np.random.Generator) -> list[np.ndarray]:
    """Pick-and-place cycles, each pose reachable (the optimiser has a feasible choice, the
    ball at its centre)."""
    poses: list[np.ndarray] = []
    while len(poses) < n:
        picks = []
        for side in (1.0, -1.0):  # pick on the left, place on the right
            while True:
                x, y, yaw = rng.uniform(0.38, 0.62), side * rng.uniform(0.2, 0.42), rng.uniform(-1.2, 1.2)
                cycle = [hand_down(x, y, z, yaw) for z in (ABOVE, GRASP, ABOVE)]
                if all(optimizer.choose(T).ok for T in cycle):
                    picks += cycle
                    break
        poses += picks
    return poses[:n]


@dataclass
class Result:
    arm: str
    mode: str
    controller: str
    reached: int = 0
    waypoints: int = 0
    raised: int = 0
    afresh: int = 0
    flips: int = 0
    min_clearance: float = np.inf
    min_margin: float = np.inf
    ticks: list[float] = field(default_factory=list, repr=False)

    def row(self) -> dict:
        ticks = np.array(self.ticks) * 1e3
        out = {k: v for k, v in asdict(self).items() if k != "ticks"}
        out.update(tick_median_ms=float(np.median(ticks)), tick_p99_ms=float(np.percentile(ticks, 99)))
        out.update(tick_max_ms=float(ticks.max()), n_ticks=len(ticks))
        return out


def mujoco_clearance(model: mujoco.MjModel, data: mujoco.MjData, pairs: list[tuple[int, int]]) -> float:
    """The smallest signed distance of the pairs, by MuJoCo (data's kinematics current)."""
    fromto = np.empty(6)
    return min(mujoco.mj_geomDistance(model, data, a, o, 1.0, fromto) for a, o in pairs)


def run(
    solver: om.OMSolver, mode: str, controller: str, poses: list[np.ndarray], q_start: np.ndarray, log=None
) -> Result:
    """One controller along the waypoints (module docstring)."""
    arm = solver.arm
    model = scene(arm)
    configuration = mink.Configuration(model)
    data = configuration.data
    configuration.update(np.concatenate([q_start, configuration.q[arm.dof :]]))
    clearance = om.Clearance(model, arm, ["table", "pole", "ball"])
    pairs = [(a, o) for arms, obstacles in clearance.geom_pairs for a in arms for o in obstacles]
    frame = mink.FrameTask(arm.frame_name, arm.frame_type or "site", position_cost=1.0, orientation_cost=1.0)
    if controller == "om":
        optimizer = om.RedundancyOptimizer(solver, clearance, min_clearance=MIN_CLEARANCE, max_step=MAX_STEP)
        second = om.ExactPoseTask(solver, model, optimizer=optimizer)
    else:
        second = mink.PostureTask(model, cost=1e-2)
        second.set_target(configuration.q)
    limits = [
        mink.ConfigurationLimit(model),
        mink.VelocityLimit(model, {name: VELOCITY for name in arm.joint_names}),
        mink.CollisionAvoidanceLimit(
            model,
            clearance.geom_pairs,
            minimum_distance_from_collisions=MIN_CLEARANCE - MINK_MARGIN,
            collision_detection_distance=0.1,
            gain=GAIN,
        ),
    ]
    ball, target = model.body("ball").mocapid[0], model.body("target").mocapid[0]
    result = Result(arm.name, mode, controller, waypoints=len(poses))
    half = (arm.upper - arm.lower) / 2.0
    signs = solver.configuration_of(configuration.q[: arm.dof]).signs
    t = 0.0
    T_from = arm.fk(configuration.q[: arm.dof])
    for T_goal in poses:
        moving = (
            max(np.linalg.norm(T_goal[:3, 3] - T_from[:3, 3]) / SPEED, 0.2) if mode == "interpolated" else 0.0
        )
        for k in range(round((HOLD + moving) / DT)):
            s = min(1.0, k * DT / moving) if moving else 1.0
            T = _between(T_from, T_goal, s)
            data.mocap_pos[ball] = ball_at(t)
            data.mocap_pos[target] = T[:3, 3]
            mujoco.mj_kinematics(model, data)  # (the ball where it is now, before the tick)
            tick = time.perf_counter()
            frame.set_target(mink.SE3.from_matrix(T))
            tasks = [frame, second]
            if controller == "om":
                try:
                    second.set_target(T)
                    result.afresh += bool(second.choice.intervals)  # (a tracked choice searches none)
                except om.UnreachableTarget:
                    result.raised += 1
            velocity = mink.solve_ik(configuration, tasks, DT, "daqp", damping=1e-6, limits=limits)
            configuration.integrate_inplace(velocity, DT)
            result.ticks.append(time.perf_counter() - tick)
            t += DT
            q = configuration.q[: arm.dof]
            result.min_clearance = min(result.min_clearance, mujoco_clearance(model, data, pairs))
            limited = np.isfinite(half)
            margin = np.minimum(q - arm.lower, arm.upper - q)[limited] / half[limited]
            result.min_margin = min(result.min_margin, float(margin.min(initial=np.inf)))
            now = solver.configuration_of(q).signs
            result.flips += now != signs
            signs = now
            if log is not None:
                log.append((q.copy(), T.copy(), ball_at(t)))
            if s == 1.0 and _reached(arm.fk(q), T_goal):
                result.reached += 1
                break
        T_from = T_goal
    return result


def _between(A: np.ndarray, B: np.ndarray, s: float) -> np.ndarray:
    """The pose a fraction s of the way from A to B (straight line, rotation slerped)."""
    if s >= 1.0:
        return B
    T = np.eye(4)
    T[:3, 3] = (1.0 - s) * A[:3, 3] + s * B[:3, 3]
    qa, qb, q = np.empty(4), np.empty(4), np.empty(4)
    mujoco.mju_mat2Quat(qa, np.ascontiguousarray(A[:3, :3]).ravel())
    mujoco.mju_mat2Quat(qb, np.ascontiguousarray(B[:3, :3]).ravel())
    if qa @ qb < 0.0:
        qb = -qb
    q = (1.0 - s) * qa + s * qb  # (nlerp: the turns here are small)
    R = np.empty(9)
    mujoco.mju_quat2Mat(R, q / np.linalg.norm(q))
    T[:3, :3] = R.reshape(3, 3)
    return T


def _reached(F: np.ndarray, T: np.ndarray) -> bool:
    angle = np.arccos(np.clip((np.trace(F[:3, :3].T @ T[:3, :3]) - 1.0) / 2.0, -1.0, 1.0))
    return np.linalg.norm(F[:3, 3] - T[:3, 3]) < REACHED[0] and angle < REACHED[1]


def start_joints(solver: om.OMSolver, optimizer: om.RedundancyOptimizer) -> np.ndarray:
    """The optimiser's choice for the hand down above the middle of the table."""
    choice = optimizer.choose(hand_down(0.5, 0.0, ABOVE, 0.0))
    assert choice.ok, choice.reason
    return choice.solution.q


def benchmark(arms, modes, n: int, seed: int) -> list[Result]:
    results = []
    for name in arms:
        solver = om.OMSolver(name)
        model = scene(solver.arm)
        clearance = om.Clearance(model, solver.arm, ["table", "pole", "ball"])
        optimizer = om.RedundancyOptimizer(solver, clearance, min_clearance=MIN_CLEARANCE)
        poses = waypoints(optimizer, n, np.random.default_rng(seed))
        q_start = start_joints(solver, optimizer)
        for mode in modes:
            for controller in ("mink", "om"):
                result = run(solver, mode, controller, poses, q_start)
                print(_line(result.row()), flush=True)
                results.append(result)
    return results


def _line(r: dict) -> str:
    return (
        f"{r['arm']:<7} {r['mode']:<12} {r['controller']:<4} reached {r['reached']:>2}/{r['waypoints']}  "
        f"raised {r['raised']:>5}  afresh {r['afresh']:>4}  flips {r['flips']:>3}  "
        f"min clearance {r['min_clearance'] * 1e3:6.1f} mm  min margin {r['min_margin']:.3f}  "
        f"tick {r['tick_median_ms']:.3f} / {r['tick_p99_ms']:.3f} ms (max {r['tick_max_ms']:.1f})"
    )


def table(rows: list[dict]) -> str:
    lines = [
        "| arm | targets | controller | reached | ticks raised | choices afresh | branch flips "
        "| min clearance (mm) | min joint margin | tick median / p99 (ms) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['arm']} | {r['mode']} | {'OM + mink' if r['controller'] == 'om' else 'plain mink'} "
            f"| {r['reached']}/{r['waypoints']} | {r['raised']} | {r['afresh']} | {r['flips']} "
            f"| {r['min_clearance'] * 1e3:.1f} | {r['min_margin']:.3f} "
            f"| {r['tick_median_ms']:.3f} / {r['tick_p99_ms']:.3f} |"
        )
    return "\n".join(lines)


def video(name: str, poses: list[np.ndarray], q_start: np.ndarray, file: Path, fps: int = 30) -> Path:
    """An mp4 of the OM run with step targets (rendered after the run; MUJOCO_GL=egl headless)."""
    import imageio

    solver = om.OMSolver(name)
    log: list = []
    run(solver, "step", "om", poses, q_start, log)
    model = scene(solver.arm)
    data = mujoco.MjData(model)
    camera = mujoco.MjvCamera()
    camera.lookat[:], camera.distance, camera.azimuth, camera.elevation = CAMERA.values()
    ball, target = model.body("ball").mocapid[0], model.body("target").mocapid[0]
    every = max(1, round(RATE / fps))
    file.parent.mkdir(parents=True, exist_ok=True)
    with mujoco.Renderer(model, 480, 640) as renderer, imageio.get_writer(file, fps=fps) as writer:
        for q, T, centre in log[::every]:
            data.qpos[: len(q)] = q
            data.mocap_pos[ball], data.mocap_pos[target] = centre, T[:3, 3]
            mujoco.mj_forward(model, data)
            renderer.update_scene(data, camera)
            writer.append_data(renderer.render())
    return file


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", nargs="+", default=list(ARMS))
    parser.add_argument(
        "--modes", nargs="+", default=["step", "interpolated"], choices=["step", "interpolated"]
    )
    parser.add_argument("--waypoints", type=int, default=WAYPOINTS)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, help="write the results table (markdown) and JSON beside it")
    parser.add_argument("--video", type=Path, help="write an mp4 of the first arm's OM run (step targets)")
    args = parser.parse_args()
    results = benchmark(args.arms, args.modes, args.waypoints, args.seed)
    rows = [r.row() for r in results]
    print(table(rows))
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.with_suffix(".json").write_text(json.dumps(rows, indent=1))
        write_block(args.out, table(rows) + "\n")
    if args.video:
        solver = om.OMSolver(args.arms[0])
        model = scene(solver.arm)
        optimizer = om.RedundancyOptimizer(
            solver, om.Clearance(model, solver.arm, ["table", "pole", "ball"]), min_clearance=MIN_CLEARANCE
        )
        poses = waypoints(optimizer, args.waypoints, np.random.default_rng(args.seed))
        print("wrote", video(args.arms[0], poses, start_joints(solver, optimizer), args.video))


if __name__ == "__main__":
    main()
