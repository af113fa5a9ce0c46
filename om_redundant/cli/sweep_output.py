"""What ``om-redundant sweep`` shows of a :class:`~om_redundant.redundancy.sweep.SweepResult`: a
table, CSV, JSON, and plots (matplotlib, imported only for ``--plot``)."""

from __future__ import annotations

import csv
import io
import math
import sys

import numpy as np

from ..redundancy.sweep import PoseSweep, SweepRequest, SweepResult
from .common import table_wanted, write_json

MAX_INTERVALS_SHOWN = 4  # per branch in the table


def margin_text(value: float) -> str:
    return "-" if not math.isfinite(value) else f"{value:.3f}"


def clearance_text(value: float) -> str:
    return "-" if math.isnan(value) else ("no obstacles" if math.isinf(value) else f"{value:.3f} m")


def signs_text(signs: tuple[int, ...]) -> str:
    return " ".join(f"{s:+d}" for s in signs)


def table(request: SweepRequest, result: SweepResult) -> str:
    """The sweep for a person: per pose, each branch's feasible psi intervals and best margin
    and clearance, and the choice; for a path, one line per pose."""
    solver = request.solver
    step = 2.0 * math.pi / len(result.psi)
    lines = [
        f"arm: {solver.arm.name} ({solver.arm.description})",
        f"psi: {len(result.psi)} angles, step {step:.4f} rad; obstacles: {len(request.obstacles)}"
        + ("" if request.scene is None else f", scene geoms: {request.scene.ngeom}"),
    ]
    if request.path:
        lines.append(
            f"\n{'pose':>5}  {'x':>7} {'y':>7} {'z':>7}  {'branch':<9} {'psi':>7}  {'margin':>7}  clearance"
        )
        for i, pose in enumerate(result.poses):
            x, y, z = pose.pose[:3, 3]
            c = pose.chosen
            if c is None:
                lines.append(f"{i:>5}  {x:7.3f} {y:7.3f} {z:7.3f}  no feasible arm angle")
                if pose.note:
                    lines.append(f"{'':>7}{pose.note}")
                continue
            signs, psi = signs_text(c.configuration.signs), c.configuration.redundancy[0]
            lines.append(
                f"{i:>5}  {x:7.3f} {y:7.3f} {z:7.3f}  {signs:<9} {psi:7.3f}  "
                f"{margin_text(c.margin):>7}  {clearance_text(c.clearance)}"
                + ("  (chosen afresh)" if c.rechosen else "")
                + ("  (branch flipped)" if c.branch_flipped else "")
            )
            if pose.note:
                lines.append(f"{'':>7}{pose.note}")
        return "\n".join(lines)
    (pose,) = result.poses
    names = " ".join(solver.sign_names)
    lines.append(f"target: xyz = {np.round(pose.pose[:3, 3], 6).tolist()} m")
    lines.append(f"\n{names:<21} {'feasible psi intervals (rad)':<48} {'margin':>7}  clearance")
    for branch in pose.branches:
        shown = [f"[{lo:+.3f}, {hi:+.3f}]" for lo, hi in branch.intervals[:MAX_INTERVALS_SHOWN]]
        more = len(branch.intervals) - len(shown)
        intervals = " ".join(shown) + (f" +{more} more" if more > 0 else "") if shown else "none"
        best_margin, best_clearance = _best(branch.margin, branch.clearance, branch.feasible)
        lines.append(
            f"{signs_text(branch.signs):<21} {intervals:<48} {margin_text(best_margin):>7}  "
            f"{clearance_text(best_clearance)}"
        )
    lines.append("")
    lines += _choice_lines(request, pose)
    return "\n".join(lines)


def _best(margin: np.ndarray, clearance: np.ndarray, feasible: np.ndarray) -> tuple[float, float]:
    """Largest smallest-joint margin and largest clearance over the feasible angles."""
    if not feasible.any():
        return math.nan, math.nan
    return float(margin[feasible].min(axis=1).max()), float(clearance[feasible].max())


def _choice_lines(request: SweepRequest, pose: PoseSweep) -> list[str]:
    c = pose.chosen
    if c is None:
        return ["chosen: none (no feasible arm angle in any branch)"] + ([pose.note] if pose.note else [])
    joints = request.solver.arm.joint_names
    return [
        f"chosen: {signs_text(c.configuration.signs)}, psi = {c.configuration.redundancy[0]:.4f} rad, "
        f"margin {margin_text(c.margin)}, clearance {clearance_text(c.clearance)}",
        "q = " + ", ".join(f"{n} {v:.5f}" for n, v in zip(joints, c.q, strict=True)),
    ]


