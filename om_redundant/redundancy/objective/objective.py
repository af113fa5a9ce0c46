r"""What the redundancy optimiser maximises: joint-limit margin, obstacle clearance and
distance from singularities.

Joint-limit margin of joint i (limited joints only), normalised by half its range
:math:`h_i = (u_i - l_i)/2`:

.. math::  m_i(q) = \min(q_i - l_i,\ u_i - q_i) / h_i,

1 at mid-range, 0 on a limit, negative beyond it; :math:`M(q) = \min_i m_i(q)`. (The
optimiser takes each revolute joint at its turn nearest mid-range, which has the most
margin; :mod:`om_redundant.redundancy.paths.linking`.) Each
:math:`m_i` is the minimum of two functions affine in q, :math:`(q_i - l_i)/h_i` and
:math:`(u_i - q_i)/h_i`, so M is the minimum of ``2 * limited`` affine pieces.

Clearance :math:`D(q) = \min_k d_k(q)` (:mod:`om_redundant.redundancy.objective.clearance`), capped at
:math:`d_{cap}` and normalised by it.

Singularity distance :math:`S(q) = \min_k s_k(q)`, :math:`s_k = |\sin x_k|` for the model's
wrist, elbow and shoulder angles :math:`x_k` (:mod:`om_redundant.redundancy.objective.singularity`),
capped at :data:`SINGULARITY_CAP` :math:`= s_{cap}` and normalised by it.

The objective, maximised over the redundancy variables, with weights :math:`w_m, w_c, w_s \ge 0`:

.. math::  f(q) = w_m\, M(q) + w_c \min\big(1,\ D(q)/d_{cap}\big) + w_s \min\big(1,\ S(q)/s_{cap}\big),

and q is feasible when it is within the limits and clear: :math:`M(q) \ge 0` and
:math:`D(q) \ge d_{min}`. The terms are dimensionless in [0, 1] on the feasible set, so the
weights trade them directly: with the defaults, 1 cm of clearance below the cap of 0.1 m is
worth 0.1 of normalised margin. Capping the clearance stops far obstacles from pulling the
arm away from mid-range. The singularity term is no constraint (every S >= 0 is
feasible): it moves the optimum off a singular wrist, elbow or shoulder where that costs
less margin and clearance than it gains, and beyond 30 degrees from every singularity
(:math:`S \ge s_{cap} = \sin 30^\circ`) it earns nothing more.

Each term is a *group*: a weight w, a floor (the feasibility bound: 0 for M,
:math:`d_{min}/d_{cap}` for the clearance, none for S), a cap (none for M, 1 for the
clearance and S), and pieces :math:`v_j(q)` whose minimum it takes. The QP linearises every piece
(:func:`~om_redundant.redundancy.choice.climb.maximise`).
"""

from __future__ import annotations

import math
import threading
from typing import NamedTuple

import numpy as np

from ... import _core
from ...exceptions import InvalidInput
from ...kinematics.arm import Arm
from ...validation import as_instance, as_joint_vector
from .clearance import Clearance
from .singularity import Singularity
from .terms import (
    DEFAULT_CLEARANCE_WEIGHT,
    DEFAULT_MARGIN_WEIGHT,
    DEFAULT_SINGULARITY_WEIGHT,
    SINGULARITY_CAP,
    Evaluation,
    check_weights,
    evaluation_of_row,
    limit_distances,
)


class GroupLayout(NamedTuple):
    """The objective's groups (module docstring) as the climb's QP reads their concatenated pieces
    (:meth:`Objective.linearised`; ``_core.Pieces``' other fields).

    Attributes:
        ends: (G + 1,) int64: group g's pieces are ``ends[g]`` to ``ends[g + 1] - 1``.
        weights, floors, caps: (G,) per group.
    """

    ends: np.ndarray
    weights: np.ndarray
    floors: np.ndarray
    caps: np.ndarray


