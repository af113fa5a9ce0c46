"""om_redundant's own OMSolver as a peer."""

from __future__ import annotations

from typing import Any

import numpy as np

import om_redundant as om

from ..om_any import COARSE_PSI, FINE_PSI, AnyInLimits
from .base import BatchMethod, Method, Peer, Unavailable, _rows


def om_redundant_peer(arm: om.Arm, rng: np.random.Generator) -> Peer:
    """om_redundant's OMSolver."""
    try:
        solver = om.OMSolver(arm)
    except om.ModelError as exc:
        raise Unavailable(f"{arm.dof}-DOF solver not available (ModelError: {exc})") from exc

    def solved(_: Any, solution: om.Solution | None) -> np.ndarray:
        return solution.q[None, :] if solution is not None and solution.ok else np.empty((0, arm.dof))

    def every_prepare(T: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, list[om.Configuration]]:
        return T, solver.configurations(solver.configuration_of(q).redundancy)

    def every_call(argument: tuple[np.ndarray, list[om.Configuration]]) -> list[om.Solution]:
        T, configurations = argument
        return [s for c in configurations for s in solver.solve_all(T, c)]

    def batch_prepare(T: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        configurations = [solver.configuration_of(q) for q in Q]
        redundancy = np.array([c.redundancy for c in configurations])
        return T, np.array([c.signs for c in configurations]), redundancy if redundancy.size else None

    def batch_solutions(_: Any, result: om.BatchSolution) -> list[np.ndarray]:
        return [
            q[None, :] if ok else np.empty((0, arm.dof)) for q, ok in zip(result.q, result.ok, strict=True)
        ]

    return Peer(
        "om_redundant",
        arm,
        None,
        "OMSolver defaults; any: first ok solution within limits over the configurations"
        + (
            f" x {COARSE_PSI} arm angles psi, most frequent cells of random in-limit joint vectors"
            f" first, then {FINE_PSI} arm angles"
            if solver.redundancy_names
            else ""
        ),
        exact=Method(
            lambda T, q: (T, solver.configuration_of(q)),
            lambda argument: solver.solve(*argument),
            solved,
        ),
        any=Method(lambda T, q: T, AnyInLimits(solver), solved),
        every=Method(
            every_prepare,
            every_call,
            lambda _, found: _rows([s.q for s in found], arm.dof),
        ),
        batch=BatchMethod(
            "om_redundant solve_batch (C, threads)",
            batch_prepare,
            lambda argument: solver.solve_batch(*argument),
            lambda argument: solver.solve_batch(*argument, threads=1),
            batch_solutions,
        ),
    )