def csv_text(request: SweepRequest, result: SweepResult) -> str:
    """One row per pose, branch and psi: signs, psi, ok, feasible, smallest margin, clearance,
    q and each joint's margin. NaN where there is no solution, inf for no obstacles."""
    solver = request.solver
    joints = solver.arm.joint_names
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(
        ["pose", *solver.sign_names, "psi", "ok", "feasible", "margin", "clearance"]
        + [f"q_{j}" for j in joints]
        + [f"margin_{j}" for j in joints]
    )
    for i, pose in enumerate(result.poses):
        for branch in pose.branches:
            smallest = np.min(branch.margin, axis=1)
            for k, psi in enumerate(result.psi):
                writer.writerow(
                    [i, *branch.signs, repr(float(psi)), int(branch.ok[k]), int(branch.feasible[k])]
                    + [
                        repr(float(v))
                        for v in (smallest[k], branch.clearance[k], *branch.q[k], *branch.margin[k])
                    ]
                )
    return out.getvalue()


def write_csv(request: SweepRequest, result: SweepResult, destination: str) -> None:
    text = csv_text(request, result)
    if destination == "-":
        sys.stdout.write(text)
    else:
        with open(destination, "w", newline="") as f:
            f.write(text)


def json_data(request: SweepRequest, result: SweepResult) -> dict:
    """The whole sweep as data for :func:`~om_redundant.cli.common.write_json`."""
    solver = request.solver
    poses = []
    for pose in result.poses:
        c = pose.chosen
        chosen = None
        if c is not None:
            chosen = {
                "signs": c.configuration.signs,
                "psi": c.configuration.redundancy[0],
                "q": c.q,
                "margin": c.margin,
                "clearance": c.clearance,
            }
        branches = [
            {
                "signs": b.signs,
                "intervals": b.intervals,
                "ok": b.ok,
                "feasible": b.feasible,
                "q": b.q,
                "margin": b.margin,
                "clearance": b.clearance,
            }
            for b in pose.branches
        ]
        if c is not None:
            chosen.update(value=c.value, branch_flipped=c.branch_flipped, rechosen=c.rechosen)
        poses.append({"target": pose.pose, "chosen": chosen, "note": pose.note, "branches": branches})
    return {
        "arm": solver.arm.name,
        "sign_names": solver.sign_names,
        "joint_names": solver.arm.joint_names,
        "lower": solver.arm.lower,
        "upper": solver.arm.upper,
        "path": request.path,
        "obstacles": [{"kind": o.kind, "values": o.values} for o in request.obstacles],
        "psi": result.psi,
        "poses": poses,
    }


# ---------------------------------------------------------------------------------------
# Plots


def _pyplot():
    import matplotlib  # imported here: it is slow to import and only plots need it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot(request: SweepRequest, result: SweepResult, path: str) -> None:
    """The pose plot (one pose) or the path map (a path), as PNG or SVG by the file's suffix."""
    figure = (_path_map if request.path else _pose_plot)(request, result)
    figure.savefig(path, dpi=110)
    _pyplot().close(figure)


