"""Solve one UR5e pose in all eight configurations and check each answer.

Run: python examples/solve_ur5e.py
"""

import numpy as np

import om_redundant as om

solver = om.OMSolver("ur5e")
T_base_target = solver.arm.fk(np.array([0.4, -1.1, 1.3, -1.2, -1.4, 0.3]))

for configuration in solver.configurations():
    solution = solver.solve(T_base_target, configuration)
    if not solution.ok:
        print(configuration.signs, solution.status)
        continue
    T_reached = solver.arm.fk(solution.q)
    assert np.abs(T_reached - T_base_target).max() < 1e-10
    assert solver.configuration_of(solution.q) == configuration
    print(configuration.signs, np.round(solution.q, 4), f"error {solution.position_error:.1e} m")
