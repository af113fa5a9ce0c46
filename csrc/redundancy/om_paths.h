/* The solution paths of a 7-DOF arm in the arm angle psi: the tangents (self_motion.c,
 * tangents.c), a path followed (follow.c), a branch's grid roots linked into paths (link.c)
 * and the cell test between neighbouring samples (cells.c). Plain C: the binding of these
 * (Python's arguments, results and errors) is csrc/binding/paths.c and csrc/binding/cells.c. */
#ifndef OM_PATHS_H
#define OM_PATHS_H

#include "om_kernels.h"

/* self_motion.c: dq/dpsi of a 7-DOF arm at q into t (see there), both in the arm's own joint
 * coordinates; false where psi does not move along the self-motion, |Dpsi . n| <= tol |Dpsi|
 * |n| (or t is not finite). */
bool om_self_motion_tangent(const om_solver_data *s, const double *q, double *t, double tol);
/* Whether q1 (at psi + d) continues the self-motion from q0 with tangent t (paths.py's
 * Probe.continues): no joint moved more than 1 rad, and |dq - t d|_inf <= |dq|_inf / 2 + 1e-6;
 * t NULL: only that no joint jumped. cyclic (NULL: none): joints compared modulo 2 pi. */
bool om_continues(int dof, const double *q0, const double *q1, const double *t, double d, const uint8_t *cyclic);
/* Whether q1 continues the path from (q0, t) d ahead beyond doubt: no joint moved more than
 * 1 rad and the first-order prediction's error is within 1/4 of the joint step. A root of
 * another path is off by the paths' separation, which no shorter step shrinks; one that
 * merely continues (om_continues: within 1/2) may be the partner at a fold. */
bool om_beyond_doubt(int dof, const double *q0, const double *q1, const double *t, double d, const uint8_t *cyclic);
/* A step's prediction for om_on_step: q d ahead of q along t (dof joints). */
typedef struct {
    int dof;
    const double *q, *t;
    double d;
} om_step_prediction;
/* solve_from.c: an om_root_test (context: om_step_prediction) taking a root that continues the
 * prediction beyond doubt, else asking for the scan. */
om_root_verdict om_on_step(const double *x, void *context);
/* solve_from.c: the solve from the joints q_prev at the previous pose: its local root taken
 * where it continues them beyond doubt along the hand's motion, else the root nearest them
 * (om_solve_one with the hint q_prev). */
om_result om_solve_from(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                        const double *q_prev, double *q_out);
/* The largest joint step |q1 - q0|_inf, cyclic joints (NULL: none) modulo 2 pi (Probe.step; numpy's
 * remainder and maximum: a NaN step is NaN). */
double om_largest_joint_step(int dof, const double *q0, const double *q1, const uint8_t *cyclic);

/* Paths in the arm angle (probe.py's END_TOLERANCE, SAME, JUMP and _AIM, read from here): a
 * following step below OM_END_TOLERANCE (rad) has ended its path; two solutions at one psi
 * within OM_PATH_SAME (rad, max-norm) are one; neighbouring solutions of one path are at most
 * OM_PATH_JUMP (rad, max-norm) apart; a step aimed at a path's predicted end goes
 * OM_FOLLOW_AIM of the way there. */
#define OM_END_TOLERANCE 1e-9
#define OM_PATH_SAME 1e-6
#define OM_PATH_JUMP 1.0
#define OM_FOLLOW_AIM (63.0 / 64.0)
/* follow.c: what om_follow_path answers. */
enum { OM_FOLLOW_ARRIVED = 0, OM_FOLLOW_ENDED = 1, OM_FOLLOW_STALLED = 2 };
/* A path that runs within rounding of a singular set (the Panda's self-motion through
 * q2 = q6 = 0 at the pose of its q = 0) is accepted only in steps of ~1e-6 rad, millions of
 * them, each a windowed scan: a follow stalls (is not followed further) after
 * OM_FOLLOW_CRAWL_STEPS accepted steps in a row shorter than OM_FOLLOW_CRAWL (rad; an end
 * approached by aimed steps takes two or three), or after OM_FOLLOW_MAX_ATTEMPTS attempts (the
 * most seen in 2,000 global choices on 6 arms: 58). */
#define OM_FOLLOW_CRAWL 1e-5
#define OM_FOLLOW_CRAWL_STEPS 16
#define OM_FOLLOW_MAX_ATTEMPTS 256
/* A 7-DOF branch at one pose, as om_follow_path and om_link_paths follow its paths: its solver
 * (S-R-S), pose, signs, the joints compared modulo 2 pi (cyclic) and taken nearest mid-range
 * centre (centred), and the pose's self-motion a batch traced and kept (traces; NULL: none;
 * om_problem.traces). */
