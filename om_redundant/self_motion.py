"""The self-motion of a redundant arm: how the joints move with the redundancy variables."""

from __future__ import annotations

import math

import numpy as np

from .exceptions import InvalidInput
from .solver import OMSolver
from .validation import as_joint_vector

_ANGLE_STEP = 1e-6  # rad: central differences of the arm angle along the null space


def self_motion_tangent(solver: OMSolver, q: np.ndarray) -> np.ndarray:
    r"""dq/dpsi: how the joints move per unit of the redundancy variables, hand fixed.

    The self-motion keeps the hand still, :math:`J(q)\,\dot q = 0`, so
    :math:`\dot q = N a` with N (dof x r) an orthonormal basis of the null space of the
    real arm's Jacobian J (6 x dof; its last r right singular vectors). The redundancy
    variables (the model's arm angle psi(q)) change by :math:`\dot\psi = D\psi(q)\,N a`, so

    .. math::  \frac{dq}{d\psi} = N\,\big(D\psi(q)\,N\big)^{-1},

    with :math:`D\psi\,N` (r x r) by central differences of psi(q) along the columns of N
    (step 1e-6 rad; error about 1e-10). It is singular where psi stops changing along the
    self-motion (a fold of the solution path).

    Args:
        solver: The solver of a redundant arm (r = dof - 6 redundancy variables).
        q: (dof,) joint vector.

    Returns:
        (dof, r) matrix.
    """
    r = len(solver.redundancy_names)
    if r == 0 or solver.arm.dof - 6 != r:
        raise InvalidInput(
            f"arm '{solver.arm.name}' has {solver.arm.dof - 6} self-motion directions and "
            f"{r} redundancy variables; the tangent needs as many of each, at least one"
        )
    q = as_joint_vector(q, solver.arm.dof)
    null = np.linalg.svd(solver.arm.jacobian(q))[2][6:].T
    change = np.empty((r, r))
    for c in range(r):
        ahead = solver.configuration_of(q + _ANGLE_STEP * null[:, c]).redundancy
        behind = solver.configuration_of(q - _ANGLE_STEP * null[:, c]).redundancy
        change[:, c] = [
            math.remainder(a - b, 2.0 * math.pi) / (2.0 * _ANGLE_STEP)
            for a, b in zip(ahead, behind, strict=True)
        ]
    return np.linalg.solve(change.T, null.T).T
