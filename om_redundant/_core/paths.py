"""The records the solution-path kernels read and write by field name: a branch's path
followed along psi and linked through its grid roots, and the cell test of the paths."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from . import Solver


class FollowWork(NamedTuple):
    """The arrays ``follow`` reads and writes, set up once per
    :class:`~om_redundant.redundancy.paths.probe.Probe` (``link_paths`` reads the branch's: all but
    ``q`` and ``t``).

    Attributes:
        kernel: The compiled solver.
        T: (4, 4) the pose.
        signs: The branch signs (int64).
        cyclic: (7,) joints compared modulo 2 pi (uint8).
        centred: (7,) joints taken at the turn nearest mid-range (uint8).
        centre: (7,) the mid-ranges (0 where not centred).
        q, t: (7,) the start's joints and tangent on entry, the point reached's on return.
        traces: The pose's self-motion a batch of the kernel traced (``torus_traces``; the
            batch's ``SolveAllBatch.traces``), which the scans for a root nearer a step's
            start start from; None: none (a scan then samples its window).
    """

    kernel: Solver
    T: np.ndarray
    signs: np.ndarray
    cyclic: np.ndarray
    centred: np.ndarray
    centre: np.ndarray
    q: np.ndarray
    t: np.ndarray
    traces: object | None = None


class LinkRoots(NamedTuple):
    """A branch's roots at the grid psi that ``link_paths`` links into paths.

    Attributes:
        psi: (n,) the grid, increasing within a turn.
        counts: (n,) the roots at each grid psi (int64), M in all.
        q, t: (M, 7) the roots' joints and tangents, grid psi by grid psi.
    """

    psi: np.ndarray
    counts: np.ndarray
    q: np.ndarray
    t: np.ndarray


class LinkRows(NamedTuple):
    """Where ``link_paths`` writes the paths it links: the R rows that following adds (rows
    M, M + 1, ... after the M roots) and each path's rows.

    Attributes:
        psi: (R,) the added rows' psi.
        q, t: (R, 7) their joints and tangents.
        members: (M + R, 2) int64: the paths' rows in order, path after path, each with the
            turns of psi it is taken at.
        paths: (M + R, 2) int64: per path, where its members end and its turns (a loop's, else 0).
    """

    psi: np.ndarray
    q: np.ndarray
    t: np.ndarray
    members: np.ndarray
    paths: np.ndarray


class CellModels(NamedTuple):
    """The cubic Hermite models of a cell's n feasibility functions between its ends a and b,
    over a parameter s of the cell, 0 at a and 1 at b (``surprise``, ``crossing``).

    Attributes:
        ga, da: (n,) the functions and their rates along psi at a.
        gb, db: (n,) the same at b.
        span_a, span_b: dpsi/ds at a and b: both psi_b - psi_a for models in psi; along the
            cell's chord, ``cell_spans``'.
        hermite: (4, N) the Hermite basis at the cell's N points.
    """

    ga: np.ndarray
    da: np.ndarray
    gb: np.ndarray
    db: np.ndarray
    span_a: float
    span_b: float
    hermite: np.ndarray


class CellSamples(NamedTuple):
    """The M samples of P paths, path after path, whose cells ``cell_looks`` tests.

    Attributes:
        q: M joint vectors (float64, dof entries each).
        tangent: M tangents dq/dpsi (float64, dof entries each).
        psi: M floats.
        pieces: M pairs (g, dg) of float64 arrays (n,): the feasibility functions and rates.
        feasible: M bools.
        bounds: (P + 1,) int64: each path's first sample, then M.
        cyclic: (P, dof) bool: each path's joints compared modulo 2 pi.
    """

    q: Sequence[np.ndarray]
    tangent: Sequence[np.ndarray]
    psi: Sequence[float]
    pieces: Sequence[tuple[np.ndarray, np.ndarray]]
    feasible: Sequence[bool]
    bounds: np.ndarray
    cyclic: np.ndarray


class PieceRows(NamedTuple):
    """The M joint vectors at which ``pieces`` computes the feasibility functions, and
    ``linearise`` the objective's pieces with their rates.

    Attributes:
        q: (M, dof) the joints.
        t: (M, dof) dq/dpsi there.
        distances: (M, P) the clearance pairs' distances.
        gradients: (M, P, dof) their gradients.
    """

    q: np.ndarray
    t: np.ndarray
    distances: np.ndarray
    gradients: np.ndarray


class PieceLimits(NamedTuple):
    """The L limited joints of an arm, as ``pieces`` reads them.

    Attributes:
        limited: (L,) their indices (int64).
        lower, upper: (L,) their limits.
        half: (L,) half their ranges.
    """

    limited: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    half: np.ndarray
