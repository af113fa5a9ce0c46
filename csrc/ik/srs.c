/* 7-DOF S-R-S model arms (spherical shoulder, elbow, spherical wrist): the closed form at an
 * arm angle (its arm angle and gradient at q: srs_arm_angle.c). The math and the parameter
 * layout are in the docstrings of om_redundant/ik/families/srs.py. */
#include "srs.h"

/* |sin phi6 sin beta| below which om_srs_model_q7 leaves q7 to the closed form: q7 is
 * ill-conditioned there (rounding / |sin phi6|), and both ways must round alike. */
#define NEAR_SINGULAR_WRIST 1e-3


/* The arm angle's reference direction n(w_hat) = R(up -> w_hat) r, and w_hat x n (_reference). */
void om_srs_reference(const double *P, vec3 w_hat, vec3 *n, vec3 *nw)
{
    vec3 up = v_load(P, SRS_UP), r = v_load(P, SRS_REF);
    vec3 v = v_cross(up, w_hat);
    vec3 vr = v_cross(v, r);
    *n = v_unit(v_add(v_add(r, vr), v_scale(1.0 / py_max(one_plus_cos(up, w_hat, v), 1e-300), v_cross(v, vr))));
    *nw = v_cross(w_hat, *n);
}

/* What every model solve for the target orientation R and arm angle psi shares: cos and sin
 * of psi, R E^T, and R w_F - S (the wrist centre less the shoulder for flange position p is
 * p + wrist). */
void om_srs_target(const double *P, om_target *t)
{
    t->cos_psi = cos(t->psi);
    t->sin_psi = sin(t->psi);
    t->RE = m_mmt(t->R, m_load(P, SRS_E_ROT));
    t->wrist = v_sub(m_mv(t->R, v_load(P, SRS_WRIST)), v_load(P, SRS_SHOULDER));
}

/* The root phi4 of x = cos(phi4 - phi*) in the ELBOW branch, x clamped into [-1, 1]: its
 * cos and sin without trig, cos(phi4 - phi*) = x and sin(phi4 - phi*) = ELBOW sqrt(1 - x^2)
 * turned by phi*; and (phi4 not NULL) the angle itself. */
typedef struct {
    double c4, s4;
} elbow_cs;

static elbow_cs elbow_root(const double *P, double x, double elbow, double *phi4)
{
    double xc = py_min(py_max(x, -1.0), 1.0);
    double y = elbow * sqrt(1.0 - xc * xc);
    double c = P[SRS_COS_PHI_STAR], s = P[SRS_SIN_PHI_STAR];
    if (phi4)
        *phi4 = P[SRS_PHI_STAR] + atan2(y, xc);
    elbow_cs e = {c * xc - s * y, s * xc + c * y};
    return e;
}

/* w_hat = w / |w| for W - S = w (L2 = |w|^2), and the arm angle's reference n, w_hat x n there. */
static void shoulder_wrist_triad(const double *P, vec3 w, double L2, vec3 *w_hat, vec3 *n, vec3 *nw)
{
    *w_hat = v_scale(1.0 / sqrt(L2), w);
    om_srs_reference(P, *w_hat, n, nw);
}

/* The frame-3 triad (v_hat, b3_hat, v_hat x b3_hat) as rows, for the elbow angle phi4 (cos
 * c4, sin s4) in the ELBOW branch `elbow`. */
static mat3 elbow_triad(const double *P, double c4, double s4, double elbow)
{
    vec3 v = elbow_vector(P, c4, s4);
    vec3 v_hat = v_unit(v);
    vec3 b3 = v_unit(v_scale(elbow * P[SRS_BEND], v3(-v.y, v.x, 0.0)));
    mat3 B = {v_hat, b3, v_cross(v_hat, b3)};
    return B;
}

/* R03 for the target's arm angle: it maps the frame-3 triad B (elbow_triad) onto (w_hat, m,
 * w_hat x m), m = n cos psi + (w_hat x n) sin psi. */
