/* The Euler decomposition of a revolute triple with intersecting axes (a spherical shoulder
 * or wrist): see om_redundant/ik/families/common.py for the math.
 * Every expression keeps the Python operand order (numba evaluates left to right). */
#include "om_kernels.h"

/* atan2(y, x) with its cos and sin (*c, *s); the fallback angle where x = y = 0. */
static double angle(double y, double x, double fallback, double *c, double *s)
{
    double r = sqrt(x * x + y * y);
    if (r > 0.0) {
        *c = x / r;
        *s = y / r;
        return atan2(y, x);
    }
    *c = cos(fallback);
    *s = sin(fallback);
    return fallback;
}

/* (phi_a, phi_b, phi_c) with M = Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(beta) Rz(phi_c); see euler_zxzxz. */
vec3 om_euler_zxzxz(mat3 M, double sigma_a, double sin_b, double cos_b, double sign, double phi_a_singular)
{
    double ax = M.r0.z, ay = M.r1.z, az = M.r2.z;
    /* |S_beta S_b| from the length of M e_z's xy part; Python's max(t, 0.0). */
    double t = ax * ax + ay * ay - cos_b * cos_b;
    double radial = sqrt(0.0 > t ? 0.0 : t);
    double sb_sign = sin_b > 0.0 ? 1.0 : -1.0;
    double cb, sb, ca, sa, phi_a;
    double phi_b = angle(sign * radial, -sigma_a * sb_sign * az, 0.0, &cb, &sb);
    if (radial > OM_SINGULAR) {
        double px = sin_b * sb, py = -sigma_a * cos_b;
        phi_a = angle(px * ay - py * ax, px * ax + py * ay, phi_a_singular, &ca, &sa);
    } else {
        phi_a = phi_a_singular;
        ca = cos(phi_a_singular);
        sa = sin(phi_a_singular);
    }
    /* Columns 0 and 1 of A = Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(beta), dotted with M's first
     * column, give cos and sin of phi_c. */
    vec3 m0 = m_col(M, 0);
    double x00 = v_dot(v3(cb * ca, cb * sa, sb * sigma_a), m0);
    double x10 = v_dot(v3(sa * sigma_a * sin_b - ca * sb * cos_b, -ca * sigma_a * sin_b - sa * sb * cos_b,
                          sigma_a * cb * cos_b),
                       m0);
    return v3(phi_a, phi_b, atan2(x10, x00));
}

/* (phi_b, phi_c, residual N22) for phi_a given; see euler_zxzxz_given_first. */
vec3 om_euler_zxzxz_given_first(mat3 M, double sin_a, double cos_a, double sigma_b, double phi_a)
{
    double ca = cos(phi_a), sa = sin(phi_a);
    /* Rz(-phi_a) M, rows 0-2; then Rx(alpha_a)^T mixes rows 1 and 2 (as om_euler_given_first_residual). */
    vec3 r0 = v_add(v_scale(ca, M.r0), v_scale(sa, M.r1));
    vec3 r1 = v_sub(v_scale(ca, M.r1), v_scale(sa, M.r0));
    vec3 n1 = v_add(v_scale(cos_a, r1), v_scale(sin_a, M.r2));
    vec3 n2 = v_sub(v_scale(cos_a, M.r2), v_scale(sin_a, r1));
    double phi_b = atan2(sigma_b * r0.z, -sigma_b * n1.z);
    double phi_c = atan2(sigma_b * n2.x, sigma_b * n2.y);
    return v3(phi_b, phi_c, om_euler_given_first_residual(M, sin_a, cos_a, ca, sa));
}
