/* The redundancy optimiser's kernels (om_redundant/redundancy/): the tracking step
 * (tracking.c), the clearance of an arm's geoms (clearance.c), the objective (objective.c), the
 * climb's QP in one variable (box_qp.c) and the bound of a climb's start (start_bounds.c). Their
 * CPython glue is csrc/binding/ (the same file names). */
#ifndef OM_REDUNDANCY_H
#define OM_REDUNDANCY_H

#include "om_kernels.h"
#include "om_paths.h" /* the self-motion's tangent and the paths' continuation tests */

/* ------------------------------------------------------------------------------------ */
/* box_qp.c: maximise phi(delta) = sum_g w_g min(cap_g, min_{j in g} v_j + a_j delta) - b delta^2 / 2
 * over [lo, hi] where every group with a floor keeps its minimum >= floor (the climb's QP and
 * the tracking step's). */

/* G groups of pieces concatenated: group g's pieces are ends[g] .. ends[g + 1] - 1 (at least
 * one each; ends[0] = 0), each group's weight, floor (-inf: none) and cap. */
typedef struct {
    const double *v, *a, *w, *floor, *cap;
    const int64_t *ends;
    ptrdiff_t G;
} om_qp_groups;

enum { OM_QP_NONE = 0, OM_QP_FOUND = 1, OM_QP_NO_MEMORY = -1 };
/* The maximiser into *delta; unless NULL, every piece's multiplier into z (0 for a piece that
 * cannot be its group's least within the box) and the model's gain model(delta) - b delta^2 / 2
 * - model(0) into *gain: OM_QP_FOUND, OM_QP_NONE where the floors leave no delta,
 * OM_QP_NO_MEMORY. The pieces and b are numbers (b > 0), lo <= hi. */
int om_qp_step(const om_qp_groups *q, double b, double lo, double hi, double *delta, double *gain, double *z);

/* ------------------------------------------------------------------------------------ */
/* start_bounds.c: what a climb from a start can reach. */

/* M samples of runs: psi (M,), values (M, columns) f and the groups' functions, slopes (M,
 * columns) their slope bounds on each sample's run, each group's first column (G, increasing,
 * >= 1), weights and caps (G,). */
typedef struct {
    const double *psi, *values, *slopes, *weights, *caps;
    const int64_t *groups;
    ptrdiff_t columns, G;
} om_start_samples;

/* The bound of a start k from its own cones, the smaller of f_k + L R and sum_g w_g min(cap_g,
 * min_j (v_jk + L_j R)); row: scratch (columns). */
double om_start_cone(const om_start_samples *s, ptrdiff_t k, double reach, double *row);
/* The bound of start k (its run's samples first .. last) within reach; row: scratch (columns). */
double om_start_bound(const om_start_samples *s, ptrdiff_t k, ptrdiff_t first, ptrdiff_t last, double reach,
                      double *row);

/* ------------------------------------------------------------------------------------ */
/* objective.c: f, M, D, the slack and S at a joint vector. */

typedef struct {
    const int64_t *limited; /* the L limited joints, their limits and half ranges */
    const double *lower, *upper, *half;
    ptrdiff_t L;
    const int64_t *joints; /* the K singularities' joints and offsets */
    const double *offsets;
    ptrdiff_t K;
    double margin_weight, clearance_weight, singularity_weight, clearance_cap, min_clearance, singularity_cap;
} om_objective_terms;

typedef struct {
    double value, margin, clearance, slack, singularity;
} om_evaluation;

/* The objective at q (dof) with the P pairs' distances d (P = 0: no obstacles). */
om_evaluation om_evaluate(const om_objective_terms *o, const double *q, const double *d, ptrdiff_t P);
/* The pieces v_j of the objective's groups at q (dof) and their rates a_j = dv_j/dq . t along
 * t (objective.py's Objective.groups with the tangent, concatenated in the groups' order), into
 * v and a (2L + P + K): the L limited joints' (q_i - l_i)/h_i, then their (u_i - q_i)/h_i; the
 * P pairs' d_k/d_cap with the rate grad_k . t / d_cap (grad: P x dof), a pair at 2 d_cap or
 * more taken there with rate 0 where some pair is nearer; the K singularities'
 * |sin x_k|/s_cap with the rate sign(sin x_k) cos x_k t_{j_k} / s_cap. */
void om_linearise(const om_objective_terms *o, ptrdiff_t dof, const double *q, const double *t, const double *d,
                  const double *grad, ptrdiff_t P, double *v, double *a);

/* ------------------------------------------------------------------------------------ */
/* clearance.c: distances of an arm's geoms and obstacle geoms. */

enum { OM_CORE_MUJOCO = 0, OM_CORE_POINT = 1, OM_CORE_SEGMENT = 2, OM_CORE_BOX = 3 };

/* An arm's links and geoms on them: its DH table (n_rows rows), the world pose of DH frame 0
 * (start: R row-major, p), each of the A geoms' link and offset (12), which joints slide. */