static mat3 rotation_03_of(const om_target *t, vec3 w_hat, vec3 n, vec3 nw, mat3 B)
{
    vec3 m = v_add(v_scale(t->cos_psi, n), v_scale(t->sin_psi, nw));
    mat3 A = {w_hat, m, v_cross(w_hat, m)};
    return m_mtm(A, B);
}

/* R03 for W - S = w, the elbow angle phi4 (cos c4, sin s4) and the target's arm angle. */
static mat3 rotation_03_at(const double *P, const om_target *t, vec3 w, double L2, double c4, double s4,
                           double elbow)
{
    vec3 w_hat, n, nw;
    shoulder_wrist_triad(P, w, L2, &w_hat, &n, &nw);
    return rotation_03_of(t, w_hat, n, nw, elbow_triad(P, c4, s4, elbow));
}

/* Joints 1-3 (if shoulder) and 4-7 for the elbow's root at x (elbow_root), W - S = w and the
 * target t. */
static void ik_with_elbow(const double *P, const om_target *t, vec3 w, double L2, double x,
                          const int64_t *signs, const double *q_prev, double *q, bool shoulder)
{
    const double *th = P + SRS_THETA;
    double phi4;
    elbow_cs e = elbow_root(P, x, (double)signs[1], &phi4);
    double c4 = e.c4, s4 = e.s4;
    mat3 R03 = rotation_03_at(P, t, w, L2, c4, s4, (double)signs[1]);
    if (shoulder) {
        vec3 phi = om_euler_zxzxz(m_mmt(m_mtm(m_load(P, SRS_R_PRE), R03), m_load(P, SRS_X3)), P[SRS_SIGMA1],
                                  P[SRS_SIGMA2], 0.0, (double)signs[0], q_prev[0] + th[0]);
        q[0] = om_wrap(phi.x - th[0]);
        q[1] = om_wrap(phi.y - th[1]);
        q[2] = om_wrap(phi.z - th[2]);
    }
    q[3] = om_wrap(phi4 - th[3]);
    mat3 R04 = m_mm(R03, m_rz_cs_times(c4, s4, m_load(P, SRS_X4)));
    mat3 M = m_mtm(R04, t->RE);
    vec3 phi = om_euler_zxzxz(M, P[SRS_SIGMA5], P[SRS_SIN_BETA], P[SRS_COS_BETA], (double)signs[2],
                              q_prev[4] + th[4]);
    q[4] = om_wrap(phi.x - th[4]);
    q[5] = om_wrap(phi.y - th[5]);
    q[6] = om_wrap(phi.z - th[6]);
}

/* W - S = w for the flange position p, L2 = |w|^2 and the elbow's x = (L2 - k0) / K; returns
 * the reach margin 1 - x^2 (-1 where W = S or w is not a number: x not written). */
static double reach(const double *P, const om_target *t, vec3 p, vec3 *w, double *L2, double *x)
{
    *w = v_add(p, t->wrist);
    *L2 = v_dot(*w, *w);
    if (!(*L2 >= DEGENERATE)) /* wrist centre at the shoulder centre, or not a number */
        return -1.0;
    *x = (*L2 - P[SRS_K0]) / P[SRS_K];
    return 1.0 - *x * *x;
}

double om_srs_reach(const double *P, const om_target *t, vec3 p, double *x)
{
    vec3 w;
    double L2;
    return reach(P, t, p, &w, &L2, x);
}

/* Solve the model for the flange pose (t->R, p) in DH frame 0, the branch signs
 * (SHOULDER, ELBOW, WRIST) and the target's arm angle (model_ik). Returns the reach margin
 * 1 - x^2; below -OM_REACH_SLACK (or -1 where W = S) q is not written. */
double om_srs_model_ik(const double *P, const om_target *t, vec3 p, const int64_t *signs, const double *q_prev,
                       double *q, bool shoulder)
{
    vec3 w;
    double L2, x;
    double margin = reach(P, t, p, &w, &L2, &x);
    if (margin < -OM_REACH_SLACK)
        return margin;
    ik_with_elbow(P, t, w, L2, x, signs, q_prev, q, shoulder);
    return margin;
}

