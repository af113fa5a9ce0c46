r"""Choices reachable from where the arm is: joint travel, and clearance along the way.

When the optimiser chooses from the arm's current joints :math:`q_0` (a fresh choice in a
mink loop, or a re-choice where tracking cannot continue), each feasible sample of the
sweep (:mod:`~om_redundant.redundancy.paths.intervals`) is a candidate. A revolute joint is taken
at the turn nearest :math:`q_0` that stays within its limits (an unlimited joint goes the
short way round), and the candidate scores

.. math::  f(q) - w_t \, \lVert q - q_0 \rVert_2,

the objective less :math:`w_t` per radian (metre, for a slide) of joint travel, plus the
clearance term of the objective taken along the way,
:math:`w_c \min(1, D_{way}/d_{cap})`, :math:`D_{way}` the smallest clearance at
:data:`WAY_SAMPLES` points along the straight joint-space segment from :math:`q_0` (every
candidate's in one batch): of two ways, the one that keeps farther from the obstacles (a
hand that stays above the table rather than diving to it). Candidates are taken best
first, and the first whose segment is certified clear
(:meth:`~om_redundant.Clearance.minimum_along`, above :func:`way_floor`: :data:`WAY_MARGIN`
more than :math:`d_{min}`, for the arm's steps off the straight way, where the arm starts
that far; an arm already nearer may stay as near, never nearer) wins; where none is, the
best candidate, with the clearance its way has.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ...angles import TURN
from ...kinematics.arm import Arm
from ..objective.objective import Objective
from ..objective.segment_clearance import ALONG_TOLERANCE
from ..objective.terms import Evaluation
from ..paths.intervals import Run
from ..paths.points import Point

#: w_t: objective given up per radian of joint travel (default).
DEFAULT_TRAVEL_WEIGHT = 0.25
#: Candidates whose way is checked, best first, before the best is taken as it is.
MAX_WAY_CHECKS = 24
#: m: a clear way keeps this much more than d_min where it starts farther: mink's steps leave the
#: straight way by up to about this (its velocity limits clip joint by joint, the FrameTask pulls).
WAY_MARGIN = 0.01
#: Points inside a way at which its clearance is sampled for the score.
WAY_SAMPLES = 15
#: A candidate's feasibility slack must exceed this: a refined interval end lies on the
#: boundary (slack ~1e-12), where the next tracking step's rounding leaves the feasible set.
INTERIOR = 1e-6


class Candidate(NamedTuple):
    """A feasible sample taken at the joints nearest the arm's.

    Attributes:
        run: Its feasible run.
        point: The sample (its ``q`` at the turns nearest mid-range).
        q: The joints at the turns nearest the arm's, within the limits.
        evaluation: The objective at ``q``.
        travel: Joint travel from the arm's joints (rad, Euclidean).
        score: f(q) less the travel's weight, plus the way's sampled clearance term.
    """

    run: Run
    point: Point
    q: np.ndarray
    evaluation: Evaluation
    travel: float
    score: float


class Way(NamedTuple):
    """The chosen candidate, the clearance along its way (inf without obstacles), and
    whether that is clear (:func:`clear_way`)."""

    candidate: Candidate
    clearance: float
    clear: bool


def nearest_turns(arm: Arm, q: np.ndarray, q_from: np.ndarray) -> np.ndarray:
    """q (M, dof) with each revolute joint moved by the whole turns k that bring it nearest
    q_from (dof,) while it stays within the arm's limits: the k nearest the unconstrained
    best, among those of the limits (q itself within them: an interval of k holding 0)."""
    turn = TURN
    k = np.clip(
        np.round((q_from - q) / turn), np.ceil((arm.lower - q) / turn), np.floor((arm.upper - q) / turn)
    )
    return np.where(arm.revolute, q + turn * k, q)


def candidates(
    objective: Objective, runs: list[Run], q_from: np.ndarray | None, travel_weight: float
) -> list[Candidate]:
    """Every feasible sample of the runs inside the feasible set (slack above
    :data:`INTERIOR`; on its boundary only where no other is) as a :class:`Candidate`, best
    score first (without the arm's joints q_from: by the objective alone, travel nan)."""
    found = [(run, p) for run in runs for p in run.points if p.evaluation.slack > INTERIOR]
    found = found or [(run, p) for run in runs for p in run.points if p.evaluation.feasible]
    if not found:
        return []
    q = np.array([p.q for _, p in found])
    if q_from is not None:
        q = nearest_turns(objective.arm, q, q_from)
    pairs = [p.terms.get_pairs() for _, p in found]
    distances = None if pairs[0] is None else np.array([d for d, _ in pairs])
    evaluations = objective.evaluations(q, distances)  # (the margins of the joints moved by turns)
    score = np.array([ev.value for ev in evaluations])
    travel = np.full(len(q), math.nan) if q_from is None else np.linalg.norm(q - q_from, axis=1)
    if q_from is not None:
        score -= travel_weight * travel
    if objective.clearance is not None and q_from is not None:  # the ways' sampled clearance
        s = np.arange(1, WAY_SAMPLES + 1) / (WAY_SAMPLES + 1)
        ways = q_from + s[None, :, None] * (q - q_from)[:, None, :]  # (K, S, dof)
        along = objective.clearance.minima(ways.reshape(-1, len(q_from))).reshape(len(q), WAY_SAMPLES)
        score += objective.clearance_weight * np.minimum(1.0, along.min(axis=1) / objective.clearance_cap)
    rows = [
        Candidate(run, p, q_k, ev, t, sc)
        for (run, p), q_k, ev, t, sc in zip(
            found, q, evaluations, travel.tolist(), score.tolist(), strict=True
        )
        if ev.feasible
    ]
    return sorted(rows, key=lambda c: -c.score)


def way_floor(objective: Objective, q_from: np.ndarray) -> float:
    r"""What a clear way from q_from keeps: :math:`\min(d_{min} + m, D(q_0))` less
    :data:`~om_redundant.redundancy.objective.segment_clearance.ALONG_TOLERANCE`, m =
    :data:`WAY_MARGIN` for the
    arm's deviation from the straight way (-inf without obstacles)."""
    if objective.clearance is None:
        return -math.inf
    floor = min(objective.min_clearance + WAY_MARGIN, objective.clearance.minimum(q_from))
    return floor - ALONG_TOLERANCE


def way_clearance(objective: Objective, q_from: np.ndarray, q_to: np.ndarray, floor: float) -> float:
    """The clearance along the way from q_from to q_to, as far as it matters against
    ``floor`` (:meth:`~om_redundant.Clearance.minimum_along`; inf without obstacles)."""
    if objective.clearance is None:
        return math.inf
    return objective.clearance.minimum_along(q_from, q_to, floor)


def clear_way(objective: Objective, ranked: list[Candidate], q_from: np.ndarray | None) -> Way | None:
    """The first of the ranked candidates whose way from q_from is clear (module docstring);
    else the first, with its way's clearance; None if there are none. (Without q_from, the
    first: no way to check.)"""
    if not ranked:
        return None
    if q_from is None:
        return Way(ranked[0], math.nan, True)
    floor = way_floor(objective, q_from)
    first = None
    for candidate in ranked[:MAX_WAY_CHECKS]:
        along = way_clearance(objective, q_from, candidate.q, floor)
        if along >= floor:
            return Way(candidate, along, True)
        if first is None:
            first = Way(candidate, along, False)
    return first
