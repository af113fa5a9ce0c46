"""The binding's own cost per call, hand-written CPython API against nanobind.

Both stubs do what ``Solver.solve_pose`` does around the kernel (``csrc/binding/solve_pose.c``):
read a (4, 4) float64 pose and a Configuration, copy them, release the GIL, and build the
Solution with a new numpy q; the kernel is replaced by a stub. Build and run (needs a C/C++
compiler, cmake and ``pip install nanobind``)::

    cmake -S benchmarks/binding -B build/binding -DPython_EXECUTABLE=$(which python)
    cmake --build build/binding
    python -m benchmarks.binding.bench build/binding

Results and the decision they support: benchmarks/results/binding.md.
"""

import statistics
import sys
import timeit
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

import om_redundant as om
from benchmarks.report import cpu_model, write_page

sys.path.insert(0, sys.argv[1] if len(sys.argv) > 1 else "build/binding")
import capi_stub
import nb_stub


@dataclass(frozen=True, slots=True)
class Configuration:
    signs: tuple
    redundancy: tuple = ()


@dataclass(frozen=True, slots=True)
class Solution:
    q: np.ndarray
    ok: bool
    status: str
    configuration: object
    position_error: float
    orientation_error: float
    iterations: int
    within_limits: bool


def per_call(call: Callable[[], object], number: int = 20_000) -> float:
    """Median over 5 runs of the best of 3 repeats, ns per call."""
    runs = [min(timeit.repeat(call, number=number, repeat=3)) / number * 1e9 for _ in range(5)]
    return statistics.median(runs)


def main() -> None:
    capi_stub.set_types(Solution, Configuration)
    nb_stub.set_type(Configuration)
    T, c = np.eye(4), Configuration((1, -1, 1), (0.3,))
    assert np.array_equal(capi_stub.solve_pose(T, c).q, nb_stub.solve_pose(T, c).q)
    ours = per_call(lambda: capi_stub.solve_pose(T, c))
    theirs = per_call(lambda: nb_stub.solve_pose(T, c))
    solver = om.OMSolver("panda")
    q = np.array([0.3, -0.4, 0.2, -2.2, 0.3, 1.9, 0.6])
    T_target, c_target = solver.arm.fk(q), solver.configuration_of(q)
    solve = per_call(lambda: solver.solve(T_target, c_target), 5_000)
    write_page(
        "binding.md",
        "| | ns per call |\n|---|---|\n"
        f"| binding alone, hand-written C API | {ours:,.0f} |\n"
        f"| binding alone, nanobind | {theirs:,.0f} ({theirs - ours:+,.0f}) |\n"
        f"| whole `OMSolver.solve`, Panda (binding + kernel) | {solve:,.0f} |\n\n"
        f"nanobind's binding on a Panda solve: {100 * (theirs - ours) / solve:+.0f} %, {cpu_model()}.\n",
    )


if __name__ == "__main__":
    main()
