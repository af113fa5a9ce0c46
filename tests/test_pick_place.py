"""A small sample of benchmarks/pick_place.py: the optimiser-fed ExactPoseTask in a mink loop
(500 Hz, joint, velocity and collision limits, a ball sweeping above the table) reaches every
waypoint of a pick-and-place, with targets that jump and targets that move, never raising,
and keeps its clearance along the motion."""

from __future__ import annotations

import numpy as np
import pytest

import om_redundant as om
from benchmarks import pick_place as pp


@pytest.mark.parametrize("name", ["panda", "iiwa14"])
@pytest.mark.parametrize("mode", ["step", "interpolated"])
def test_every_waypoint_is_reached_clear_and_nothing_raises(name, mode):
    solver = om.OMSolver(name)
    model = pp.scene(solver.arm)
    clearance = om.Clearance(model, solver.arm, ["table", "pole", "ball"])
    optimizer = om.RedundancyOptimizer(solver, clearance, min_clearance=pp.MIN_CLEARANCE)
    poses = pp.waypoints(optimizer, 7, np.random.default_rng(1))
    result = pp.run(solver, mode, "om", poses, pp.start_joints(solver, optimizer))
    assert result.reached == len(poses) and result.raised == 0 and result.flips == 0
    # MuJoCo's own distances, every tick: at least what mink's collision limit keeps
    assert result.min_clearance >= pp.MIN_CLEARANCE - pp.MINK_MARGIN
