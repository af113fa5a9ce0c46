"""Shared parts of the obstacle-avoidance examples: the scene, the mink loop (OM or plain
mink), the summary, the rendering and the plot. Each example only describes its arm,
obstacles and hand path."""

from __future__ import annotations

import argparse
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import mink
import mujoco
import numpy as np

import om_redundant as om

DT = 0.01  # control period (s)


def parse_args(doc: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--headless", action="store_true", help="render to --out instead of the viewer")
    parser.add_argument("--seconds", type=float, default=6.0, help="simulated time of each run")
    parser.add_argument("--out", default="examples_out", help="directory for the strip and the plot")
    return parser.parse_args()


def scene(arm: om.Arm, obstacles: dict[str, dict]) -> mujoco.MjModel:
    """The project's arm MJCF on a floor, plus obstacle geoms (name -> MjSpec geom fields)."""
    spec = mujoco.MjSpec.from_string(om.scene_mjcf(arm))
    for name, geom in obstacles.items():
        spec.worldbody.add_geom(name=name, rgba=[0.9, 0.4, 0.1, 0.7], **geom)
    target = spec.worldbody.add_body(name="target", mocap=True)
    target.add_site(name="target", size=[0.02, 0, 0], rgba=[0.1, 0.8, 0.1, 0.8])
    return spec.compile()


def min_joint_margin(arm: om.Arm, q: np.ndarray) -> float:
    """Smallest joint-limit margin, 1 at mid-range and 0 on a limit."""
    return float((np.minimum(q - arm.lower, arm.upper - q) / ((arm.upper - arm.lower) / 2)).min())


@dataclass
class Run:
    name: str
    t: list[float] = field(default_factory=list)
    q: list[np.ndarray] = field(default_factory=list)
    clearance: list[float] = field(default_factory=list)
    joint_margin: list[float] = field(default_factory=list)
    error: list[float] = field(default_factory=list)
    failure: str = ""

    def summary(self) -> dict:
        return {
            "min_clearance": round(min(self.clearance), 5),
            "min_joint_margin": round(min(self.joint_margin), 4),
            "max_error": float(f"{max(self.error):.3e}"),
            "final_error": float(f"{self.error[-1]:.3e}"),
            **({"failure": self.failure} if self.failure else {}),
        }


def follow(solver, model, obstacles, path, seconds, *, exact, q_start, margin) -> Run:
    """Drive the hand along path(s) for s in [0, 1] over `seconds` (the last quarter holds the
    end pose), with mink: the FrameTask plus either OM's ExactPoseTask, whose optimiser keeps
    `margin` of clearance (exact=True), or a PostureTask to q_start (plain mink). Both use the
    same limits: joints, velocities and CollisionAvoidanceLimit."""
    arm, site = solver.arm, solver.arm.frame_name
    clearance = om.Clearance(model, arm, list(obstacles))
    configuration = mink.Configuration(model)
    configuration.update(np.concatenate([q_start, configuration.q[arm.dof :]]))
    frame = mink.FrameTask(site, "site", position_cost=1.0, orientation_cost=1.0)
    if exact:
        optimizer = om.RedundancyOptimizer(solver, clearance, min_clearance=margin, max_step=0.05)
        second = om.ExactPoseTask(solver, model, optimizer=optimizer)
        second.set_target(path(0.0))  # global choice of branch and psi for the first pose
        second.seed(configuration)  # start there: the hand is on the same pose as plain mink's
    else:
        second = mink.PostureTask(model, cost=1e-2)
        second.set_target(configuration.q)
    arm_geoms = sorted({a for a, _ in clearance.pairs})
    limits = [
        mink.ConfigurationLimit(model),
        mink.VelocityLimit(model, {name: np.pi for name in arm.joint_names}),
        mink.CollisionAvoidanceLimit(model, [(arm_geoms, list(obstacles))], collision_detection_distance=0.1),
    ]
    run = Run("OM + mink" if exact else "plain mink")
    for k in range(round(seconds / DT) + 1):
        T = path(min(1.0, k * DT / (0.75 * seconds)))
        frame.set_target(mink.SE3.from_matrix(T))
        if exact and not run.failure:
            try:
                second.set_target(T)
            except om.UnreachableTarget as error:  # keeps the previous target; reported
                run.failure = str(error)
        if k > 0:
            velocity = mink.solve_ik(configuration, [frame, second], DT, "daqp", damping=1e-6, limits=limits)
            configuration.integrate_inplace(velocity, DT)
        q = configuration.q[: arm.dof].copy()
        run.t.append(k * DT)
        run.q.append(q)
        run.clearance.append(clearance.minimum(q))
        run.joint_margin.append(min_joint_margin(arm, q))
        run.error.append(float(np.linalg.norm(arm.fk(q)[:3, 3] - T[:3, 3])))
    return run


def report(example: str, margin: float, om_run: Run, mink_run: Run) -> dict:
    """Print both runs' numbers; the summary (printed last by finish as one JSON line)."""
    for run in (om_run, mink_run):
        s = run.summary()
        print(
            f"{run.name:>11}: min clearance {s['min_clearance'] * 1000:7.1f} mm "
            f"(margin {margin * 1000:.0f} mm), "
            f"min joint margin {s['min_joint_margin']:.2f}, final hand error {s['final_error']:.1e} m"
        )
    return {"example": example, "margin": margin, "om": om_run.summary(), "mink": mink_run.summary()}


def render_strip(model, name, runs, path_of_run, out: Path, camera: dict, frames: int = 4) -> Path:
    """A PNG: one row per run, `frames` snapshots along it (the target as a green dot)."""
    from PIL import Image

    data = mujoco.MjData(model)
    cam = mujoco.MjvCamera()
    cam.lookat[:], cam.distance, cam.azimuth, cam.elevation = (
        camera["lookat"],
        camera["distance"],
        camera["azimuth"],
        camera["elevation"],
    )
    rows = []
    with mujoco.Renderer(model, 240, 320) as renderer:
        for run in runs:
            images = []
            for k in np.linspace(0, len(run.q) - 1, frames).astype(int):
                data.qpos[: len(run.q[k])] = run.q[k]
                data.mocap_pos[0] = path_of_run(run.t[k])[:3, 3]
                mujoco.mj_forward(model, data)
                renderer.update_scene(data, cam)
                images.append(renderer.render())
            rows.append(np.hstack(images))
    out.mkdir(parents=True, exist_ok=True)
    file = out / f"{name}_strip.png"
    Image.fromarray(np.vstack(rows)).quantize(128).save(file, optimize=True)
    return file


def plot(runs, margin: float, title: str, file: Path) -> Path:
    """Clearance, joint margin and hand error over time, OM vs plain mink."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2), constrained_layout=True)
    for run in runs:
        axes[0].plot(run.t, np.array(run.clearance) * 1000, label=run.name)
        axes[1].plot(run.t, run.joint_margin, label=run.name)
        axes[2].semilogy(run.t, np.maximum(run.error, 1e-12), label=run.name)
    axes[0].axhline(margin * 1000, color="k", ls="--", lw=0.8, label="margin")
    labels = ["clearance to obstacle (mm)", "min joint-limit margin", "hand error (m)"]
    for ax, label in zip(axes, labels, strict=True):
        ax.set_xlabel("t (s)")
        ax.set_ylabel(label)
    axes[0].legend()
    fig.suptitle(title)
    fig.savefig(file, dpi=80)
    plt.close(fig)
    return file


def show(model, runs, path_of_run) -> None:
    """Replay the runs, one after another, in MuJoCo's viewer (needs a display)."""
    import mujoco.viewer

    data = mujoco.MjData(model)
    with mujoco.viewer.launch_passive(model, data) as viewer:
        while viewer.is_running():
            for run in runs:
                print("showing", run.name)
                for t, q in zip(run.t, run.q, strict=True):
                    data.qpos[: len(q)] = q
                    data.mocap_pos[0] = path_of_run(t)[:3, 3]
                    mujoco.mj_forward(model, data)
                    viewer.sync()
                    time.sleep(DT)


def finish(args, name, model, solver, obstacles, path, q_start, margin, camera, title) -> dict:
    """Run OM and plain mink on the same path, report, then render and plot or show."""
    runs = [
        follow(solver, model, obstacles, path, args.seconds, exact=exact, q_start=q_start, margin=margin)
        for exact in (True, False)
    ]
    summary = report(name, margin, *runs)
    path_of_run = lambda t: path(min(1.0, t / (0.75 * args.seconds)))  # noqa: E731
    if args.headless or not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        out = Path(args.out)
        print("wrote", render_strip(model, name, runs, path_of_run, out, camera))
        print("wrote", plot(runs, margin, title, out / f"{name}_clearance.png"))
    else:
        show(model, runs, path_of_run)
    print(json.dumps(summary))
    return summary
