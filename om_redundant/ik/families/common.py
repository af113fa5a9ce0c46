r"""Pieces every family uses: the reach slack, and the angles of three revolute joints with
intersecting axes (a spherical shoulder or wrist), computed in ``csrc/ik/common.c``
(``om_euler_zxzxz``, ``om_euler_zxzxz_given_first``).

The rotation of such a triple is

.. math::  M = R_z(\varphi_a)\, R_x(\alpha_a)\, R_z(\varphi_b)\, R_x(\beta)\, R_z(\varphi_c),
           \qquad \sigma_a = \sin\alpha_a = \pm 1,

so with :math:`S = \sin, C = \cos`, :math:`M e_z = R_z(\varphi_a)\,(S_\beta S_b,\
-\sigma_a C_\beta)` in x and y and :math:`-\sigma_a S_\beta C_b` in z. Axes a and b are
perpendicular; :math:`\beta` is :math:`\pm 90°` on most arms but may differ (the Sawyer's
joint 7 leans by :math:`7 \cdot 10^{-6}` rad), which leaves a cone of half-angle
:math:`|C_\beta|` around axis a that axis c cannot reach. With the branch sign
:math:`s = \mathrm{sign}(\sin\varphi_b)`, :math:`\varphi_b` and :math:`\varphi_a` follow from M's
last column, and :math:`\varphi_c` is the angle of the residual
:math:`(R_z(\varphi_a) R_x(\alpha_a) R_z(\varphi_b) R_x(\beta))^T M`. Taking :math:`\varphi_c`
from this residual rather than from M's last row makes the three angles consistent, so that
their rounding errors cancel in the product even near the singularity
:math:`\sin\varphi_b = 0`, where axes a and c align (up to :math:`C_\beta`) and
:math:`\varphi_a` keeps a given value.
"""

from ... import _core

#: Relative slack under a square root before a target counts as outside the model's reach.
REACH_SLACK = _core.REACH_SLACK