class Objective:
    """The objective f and the feasibility test of the module docstring.

    Args:
        arm: The arm.
        clearance: Obstacle distances, or None for no obstacles.
        singularity: The model's singularities (``Singularity.of(solver.model_arm)``), or None for
            no singularity term.
        margin_weight: w_m >= 0.
        clearance_weight: w_c >= 0 (ignored without obstacles).
        singularity_weight: w_s >= 0 (ignored without ``singularity``).
        clearance_cap: d_cap > 0 (m): clearance beyond it earns nothing more.
        min_clearance: d_min (m), 0 <= d_min < d_cap: the clearance every choice must keep.

    Attributes:
        layout: Its groups' sizes, weights, floors and caps (:class:`GroupLayout`).
    """

    def __init__(
        self,
        arm: Arm,
        clearance: Clearance | None = None,
        singularity: Singularity | None = None,
        *,
        margin_weight: float = DEFAULT_MARGIN_WEIGHT,
        clearance_weight: float = DEFAULT_CLEARANCE_WEIGHT,
        singularity_weight: float = DEFAULT_SINGULARITY_WEIGHT,
        clearance_cap: float = 0.1,
        min_clearance: float = 0.0,
    ):
        as_instance(arm, Arm, "arm")
        check_weights(margin_weight, clearance_weight, clearance_cap, min_clearance, singularity_weight)
        if singularity is not None and as_instance(singularity, Singularity, "singularity").dof != arm.dof:
            raise InvalidInput(f"the singularity's arm has {singularity.dof} joints, the arm {arm.dof}")
        if clearance is not None and clearance.distmax < clearance_cap:
            raise InvalidInput(
                f"the clearance's distmax ({clearance.distmax} m) is below clearance_cap ({clearance_cap} m)"
            )
        self.arm, self.clearance, self._dof = arm, clearance, arm.dof
        self.singularity = singularity
        self.margin_weight, self.clearance_weight = float(margin_weight), float(clearance_weight)
        self.singularity_weight = float(singularity_weight)
        self.clearance_cap, self.min_clearance = float(clearance_cap), float(min_clearance)
        #: Twice d_cap (m), the distance beyond which a pair changes neither the capped term nor the
        #: slack's minimum.
        self.clearance_reach = 2.0 * self.clearance_cap
        self._limited = np.flatnonzero(np.isfinite(arm.lower) & np.isfinite(arm.upper))
        self._lower, self._upper = arm.lower[self._limited], arm.upper[self._limited]
        self._half = (self._upper - self._lower) / 2.0
        none = (np.zeros(0, dtype=np.int64), np.zeros(0))
        joints, offsets = none if singularity is None else singularity.rows()
        # what _core.pieces reads: 2 d_cap, d_cap, d_min / d_cap
        self._clearance_numbers = np.array(
            [self.clearance_reach, self.clearance_cap, self.min_clearance / self.clearance_cap]
        )
        self._no_distances = np.zeros(0)  # _core.evaluate's without obstacles
        self._scratch = threading.local()  # each thread's record of one row for _core.evaluate
        # what _core.pieces reads of the limits, and _core.evaluate of every term
        # (csrc/redundancy/objective.c)
        self._piece_limits = _core.PieceLimits(self._limited, self._lower, self._upper, self._half)
        self._terms = _core.ObjectiveTerms(
            self._dof,
            self._limited,
            self._lower,
            self._upper,
            self._half,
            joints,
            offsets,
            margin_weight=self.margin_weight,
            clearance_weight=self.clearance_weight,
            singularity_weight=self.singularity_weight,
            clearance_cap=self.clearance_cap,
            min_clearance=self.min_clearance,
            singularity_cap=SINGULARITY_CAP,
        )
        sizes, numbers = [], []  # the groups (module docstring): their pieces, weights, floors, caps
        if len(self._limited):
            sizes.append(2 * len(self._limited)), numbers.append((self.margin_weight, 0.0, math.inf))
        if clearance is not None:
            floor = self.min_clearance / self.clearance_cap
            sizes.append(len(clearance.pairs)), numbers.append((self.clearance_weight, floor, 1.0))
        if singularity is not None:
            sizes.append(len(joints)), numbers.append((self.singularity_weight, -math.inf, 1.0))
        weights, floors, caps = np.array(numbers, dtype=float).reshape(-1, 3).T.copy()
        self.layout = GroupLayout(np.cumsum([0, *sizes], dtype=np.int64), weights, floors, caps)
        self._no_pairs = np.zeros((0,)), np.zeros((0, self._dof))

    def linearised(
        self, q: np.ndarray, tangent: np.ndarray, pairs: tuple[np.ndarray, np.ndarray] | None
    ) -> tuple[np.ndarray, np.ndarray]:
        """The pieces v_j of the groups (module docstring) at q, concatenated in the groups'
        order (:attr:`layout`), and their rates dv_j/dpsi along the tangent: what the climb's
        QP linearises (``_core.linearise``, ``csrc/redundancy/objective.c``;
        ``tests/reference/objective.py`` builds the groups in numpy, the same numbers to
        rounding). The margin's pieces are the limited joints' (q_i - l_i)/h_i, then their
        (u_i - q_i)/h_i; the clearance's the pairs' d_k/d_cap, those at 2 d_cap or farther
        taken there with rate 0 where some pair is nearer; the singularity's s_k/s_cap.

        Args:
            q: (dof,) joint vector.
            tangent: (dof, 1) dq/dpsi at q.
            pairs: The pairs' distances (P,) and gradients (P, dof) at q (:meth:`pairs`); None
                without obstacles.

        Returns:
            (n,) values and (n,) rates, n = ``layout.ends[-1]``.
        """
        d, grad = self._no_pairs if pairs is None else pairs
        values, rates = np.empty((2, int(self.layout.ends[-1])))
        rows = _core.PieceRows(q, tangent[:, 0], d, grad)
        _core.linearise(self._terms, rows, values, rates)
        return values, rates

    def pairs(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The clearance's pair distances at q and the gradients that :meth:`pieces` and
        :meth:`linearised` read: those of the pairs within :attr:`clearance_reach` where one
        is, else all (:meth:`Clearance.distances_and_gradients
        <om_redundant.Clearance.distances_and_gradients>` with ``near``); None without
        obstacles. (Distances capped at the reach where a pair is within it would skip the far
        pairs, but a row with none near would then be computed twice: 1.2x faster where every
        row has a pair near, 1.5x slower where a fifth has.)

        Args:
            q: (dof,) joint vector, or (M, dof) rows.

        Returns:
            (P,) distances and (P, dof) gradients, or (M, P) and (M, P, dof); or None.
        """
        if self.clearance is None:
            return None
        return self.clearance.distances_and_gradients(q, near=self.clearance_reach)

    def evaluate(self, q: np.ndarray, distances: np.ndarray | None = None) -> Evaluation:
        """f(q), M(q), D(q), the feasibility slack and S(q): each group's minimum
        (the smallest of its pieces, module docstring) capped and weighted, summed in the
        groups' order (``_core.evaluate``, ``csrc/redundancy/objective.c``).

        Args:
            q: (dof,) joint vector.
            distances: (P,) the clearance's pair distances at q if already computed.
        """
        q = as_joint_vector(q, self._dof, stack=False)
        scratch = self._scratch
        try:
            row, record = scratch.row, scratch.record
        except AttributeError:  # (the thread's first: its out record, each field a slice of one row)
            row = scratch.row = np.empty(len(_core.Evaluations._fields))
            record = scratch.record = _core.Evaluations(*(row[k : k + 1] for k in range(len(row))))
        _core.evaluate(self._terms, q, self._distances(q, distances), record)
        return Evaluation(*row.tolist())

    def evaluations(self, q: np.ndarray, distances: np.ndarray | None = None) -> list[Evaluation]:
        """:meth:`evaluate` at every row of q (M, dof), in one call.

        Args:
            q: (M, dof) joint vectors.
            distances: (M, P) the rows' pair distances if already computed (with obstacles).
        """
        q = as_joint_vector(q, self._dof).reshape(-1, self._dof)
        out = np.empty((len(_core.Evaluations._fields), len(q)))  # (a field's values in each row)
        _core.evaluate(self._terms, q, self._distances(q, distances), _core.Evaluations(*out))
        return list(map(evaluation_of_row, out.T.tolist()))

    def _distances(self, q: np.ndarray, distances: np.ndarray | None) -> np.ndarray:
        """What ``_core.evaluate`` reads of the pairs' distances at q: those given, else computed
        (none without obstacles)."""
        if self.clearance is None:
            return self._no_distances
        if distances is None:
            distances = self.clearance.distances(q)
        return np.ascontiguousarray(distances, dtype=float)

    def pieces(
        self, q: np.ndarray, tangent: np.ndarray, pairs: tuple[np.ndarray, np.ndarray] | None
    ) -> tuple[np.ndarray, np.ndarray]:
        """The feasibility functions g_j at q (>= 0 iff feasible) and dg_j/dpsi along the
        tangent: each limited joint's margin, the smaller of its two pieces (continuous also
        where a revolute joint is taken modulo 2 pi nearest mid-range), then each pair's
        d_k/d_cap - d_min/d_cap (``_core.pieces``, ``csrc/redundancy/cells.c``; the numpy
        groups' of ``tests/reference/objective.py`` to rounding), at one joint vector or at
        every row of q in one call.

        Args:
            q: (dof,) joint vector, or (M, dof) rows.
            tangent: (dof, 1) dq/dpsi at q, or (M, dof, 1).
            pairs: The pairs' distances (P,) and gradients (P, dof) at q, or (M, P) and
                (M, P, dof); None without obstacles.

        Returns:
            (g, dg), each (limited + P,), or (M, limited + P).
        """
        rows = q.shape[:-1]
        if pairs is None:
            pairs = np.zeros((*rows, 0)), np.zeros((*rows, 0, self._dof))
        distances, gradients = np.ascontiguousarray(pairs[0], float), np.ascontiguousarray(pairs[1], float)
        g, dg = np.empty((2, *rows, len(self._limited) + distances.shape[-1]))
        q, rate = np.ascontiguousarray(q, float), np.ascontiguousarray(tangent[..., 0], float)
        sampled = _core.PieceRows(q, rate, distances, gradients)
        _core.pieces(self._dof, sampled, self._piece_limits, self._clearance_numbers, g, dg)
        return g, dg

    def term_functions(
        self, q: np.ndarray, distances: np.ndarray | None
    ) -> list[tuple[float, float, np.ndarray]]:
        """The objective at the rows of q as ``f = sum_g w_g min(cap_g, min_j values_j)``:
        per group its weight, its cap and its functions at every row. The margin's are the
        limited joints' margins m_i, the clearance's the pairs' distances d_k / d_cap, the
        singularity's the distances s_k / s_cap. For bounds of f from bounds of each
        function (the climbs' starts, :meth:`~om_redundant.RedundancyOptimizer.choose`).

        Args:
            q: (M, dof) joint vectors.
            distances: (M, P) the pairs' distances d_k(q) (m) (None without obstacles).

        Returns:
            [(w_g, cap_g, (M, p_g) values)] in the groups' order (:attr:`layout`).
        """
        groups = []
        if len(self._limited):
            groups.append((self.margin_weight, math.inf, self._margins(q)))
        if self.clearance is not None:
            groups.append((self.clearance_weight, 1.0, distances / self.clearance_cap))
        if self.singularity is not None:
            singular = self.singularity.distances(q) / SINGULARITY_CAP
            groups.append((self.singularity_weight, 1.0, singular))
        return groups

    def _margins(self, q: np.ndarray) -> np.ndarray:
        """The limited joints' margins m_i at the rows of q (M, dof): (M, limited)."""
        return np.minimum(*limit_distances(q[:, self._limited], self._lower, self._upper, self._half))
