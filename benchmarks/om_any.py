"""om_redundant's answer to "any in-limit solution for this pose".

A 6-DOF arm tries its configurations in turn. A 7-DOF arm tries configurations with the arm
angle psi on a grid over [-pi, pi), cells ordered by how often random joint vectors within
the limits fall in them (a prior computed once per arm), so that most poses are solved in
the first few tries; if no cell gives a solution within the limits, a finer grid follows,
for poses whose in-limit arm angles form a narrow interval.
"""

from __future__ import annotations

import numpy as np

import om_redundant as om

#: Arm angles per configuration in the first, ordered pass, and in the fine pass.
COARSE_PSI = 16
FINE_PSI = 256
#: Random joint vectors behind the order of the (configuration, psi) cells.
PRIOR_SAMPLES = 20_000


class AnyInLimits:
    """The first solution within limits over configurations (and psi for a 7-DOF arm).

    Args:
        solver: The arm's solver.
        seed: Seed of the prior's joint vectors (not the benchmark's targets).
    """

    def __init__(self, solver: om.OMSolver, seed: int = 12345):
        self.solver = solver
        self.configurations = solver.configurations()
        if not solver.redundancy_names:
            self.coarse = self.configurations
            self.fine = []
            return
        arm = solver.arm
        lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
        upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
        Q = np.random.default_rng(seed).uniform(lower, upper, (PRIOR_SAMPLES, arm.dof))
        counts: dict[tuple, int] = {}
        for q in Q:
            c = solver.configuration_of(q)
            cell = (c.signs, int(np.floor((c.redundancy[0] + np.pi) / (2 * np.pi) * COARSE_PSI)) % COARSE_PSI)
            counts[cell] = counts.get(cell, 0) + 1
        cells = sorted(
            ((c.signs, k) for c in self.configurations for k in range(COARSE_PSI)),
            key=lambda cell: -counts.get(cell, 0),
        )
        self.coarse = [
            om.Configuration(signs, (-np.pi + (k + 0.5) * 2 * np.pi / COARSE_PSI,)) for signs, k in cells
        ]
        fine_psi = np.linspace(-np.pi, np.pi, FINE_PSI, endpoint=False)
        self.fine = [om.Configuration(c.signs, (psi,)) for c in self.configurations for psi in fine_psi]

    def __call__(self, T: np.ndarray) -> om.Solution | None:
        """The first ``ok`` solution within limits for pose T (4x4, root frame), or None."""
        for candidate in (*self.coarse, *self.fine):
            solution = self.solver.solve(T, candidate)
            if solution.ok and solution.within_limits:
                return solution
        return None
