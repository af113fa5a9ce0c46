/* The arm angle psi of an S-R-S model arm at joints q, its half-line, branch values and
 * gradient: the math is in the docstrings of om_redundant/redundancy/arm_angle.py. */
#include "srs.h"

/* R03 for trig: cos and sin of phi_j = q_j + theta_j, j = 1..3 (_rotation_03). */
static mat3 rotation_03(const double *P, const double *trig)
{
    mat3 R = m_mm(m_load(P, SRS_R_PRE), m_rz_cs_times(trig[0], trig[1], rx(P[SRS_SIGMA1])));
    R = m_mm(R, m_rz_cs_times(trig[2], trig[3], rx(P[SRS_SIGMA2])));
    return m_mm(R, m_rz_cs_times(trig[4], trig[5], m_load(P, SRS_X3)));
}

/* The model's arm angle psi at joint vector q (arm_angle). */
double om_srs_arm_angle(const double *P, const double *q)
{
    return om_srs_arm_angle_in(P, q, sin(q[3] + P[SRS_THETA + 3] - P[SRS_PHI_STAR]) < 0.0 ? -1.0 : 1.0);
}

/* cos and sin of phi_j = q_j + theta_j, j = 1..4, into trig (8 values). */
static void joint_trig(const double *P, const double *q, double *trig)
{
    for (int j = 0; j < 4; j++) {
        double phi = q[j] + P[SRS_THETA + j];
        trig[2 * j] = cos(phi);
        trig[2 * j + 1] = sin(phi);
    }
}

/* psi at q read in the ELBOW branch `elbow` (+-1): the elbow plane's normal flips with the
 * branch, so at a straight elbow (both branches) psi is the requested branch's. */
double om_srs_arm_angle_in(const double *P, const double *q, double elbow)
{
    double trig[8];
    joint_trig(P, q, trig);
    return om_srs_arm_angle_trig(P, trig, elbow);
}

/* The model's shoulder-wrist vector w = W - S for trig (cos and sin of phi_j = q_j + theta_j,
 * j = 1..4), its rotation R03 into *R03. */
static vec3 shoulder_wrist(const double *P, const double *trig, mat3 *R03)
{
    *R03 = rotation_03(P, trig);
    return m_mv(*R03, elbow_vector(P, trig[6], trig[7]));
}

/* shoulder_wrist at joint vector q. */
static vec3 shoulder_wrist_at(const double *P, const double *q, mat3 *R03)
{
    double trig[8];
    joint_trig(P, q, trig);
    return shoulder_wrist(P, trig, R03);
}

/* psi for R03 and w = W - S, read in the ELBOW branch `elbow`. */
static double arm_angle_of(const double *P, mat3 R03, vec3 w, double elbow)
{
    vec3 w_hat = v_unit(w);
    vec3 n, nw;
    om_srs_reference(P, w_hat, &n, &nw);
    vec3 b = v_scale(elbow * P[SRS_BEND], v_cross(m_col(R03, 2), w_hat));
    return atan2(v_dot(nw, b), v_dot(n, b));
}

/* om_srs_arm_angle_in from trig: cos and sin of phi_j = q_j + theta_j, j = 1..4 (8 values). */
double om_srs_arm_angle_trig(const double *P, const double *trig, double elbow)
{
    mat3 R03;
    vec3 w = shoulder_wrist(P, trig, &R03);
    return arm_angle_of(P, R03, w, elbow);
}

/* The angle of w = W - S from psi's singular half-line w_hat = -up (the wrist centre straight
 * below the shoulder), across = up x w its part across up turned by pi / 2. */
static double line_angle(const double *P, vec3 w, vec3 across)
{
    return atan2(sqrt(v_dot(across, across)), -v_dot(v_load(P, SRS_UP), w));
}

/* up x (W - S) of the model at q: zero on psi's singular half-line and on its continuation above. */
vec3 om_srs_half_line_across(const double *P, const double *q)
{
    mat3 R03;
    return v_cross(v_load(P, SRS_UP), shoulder_wrist_at(P, q, &R03));
}

