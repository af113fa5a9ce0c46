"""Panda at 500 Hz: the optimiser picks the arm angle every tick of a mink loop, around a pole and a ball.

A mocap target moves along a scripted figure eight in front of the arm (or, with --mouse,
wherever you drag it in the viewer: double-click it, then Ctrl + right-drag). Every tick,
as in mink's own examples, the target goes to a FrameTask and to om.ExactPoseTask, whose
RedundancyOptimizer tracks the branch and arm angle that keep the joints far from their
limits, the arm 3 cm clear of the pole and the ball, and the wrist away from singularities;
mink.solve_ik then gives the velocity, limited by ConfigurationLimit and VelocityLimit, and
a RateLimiter holds the loop at 500 Hz when the tick takes less than 2 ms.

It prints the achieved rate and the ticks' median, p99 and worst time; the last line is a
JSON summary. Headless (--headless, or no display) it writes an mp4 (MuJoCo's renderer; set
MUJOCO_GL=egl) and a plot of tick time, clearance, hand error and arm angle to --out.

Run: python examples/realtime_panda.py [--headless] [--mouse] [--seconds 8] [--out examples_out]
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import mink
import mujoco
import numpy as np
from _common import scene
from loop_rate_limiters import RateLimiter

import om_redundant as om

RATE = 500.0  # Hz, the control loop
MARGIN = 0.03  # m of clearance the optimiser keeps
PERIOD = 8.0  # s, one figure eight
FPS = 30  # frames per second of the video
HOME = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785])  # hand down in front, elbow up
OBSTACLES = {
    "pole": dict(
        type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.03, 0, 0], fromto=[0.08, -0.6, 0.72, 0.08, 0.6, 0.72]
    ),
    "ball": dict(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.06, 0, 0], pos=[0.3, 0.35, 0.5]),
}
CAMERA = dict(lookat=[0.3, 0.0, 0.45], distance=1.9, azimuth=150.0, elevation=-15.0)


def parse_args() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--headless", action="store_true", help="write a video and a plot, no viewer")
    parser.add_argument("--mouse", action="store_true", help="drag the target (needs a display)")
    parser.add_argument("--seconds", type=float, default=PERIOD, help="simulated time when headless")
    parser.add_argument("--out", default="examples_out", help="directory for the video and the plot")
    args = parser.parse_args()
    args.headless = args.headless or not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    if args.mouse and args.headless:
        parser.error("--mouse needs the viewer: a display, without --headless")
    return args


def figure_eight(t: float, T_home: np.ndarray) -> np.ndarray:
    """The scripted target: hand pointing down at 0.45 m height, a figure eight in x and y."""
    phase = 2.0 * np.pi * t / PERIOD
    T = T_home.copy()
    T[:3, 3] = [0.5 + 0.1 * np.sin(2.0 * phase), 0.3 * np.sin(phase), 0.45]
    return T


def place(data: mujoco.MjData, mocap: int, T: np.ndarray) -> None:
    """Put the mocap target at pose T."""
    data.mocap_pos[mocap] = T[:3, 3]
    mujoco.mju_mat2Quat(data.mocap_quat[mocap], T[:3, :3].ravel())


def main() -> dict:
    args = parse_args()
    solver = om.OMSolver("panda")
    arm = solver.arm
    model = scene(arm, OBSTACLES)
    configuration = mink.Configuration(model)
    data = configuration.data
    clearance = om.Clearance(model, arm, list(OBSTACLES))
    optimizer = om.RedundancyOptimizer(solver, clearance, min_clearance=MARGIN)
    hand = mink.FrameTask(arm.frame_name, "site", position_cost=1.0, orientation_cost=1.0)
    exact = om.ExactPoseTask(solver, model, optimizer=optimizer)
    tasks = [hand, exact]
    limits = [
        mink.ConfigurationLimit(model),
        mink.VelocityLimit(model, {name: np.pi for name in arm.joint_names}),
    ]

    T_home = arm.fk(HOME)
    T = figure_eight(0.0, T_home)
    exact.set_target(T)  # the global choice of branch and arm angle for the first pose
    exact.seed(configuration)  # start there, the hand on the target
    mocap = model.body("target").mocapid[0]
    place(data, mocap, T)

    rate = RateLimiter(frequency=RATE, warn=False)
    log: dict[str, list] = {key: [] for key in ("t", "tick", "q", "target", "clearance", "error", "psi")}
    unreachable = 0
    viewer = None
    if not args.headless:
        import mujoco.viewer

        viewer = mujoco.viewer.launch_passive(model, data, show_left_ui=False, show_right_ui=False)
    start = time.perf_counter()
    k = 0
    while viewer.is_running() if viewer else k * rate.dt < args.seconds:
        t = k * rate.dt
        if not args.mouse:  # the script moves the mocap target; with --mouse, you do
            T = figure_eight(t, T_home)
            place(data, mocap, T)
        tick = time.perf_counter()
        target = mink.SE3.from_mocap_id(data, mocap)
        hand.set_target(target)
        try:
            exact.set_target(target)  # the optimiser tracks psi from the previous tick
        except om.UnreachableTarget:
            unreachable += 1  # (a dragged target out of reach) keeps the previous one
        velocity = mink.solve_ik(configuration, tasks, rate.dt, "daqp", damping=1e-6, limits=limits)
        configuration.integrate_inplace(velocity, rate.dt)
        log["tick"].append(time.perf_counter() - tick)
        q = configuration.q[: arm.dof].copy()
        log["t"].append(t)
        log["q"].append(q)
        log["target"].append(target.as_matrix())
        log["clearance"].append(clearance.minimum(q))
        log["error"].append(float(np.linalg.norm(arm.fk(q)[:3, 3] - target.translation())))
        log["psi"].append(exact.choice.configuration.redundancy[0] if exact.choice else np.nan)
        if viewer:
            mujoco.mj_camlight(model, data)
            viewer.sync()
        rate.sleep()
        k += 1
    elapsed = time.perf_counter() - start
    if viewer:
        viewer.close()

    summary = report(log, elapsed, unreachable)
    if args.headless:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        print("wrote", render(model, log, out / "realtime_panda.mp4"))
        print("wrote", plot(log, out / "realtime_panda.png"))
    print(json.dumps(summary))
    return summary


def report(log: dict[str, list], elapsed: float, unreachable: int) -> dict:
    """Print the rate and tick times; the summary."""
    ticks = np.array(log["tick"]) * 1000.0
    worst = int(np.argmax(ticks))
    summary = {
        "example": "realtime_panda",
        "ticks": len(ticks),
        "rate_hz": round(len(ticks) / elapsed, 1),
        "target_hz": RATE,
        "tick_ms": {
            "median": round(float(np.median(ticks)), 3),
            "p99": round(float(np.percentile(ticks, 99)), 3),
            "worst": round(float(ticks[worst]), 3),
            "worst_at_s": round(log["t"][worst], 3),
        },
        "margin": MARGIN,
        "min_clearance": round(min(log["clearance"]), 5),
        "max_error": float(f"{max(log['error']):.3e}"),
        "final_error": float(f"{log['error'][-1]:.3e}"),
        "unreachable": unreachable,
    }
    tick_ms = summary["tick_ms"]
    print(
        f"{summary['ticks']} ticks at {summary['rate_hz']:.0f} Hz (target {RATE:.0f} Hz): tick median "
        f"{tick_ms['median']:.2f} ms, p99 {tick_ms['p99']:.2f} ms, worst {tick_ms['worst']:.2f} ms "
        f"at t = {tick_ms['worst_at_s']:.2f} s"
    )
    print(
        f"min clearance {summary['min_clearance'] * 1000:.1f} mm (margin {MARGIN * 1000:.0f} mm), "
        f"max hand error {summary['max_error']:.1e} m"
    )
    return summary


def render(model: mujoco.MjModel, log: dict[str, list], file: Path) -> Path:
    """The run as an mp4 at FPS frames per second of simulated time (after the loop, so that
    rendering takes no time from the ticks)."""
    import imageio

    data = mujoco.MjData(model)
    camera = mujoco.MjvCamera()
    camera.lookat[:], camera.distance, camera.azimuth, camera.elevation = CAMERA.values()
    every = max(1, round(RATE / FPS))
    with mujoco.Renderer(model, 480, 640) as renderer, imageio.get_writer(file, fps=FPS) as video:
        for q, target in zip(log["q"][::every], log["target"][::every], strict=True):
            data.qpos[: len(q)] = q
            data.mocap_pos[0] = target[:3, 3]
            mujoco.mj_forward(model, data)
            renderer.update_scene(data, camera)
            video.append_data(renderer.render())
    return file


def plot(log: dict[str, list], file: Path) -> Path:
    """Tick time, clearance, hand error and arm angle over time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.array(log["t"])
    fig, axes = plt.subplots(1, 4, figsize=(15, 3.2), constrained_layout=True)
    axes[0].plot(t, np.array(log["tick"]) * 1000.0, lw=0.6)
    axes[0].axhline(1000.0 / RATE, color="k", ls="--", lw=0.8, label=f"{RATE:.0f} Hz budget")
    axes[1].plot(t, np.array(log["clearance"]) * 1000.0)
    axes[1].axhline(MARGIN * 1000.0, color="k", ls="--", lw=0.8, label="margin")
    axes[2].semilogy(t, np.maximum(log["error"], 1e-12))
    axes[3].plot(t, log["psi"])
    labels = ["tick (ms)", "clearance to pole and ball (mm)", "hand error (m)", "arm angle psi (rad)"]
    for ax, label in zip(axes, labels, strict=True):
        ax.set_xlabel("t (s)")
        ax.set_ylabel(label)
    axes[0].legend()
    axes[1].legend()
    fig.suptitle("Panda at 500 Hz: OM's optimiser choosing psi every tick")
    fig.savefig(file, dpi=80)
    plt.close(fig)
    return file


if __name__ == "__main__":
    main()
