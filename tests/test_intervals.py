"""The ends of the feasible intervals (om_redundant/redundancy/paths/intervals.py): each refined end
is the last feasible point before the boundary, and refining every end at once (lockstep)
makes the same follows as refining each alone."""

from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

import om_redundant as om
from benchmarks.control_rate import MIN_CLEARANCE, obstacles
from om_redundant.redundancy.paths.intervals import SLACK_TOLERANCE, _refined, _runs, _spans
from om_redundant.redundancy.paths.linking import lockstep, sweep_circle
from om_redundant.redundancy.paths.probe import END_TOLERANCE
from tests.conftest import random_pose, random_scenes, solver_of


def alone(process):
    """A lockstep process run by itself, each follow's point evaluated when asked."""
    answer = None
    try:
        while True:
            probe, start, psi = process.send(answer)
            answer = probe.follow(start, psi)
    except StopIteration as done:
        return done.value


@settings(max_examples=6, deadline=None)
@random_scenes
# Runs that are their path's fold end alone (intervals._refined, "Path ends"): the follow
# from the fold cannot leave it (seeds 9, 385, 104), the cubic models' trial from it lies
# within END_TOLERANCE of it (seeds 315, 385); each such end stayed at the fold, its slack
# 2e-2 to 1e-1.
@example(seed=9, name="panda", count=1)
@example(seed=315, name="panda", count=1)
@example(seed=385, name="panda", count=3)
@example(seed=104, name="fr3", count=3)
def test_refined_ends_are_the_boundary_and_lockstep_is_alone(seed, name, count):
    """On a random reachable pose with obstacles about the hand: every end refined between a
    run's end sample and the infeasible sample beyond is feasible, and either its slack is
    at most SLACK_TOLERANCE or the path is infeasible 2 END_TOLERANCE farther out (beyond
    the bracket's outer end, which is within END_TOLERANCE: a follow shorter than
    END_TOLERANCE is refused), also where the run's end sample is where its path ends; the
    ends refined all at once are those refined one by one, to the bit."""
    solver = solver_of(name)
    T = random_pose(solver, seed)
    optimizer = om.RedundancyOptimizer(solver, obstacles(T[:3, 3], count), min_clearance=MIN_CLEARANCE)
    probes = [optimizer._probe(T, signs) for signs in optimizer.branches]
    swept = sweep_circle(probes, optimizer.grid_points)
    ends = [
        (probe, span.points[k], outside)
        for probe, paths in zip(probes, swept, strict=True)
        for path in paths
        for span in _spans(path)
        for k, outside in ((0, span.before), (-1, span.after))
        if outside is not None
    ]
    together = lockstep([_refined(*end) for end in ends])
    for (probe, inside, outside), end in zip(ends, together, strict=True):
        one = alone(_refined(probe, inside, outside))
        assert one.psi == end.psi and np.array_equal(one.q, end.q)
        assert end.evaluation.feasible
        direction = np.sign(outside.psi - inside.psi)
        assert 0.0 <= (end.psi - inside.psi) * direction < abs(outside.psi - inside.psi)
        if end.evaluation.slack > SLACK_TOLERANCE:
            beyond, arrived = probe.follow(end, end.psi + direction * 2.0 * END_TOLERANCE)
            assert arrived and not beyond.evaluation.feasible


@given(flags=st.lists(st.booleans(), max_size=40))
def test_runs_are_the_maximal_runs_of_true_flags(flags):
    """_runs: every true flag in exactly one run [i, j), all of a run's flags true, and the
    flags just outside a run false (or the list's ends)."""
    runs = _runs(flags)
    covered = [k for i, j in runs for k in range(i, j)]
    assert covered == [k for k, flag in enumerate(flags) if flag]
    for i, j in runs:
        assert i < j and (i == 0 or not flags[i - 1]) and (j == len(flags) or not flags[j])