double om_srs_half_line_angle(const double *P, const double *q)
{
    mat3 R03;
    vec3 w = shoulder_wrist_at(P, q, &R03);
    return line_angle(P, w, v_cross(v_load(P, SRS_UP), w));
}

double om_srs_half_line_psi(const double *P, const double *q, double elbow, vec3 *across, double *angle)
{
    mat3 R03;
    vec3 w = shoulder_wrist_at(P, q, &R03);
    *across = v_cross(v_load(P, SRS_UP), w);
    *angle = line_angle(P, w, *across);
    return arm_angle_of(P, R03, w, elbow);
}

/* The quantities whose signs are (SHOULDER, ELBOW, WRIST) at joint vector q, into out[0..2]. */
void om_srs_branch_values(const double *P, const double *q, double *out)
{
    const double *th = P + SRS_THETA;
    out[0] = sin(q[1] + th[1]);
    out[1] = sin(q[3] + th[3] - P[SRS_PHI_STAR]);
    out[2] = sin(q[5] + th[5]);
}

/* om_srs_branch_values from trig: cos and sin of q_j + theta_j for j = 1..6, as the real FK
 * computed them where they are the model's (om_trig_shared). */
void om_srs_branch_values_trig(const double *P, const double *q, const double *trig, double *out)
{
    out[0] = trig[3];
    out[1] = sin(q[3] + P[SRS_THETA + 3] - P[SRS_PHI_STAR]);
    out[2] = trig[11];
}

/* psi at q of the S-R-S model with parameters P and DH table, and d psi / dq into grad[0..6]
 * unless grad is NULL (arm_angle_gradient_kernel; psi depends on joints 1-4 only). */
double om_arm_angle_gradient(const double *P, const double *table, int n_rows, const double *q, double *grad)
{
    /* The frames of joints 1-6 in DH frame 0; S is the origin after joint 1's row, W the one
     * after joint 5's row. */
    double frames[6 * 12], R[9], p[3];
    om_joint_frames(table, n_rows, q, 6, frames, R, p);
    vec3 S = v_load(frames + 12, 9), W = v_load(frames + 60, 9), z4 = om_frame_axis(frames + 36);
    vec3 w = v_sub(W, S);
    double length = sqrt(v_dot(w, w));
    vec3 w_hat = v_scale(1.0 / length, w);
    double elbow = sin(q[3] + P[SRS_THETA + 3] - P[SRS_PHI_STAR]) < 0.0 ? -1.0 : 1.0;
    double bend = elbow * P[SRS_BEND];
    vec3 b = v_scale(bend, v_cross(z4, w_hat));
    vec3 n, nw;
    om_srs_reference(P, w_hat, &n, &nw);
    vec3 up = v_load(P, SRS_UP);
    vec3 wb = v_cross(w_hat, b);
    double bb = v_dot(b, b);
    double twist = 1.0 / one_plus_cos(up, w_hat, v_cross(up, w_hat));
    for (int j = 0; grad && j < 7; j++)
        grad[j] = 0.0;
    for (int j = 0; grad && j < 4; j++) {
        vec3 zj = om_frame_axis(frames + 12 * j), oj = v_load(frames + 12 * j, 9);
        vec3 dW = v_cross(zj, v_sub(W, oj));
        vec3 dw_hat = v_scale(1.0 / length, v_sub(dW, v_scale(v_dot(w_hat, dW), w_hat)));
        vec3 dz4 = j < 3 ? v_cross(zj, z4) : v3(0.0, 0.0, 0.0);
        vec3 db = v_scale(bend, v_add(v_cross(dz4, w_hat), v_cross(z4, dw_hat)));
        grad[j] = v_dot(wb, db) / bb + v_dot(up, v_cross(w_hat, dw_hat)) * twist;
    }
    return atan2(v_dot(nw, b), v_dot(n, b));
}
