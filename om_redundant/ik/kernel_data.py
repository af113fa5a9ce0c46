r"""The OM system (9), which the compiled kernels (``csrc/``) solve, and the data they take:
the fixed data of an arm and its model, and a target as its flange pose.

System (9) asks for the model's hand position :math:`p_m` with

.. math::  p_m = p_d + \Delta p\big(\mathrm{IK}_{model}(R_d, p_m, c)\big).

Every solution has the form :math:`p_m = p_d + R_d\,\delta(w)`, where :math:`\delta` is dp
seen from the flange and depends on one wrist joint, :math:`w = q_J` (see
:mod:`om_redundant.ik.model`). So the three equations reduce exactly to one on the circle,

.. math::  g(w) = \mathrm{wrap}\big(\mathrm{IK}_{model}(R_d, p_d + R_d\,\delta(w), c)_J - w\big) = 0,

and a root gives the real arm's joints :math:`q = \mathrm{IK}_{model}(\ldots)` with
:math:`|p_{real}(q) - p_d| = |\delta(w) - \delta(q_J)| \le \Delta p_{max}\,|g(w)|`.
A 6-DOF wrist with :math:`a_4 \ne 0` has the circle :math:`p_m = p_d + \Delta p(w)`,
:math:`w = q_1`, instead (:mod:`om_redundant.ik.model`, ``csrc/ik/wrist_offset.c``), or, a
PUMA-like wrist, the torus :math:`p_m = p_d + R_d\,\delta(q_5, q_6)` (below; lifted by the
elbow angle, ``om_six_dof_model_ik_lifted``).

Arms with shoulder offsets (Gen3, Sawyer) add :math:`a(q_1)`, so solutions lie on a torus
:math:`(w_1, w_7) = (q_1, q_7)`: :math:`p_m = p_d + a(w_1) + R_d\,\delta(w_7)`. There the
system is lifted to three unknowns :math:`(w_1, w_7, \varphi_4)` and three residuals that
are smooth everywhere (:func:`~om_redundant.ik.families.srs.model_ik_lifted`): the model IK
with q1, q7 and the elbow angle given is consistent with the shoulder, the wrist and the
elbow equation. In (w1, w7) alone the residual has a square-root branch point at the edge of
reach (the straight or folded elbow) and steep Euler angles at the shoulder and wrist
singularities, which is where roots crowd; lifted, Newton's method converges there.

* Local solve: Broyden's method, which in one unknown is the secant method, started with a
  finite-difference slope, from the joint of the paper's fixed-point start
  (:math:`p_m = p_d`) or of a hint; on the torus, damped Newton on the lifted system. On a
  7-DOF circle arm, where the secant fails (g's square root at the edge of reach sends it
  out of reach) or p_d is beyond the model's reach (the start then holds the elbow at the
  edge), the same lifted Newton, with zero shoulder offsets, takes over.
* Bounded search, the paper's guarantee: g is sampled on a grid over the whole circle (the
  image of the ball :math:`|p_m - p_d| \le \Delta p_{max}` that can hold solutions); each sign
  change is refined; near the edges of the model's reach, at local minima of |g| and on
  small islands of reach, where roots come in close pairs, 1-D extremum searches find
  them. On the torus, a grid of the lifted residual seeds Newton's method, with deflation
  and a search along each root's fold direction for close pairs (``csrc/ik/torus.c``);
  this is a thorough search rather than a proof. At a grid node the residual is linear in
  :math:`\cos\psi` and :math:`\sin\psi`
  (:func:`~om_redundant.ik.families.srs.model_lifted_terms`), so a batch's searches of one
  pose at many arm angles (the optimiser's sweep) compute the nodes' terms once, and start
  not from the grid but from the pose's self-motion, traced once per ELBOW sign
  (``csrc/ik/torus_trace.c``): with psi a fourth unknown the lifted residual's roots form
  curves, each traced by predictor-corrector continuation from seeds the grid's starts would
  take at some psi, and a search at psi starts Newton's method where they cross it (and from
  a fold near it, for the fold's pair): one start a root instead of the grid's many. Within
  the joint limits it finds what the grid's starts find (``tests/test_torus_trace.py``; 780
  Sawyer poses at 512 arm angles and branches each); where the folded elbow puts the wrist
  centre on the shoulder (W = S), beyond the Sawyer's limits, either may hold roots the other
  lacks. Before it, a certificate
  (``csrc/ik/contraction.c``) bounds how fast the model's q1 and q7 turn as the wrist centre
  moves over the ball that holds the torus: where the map w -> (q1, q7) contracts (in a
  weighted max norm), on the whole torus or on cells of it, Banach's theorem proves each
  cell's root unique, found by iterating the map, and cells where the residual cannot
  vanish are proved empty; only where it decides nothing (singular shoulder or wrist, the
  edge of reach, psi's half-line, most Sawyer poses) does the grid search run. Every
  candidate is verified with the REAL arm's forward kinematics.

The kernels are C (``csrc/``, one file per idea: ``residual.c``, ``scalar.c`` (secant,
regula falsi, Brent), ``circle.c``, ``torus.c``, ``verify.c``, ``search.c``, ``solve.c``),
compiled when the package is installed: no compile at run time. They work in DH frame 0
with the flange pose. What crosses into them is :class:`SolverData`, copied once per solver
into :class:`om_redundant._core.Solver`, and per call the pose, the configuration's
tuples and C-contiguous float64 arrays.
"""

