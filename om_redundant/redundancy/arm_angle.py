r"""The arm angle psi of a 7-DOF arm and its gradient d psi / dq, from the model's kinematics.

psi is defined in :mod:`om_redundant.om.families.srs` on the MODEL arm at joints q: with the
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
elbow), where this gradient is the one-sided derivative of either branch.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ..exceptions import InvalidInput
from ..kinematics.kernels import joint_axes_kernel
from ..om.families import srs
from ..om.families.common import add, cross, dot, scale, sub, vec
from ..om.solver import OMSolver
from ..validation import as_joint_vector

#: Number of joints psi depends on: the shoulder's three and the elbow.
ARM_ANGLE_JOINTS = 4


@nb.njit(cache=True)
def arm_angle_gradient_kernel(P, table, q, grad):
    """psi at q of the S-R-S model with parameters P and DH table ``table``; writes d psi/dq.

    Args:
        P: The model's parameter vector (:mod:`om_redundant.om.families.srs` layout).
        table: The model chain's DH table.
        q: (7,) joint vector.
        grad: (7,) output, d psi / dq.

    Returns:
        psi (rad), equal to :func:`om_redundant.om.families.srs.arm_angle`.
    """
    # Axis and origin of joints 1-6 in DH frame 0: joint j turns about z of the frame its
    # row starts from. S is the origin after joint 1's row, W the one after joint 5's row.
    axes = np.empty((6, 3))
    origins = np.empty((6, 3))
    joint_axes_kernel(table, q, axes, origins, np.empty((3, 3)), np.empty(3))
    S = (origins[1, 0], origins[1, 1], origins[1, 2])
    W = (origins[5, 0], origins[5, 1], origins[5, 2])
    z4 = (axes[3, 0], axes[3, 1], axes[3, 2])
    w = sub(W, S)
    length = np.sqrt(dot(w, w))
    w_hat = scale(1.0 / length, w)
    elbow = -1.0 if np.sin(q[3] + P[srs.THETA + 3] - P[srs.PHI_STAR]) < 0.0 else 1.0
    bend = elbow * P[srs.BEND]
    b = scale(bend, cross(z4, w_hat))
    n, nw = srs.reference_direction(P, w_hat)
    up = vec(P, srs.UP)
    wb = cross(w_hat, b)
    bb = dot(b, b)
    twist = 1.0 / (1.0 + dot(up, w_hat))
    grad[:] = 0.0
    for j in range(ARM_ANGLE_JOINTS):
        zj = (axes[j, 0], axes[j, 1], axes[j, 2])
        oj = (origins[j, 0], origins[j, 1], origins[j, 2])
        dW = cross(zj, sub(W, oj))
        dw_hat = scale(1.0 / length, sub(dW, scale(dot(w_hat, dW), w_hat)))
        dz4 = cross(zj, z4) if j < 3 else (0.0, 0.0, 0.0)
        db = scale(bend, add(cross(dz4, w_hat), cross(z4, dw_hat)))
        grad[j] = dot(wb, db) / bb + dot(up, cross(w_hat, dw_hat)) * twist
    return np.arctan2(dot(nw, b), dot(n, b))


def check_arm_angle(solver: OMSolver) -> None:
    """Raise :class:`InvalidInput` unless the solver's configurations carry an arm angle psi."""
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
    q = as_joint_vector(q, solver.arm.dof)
    if q.ndim != 1:
        raise InvalidInput("arm_angle_and_gradient takes one joint vector")
    grad = np.empty(solver.arm.dof)
    psi = arm_angle_gradient_kernel(solver.om.params, solver.model.chain.table, q, grad)
    return float(psi), grad
