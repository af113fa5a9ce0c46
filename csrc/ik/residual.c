/* The residual of the OM system (9), reduced to the circle or lifted on the torus
 * (the method: om_redundant/ik/kernel_data.py). Each evaluation counts in pb->counter. */
#include "om_system.h"

#define REACH_BOUND_SLACK 1e-9 /* of the elbow's x, for rounding (x itself is rounded to about 1e-16) */

/* dp seen from the flange, delta(w) = D0 + D1 cos w + D2 sin w (rows 0-2 of D). */
vec3 om_delta(const double D[6][3], double w)
{
    double c = cos(w), s = sin(w);
    return v3(D[0][0] + D[1][0] * c + D[2][0] * s, D[0][1] + D[1][1] * c + D[2][1] * s,
              D[0][2] + D[1][2] * c + D[2][2] * s);
}

/* The model's hand position on the circle, p_m = p_d + R delta(w) (a wrist with a4 != 0:
 * p_d + dp(w), w = q1, see wrist_offset.c). */
vec3 om_on_circle(const om_problem *pb, double w)
{
    if (pb->s->family != OM_SRS && pb->s->params[SD_WRIST_OFFSET] != 0.0)
        return om_wrist_offset_point(pb->s->params, &pb->t, pb->p, (double)pb->signs[2], w);
    vec3 d = om_delta(pb->s->D, w);
    const mat3 *R = &pb->t.R;
    vec3 p = pb->p;
    return v3(p.x + R->r0.x * d.x + R->r0.y * d.y + R->r0.z * d.z, p.y + R->r1.x * d.x + R->r1.y * d.y + R->r1.z * d.z,
              p.z + R->r2.x * d.x + R->r2.y * d.y + R->r2.z * d.z);
}

/* on_circle, counted as one residual evaluation. */
static vec3 circle_point(om_problem *pb, double w)
{
    pb->counter++;
    return om_on_circle(pb, w);
}

/* What om_model_ik_at solves: the circle's point w, and whether for every joint. */
typedef struct {
    double w;
    bool all_joints;
} circle_ik;

/* The model IK at the circle's point (om_model_eval; its residual g, 0 on a fixed arm). */
static double _circle_ik(om_problem *pb, const void *args, double *q, bool nearest, double *residual)
{
    const om_solver_data *data = pb->s;
    const circle_ik *a = args;
    vec3 pm = circle_point(pb, a->w);
    *residual = INFINITY;
    if (!isfinite(pm.x)) /* a singular wrist with a4 != 0: no point of the circle */
        return nearest ? NAN : -1.0;
    if (nearest)
        return om_model_ik_nearest(data->family, data->params, data->model_table, &pb->t, pm, pb->signs, pb->q_prev,
                                   q);
    double margin;
    if (!a->all_joints && data->family == OM_SRS && data->dp_joint == 6)
        margin = om_srs_model_q7(data->params, &pb->t, pm, pb->signs, pb->q_prev, q);
    else
        margin = om_model_ik(data->family, data->params, data->model_table, &pb->t, pm, pb->signs, pb->q_prev, q,
                             a->all_joints);
    if (margin >= -OM_REACH_SLACK)
        *residual = data->mode == OM_FIXED ? 0.0 : om_wrap(q[data->dp_joint] - a->w);
    return margin;
}

/* Model IK for p_m = p_d + R delta(w), one residual evaluation; returns the reach margin
 * (negative beyond OM_REACH_SLACK: out of the model's reach, q not written). all_joints false
 * writes only what g needs: q_J (an S-R-S arm whose dp turns with q7: q7 alone), or more; an
 * arm near a family, whose correction is the real arm's at every joint, writes them all (but
 * in its scan of its nominal arm: pb->nominal). */
double om_model_ik_at(om_problem *pb, double w, double *q, bool all_joints)
{
    circle_ik args = {w, all_joints || (pb->s->nominal_table && !pb->nominal)};
    return om_near_ik(pb, _circle_ik, &args, q);
}

/* What om_wrist_residual solves: the circle's point w = q6, and the residual there (out). */
typedef struct {
    double w, residual;
} wrist_ik;

