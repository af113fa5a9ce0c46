/* Dispatch on the family code (om_redundant/ik/families/dispatch.py calls it from Python). */
#include "om_kernels.h"

/* The target for the flange orientation R (and, S-R-S, the arm angle redundancy[0]): what
 * every model solve for this orientation shares, computed once. */
om_target om_target_at(int family, const double *P, const mat3 *R, const double *redundancy)
{
    om_target t = {.R = *R, .psi = family == OM_SRS ? redundancy[0] : 0.0};
    if (family == OM_SRS)
        om_srs_target(P, &t);
    else
        om_six_dof_target(P, &t);
    return t;
}

/* Solve the model arm for the target t's orientation and the position p in DH frame 0; write q.
 * all_joints false lets the S-R-S family skip the shoulder. Returns the reach margin (negative
 * beyond OM_REACH_SLACK: out of reach, q not written). */
double om_model_ik(int family, const double *P, const double *table, const om_target *t, vec3 p,
                   const int64_t *signs, const double *q_prev, double *q, bool all_joints)
{
    if (family == OM_SRS)
        return om_srs_model_ik(P, t, p, signs, q_prev, q, all_joints);
    return om_six_dof_model_ik(family, P, table, t, p, signs, q_prev, q, false);
}

double om_model_ik_nearest(int family, const double *P, const double *table, const om_target *t, vec3 p,
                           const int64_t *signs, const double *q_prev, double *q)
{
    if (family != OM_SRS)
        return om_six_dof_model_ik(family, P, table, t, p, signs, q_prev, q, true);
    double x, margin = om_srs_reach(P, t, p, &x);
    if (margin >= -OM_REACH_SLACK)
        return om_srs_model_ik(P, t, p, signs, q_prev, q, true);
    return om_srs_model_ik_at_reach(P, t, p, signs, q_prev, q) ? margin : NAN;
}

/* The quantities whose signs are the configuration's branch signs at q. */
void om_branch_values(int family, const double *P, const double *q, double *out)
{
    if (family == OM_SRS)
        om_srs_branch_values(P, q, out);
    else
        om_six_dof_branch_values(family, P, q, out);
}

/* The redundancy values at q: out[0] = the arm angle for S-R-S; nothing for 6-DOF. */
void om_redundancy_values(int family, const double *P, const double *q, double *out)
{
    if (family == OM_SRS)
        out[0] = om_srs_arm_angle(P, q);
}
