r"""Solution paths of a branch: the exact solutions of one pose and one set of branch signs,
followed continuously in the arm angle psi.

One (signs, psi) can have several exact solutions (2-4 near a singular wrist or a straight
elbow), so the solutions of a branch are organised as *paths*:

* **Following.** From a solution, the next one is the solution nearest it (``q_hint``),
  accepted when it continues the path (no joint moves more than :data:`~.probe.JUMP`, and
  the joints move as the path's tangent predicts to first order,
  :math:`|\Delta q - (dq/d\psi)\,\Delta\psi|_\infty \le \frac12 |\Delta q|_\infty`; a
  solution on another path, however near, is off by the paths' separation, which no shorter
  step of psi shrinks); a step that fails is
  halved (near a singular shoulder or wrist two joints turn fast), and doubled again after
  a success (:meth:`Probe.follow`). Below :data:`END_TOLERANCE` the path has *ended*:
  it folded back in psi (meeting a second path there), or left the branch or the reach.
  For the feasible intervals, revolute joints are compared modulo 2 pi and each solution is
  taken at the representative nearest mid-range (the solver's within-limits one, if any):
  feasibility is that of the arm's pose, not of one unwrapped joint vector. Tracking
  compares the joints as they are (the path the joints can move along).
* **Sweep** (:func:`sweep_circle`). Every solution of the branch at each psi of a grid
  (:meth:`~om_redundant.OMSolver.solve_all`; an offset model, ``dp_max > 0``, can have
  several per psi) comes from one parallel batch (:meth:`~om_redundant.OMSolver.solve_grid`;
  on an arm with shoulder offsets its rows trace the pose's self-motion, which it keeps for
  the follows after it: :meth:`Probe.use_traces`).
  Each solution is followed to the next grid psi and linked to the
  solution it arrives at; solutions not arrived at start new paths, followed backwards to
  where they end; paths are joined across +-pi, and close into loops (one
  ``_core.link_paths`` call per branch, :meth:`Probe.link`). The linked paths depend on the
  pose and the branch alone, not on the obstacles: a sweep of the same pose again (a target
  held while the obstacles move) takes them as they were linked, and the traced self-motion
  (a :class:`LinkedMemo`), its points' objective evaluated afresh, and does only what follows.
* **Cells.** Between neighbouring samples of a path where a joint moves more than
  :data:`FINE_STEP`, samples are inserted. Every sample carries its feasibility functions
  :math:`g_j` (each joint's margin, each clearance minus d_min, normalised; feasible iff all
  :math:`g_j \ge 0`) and their rates :math:`dg_j/d\psi` (through dq/dpsi); between
  neighbours each :math:`g_j` is modelled by the cubic Hermite interpolant of those values
  and rates along the cell's chord (the joints moving at the chord's length at both ends:
  ``_core.cell_spans``; to first order the models in psi where the path is smooth in psi,
  and smooth at a fold too, where a model in psi takes the end's rate, about 1e4-1e10, as a
  cubic's slope and sees a dip in every cell that ends there), and where the models predict
  a feasible island or an infeasible dip that the two samples do not show (two limits
  pinching, a joint turning through a limit), an exact sample is inserted there, and the
  cell is checked again.
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from collections.abc import Generator
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from ... import _core
from ...angles import TURN
from ...ik.threads import run_rows
from ..objective.objective import Objective
from .points import Point, PointTerms, evaluate_points
from .probe import END_TOLERANCE, SAME, Probe

FINE_STEP = 0.25  # rad: cells in which a joint moves further get samples in between
_MODEL_POINTS = 256  # points of a cell where the Hermite models are checked
_MAX_INSERTED = 64  # exact samples inserted per cell
_T = np.arange(1, _MODEL_POINTS + 1) / (_MODEL_POINTS + 1)
_HERMITE = np.array(
    [2 * _T**3 - 3 * _T**2 + 1, _T**3 - 2 * _T**2 + _T, -2 * _T**3 + 3 * _T**2, _T**3 - _T**2]
)
_BOUND_SLACK = 1e-9  # covers the rounding of the Hermite models in cell_looks' bounds
#: Sweeps whose linked paths a :class:`LinkedMemo` keeps: a fresh choice's (each turn of a
#: free rotation, the quick look and the sweep of every branch).
MEMO_SWEEPS = 16

#: What a process of :func:`lockstep` asks for: follow from the point towards psi on the
#: probe's branch (:meth:`Probe.follow`).
Follow = tuple[Probe, Point, float]


@dataclass(eq=False)
class Path:
    """One solution path of a branch, its samples in increasing psi (unwrapped).

    Attributes:
        points: The samples.
        turns: For a loop, the number of turns of psi after which it closes; 0 if it does
            not close: then its first and last samples are where it ends (to
            :data:`END_TOLERANCE`) or the edges of the swept window.
    """

    points: list[Point]
    turns: int = 0


class Kept:
    """A linked path as a :class:`LinkedMemo` keeps it: its samples' psi, joints, tangents
    and solutions, without their objective (hundreds of terms per sweep, evaluated where the
    obstacles were then)."""

    __slots__ = ("samples", "turns")

    def __init__(self, path: Path):
        self.samples = [(p.psi, p.q, p.tangent, p.solution) for p in path.points]
        self.turns = path.turns

    def unevaluated(self, objective: Objective) -> Path:
        """The path again, its points' objective computed when asked for."""
        points = [
            Point(psi, q, t, PointTerms(objective, q, t), solution) for psi, q, t, solution in self.samples
        ]
        return Path(points, self.turns)


