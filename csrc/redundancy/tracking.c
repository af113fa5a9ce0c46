/* The redundancy optimiser's tracking step in one call (om_redundant/redundancy/choice/tracking.py):
 * the exact solve at the previous arm angle, the objective's pieces and their rates along
 * the self-motion, the step of the 1-variable box QP, the exact solve at the new arm angle.
 *
 * Pieces v_j (normalised, see objective.py) in three groups g: the joint-limit margins
 * (q_i - l_i)/h_i and (u_i - q_i)/h_i (floor 0, no cap), the clearances d_k/d_cap linearised
 * about the joints where Python last evaluated them (given in metres; floor d_min/d_cap, cap 1), the
 * singularity distances |sin(q_j + c_j)|/s_cap (no floor, cap 1). Their rates
 * a_j = dv_j/dq . dq/dpsi use the self-motion tangent dq/dpsi = n / (dpsi/dq . n), n the
 * null vector of the 6 x 7 Jacobian J by cofactors, n_i = (-1)^i det J_{-i} (smooth in q, no
 * factorisation to pick a sign). The step maximises the concave model
 *     phi(d) = sum_g w_g min(cap_g, min_j v_j + a_j d) - b d^2 / 2
 * over the box |d| <= radius intersected with the floors v_j + a_j d >= floor_g (box_qp.c,
 * the climb's QP). */
#include <string.h>

#include "redundancy.h"

#define MAX_PIECES OM_TRACK_MAX_PIECES
#define HALVINGS 6
#define MIN_CURVATURE 1e-3
#define MAX_CURVATURE 1e3
#define SINGULAR_TANGENT 1e-9 /* |Dpsi . n| below this of |Dpsi| |n|: a fold, no step */
/* The step keeps the floors' pieces this far above them: a step to a floor itself lands the
 * exact solve's rounding (1e-16 of the pieces) on either side, and one just outside is refused */
#define FLOOR_SLACK 1e-9

typedef struct {
    int n;
    double v[MAX_PIECES], a[MAX_PIECES];
    int group[MAX_PIECES];
} pieces;

typedef om_tracking tracking;

void om_tracking_groups(om_tracking *tr, double w_m, double w_c, double w_s, double clearance_floor) {
    double weight[3] = {w_m, w_c, w_s}, floor[3] = {FLOOR_SLACK, clearance_floor + FLOOR_SLACK, -INFINITY};
    double cap[3] = {INFINITY, 1.0, 1.0};
    memcpy(tr->weight, weight, sizeof weight);
    memcpy(tr->floor, floor, sizeof floor);
    memcpy(tr->cap, cap, sizeof cap);
}

/* The pieces and their rates at q with tangent t. */
static void pieces_at(const tracking *tr, const double *q, const double *t, pieces *P) {
    const om_solver_data *s = tr->s;
    int n = 0, dof = s->dof;
    for (int i = 0; i < dof; i++) {
        if (!(isfinite(tr->lower[i]) && isfinite(tr->upper[i]))) continue;
        double h = (tr->upper[i] - tr->lower[i]) / 2.0;
        P->v[n] = (q[i] - tr->lower[i]) / h, P->a[n] = t[i] / h, P->group[n++] = 0;
        P->v[n] = (tr->upper[i] - q[i]) / h, P->a[n] = -t[i] / h, P->group[n++] = 0;
    }
    int n_clear = tr->n_clear, n_sing = tr->n_sing;
    double d_cap = tr->clearance_cap;
    for (int k = 0; k < n_clear; k++) {
        const double *g = tr->clear_g + k * dof;
        double v = tr->clear_d[k] / d_cap, a = 0.0;
        int moving = 0;
        for (int i = 0; i < dof; i++) {
            double gi = g[i] / d_cap;
            v += gi * (q[i] - tr->q_ref[i]), a += gi * t[i], moving |= gi != 0.0;
        }
        if (!moving && v >= tr->cap[1]) continue; /* a pair beyond the reach: constant above the cap, never active */
        P->v[n] = v, P->a[n] = a, P->group[n++] = 1;
    }
    for (int k = 0; k < n_sing; k++) {
        int j = (int)tr->sing_joint[k];
        double x = q[j] + tr->sing_offset[k], sn = sin(x), cap = tr->singularity_cap;
        P->v[n] = fabs(sn) / cap, P->a[n] = (sn < 0.0 ? -1.0 : 1.0) * cos(x) * t[j] / cap, P->group[n++] = 2;
    }
    P->n = n;
}

