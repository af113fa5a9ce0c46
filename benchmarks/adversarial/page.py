"""The results page: summary, decades, the half-line, the other side, bad input, reproducers."""

from __future__ import annotations

import argparse
import os
import platform
import sys
from collections import Counter
from collections.abc import Sequence
from typing import Any

import numpy as np

import om_redundant as om
from om_redundant.ik import BRANCH_BAND

from ..bad_input import BadInput, bad_input_table
from ..report import cpu_model
from .records import (
    CLASSES,
    DECADES,
    FK_ROUNDING,
    KEEP,
    ORIENTATION_TOLERANCE,
    POSITION_TOLERANCE,
    REDUNDANCY_TOLERANCE,
    ROOT_MATCH,
    THREADS,
    TORUS_SOLVE_ALL_STRIDE,
    ArmResult,
    Failure,
)
from .runner import Sizes


def _cells(values: Sequence[Any]) -> str:
    return "| " + " | ".join(str(v) for v in values) + " |"


def _fmt(x: float) -> str:
    return repr(float(x))


def reproducer(f: Failure) -> str:
    c = f"Configuration({f.signs}{', ' + repr(f.redundancy) if f.redundancy else ''})"
    parts = [f"`{f.arm}` {f.cls}, {f.call}: {f.detail}.", f"c = `{c}`"]
    if f.q is not None:
        parts.append(f"q = `[{', '.join(map(_fmt, f.q))}]`")
    if f.T is not None:
        parts.append("T = `arm.fk(q)`" if f.T_is_fk and f.q is not None else f"T = `{f.T}`")
    if f.hint is not None:
        parts.append(f"q_hint = `[{', '.join(map(_fmt, f.hint))}]`")
    return "* " + "; ".join(parts)


def unlimited_prismatic_note(arms: Sequence[str]) -> list[str]:
    """A note on arms with an unlimited prismatic joint: any distance is within their reach."""
    found = []
    for name in arms:
        arm = om.load_arm(name)
        if (~arm.revolute & ~(np.isfinite(arm.lower) & np.isfinite(arm.upper))).any():
            found.append(name)
    if not found:
        return []
    return [
        "",
        f"Arms with an unlimited prismatic joint ({', '.join(found)}) reach any distance: their "
        "translated poses are not unreachable, and at |p| = 1e120 m no float64 FK agrees with "
        "another to 1e-10 m (MuJoCo's rounding alone is about 1e-16 |p|): the position check there "
        f"is relative, {FK_ROUNDING:.1e} |p|.",
    ]


def arm_angle_line_table(results: list[ArmResult]) -> list[str]:
    """The 7-DOF arms' poses next to the arm angle's singular half-line, per decade of delta."""
    rows = [r for r in results if r.arm_angle_line]
    if not rows:
        return []
    found = {k for r in rows for k in r.arm_angle_line}
    columns = sorted(found, key=lambda k: (k.split()[0], int(k.split()[1])))
    return [
        "",
        "## The arm angle's singular half-line",
        "",
        "7-DOF arms: the model's wrist centre at the angle delta from straight below the shoulder "
        "(w_hat = -up, where psi's reference n(w_hat) = R(up -> w_hat) r is undefined) or straight above; "
        "solve, hinted solve and solve_all in c = configuration_of(q) (counted in the singular class "
        "above). Cell: poses with any false no, wrong ok or non-library exception / poses, by "
        "floor(log10 delta).",
        "",
        _cells(["arm", *[f"{k.split()[0]} 1e{k.split()[1]}" for k in columns]]),
        "|" + "---|" * (len(columns) + 1),
        *(
            _cells(
                [
                    r.arm,
                    *[f"{d['any']}/{d['cases']}" if (d := r.arm_angle_line.get(k)) else "-" for k in columns],
                ]
            )
            for r in rows
        ),
    ]


