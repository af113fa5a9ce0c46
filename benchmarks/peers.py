"""om_redundant against the IK libraries users would otherwise pick, on the same targets.

Run: ``python -m benchmarks.peers --n 1000 --seed 0 [--arms panda,ur5e] [--peers EAIK,ikpy]
[--quick]``. Writes ``results/peers.md`` and ``results/peers.png`` (``peers_quick.*`` with
``--quick``). Peers come from the ``bench`` extra: ``pip install -e ".[bench]"``; one that
is missing, does not handle an arm, crashes, or whose FK disagrees with the arm file is
skipped with the reason printed.

Protocols (see :mod:`benchmarks.protocols`): exact solve for a given redundancy, any
in-limit solution, all solutions for a redundancy value, batch throughput, and the OM
paper's experiment on the Spherical arm.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import traceback
from pathlib import Path

import numpy as np

import om_redundant as om
from om_redundant.ik.experiment import run as run_paper_experiment

from .adapters import PEERS, Peer, Unavailable
from .pages import write_block
from .protocols import PROTOCOLS, Targets, measure, measure_batches
from .report import Results, markdown, plot
from .robots import check_fk

DEFAULT_ARMS = ("panda", "iiwa14", "ur5e", "spherical")
RESULTS = Path(__file__).parent / "results"


def _say(text: str) -> None:
    print(text, flush=True)


def _set_up(name: str, arm: om.Arm, results: Results, seed: int, fk_samples: int) -> Peer | None:
    """The peer for this arm, or None (reason printed and recorded)."""
    rng = np.random.default_rng(seed)
    try:
        peer = PEERS[name](arm, rng)
    except Unavailable as exc:
        reason = str(exc)
    except Exception as exc:  # a peer's own failure must not stop the suite
        reason = f"crashed while setting up: {type(exc).__name__}: {exc}"
    else:
        if peer.fk is not None:
            check = check_fk(name, arm, peer.fk, rng, samples=fk_samples)
            results.fk_checks.append(check)
            _say(f"  {check.line()}")
            if not check.passed:
                results.skipped.append((arm.name, name, "refused: its FK disagrees with the arm file"))
                return None
        results.settings.append((arm.name, name, peer.settings))
        return peer
    _say(f"  {name}: {reason}")
    results.skipped.append((arm.name, name, reason))
    return None


def _run_peer(peer: Peer, targets: Targets, results: Results) -> None:
    for protocol in PROTOCOLS:
        if getattr(peer, protocol) is None:
            continue
        start = time.perf_counter()
        try:
            outcome = measure(peer, protocol, targets)
        except Exception as exc:
            _say(f"  {peer.name} {protocol}: crashed ({type(exc).__name__}: {exc}); skipped")
            traceback.print_exc(limit=3)
            results.skipped.append(
                (targets.arm.name, peer.name, f"{protocol}: crashed ({type(exc).__name__})")
            )
            continue
        results.outcomes.append(outcome)
        extra = (
            f", {outcome.solutions:.2f} solutions, true q found {100 * outcome.true_found:.1f} %"
            if outcome.solutions is not None and outcome.true_found is not None
            else ""
        )
        _say(
            f"  {peer.name} {protocol}: success {100 * outcome.success:.1f} %{extra}, "
            f"median {outcome.median_us:.1f} us, p99 {outcome.p99_us:.1f} us "
            f"({time.perf_counter() - start:.1f} s)"
        )


def _run_batches(peers: list[Peer], targets: Targets, results: Results, repeats: int) -> None:
    """The peers' batch calls, timed in turn in each round (see measure_batches)."""
    methods = [(p.batch, p.limit_tolerance) for p in peers if p.batch is not None]
    if not methods:
        return
    try:
        throughputs = measure_batches(methods, targets, repeats)
    except Exception as exc:
        _say(f"  batch calls: crashed ({type(exc).__name__}: {exc}); skipped")
        results.skipped.append((targets.arm.name, "batch calls", f"crashed ({type(exc).__name__})"))
        return
    results.throughputs += throughputs
    for t in throughputs:
        _say(
            f"  {t.peer}: {t.per_second:,.0f} solves/s, one thread {t.cpu_ms_per_1000:.2f} ms CPU "
            f"per 1,000, success {100 * t.success:.1f} %"
        )


def main(argv: list[str] | None = None) -> Results:
    """Run the suite and write the Markdown page and the plot."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--n", type=int, default=1000, help="targets per arm (default 1000)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--arms", default=",".join(DEFAULT_ARMS), help="comma-separated arm names")
    parser.add_argument("--peers", default=",".join(PEERS), help="comma-separated peer names")
    parser.add_argument("--quick", action="store_true", help="at most 50 targets; writes peers_quick.*")
    parser.add_argument("--out", type=Path, default=None, help="Markdown output (default results/peers.md)")
    args = parser.parse_args(argv)
    n = min(args.n, 50) if args.quick else args.n
    arms = [a for a in args.arms.split(",") if a]
    peers = [p for p in args.peers.split(",") if p]
    unknown = [p for p in peers if p not in PEERS]
    if unknown:
        parser.error(f"unknown peers {unknown}; known: {list(PEERS)}")
    if unknown_arms := [a for a in arms if a not in om.arm_names()]:
        parser.error(f"unknown arms {unknown_arms}; known: {om.arm_names()}")
    out = args.out or RESULTS / ("peers_quick.md" if args.quick else "peers.md")
    command = "python -m benchmarks.peers " + " ".join(argv if argv is not None else sys.argv[1:])
    repeats = 3 if args.quick else 11
    results = Results(n=n, seed=args.seed, arms=arms, command=command.strip(), batch_repeats=repeats)
    load_start = os.getloadavg()[0]
    start = time.perf_counter()

    for name in arms:
        arm = om.load_arm(name)
        _say(f"[{name}] {arm.description}: {n} targets, seed {args.seed}")
        targets = Targets.random(arm, n, args.seed)
        ready = []
        for peer_name in peers:
            peer = _set_up(peer_name, arm, results, args.seed, fk_samples=16 if args.quick else 64)
            if peer is not None:
                _run_peer(peer, targets, results)
                ready.append(peer)
        _run_batches(ready, targets, results, repeats)
        if name == "spherical":
            _say(f"[spherical] the OM paper's experiment, {n} targets")
            results.paper_table = run_paper_experiment("spherical", n, args.seed).table()

    results.seconds = time.perf_counter() - start
    results.load = (load_start, os.getloadavg()[0])
    write_block(out, markdown(results))
    picture = out.with_suffix(".png")
    try:
        why_not = "" if plot(results, picture) else "nothing measured"
    except ImportError as exc:  # matplotlib comes with the bench extra
        why_not = str(exc)
    _say(f"written {out}" + (f" (no plot: {why_not})" if why_not else f" and {picture}"))
    _say(f"{results.seconds:.0f} s in all")
    return results


if __name__ == "__main__":
    main()
