"""The numpy reference of the self-motion tangents of many rows (``_core.self_motion_tangents``,
``csrc/redundancy/tangents.c``; the library's is
:func:`om_redundant.redundancy.self_motion.self_motion_tangents`)."""

from __future__ import annotations

import numpy as np

from om_redundant import _core
from om_redundant.ik.solver import OMSolver

_MINORS = np.array([[j for j in range(7) if j != i] for i in range(7)])  # J without column i
_COFACTOR_SIGNS = (-1.0) ** np.arange(7)


def self_motion_tangents(solver: OMSolver, q: np.ndarray) -> np.ndarray:
    """dq/dpsi of a 7-DOF arm at every row of q (M, 7) by numpy: the null vector of the real
    arm's Jacobian's signed 6x6 minors, over the arm angle's gradient along it (the operations
    of :func:`~om_redundant.redundancy.self_motion.self_motion_tangent`, the minors of all rows
    in one batch).

    Returns:
        (M, 7, 1) tangents, NaN rows where psi does not move along the self-motion.
    """
    chain, model, flip = solver.arm.chain, solver.model.chain, solver.flip
    q = np.asarray(q, dtype=float).reshape(-1, 7)
    jacobians = np.empty((len(q), 6, 7))
    gradients = np.empty((len(q), 7))
    for row, J, grad in zip(q, jacobians, gradients, strict=True):
        _core.jacobian(chain.table, chain.T_root_base, chain.T_flange_tool, row, J)
        _core.arm_angle_gradient(solver.model_arm.params, model.table, flip * row, grad)
    gradients *= flip
    null = _COFACTOR_SIGNS * np.linalg.det(jacobians[:, :, _MINORS].transpose(0, 2, 1, 3))
    change = np.array([g @ n for g, n in zip(gradients, null, strict=True)])
    with np.errstate(divide="ignore", invalid="ignore"):
        tangent = null / change[:, None]
    tangent[~np.isfinite(tangent).all(axis=1)] = np.nan
    return tangent[:, :, None]
