/* The dp circle of a 6-DOF arm whose wrist has a4 != 0 (the method: om_redundant/ik/model.py,
 * _wrist_offset). With joints 2, 3 and 4 parallel, joint 4's axis z3 turns with q1 alone and
 * joint 6's axis z5 is the target's; joint 5's axis is normal to both, z4 = -sigma4 sigma5
 * WRIST (z3 x z5) / |z3 x z5| (|z3 x z5| = |sin phi5|), so at a solution
 * dp = -(a4 x4 + d5 z4 + a5 x5), x4 = sigma4 z3 x z4, x5 = sigma5 z4 x z5, depends on w = q1. */
#include "om_kernels.h"

#define SINGULAR_WRIST 1e-300 /* |z3 x z5| below which z4 is undefined (axes 4 and 6 parallel) */

vec3 om_wrist_offset_point(const double *P, const om_target *t, vec3 p, double wrist, double w)
{
    double c = cos(w), s = sin(w);
    vec3 z3 = v_add(v_load(P, SD_AXIS4),
                    v_add(v_scale(c, v_load(P, SD_AXIS4 + 3)), v_scale(s, v_load(P, SD_AXIS4 + 6))));
    vec3 z5 = m_mv(t->R, v_load(P, SD_AXIS6));
    vec3 n = v_cross(z3, z5);
    double size = sqrt(v_dot(n, n));
    if (!(size > SINGULAR_WRIST))
        return v3(NAN, NAN, NAN);
    vec3 z4 = v_scale(-P[SD_SIGMA4] * P[SD_SIGMA5] * wrist / size, n);
    vec3 x4 = v_scale(P[SD_SIGMA4], v_cross(z3, z4));
    vec3 x5 = v_scale(P[SD_SIGMA5], v_cross(z4, z5));
    vec3 offset = v_add(v_add(v_scale(P[SD_WRIST_OFFSET], x4), v_scale(P[SD_WRIST_OFFSET + 1], z4)),
                        v_scale(P[SD_WRIST_OFFSET + 2], x5));
    return v_sub(p, offset);
}
