"""The command line of ``python -m benchmarks.adversarial``: run, or combine saved runs."""

from __future__ import annotations

import argparse
import json
import os
import pickle
import sys
import time
from collections import Counter
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor

import om_redundant as om

from ..bad_input import run_bad_inputs
from ..report import RESULTS, write_page
from .page import markdown
from .records import CLASSES, ArmResult
from .runner import Sizes, run_arm


def merge(parts: Sequence[ArmResult]) -> ArmResult:
    """One arm's results from several runs (different classes of it) as one."""
    out = ArmResult(parts[0].arm)
    for r in parts:
        out.tallies += r.tallies
        for mine, theirs in ((out.decades, r.decades), (out.arm_angle_line, r.arm_angle_line)):
            for key, counts in theirs.items():
                mine.setdefault(key, Counter()).update(counts)
        out.other_side.update(r.other_side)
        out.failures += r.failures
        out.failure_counts.update(r.failure_counts)
        out.seconds += r.seconds
    return out


def combine(paths: Sequence[str]) -> str:
    """The page of several ``--save-results`` pickles (runs of different arms or classes on the
    same code), arms in :func:`om.arm_names` order; writes it as ``adversarial.md``."""
    runs = []
    for path in paths:
        with open(path, "rb") as f:
            runs.append(pickle.load(f))
    by_arm: dict[str, list[ArmResult]] = {}
    for run in runs:
        for r in run["results"]:
            by_arm.setdefault(r.arm, []).append(r)
    results = [merge(by_arm[name]) for name in om.arm_names() if name in by_arm]
    bad = [b for run in runs for b in run["bad"]]
    run_line = "Runs, combined with `--combine`: " + "; ".join(
        f"`python -m benchmarks.adversarial {' '.join(run['argv'])}` ({run['seconds']:.0f} s)" for run in runs
    )
    args = argparse.Namespace(seed=0, jobs=len(runs))
    load = os.getloadavg()[0]
    sizes = runs[0].get("sizes", Sizes.of(100_000, 10_000))
    text = markdown(results, bad, sizes, args, 0.0, (load, load), run_line + ".  ")
    write_page("adversarial.md", text)
    failures = [f.__dict__ for r in results for f in r.failures]
    (RESULTS / "adversarial.json").write_text(json.dumps(failures, indent=1) + "\n")
    return text


def main(argv: list[str] | None = None) -> list[ArmResult]:
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.adversarial",
        description=sys.modules[__package__].__doc__,  # the package's docstring, as before the split
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--arms", nargs="+", default=om.arm_names(), choices=om.arm_names())
    parser.add_argument("--n-random", type=int, default=100_000, help="random poses per arm (default 1e5)")
    parser.add_argument("--n-singular", type=int, default=10_000, help="branch-boundary poses per arm (1e4)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--quick", action="store_true", help="1/100 of the sizes; writes adversarial_quick.md"
    )
    parser.add_argument(
        "--n-line",
        type=int,
        help="poses next to psi's half-line per 7-DOF arm, in the singular class (--n-singular / 10)",
    )
    parser.add_argument("--jobs", type=int, default=1, help="processes, one arm each at a time (default 1)")
    parser.add_argument("--classes", nargs="+", default=list(CLASSES), choices=CLASSES)
    parser.add_argument("--no-bad-input", action="store_true", help="skip the bad-input table")
    parser.add_argument(
        "--save-results", metavar="PATH", help="also pickle the per-arm results (for --combine)"
    )
    parser.add_argument("--combine", nargs="+", metavar="PATH", help="only write the page of these pickles")
    args = parser.parse_args(argv)
    if args.combine:
        combine(args.combine)
        return []
    n_random, n_singular = args.n_random, args.n_singular
    if args.quick:
        n_random, n_singular = max(n_random // 100, 1), max(n_singular // 100, 1)
    sizes = Sizes.of(n_random, n_singular, args.n_line)
    load_start = os.getloadavg()[0]
    start = time.perf_counter()
    bad = [] if args.no_bad_input else run_bad_inputs()
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            # The torus arms (slowest) first, so that they do not finish last alone.
            order = sorted(args.arms, key=lambda name: name not in ("sawyer", "gen3"))
            futures = {name: pool.submit(run_arm, name, sizes, args.seed, args.classes) for name in order}
            results = [futures[name].result() for name in args.arms]
    else:
        results = [run_arm(name, sizes, args.seed, args.classes) for name in args.arms]
    seconds = time.perf_counter() - start
    text = markdown(results, bad, sizes, args, seconds, (load_start, os.getloadavg()[0]))
    stem = "adversarial_quick" if args.quick else "adversarial"
    write_page(f"{stem}.md", text)
    if args.save_results:
        with open(args.save_results, "wb") as f:
            pickle.dump(
                {"results": results, "bad": bad, "seconds": seconds, "argv": sys.argv[1:], "sizes": sizes}, f
            )
    failures = [f.__dict__ for r in results for f in r.failures]
    (RESULTS / f"{stem}.json").write_text(json.dumps(failures, indent=1) + "\n")
    print(f"total wall time {seconds:.1f} s")
    return results