from __future__ import annotations

import numpy as np

from .. import _core
from .model import ModelArm
from .nominal import NominalArm


def kernel_data(
    model_arm: ModelArm, tolerances: tuple[float, float], scan_points: int, nominal: NominalArm | None = None
) -> _core.SolverData:
    """The :class:`~om_redundant._core.SolverData` of ``_core.Solver`` for an arm and
    its closed-form model.

    Args:
        model_arm: The closed-form model (:func:`~om_redundant.ik.model.derive_model`) of the arm, or
            of its nominal arm (``model_arm.real``) for an arm near a family.
        tolerances: Accepted position and orientation errors (m, rad).
        scan_points: Grid points of the bounded search.
        nominal: The nominal arm of an arm near a family (None: ``model_arm.real`` is the arm): every
            answer is verified with the arm's exact chain, in the nominal joint coordinates.
    """
    arm = model_arm.real
    chain = arm.chain
    shoulder, wrist = (0.0, 0.0) if nominal is None else (nominal.shoulder_offset, nominal.wrist_offset)
    # dp turns with q1 and q7: the torus (q1, q7); with a shoulder offset a2 or a wrist offset a5
    # zeroed by the nominal arm, q1 and q7 are given on the torus and the correction's fixed
    # point turns with q2 (on the left) or q6 (on the right) alone
    # dp of a PUMA-like 6-DOF wrist turns with q5 and q6: the torus (q5, q6)
    if model_arm.shoulder.any() or model_arm.wrist_torus is not None or shoulder or wrist:
        mode, dp_joint = _core.TORUS, 0
    elif model_arm.dp_joint >= 0:
        mode, dp_joint = _core.CIRCLE, model_arm.dp_joint
    else:
        mode, dp_joint = _core.FIXED, 0
    c = as_kernel_array
    return _core.SolverData(
        family=int(model_arm.family),
        mode=mode,
        params=c(model_arm.params),
        model_table=c(model_arm.model.chain.table),
        real_table=c((chain if nominal is None else nominal.exact).table),
        dp_joint=int(dp_joint),
        dp_coefficients=c(np.vstack([model_arm.delta, model_arm.shoulder])),
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


def flange_target(
    T: np.ndarray, T_base_root: np.ndarray, T_tool_flange: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The flange pose (R, p) in DH frame 0 for an end-effector pose T in the root frame:
    ``T_base_root @ T @ T_tool_flange``, as the kernels compute it."""
    R, p = np.empty((3, 3)), np.empty(3)
    _core.flange_target(
        as_kernel_array(T), as_kernel_array(T_base_root), as_kernel_array(T_tool_flange), R, p
    )
    return R, p


def as_kernel_array(array: np.ndarray) -> np.ndarray:
    """The array as the kernels take it: C-contiguous float64 (a copy only if needed)."""
    return np.ascontiguousarray(array, dtype=np.float64)
