/* A solve from the joints at the previous pose (om_redundant/ik/solver.py's OMSolver.solve_from;
 * the tracking step's first solve, tracking.c): the hinted solve whose local root is taken
 * without the windowed scan for a nearer one where it continues from the previous joints
 * beyond doubt (om_beyond_doubt, as follow.c takes its roots) along their first-order motion
 * to the target pose and arm angle,
 *     [J(q); Dpsi(q)] dq = [p_d - p; omega; wrap(psi_d - psi(q))]   (6-DOF: J(q) dq = [p_d - p; omega]),
 * J the flange's geometric Jacobian [v; omega] and omega = vee((E - E^T) / 2), E = R_d R^T, the
 * rotation vector of E to first order (all in DH frame 0, as om_self_motion_null's J). Else the
 * scan decides, and where the local solve fails, the bounded search: the root nearest the
 * previous joints, as the hinted solve's. (On a torus arm the scan is most of a hinted solve:
 * hundreds of evaluations, each a fixed point of the correction near a family.) */
#include <string.h>

#include "om_paths.h"

om_root_verdict om_on_step(const double *x, void *context) {
    const om_step_prediction *p = context;
    return om_beyond_doubt(p->dof, p->q, x, p->t, p->d, NULL) ? OM_ROOT_TAKE : OM_ROOT_SCAN;
}

/* dq above into dq (dof); false where the system is singular (a zero pivot, or dq not finite):
 * no prediction. */
static bool pose_motion(const om_solver_data *s, const double *T, const double *redundancy, const double *q,
                        double *dq) {
    int n = s->dof; /* 6, or 7 with the arm angle's row */
    double A[7 * 7], R[9], p[3], turn = 0.0;
    om_solver_jacobian(s, q, A, R, p); /* rows 0-5 of A; the flange (R, p) */
    if (n == 7) turn = om_wrap(redundancy[0] - om_solver_psi_gradient(s, q, A + 6 * 7));
    mat3 Rd;
    vec3 pd;
    om_flange_target(T, s->T_base_root, s->T_tool_flange, &Rd, &pd);
    mat3 E = m_mmt(Rd, m_load(R, 0));
    double b[7] = {pd.x - p[0], pd.y - p[1], pd.z - p[2], 0.5 * (E.r2.y - E.r1.z), 0.5 * (E.r0.z - E.r2.x),
                   0.5 * (E.r1.x - E.r0.y), turn};
    if (!om_eliminate(A, b, n, NULL)) return false;
    for (int i = 0; i < n; i++)
        if (!isfinite(b[i])) return false;
    memcpy(dq, b, (size_t)n * sizeof(double));
    return true;
}

om_result om_solve_from(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                        const double *q_prev, double *q_out) {
    double dq[OM_MAX_DOF];
    om_step_prediction moved = {s->dof, q_prev, dq, 1.0};
    bool predicted = s->mode != OM_FIXED && pose_motion(s, T, redundancy, q_prev, dq); /* (fixed dp: no scan) */
    return om_solve_one(s, T, signs, redundancy, q_prev, q_out, predicted ? om_on_step : NULL, &moved);
}
