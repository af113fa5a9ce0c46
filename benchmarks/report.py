"""The suite's results as a Markdown page and a plot."""

from __future__ import annotations

import math
import os
import platform
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

from .pages import write_block
from .protocols import (
    ORIENTATION_TOLERANCE,
    POSITION_TOLERANCE,
    PROTOCOLS,
    Outcome,
    Throughput,
)
from .robots import FKCheck

#: Packages whose versions the page names.
PACKAGES = (
    "om_redundant",
    "numpy",
    "scipy",
    "eaik",
    "ik-geo",
    "frankik",
    "pytracik",
    "ikpy",
    "mink",
    "mujoco",
    "daqp",
    "matplotlib",
)
OM = "om_redundant"

#: How each peer was fed; conventions that differ from the arm file are mapped by the adapters.
NOTES = (
    "Notes on the peers (all robots are generated from the same arm file; see the FK checks below):",
    "",
    "* *home*, the start of the iterative peers, is the middle of each joint's range.",
    "* EAIK and ik-geo solve 6 joints: for a 7-DOF arm the last joint is held at a value and the "
    "target becomes `T P_tail^-1 Rz(-q7)` for the first six joints (computed before timing).",
    "* ik-geo: the decomposition (and whether to reverse the chain) is picked by geometry and a "
    "round-trip test; its Python binding takes and returns rotation matrices transposed.",
    "* frankik: `fk` returns the Franka hand's TCP but `ik` takes the flange pose; both are mapped "
    "to the arm file's end-effector frame by a constant offset.",
    "* TRAC-IK keeps joint limits in float32, hence the 1e-6 rad slack; ikpy and mink take them from "
    "the URDF / MJCF in double precision.",
    "* mink's PostureTask pulls toward home and leaves about 1e-3 of pose error at convergence, so the "
    "example setup never meets 1e-6; the FrameTask-only row shows mink without that bias.",
)


@dataclass
class Results:
    """Everything one run measured.

    Attributes:
        n: Targets per arm.
        seed: Seed of the targets.
        arms: Arms run.
        command: The command line.
        outcomes: Per protocol, arm and peer.
        throughputs: Batch calls.
        fk_checks: FK comparisons of the peers.
        skipped: ``(arm, peer, reason)`` of peers not run (or refused).
        settings: ``(arm, peer, settings)``.
        paper_table: The paper experiment's Markdown table, if run.
        seconds: Wall time of the whole run.
        batch_repeats: Batch calls timed per measurement.
        load: One-minute load average at the start and at the end of the run.
    """

    n: int
    seed: int
    arms: list[str]
    command: str
    outcomes: list[Outcome] = field(default_factory=list)
    throughputs: list[Throughput] = field(default_factory=list)
    fk_checks: list[FKCheck] = field(default_factory=list)
    skipped: list[tuple[str, str, str]] = field(default_factory=list)
    settings: list[tuple[str, str, str]] = field(default_factory=list)
    paper_table: str | None = None
    seconds: float = 0.0
    batch_repeats: int = 5
    load: tuple[float, float] = (math.nan, math.nan)


RESULTS = Path(__file__).parent / "results"


def write_page(name: str, text: str) -> Path:
    """Print a result page and write it as the generated block of ``benchmarks/results/<name>``
    (:func:`benchmarks.pages.write_block`: the page's hand-written lines are kept)."""
    print(text)
    out = write_block(RESULTS / name, text)
    print(f"written to {out}")
    return out


