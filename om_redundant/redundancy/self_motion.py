"""The self-motion of a redundant arm: how the joints move with the redundancy variables."""

from __future__ import annotations

import numpy as np

from .. import _core
from ..exceptions import SingularSelfMotion
from ..ik.solver import OMSolver
from ..ik.threads import run_rows
from ..validation import as_joint_vector
from .arm_angle import arm_angle_and_gradient, check_arm_angle


def self_motion_tangent(solver: OMSolver, q: np.ndarray) -> np.ndarray:
    r"""dq/dpsi: how the joints move per unit of the redundancy variables, hand fixed.

    The self-motion keeps the hand still, :math:`J(q)\,\dot q = 0`, so
    :math:`\dot q = N a` with N (dof x r) a basis of the null space of the
    real arm's Jacobian J (6 x dof; for r = 1 the vector of its signed 6x6 minors,
    :math:`n_i = (-1)^i \det J_{(i)}` with column i removed, else its last r right singular
    vectors; N's scale cancels below). The redundancy
    variables (the model's arm angle psi(q)) change by :math:`\dot\psi = D\psi(q)\,N a`, so

    .. math::  \frac{dq}{d\psi} = N\,\big(D\psi(q)\,N\big)^{-1},

    with :math:`D\psi` the analytic gradient of
    :func:`~om_redundant.redundancy.arm_angle.arm_angle_and_gradient`. It is singular where psi stops
    changing along the self-motion (a fold of the solution path).

    Args:
        solver: The solver of a redundant arm (r = dof - 6 redundancy variables).
        q: (dof,) joint vector.

    Returns:
        (dof, r) matrix.

    Raises:
        InvalidInput: The arm has no arm angle, or q is malformed.
        SingularSelfMotion: psi does not move along the self-motion at q: :math:`D\psi\,N`
            is singular to rounding (exactly at a fold, or J of rank below 6). Near a fold
            dq/dpsi is large but finite, and returned.
    """
    check_arm_angle(solver)
    q = as_joint_vector(q, solver.arm.dof, stack=False)
    if solver.arm.dof == 7:  # one variable: the null vector of cofactors, n_i = (-1)^i det J_(i)
        tangent = self_motion_tangents(solver, q[None])[0]
    else:
        jacobian = solver.arm.jacobian(q)
        gradient = arm_angle_and_gradient(solver, q)[1]
        null = np.linalg.svd(jacobian)[2][6:].T
        change = np.atleast_2d(gradient @ null)
        try:
            tangent = np.linalg.solve(change.T, null.T).T
        except np.linalg.LinAlgError:
            tangent = np.full_like(null, np.nan)
    if not np.isfinite(tangent).all():
        raise SingularSelfMotion(
            f"the arm angle does not move along the self-motion at q = {np.round(q, 6).tolist()} "
            "(exactly at a fold of the solution path, or where the Jacobian lost rank)"
        )
    return tangent


def self_motion_tangents(solver: OMSolver, q: np.ndarray) -> np.ndarray:
    r"""dq/dpsi of a 7-DOF arm (one redundancy variable) at every row of q, as
    :func:`self_motion_tangent` computes it, by the arm's compiled solver
    (``_core.self_motion_tangents``, ``csrc/redundancy/tangents.c``: the cofactors of the real
    arm's Jacobian in its base frame, the same null vector, and the tangents of
    ``_core.follow``; calls of up to :data:`~om_redundant.ik.threads.BATCH_CHUNK` rows on the
    pool's threads), NaN rows where psi does not move along the self-motion.

    Args:
        solver: The solver of a 7-DOF arm.
        q: (M, 7) joint vectors.

    Returns:
        (M, 7, 1) tangents.

    Raises:
        InvalidInput: The arm has no arm angle, or q is malformed.
    """
    check_arm_angle(solver)
    q = as_joint_vector(q, solver.arm.dof).reshape(-1, solver.arm.dof)
    tangent = np.empty((len(q), 7))

    def chunk(start: int, stop: int) -> None:  # (the kernel releases the GIL: threads share a batch)
        _core.self_motion_tangents(solver.kernel, q[start:stop], tangent[start:stop])

    run_rows(chunk, len(q))
    return tangent[:, :, None]
