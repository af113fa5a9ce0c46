/* The singular boundary: candidates that the model's closed form leaves a few digits short
 * where a branch quantity vanishes (an angle from acos or atan2 of a vanishing pair), made
 * exact by the Gauss-Newton refinement on the REAL arm (polish.c) and then verified like
 * every other candidate (verify.c). */
#include "om_system.h"

#define NEAR_BOUNDARY 1e-2 /* |branch quantity| under which a failed candidate is polished */
#define POLISH_STEPS 12    /* Jacobians per refinement (it converges in 2-4 where it can) */
#define ELBOW_SIGN 1       /* (SHOULDER or ARM, ELBOW, WRIST) in every family */
#define GATE_POINTS 8      /* free-angle samples of the cheap test before a neighbour's search */
#define GATE_NEAR 0.2      /* |branch quantity| at a sample that lets a neighbour be searched */

/* Whether some branch quantity of q is within NEAR_BOUNDARY of zero (false for NaN). */
static bool near_boundary(const om_solver_data *s, const double *q)
{
    double values[3];
    om_branch_values(s->family, s->params, q, values);
    for (int i = 0; i < s->n_signs; i++)
        if (fabs(values[i]) < NEAR_BOUNDARY)
            return true;
    return false;
}

bool om_polish_candidate(om_problem *pb, double *q, double *pos, double *ori)
{
    const om_solver_data *s = pb->s;
    if (!near_boundary(s, q))
        return false;
    bool srs = s->family == OM_SRS;
    om_polish_task t = {s->real_table, s->n_real_rows, s->dof, srs ? s->params : NULL,
                        srs ? s->model_table : NULL, s->n_model_rows, pb->R, pb->p,
                        srs ? pb->redundancy[0] : 0.0, srs ? (double)pb->signs[ELBOW_SIGN] : 0.0};
    om_polish(&t, POLISH_STEPS, q);
    return om_verify(pb, q, pos, ori);
}

int om_add_candidate(om_problem *pb, double *q, double *roots, int count)
{
    if (!om_verify(pb, q, NULL, NULL) && !om_polish_candidate(pb, q, NULL, NULL))
        return count;
    return om_add_root(pb, q, roots, count);
}

/* The problem with branch i flipped: the neighbouring configuration across that boundary.
 * psi's reference flips with the ELBOW branch, so there psi becomes psi + pi. */
static om_problem neighbour(const om_problem *pb, int i, int64_t *signs, double *redundancy)
{
    const om_solver_data *s = pb->s;
    om_problem other = *pb;
    memcpy(signs, pb->signs, (size_t)s->n_signs * sizeof(int64_t));
    signs[i] = -signs[i];
    for (int r = 0; r < s->n_redundancy; r++)
        redundancy[r] = pb->redundancy[r];
    if (s->family == OM_SRS && i == ELBOW_SIGN)
        redundancy[0] = om_wrap(redundancy[0] + OM_PI);
    other.signs = signs;
    other.redundancy = redundancy;
    other.counter = 0;
    return other;
}

/* Which branches may meet zero, so that a neighbour's root may lie in the band (the cheap
 * test before a neighbour's bounded search): near[i] if branch i of the model's solution in
 * the problem's configuration comes within GATE_NEAR of zero at GATE_POINTS samples of the
 * free angle. (A straight elbow is an edge of reach, found by the touch candidates of the
 * problem's own search.) On the torus every branch is marked. */
static void may_meet_zero(om_problem *pb, bool *near)
{
    const om_solver_data *s = pb->s;
    bool torus = s->mode == OM_TORUS;
    for (int i = 0; i < s->n_signs; i++)
        near[i] = torus;
    if (torus)
        return;
    double q[OM_MAX_DOF], values[3];
    int points = s->mode == OM_FIXED ? 1 : GATE_POINTS;
    for (int k = 0; k < points; k++) {
        if (om_model_ik_at(pb, -OM_PI + 2.0 * OM_PI * (double)k / (double)points, q, true) < -OM_REACH_SLACK)
            continue;
        om_branch_values(s->family, s->params, q, values);
        for (int i = 0; i < s->n_signs; i++)
            near[i] = near[i] || fabs(values[i]) < GATE_NEAR;
    }
}

int om_band_roots(om_problem *pb, double *roots, bool *neighbour_reached)
{
    const om_solver_data *s = pb->s;
    int64_t signs[64];
    double redundancy[1], found[OM_MAX_ROOTS * OM_MAX_DOF];
    int count = 0;
    bool near[3];
    may_meet_zero(pb, near);
    *neighbour_reached = false;
    for (int i = 0; i < s->n_signs; i++) {
        if (!near[i])
            continue;
        om_problem other = neighbour(pb, i, signs, redundancy);
        int n = om_all_roots(&other, s->scan_points, found, pb->q_prev, INFINITY);
        pb->counter += other.counter;
        *neighbour_reached = *neighbour_reached || n > 0;
        for (int r = 0; r < n; r++) /* verified again in the problem's own configuration */
            count = om_add_root(pb, found + r * s->dof, roots, count);
    }
    return count;
}
