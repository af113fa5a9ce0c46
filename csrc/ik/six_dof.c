/* 6-DOF model arms with a spherical wrist (RRR and RRP position families): the math is in
 * om_redundant/ik/families/six_dof.py. */
#include "om_kernels.h"


/* Joint 1 for the wrist centre pw and the ARM sign, into q[0], and the wrist centre in the arm
 * plane, (u, v) (six_dof.py). Returns the shoulder's reach margin (q[0], u, v not written below
 * out_of_reach). */
static double _shoulder(const double *P, vec3 pw, const int64_t *signs, const double *q_prev, double *q,
                        double out_of_reach, double *u, double *v)
{
    double h = P[SD_LATERAL];
    double r2 = pw.x * pw.x + pw.y * pw.y;
    double k = r2 - h * h;
    double margin = k / py_max(r2, 1.0);
    if (margin < out_of_reach)
        return margin;
    double rho = (double)signs[0] * sqrt(py_max(k, 0.0));
    double phi1;
    if (r2 < 1e-24) /* rule 1: wrist centre on joint 1's axis */
        phi1 = q_prev[0] + P[SD_THETA1];
    else
        phi1 = atan2(pw.y, pw.x) - atan2(-P[SD_SIGMA1] * h, rho);
    q[0] = om_wrap(phi1 - P[SD_THETA1]);
    *u = cos(phi1) * pw.x + sin(phi1) * pw.y - P[SD_A1];
    *v = P[SD_SIGMA1] * (pw.z - P[SD_D1]);
    return margin;
}

/* Joint 2 of the RRR family for the arm plane's (u, v), D = u^2 + v^2, and the elbow angle
 * gamma = phi3 + beta, into q[1]; joint 3 into q[2]. */
static void _rrr_joints_2_3(const double *P, double u, double v, double D, double gamma, const double *q_prev,
                            double *q)
{
    double l3 = P[SD_ELL3], phi2;
    if (D < 1e-24) /* rule 2: wrist centre on joint 2's axis */
        phi2 = q_prev[1] + P[SD_THETA2];
    else
        phi2 = atan2(v, u) - atan2(l3 * sin(gamma), P[SD_A2] + l3 * cos(gamma));
    q[1] = om_wrap(phi2 - P[SD_THETA2]);
    q[2] = om_wrap(gamma - P[SD_BETA] - P[SD_THETA3]);
}

/* The wrist's rotation M = R_in^T R E^T = Rz(phi4) Rx(alpha4) Rz(phi5) Rx(alpha5) Rz(phi6),
 * R_in the frame before joint 4's row at joints 1-3 of q. */
static mat3 _wrist_rotation(const double *P, const double *table, const om_target *t, const double *q)
{
    double Rin[9], pin[3];
    for (int i = 0; i < 9; i++)
        Rin[i] = (i % 4 == 0) ? 1.0 : 0.0;
    pin[0] = pin[1] = pin[2] = 0.0;
    int j = 0;
    for (int row = 0; row < (int)P[SD_WRIST_ROW]; row++) {
        if (table[OM_DH_COLUMNS * row + OM_DH_KIND] == OM_JOINT_FIXED) {
            om_apply_row(Rin, pin, table + 6 * row, 0.0);
        } else {
            om_apply_row(Rin, pin, table + 6 * row, q[j]);
            j++;
        }
    }
    return m_mtm(m_load(Rin, 0), t->RE);
}

/* Joints 1-3 for the flange pose (t->R, p) in DH frame 0 and the ARM and ELBOW signs, into q,
 * and the wrist's rotation M (_wrist_rotation) into *M. Returns the reach margin: below
 * -OM_REACH_SLACK the pose is out of reach and neither is written, unless nearest: then both
 * are, with the square roots of the reach's conditions held at zero (the shoulder's, the
 * elbow's: the nearest pose the model reaches). */
