"""om_redundant's answer to "any in-limit solution for this pose" (until the library has one).

A 6-DOF arm tries its configurations in turn; a 7-DOF arm tries each configuration with
the arm angle psi on a grid over [-pi, pi). The first solution that is ok and within the
joint limits is returned.
"""

from __future__ import annotations

import numpy as np

import om_redundant as om

#: Arm angles tried for each configuration of a 7-DOF arm.
PSI_GRID = tuple(np.linspace(-np.pi, np.pi, 16, endpoint=False))


def solve_any_in_limits(
    solver: om.OMSolver, T: np.ndarray, psi_grid: tuple[float, ...] = PSI_GRID
) -> om.Solution | None:
    """The first solution within limits over configurations (and psi for a 7-DOF arm).

    Args:
        solver: The arm's solver.
        T: Target pose (4x4) of the end effector in the root frame.
        psi_grid: Arm angles tried per configuration when the arm is redundant.

    Returns:
        The first ``ok`` solution within limits, or None.
    """
    redundant = len(solver.redundancy_names) > 0
    for configuration in solver.configurations():
        candidates = (
            [om.Configuration(configuration.signs, (psi,)) for psi in psi_grid]
            if redundant
            else [configuration]
        )
        for candidate in candidates:
            solution = solver.solve(T, candidate)
            if solution.ok and solution.within_limits:
                return solution
    return None
