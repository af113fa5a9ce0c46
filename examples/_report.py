"""What the examples report of their runs: the recording, the printed numbers, the plot and
the pictures (a strip of snapshots, a video). The mink loops are the examples' own."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import mink
import mujoco
import numpy as np

import om_redundant as om

LABELS = {
    "tick": "tick (ms)",
    "clearance": "clearance to the obstacles (mm)",
    "joint_margin": "min joint-limit margin",
    "error": "hand error (m)",
    "psi": "arm angle psi (rad)",
}
SCALE = {"clearance": 1000.0, "tick": 1000.0}  # plotted in mm and ms
LOG = {"error"}  # plotted on a log scale


class Recording:
    """A run, tick by tick: the time, the arm's joints, the target, the clearance, the
    joint-limit margin and the hand error they give, and what else the example adds."""

    def __init__(self, name: str, arm: om.Arm, clearance: om.Clearance):
        self.name, self.arm, self.clearance = name, arm, clearance
        self.series: dict[str, list] = defaultdict(list)

    def add(self, t: float, q: np.ndarray, target: mink.SE3, **more: float) -> None:
        """Record a tick: the arm's joints q with the target, and `more` (e.g. ``tick=seconds``)."""
        arm, T = self.arm, target.as_matrix()
        half_range = (arm.upper - arm.lower) / 2  # the margin is 1 at mid-range, 0 on a limit
        values = {
            "t": t,
            "q": q.copy(),
            "target": T,
            "clearance": self.clearance.minimum(q),
            "joint_margin": float(np.min(np.minimum(q - arm.lower, arm.upper - q) / half_range)),
            "error": float(np.linalg.norm(arm.fk(q)[:3, 3] - T[:3, 3])),
            **more,
        }
        for key, value in values.items():
            self.series[key].append(value)

    def __getitem__(self, key: str) -> np.ndarray:
        return np.array(self.series[key])

    def summary(self) -> dict:
        return {
            "min_clearance": round(min(self.series["clearance"]), 5),
            "min_joint_margin": round(min(self.series["joint_margin"]), 4),
            "max_error": float(f"{max(self.series['error']):.3e}"),
            "final_error": float(f"{self.series['error'][-1]:.3e}"),
        }


def print_runs(runs: list[Recording], margin: float) -> None:
    """A line per run: its clearance against the margin, joint margin and hand error."""
    for run in runs:
        s = run.summary()
        print(
            f"{run.name:>11}: min clearance {s['min_clearance'] * 1000:7.1f} mm "
            f"(margin {margin * 1000:.0f} mm), min joint margin {s['min_joint_margin']:.2f}, "
            f"hand error max {s['max_error']:.1e} m, final {s['final_error']:.1e} m"
        )


def timing(run: Recording, elapsed: float, rate: float) -> dict:
    """The rate achieved over `elapsed` seconds of the loop and the ticks' times (recorded as
    ``tick``, in seconds), printed and returned."""
    ticks = run["tick"] * 1000.0
    worst = int(np.argmax(ticks))
    summary = {
        "ticks": len(ticks),
        "rate_hz": round(len(ticks) / elapsed, 1),
        "target_hz": rate,
        "tick_ms": {
            "median": round(float(np.median(ticks)), 3),
            "p99": round(float(np.percentile(ticks, 99)), 3),
            "worst": round(float(ticks[worst]), 3),
            "worst_at_s": round(run.series["t"][worst], 3),
        },
    }
    tick_ms = summary["tick_ms"]
    print(
        f"{summary['ticks']} ticks at {summary['rate_hz']:.0f} Hz (target {rate:.0f} Hz): tick median "
        f"{tick_ms['median']:.2f} ms, p99 {tick_ms['p99']:.2f} ms, worst {tick_ms['worst']:.2f} ms "
        f"at t = {tick_ms['worst_at_s']:.2f} s"
    )
    return summary


def plot(runs: list[Recording], keys: list[str], title: str, file: Path, **lines: tuple[float, str]) -> Path:
    """A panel per recorded series over time, a curve per run; `lines` adds dashed references
    (key=(value, label)), in the series' units."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(keys), figsize=(3 * len(keys) + 3, 3.2), constrained_layout=True)
    for ax, key in zip(axes, keys, strict=True):
        scale = SCALE.get(key, 1.0)
        for run in runs:
            values = np.maximum(run[key], 1e-12) if key in LOG else run[key] * scale
            (ax.semilogy if key in LOG else ax.plot)(
                run["t"], values, lw=0.6 if key == "tick" else None, label=run.name if len(runs) > 1 else None
            )
        if key in lines:
            value, name = lines[key]
            ax.axhline(value * scale, color="k", ls="--", lw=0.8, label=name)
            ax.legend()
        ax.set_xlabel("t (s)")
        ax.set_ylabel(LABELS[key])
    fig.suptitle(title)
    file.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(file, dpi=80)
    plt.close(fig)
    return file


def snapshots(model: mujoco.MjModel, run: Recording, camera: dict, ticks, size: tuple[int, int]):
    """Images (height, width = size) of the run at the given ticks, the target a green dot."""
    data = mujoco.MjData(model)
    cam = mujoco.MjvCamera()
    cam.lookat[:], cam.distance = camera["lookat"], camera["distance"]
    cam.azimuth, cam.elevation = camera["azimuth"], camera["elevation"]
    with mujoco.Renderer(model, *size) as renderer:
        for k in ticks:
            q = run.series["q"][k]
            data.qpos[: len(q)] = q
            data.mocap_pos[0] = run.series["target"][k][:3, 3]
            mujoco.mj_forward(model, data)
            renderer.update_scene(data, cam)
            yield renderer.render()


def render_strip(
    model: mujoco.MjModel, runs: list[Recording], camera: dict, file: Path, frames: int = 4
) -> Path:
    """A PNG: a row per run, `frames` snapshots along it."""
    from PIL import Image

    rows = []
    for run in runs:
        ticks = np.linspace(0, len(run.series["t"]) - 1, frames).astype(int)
        rows.append(np.hstack(list(snapshots(model, run, camera, ticks, (240, 320)))))
    file.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.vstack(rows)).quantize(128).save(file, optimize=True)
    return file


def render_video(
    model: mujoco.MjModel, run: Recording, camera: dict, file: Path, rate: float, fps: int
) -> Path:
    """An mp4 of a run recorded at `rate` ticks per second, at `fps` frames per second of
    simulated time (rendered after the loop, taking no time from the ticks)."""
    import imageio

    ticks = range(0, len(run.series["t"]), max(1, round(rate / fps)))
    file.parent.mkdir(parents=True, exist_ok=True)
    with imageio.get_writer(file, fps=fps) as video:
        for image in snapshots(model, run, camera, ticks, (480, 640)):
            video.append_data(image)
    return file
