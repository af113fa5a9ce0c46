/* The singular boundary: candidates that the model's closed form leaves a few digits short
 * where a branch quantity vanishes (an angle from acos or atan2 of a vanishing pair), made
 * exact by the Gauss-Newton refinement on the REAL arm (polish.c) and then verified like
 * every other candidate (verify.c). */
#include "om_system.h"
#include "boundary.h"

#define POLISH_STEPS 100   /* Jacobians per refinement: 2-4 at a simple root, more at a double one */
#define SPLIT_STARTS 16    /* starts of q1 (wrist centre on joint 1's axis) or of the aligned wrist's split */
#define SPLIT_NEAR 1e-6    /* |branch quantity| under which the model's split is arbitrary: SPLIT_STARTS */

/* The smallest |branch quantity| of q and its index (NaN-safe: INFINITY for NaN). */
static double nearest_branch(const om_solver_data *s, const double *q, int *index)
{
    double values[3], nearest = INFINITY;
    om_branch_values(s->family, s->params, q, values);
    for (int i = 0; i < s->n_signs; i++) {
        if (fabs(values[i]) < nearest) {
            nearest = fabs(values[i]);
            *index = i;
        }
    }
    return nearest;
}

bool om_polish_candidate(om_problem *pb, double *q, double *pos, double *ori)
{
    const om_solver_data *s = pb->s;
    int branch = -1;
    double nearest = nearest_branch(s, q, &branch);
    bool srs = s->family == OM_SRS;
    /* Next to psi's singular half-line the circle's root holds q to a few digits only: g turns
     * by 2 pi within 1e-16 / rho of w there, the model's reference n by 1e-16 / rho rad */
    bool half_line = srs && om_srs_half_line_angle(s->params, q) < NEAR_BOUNDARY;
    /* An arm near a family's root of G holds q to the correction's settling (near.c) */
    bool near_root = s->nominal_table && om_near_polish(pb, q, pos, ori);
    if (near_root || (!(nearest < NEAR_BOUNDARY) && !half_line))
        return near_root;
    om_polish_task t = om_problem_polish_task(pb);
    double start[OM_MAX_DOF];
    memcpy(start, q, (size_t)s->dof * sizeof(double));
    om_polish(&t, POLISH_STEPS, q);
    if (om_verify(pb, q, pos, ori))
        return true;
    if (half_line && s->dof == 7) { /* the pose met, psi not: psi turns along the loop next to the half-line */
        double on_pose[7];
        om_polish_task pose = t;
        pose.P = NULL;
        memcpy(on_pose, q, sizeof on_pose);
        om_polish(&pose, POLISH_STEPS, on_pose);
        if (om_loop_pass(pb, on_pose, pos, ori)) {
            memcpy(q, on_pose, sizeof on_pose);
            return true;
        }
    }
    /* The model's q1 is arbitrary all along its shoulder boundary where that boundary is the
     * wrist centre on joint 1's axis (no lateral offset; a candidate there may be far off in
     * q1 and in the ARM quantity); with a lateral offset, as at every other boundary, only
     * within SPLIT_NEAR of it. */
    bool on_axis = s->family == OM_SRS || s->params[SD_LATERAL] == 0.0;
    if (!pb->split_starts || !(nearest < NEAR_BOUNDARY) || branch == ELBOW_SIGN ||
        ((branch != SHOULDER_SIGN || !on_axis) && !(nearest < SPLIT_NEAR)))
        return false;
    /* The wrist centre on joint 1's axis: the model's q1 is arbitrary there (atan2 of a
     * vanishing pair), the real arm's is not: starts around the circle of q1, each with the
     * wrist as it was and flipped (q_{m-1} + pi, -q_m, q_{m+1} + pi: the same rotation of a
     * spherical wrist, the other WRIST sign), since turning q1 by a turns the hand, and the
     * wrist must turn it back, which from the kept wrist may lead the refinement across its
     * singularity into the other WRIST sign (the Spherical arm's ARM = -3e-14 reproducer).
     * The wrist aligned (its middle joint m = dof - 2 at zero): the model splits q_{m-1} +-
     * q_{m+1} by the previous q, the real arm's offsets do not: starts that turn q_{m-1} by a
     * and q_{m+1} by -+a (the model's pose kept for either alignment of the two axes). */
    bool shoulder = branch == SHOULDER_SIGN;
    int m = s->dof - 2;
    for (int k = 1; k < SPLIT_STARTS; k++) {
        double a = 2.0 * OM_PI * (double)k / (double)SPLIT_STARTS;
        for (int turn = -1; turn <= 1; turn += 2) {
            memcpy(q, start, (size_t)s->dof * sizeof(double));
            if (shoulder) {
                q[0] += a;
                if (turn > 0) { /* the flipped wrist */
                    q[m - 1] += OM_PI;
                    q[m] = -q[m];
                    q[m + 1] += OM_PI;
                }
            } else {
                q[m - 1] += a;
                q[m + 1] += (double)turn * a;
            }
            om_polish(&t, POLISH_STEPS, q);
            if (om_verify(pb, q, pos, ori))
                return true;
        }
    }
    return false;
}

int om_add_candidate(om_problem *pb, double *q, double *roots, int count)
{
    if (!om_verify(pb, q, NULL, NULL) && !om_polish_candidate(pb, q, NULL, NULL))
        return count;
    return om_add_root(pb, q, roots, count);
}
