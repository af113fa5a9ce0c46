"""Panda at 500 Hz: the optimiser picks the arm angle every tick of a mink loop, around a pole and a ball.

A mocap target moves along a figure eight (with --mouse, where you drag it in the viewer:
double-click it, then Ctrl + right-drag). Every tick it goes to a FrameTask and to
om.ExactPoseTask, whose RedundancyOptimizer keeps the joints far from their limits, the arm
3 cm clear of the obstacles and the wrist away from singularities; a RateLimiter holds the
loop at 500 Hz. It prints the rate and the ticks' times, then a JSON summary; headless
(--headless or no display; MUJOCO_GL=egl) it writes an mp4 and a plot to --out.

Run: python examples/realtime_panda.py [--headless] [--mouse] [--seconds 8] [--out examples_out]
"""

import argparse
import json
import os
import time
from pathlib import Path

import mink
import mujoco
import mujoco.viewer
import numpy as np
from _report import Recording, plot, print_runs, render_video, timing
from _scene import scene
from loop_rate_limiters import RateLimiter

import om_redundant as om

RATE = 500.0  # Hz, the control loop
MARGIN = 0.03  # m of clearance the optimiser keeps
# rad per tick that psi moves at most: 2.5 rad/s, which the joints follow within the velocity
# limit (the default 0.05 suits 100 Hz; at 500 Hz the hand would lag 3 cm behind its target)
MAX_STEP = 0.005
PERIOD = 8.0  # s, one figure eight
HOME = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785])  # hand down in front, elbow up
CAPSULE, SPHERE = mujoco.mjtGeom.mjGEOM_CAPSULE, mujoco.mjtGeom.mjGEOM_SPHERE
OBSTACLES = {
    "pole": dict(type=CAPSULE, size=[0.03, 0, 0], fromto=[0.08, -0.6, 0.72, 0.08, 0.6, 0.72]),
    "ball": dict(type=SPHERE, size=[0.06, 0, 0], pos=[0.3, 0.35, 0.5]),
}
CAMERA = dict(lookat=[0.3, 0.0, 0.45], distance=1.9, azimuth=150.0, elevation=-15.0)


def figure_eight(t: float) -> np.ndarray:
    """The scripted target's position: 0.45 m high, a figure eight in x and y."""
    phase = 2.0 * np.pi * t / PERIOD
    return np.array([0.5 + 0.1 * np.sin(2.0 * phase), 0.3 * np.sin(phase), 0.45])


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--headless", action="store_true", help="write a video and a plot, no viewer")
    parser.add_argument("--mouse", action="store_true", help="drag the target (needs a display)")
    parser.add_argument("--seconds", type=float, default=PERIOD, help="simulated time when headless")
    parser.add_argument("--out", default="examples_out", help="directory for the video and the plot")
    args = parser.parse_args()
    show = not args.headless and bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    if args.mouse and not show:
        parser.error("--mouse needs the viewer: a display, without --headless")

    solver = om.OMSolver("panda")
    model = scene(solver.arm, OBSTACLES)
    configuration = mink.Configuration(model)
    data = configuration.data
    clearance = om.Clearance(model, solver.arm, list(OBSTACLES))

    optimizer = om.RedundancyOptimizer(solver, clearance, min_clearance=MARGIN, max_step=MAX_STEP)
    tasks = [
        hand := mink.FrameTask(solver.arm.frame_name, "site", position_cost=1.0, orientation_cost=1.0),
        exact := om.ExactPoseTask(solver, model, optimizer=optimizer),
    ]
    limits = [
        mink.ConfigurationLimit(model),
        mink.VelocityLimit(model, {name: np.pi for name in solver.arm.joint_names}),
    ]

    # Start on the figure eight's first pose (the hand pointing down, as at home), in the
    # optimiser's global choice of branch and arm angle, the mocap target on the hand.
    T_start = solver.arm.fk(HOME)
    T_start[:3, 3] = figure_eight(0.0)
    exact.set_target(T_start)
    exact.seed(configuration)
    mink.move_mocap_to_frame(model, data, "target", solver.arm.frame_name, "site")

    viewer = None
    if show:
        viewer = mujoco.viewer.launch_passive(model, data, show_left_ui=False, show_right_ui=False)
    rate = RateLimiter(frequency=RATE, warn=False)
    run = Recording("OM + mink", solver.arm, clearance)
    unreachable = 0
    k, start = 0, time.perf_counter()
    while viewer.is_running() if viewer else k * rate.dt < args.seconds:
        if not args.mouse:  # the script moves the mocap target; with --mouse, you do
            data.mocap_pos[0] = figure_eight(k * rate.dt)
        tick = time.perf_counter()
        target = mink.SE3.from_mocap_name(model, data, "target")
        hand.set_target(target)
        try:
            exact.set_target(target)  # the optimiser tracks psi from the previous tick
        except om.UnreachableTarget:
            unreachable += 1  # (a dragged target out of reach) keeps the previous one
        velocity = mink.solve_ik(configuration, tasks, rate.dt, "daqp", damping=1e-6, limits=limits)
        configuration.integrate_inplace(velocity, rate.dt)
        psi = exact.choice.configuration.redundancy[0] if exact.choice else np.nan
        run.add(k * rate.dt, configuration.q, target, tick=time.perf_counter() - tick, psi=psi)
        if viewer:
            viewer.sync()
        rate.sleep()
        k += 1
    elapsed = time.perf_counter() - start
    if viewer:
        viewer.close()

    summary = {"example": "realtime_panda", **timing(run, elapsed, RATE), "margin": MARGIN, **run.summary()}
    summary["unreachable"] = unreachable
    print_runs([run], MARGIN)
    if not show:
        out = Path(args.out)
        print("wrote", render_video(model, run, CAMERA, out / "realtime_panda.mp4", RATE, fps=30))
        keys = ["tick", "clearance", "error", "psi"]
        budget, margin = (1.0 / RATE, f"{RATE:.0f} Hz budget"), (MARGIN, "margin")
        title = "Panda at 500 Hz: OM's optimiser choosing psi every tick"
        print("wrote", plot([run], keys, title, out / "realtime_panda.png", tick=budget, clearance=margin))
    print(json.dumps(summary))
