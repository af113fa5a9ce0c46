/* What a problem (om_problem) gives besides its residual: the same pose in another
 * configuration, the real arm's refinement toward its goal, the torus's shoulder-wrist
 * centre. Below every search that takes them (boundary.c, candidates.c, near.c,
 * loop_search.c, torus.c), so that none of them calls another for these. */
#include "om_system.h"

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

om_polish_task om_problem_polish_task(const om_problem *pb)
{
    const om_solver_data *s = pb->s;
    bool srs = s->family == OM_SRS;
    om_polish_task t = {s->real_table, s->n_real_rows, s->dof, srs ? s->params : NULL,
                        srs ? s->model_table : NULL, s->n_model_rows, pb->goal.R, pb->goal_p,
                        srs ? pb->redundancy[0] : 0.0, srs ? (double)pb->signs[OM_ELBOW_SIGN] : 0.0, true};
    return t;
}

vec3 om_shoulder_wrist_centre(const om_problem *pb)
{
    const double(*D)[3] = pb->s->D;
    return v_add(v_add(pb->p, pb->t.wrist), v_add(v_load(D[3], 0), m_mv(pb->t.R, v_load(D[0], 0))));
}