/* The maximiser of the model over the box |d| <= radius and the floors (om_qp_step); false if
 * they leave nothing. pieces_at lists the groups' pieces group by group. */
static bool box_step(const tracking *tr, const pieces *P, double b, double radius, double *step) {
    int64_t ends[4] = {0, 0, 0, 0};
    for (int j = 0; j < P->n; j++) ends[P->group[j] + 1]++;
    for (int g = 0; g < 3; g++) ends[g + 1] += ends[g];
    om_qp_groups q = {P->v, P->a, tr->weight, tr->floor, tr->cap, ends, 3};
    return om_qp_step(&q, b, -radius, radius, step, NULL, NULL) == OM_QP_FOUND;
}

int om_track(const om_tracking *tr, const double *T, const int64_t *signs, double psi, const double *q_prev,
             double max_step, double curvature, double *q1, om_tracked *out) {
    const om_solver_data *s = tr->s;
    int dof = s->dof;
    double q0[OM_MAX_DOF], t0[OM_MAX_DOF], t1[OM_MAX_DOF];
    /* each solve's root taken without the scan where it continues beyond doubt: the first's along
     * the hand's motion (om_solve_from), the second's along the self-motion */
    om_result r = om_solve_from(s, T, signs, &psi, q_prev, q0);
    if (r.status != OM_OK || !om_continues(dof, q_prev, q0, NULL, 0.0, NULL)) return OM_TRACK_NO_SOLUTION;
    if (!om_self_motion_tangent(s, q0, t0, SINGULAR_TANGENT)) return OM_TRACK_SINGULAR;
    static pieces P0, P1; /* (the GIL is held: one call at a time) */
    pieces_at(tr, q0, t0, &P0);
    double b = fmin(fmax(curvature, MIN_CURVATURE), MAX_CURVATURE), tmax = 0.0;
    for (int i = 0; i < dof; i++) tmax = fmax(tmax, fabs(t0[i]));
    double radius = fmin(max_step, tr->joint_step / fmax(tmax, 1e-12)), d;
    if (!box_step(tr, &P0, b, radius, &d)) return OM_TRACK_INFEASIBLE;
    double psi1 = psi + d;
    for (int k = 0;; k++) {
        psi1 = psi + d;
        om_step_prediction p = {dof, q0, t0, d};
        r = om_solve_one(s, T, signs, &psi1, q0, q1, om_on_step, &p);
        if (r.status == OM_OK && om_continues(dof, q0, q1, t0, d, NULL) && om_self_motion_tangent(s, q1, t1, SINGULAR_TANGENT)) break;
        if (k == HALVINGS) return OM_TRACK_LEFT;
        d /= 2.0;
    }
    pieces_at(tr, q1, t1, &P1);
    /* b: the secant of each uncapped group's active piece's rate, weighted */
    double low[3] = {INFINITY, INFINITY, INFINITY}, y = 0.0;
    int active[3] = {-1, -1, -1};
    for (int j = 0; j < P1.n; j++)
        if (P1.v[j] < low[P1.group[j]]) low[P1.group[j]] = P1.v[j], active[P1.group[j]] = j;
    for (int g = 0; g < 3; g++)
        if (active[g] >= 0 && low[g] < tr->cap[g]) y += tr->weight[g] * (P1.a[active[g]] - P0.a[active[g]]);
    if (fabs(d) > 1e-12 && isfinite(y)) b = fmin(fmax(-y / d, MIN_CURVATURE), MAX_CURVATURE);
    *out = (om_tracked){psi1, d, b, r.position_error, r.orientation_error, r.evaluations, r.within_limits};
    return OM_TRACK_OK;
}