/* The model IK with q6 = w given at the circle's point (om_model_eval; its residual the wrist's). */
static double _wrist_ik(om_problem *pb, const void *args, double *q, bool nearest, double *residual)
{
    const om_solver_data *data = pb->s;
    wrist_ik *a = (wrist_ik *)args;
    vec3 pm = circle_point(pb, a->w);
    *residual = INFINITY;
    if (nearest)
        return om_model_ik_nearest(data->family, data->params, data->model_table, &pb->t, pm, pb->signs, pb->q_prev,
                                   q);
    double margin = om_six_dof_model_ik_q6(data->family, data->params, data->model_table, &pb->t, pm, pb->signs,
                                           pb->q_prev, a->w, q, &a->residual);
    if (margin >= -OM_REACH_SLACK)
        *residual = a->residual;
    return margin;
}

/* om_wrist_residual, its reach margin into *margin (NULL: not wanted). */
static double _wrist_residual(om_problem *pb, double w, double *q, double *margin)
{
    wrist_ik args = {w, NAN};
    double m = om_near_ik(pb, _wrist_ik, &args, q);
    if (margin)
        *margin = m;
    return m < -OM_REACH_SLACK ? NAN : args.residual;
}

/* The wrist's consistency at p_m = p_d + R delta(w) with the wrist joint J = w given, for a
 * 6-DOF circle arm (om_six_dof_model_ik_q6): smooth where g is steep at a singular wrist.
 * Writes q (q_J = w); NaN out of the model's reach, and where w is not q6 (a4 != 0). */
double om_wrist_residual(om_problem *pb, double w, double *q)
{
    if (pb->s->dp_joint != 5) /* a wrist with a4 != 0: w is q1, not q6 (wrist_offset.c) */
        return NAN;
    return _wrist_residual(pb, w, q, NULL);
}

/* Residual g(w) (NaN if unreachable) and the model's reach margin; writes the IK into q. In a
 * near arm's scan of its wrist residual (pb->wrist), that residual and the IK with q6 = w. */
double om_g_margin(om_problem *pb, double w, double *q, bool all_joints, double *margin)
{
    if (pb->wrist)
        return _wrist_residual(pb, w, q, margin);
    bool fixed = pb->s->mode == OM_FIXED;
    double m = om_model_ik_at(pb, w, q, all_joints || fixed);
    if (margin)
        *margin = m;
    if (m < -OM_REACH_SLACK)
        return NAN;
    if (fixed)
        return 0.0;
    return om_wrap(q[pb->s->dp_joint] - w);
}

/* The reach margin of om_g_margin alone: on an S-R-S arm in its family no joint is solved for
 * it (not a residual evaluation, not counted); on the others, and near a family (where the
 * margin is the corrected target's), it is om_g_margin's (q written). */
double om_reach_margin(om_problem *pb, double w, double *q)
{
    if (pb->s->family == OM_SRS && !pb->s->nominal_table) {
        double x;
        return om_srs_reach(pb->s->params, &pb->t, om_on_circle(pb, w), &x);
    }
    double margin;
    om_g_margin(pb, w, q, false, &margin);
    return margin;
}

/* The S-R-S model's shoulder-wrist vector on the circle, W(w) - S = e + u1 cos w + u2 sin w:
 * e = p_d + R D0 + R w_F - S, u1 = R D1, u2 = R D2. */
void om_srs_wrist_circle(const om_problem *pb, vec3 *e, vec3 *u1, vec3 *u2)
{
    const double(*D)[3] = pb->s->D;
    const mat3 *R = &pb->t.R;
    *e = v_add(v_add(pb->p, pb->t.wrist), m_mv(*R, v_load(D[0], 0)));
    *u1 = m_mv(*R, v_load(D[1], 0));
    *u2 = m_mv(*R, v_load(D[2], 0));
}

/* The S-R-S model's elbow x at p_d + R delta(w) (NaN where W = S): the bound's sample's where w
 * is one, bit for bit (the same arithmetic on the same inputs), else computed. */
