"""The arm angle psi of a 7-DOF arm swept for a pose or a path: the data behind ``om-redundant sweep``.

A :class:`SweepRequest` says what to sweep (arm, poses, branches, psi grid, obstacles and
scene); :func:`compute_sweep` returns a :class:`SweepResult`: joint angles, normalised
joint-limit margins (:func:`~om_redundant.joint_margins`) and clearance along the psi grid,
and from the redundancy optimiser (:class:`~om_redundant.RedundancyOptimizer`) the feasible
intervals (exact ends) and its choice. The command line (:mod:`om_redundant.cli.sweep`)
builds the request; :mod:`om_redundant.cli.sweep_output` shows the result.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import mujoco
import numpy as np

from ..angles import wrap_angles
from ..ik.configuration import Configuration
from ..ik.solver import OMSolver
from .choice.optimizer import RedundancyOptimizer
from .choice.result import RedundancyChoice
from .objective.clearance import Clearance
from .objective.shapes import Box, Capsule, Shape, Sphere
from .objective.terms import DEFAULT_SINGULARITY_WEIGHT, joint_margins

#: Obstacle shapes: the numbers each takes, in order (metres, in the arm's root frame).
SHAPES = {
    "sphere": ("x", "y", "z", "r"),
    "capsule": ("x1", "y1", "z1", "x2", "y2", "z2", "r"),
    "box": ("x", "y", "z", "hx", "hy", "hz"),
}


@dataclass(frozen=True)
class Obstacle:
    """An obstacle as the command line gives it (``kind:n1,n2,...``), in the arm's root frame (metres).

    Attributes:
        kind: ``"sphere"``, ``"capsule"`` or ``"box"`` (axis-aligned).
        values: The numbers of :data:`SHAPES` for that kind, in order.
    """

    kind: str
    values: tuple[float, ...]

    def shape(self, name: str = "") -> Shape:
        """The library's obstacle (:class:`~om_redundant.Sphere`, ``Capsule`` or ``Box``)."""
        v = self.values
        if self.kind == "sphere":
            return Sphere(v[:3], v[3], name)
        if self.kind == "capsule":
            return Capsule(v[:3], v[3:6], v[6], name)
        pose = np.eye(4)
        pose[:3, 3] = v[:3]
        return Box(v[3:], pose, name)


@dataclass(frozen=True, eq=False)
class SweepRequest:
    """What to sweep, checked (``om-redundant sweep`` builds it from its options).

    Attributes:
        solver: The arm's solver; a 7-DOF arm (``solver.redundancy_names == ("psi",)``).
        poses: (M, 4, 4) targets in the arm's root frame; M = 1 for a single pose.
        path: True when the poses are a path (``--path``): psi is tracked from pose to pose.
        branches: Branch signs to sweep: the one given with ``--signs``, or every combination.
        psi: (N,) arm angles to evaluate, rad, increasing over [-pi, pi).
        obstacles: Obstacles given with ``--obstacle``.
        scene: The ``--scene`` model (compiled, meshes dropped if their files are missing),
            whose geoms are further obstacles; None without one.
        singularity_weight: The optimiser's weight of the distance from singularities
            (``--singularity-weight``).
        progress: Call with the number of poses done so far (drives the progress bar).
    """

    solver: OMSolver
    poses: np.ndarray
    path: bool
    branches: tuple[tuple[int, ...], ...]
    psi: np.ndarray
    obstacles: tuple[Obstacle, ...] = ()
    scene: mujoco.MjModel | None = None
    singularity_weight: float = DEFAULT_SINGULARITY_WEIGHT
    progress: Callable[[int], None] = field(default=lambda done: None)


@dataclass(frozen=True, eq=False)
class BranchSweep:
    """One branch of one pose, along the psi grid.

    Attributes:
        signs: The branch signs.
        q: (N, dof) joint vectors at each psi (NaN rows where there is no solution).
        ok: (N,) a solution exists at psi.
        margin: (N, dof) normalised joint-limit margin of each joint
            (:func:`~om_redundant.joint_margins`: 1 at mid-range, 0 on a limit, negative
            beyond); NaN where there is no solution.
        clearance: (N,) smallest distance between the arm and the obstacles (m), negative
            in penetration; +inf without obstacles, NaN where there is no solution.
        feasible: (N,) a solution within the limits and clear of the obstacles.
        intervals: Feasible psi intervals ``(low, high)``, rad, with the optimiser's exact ends
            (:meth:`~om_redundant.RedundancyOptimizer.intervals`): low in [-pi, pi), high
            above pi when the arc crosses +-pi; ``(-pi, pi)`` for the whole circle.
    """

    signs: tuple[int, ...]
    q: np.ndarray
    ok: np.ndarray
    margin: np.ndarray
    clearance: np.ndarray
    feasible: np.ndarray
    intervals: tuple[tuple[float, float], ...]


@dataclass(frozen=True, eq=False)
class Choice:
    """The optimiser's pick for one pose: a configuration, its joints, margin and clearance."""

    configuration: Configuration
    q: np.ndarray
    margin: float  # smallest normalised joint-limit margin
    clearance: float  # m; +inf without obstacles
    value: float = math.nan  # the optimiser's objective
    branch_flipped: bool = False  # path mode: left the previous branch
    rechosen: bool = False  # path mode: tracking stopped, chosen afresh from the previous joints