typedef struct {
    const om_solver_data *s;
    const double *T, *centre;
    const int64_t *signs;
    const uint8_t *cyclic, *centred;
    const om_torus_memo *traces;
} om_branch;
/* A 7-DOF branch's solution path followed from (*psi, q, t) (t = dq/dpsi) towards target
 * (probe.py's Probe.follow), *psi, q and t updated in place to the point reached, *steps the
 * accepted steps: OM_FOLLOW_ARRIVED there, OM_FOLLOW_ENDED where the step fell below min_step
 * (the path ended on the way; a root without a tangent, a fold met exactly, fails its step as
 * any other, so the path ends beside it), OM_FOLLOW_STALLED after
 * OM_FOLLOW_MAX_ATTEMPTS attempts (the point reached: the last accepted). */
int om_follow_path(const om_branch *branch, double *psi, double *q, double *t, double target, double min_step,
                   int *steps);
/* tangents.c: om_self_motion_tangent of each of the rows of q (rows x 7, row-major) into t,
 * a row of NaN where psi does not move along the self-motion. */
void om_self_motion_tangents(const om_solver_data *s, const double *q, double *t, ptrdiff_t rows);

/* link.c: what om_link_paths answers (ckernels.LINK_DONE, ...): the paths linked; more rows
 * added than the capacity; no memory for its scratch. */
enum { OM_LINK_DONE = 0, OM_LINK_FULL = 1, OM_LINK_NO_MEMORY = 2 };
/* A branch's grid roots to link into paths, and where the paths go (link.c's top comment). */
typedef struct {
    om_branch branch;
    /* the grid (n psi, increasing within a turn) and its roots: counts[k] of them at grid[k],
     * m in all, their joints q and tangents t (m x 7) */
    int64_t n, m;
    const double *grid, *q, *t;
    const int64_t *counts;
    /* the rows that following adds (capacity of them): new_psi, new_q and new_t (x 7); each
     * path's rows in order into members ((m + capacity) x 2: the row, the turns of psi it is
     * taken at), and into paths ((m + capacity) x 2) where its members end and its turns (a
     * loop's, else 0) */
    int64_t capacity;
    double *new_psi, *new_q, *new_t;
    int64_t *members, *paths;
} om_link_job;
/* The paths of job (link.c's top comment): OM_LINK_DONE and *n_paths of them, or why not; *added
 * the rows that following added. */
int om_link_paths(const om_link_job *job, int64_t *added, int64_t *n_paths);

/* cells.c: the feasibility functions g (M x (L + P)) and their rates dg of the M rows q (M x
 * dof) with dq/dpsi = t, the pairs' distances d (M x P) and gradients grad (M x P x dof); the
 * L limited joints' indices, lower and upper limits and half ranges; numbers: 2 d_cap, d_cap,
 * d_min / d_cap (binding/cells.c: pieces). */
void om_pieces(ptrdiff_t dof, ptrdiff_t M, ptrdiff_t L, ptrdiff_t P, const double *q, const double *t,
               const double *d, const double *grad, const int64_t *limited, const double *lower,
               const double *upper, const double *half, const double *numbers, double *g, double *dg);
/* The Hermite models of a cell's n pieces between its ends a and b over a parameter s of the
 * cell (0 at a, 1 at b): their values ga, gb, their rates along psi da, db, dpsi/ds at a and b
 * (span_a, span_b: both psi_b - psi_a for models in psi; om_chord_spans' for models along the
 * chord), and the basis H (4 x N) at the cell's N points. */
typedef struct {
    const double *ga, *da, *gb, *db, *H;
    double span_a, span_b;
    ptrdiff_t n, N;
} om_cell_models;
/* dpsi/ds at the ends a and b of a cell of a path (joints qa, qb, tangents dq/dpsi ta, tb;
 * the cyclic joints compared modulo 2 pi) for the parameter s that moves the joints at the
 * cell's chord length |qb - qa|_2 at both ends: that length over |t|_2 at each (0 where t = 0,
 * whose rates are 0) (binding/cells.c: cell_spans). */
void om_chord_spans(int dof, const uint8_t *cyclic, const double *qa, const double *ta, const double *qb,
                    const double *tb, double spans[2]);
/* The fraction of the cell where its models predict a feasibility that ends feasible fa, fb do
 * not explain (binding/cells.c: surprise), or -1 where there is none; live: room for c->n
 * piece indices. */
double om_surprise(const om_cell_models *c, int fa, int fb, double slack, ptrdiff_t *live);
/* The fraction of the cell where the first of the models reaches zero from a feasible end a
 * (binding/cells.c: crossing), or -1 where none does. */
double om_crossing(const om_cell_models *c);
/* The samples of paths: M of them, each's joints q and tangent t (M x dof each), psi,
 * feasibility functions g and rates dg (M x n), and feasibility. */
typedef struct {
    double *q, *t, *psi, *g, *dg;
    uint8_t *feasible;
} om_cell_samples;
/* The first looks into the cells of one path, samples a .. b - 1 of s (cell k: samples k,
 * k + 1), into first (binding/cells.c: cell_looks); live: room for n piece indices. */
void om_path_looks(const om_cell_samples *s, ptrdiff_t a, ptrdiff_t b, ptrdiff_t dof, ptrdiff_t n,
                   const uint8_t *cyclic, double fine, double slack, const double *H, ptrdiff_t N, double *first,
                   ptrdiff_t *live);

#endif
