"""Panda: the hand sweeps sideways under a horizontal pole that sits where the default elbow goes.

OM's redundancy optimiser, tracking along the path, swings the elbow out of the way and keeps
3 cm of clearance; mink executes it (FrameTask + om.ExactPoseTask, with ConfigurationLimit,
VelocityLimit and CollisionAvoidanceLimit). Plain mink (FrameTask + PostureTask, same
limits) runs the same path for comparison.

Run: python examples/avoid_pole_panda.py [--headless] [--seconds 6] [--out examples_out]
"""

import mujoco
import numpy as np
from _common import finish, parse_args, scene

import om_redundant as om

MARGIN = 0.03  # m of clearance the optimiser keeps
HOME = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785])  # hand down in front, elbow up

solver = om.OMSolver("panda")
obstacles = {
    "pole": dict(
        type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.03, 0, 0], fromto=[0.08, -0.6, 0.72, 0.08, 0.6, 0.72]
    )
}
model = scene(solver.arm, obstacles)
T_home = solver.arm.fk(HOME)


def path(s: float) -> np.ndarray:
    """Hand pointing down, 0.5 m in front, sweeping y from -0.35 to 0.35 m."""
    T = T_home.copy()
    T[:3, 3] = [0.5, -0.35 + 0.7 * s, 0.45]
    return T


# Plain mink starts in the home configuration's branch and arm angle, at the first pose.
q_start = solver.solve(path(0.0), solver.configuration_of(HOME), q_hint=HOME).q
camera = dict(lookat=[0.25, 0.0, 0.45], distance=1.9, azimuth=150.0, elevation=-15.0)
finish(
    parse_args(__doc__),
    "panda_pole",
    model,
    solver,
    obstacles,
    path,
    q_start,
    MARGIN,
    camera,
    "Panda under a pole: OM vs plain mink",
)
