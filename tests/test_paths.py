"""The look inside the cells of the global choose's solution paths (paths._with_hidden,
paths._hidden): every cell that one sheet of solutions spans is halved until no joint moves
more than FINE_STEP in it, also the first cell of a path that starts at a fold, from which no
follow leaves (its samples are followed from the cell's other end); and a feasibility change
that such a cell's ends do not show is found."""

from __future__ import annotations

import dataclasses
import itertools
from unittest import mock

import numpy as np
from hypothesis import example, settings

import om_redundant as om
from benchmarks.control_rate import MIN_CLEARANCE, obstacles
from om_redundant import _core
from om_redundant.angles import TURN
from om_redundant.redundancy.paths import linking as paths
from om_redundant.redundancy.paths.linking import FINE_STEP, sweep_circle
from tests.conftest import random_pose, random_scenes, solver_of


def swept(solver: om.OMSolver, T: np.ndarray, count: int, looked: bool = True):
    """The probes of every branch of the pose T with ``count`` obstacles about the hand, and
    their paths, with the look inside the cells or (``looked=False``) without."""
    optimizer = om.RedundancyOptimizer(solver, obstacles(T[:3, 3], count), min_clearance=MIN_CLEARANCE)
    probes = [optimizer._probe(T, signs) for signs in optimizer.branches]
    if looked:
        return probes, sweep_circle(probes, optimizer.grid_points)
    with mock.patch.object(paths, "_with_hidden", lambda found: [path for _, path in found]):
        return probes, sweep_circle(probes, optimizer.grid_points)


def cells(path: paths.Path):
    """The neighbouring samples of a path, a loop's closing cell too."""
    points = path.points
    if path.turns:
        points = [*points, points[0].at(points[0].psi + TURN * path.turns)]
    return itertools.pairwise(points)


def traced(probe, a, b) -> bool:
    """Whether a follow from one end of the cell arrives at its middle: then the cell is one
    sheet of solutions (the following leaves a fold from neither side)."""
    middle = 0.5 * (a.psi + b.psi)
    return probe.follow(a, middle)[1] or probe.follow(b, middle)[1]


@settings(max_examples=6, deadline=None)
@random_scenes
# Paths that start at a fold, their first cells 0.25-0.77 rad in the joints (main left them
# unsampled: no follow leaves the fold).
@example(seed=9, name="panda", count=1)
@example(seed=0, name="fr3", count=1)
@example(seed=0, name="panda", count=3)
def test_every_traced_cell_is_finer_than_fine_step(seed, name, count):
    """On a random reachable pose with obstacles about the hand: in every cell of every path
    that a follow traces from either end to its middle, no joint moves more than FINE_STEP
    (compared as the probe compares them)."""
    solver = solver_of(name)
    probes, found = swept(solver, random_pose(solver, seed), count)
    for probe, branch in zip(probes, found, strict=True):
        for path in branch:
            for a, b in cells(path):
                step = _core.joint_step(probe.cyclic, a.q, b.q)
                assert step <= FINE_STEP or not traced(probe, a, b), (probe.signs, a.psi, b.psi, step)


def test_a_dip_in_the_first_cell_of_a_path_that_starts_at_a_fold_is_found():
    """Seed 9, Panda, 1 obstacle: a path starts at a fold (no follow leaves it), its first
    cell 0.357 rad in the joints, both ends feasible, and a joint turns inside it (an
    extremum beyond both ends' values). With that joint's limit halfway between the extremum
    and the nearer end's value, the cell hides an infeasible dip; the look inside finds it:
    an infeasible sample between the ends, which stay feasible."""
    solver = solver_of("panda")
    T = random_pose(solver, 9)
    probes, raw = swept(solver, T, 1, looked=False)
    dips = []  # (signs, a, b, joint, limit side, limit)
    for probe, branch in zip(probes, raw, strict=True):
        for path in branch:
            a, b = path.points[:2]
            middle = 0.5 * (a.psi + b.psi)
            if path.turns or probe.follow(a, middle)[1] or not probe.follow(b, middle)[1]:
                continue  # (not a path whose first sample is where it ends, or not one sheet)
            if not (a.evaluation.feasible and b.evaluation.feasible):
                continue
            inner = np.array(
                [probe.follow(b, a.psi + s * (b.psi - a.psi))[0].q for s in np.linspace(0.02, 0.98, 49)]
            )
            ends = np.array([a.q, b.q])
            for j in range(solver.arm.dof):
                low, high = inner[:, j].min(), inner[:, j].max()
                if low < ends[:, j].min() - 1e-4:
                    dips.append((probe.signs, a, b, j, "lower", 0.5 * (low + ends[:, j].min())))
                if high > ends[:, j].max() + 1e-4:
                    dips.append((probe.signs, a, b, j, "upper", 0.5 * (high + ends[:, j].max())))
    assert dips  # (the pose has such a cell)
    for signs, a, b, j, side, limit in dips:
        bounds = getattr(solver.arm, side).copy()
        bounds[j] = limit
        limited = om.OMSolver(dataclasses.replace(solver.arm, **{side: bounds}))
        probes, found = swept(limited, T, 1)
        ((probe, branch),) = [
            (probe, branch) for probe, branch in zip(probes, found, strict=True) if probe.signs == signs
        ]
        (path,) = [  # (the fold as the limited arm's solver finds it, to rounding)
            path
            for path in branch
            if abs(path.points[0].psi - a.psi) < 1e-12 and probe.step(path.points[0].q, a.q) < 1e-6
        ]
        k = next(k for k, p in enumerate(path.points) if p.psi == b.psi)
        assert path.points[0].evaluation.feasible and path.points[k].evaluation.feasible
        assert k > 1 and not all(p.evaluation.feasible for p in path.points[1:k])