/* What q7_with_elbow computes of the elbow's root at x, W - S = w and L2 = |w|^2 before the
 * target's arm angle enters (into e, its margin left to the caller). */
static void elbow_parts(const double *P, vec3 w, double L2, double x, double elbow, om_srs_elbow *e)
{
    elbow_cs root = elbow_root(P, x, elbow, NULL);
    e->w = w;
    e->L2 = L2;
    e->x = x;
    shoulder_wrist_triad(P, w, L2, &e->w_hat, &e->n, &e->nw);
    e->B = elbow_triad(P, root.c4, root.s4, elbow);
    e->X4 = m_rz_cs_times(root.c4, root.s4, m_load(P, SRS_X4));
}

/* The parts of the hand position p (reach, then elbow_parts within reach); returns the margin. */
double om_srs_elbow_at(const double *P, const om_target *t, vec3 p, double elbow, om_srs_elbow *e)
{
    vec3 w;
    double L2, x = NAN;
    e->margin = reach(P, t, p, &w, &L2, &x);
    e->x = x;
    if (e->margin >= -OM_REACH_SLACK)
        elbow_parts(P, w, L2, x, elbow, e);
    return e->margin;
}

/* The wrist's M = R04^T R E^T = Rz(phi5) Rx(alpha5) Rz(phi6) Rx(beta) Rz(phi7) is not formed:
 * its last column gives (sin phi6, cos phi6 cos beta) up to one positive factor (the Euler
 * decomposition's phi6), (u, v) with u = WRIST radial; its last row is sigma5 (u cos phi7 + v
 * sin phi7, v cos phi7 - u sin phi7) for that pair: (m20, m21) = (M[2][0], M[2][1]) give phi7
 * without phi5 (om_srs_q7_of). */
om_srs_wrist_terms om_srs_wrist_terms_of(const double *P, const om_target *t, const om_srs_elbow *e)
{
    mat3 R04 = m_mm(rotation_03_of(t, e->w_hat, e->n, e->nw, e->B), e->X4);
    mat3 RE_cols = m_transpose(t->RE);
    vec3 z4 = m_col(R04, 2); /* M[i][j] = (column i of R04) . (column j of R E^T) */
    double ax = v_dot(m_col(R04, 0), RE_cols.r2), ay = v_dot(m_col(R04, 1), RE_cols.r2), az = v_dot(z4, RE_cols.r2);
    double sigma = P[SRS_SIGMA5], sin_b = P[SRS_SIN_BETA], cos_b = P[SRS_COS_BETA];
    double radial_2 = ax * ax + ay * ay - cos_b * cos_b; /* as om_euler_zxzxz */
    om_srs_wrist_terms terms = {
        .radial = sqrt(0.0 > radial_2 ? 0.0 : radial_2),
        .v = -sigma * (sin_b > 0.0 ? 1.0 : -1.0) * az * cos_b,
        .m20 = v_dot(z4, RE_cols.r0),
        .m21 = v_dot(z4, RE_cols.r1),
    };
    return terms;
}

/* Near the wrist singularity (radial = 0), where the closed form takes phi5 from q_prev, it
 * decides q7. */
void om_srs_q7_of(const double *P, const om_target *t, const om_srs_elbow *e, const om_srs_wrist_terms *terms,
                  const int64_t *signs, const double *q_prev, double *q)
{
    if (!(terms->radial > NEAR_SINGULAR_WRIST)) {
        double wrist_joints[7];
        ik_with_elbow(P, t, e->w, e->L2, e->x, signs, q_prev, wrist_joints, false);
        q[6] = wrist_joints[6];
        return;
    }
    double sigma = P[SRS_SIGMA5], u = (double)signs[2] * terms->radial, v = terms->v;
    q[6] = om_wrap(atan2(sigma * (v * terms->m20 - u * terms->m21), sigma * (u * terms->m20 + v * terms->m21)) -
                   P[SRS_THETA + 6]);
}