def cpu_model() -> str:
    """The CPU model named in /proc/cpuinfo (or what platform knows)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def versions() -> dict[str, str]:
    """Installed versions of :data:`PACKAGES` ("not installed" where missing)."""
    found = {}
    for name in PACKAGES:
        try:
            found[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            found[name] = "not installed"
    return found


def _us(value: float) -> str:
    if not math.isfinite(value):
        return "-"
    return f"{value:.1f}" if value < 100 else f"{value:,.0f}"


def _ratio(value: float, reference: float | None) -> str:
    if reference is None or not math.isfinite(value):
        return "n/a"
    ratio = value / reference
    return f"{ratio:.2g}x" if ratio < 10 else f"{ratio:,.0f}x"


def _percent(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.1f} %"


def _error(value: float) -> str:
    return "none returned" if not math.isfinite(value) else f"{value:.0e}"


def _batch_table(results: Results) -> list[str]:
    """Wall time on the library's threads and CPU time on one thread, each against om_redundant's."""
    lines = [
        f"One call over all N targets with their configurations (or held q7) given; medians of "
        f"{results.batch_repeats} rounds, each round timing every call in turn. **solves/s**: wall "
        "time of the call on its own threads (every core). **CPU ms per 1,000**: the same call on "
        "one thread, by `time.process_time` (threads the library starts count too), per 1,000 "
        "targets: the work itself, which other load on the cores inflates far less than wall "
        "time. **vs om**: the call's time over om_redundant's (above 1x: om_redundant is faster).",
        "",
        "| arm | call | N | solves/s | wall vs om | CPU ms per 1,000 (one thread) | CPU vs om | success |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for arm in results.arms:
        rows = [t for t in results.throughputs if t.arm == arm]
        om = next((t for t in rows if t.peer.startswith(OM)), None)
        for t in rows:
            wall = "n/a" if om is None else f"{t.seconds / om.seconds:.2f}x"
            cpu = "n/a" if om is None else f"{t.cpu_seconds / om.cpu_seconds:.2f}x"
            lines.append(
                f"| {arm} | {t.peer} | {t.n} | {t.per_second:,.0f} | {wall} | {t.cpu_ms_per_1000:.2f} | "
                f"{cpu} | {_percent(t.success)} |"
            )
    return lines


def _protocol_table(results: Results, protocol: str) -> list[str]:
    outcomes = [o for o in results.outcomes if o.protocol == protocol]
    every = protocol == "every"
    head = (
        ["arm", "peer", "solutions (mean)", "true q among them", "median us", "p99 us", "median vs om"]
        if every
        else ["arm", "peer", "success", "median error", "median us", "p99 us", "median vs om"]
    )
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for arm in results.arms:
        rows = [o for o in outcomes if o.arm == arm]
        om = next((o.median_us for o in rows if o.peer == OM), None)
        for o in rows:
            first = (
                [f"{o.solutions:.2f}", _percent(o.true_found)]
                if every
                else [_percent(o.success), _error(o.median_error)]
            )
            cells = [arm, o.peer, *first, _us(o.median_us), _us(o.p99_us), _ratio(o.median_us, om)]
            lines.append("| " + " | ".join(cells) + " |")
        if rows and om is None:
            lines.append(f"| {arm} | {OM} | n/a (not available, see below) | | | | |")
    return lines


def markdown(results: Results) -> str:
    """The Markdown page."""
    packages = ", ".join(f"{name} {version}" for name, version in versions().items())
    out = [
        "# om_redundant and the IK libraries users would otherwise pick",
        "",
        f"Machine: {cpu_model()}, {os.cpu_count()} cores, {platform.system()} {platform.machine()}, "
        f"Python {platform.python_version()}; load average {results.load[0]:.2f} at the start, "
        f"{results.load[1]:.2f} at the end (above 0 means other work shared the cores).  ",
        f"Packages: {packages}.  ",
        f"Run: `{results.command}`: N = {results.n} targets per arm, seed {results.seed}, "
        f"arms {', '.join(results.arms)}; {results.seconds:.0f} s in all.",
        "",
        "Targets: joint vectors drawn uniformly within the limits, the same for every peer. "
        f"**Success**: a returned joint vector reaches the target within {POSITION_TOLERANCE:g} m and "
        f"{ORIENTATION_TOLERANCE:g} rad, checked with the arm's own FK (not the peer's report), and lies "
        "within the joint limits after shifting revolute joints by multiples of 2 pi "
        "(1e-6 rad slack for peers that store limits in float32). "
        "**Time**: the library call alone, per target, from Python, target and result "
        "conversions excluded (so the peers' numbers are, if anything, flattering); median and "
        "99th percentile in microseconds. **median vs om**: the peer's median over om_redundant's "
        "(above 1x: om_redundant is faster). 7-DOF peers hold q7 at the true value where a "
        "redundancy is given; om_redundant takes the true arm angle psi instead.",
        "",
        *NOTES,
        "",
    ]
    for protocol, title in PROTOCOLS.items():
        out += [f"## {title}", "", *_protocol_table(results, protocol), ""]
    if results.throughputs:
        out += ["## Batch throughput", "", *_batch_table(results), ""]
    if results.paper_table:
        out += ["## The OM paper's experiment (Spherical arm)", "", results.paper_table, ""]
    if results.fk_checks:
        out += [
            "## Forward-kinematics checks",
            "",
            "Each peer's own FK, from the generated URDF, MJCF or (H, P), against `arm.fk` on random q.",
            "",
            "| arm | peer | max position error (m) | max angle (rad) | verdict |",
            "|---|---|---|---|---|",
        ]
        out += [
            f"| {c.arm} | {c.peer} | {c.position_error:.1e} | {c.orientation_error:.1e} | "
            f"{'ok' if c.passed else 'REFUSED'} (tol {c.tolerance:g}) |"
            for c in results.fk_checks
        ]
        out.append("")
    if results.skipped:
        out += ["## Not run", "", "| arm | peer | why |", "|---|---|---|"]
        out += [f"| {arm} | {peer} | {reason} |" for arm, peer, reason in results.skipped]
        out.append("")
    if results.settings:
        out += ["## Settings", "", "| arm | peer | settings |", "|---|---|---|"]
        out += [f"| {arm} | {peer} | {text} |" for arm, peer, text in results.settings]
        out.append("")
    return "\n".join(out)


def _short_percent(fraction: float) -> str:
    """A success rate for a bar: whole percent, one decimal when that would round to 0 or 100."""
    text = f"{100 * fraction:.0f}"
    if text in ("0", "100") and 0.0 < fraction < 1.0:
        text = f"{100 * fraction:.1f}"
    return text + "%"


def _time_label(us: float, _: object = None) -> str:
    if us >= 1e6:
        return f"{us / 1e6:g} s"
    return f"{us / 1e3:g} ms" if us >= 1e3 else f"{us:g} us"


def plot(results: Results, path: Path) -> bool:
    """Median time per target (log scale) for each protocol, arm and peer, success on the bars.

    Returns:
        Whether a plot was written (not when nothing was measured).
    """
    if not results.outcomes:
        return False
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter

    peers = list(dict.fromkeys(o.peer for o in results.outcomes))
    colours = {peer: plt.get_cmap("tab10")(i % 10) for i, peer in enumerate(peers)}
    fig, axes = plt.subplots(1, len(PROTOCOLS), figsize=(6 * len(PROTOCOLS), 5.5), squeeze=False)
    for ax, (protocol, title) in zip(axes[0], PROTOCOLS.items(), strict=True):
        outcomes = [o for o in results.outcomes if o.protocol == protocol]
        arms = [arm for arm in results.arms if any(o.arm == arm for o in outcomes)]
        for a, arm in enumerate(arms):
            rows = [o for o in outcomes if o.arm == arm]
            width = 0.8 / max(len(rows), 1)
            for k, o in enumerate(rows):
                x = a - 0.4 + width * (k + 0.5)
                ax.bar(x, o.median_us, width, color=colours[o.peer], label=o.peer)
                label = f"{o.solutions:.1f}" if protocol == "every" else _short_percent(o.success)
                ax.text(x, o.median_us, label, ha="center", va="bottom", fontsize=7, rotation=90)
        ax.set_xticks(range(len(arms)), arms)
        ax.set_yscale("log")
        top = max((o.median_us for o in outcomes), default=10.0)
        ax.set_ylim(1.0, top * 30)
        ax.yaxis.set_major_formatter(FuncFormatter(_time_label))
        ax.set_ylabel("median time per target")
        note = "solutions found" if protocol == "every" else "success"
        ax.set_title(f"{title}\n(bar labels: {note})", fontsize=10)
        ax.grid(axis="y", alpha=0.3)
    handles = {}
    for ax in axes[0]:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(label, handle)
    fig.legend(handles.values(), handles.keys(), loc="lower center", ncol=min(len(handles), 5), fontsize=9)
    fig.suptitle(
        f"om_redundant and peers: N = {results.n} targets per arm, seed {results.seed}, {cpu_model()}"
    )
    fig.tight_layout(rect=(0, 0.1, 1, 0.95))
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True