def markdown(
    results: list[ArmResult],
    bad: list[BadInput],
    sizes: Sizes,
    args: argparse.Namespace,
    seconds: float,
    load,
    run_line: str | None = None,
) -> str:
    tallies = [t for r in results for t in r.tallies]
    out = [
        "# Adversarial reliability (issue 18)",
        "",
        f"Machine: {cpu_model()}, {os.cpu_count()} cores, {platform.system()} {platform.machine()}, "
        f"Python {platform.python_version()}; load average {load[0]:.2f} at the start, {load[1]:.2f} "
        "at the end (the machine was shared).  ",
        run_line
        or (
            f"Run: `{' '.join(['python -m benchmarks.adversarial', *sys.argv[1:]])}`, seed {args.seed}, "
            f"{args.jobs} process(es); **{seconds:.0f} s** wall time in all.  "
        ),
        f"Sizes per arm: random {sizes.random} poses, singular {sizes.singular} branch poses and "
        f"{sizes.limits} poses at limits, {sizes.line} next to psi's half-line (7-DOF), "
        f"huge/tiny {sizes.huge}, layouts {sizes.layouts}, "
        f"threads {sizes.threads} questions x {THREADS} threads, repeated {sizes.repeated} questions.",
        "",
        "Every answer marked ok is checked against MuJoCo's FK of the project's MJCF of the arm "
        f"(`om.arm_model(arm)`, `mj_kinematics`, the end-effector site): **wrong ok** if it misses T by "
        f"more than {POSITION_TOLERANCE:g} m (or {FK_ROUNDING:.1e} |p| where that is more: two FKs' "
        f"rounding far away) or {ORIENTATION_TOLERANCE:g} rad, or q is not in the "
        f"requested configuration (a branch quantity within {BRANCH_BAND:g} of zero counts for both "
        f"signs; psi within {REDUNDANCY_TOLERANCE:g} rad modulo 2 pi, or within its own rounding "
        "next to its singular half-line: `OMSolver.holds`), or `within_limits` is not "
        "`lower <= q <= upper`. **false no**: ok False (or an empty `solve_all`) for T = FK(q) in "
        "c = configuration_of(q) (for huge psi: only where the reduced psi is within 1e-9 of q's). "
        "**non-library**: an exception that is not an `om.OMError`. **differ**: an answer (status, q, "
        "errors, within_limits, bit for bit) that differs from one it must equal: the same call again, "
        "another layout, a thread, a batch row, a huge psi's exact reduction. **calls**: library calls "
        "checked (a batch counts its rows).",
        "",
        f"`solve_all` on the torus arms (gen3, sawyer; about 5 ms a call) runs on every "
        f"{TORUS_SOLVE_ALL_STRIDE}th pose of the random, singular and layouts classes, and in 1.5 % of "
        "their thread and repeated questions; on every pose for the other arms.",
        "",
        "Reading the notes: a wrong ok marked *within the solver's own tolerance* misses by more "
        "than this page's 1e-10 but less than the solver's own `position_tolerance` / "
        "`orientation_tolerance` (defaults 1e-10 m and 1e-10 rad); *solve_all without q*: "
        f"`solve_all` returned roots, none within {ROOT_MATCH:g} of q; *far: status not 'unreachable'*: "
        "a pose translated 1e3 ... 1e300 m answered otherwise; *library exception*: an `om.OMError` "
        "raised for a valid input.",
        *unlimited_prismatic_note([r.arm for r in results]),
        "",
        "## Summary",
        "",
        _cells(
            [
                "class",
                "arm",
                "poses",
                "calls",
                "ok",
                "wrong ok",
                "false no",
                "non-library",
                "differ",
                "s",
                "slowest call",
                "notes",
            ]
        ),
        "|" + "---|" * 12,
    ]
    for cls in CLASSES:
        for t in (t for t in tallies if t.cls == cls):
            notes = "; ".join(f"{k}: {v}" for k, v in sorted(t.notes.items()))
            out.append(
                _cells(
                    [
                        cls,
                        t.arm,
                        t.poses,
                        t.calls,
                        t.ok,
                        t.wrong_ok,
                        t.false_no,
                        t.foreign,
                        t.differs,
                        f"{t.seconds:.0f}",
                        f"{1e3 * t.slowest[0]:.0f} ms ({t.slowest[1]})",
                        notes,
                    ]
                )
            )
    out += ["", "Totals per class:", ""]
    out += [
        _cells(["class", "poses", "calls", "ok", "wrong ok", "false no", "non-library", "differ"]),
        "|" + "---|" * 8,
    ]
    for cls in CLASSES:
        rows = [t for t in tallies if t.cls == cls]
        if rows:
            sums = [
                sum(getattr(t, a) for t in rows)
                for a in ("poses", "calls", "ok", "wrong_ok", "false_no", "foreign", "differs")
            ]
            out.append(_cells([cls, *sums]))
    if any(r.decades for r in results):
        found = {k for r in results for k in r.decades if k != "limits"}
        columns = [str(d) for d in sorted({*DECADES, *map(int, found)})] + ["limits"]
        out += [
            "",
            "## Singular and boundary poses per decade of the branch offset",
            "",
            "Cell: poses with any false no, wrong ok or non-library exception / poses, by "
            "floor(log10 |branch quantity|) of the moved branch; *limits*: joints at a limit +- 1e-12.",
            "",
            _cells(["arm", *[f"1e{d}" if d != "limits" else d for d in columns]]),
            "|" + "---|" * (len(columns) + 1),
        ]
        for r in results:
            cells = [r.arm]
            for col in columns:
                d = r.decades.get(col)
                cells.append(f"{d['any']}/{d['cases']}" if d else "-")
            out.append(_cells(cells))
        kinds = ["false no (solve)", "false no (hinted solve)", "false no (solve_all)", "wrong ok"]
        out += ["", "The same, by call (all decades and limits together):", ""]
        out += [_cells(["arm", "poses", *kinds]), "|" + "---|" * (len(kinds) + 2)]
        for r in results:
            total = Counter()
            for d in r.decades.values():
                total.update(d)
            out.append(_cells([r.arm, total["cases"], *[total[k] for k in kinds]]))
        out += arm_angle_line_table(results)
        out += [
            "",
            "## The other side of the boundary",
            "",
            f"Poses with |branch offset| <= {BRANCH_BAND:g} (`BRANCH_BAND`), asked in the configuration "
            "with that branch's sign flipped: by the band contract such a pose belongs to both, so a "
            "'no' there is a false no (counted in the singular class above).",
            "",
            _cells(
                [
                    "arm",
                    "poses",
                    "ok (solve)",
                    "ok (hinted)",
                    "false no (solve / hinted)",
                    "wrong ok",
                ]
            ),
            "|---|---|---|---|---|---|",
        ]
        for r in results:
            o = r.other_side
            out.append(
                _cells(
                    [
                        r.arm,
                        o["cases"],
                        o["ok (solve)"],
                        o["ok (hinted solve)"],
                        f"{o['false no (solve)']} / {o['false no (hinted solve)']}",
                        o["wrong ok"],
                    ]
                )
            )
    out += bad_input_table(bad)
    failures = [f for r in results for f in r.failures]
    counts = Counter()
    for r in results:
        for (cls, kind), v in r.failure_counts.items():
            counts[(r.arm, cls, kind)] += v
    out += ["", "## Reproducers", ""]
    if not failures:
        out.append("None: nothing failed.")
    else:
        out += [
            "Counts of every failure kind, then up to 5 reproducers of each (all kept ones, up to "
            f"{KEEP} per kind, in the `.json` beside this page). q, T and c as given to the call.",
            "",
            _cells(["arm", "class", "kind", "count"]),
            "|---|---|---|---|",
        ]
        out += [_cells([a, c, k, v]) for (a, c, k), v in sorted(counts.items())]
        out.append("")
        shown: Counter = Counter()
        for f in failures:
            key = (f.arm, f.cls, f.kind)
            shown[key] += 1
            if shown[key] <= 5:
                out.append(reproducer(f))
    out.append("")
    return "\n".join(out)
