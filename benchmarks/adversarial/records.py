"""The benchmark's tolerances and sizes, and what a run records: tallies, failures, an arm's result."""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

TURN = 2.0 * math.pi
POSITION_TOLERANCE = 1e-10  # m, MuJoCo's FK against T (at |p| up to 1e5 m; see FK_ROUNDING)
#: Relative part of the position check, for poses 1e5 ... 1e300 m away (arms with an unlimited
#: prismatic joint reach them): each coordinate of an FK is a sum of terms of size |p|, each
#: rounded to eps |p| / 2, and MuJoCo sums them in another order than the library, so two
#: exact FKs of the same q differ by a few eps |p| (measured: 0.3 ... 1.1 eps |p| at 1e89 ...
#: 1e125 m). The check's position tolerance is max(POSITION_TOLERANCE, FK_ROUNDING |p|): the
#: checker's rounding, not the library's tolerance (the solver still verifies to 1e-10 m).
FK_ROUNDING = 8.0 * float(np.finfo(np.float64).eps)
ORIENTATION_TOLERANCE = 1e-10  # rad
REDUNDANCY_TOLERANCE = 1e-9  # rad, modulo 2 pi
ROOT_MATCH = 1e-6  # rad (or m): q among solve_all's roots
HINT_NOISE = 0.05  # rad, standard deviation of the random class's hint
DECADES = tuple(range(-14, -3))  # floor(log10 |branch quantity|) of the singular cases
CROSSING_GRID = 64  # samples of a joint's range where the singular class looks for crossings
TORUS_SOLVE_ALL_STRIDE = 20  # gen3, sawyer: solve_all on every 20th pose (5 ms a call)
BATCH_CHUNK = 10_000
THREADS = 4
KEEP = 20  # reproducers kept per (class, arm, kind)
WITHIN_SOLVER = "within the solver's own tolerance"
CLASSES = ("random", "singular", "huge/tiny", "layouts", "threads", "repeated")


@dataclass
class Tally:
    """Counts of one attack class on one arm.

    Attributes:
        cls, arm: The class and the arm.
        poses: Poses (or questions) generated.
        calls: Library calls whose answers were checked.
        ok: Calls answered ok (solve_all: at least one root).
        wrong_ok: Ok answers that fail the check (solve_all: calls with a wrong root).
        false_no: Reachable requests answered no (ok False or an empty solve_all).
        foreign: Exceptions raised that are not ``om.OMError``.
        differs: Answers that differ from the one they must equal (repeated calls, layouts,
            threads, batch rows, a huge psi and its reduction).
        seconds: Wall time of the class on this arm.
        notes: Further counts, by name.
    """

    cls: str
    arm: str
    poses: int = 0
    calls: int = 0
    ok: int = 0
    wrong_ok: int = 0
    false_no: int = 0
    foreign: int = 0
    differs: int = 0
    seconds: float = 0.0
    slowest: tuple[float, str] = (0.0, "")
    notes: Counter = field(default_factory=Counter)

    def line(self) -> str:
        extra = "; ".join(f"{k} {v}" for k, v in sorted(self.notes.items()))
        return (
            f"[{self.arm}] {self.cls}: {self.poses} poses, {self.calls} calls, {self.ok} ok, "
            f"{self.wrong_ok} wrong ok, {self.false_no} false no, {self.foreign} non-library "
            f"exceptions, {self.differs} differ ({self.seconds:.1f} s; slowest call "
            f"{1e3 * self.slowest[0]:.0f} ms)" + (f" [{extra}]" if extra else "")
        )


@dataclass
class Failure:
    """A reproducer: the call, its inputs and what went wrong."""

    cls: str
    arm: str
    kind: str  # "wrong ok", "false no", "non-library exception", "differs", ...
    call: str
    detail: str
    q: list[float] | None = None  # the joint vector T was made from (None: not from a q)
    T: list[list[float]] | None = None
    signs: tuple[int, ...] = ()
    redundancy: tuple[float, ...] = ()
    hint: list[float] | None = None
    T_is_fk: bool = True  # T = arm.fk(q)


@dataclass
class ArmResult:
    """Everything one arm's run found."""

    arm: str
    tallies: list[Tally] = field(default_factory=list)
    decades: dict[str, Counter] = field(default_factory=dict)  # column -> counts
    other_side: Counter = field(default_factory=Counter)
    arm_angle_line: dict[str, Counter] = field(default_factory=dict)  # column -> counts
    failures: list[Failure] = field(default_factory=list)
    failure_counts: Counter = field(default_factory=Counter)
    seconds: float = 0.0
