r"""7-DOF model arms: spherical shoulder, one elbow joint, spherical wrist (Hollerbach arms).

The closed form is C (``csrc/ik/srs.c``); this module holds its math. The family code and the
parameter vector's layout are written once, in ``csrc/ik/om_kernels.h``: Python reads them from
:mod:`om_redundant._core` (``_core.SRS``, ``_core.SRS_THETA``, ... ``_core.SRS_N_PARAMS``) where it
uses them.

Joints 1-3 intersect at the shoulder centre S (fixed in DH frame 0), joints 5-7 at the wrist
centre W (fixed in the flange frame), and joint 4 is the elbow. Offsets between S and W
(an offset elbow, as on the Panda and xArm7) are allowed; the pure S-R-S arm (iiwa) is the
special case without them.

Elbow. With :math:`R_{03}` the rotation of DH frame 3 and :math:`s_3` the shoulder centre
in frame 3, :math:`W - S = R_{03}\,v(\varphi_4)` with :math:`v = R_z(\varphi_4)\,u - s_3`
(:math:`u` constant), so

.. math::  |W - S|^2 = k_0 + k_1 \cos\varphi_4 + k_2 \sin\varphi_4
                     = k_0 + K \cos(\varphi_4 - \varphi^*),

and :math:`\varphi_4 = \varphi^* + \mathrm{atan2}(\mathrm{ELBOW}\sqrt{1 - x^2},\ x)`,
:math:`x = (|W - S|^2 - k_0)/K`. :math:`\varphi^*` is the model's straight elbow, so the
ELBOW sign is :math:`\mathrm{sign}\,\sin(\varphi_4 - \varphi^*)`, not the sign of :math:`q_4`.

Arm angle. The arm angle :math:`\psi` is the angle about the shoulder-wrist line of the
elbow's bend direction :math:`b = \mathrm{ELBOW}\,\sigma\,(z_4 \times \hat w)`, where
:math:`z_4` is joint 4's axis, :math:`\hat w = (W - S)/|W - S|` and the constant
:math:`\sigma = \pm 1` makes b point from the line to the elbow. (On the arms here S, the
elbow and W lie in a plane normal to :math:`z_4`, so b is the direction of the elbow point;
unlike the elbow point, b stays defined at the straight elbow.) It is measured from a
reference direction :math:`n(\hat w)` perpendicular to :math:`\hat w`:

.. math::  \psi = \mathrm{atan2}\big((\hat w \times n)\cdot b,\ n\cdot b\big),
           \qquad n(\hat w) = R(\hat z \to \hat w)\, r,

where :math:`R(\hat z \to \hat w) = I + [\hat z \times \hat w]_\times
+ [\hat z \times \hat w]_\times^2 / (1 + \hat z\cdot\hat w)` is the shortest rotation taking
the root frame's up axis :math:`\hat z` to :math:`\hat w`, and :math:`r = -\hat x` (root
frame). This is the stereographic shoulder-elbow-wrist angle of Elias and Wen (2023): it is
continuous everywhere except on the half-line :math:`\hat w = -\hat z`, the wrist straight
below the shoulder, inside the base. With the wrist in front of the shoulder (+x),
:math:`\psi = 0` puts the elbow above the shoulder-wrist line; :math:`\psi` turns the elbow
right-handedly about :math:`\hat w`.

Shoulder and wrist. Given :math:`\psi`, :math:`R_{03}` maps the frame-3 triad
:math:`(\hat v, \hat b_3, \hat v \times \hat b_3)`, :math:`b_3 = \mathrm{ELBOW}\,\sigma\,
(e_z \times v)` (the shoulder-wrist direction and the bend direction in frame 3) onto
:math:`(\hat w, m, \hat w \times m)`, :math:`m = \cos\psi\, n + \sin\psi\, (\hat w \times n)`.
Joints 1-3 and 5-7 then follow from :mod:`~om_redundant.ik.families.common`
with the SHOULDER and WRIST signs
(:math:`\mathrm{sign}\sin\varphi_2`, :math:`\mathrm{sign}\sin\varphi_6`).

Angles :math:`\varphi_i = q_i + \theta_i` are DH joint angles with their offsets. Fixed
rows between joints 6 and 7 (the Sawyer's) fold into the wrist's middle rotation,
:math:`R_x(\alpha_6) F = R_z(a) R_x(\beta) R_z(b)`: a joins :math:`\theta_6`, b joins
:math:`\theta_7`, and :math:`\beta` is the twist between joints 6 and 7 (see
:mod:`~om_redundant.ik.families.common`).
"""