@dataclass(frozen=True, eq=False)
class PoseSweep:
    """The sweep of one pose: every requested branch, and the choice (None if none is feasible);
    ``note``: why nothing was chosen, or (path mode) why tracking chose afresh."""

    pose: np.ndarray
    branches: tuple[BranchSweep, ...]
    chosen: Choice | None
    note: str = ""


@dataclass(frozen=True, eq=False)
class SweepResult:
    """The sweep of every pose on the request's psi grid (for a path: the tracked choices)."""

    psi: np.ndarray
    poses: tuple[PoseSweep, ...]


def optimizer_for(request: SweepRequest) -> RedundancyOptimizer:
    """The redundancy optimiser of the request: its arm, branches and obstacles (shapes and
    scene in one :class:`~om_redundant.Clearance`), singularity weight, default objective
    otherwise."""
    shapes: list[Shape | mujoco.MjModel] = [
        o.shape(f"cli_{o.kind}{k}") for k, o in enumerate(request.obstacles)
    ]
    if request.scene is not None:
        shapes.append(request.scene)
    obstacles = Clearance.for_arm(request.solver.arm, shapes) if shapes else None
    return RedundancyOptimizer(
        request.solver, obstacles, branches=request.branches, singularity_weight=request.singularity_weight
    )


def compute_sweep(request: SweepRequest) -> SweepResult:
    """Sweep psi for every pose and branch of the request, and pick psi with the optimiser.

    For each pose and branch the psi grid is solved in one batch (on a path, hinted by the
    previous pose's joints at the same psi); margins and clearance are the optimiser's own
    (:func:`~om_redundant.joint_margins`, its :class:`~om_redundant.Clearance`). The intervals
    are :meth:`RedundancyOptimizer.intervals`, the choice :meth:`RedundancyOptimizer.choose`
    (on a path, tracked from the previous pose's choice).
    """
    psi = request.psi
    optimizer = optimizer_for(request)
    objective = optimizer.objective
    poses: list[PoseSweep] = []
    previous: RedundancyChoice | None = None
    hints: dict[tuple[int, ...], np.ndarray] = {}
    for i, T in enumerate(request.poses):
        choice = optimizer.choose(T, previous if request.path else None)
        if request.path:
            found = optimizer.intervals(T)
            previous = choice
        else:
            found = list(choice.intervals)  # untracked: every allowed branch's, as intervals(T)
        branches = []
        for signs in request.branches:
            sweep = _branch_sweep(request, objective, T, signs, hints.get(signs))
            if request.path:
                hints[signs] = np.where(sweep.ok[:, None], sweep.q, hints.get(signs, sweep.q))
            spans = tuple(
                (-math.pi, math.pi) if iv.closed else (float(iv.lo), float(iv.hi))
                for iv in found
                if tuple(iv.signs) == tuple(signs)
            )
            branches.append(replace(sweep, intervals=spans))
        chosen = None
        if choice.ok:
            chosen = Choice(
                choice.configuration,
                np.array(choice.solution.q),
                float(choice.margin),
                float(choice.clearance),
                float(choice.value),
                choice.branch_flipped,
                choice.rechosen,
            )
        poses.append(PoseSweep(T, tuple(branches), chosen, choice.reason))
        request.progress(i + 1)
    return SweepResult(psi, tuple(poses))


def _branch_sweep(request, objective, T, signs, hint) -> BranchSweep:
    """One branch along the grid: one batch solve, margins, clearance, feasibility."""
    solver, psi = request.solver, request.psi
    arm = solver.arm
    n = len(psi)
    if hint is not None and not np.isfinite(hint).all():
        hint = None  # the kernel takes hints for every row or none
    batch = solver.solve_batch(np.repeat(T[None], n, axis=0), signs, psi, q_hint=hint)
    ok = np.asarray(batch.ok, dtype=bool)
    q = np.full((n, arm.dof), np.nan)
    margin = np.full((n, arm.dof), np.nan)
    clearance = np.full(n, np.nan)
    if ok.any():
        q[ok] = _nearest_mid_range(arm, batch.q[ok])
        margin[ok] = joint_margins(arm, q[ok])
        if objective.clearance is None:
            clearance[ok] = math.inf
        else:
            clearance[ok] = objective.clearance.minima(q[ok])
    with np.errstate(invalid="ignore"):
        feasible = ok & (np.min(np.nan_to_num(margin, nan=-1.0), axis=1) >= 0.0)
        feasible &= ~(clearance < objective.min_clearance)
    return BranchSweep(tuple(signs), q, ok, margin, clearance, feasible, ())


def _nearest_mid_range(arm, q: np.ndarray) -> np.ndarray:
    """Revolute joints with limits at their turn nearest mid-range, as the optimiser takes them."""
    centred = arm.revolute & np.isfinite(arm.lower) & np.isfinite(arm.upper)
    centre = np.where(centred, (arm.lower + arm.upper) / 2.0, 0.0)
    wrapped = centre + wrap_angles(q - centre)
    return np.where(centred, wrapped, q)
