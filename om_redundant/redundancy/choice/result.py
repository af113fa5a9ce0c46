"""What the redundancy optimiser answers: a :class:`RedundancyChoice`, or a failed one that says
why nothing is feasible."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...ik.configuration import Configuration
from ...ik.solver import Solution
from ..paths.intervals import PsiInterval


@dataclass(frozen=True, eq=False)
class RedundancyChoice:
    """What :meth:`RedundancyOptimizer.choose` picked.

    Attributes:
        ok: A feasible configuration was found.
        configuration: The chosen configuration (signs, (psi,)), psi in [-pi, pi); None if not ok.
        solution: The exact OM solution in it; None if not ok.
        margin: Smallest normalised joint-limit margin M(q) (nan if not ok).
        clearance: Clearance D(q) in metres (inf without obstacles, nan if not ok).
        value: The objective f(q) (nan if not ok).
        intervals: The feasible intervals searched: every allowed branch's, or, chosen
            afresh from the arm's joints, those of the branches swept (the previous one
            first); empty from the one-call tracking step
            (:mod:`~om_redundant.redundancy.choice.tracking`), which searches none.
        reason: Why nothing is feasible, or why tracking chose afresh; "" otherwise.
        branch_flipped: The choice left the previous choice's branch.
        curvature: The curvature (per rad^2) of the objective along psi that the next
            tracking step's model takes (:mod:`~om_redundant.redundancy.choice.tracking`); nan:
            its initial value.
        rechosen: Tracking could not continue from the previous choice, and this choice
            was made afresh from the arm's joints (``reason`` says why).
        travel: Joint travel (rad, Euclidean) from the arm's joints ``q_current`` (or the
            previous choice's) to ``solution.q``; nan from a global choice.
        way_clearance: Of a choice made afresh from the arm's joints: a lower bound of the
            clearance along the straight joint-space way from them to ``solution.q``
            (:meth:`~om_redundant.Clearance.minimum_along`), at least
            ``min(min_clearance, D(q_current))`` less 1 mm where the way is clear; inf
            without obstacles; nan otherwise (a tracking step moves the joints a step at a
            time, each step's joints clear).
        way_clear: The way is certified clear, or none was checked (``way_clearance`` nan).
        turn: With a free rotation (``choose(..., free=...)``), the turn R of the target the
            solution reaches, :meth:`FreeRotation.turned(T, R)
            <om_redundant.FreeRotation.turned>`; None without.
        pose: The end-effector pose the solution reaches (T, or T turned); None if not ok.
        clearance_version: The optimiser's :attr:`Clearance.version
            <om_redundant.Clearance.version>` the choice was weighed in: where the obstacles
            were (0 without a clearance).
    """

    ok: bool
    configuration: Configuration | None
    solution: Solution | None
    margin: float
    clearance: float
    value: float
    intervals: tuple[PsiInterval, ...]
    reason: str = ""
    branch_flipped: bool = False
    curvature: float = math.nan
    rechosen: bool = False
    travel: float = math.nan
    way_clearance: float = math.nan
    way_clear: bool = True
    turn: np.ndarray | None = None
    pose: np.ndarray | None = None
    clearance_version: int = 0


def failed_choice(intervals: tuple[PsiInterval, ...], reason: str) -> RedundancyChoice:
    """A choice that found nothing: ok False, why in ``reason``."""
    return RedundancyChoice(False, None, None, math.nan, math.nan, math.nan, intervals, reason)
