/* The solves of system (9): starts, one problem's roots, and the entry points. Included by om_kernels.h, after what it declares. */
#ifndef OM_SOLVE_H
#define OM_SOLVE_H

/* The fixed-point start: where only q_J of it is known (*complete false), every joint of the
 * model IK at p_m = p_d (S-R-S: at the edge of reach beyond it) into start. */
void om_complete_start(om_problem *pb, double *start, bool *complete);
/* The paper's fixed-point start p_m = p_d, every joint: the model's IK at the target into
 * start; where p_d is outside the model's reach, the elbow held at the edge of reach (S-R-S)
 * or the point of the dp circle the model reaches with the smallest residual (q: scratch,
 * dof). Returns whether there is a start. */
bool om_fixed_point_start(om_problem *pb, double *q, double *start);
bool om_local_solve(om_problem *pb, double *start, bool *start_complete, double *q, double *pos, double *ori);
bool om_exists_other(om_problem *pb, bool skip_neighbours);
bool om_nearest_in_window(om_problem *pb, const double *hint, double *q);

/* solve.c */
typedef struct {
    int status;
    double position_error, orientation_error;
    int64_t evaluations;
    bool within_limits;
} om_result;

void om_flange_target(const double *T, const double *T_base_root, const double *T_tool_flange, mat3 *R, vec3 *p);
/* The problem of one solve: the target T, the branch signs, the redundancy values reduced
 * into reduced (n_redundancy; it must outlive the problem), joints kept at singularities
 * from q_prev. */
void om_problem_init(om_problem *pb, const om_solver_data *s, const double *T, const int64_t *signs,
                     const double *redundancy, double *reduced, const double *q_prev);
/* What a caller makes of a root: scan for a nearer one, take it as it is, or reject it and
 * every root at most as near the hint. */
typedef enum { OM_ROOT_SCAN = 0, OM_ROOT_TAKE = 1, OM_ROOT_REJECT = 2 } om_root_verdict;
/* A test of a root (a joint vector) with its caller's context. */
typedef om_root_verdict (*om_root_test)(const double *q, void *context);
/* One solve. hint NULL: no hint. as_is (NULL: none) judges a hinted solve's local root as
 * om_solve_near's does; where the local part fails, or as_is rejects, the bounded search
 * decides. */
om_result om_solve_one(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                       const double *hint, double *q_out, om_root_test as_is, void *context);
/* om_solve_one's local part alone, for a hint: the root the local solve from the hint
 * reaches, replaced by any root nearer the hint (a windowed scan), into q_out (revolute
 * joints at the turn nearest the hint). as_is (NULL: none) judges the local root (in q_out
 * when called): taken as it is, or rejected, without the scan. Returns false where the local
 * solve fails, without the bounded search that would follow in om_solve_one: a solution may
 * still exist (the path following halves such a step, where that search's costly "no" would
 * be wasted); and where as_is rejects. A candidate at a singular boundary is refined from the
 * hint's split of the singular joints alone (om_problem.split_starts), in the local solve and
 * in the scan (the model takes that split from the hint; the split starts begin 2 pi / 16 or
 * more from it in two joints, and cost a follow most of its time at an aligned wrist). result (NULL: not wanted): om_solve_one's
 * for the root. traces (NULL: none): the pose's self-motion a batch traced and kept, which the
 * scan's windows on the torus start from (om_problem.traces). */
bool om_solve_near(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                   const double *hint, double *q_out, om_root_test as_is, void *context, om_result *result,
                   const om_torus_memo *traces);
/* Every root (OM_MAX_ROOTS x dof) with per root (position error, orientation error, within limits)
 * in info (OM_MAX_ROOTS x 3). Returns the count; *evaluations the residual evaluations. */
int om_solve_all(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                 double *roots, double *info, int64_t *evaluations, bool band, om_scan_cache *cache);

#endif