typedef struct {
    const double *table, *start, *offset;
    int n_rows, dof;
    const int64_t *link;
    const uint8_t *slide;
    ptrdiff_t A;
} om_arm_links;

/* The G = A + O geoms' cores (kind, radius, half sizes), the O obstacles' poses, and the P
 * pairs (arm geom, obstacle) with the sums of their bounding-sphere radii. */
typedef struct {
    const double *obstacle_pos, *obstacle_mat, *radius, *half, *bounds;
    const int64_t *kind, *pairs;
    ptrdiff_t G, P;
} om_geom_cores;

/* The world poses xpos (A, 3), xmat (A, 9) of the arm's geoms at q. */
void om_arm_geom_poses(const om_arm_links *arm, const double *q, double *xpos, double *xmat);
/* The pairs' distances (P) capped at reach and nearest points (P, 6) at each of M rows of q (dist
 * (M, P), fromto (M, P, 6); unless given, written, nan for the pairs MuJoCo must compute), and
 * unless grad is NULL their gradients (M, P, dof), in a row with a pair nearer than near only
 * those of the pairs nearer than it. work: the G geoms' poses (12 G; the obstacles' copied in).
 * Returns the pairs left to MuJoCo. */
long om_arm_clearance(const om_arm_links *arm, const om_geom_cores *geoms, ptrdiff_t M, const double *q,
                      double reach, double near, double *dist, double *fromto, double *grad, bool given,
                      double *work);
/* ------------------------------------------------------------------------------------ */
/* segment_clearance.c: the clearance along a straight joint-space segment. */

/* A segment from q_from to q_to (dof) and its samples' rows (capacity x dof: the ends, then a
 * round's midpoints after another's) and their P pairs' distances (capacity x P), which
 * distances(context, start, stop) computes for rows start .. stop - 1 (0, or -1 on an error). */
typedef struct {
    int dof;
    ptrdiff_t pairs, capacity;
    const double *q_from, *q_to;
    double *rows, *dist;
    int (*distances)(void *context, ptrdiff_t start, ptrdiff_t stop);
    void *context;
} om_segment;

enum { OM_SEGMENT_OK = 0, OM_SEGMENT_FAILED = 1, OM_SEGMENT_FULL = 2, OM_SEGMENT_NO_MEMORY = -1 };
/* The clearance along the segment as far as it matters against floor (segment_clearance.c: the
 * rule), L = lipschitz, at most `budget` samples inside it, pieces within `tolerance` not split;
 * *status OM_SEGMENT_OK, or FAILED (distances failed), FULL (more rows than capacity),
 * NO_MEMORY, each with NaN. */
double om_segment_minimum(const om_segment *s, double lipschitz, double floor, double budget, double tolerance,
                          int *status);

/* The signed distance of a sphere or capsule (pos, mat, half sizes (0, 0, l), radius) that
 * overlaps a box (box_pos, box_mat, box_half), its nearest points into fromto (6). */
double om_box_overlap(const double *pos, const double *mat, const double *half, double radius,
                      const double *box_pos, const double *box_mat, const double *box_half, double *fromto);

/* ------------------------------------------------------------------------------------ */
/* tracking.c: the tracking step. */

/* What om_track answers. */
enum { OM_TRACK_OK = 0, OM_TRACK_NO_SOLUTION = 1, OM_TRACK_SINGULAR = 2, OM_TRACK_INFEASIBLE = 3, OM_TRACK_LEFT = 4 };
#define OM_TRACK_MAX_PIECES 512

/* The optimiser's fixed data and a step's clearances linearised about q_ref. */
typedef struct {
    const om_solver_data *s;
    const double *lower, *upper;            /* (7,) joint limits */
    const double *sing_joint, *sing_offset; /* (n_sing,) the singularities' joints and constants */
    int n_sing;
    const double *q_ref, *clear_d, *clear_g; /* (7,), (n_clear,) metres, (n_clear, 7) */
    int n_clear;
    double clearance_cap, singularity_cap, joint_step;
    double weight[3], floor[3], cap[3]; /* of the groups margin, clearance, singularity (om_tracking_groups) */
} om_tracking;

/* The groups' weights (w_m, w_c, w_s), floors (0, clearance_floor = d_min / d_cap) and caps. */
void om_tracking_groups(om_tracking *tr, double w_m, double w_c, double w_s, double clearance_floor);

/* A step taken: the new psi, the step, the next curvature, the second solve's errors,
 * evaluations and within_limits (the objective at the new joints: objective.c's om_evaluate). */
typedef struct {
    double psi, step, curvature, position_error, orientation_error;
    int64_t evaluations;
    bool within_limits;
} om_tracked;

/* From (psi, q_prev) to pose T (signs): the new joints into q1, the step into out; OM_TRACK_OK
 * or why not. Not reentrant (static scratch): the binding holds the GIL. */
int om_track(const om_tracking *tr, const double *T, const int64_t *signs, double psi, const double *q_prev,
             double max_step, double curvature, double *q1, om_tracked *out);

#endif
