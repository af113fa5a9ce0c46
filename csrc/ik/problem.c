/* A problem's relatives: the same pose in another configuration (om_problem_at), and what
 * the refinement on the real arm is asked for its candidates (om_problem_polish_task). */
#include "om_system.h"
#include "boundary.h"

om_polish_task om_problem_polish_task(const om_problem *pb)
{
    const om_solver_data *s = pb->s;
    bool srs = s->family == OM_SRS;
    om_polish_task t = {s->real_table, s->n_real_rows, s->dof, srs ? s->params : NULL,
                        srs ? s->model_table : NULL, s->n_model_rows, pb->goal.R, pb->goal_p,
                        srs ? pb->redundancy[0] : 0.0, srs ? (double)pb->signs[ELBOW_SIGN] : 0.0, true};
    return t;
}

om_problem om_problem_at(const om_problem *pb, const int64_t *signs, const double *redundancy)
{
    const om_solver_data *s = pb->s;
    om_problem other = *pb;
    other.signs = signs;
    other.redundancy = redundancy;
    other.goal = om_target_at(s->family, s->params, &pb->goal.R, redundancy);
    other.t = other.goal;
    other.counter = 0;
    return other;
}
