/* Every candidate checked with the REAL arm: pose errors, configuration, joint limits
 * (the method: om_redundant/ik/kernel_data.py). */
#include "om_system.h"

#define REDUNDANCY_TOL 1e-9 /* a solution's redundancy values (rad) must equal the requested ones */
/* rad per joint: psi's own rounding at q is at most its change when each joint moves by this
 * (an ulp of pi, 2^-51), which exceeds REDUNDANCY_TOL only next to psi's singular set: the
 * half-line, and the wrist centre at the shoulder */
#define PSI_ROUNDING 4.440892098500626e-16
#define SRS_ELBOW_SIGN 1    /* (SHOULDER, ELBOW, WRIST) */
#define MAX_VALUES 16       /* branch values of a family (3 today) */
#define HUGE_HINT 1e4       /* rad: a revolute joint's hint beyond it is reduced exactly (om_wrap) first */

/* How far psi computed at q can be from psi at the exact joint values (NaN: not finite):
 * |grad psi|_1 PSI_ROUNDING. Next to psi's singular half-line (the wrist centre straight
 * below the shoulder, at the angle rho from it) |grad psi| grows as 1 / rho, and the last bits
 * of q, and of any pose's solution, leave psi uncertain by 1e-16 / rho: beyond REDUNDANCY_TOL
 * below rho = 1e-7, where no floating-point q can meet psi to 1e-9. Likewise where the model's
 * wrist centre W is at its shoulder S (|grad psi| grows as 1 / |W - S|: a model whose upper
 * arm and forearm are equal, folded; the Sawyer's at q4 = +-pi, beyond its limits). */
static double psi_rounding(const om_solver_data *s, const double *q)
{
    double grad[OM_MAX_DOF], sum = 0.0;
    om_arm_angle_gradient(s->params, s->model_table, s->n_model_rows, q, grad);
    for (int j = 0; j < s->dof; j++)
        sum += fabs(grad[j]);
    return sum * PSI_ROUNDING;
}

/* om_in_configuration for a requested psi already in [-pi, pi) (om_wrap leaves it as it is);
 * trig not NULL (s->trig_shared): the real FK's cos and sin of q_j + theta_j, which are the
 * model's for joints 1-6, bit for bit, so they are not computed again. */
static bool in_configuration(const om_solver_data *s, const double *q, const double *trig, const int64_t *signs,
                             double psi_requested)
{
    double values[MAX_VALUES];
    if (trig)
        om_srs_branch_values_trig(s->params, q, trig, values);
    else
        om_branch_values(s->family, s->params, q, values);
    for (int i = 0; i < s->n_signs; i++)
        if (!(values[i] * (double)signs[i] >= 0.0 || fabs(values[i]) <= OM_BRANCH_BAND)) /* NaN: not in it */
            return false;
    if (s->family == OM_SRS) { /* psi: the only redundancy value; in the requested ELBOW branch */
        double elbow = (double)signs[SRS_ELBOW_SIGN];
        double psi = trig ? om_srs_arm_angle_trig(s->params, trig, elbow) : om_srs_arm_angle_in(s->params, q, elbow);
        double miss = fabs(om_wrap(psi - psi_requested));
        return miss <= REDUNDANCY_TOL || miss <= psi_rounding(s, q);
    }
    return true;
}

bool om_in_configuration(const om_solver_data *s, const double *q, const int64_t *signs, const double *redundancy)
{
    /* reduced exactly first: a huge requested psi (1e16) is one well-defined angle */
    return in_configuration(s, q, NULL, signs, s->family == OM_SRS ? om_wrap(redundancy[0]) : 0.0);
}

/* Whether the real chain's joints 1-6 turn by the S-R-S model's angles q_j + theta_j, bit for
 * bit (revolute rows whose theta is the model's): then om_verify reuses the FK's cos and sin. */
bool om_trig_shared(const om_solver_data *s)
{
    if (s->family != OM_SRS || s->dof != 7)
        return false;
    int j = 0;
    for (int k = 0; k < s->n_real_rows && j < 6; k++) {
        const double *row = s->real_table + 6 * k;
        if (row[OM_DH_KIND] == OM_JOINT_FIXED)
            continue;
        if (row[OM_DH_KIND] != OM_JOINT_REVOLUTE ||
            memcmp(&row[OM_DH_THETA], &s->params[SRS_THETA + j], sizeof(double)) != 0)
            return false;
        j++;
    }
    return j == 6;
}

