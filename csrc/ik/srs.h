/* What the S-R-S model arm's closed form (srs.c) and its arm angle (srs_arm_angle.c) share. */
#ifndef OM_SRS_H
#define OM_SRS_H

#include "om_kernels.h"

#define DEGENERATE 1e-12 /* |W - S|^2 below which the wrist centre is at the shoulder centre */

/* Rx(alpha) with sin(alpha) = sigma = +-1. */
static inline mat3 rx(double sigma)
{
    mat3 A = {v3(1.0, 0.0, 0.0), v3(0.0, 0.0, -sigma), v3(0.0, sigma, 0.0)};
    return A;
}

/* 1 + up . w_hat for unit vectors, v = up x w_hat: to its last digits also near w_hat = -up,
 * where 1 + up . w_hat = |v|^2 / (1 - up . w_hat) has no cancellation (1 + up . w_hat
 * itself keeps only 1e-16 of it: relative error 1e-16 / angle^2 from the half-line). */
static inline double one_plus_cos(vec3 up, vec3 w_hat, vec3 v)
{
    double c = v_dot(up, w_hat);
    return c < 0.0 ? v_dot(v, v) / (1.0 - c) : 1.0 + c;
}

/* v(phi4) = Rz(phi4) u - s3: W - S in frame 3, for c4 = cos(phi4), s4 = sin(phi4). */
static inline vec3 elbow_vector(const double *P, double c4, double s4)
{
    vec3 u = v_load(P, SRS_U), s3 = v_load(P, SRS_S3);
    return v3(c4 * u.x - s4 * u.y - s3.x, s4 * u.x + c4 * u.y - s3.y, u.z - s3.z);
}

#endif