class KeptSweep(NamedTuple):
    """A sweep as a :class:`LinkedMemo` keeps it.

    Attributes:
        paths: Each branch's linked paths.
        traces: The self-motion its grid's rows traced (``_core.torus_traces``; None: none),
            which the follows of a sweep of the pose again take too.
    """

    paths: list[list[Kept]]
    traces: object | None


class LinkedMemo:
    """The linked paths of the last :data:`MEMO_SWEEPS` sweeps (:func:`sweep_circle`), by
    pose, branches, grid and ``quick``: what a sweep of the same pose again takes instead of
    solving and linking. Shared by threads."""

    def __init__(self) -> None:
        self._entries: OrderedDict[tuple[Any, ...], KeptSweep] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: tuple[Any, ...]) -> KeptSweep | None:
        with self._lock:
            linked = self._entries.get(key)
            if linked is not None:
                self._entries.move_to_end(key)
            return linked

    def put(self, key: tuple[Any, ...], linked: KeptSweep) -> None:
        with self._lock:
            self._entries[key] = linked
            self._entries.move_to_end(key)
            while len(self._entries) > MEMO_SWEEPS:
                self._entries.popitem(last=False)


def sweep_circle(
    probes: list[Probe], n: int, quick: bool = False, memo: LinkedMemo | None = None
) -> list[list[Path]]:
    """The solution paths of each probe's branch over the whole circle, from the grid
    psi_k = -pi + 2 pi k / n (module docstring). The probes share one solver, objective and
    pose, and each follows its own branch's paths here and after (a probe keeps no state
    between its answers). ``quick``: no grid row searches beyond its configuration's own roots
    (:meth:`~om_redundant.OMSolver.solve_grid`'s band, as where every neighbouring branch is
    swept too), for a first look at a branch alone; its "no" rows are then the cheap ones.
    ``memo``: where the linked paths of a sweep of the same pose, branches, n and ``quick``
    are kept and taken from (the objective evaluated afresh: the obstacles may have moved).

    Returns:
        Each branch's paths, with the samples inserted where a cell hides a feature.
    """
    key = (probes[0].T.tobytes(), tuple(probe.signs for probe in probes), n, quick)
    kept = None if memo is None else memo.get(key)
    # (new traces: filled by _linked's batch; None: an arm whose searches trace none)
    traces = _core.torus_traces(probes[0].solver.kernel) if kept is None else kept.traces
    for probe in probes:
        probe.use_traces(traces)
    if kept is None:
        linked = _linked(probes, n, quick, traces)
        if memo is not None:  # (the solutions alone: a sweep evaluates its points where the obstacles are)
            memo.put(key, KeptSweep([[Kept(path) for path in paths] for paths in linked], traces))
    else:
        linked = [[path.unevaluated(probes[0].objective) for path in paths] for paths in kept.paths]
    swept = [[(probe, path) for path in paths] for probe, paths in zip(probes, linked, strict=True)]
    filled = iter(_with_hidden([path for paths in swept for path in paths]))  # (every branch's at once)
    return [[next(filled) for _ in paths] for paths in swept]


