"""``om-redundant bench paper``: the OM paper's experiment."""

from __future__ import annotations

import argparse
import dataclasses

from .common import UsageError, add_output_options, table_wanted, write_json


def add_parser(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "bench",
        help="benchmarks: 'paper' runs the OM paper's experiment",
        description="paper: the OM paper's experiment (Section III-B): random joint-space targets, each "
        "solved in its own configuration by one timed call; prints a table beside the paper's figures.",
    )
    parser.add_argument("name", choices=["paper"], help="paper: the OM paper's experiment")
    parser.add_argument("--arm", default="spherical", choices=["spherical", "ur5e"], help="default spherical")
    parser.add_argument("--n", type=int, default=100_000, help="number of targets (default 100000)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the targets")
    add_output_options(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..ik.experiment import run as run_experiment

    if args.n < 1:
        raise UsageError(f"--n must be positive, got {args.n}")
    result = run_experiment(args.arm, args.n, args.seed)
    if table_wanted(args):
        print(result.table())
    if args.json is not None:
        write_json(dataclasses.asdict(result), args.json)
    return 0
