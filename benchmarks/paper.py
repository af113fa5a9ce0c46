"""The OM paper's experiment on the Spherical arm and on the UR5e; writes results/paper.md.

Run: ``python -m benchmarks.paper [--n 100000]`` (``om-redundant bench paper`` runs one arm).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from om_redundant.paper_experiment import run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    tables = [run(arm, args.n, args.seed).table() for arm in ("spherical", "ur5e")]
    text = "\n\n".join(tables) + "\n"
    print(text)
    out = Path(__file__).parent / "results" / "paper.md"
    out.write_text(text)
    print(f"written to {out}")


if __name__ == "__main__":
    main()