static double _elbow_x(om_problem *pb, const om_reach_bound *bound, double w)
{
    if (bound->samples) {
        double k = round((w - bound->lo) / bound->h);
        double wk = bound->lo + bound->h * k;
        if (k >= 0.0 && k < (double)bound->n && memcmp(&wk, &w, sizeof w) == 0)
            return bound->samples[(int)k].x;
    }
    double x = NAN;
    om_srs_reach(pb->s->params, &pb->t, om_on_circle(pb, w), &x);
    return x;
}

/* Whether an S-R-S model may reach p_d + R delta(w) for some w in [a, b], where it reaches
 * neither end: the elbow's x(w) = (L2(w) - k0) / K must come within [-1, 1]. With e = p_d +
 * R D0 + R w_F - S, u1 = R D1, u2 = R D2, L2(w) = |e + u1 cos w + u2 sin w|^2 = c0 + a1 cos w
 * + b1 sin w + a2 cos 2w + b2 sin 2w (a1 = 2 e.u1, b1 = 2 e.u2, a2 = (|u1|^2 - |u2|^2) / 2,
 * b2 = u1.u2), so |x''| <= (|(a1, b1)| + 4 |(a2, b2)|) / K, and x stays within
 * (b - a)^2 / 8 times that of the chord through its ends: a proof that no island of reach
 * lies between two samples, without searching. The bound on |x''| is the circle's, computed
 * at the first call of a scan; x at a is the last call's x at b where a is that b (the cells
 * of a scan in order), the same value, and at a sample of the scan its part's (_elbow_x). */
bool om_srs_reach_possible(om_problem *pb, om_reach_bound *bound, double a, double b)
{
    const double *P = pb->s->params;
    double xa = a == bound->w ? bound->x : _elbow_x(pb, bound, a), xb = _elbow_x(pb, bound, b);
    bound->w = b, bound->x = xb;
    if (isnan(xa) || isnan(xb)) /* W = S at an end */
        return true;
    if (isnan(bound->curvature)) {
        vec3 e, u1, u2;
        om_srs_wrist_circle(pb, &e, &u1, &u2);
        double a1 = 2.0 * v_dot(e, u1), b1 = 2.0 * v_dot(e, u2);
        double a2 = 0.5 * (v_dot(u1, u1) - v_dot(u2, u2)), b2 = v_dot(u1, u2);
        bound->curvature = (sqrt(a1 * a1 + b1 * b1) + 4.0 * sqrt(a2 * a2 + b2 * b2)) / P[SRS_K];
    }
    double sag = 0.125 * (b - a) * (b - a) * bound->curvature + REACH_BOUND_SLACK;
    if (xa > 1.0 && xb > 1.0)
        return py_min(xa, xb) - sag <= 1.0;
    if (xa < -1.0 && xb < -1.0)
        return py_max(xa, xb) + sag >= -1.0;
    return true;
}

/* Residual g(w) of the reduced system, NaN if unreachable (see om_g_margin). */
double om_g(om_problem *pb, double w, double *q, bool all_joints)
{
    return om_g_margin(pb, w, q, all_joints, NULL);
}

/* The model's hand position on the torus, p_m = p_d + a(w1) + R delta(w7) (a PUMA-like wrist's
 * torus (w5, w6) = (q5, q6): p_d + R delta(w5, w6)) (not counted as an evaluation). */
vec3 om_torus_point(const om_problem *pb, double w1, double w7)
{
    if (pb->s->family != OM_SRS)
        return om_six_dof_torus_point(pb->s->params, &pb->t.R, pb->p, w1, w7);
    const double(*D)[3] = pb->s->D;
    const mat3 *R = &pb->t.R;
    vec3 p = pb->p;
    double c1 = cos(w1), s1 = sin(w1);
    vec3 d = om_delta(D, w7);
    return v3(p.x + D[3][0] + D[4][0] * c1 + D[5][0] * s1 + R->r0.x * d.x + R->r0.y * d.y + R->r0.z * d.z,
              p.y + D[3][1] + D[4][1] * c1 + D[5][1] * s1 + R->r1.x * d.x + R->r1.y * d.y + R->r1.z * d.z,
              p.z + D[3][2] + D[4][2] * c1 + D[5][2] * s1 + R->r2.x * d.x + R->r2.y * d.y + R->r2.z * d.z);
}

