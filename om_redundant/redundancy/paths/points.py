r"""The points of a branch's solution paths: an exact solution at an arm angle, its tangent
dq/dpsi, and its objective terms, evaluated when first asked for or for many points in one
batch."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...ik.solver import Solution
from ..objective.objective import Objective
from ..objective.terms import Evaluation


class PointTerms:
    """The objective at a point, computed when first asked for (a path's following steps
    need only the joints and the tangent), or given by a batch (:func:`evaluate_points`):
    the clearance's pair distances and gradients (:meth:`Objective.pairs`), from
    which the groups' pieces with their rates, the evaluation and the feasibility functions. Shared
    by the copies of a point at other representatives of psi. (Slots, the arrays of a pair
    each in its own: the sweep keeps hundreds of terms per pose, and each container they
    hold would count towards the garbage collector's next pass.)

    Attributes:
        d, grad: The pairs' distances (P,) and gradients (P, dof), or None.
        g, dg: The feasibility functions and their rates, or None.
    """

    __slots__ = ("d", "dg", "evaluation", "g", "grad", "linear", "objective", "q", "tangent")

    def __init__(
        self,
        objective: Objective,
        q: np.ndarray,
        tangent: np.ndarray,
        evaluation: Evaluation | None = None,
        g: np.ndarray | None = None,
        dg: np.ndarray | None = None,
        d: np.ndarray | None = None,
        grad: np.ndarray | None = None,
    ):
        self.objective, self.q, self.tangent, self.evaluation = objective, q, tangent, evaluation
        self.g, self.dg, self.d, self.grad = g, dg, d, grad
        self.linear: tuple[np.ndarray, np.ndarray] | None = None

    def get_pairs(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The clearance's pair distances and gradients at q (:meth:`Objective.pairs`); None
        without obstacles."""
        if self.d is None:
            if self.objective.clearance is None:
                return None
            self.d, self.grad = self.objective.pairs(self.q)
        return self.d, self.grad

    def get_evaluation(self) -> Evaluation:
        """The objective at q."""
        if self.evaluation is None:
            pairs = self.get_pairs()
            self.evaluation = self.objective.evaluate(self.q, None if pairs is None else pairs[0])
        return self.evaluation

    def get_pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """The feasibility functions and their rates (:meth:`Point.pieces`)."""
        if self.g is None:
            self.g, self.dg = self.objective.pieces(self.q, self.tangent, self.get_pairs())
        return self.g, self.dg

    def get_linearised(self) -> tuple[np.ndarray, np.ndarray]:
        """The groups' pieces at q and their rates along psi (:meth:`Objective.linearised`)."""
        if self.linear is None:
            self.linear = self.objective.linearised(self.q, self.tangent, self.get_pairs())
        return self.linear


def evaluate_points(objective: Objective, points: list[Point]) -> None:
    """The objective at those of the points not yet evaluated, in one batch: their
    clearance's pair distances and gradients, their evaluations and their feasibility
    functions (what :attr:`Point.evaluation` and :meth:`Point.pieces` would compute point by
    point)."""
    terms = list(dict.fromkeys(p.terms for p in points if p.terms.evaluation is None))  # (distinct)
    if terms:
        q, tangents = np.array([t.q for t in terms]), np.array([t.tangent for t in terms])
        for t, ev, g, dg, d, grad in zip(terms, *evaluated_terms(objective, q, tangents), strict=True):
            t.evaluation, t.g, t.dg, t.d, t.grad = ev, g, dg, d, grad


def evaluated_terms(objective: Objective, q: np.ndarray, tangents: np.ndarray) -> tuple[list[Any], ...]:
    """The terms of the rows of q (M, dof) with tangents (M, dof, 1), one call each for all
    rows: the rows' evaluations, feasibility functions g and rates dg, pair distances d and
    gradients grad (None without obstacles), the arrays views of the batch's, in the order
    of :class:`PointTerms`' arguments."""
    pairs = objective.pairs(q)
    evaluations = objective.evaluations(q, None if pairs is None else pairs[0])
    g, dg = objective.pieces(q, tangents, pairs)
    d, grad = ([None] * len(q),) * 2 if pairs is None else pairs
    return evaluations, list(g), list(dg), list(d), list(grad)


@dataclass(eq=False, slots=True)
class Point:
    """An exact solution on a branch, its objective, and their rates along psi. (Not frozen,
    but never changed: a frozen dataclass is built several times slower, and the sweep builds
    hundreds of points per pose.)

    Attributes:
        psi: The redundancy value (rad); an (r,) array for r > 1 redundancy variables.
        q: The joints.
        tangent: dq/dpsi (dof, r).
        terms: The objective at q, evaluated when first asked for (:attr:`evaluation`,
            :attr:`linearised`).
        solution: The solver's Solution of it, when solved singly (its q may differ from
            ``q`` by turns of revolute joints); None for a batch sample.
    """

    psi: float | np.ndarray
    q: np.ndarray
    tangent: np.ndarray
    terms: PointTerms
    solution: Solution | None = None

    def at(self, psi: float | np.ndarray) -> Point:
        """The same solution at another representative of psi (itself at the same psi)."""
        same = isinstance(psi, float) and psi == self.psi
        return self if same else Point(psi, self.q, self.tangent, self.terms, self.solution)

    @property
    def evaluation(self) -> Evaluation:
        """The objective at q."""
        evaluation = self.terms.evaluation  # (read often: the call only when not yet computed)
        return self.terms.get_evaluation() if evaluation is None else evaluation

    @property
    def linearised(self) -> tuple[np.ndarray, np.ndarray]:
        """The objective's groups' pieces at q and their rates along psi (a one-variable
        psi; :meth:`Objective.linearised`)."""
        return self.terms.get_linearised()

    def pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """The feasibility functions g_j (all >= 0 iff feasible;
        :meth:`Objective.pieces <om_redundant.redundancy.objective.objective.Objective.pieces>`)
        and dg_j/dpsi."""
        return self.terms.get_pieces()