static double position_and_wrist(int family, const double *P, const double *table, const om_target *t, vec3 p,
                                 const int64_t *signs, const double *q_prev, double *q, mat3 *M, bool nearest)
{
    double out_of_reach = nearest ? -INFINITY : -OM_REACH_SLACK;
    double u, v;
    double margin = _shoulder(P, v_add(t->wrist, p), signs, q_prev, q, out_of_reach, &u, &v);
    if (margin < out_of_reach)
        return margin;
    double D = u * u + v * v;
    double a2 = P[SD_A2], k;
    if (family == OM_RRR_SPHERICAL_WRIST) {
        double l3 = P[SD_ELL3];
        double outer = fabs(a2) + l3, inner = fabs(a2) - l3;
        k = (outer * outer - D) * (D - inner * inner);
        margin = py_min(margin, k / py_max(D * D, 1.0));
        if (margin < out_of_reach)
            return margin;
        double gamma = atan2((double)signs[1] * sqrt(py_max(k, 0.0)), om_sign(a2) * (D - a2 * a2 - l3 * l3));
        _rrr_joints_2_3(P, u, v, D, gamma, q_prev, q);
    } else {
        k = D - a2 * a2;
        margin = py_min(margin, k / py_max(D, 1.0));
        if (margin < out_of_reach)
            return margin;
        double t = (double)(-signs[1]) * sqrt(py_max(k, 0.0)), phi2;
        if (D < 1e-24)
            phi2 = q_prev[1] + P[SD_THETA2];
        else
            phi2 = atan2(v, u) - atan2(t, a2);
        q[1] = om_wrap(phi2 - P[SD_THETA2]);
        q[2] = -P[SD_SIGMA2] * t - P[SD_D3];
    }
    *M = _wrist_rotation(P, table, t, q);
    return margin;
}

/* What the closed form needs of the target orientation R alone: R E^T and R times the
 * wrist centre's offset from the flange. */
void om_six_dof_target(const double *P, om_target *t)
{
    t->RE = m_mmt(t->R, m_load(P, SD_E_ROT));
    t->wrist = m_mv(t->R, v_load(P, SD_WRIST_CENTRE));
}

/* Solve the model arm for the flange pose (t->R, p) in DH frame 0 and the branch signs
 * (ARM, ELBOW, WRIST); write q. Returns the reach margin (model_ik): below -OM_REACH_SLACK the
 * pose is out of reach and q is not written, unless nearest (position_and_wrist's). */
double om_six_dof_model_ik(int family, const double *P, const double *table, const om_target *t, vec3 p,
                           const int64_t *signs, const double *q_prev, double *q, bool nearest)
{
    mat3 M;
    double margin = position_and_wrist(family, P, table, t, p, signs, q_prev, q, &M, nearest);
    if (margin < -OM_REACH_SLACK && !nearest)
        return margin;
    vec3 phi = om_euler_zxzxz(M, P[SD_SIGMA4], P[SD_SIGMA5], 0.0, (double)signs[2], q_prev[3] + P[SD_THETA4]);
    q[3] = om_wrap(phi.x - P[SD_THETA4]);
    q[4] = om_wrap(phi.y - P[SD_THETA5]);
    q[5] = om_wrap(phi.z - P[SD_THETA6]);
    return margin;
}

/* Joints 4 and 5 from the wrist's rotation M with q6 given, phi6 first: into q (q6 as given);
 * returns the wrist's consistency N22 (om_six_dof_model_ik_q6). */
static double _wrist_given_q6(const double *P, mat3 M, double q6, double *q)
{
    vec3 neg = om_euler_zxzxz_given_first(m_transpose(M), -P[SD_SIGMA5], 0.0, -P[SD_SIGMA4], -(q6 + P[SD_THETA6]));
    q[3] = om_wrap(-neg.y - P[SD_THETA4]);
    q[4] = om_wrap(-neg.x - P[SD_THETA5]);
    q[5] = q6;
    return neg.z;
}