/* Joint 7 alone, as ik_with_elbow computes it for the elbow's root at x (q[6] written, the
 * rest of q untouched): what the circle residual g needs of the model, in the three parts
 * above (elbow_parts, om_srs_wrist_terms_of, om_srs_q7_of), which a scan of the circle shares
 * between problems (circle.c). */
static void q7_with_elbow(const double *P, const om_target *t, vec3 w, double L2, double x, const int64_t *signs,
                          const double *q_prev, double *q)
{
    om_srs_elbow e;
    elbow_parts(P, w, L2, x, (double)signs[1], &e);
    om_srs_wrist_terms terms = om_srs_wrist_terms_of(P, t, &e);
    om_srs_q7_of(P, t, &e, &terms, signs, q_prev, q);
}

/* Joint 7 alone, as om_srs_model_ik computes it (q7_with_elbow). Returns the reach margin as
 * om_srs_model_ik. */
double om_srs_model_q7(const double *P, const om_target *t, vec3 p, const int64_t *signs, const double *q_prev,
                       double *q)
{
    vec3 w;
    double L2, x;
    double margin = reach(P, t, p, &w, &L2, &x);
    if (margin < -OM_REACH_SLACK)
        return margin;
    q7_with_elbow(P, t, w, L2, x, signs, q_prev, q);
    return margin;
}

/* The model IK with the elbow held at the edge of reach beyond it: every joint, or joint 7 alone
 * (as ik_with_elbow computes it); false, q untouched, only where W = S. */
static bool at_reach(const double *P, const om_target *t, vec3 p, const int64_t *signs, const double *q_prev,
                     double *q, bool every_joint)
{
    vec3 w;
    double L2, x;
    reach(P, t, p, &w, &L2, &x);
    if (!(L2 >= DEGENERATE)) /* x not written (reach) */
        return false;
    if (every_joint)
        ik_with_elbow(P, t, w, L2, x, signs, q_prev, q, true);
    else
        q7_with_elbow(P, t, w, L2, x, signs, q_prev, q);
    return true;
}

/* Joint 7 alone, as om_srs_model_ik_at_reach computes it. */
bool om_srs_model_q7_at_reach(const double *P, const om_target *t, vec3 p, const int64_t *signs,
                              const double *q_prev, double *q)
{
    return at_reach(P, t, p, signs, q_prev, q, false);
}

/* om_srs_model_ik with the elbow held at the edge of reach beyond it (model_ik_at_reach). */
bool om_srs_model_ik_at_reach(const double *P, const om_target *t, vec3 p, const int64_t *signs,
                              const double *q_prev, double *q)
{
    return at_reach(P, t, p, signs, q_prev, q, true);
}

bool om_srs_lifted_terms_at(const double *P, const om_target *t, vec3 p, double elbow, double q1, double q7,
                            double phi4, om_srs_lifted_terms *out)
{
    vec3 w = v_add(p, t->wrist);
    double L2 = v_dot(w, w);
    if (!(L2 >= DEGENERATE))
        return false;
    double x = (L2 - P[SRS_K0]) / P[SRS_K], c4, s4;
    if (isnan(phi4)) {
        elbow_cs e = elbow_root(P, x, elbow, &out->phi4);
        c4 = e.c4;
        s4 = e.s4;
    } else {
        out->phi4 = phi4;
        c4 = cos(phi4);
        s4 = sin(phi4);
    }
    vec3 w_hat, n, nw, zero = v3(0.0, 0.0, 0.0);
    shoulder_wrist_triad(P, w, L2, &w_hat, &n, &nw);
    mat3 B = elbow_triad(P, c4, s4, elbow);
    mat3 X4 = m_rz_cs_times(c4, s4, m_load(P, SRS_X4));
    /* A = {w_hat, m, w_hat x m} in parts: 1, cos psi, sin psi */
    const mat3 A[3] = {{w_hat, zero, zero}, {zero, n, v_cross(w_hat, n)}, {zero, nw, v_cross(w_hat, nw)}};
    const double *th = P + SRS_THETA;
    double a1 = q1 + th[0], a7 = -(q7 + th[6]);
    double c1 = cos(a1), s1 = sin(a1), c7 = cos(a7), s7 = sin(a7);
    for (int k = 0; k < 3; k++) {
        mat3 R03 = m_mtm(A[k], B);
        mat3 shoulder = m_mmt(m_mtm(m_load(P, SRS_R_PRE), R03), m_load(P, SRS_X3));
        mat3 wrist = m_transpose(m_mtm(m_mm(R03, X4), t->RE));
        out->shoulder[k] = om_euler_given_first_residual(shoulder, P[SRS_SIGMA1], 0.0, c1, s1);
        out->wrist[k] = om_euler_given_first_residual(wrist, -P[SRS_SIN_BETA], P[SRS_COS_BETA], c7, s7);
    }
    out->elbow = x - cos(out->phi4 - P[SRS_PHI_STAR]);
    return true;
}

