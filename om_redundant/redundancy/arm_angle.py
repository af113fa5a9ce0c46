r"""The arm angle psi of a 7-DOF arm and its gradient d psi / dq, from the model's kinematics.

psi is defined in :mod:`om_redundant.ik.families.srs` on the MODEL arm at joints q: with the
shoulder centre S, the wrist centre W, :math:`w = W - S`, :math:`\hat w = w/|w|`, joint 4's
axis :math:`z_4` and the bend direction :math:`b = e\,\sigma\,(z_4 \times \hat w)`
(e the ELBOW sign, :math:`\sigma` the model's constant bend sign),

.. math::  \psi = \mathrm{atan2}\big(n_w \cdot b,\ n \cdot b\big), \qquad
           n = R(u \to \hat w)\, r, \quad n_w = \hat w \times n,

with u the root frame's up axis and r its -x axis. Everything is evaluated in DH frame 0 of
the model chain, where S, W and the joint axes :math:`z_j` through origins :math:`o_j` come
from one pass over the DH rows.

Gradient. Write :math:`b = |b|(\cos\psi\, n + \sin\psi\, n_w)`. Differentiating
:math:`\psi = \mathrm{atan2}(y, x)`, :math:`x = n\cdot b`, :math:`y = n_w\cdot b`, and using
:math:`b \in \mathrm{span}(n, n_w)`, :math:`dn\cdot n = 0`, :math:`dn_w \cdot n = -n_w\cdot dn`:

.. math::  d\psi = \frac{(\hat w \times b)\cdot db}{|b|^2} - \kappa, \qquad
           \kappa = n_w \cdot dn,

the turn of b about :math:`\hat w` minus the turn of the reference. The reference is the
minimal rotation from u: in spherical coordinates :math:`(\theta, \phi)` of :math:`\hat w`
about u, :math:`R(u\to\hat w) = R_u(\phi) R_y(\theta) R_u(-\phi)` turns about
:math:`\hat w` at the rate :math:`-(1 - \cos\theta)\,\dot\phi`, that is

.. math::  \kappa = -\frac{u \cdot (\hat w \times d\hat w)}{1 + u \cdot \hat w},

singular only on psi's singular half-line :math:`\hat w = -u`. Per joint j (0-based),
:math:`\partial_j W = z_j \times (W - o_j)` (zero for the wrist joints, whose axes pass through
W), :math:`\partial_j \hat w = (I - \hat w \hat w^T)\,\partial_j W / |w|`,
:math:`\partial_j z_4 = z_j \times z_4` for the joints before joint 4 (zero from joint 4 on),
:math:`\partial_j b = e\sigma(\partial_j z_4 \times \hat w + z_4 \times \partial_j \hat w)`.
So psi depends on q1..q4 only. It jumps by pi where the ELBOW sign flips (the straight
elbow), where this gradient is the one-sided derivative of either branch. The kernel is C
(``om_arm_angle_gradient`` in ``csrc/ik/srs.c``).
"""

from __future__ import annotations

import numpy as np

from .. import _core
from ..exceptions import InvalidInput
from ..ik.solver import OMSolver
from ..validation import as_instance, as_joint_vector


def check_arm_angle(solver: OMSolver) -> None:
    """Raise :class:`InvalidInput` unless the solver's configurations carry an arm angle psi."""
    as_instance(solver, OMSolver, "solver")
    if solver.redundancy_names != ("psi",):
        raise InvalidInput(f"arm '{solver.arm.name}' has no arm angle psi (it is not a 7-DOF arm)")


def arm_angle_and_gradient(solver: OMSolver, q: np.ndarray) -> tuple[float, np.ndarray]:
    """The arm angle psi of joint vector q and its gradient, for a 7-DOF arm's solver.

    psi is the model's (``solver.configuration_of(q).redundancy[0]``); see the module
    docstring for the gradient's derivation.

    Args:
        solver: An :class:`~om_redundant.OMSolver` of a 7-DOF arm.
        q: (7,) joint vector.

    Returns:
        ``(psi, dpsi_dq)`` with dpsi_dq of shape (7,); its entries for joints 5-7 are zero.

    Raises:
        InvalidInput: The arm has no arm angle, or q is malformed.
    """
    check_arm_angle(solver)
    q = as_joint_vector(q, solver.arm.dof, stack=False)
    grad = np.empty(solver.arm.dof)
    flip = solver.flip  # the model's joint coordinates are flip * q
    psi = _core.arm_angle_gradient(
        solver.model_arm.params, solver.model.chain.table, np.ascontiguousarray(flip * q), grad
    )
    return float(psi), flip * grad