/* The closed form with q6 given (as the S-R-S lifted system takes q7): joints 1-3 as in
 * om_six_dof_model_ik, joints 4 and 5 from M^T = Rz(-phi6) Rx(-alpha5) Rz(-phi5) Rx(-alpha4)
 * Rz(-phi4) with phi6 first (om_euler_zxzxz_given_first), which is smooth also at the wrist
 * singularity sin(phi5) = 0, where the closed form's q4 and q6 swing by pi. Writes q (q6 as
 * given) and *residual, the wrist's consistency (zero iff q6 fits M); returns the margin. */
double om_six_dof_model_ik_q6(int family, const double *P, const double *table, const om_target *t, vec3 p,
                              const int64_t *signs, const double *q_prev, double q6, double *q, double *residual)
{
    mat3 M;
    double margin = position_and_wrist(family, P, table, t, p, signs, q_prev, q, &M, false);
    if (margin < -OM_REACH_SLACK)
        return margin;
    *residual = _wrist_given_q6(P, M, q6, q);
    return margin;
}

/* The wrist's residuals at joints 1-3 of q with q5 and q6 given: joints 4 and 5 into q
 * (_wrist_given_q6); returns the wrist's consistency N22, phi5 less q5's into *joint5: zero
 * together iff q5 and q6 fit the target. */
static double _wrist_given_q5_q6(const double *P, const double *table, const om_target *t, double q5, double q6,
                                 double *q, double *joint5)
{
    double wrist = _wrist_given_q6(P, _wrist_rotation(P, table, t, q), q6, q);
    *joint5 = om_wrap(q[4] - q5);
    return wrist;
}

/* The elbow's cosine x = (D - a2^2 - l3^2) / (2 a2 l3) that the wrist centre asks for (D the
 * squared reach in the arm plane), into *x; returns gamma if given, else (NaN) the root of x =
 * cos(gamma) in the ELBOW branch elbow, x clamped into [-1, 1]. */
static double _elbow(const double *P, double D, double gamma, double elbow, double *x)
{
    double a2 = P[SD_A2], l3 = P[SD_ELL3];
    *x = (D - a2 * a2 - l3 * l3) / (2.0 * a2 * l3);
    if (!isnan(gamma))
        return gamma;
    double xc = py_min(py_max(*x, -1.0), 1.0);
    return atan2(elbow * sqrt(1.0 - xc * xc), xc);
}

/* The lifted model IK of the RRR family on the torus (q5, q6) of a PUMA-like wrist (the
 * S-R-S one's: om_srs_model_ik_lifted), with q5, q6 and the elbow angle gamma = phi3 + beta given
 * (gamma NaN: the elbow's root in the ELBOW branch, x clamped into [-1, 1]): joint 1 from the
 * wrist centre (ARM), joints 2 and 3 from gamma, and joints 4 and 5 from the wrist's rotation
 * (_wrist_given_q5_q6). Returns the (wrist, joint 5, elbow) residuals, zero together iff q is
 * the model's solution: the wrist's, and x - cos(gamma), x = (D - a2^2 - l3^2) / (2 a2 l3) the
 * elbow's cosine that the wrist centre asks for (smooth where the closed form's square root
 * is not: at the edge of reach); NaN beyond the shoulder's reach (q not written). Writes q
 * (unless NULL), q6 as given. */
vec3 om_six_dof_model_ik_lifted(const double *P, const double *table, const om_target *t, vec3 p,
                                const int64_t *signs, const double *q_prev, double q5, double q6, double gamma,
                                double *q)
{
    double joints[OM_MAX_DOF], u, v, joint5, x;
    double *out = q ? q : joints;
    if (_shoulder(P, v_add(t->wrist, p), signs, q_prev, out, -OM_REACH_SLACK, &u, &v) < -OM_REACH_SLACK)
        return v3(NAN, NAN, NAN);
    double D = u * u + v * v;
    gamma = _elbow(P, D, gamma, (double)signs[1], &x);
    _rrr_joints_2_3(P, u, v, D, gamma, q_prev, out);
    double wrist = _wrist_given_q5_q6(P, table, t, q5, q6, out, &joint5);
    return v3(wrist, joint5, x - cos(gamma));
}

