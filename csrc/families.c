/* Dispatch on the family code (om_redundant/om/families/dispatch.py calls it from Python). */
#include "om_kernels.h"

/* Solve the model arm for the flange pose (R, p) in DH frame 0; write q. redundancy[0] is the arm
 * angle of an S-R-S arm (unused for 6-DOF); all_joints false lets the S-R-S family skip the
 * shoulder. Returns the reach margin (negative beyond OM_REACH_SLACK: out of reach, q not written). */
double om_model_ik(int family, const double *P, const double *table, const mat3 *R, vec3 p, const int64_t *signs,
                   const double *redundancy, const double *q_prev, double *q, bool all_joints)
{
    if (family == OM_SRS)
        return om_srs_model_ik(P, R, p, signs, redundancy[0], q_prev, q, all_joints);
    return om_six_dof_model_ik(family, P, table, R, p, signs, q_prev, q);
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