/* The model IK with q1, q7 and the elbow angle phi4 given (phi4 NaN: the elbow root in the ELBOW
 * branch); writes q (unless NULL: the residuals alone) and returns the (shoulder, wrist, elbow)
 * residuals (model_ik_lifted). */
vec3 om_srs_model_ik_lifted(const double *P, const om_target *t, vec3 p, const int64_t *signs, double q1, double q7,
                            double phi4, double *q)
{
    vec3 w = v_add(p, t->wrist);
    double L2 = v_dot(w, w);
    if (L2 < DEGENERATE)
        return v3(NAN, NAN, NAN);
    double x = (L2 - P[SRS_K0]) / P[SRS_K];
    const double *th = P + SRS_THETA;
    double c4, s4;
    if (isnan(phi4)) {
        elbow_cs e = elbow_root(P, x, (double)signs[1], &phi4);
        c4 = e.c4;
        s4 = e.s4;
    } else {
        c4 = cos(phi4);
        s4 = sin(phi4);
    }
    mat3 R03 = rotation_03_at(P, t, w, L2, c4, s4, (double)signs[1]);
    mat3 shoulder = m_mmt(m_mtm(m_load(P, SRS_R_PRE), R03), m_load(P, SRS_X3));
    mat3 R04 = m_mm(R03, m_rz_cs_times(c4, s4, m_load(P, SRS_X4)));
    /* The wrist's M^T = Rz(-phi7) Rx(-beta) Rz(-phi6) Rx(-alpha5) Rz(-phi5): phi7 comes first. */
    mat3 wrist = m_transpose(m_mtm(R04, t->RE));
    double elbow_residual = x - cos(phi4 - P[SRS_PHI_STAR]);
    if (!q) { /* the residuals alone: no joint angle (atan2) */
        double a1 = q1 + th[0], a7 = -(q7 + th[6]);
        return v3(om_euler_given_first_residual(shoulder, P[SRS_SIGMA1], 0.0, cos(a1), sin(a1)),
                  om_euler_given_first_residual(wrist, -P[SRS_SIN_BETA], P[SRS_COS_BETA], cos(a7), sin(a7)),
                  elbow_residual);
    }
    vec3 sh = om_euler_zxzxz_given_first(shoulder, P[SRS_SIGMA1], 0.0, P[SRS_SIGMA2], q1 + th[0]);
    vec3 wr = om_euler_zxzxz_given_first(wrist, -P[SRS_SIN_BETA], P[SRS_COS_BETA], -P[SRS_SIGMA5], -(q7 + th[6]));
    q[0] = q1;
    q[1] = om_wrap(sh.x - th[1]);
    q[2] = om_wrap(sh.y - th[2]);
    q[3] = om_wrap(phi4 - th[3]);
    q[4] = om_wrap(-wr.y - th[4]);
    q[5] = om_wrap(-wr.x - th[5]);
    q[6] = q7;
    return v3(sh.z, wr.z, elbow_residual);
}
