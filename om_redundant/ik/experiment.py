"""The OM paper's experiment (Section III-B), reproduced and timed per solve.

Targets are uniform random joint vectors (the Spherical arm's q3 in +-0.5 m, the paper's
protocol; joint limits for other arms); the configuration asked for is that of the
joint vector, so a solution exists. Each target is solved by one call of
:meth:`OMSolver.solve`, timed with ``perf_counter``, from Python.
"""

from __future__ import annotations

import platform
import time
from dataclasses import dataclass

import numpy as np

from ..angles import wrap_angles
from .solver import OMSolver

#: The paper's figures for the Spherical arm (C on a SUN SPARCstation 2).
PAPER = {
    "converged": "100 %",
    "configuration errors": "0",
    "orientation error": "< 1e-8",
    "position error": "< 1e-4 m (E_max = 0.1 mm)",
    "mean time": "996 us",
    "max time": "14.074 s",
}


@dataclass(frozen=True)
class ExperimentResult:
    arm: str
    n: int
    converged: float
    configuration_errors: int
    max_orientation_error: float  # the paper's |n - n| + |s - s| + |a - a|
    max_position_error: float
    recovered: float  # fraction returning the very joint vector the target came from
    mean_us: float
    median_us: float
    p99_us: float
    max_us: float
    machine: str

    def table(self) -> str:
        """Markdown table of this run beside the paper's figures."""
        paper = PAPER if self.arm == "spherical" else dict.fromkeys(PAPER, "-")
        rows = [
            ("targets", f"{self.n:,}", "100,000" if self.arm == "spherical" else "-"),
            ("converged", f"{100 * self.converged:.3f} %", paper["converged"]),
            ("configuration errors", f"{self.configuration_errors}", paper["configuration errors"]),
            ("max orientation error", f"{self.max_orientation_error:.1e}", paper["orientation error"]),
            ("max position error (m)", f"{self.max_position_error:.1e}", paper["position error"]),
            ("original q returned", f"{100 * self.recovered:.2f} %", "-"),
            ("mean time per solve", f"{self.mean_us:.1f} us", paper["mean time"]),
            ("median / p99", f"{self.median_us:.1f} / {self.p99_us:.1f} us", "-"),
            ("max time", f"{self.max_us:.0f} us", paper["max time"]),
        ]
        lines = [f"| {self.arm} | om_redundant ({self.machine}) | paper |", "|---|---|---|"]
        lines += [f"| {a} | {b} | {c} |" for a, b, c in rows]
        return "\n".join(lines)


def run(arm: str = "spherical", n: int = 100_000, seed: int = 0) -> ExperimentResult:
    """Run the experiment on ``n`` targets of a built-in arm."""
    solver = OMSolver(arm)
    rng = np.random.default_rng(seed)
    lower = np.where(np.isfinite(solver.arm.lower), solver.arm.lower, -np.pi)
    upper = np.where(np.isfinite(solver.arm.upper), solver.arm.upper, np.pi)
    Q = rng.uniform(lower, upper, (n, solver.arm.dof))
    if arm == "spherical":
        Q[:, 2] = rng.uniform(-0.5, 0.5, n)
    T = solver.arm.fk(Q)
    configurations = [solver.configuration_of(q) for q in Q]
    solver.solve(T[0], configurations[0])  # compile before timing
    times = np.empty(n)
    q_out = np.full_like(Q, np.nan)
    ok = np.zeros(n, dtype=bool)
    clock = time.perf_counter
    for i in range(n):
        t0 = clock()
        sol = solver.solve(T[i], configurations[i])
        times[i] = clock() - t0
        ok[i] = sol.ok
        q_out[i] = sol.q
    reached = solver.arm.fk(np.where(ok[:, None], q_out, 0.0))
    orientation = np.abs(reached[:, :3, :3] - T[:, :3, :3]).sum(axis=(1, 2))[ok]
    position = np.linalg.norm(reached[:, :3, 3] - T[:, :3, 3], axis=1)[ok]
    wrong_configuration = sum(
        solver.configuration_of(q) != c for q, c, good in zip(q_out, configurations, ok, strict=True) if good
    )
    diff = q_out - Q
    diff[:, solver.arm.revolute] = wrap_angles(diff[:, solver.arm.revolute])
    recovered = np.abs(diff).max(axis=1) < 1e-9
    us = times * 1e6
    return ExperimentResult(
        arm=arm,
        n=n,
        converged=float(ok.mean()),
        configuration_errors=int(wrong_configuration + (~ok).sum()),
        max_orientation_error=float(orientation.max(initial=0.0)),
        max_position_error=float(position.max(initial=0.0)),
        recovered=float(recovered.mean()),
        mean_us=float(us.mean()),
        median_us=float(np.median(us)),
        p99_us=float(np.percentile(us, 99)),
        max_us=float(us.max()),
        machine=f"{platform.machine()}, Python {platform.python_version()}",
    )


__all__ = ["PAPER", "ExperimentResult", "run"]
