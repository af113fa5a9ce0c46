r"""6-DOF model arms with a spherical wrist: joints 1-3 place the wrist centre, 4-6 orient.

Two position families share one shoulder and one wrist:

* ``RRR_SPHERICAL_WRIST``: joint 1 perpendicular to joint 2, joints 2 and 3 parallel
  (UR, PUMA and most industrial arms).
* ``RRP_SPHERICAL_WRIST``: revolute 1 and 2 with perpendicular axes, prismatic 3
  (the OM paper's Spherical manipulator).

Shoulder. With :math:`\sigma_1 = \sin\alpha_1 = \pm 1`, the wrist centre is
:math:`p_w = R_z(\varphi_1)\,(\rho,\ -\sigma_1 h,\ \cdot) + (0, 0, d_1)`, where
:math:`\varphi_1 = q_1 + \theta_1`, :math:`h` is the lateral offset (sum of the d's along the
parallel axes) and :math:`\rho = a_1 + u` the reach in the arm plane. So
:math:`\rho = \mathrm{ARM}\sqrt{p_x^2 + p_y^2 - h^2}` and
:math:`\varphi_1 = \mathrm{atan2}(p_y, p_x) - \mathrm{atan2}(-\sigma_1 h, \rho)`.

Arm plane. :math:`(u, v) = (\rho - a_1,\ \sigma_1 (p_z - d_1))` is reached by a planar pair:

* RRR: links :math:`a_2` and :math:`\ell_3 = |(a_3, -d_4 \sin\alpha_3)|` (angle :math:`\beta`);
  the elbow angle :math:`\gamma = \varphi_3 + \beta` satisfies
  :math:`\cos\gamma = (D - a_2^2 - \ell_3^2) / (2 a_2 \ell_3)` with :math:`D = u^2 + v^2`;
  :math:`\mathrm{ELBOW} = \mathrm{sign}(\sin\gamma)`.
* RRP: :math:`(u, v) = R(\varphi_2)(a_2, t)`, :math:`t = -\sigma_2 (q_3 + d_3)`,
  :math:`t = -\mathrm{ELBOW}\sqrt{D - a_2^2}` (the sign convention of the paper's Appendix III).

Wrist. With :math:`M = R_{in}^T R_{flange} E^T = R_z(\varphi_4) R_x(\alpha_4) R_z(\varphi_5)
R_x(\alpha_5) R_z(\varphi_6)` and :math:`\sigma_{4,5} = \sin\alpha_{4,5} = \pm 1`:
:math:`M e_z = (\sigma_5 S_5 C_4,\ \sigma_5 S_5 S_4,\ -\sigma_4\sigma_5 C_5)`, so with
:math:`\mathrm{WRIST} = \mathrm{sign}(\sin\varphi_5)`,
:math:`\varphi_4` and :math:`\varphi_5` are atan2s of entries of M, and :math:`\varphi_6` is the angle of the
residual :math:`(R_z(\varphi_4) R_x(\alpha_4) R_z(\varphi_5) R_x(\alpha_5))^T M`.
At :math:`\sin\varphi_5 = 0` (rule 3 of the paper) :math:`q_4` keeps its previous value;
likewise :math:`q_1` (rule 1) when the wrist centre is on the axis of joint 1. Every angle
comes from atan2, never acos, so that precision holds near singular joints.

The closed form is C (``csrc/ik/six_dof.c``). The family codes and the parameter vector's layout
are written once, in ``csrc/ik/om_kernels.h``: Python reads them from :mod:`om_redundant._core`
(``_core.RRR_SPHERICAL_WRIST``, ``_core.SD_A1``, ... ``_core.SD_N_PARAMS``) where it uses them.
"""

from __future__ import annotations
