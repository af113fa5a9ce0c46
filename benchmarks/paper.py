"""The OM paper's experiment on the Spherical arm and on the UR5e; writes results/paper.md.

Run: ``python -m benchmarks.paper [--n 100000]`` (``om-redundant bench paper`` runs one arm).
"""

from __future__ import annotations

import argparse

from om_redundant.ik.experiment import run

from .report import write_page


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    tables = [run(arm, args.n, args.seed).table() for arm in ("spherical", "ur5e")]
    write_page("paper.md", "\n\n".join(tables) + "\n")


if __name__ == "__main__":
    main()
