"""KUKA iiwa14: the hand reaches in under a shelf board, where the default (upright) elbow hits it.

OM's redundancy optimiser, tracking along the path, lowers the elbow beside the arm and keeps
3 cm of clearance; mink executes it (FrameTask + om.ExactPoseTask, with ConfigurationLimit,
VelocityLimit and CollisionAvoidanceLimit). Plain mink (FrameTask + PostureTask, same
limits) runs the same path for comparison.

Run: python examples/avoid_shelf_iiwa14.py [--headless] [--seconds 6] [--out examples_out]
"""

import mujoco
import numpy as np
from _common import finish, parse_args, scene

import om_redundant as om

MARGIN = 0.03  # m of clearance the optimiser keeps
HOME = np.array([0.0, 0.6, 0.0, -1.3, 0.0, 1.2, 0.0])  # hand down in front, elbow up

solver = om.OMSolver("iiwa14")
obstacles = {"shelf": dict(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.3, 0.5, 0.01], pos=[0.6, 0.0, 0.74])}
model = scene(solver.arm, obstacles)
T_home = solver.arm.fk(HOME)


def path(s: float) -> np.ndarray:
    """Hand pointing down at 0.4 m height, reaching in from x = 0.45 to 0.7 m under the shelf."""
    T = T_home.copy()
    T[:3, 3] = [0.45 + 0.25 * s, 0.1 - 0.2 * s, 0.4]
    return T


# Plain mink starts in the home configuration's branch and arm angle, at the first pose.
q_start = solver.solve(path(0.0), solver.configuration_of(HOME), q_hint=HOME).q
camera = dict(lookat=[0.35, 0.0, 0.45], distance=2.0, azimuth=120.0, elevation=-10.0)
title = "iiwa14 under a shelf: OM vs plain mink"
finish(parse_args(__doc__), "iiwa14_shelf", model, solver, obstacles, path, q_start, MARGIN, camera, title)