/* What om_lifted_residual solves: the point x = (w1, w7, phi4) (a PUMA-like wrist's: (q5, q6,
 * gamma), om_six_dof_model_ik_lifted), and the residual there (out). */
typedef struct {
    vec3 x, F;
} lifted_ik;

/* The lifted model IK at x for p_m = p_d + a(w1) + R delta(w7) (om_model_eval; q NULL: the
 * residual alone; its residual the largest of the three). Its margin: 0, NaN where W = S (no
 * joint written); nearest is never asked. */
static double _lifted_ik(om_problem *pb, const void *args, double *q, bool nearest, double *residual)
{
    lifted_ik *a = (lifted_ik *)args;
    vec3 x = a->x;
    pb->counter++;
    vec3 pm = om_torus_point(pb, x.x, x.y);
    const om_solver_data *s = pb->s;
    if (s->family == OM_SRS)
        a->F = om_srs_model_ik_lifted(s->params, &pb->t, pm, pb->signs, x.x, x.y, x.z, q);
    else
        a->F = om_six_dof_model_ik_lifted(s->params, s->model_table, &pb->t, pm, pb->signs, pb->q_prev, x.x, x.y,
                                          x.z, q);
    *residual = om_max_norm(a->F);
    return isnan(a->F.x) ? NAN : 0.0;
}

/* The lifted residual (shoulder, wrist, elbow) at x = (w1, w7, phi4) for
 * p_m = p_d + a(w1) + R delta(w7) (see srs.model_ik_lifted); writes the model IK into q
 * unless q is NULL (the residual alone, cheaper: no joint angles; an arm near a family
 * solves them for its correction all the same). */
vec3 om_lifted_residual(om_problem *pb, vec3 x, double *q)
{
    double scratch[OM_MAX_DOF];
    lifted_ik args = {x, v3(NAN, NAN, NAN)};
    om_near_ik(pb, _lifted_ik, &args, q || !pb->s->nominal_table ? q : scratch);
    return args.F;
}

/* What om_axis_residual solves: the point x = (w5, w6, q1, gamma), and the residual there (out). */
typedef struct {
    const double *x;
    double F[4];
} axis_ik;

/* The model IK about joint 1's axis at x (om_model_eval; its residual the largest of the four;
 * its margin 0: nothing out of reach). */
static double _axis_ik(om_problem *pb, const void *args, double *q, bool nearest, double *residual)
{
    axis_ik *a = (axis_ik *)args;
    const om_solver_data *s = pb->s;
    pb->counter++;
    vec3 pm = om_torus_point(pb, a->x[0], a->x[1]);
    om_six_dof_model_ik_about_axis(s->params, s->model_table, &pb->t, pm, pb->signs, pb->q_prev, a->x, q, a->F);
    *residual = py_max(py_max(fabs(a->F[0]), fabs(a->F[1])), py_max(fabs(a->F[2]), fabs(a->F[3])));
    return 0.0;
}

void om_axis_residual(om_problem *pb, const double *x, double *q, double *F)
{
    axis_ik args = {x, {NAN, NAN, NAN, NAN}};
    om_near_ik(pb, _axis_ik, &args, q);
    memcpy(F, args.F, sizeof args.F);
}

/* The lifted residual times prod_k (1 + 1 / |x - x_k|^2) over the known roots x_k
 * (deflation: Newton's method is repelled from them). known: n_known x 3; q as om_lifted_residual. */
vec3 om_deflated_residual(om_problem *pb, vec3 x, double *q, const double *known, int n_known)
{
    vec3 F = om_lifted_residual(pb, x, q);
    double factor = 1.0;
    for (int k = 0; k < n_known; k++) {
        double d2 = 0.0;
        for (int i = 0; i < 3; i++) {
            double e = om_wrap(v_get(x, i) - known[3 * k + i]);
            d2 += e * e;
        }
        factor *= 1.0 + 1.0 / py_max(d2, 1e-300);
    }
    return v_scale(factor, F);
}

/* max |F_i| of a 3-vector (Python's max: a NaN after the first entry is skipped). */
double om_max_norm(vec3 F)
{
    return py_max(py_max(fabs(F.x), fabs(F.y)), fabs(F.z));
}
