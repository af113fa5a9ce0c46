"""The sizes of a run and every attack class on one arm."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

from .arm_run import ArmRun
from .huge_tiny import run_huge_tiny
from .layouts import run_layouts
from .random_poses import run_random
from .records import CLASSES, ArmResult
from .repeated import run_repeated
from .singular import run_singular
from .threads import run_threads


@dataclass(frozen=True)
class Sizes:
    random: int
    singular: int
    limits: int
    line: int
    huge: int
    layouts: int
    threads: int
    repeated: int

    @staticmethod
    def of(n_random: int, n_singular: int, n_line: int | None = None) -> Sizes:
        return Sizes(
            random=n_random,
            singular=n_singular,
            limits=max(n_singular // 4, 1),
            line=max(n_singular // 10, 1) if n_line is None else n_line,
            huge=max(n_random // 50, 10),
            layouts=max(n_random // 1000, 5),
            threads=max(n_random // 50, 20),
            repeated=max(n_random // 50, 20),
        )


def run_arm(name: str, sizes: Sizes, seed: int, classes: Sequence[str] = CLASSES) -> ArmResult:
    """Every attack class on one arm, printing a summary line per class."""
    start = time.perf_counter()
    run = ArmRun(name, seed)
    steps = {
        "random": lambda: run_random(run, sizes.random),
        "singular": lambda: run_singular(run, sizes.singular, sizes.limits, sizes.line),
        "huge/tiny": lambda: run_huge_tiny(run, sizes.huge),
        "layouts": lambda: run_layouts(run, sizes.layouts),
        "threads": lambda: run_threads(run, sizes.threads),
        "repeated": lambda: run_repeated(run, sizes.repeated),
    }
    for cls in classes:
        print(steps[cls]().line(), flush=True)
    run.result.seconds = time.perf_counter() - start
    return run.result