/* The same model IK about joint 1's axis, with q5, q6, q1 and the elbow angle gamma given (x:
 * these four; gamma NaN: the elbow's root in the ELBOW branch, as om_six_dof_model_ik_lifted's):
 * where the wrist centre is on the axis, or h from it (the shoulder's edge of reach), the closed
 * form's q1 turns about a point or has a square root; with q1 given, the reach in the arm plane
 * is the centre's signed part along phi1, rho (ARM its sign), and nothing has a square root,
 * the elbow's edge included. Joints 2 and 3 from gamma, 4 and 5 as om_six_dof_model_ik_lifted's.
 * Writes q (q6 as given) and the (wrist, joint 5, shoulder, elbow) residuals into F, the
 * shoulder's the centre's part across phi1 less the lateral offset's, -sigma1 h (m). */
void om_six_dof_model_ik_about_axis(const double *P, const double *table, const om_target *t, vec3 p,
                                    const int64_t *signs, const double *q_prev, const double *x, double *q, double *F)
{
    vec3 pw = v_add(t->wrist, p);
    double phi1 = x[2] + P[SD_THETA1], c1 = cos(phi1), s1 = sin(phi1);
    double u = c1 * pw.x + s1 * pw.y - P[SD_A1], v = P[SD_SIGMA1] * (pw.z - P[SD_D1]);
    double D = u * u + v * v, elbow;
    double gamma = _elbow(P, D, x[3], (double)signs[1], &elbow);
    q[0] = om_wrap(x[2]);
    _rrr_joints_2_3(P, u, v, D, gamma, q_prev, q);
    F[0] = _wrist_given_q5_q6(P, table, t, x[0], x[1], q, &F[1]);
    F[2] = -s1 * pw.x + c1 * pw.y + P[SD_SIGMA1] * P[SD_LATERAL];
    F[3] = elbow - cos(gamma);
}

vec3 om_six_dof_wrist_delta(const double *P, double w5, double w6, vec3 *d5, vec3 *d6)
{
    double c5 = cos(w5), s5 = sin(w5), c6 = cos(w6), s6 = sin(w6);
    const double t5[3] = {1.0, c5, s5}, t6[3] = {1.0, c6, s6}, dt5[3] = {0.0, -s5, c5}, dt6[3] = {0.0, -s6, c6};
    vec3 delta = v3(0.0, 0.0, 0.0), e5 = delta, e6 = delta;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            vec3 C = v_load(P, SD_WRIST_TORUS + 3 * (3 * i + j));
            delta = v_add(delta, v_scale(t5[i] * t6[j], C));
            if (d5) {
                e5 = v_add(e5, v_scale(dt5[i] * t6[j], C));
                e6 = v_add(e6, v_scale(t5[i] * dt6[j], C));
            }
        }
    if (d5)
        *d5 = e5, *d6 = e6;
    return delta;
}

/* The model's hand position on the torus of a PUMA-like wrist, p_m = p_d + R delta(w5, w6)
 * (SD_WRIST_TORUS). */
vec3 om_six_dof_torus_point(const double *P, const mat3 *R, vec3 p, double w5, double w6)
{
    return v_add(p, m_mv(*R, om_six_dof_wrist_delta(P, w5, w6, NULL, NULL)));
}

/* The quantities whose signs are (ARM, ELBOW, WRIST) at joint vector q, into out[0..2]. */
void om_six_dof_branch_values(int family, const double *P, const double *q, double *out)
{
    double phi2 = q[1] + P[SD_THETA2];
    double u;
    if (family == OM_RRR_SPHERICAL_WRIST) {
        double gamma = q[2] + P[SD_THETA3] + P[SD_BETA];
        u = P[SD_A2] * cos(phi2) + P[SD_ELL3] * cos(phi2 + gamma);
        out[1] = sin(gamma);
    } else {
        double t = -P[SD_SIGMA2] * (q[2] + P[SD_D3]);
        u = P[SD_A2] * cos(phi2) - t * sin(phi2);
        out[1] = -t;
    }
    out[0] = P[SD_A1] + u;
    out[2] = sin(q[4] + P[SD_THETA5]);
}
