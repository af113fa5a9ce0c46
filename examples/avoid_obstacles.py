"""OM against plain mink: the hand passes an obstacle where the default elbow goes.

--scene panda_pole: the Panda's hand sweeps sideways under a pole; iiwa14_shelf: the iiwa14's
reaches in under a shelf. The same mink loop runs twice, with a FrameTask, the limits and either
om.ExactPoseTask (its RedundancyOptimizer keeps 3 cm of clearance) or mink's PostureTask. The
viewer shows both runs; headless (--headless or no display; MUJOCO_GL=egl) a strip and a plot
go to --out. The last line printed is a JSON summary.

Run: python examples/avoid_obstacles.py [--scene panda_pole] [--headless] [--seconds 6] [--out examples_out]
"""

import argparse
import json
import os
from pathlib import Path

import mink
import mujoco
import mujoco.viewer
import numpy as np
from _report import Recording, plot, print_runs, render_strip
from _scene import scene
from loop_rate_limiters import RateLimiter

import om_redundant as om

DT = 0.01  # s, the control period
MARGIN = 0.03  # m of clearance the optimiser keeps
CAPSULE, BOX = mujoco.mjtGeom.mjGEOM_CAPSULE, mujoco.mjtGeom.mjGEOM_BOX
SCENES = {  # the arm, its home (hand down in front, elbow up), the obstacle, the hand's way
    "panda_pole": dict(
        arm="panda",
        home=[0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785],
        obstacles={"pole": dict(type=CAPSULE, size=[0.03, 0, 0], fromto=[0.08, -0.6, 0.72, 0.08, 0.6, 0.72])},
        way=[[0.5, -0.35, 0.45], [0.5, 0.35, 0.45]],
        camera=dict(lookat=[0.25, 0.0, 0.45], distance=1.9, azimuth=150.0, elevation=-15.0),
        title="Panda under a pole: OM vs plain mink",
    ),
    "iiwa14_shelf": dict(
        arm="iiwa14",
        home=[0.0, 0.6, 0.0, -1.3, 0.0, 1.2, 0.0],
        obstacles={"shelf": dict(type=BOX, size=[0.3, 0.5, 0.01], pos=[0.6, 0.0, 0.74])},
        way=[[0.45, 0.1, 0.4], [0.7, -0.1, 0.4]],
        camera=dict(lookat=[0.35, 0.0, 0.45], distance=2.0, azimuth=120.0, elevation=-10.0),
        title="iiwa14 under a shelf: OM vs plain mink",
    ),
}

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=SCENES, default="panda_pole")
    parser.add_argument("--headless", action="store_true", help="write a strip and a plot, no viewer")
    parser.add_argument("--seconds", type=float, default=6.0, help="simulated time of each run")
    parser.add_argument("--out", default="examples_out", help="directory for the strip and the plot")
    args = parser.parse_args()
    show = not args.headless and bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    setup = SCENES[args.scene]

    solver = om.OMSolver(setup["arm"])
    model = scene(solver.arm, setup["obstacles"])
    configuration = mink.Configuration(model)
    data = configuration.data
    clearance = om.Clearance(model, solver.arm, list(setup["obstacles"]))

    hand = mink.FrameTask(solver.arm.frame_name, "site", position_cost=1.0, orientation_cost=1.0)
    optimizer = om.RedundancyOptimizer(solver, clearance, min_clearance=MARGIN)
    exact = om.ExactPoseTask(solver, model, optimizer=optimizer)
    posture = mink.PostureTask(model, cost=1e-2)
    limits = [
        mink.ConfigurationLimit(model),
        mink.VelocityLimit(model, {name: np.pi for name in solver.arm.joint_names}),
        mink.CollisionAvoidanceLimit(model, clearance.geom_pairs, collision_detection_distance=0.1),
    ]

    # The hand's first pose, reached in the home configuration's branch and arm angle: where
    # plain mink starts and stays near (its posture target); OM starts where its optimiser chooses.
    home = np.array(setup["home"])
    start, end = np.array(setup["way"])
    T_start = solver.arm.fk(home)
    T_start[:3, 3] = start
    q_start = solver.solve(T_start, solver.configuration_of(home), q_hint=home).q
    posture.set_target(q_start)

    viewer = None
    if show:
        viewer = mujoco.viewer.launch_passive(model, data, show_left_ui=False, show_right_ui=False)
    rate = RateLimiter(frequency=1.0 / DT, warn=False)
    runs = []
    for name, tasks in {"OM + mink": [hand, exact], "plain mink": [hand, posture]}.items():
        configuration.update(q_start)
        mink.move_mocap_to_frame(model, data, "target", solver.arm.frame_name, "site")
        if exact in tasks:
            exact.set_target(T_start)  # the global choice of branch and arm angle
            exact.seed(configuration)  # start there, the hand on the same pose
        run = Recording(name, solver.arm, clearance)
        for k in range(round(args.seconds / DT) + 1):
            # The target moves along the way in 3/4 of the time, then holds the end pose.
            s = min(1.0, k * DT / (0.75 * args.seconds))
            data.mocap_pos[0] = start + s * (end - start)
            target = mink.SE3.from_mocap_name(model, data, "target")
            hand.set_target(target)
            if exact in tasks:
                exact.set_target(target)  # the optimiser tracks psi from the previous tick
            if k > 0:
                velocity = mink.solve_ik(configuration, tasks, DT, "daqp", damping=1e-6, limits=limits)
                configuration.integrate_inplace(velocity, DT)
            run.add(k * DT, configuration.q, target)
            if viewer:
                viewer.sync()
                rate.sleep()
        runs.append(run)
    if viewer:
        viewer.close()

    print_runs(runs, MARGIN)
    if not show:
        out = Path(args.out)
        print("wrote", render_strip(model, runs, setup["camera"], out / f"{args.scene}_strip.png"))
        keys, file = ["clearance", "joint_margin", "error"], out / f"{args.scene}_clearance.png"
        print("wrote", plot(runs, keys, setup["title"], file, clearance=(MARGIN, "margin")))
    summary = {"example": args.scene, "margin": MARGIN, "om": runs[0].summary(), "mink": runs[1].summary()}
    print(json.dumps(summary))