def _linked(probes: list[Probe], n: int, quick: bool, traces: object | None) -> list[list[Path]]:
    """Each probe's branch's linked paths (:func:`sweep_circle`, before the looks inside the
    cells); the self-motion the grid's rows trace kept in ``traces`` (``_core.torus_traces``),
    which the probes' follows use from then on (:meth:`Probe.use_traces`)."""
    solver, T, branches = probes[0].solver, probes[0].T, [probe.signs for probe in probes]
    psi = -math.pi + TURN * np.arange(n) / n
    # Rows by ELBOW sign, then psi by psi, the branches that differ in the first sign alone next
    # to each other: the solver shares a search of one psi where it is the same (S-R-S: across
    # the SHOULDER sign; on the torus the WRIST sign too), and the parts of its samples that do
    # not depend on psi across the rows of one ELBOW sign (its memos).
    order = sorted(range(len(branches)), key=lambda b: (branches[b][1:], branches[b][0]))
    rows = np.empty((len(branches), n), dtype=int)  # the batch row of each branch and grid psi
    first = chunk = 0  # chunk: a group's rows, a thread's (they share the traced self-motion)
    for elbow in sorted({branches[b][1] for b in order}):
        group = [b for b in order if branches[b][1] == elbow]
        rows[group] = first + np.arange(n * len(group)).reshape(n, len(group)).T
        first += n * len(group)
        chunk = max(chunk, n * len(group))
    signs, band = np.empty((first, len(branches[0])), dtype=int), np.empty(first, dtype=bool)
    for b, signs_b in enumerate(branches):
        signs[rows[b]] = signs_b
        band[rows[b]] = not quick and not _neighbours_swept(signs_b, branches, n)
    grid_psi = np.empty(first)
    grid_psi[rows] = psi
    poses = np.repeat(T[None], first, axis=0)
    batch = solver.solve_grid(poses, signs, grid_psi, band, chunk=chunk, traces=traces)
    # every branch's distinct roots, their points in one batch (a point is the same on any branch)
    found = [_distinct(probe, batch.q[rows[b]], batch.count[rows[b]]) for b, probe in enumerate(probes)]
    grid = np.concatenate([k for k, _ in found])
    branch = np.repeat(np.arange(len(probes)), [len(k) for k, _ in found])
    points = probes[0].points(psi[grid], np.concatenate([q for _, q in found]))
    roots: list[list[list[Point]]] = [[[] for _ in range(n)] for _ in probes]
    for b, k, point in zip(branch.tolist(), grid.tolist(), points, strict=True):
        if point is not None:
            roots[b][k].append(point)
    linked: list[list[Path]] = [[] for _ in probes]

    def link(start: int, stop: int) -> None:  # (each branch's link_paths call releases the GIL)
        for b in range(start, stop):
            linked[b] = [Path(points, turns) for points, turns in probes[b].link(psi, roots[b])]

    run_rows(link, len(probes), chunk=1)
    return linked


