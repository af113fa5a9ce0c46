r"""The QP in one redundancy variable, of the climb (:mod:`om_redundant.redundancy.choice.climb`) and
of the tracking step, solved exactly.

With one variable the epigraph QP is the maximisation of the concave, piecewise quadratic

.. math::  \phi(\delta) = \sum_g w_g \min\big(cap_g,\ \min_{j \in g} v_j + a_j\delta\big)
           - \tfrac12 b\,\delta^2

over the interval where every group with a floor keeps :math:`\min_j v_j + a_j\delta \ge
floor_g`, within the box [lower, upper]. phi is strictly concave (b > 0): its right
derivative, :math:`-b\delta` plus each uncapped group's weight times its least piece's rate,
falls through zero once, at the maximiser (a kink or a stationary point), which bisection on
its sign finds to rounding (``_core.step_1d``, ``csrc/redundancy/box_qp.c``, reading only the pieces that
can be their group's least in the box; ``tests/reference/box_qp.py`` solves it by the
breakpoints instead, the tests' oracle). The multipliers of the pieces are those of the
epigraph's KKT conditions: each uncapped group's weight on its least piece, or at a kink split
between the least and the most increasing of the pieces that meet there so that the slope
balances :math:`b\delta`.
"""

from __future__ import annotations

import numpy as np

from ... import _core
from ..paths.points import Point


class Pieces(_core.Pieces):
    """Groups of one variable concatenated, as ``_core.step_1d`` reads them (``_core.Pieces``:
    values, rates, ends, weights, floors, caps; group g's pieces are ``ends[g]`` to
    ``ends[g + 1] - 1``, each group has at least one)."""

    __slots__ = ()

    @classmethod
    def at(cls, point: Point) -> Pieces:
        """The pieces of the objective's groups at a point and their rates along psi
        (:attr:`Point.linearised <om_redundant.redundancy.paths.points.Point.linearised>`)."""
        return cls(*point.linearised, *point.terms.objective.layout)


def step_1d(
    pieces: Pieces, curvature: float, lower: float, upper: float
) -> tuple[float, float, np.ndarray] | None:
    r"""The climb's QP step in one variable, maximised as in the module docstring
    (``_core.step_1d``, ``csrc/redundancy/box_qp.c``).

    Args:
        pieces: The groups' pieces.
        curvature: b > 0.
        lower, upper: Bounds of delta, lower <= 0 <= upper.

    Returns:
        (delta, the model's gain ``model(delta) - b delta^2 / 2 - model(0)``, every piece's
        multiplier (n,), 0 for those that cannot be their group's least in the box), or None
        when the floors leave no delta.

    Raises:
        ValueError: A piece, the curvature or a bound is not a number (or b <= 0, lower > upper).
    """
    z = np.empty(len(pieces.values))
    found = _core.step_1d(pieces, curvature, lower, upper, z)
    return None if found is None else (found.delta, found.gain, z)