/* Position and orientation error of the REAL arm at q (into *pos, *ori), and the
 * configuration check; returns whether q is accepted. The problem's redundancy is reduced
 * (solve.c; a neighbour's in bands.c is wrapped). */
bool om_verify(om_problem *pb, const double *q, double *pos, double *ori)
{
    const om_solver_data *data = pb->s;
    double Rr[9], pr[3], trig[2 * OM_MAX_DOF];
    om_flange_trig(data->real_table, data->n_real_rows, q, Rr, pr, trig);
    vec3 d = v3(pr[0] - pb->goal_p.x, pr[1] - pb->goal_p.y, pr[2] - pb->goal_p.z);
    double position = sqrt(v_dot(d, d));
    mat3 E = m_mtm(pb->goal.R, m_load(Rr, 0));
    double e0 = E.r2.y - E.r1.z, e1 = E.r0.z - E.r2.x, e2 = E.r1.x - E.r0.y;
    double s = 0.5 * sqrt(e0 * e0 + e1 * e1 + e2 * e2);
    double orientation = atan2(s, 0.5 * (E.r0.x + E.r1.y + E.r2.z - 1.0));
    if (pos)
        *pos = position;
    if (ori)
        *ori = orientation;
    return position <= data->tol_pos && orientation <= data->tol_ori &&
           in_configuration(data, q, data->trig_shared ? trig : NULL, pb->signs,
                            data->family == OM_SRS ? pb->redundancy[0] : 0.0);
}

/* Append q to roots (OM_MAX_ROOTS x dof) if the real arm verifies it and it is new;
 * returns the count. Within OM_SAME_ROOT of a kept root q is that root; within OM_ONE_ROOT
 * (a root found twice near a fold of the residual, where it is flat to second order) the
 * copy with the smaller pose error is kept. */
int om_add_root(om_problem *pb, const double *q, double *roots, int count)
{
    double pos, ori;
    if (!om_verify(pb, q, &pos, &ori))
        return count;
    int dof = pb->s->dof;
    for (int r = 0; r < count; r++) {
        double diff = om_wrapped_distance_max(q, roots + r * dof, dof);
        if (diff < OM_SAME_ROOT)
            return count;
        if (diff < OM_ONE_ROOT) {
            double kept_pos, kept_ori;
            om_verify(pb, roots + r * dof, &kept_pos, &kept_ori);
            if (pos + ori < kept_pos + kept_ori)
                memcpy(roots + r * dof, q, (size_t)dof * sizeof(double));
            return count;
        }
    }
    if (count < OM_MAX_ROOTS) {
        memcpy(roots + count * dof, q, (size_t)dof * sizeof(double));
        count += 1;
    }
    return count;
}

/* Shift revolute joints by multiples of 2 pi into the limits, nearest to the hint (to zero
 * without one); returns whether q is within limits. hint is read only if has_hint. */
bool om_representative(double *q, int dof, const uint8_t *revolute, const double *lower, const double *upper,
                       const double *hint, bool has_hint)
{
    bool inside = true;
    for (int j = 0; j < dof; j++) {
        if (!revolute[j]) {
            inside = inside && lower[j] <= q[j] && q[j] <= upper[j];
            continue;
        }
        double target = has_hint ? hint[j] : 0.0;
        double best = om_wrap(q[j] - target) + target;
        bool found = lower[j] <= best && best <= upper[j];
        if (!found) {
            double base = om_wrap(q[j]);
            double best_dist = INFINITY;
            for (int k = -3; k < 4; k++) {
                double cand = base + 2.0 * OM_PI * (double)k;
                if (lower[j] <= cand && cand <= upper[j] && fabs(cand - target) < best_dist) {
                    best = cand;
                    best_dist = fabs(cand - target);
                    found = true;
                }
            }
        }
        q[j] = best;
        inside = inside && found;
    }
    return inside;
}

void om_usable_hint(const om_solver_data *s, const double *hint, double *out)
{
    for (int j = 0; j < s->dof; j++)
        out[j] = s->revolute[j] && fabs(hint[j]) > HUGE_HINT ? om_wrap(hint[j]) : hint[j];
}
