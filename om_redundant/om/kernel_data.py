"""The fixed data of the compiled solver kernel for an arm and its model."""

from __future__ import annotations

import numpy as np

from . import system
from .model import ModelArm
from .nominal import NominalArm


def kernel_data(
    om: ModelArm, tolerances: tuple[float, float], scan_points: int, nominal: NominalArm | None = None
) -> system.SolverData:
    """The :class:`~om_redundant.om.system.SolverData` of ``ckernels.Solver`` for an arm and
    its closed-form model.

    Args:
        om: The closed-form model (:func:`~om_redundant.om.model.derive_model`) of the arm, or
            of its nominal arm (``om.real``) for an arm near a family.
        tolerances: Accepted position and orientation errors (m, rad).
        scan_points: Grid points of the bounded search.
        nominal: The nominal arm of an arm near a family (None: ``om.real`` is the arm): every
            answer is verified with the arm's exact chain, in the nominal joint coordinates.
    """
    arm = om.real
    chain = arm.chain
    shoulder, wrist = (0.0, 0.0) if nominal is None else (nominal.shoulder_offset, nominal.wrist_offset)
    # dp turns with q1 and q7: the torus (q1, q7); with a shoulder offset a2 or a wrist offset a5
    # zeroed by the nominal arm, q1 and q7 are given on the torus and the correction's fixed
    # point turns with q2 (on the left) or q6 (on the right) alone
    if om.shoulder.any() or shoulder or wrist:
        mode, dp_joint = system.TORUS, 0
    elif om.dp_joint >= 0:
        mode, dp_joint = system.CIRCLE, om.dp_joint
    else:
        mode, dp_joint = system.FIXED, 0
    c = system.as_kernel_array
    return system.SolverData(
        family=int(om.family),
        mode=mode,
        params=c(om.params),
        model_table=c(om.model.chain.table),
        real_table=c((chain if nominal is None else nominal.exact).table),
        dp_joint=int(dp_joint),
        dp_coefficients=c(np.vstack([om.delta, om.shoulder])),
        T_base_root=c(np.linalg.inv(chain.T_root_base)),
        T_tool_flange=c(np.linalg.inv(chain.T_flange_tool)),
        revolute=np.ascontiguousarray(arm.revolute, dtype=np.bool_),
        lower=c(arm.lower),
        upper=c(arm.upper),
        scan_points=scan_points,
        position_tolerance=tolerances[0],
        orientation_tolerance=tolerances[1],
        nominal_table=c(np.empty((0, 6)) if nominal is None else chain.table),
        flip=c(np.ones(arm.dof) if nominal is None else nominal.flip),
        near_deviation=0.0 if nominal is None else nominal.deviation,
        near_left=shoulder != 0.0 and abs(shoulder) >= abs(wrist),
        near_mixed=shoulder != 0.0 or wrist != 0.0,
    )