from __future__ import annotations

import numpy as np

from ... import _core
from .dispatch import f64, flange_target


def model_ik_lifted(
    P: np.ndarray,
    R: np.ndarray,
    p: np.ndarray,
    signs: np.ndarray,
    psi: float,
    q1: float,
    q7: float,
    phi4: float,
    q: np.ndarray,
) -> _core.Lifted:
    r"""The model IK with q1, q7 and the elbow angle phi4 given rather than solved for
    (phi4 NaN: the elbow equation's root in the ELBOW branch, the edge of reach beyond it).

    Writes q (q1 and q7 as given) and returns the residuals of the three equations they
    must satisfy, by name: the shoulder's and the wrist's consistency and the elbow's,
    :math:`x - \cos(\varphi_4 - \varphi^*)`. Unlike the closed form, this is smooth
    everywhere but at W = S (NaN): across the straight elbow, where the two ELBOW branches
    meet in a square root, and at the shoulder and wrist singularities, where the Euler
    angles are ill-conditioned. Its roots are the model's IK in every SHOULDER and WRIST
    branch at once (each angle pair's branch follows from q1 or q7).
    """
    return _core.model_ik_lifted(f64(P), flange_target(R, p, signs, psi), q1, q7, phi4, q)


def model_lifted_terms(
    P: np.ndarray, R: np.ndarray, p: np.ndarray, signs: np.ndarray, q1: float, q7: float
) -> _core.LiftedTerms | None:
    r""":func:`model_ik_lifted`'s residuals with phi4 the elbow's root, at every arm angle at once.

    With q1, q7 and the hand position given, the elbow's root and the frames of
    :math:`w = W - S` do not depend on :math:`\psi`; :math:`\psi` enters :math:`R_{03} = A^T B`
    only through A's rows :math:`m = \cos\psi\, n + \sin\psi\, (\hat w \times n)` and
    :math:`\hat w \times m`, linearly, and the shoulder's and wrist's residuals are entries of
    fixed rotations of :math:`R_{03}`. So each is

    .. math::  r(\psi) = r_0 + r_1 \cos\psi + r_2 \sin\psi,

    and the torus search's grid, whose nodes (q1, q7) are the same at every arm angle of a
    sweep, evaluates them once per pose (``csrc/ik/torus.c``, the torus memo).

    Returns:
        The terms ``shoulder`` and ``wrist`` (:math:`r_0, r_1, r_2` each), the elbow's residual
        and its root phi4; None where W = S.
    """
    return _core.model_lifted_terms(f64(P), flange_target(R, p, signs, 0.0), q1, q7)


def model_ik_at_reach(
    P: np.ndarray,
    R: np.ndarray,
    p: np.ndarray,
    signs: np.ndarray,
    psi: float,
    q_prev: np.ndarray,
    q: np.ndarray,
) -> bool:
    """The closed form, but where the wrist centre lies beyond the model's reach the elbow is
    held at the edge (straight or folded): a start for :func:`model_ik_lifted`, which is
    smooth across that edge. Returns False, and leaves q, only where W = S."""
    return _core.model_ik_at_reach(f64(P), flange_target(R, p, signs, psi), f64(q_prev), q)
