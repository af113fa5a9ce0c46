/* The arm's own joint coordinates: q = flip * q_n, q_n the kernels' (a near arm's reversed
 * axes turn the other way in its nominal arm), and what the solver computes at a q given in
 * them. Apart from near.c, so that what works in either coordinates (self_motion.c, solve.c,
 * the binding) depends on no search. */
#include "om_kernels.h"

void om_flip(const om_solver_data *s, const double *in, double *out)
{
    for (int j = 0; j < s->dof; j++)
        out[j] = s->flip[j] * in[j];
}

/* q in the kernels' coordinates into scratch, returned (q itself where nothing is flipped). */
static const double *_kernels(const om_solver_data *s, const double *q, double *scratch)
{
    if (!s->flipped)
        return q;
    om_flip(s, q, scratch);
    return scratch;
}

void om_solver_jacobian(const om_solver_data *s, const double *q, double *J, double *R, double *p)
{
    static const double eye[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    double scratch[OM_MAX_DOF];
    int dof = s->dof;
    om_jacobian(s->real_table, s->n_real_rows, eye, eye, _kernels(s, q, scratch), dof, J, R, p);
    for (int i = 0; i < 6 && s->flipped; i++)
        for (int j = 0; j < dof; j++)
            J[i * dof + j] *= s->flip[j];
}

double om_solver_psi_gradient(const om_solver_data *s, const double *q, double *grad)
{
    double scratch[OM_MAX_DOF];
    double psi = om_arm_angle_gradient(s->params, s->model_table, s->n_model_rows, _kernels(s, q, scratch), grad);
    if (s->flipped)
        om_flip(s, grad, grad);
    return psi;
}

void om_solver_configuration_values(const om_solver_data *s, const double *q, double *branch, double *redundancy)
{
    double scratch[OM_MAX_DOF];
    const double *at = _kernels(s, q, scratch);
    om_branch_values(s->family, s->params, at, branch);
    if (redundancy)
        om_redundancy_values(s->family, s->params, at, redundancy);
}