def _pose_plot(request: SweepRequest, result: SweepResult):
    """Joint angles against psi, limits shaded; clearance against psi; feasible intervals;
    the chosen psi marked everywhere. Thin lines: solutions outside the limits or obstacles."""
    plt = _pyplot()
    arm = request.solver.arm
    (pose,) = result.poses
    psi = result.psi
    panels, columns = arm.dof + 2, 3
    rows = math.ceil(panels / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 2.5 * rows + 0.9), sharex=True)
    axes = axes.ravel()
    colour = plt.get_cmap("tab10")
    chosen = pose.chosen
    chosen_psi = None if chosen is None else chosen.configuration.redundancy[0]

    def lines(ax, values, b, branch):
        values = np.where(branch.ok, values, np.nan)
        values[1:][np.abs(np.diff(values)) > np.pi] = np.nan  # no vertical strokes at 2 pi wraps
        ax.plot(psi, values, lw=0.8, alpha=0.35, color=colour(b % 10))
        ax.plot(psi, np.where(branch.feasible, values, np.nan), lw=1.6, color=colour(b % 10))

    for j in range(arm.dof):
        ax = axes[j]
        for b, branch in enumerate(pose.branches):
            lines(ax, branch.q[:, j], b, branch)
        low, high = ax.get_ylim()
        lo, hi = arm.lower[j], arm.upper[j]
        if np.isfinite(lo):
            low = min(low, lo - 0.2)
            ax.axhspan(low, lo, color="tab:red", alpha=0.15, lw=0)
        if np.isfinite(hi):
            high = max(high, hi + 0.2)
            ax.axhspan(hi, high, color="tab:red", alpha=0.15, lw=0)
        ax.set_ylim(low, high)
        ax.set_title(f"{arm.joint_names[j]} ({'rad' if arm.revolute[j] else 'm'})", fontsize=9)
    ax = axes[arm.dof]
    for b, branch in enumerate(pose.branches):
        lines(ax, np.where(np.isfinite(branch.clearance), branch.clearance, np.nan), b, branch)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_title("clearance to obstacles (m)", fontsize=9)
    if not request.obstacles and request.scene is None:
        ax.text(0.5, 0.75, "no obstacles", transform=ax.transAxes, ha="center", va="center", color="0.4")
    ax = axes[arm.dof + 1]
    step = psi[1] - psi[0] if len(psi) > 1 else 2 * math.pi
    for b, branch in enumerate(pose.branches):
        spans = []
        for lo, hi in branch.intervals:  # an arc crossing +-pi is drawn at both ends
            spans.append((lo, max(min(hi, math.pi) - lo, step)))
            if hi > math.pi:
                spans.append((-math.pi, max(hi - 2.0 * math.pi + math.pi, step)))
        ax.broken_barh(spans, (b - 0.35, 0.7), color=colour(b % 10))
        if chosen is not None and chosen.configuration.signs == branch.signs:
            ax.plot([chosen_psi], [b], "k*", ms=10)
    ax.set_yticks(range(len(pose.branches)), [signs_text(b.signs) for b in pose.branches], fontsize=7)
    ax.set_ylim(-0.6, len(pose.branches) - 0.4)
    ax.set_title("feasible psi by branch", fontsize=9)
    for ax in axes[:panels]:
        if chosen_psi is not None:
            ax.axvline(chosen_psi, color="k", ls="--", lw=1.0)
        ax.set_xlim(-math.pi, math.pi)
        ax.tick_params(labelsize=7)
    for ax in axes[panels:]:
        ax.set_visible(False)
    for ax in axes[max(panels - columns, 0) : panels]:
        ax.set_xlabel("arm angle psi (rad)", fontsize=8)
        ax.xaxis.set_tick_params(labelbottom=True)
    handles = [plt.Line2D([], [], color=colour(b % 10), lw=1.6) for b in range(len(pose.branches))]
    labels = [signs_text(b.signs) for b in pose.branches]
    if chosen is not None:
        handles.append(plt.Line2D([], [], color="k", ls="--"))
        labels.append(f"chosen: psi = {chosen_psi:.3f}, {signs_text(chosen.configuration.signs)}")
    figure.legend(
        handles,
        labels,
        loc="lower center",
        ncol=min(len(labels), 5),
        fontsize=8,
        frameon=False,
        title=" ".join(request.solver.sign_names),
        title_fontsize=8,
    )
    x, y, z = pose.pose[:3, 3]
    figure.suptitle(
        f"{arm.name}: arm angle sweep for the target at ({x:.3f}, {y:.3f}, {z:.3f}) m; "
        "joint limits shaded red"
    )
    figure.tight_layout(rect=(0, 0.75 / (2.5 * rows + 0.9), 1, 1))
    return figure


def _path_map(request: SweepRequest, result: SweepResult):
    """Pose index against psi, coloured by the best smallest-joint margin over the feasible
    branches (grey: no feasible branch), with the tracked psi drawn on it."""
    plt = _pyplot()
    psi = result.psi
    best = np.full((len(result.poses), len(psi)), np.nan)
    for i, pose in enumerate(result.poses):
        for branch in pose.branches:
            margin = np.where(branch.feasible, np.min(branch.margin, axis=1), np.nan)
            best[i] = np.fmax(best[i], margin)
    figure, ax = plt.subplots(figsize=(10, 5.5))
    cmap = plt.get_cmap("viridis").with_extremes(bad="0.85")
    step = psi[1] - psi[0] if len(psi) > 1 else 2 * math.pi
    extent = (psi[0] - step / 2, psi[-1] + step / 2, len(result.poses) - 0.5, -0.5)
    image = ax.imshow(
        np.ma.masked_invalid(best), aspect="auto", extent=extent, cmap=cmap, interpolation="nearest"
    )
    figure.colorbar(image, ax=ax, label="best normalised joint-limit margin of a feasible branch")
    tracked = [(i, p.chosen.configuration.redundancy[0]) for i, p in enumerate(result.poses) if p.chosen]
    if tracked:
        index, angle = np.array(tracked).T
        ax.plot(angle, index, "w-", lw=2.5)
        ax.plot(angle, index, "r.-", lw=1.2, label="tracked psi (chosen)")
        ax.legend(loc="upper right", fontsize=8)
    ax.set_xlabel("arm angle psi (rad)")
    ax.set_ylabel("pose index")
    ax.set_title(f"{request.solver.arm.name}: arm angle along the path (grey: no feasible branch)")
    figure.tight_layout()
    return figure


def show(request: SweepRequest, result: SweepResult, args) -> None:
    """Everything the command line asked for: the table, CSV, JSON and plot."""
    if table_wanted(args) and args.csv != "-":
        print(table(request, result))
    if args.csv is not None:
        write_csv(request, result, args.csv)
    if args.json is not None:
        write_json(json_data(request, result), args.json)
    if args.plot is not None:
        plot(request, result, args.plot)