def _distinct(probe: Probe, q: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct solutions of the grid rows q (n, roots, dof), count[k] of them in row k:
    their grid indices, in order, and their joints. Solutions within SAME of an earlier one
    of the row are that one; only rows with several solutions need the test."""
    sizes = np.minimum(count, 1)
    found = {}
    for k in np.flatnonzero(count > 1).tolist():
        found[k] = []
        for row in q[k, : count[k]]:
            if all(probe.step(row, f) > SAME for f in found[k]):
                found[k].append(row)
        sizes[k] = len(found[k])
    grid = np.repeat(np.arange(len(count)), sizes)
    distinct = q[grid, 0]
    starts = np.cumsum(sizes) - sizes
    for k, rows in found.items():
        distinct[starts[k] : starts[k] + sizes[k]] = rows
    return grid, distinct


def _neighbours_swept(signs: tuple[int, ...], branches: list[tuple[int, ...]], n: int) -> bool:
    """Whether the grid holds, at each of its psi, every configuration one branch away from
    ``signs`` (each sign flipped in turn) at the psi where the solutions within BRANCH_BAND
    of their common boundary are its own: the same psi, and psi + pi across the S-R-S elbow,
    whose flip turns psi's reference (a grid psi when n is even). Then a grid row of
    ``signs`` need not search the band (:meth:`~om_redundant.OMSolver.solve_grid`): a
    neighbour's roots there are that neighbour's row's, the same joints and objective."""
    flips = (tuple(-s if j == i else s for j, s in enumerate(signs)) for i in range(len(signs)))
    return n % 2 == 0 and all(f in branches for f in flips)


def lockstep(processes: list[Generator[Follow, tuple[Point, bool], Any]]) -> list[Any]:
    """Run processes that each follow their paths one step after another (the refinement
    of an interval's end, the look inside a cell), all at once: each round follows every
    process's request (:data:`Follow`), evaluates the objective at all the points reached
    in one batch (:func:`~om_redundant.redundancy.paths.points.evaluate_points`) and sends each
    process its answer, ``probe.follow``'s (point reached, arrived). Each process makes the
    same follows as it would alone; the objective is evaluated in batches instead of point
    by point. The processes' probes share one objective.

    Returns:
        Each process's return value, in order.
    """
    results: list[Any] = [None] * len(processes)
    going = list(range(len(processes)))  # the processes going on, in order, and their answers
    answers: list[tuple[Point, bool] | None] = [None] * len(processes)
    while going:
        asked: list[tuple[int, Follow]] = []
        for i, answer in zip(going, answers, strict=True):
            try:
                asked.append((i, processes[i].send(answer)))
            except StopIteration as done:
                results[i] = done.value
        answers = [probe.follow(start, psi) for _, (probe, start, psi) in asked]
        if asked:
            evaluate_points(asked[0][1][0].objective, [point for point, _ in answers])
        going = [i for i, _ in asked]
    return results


def _with_hidden(paths: list[tuple[Probe, Path]]) -> list[Path]:
    """The paths with exact samples inserted where a cell hides a feature (module
    docstring): the look inside every cell of every (probe, path) at once (:func:`lockstep`).
    The probes share one objective."""
    if not paths:
        return []
    ends_of = []  # each path's samples, then a loop's closing cell's end (its first, a loop later)
    for _, path in paths:
        closing = [path.points[0].at(path.points[0].psi + TURN * path.turns)] if path.turns else []
        ends_of.append(list(path.points) + closing)
    flat = [p for ends in ends_of for p in ends]
    evaluate_points(paths[0][0].objective, flat)  # (the path ends that the following found)
    # every cell's first tests at once (_core.cell_looks, which reads the samples' lists)
    lengths = [len(ends) for ends in ends_of]
    owner = np.repeat(np.arange(len(paths)), lengths).tolist()  # each end's path
    start = np.cumsum([0, *lengths]).tolist()  # each path's first end in flat
    first = np.empty(len(flat))  # cell a: between ends a, a + 1
    samples = _core.CellSamples(
        [p.q for p in flat],
        [p.tangent for p in flat],
        [p.psi for p in flat],
        [p.pieces() for p in flat],
        [p.evaluation.feasible for p in flat],
        np.array(start, dtype=np.int64),
        np.array([probe.cyclic for probe, _ in paths]),
    )
    _core.cell_looks(samples, FINE_STEP, _BOUND_SLACK, _HERMITE, first)
    looked = np.flatnonzero(~np.isnan(first)).tolist()
    t = first[looked].tolist()
    cells = [_hidden(paths[owner[a]][0], flat[a], flat[a + 1], t_a) for a, t_a in zip(looked, t, strict=True)]
    filled = [list(ends) for ends in ends_of]
    for a, points in zip(reversed(looked), reversed(lockstep(cells)), strict=True):  # (back to front)
        at = a - start[owner[a]] + 1
        filled[owner[a]][at:at] = points
    return [
        Path(points[:-1] if path.turns else points, path.turns)
        for (_, path), points in zip(paths, filled, strict=True)
    ]


def _hidden(probe: Probe, a: Point, b: Point, t: float) -> Generator[Follow, tuple[Point, bool], list[Point]]:
    r"""Exact samples inserted between neighbours a and b of a path, in order, the first at
    the fraction t of the cell (where :func:`_look` would look; ``_core.cell_looks``):
    halving until no joint moves more than :data:`FINE_STEP` in a sub-cell, then until the
    Hermite models of every sub-cell agree with its ends (module docstring). A process of
    :func:`lockstep`, which asks for each inserted sample's follow: from the sub-cell's left
    end, and where that is not arrived at, from its right end.

    **Path ends.** a can be where its path ends: a path's first sample, followed back to a
    fold (the linking follows it back to where it ends), where :math:`q - q_f \sim (\psi - \psi_f)^{1/2}` and
    :math:`|dq/d\psi|` is about 1e4-1e10. No follow leaves it (the first-order prediction of
    a step longer than its distance to the fold overshoots; a shorter one, below
    :data:`END_TOLERANCE`, is refused), so the samples of such a cell are followed from its
    right end, which traces the one sheet between them; once a follow from a has not left
    it, the sub-cells that start at a are followed from their right end alone. (A path's
    last sample at a fold is the right end of its cell: the follows from the left reach
    it.)"""
    inserted, cells, cyclic = [], [], probe.cyclic
    left, right, ended = a, b, False  # ended: a follow from a did not leave it (see above)
    while True:
        if t is not None and right.psi - left.psi > END_TOLERANCE:
            x = left.psi + t * (right.psi - left.psi)
            middle, arrived = left, False
            if not (ended and left is a):
                middle, arrived = yield probe, left, x
                ended = ended or middle is a
            if not arrived:
                middle, arrived = yield probe, right, x
            if arrived:
                inserted.append(middle)
                cells += [(left, middle), (middle, right)]
        if not cells or len(inserted) >= _MAX_INSERTED:
            return sorted(inserted, key=lambda p: p.psi)
        left, right = cells.pop()
        t = _look(cyclic, left, right)


def _look(cyclic: np.ndarray, a: Point, b: Point) -> float | None:
    """Where, as a fraction of the cell between a and b, :func:`_hidden` samples it: the
    middle where a joint moves more than :data:`FINE_STEP` (``cyclic``: the probe's joints
    compared modulo 2 pi, :meth:`Probe.step`), else :func:`_surprise`'s."""
    return 0.5 if _core.joint_step(cyclic, a.q, b.q) > FINE_STEP else _surprise(cyclic, a, b)


def _surprise(cyclic: np.ndarray, a: Point, b: Point) -> float | None:
    """Where, as a fraction of the cell, the pieces' cubic models along its chord (module
    docstring; ``cyclic``: the joints compared modulo 2 pi) predict a feasibility that
    the ends do not explain: more changes between feasible and infeasible than the ends'
    (none if alike, one if not), at the _MODEL_POINTS points of the cell. Returns the middle
    of the first unexplained stretch. (``_core.surprise``, ``csrc/redundancy/cells.c``; a piece
    that the bound of ``_core.cell_looks`` keeps positive cannot change the pattern and
    is skipped.)"""
    (ga, da), (gb, db) = a.pieces(), b.pieces()
    if len(ga) == 0:
        return None
    span_a, span_b = _core.cell_spans(cyclic, a.q, a.tangent, b.q, b.tangent)
    models = _core.CellModels(ga, da, gb, db, span_a, span_b, _HERMITE)
    return _core.surprise(models, a.evaluation.feasible, b.evaluation.feasible, _BOUND_SLACK)
