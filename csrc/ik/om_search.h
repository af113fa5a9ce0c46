/* The searches of system (9): an arm near a family, the residuals, the 1-D root finders, the
 * circle's and the torus' bounded searches, verification, polish and the singular boundary. Included by om_kernels.h, after what it declares. */
#ifndef OM_SEARCH_H
#define OM_SEARCH_H

/* near.c: an arm near a family (om_solver_data.nominal_table). */
/* One model IK of system (9) at pb's model side (t, p): the reach margin, q written where it is
 * not below -OM_REACH_SLACK, and the residual it serves into *residual (g: its size sets how far
 * a near arm's correction settles; INFINITY: none); with nearest, also where it is out of
 * reach: the closed form of the nearest pose the model reaches (om_model_ik_nearest; NaN: none
 * written). */
typedef double (*om_model_eval)(om_problem *pb, const void *args, double *q, bool nearest, double *residual);
/* For an arm near a family: eval from pb's goal, then again with pb's model side moved to
 * goal C(q) until the correction C settles (the fixed point of near.c's (N), to the precision
 * its residual needs), the model side the goal again at the end. Returns the margin of the last
 * evaluation, q as it wrote it: a function of eval's arguments and the goal alone. om_near_ik
 * (om_system.h) is the call for every arm. */
double om_near_settle(om_problem *pb, om_model_eval eval, const void *args, double *q);
/* pb's goal (R, p), with the closed form's constants for pb->redundancy, and its model side,
 * the goal itself (pb->s and pb->redundancy set). */
void om_set_goal(om_problem *pb, const mat3 *R, vec3 p);
/* An arm near a family's root q (the kernels' coordinates) to its last digits: a few Gauss-Newton
 * steps on its exact chain (near.c: NEAR_POLISH), where q is within NEAR_POLISH_FROM of the
 * pose; q replaced, and its errors into *pos, *ori (NULL: not wanted), only where the polished
 * one verifies with smaller errors. Returns whether q verifies at the end. */
bool om_near_polish(om_problem *pb, double *q, double *pos, double *ori);
/* out = flip * in: the arm's own joint coordinates to the kernels' and back (out may be in). */
void om_flip(const om_solver_data *s, const double *in, double *out);
/* At q in the arm's own joint coordinates: the real arm's flange Jacobian in DH frame 0 (6 x dof,
 * rows [v; omega], columns by the arm's joints) and the flange pose (R, p; NULL: not wanted); the
 * model's arm angle psi (returned) and its gradient by the arm's joints (S-R-S); the model's
 * branch quantities and redundancy values (NULL: not wanted), which read q's configuration. */
void om_solver_jacobian(const om_solver_data *s, const double *q, double *J, double *R, double *p);
double om_solver_psi_gradient(const om_solver_data *s, const double *q, double *grad);
void om_solver_configuration_values(const om_solver_data *s, const double *q, double *branch, double *redundancy);

/* The deviation (m, om_solver_data.near_deviation) up to which a near arm's bounded search of
 * the circle scans its nominal arm's g and searches G in windows where it may differ (circle.c);
 * beyond it, where most of the circle would be windows, the search is of G throughout. */
#define OM_NEAR_SCAN 1e-4
/* A bound, with room, on how far the correction moves g (rad), the reach margins and the branch
 * quantities per metre of the deviation, away from the model's singular set (1 to 20 there). */
#define OM_NEAR_SENSITIVITY 100.0

/* residual.c */
vec3 om_delta(const double D[6][3], double w);
/* The model's hand position on the circle, p_d + R delta(w) (not counted as an evaluation). */
vec3 om_on_circle(const om_problem *pb, double w);
double om_model_ik_at(om_problem *pb, double w, double *q, bool all_joints); /* returns the reach margin */
double om_g_margin(om_problem *pb, double w, double *q, bool all_joints, double *margin); /* g (NaN out of reach) */
double om_g(om_problem *pb, double w, double *q, bool all_joints);
/* om_g_margin's margin alone (S-R-S: no joint solved, not counted). */
double om_reach_margin(om_problem *pb, double w, double *q);
/* What om_srs_reach_possible keeps across the cells of one scan: the bound on the elbow's |x''|
 * along the circle (NaN: not yet computed), x at w, the last cell's end (NaN: none), and the
 * scan's samples w_k = lo + h k, k < n, whose parts are known (samples NULL: none). */
typedef struct {
    double curvature, w, x;
    const om_srs_elbow *samples;
    double lo, h;
    int n;
} om_reach_bound;
#define OM_REACH_BOUND_NONE ((om_reach_bound){NAN, NAN, NAN, NULL, 0.0, 0.0, 0})
/* S-R-S: whether the model may reach the circle's points somewhere in [a, b] (a bound; see residual.c). */
bool om_srs_reach_possible(om_problem *pb, om_reach_bound *bound, double a, double b);
/* S-R-S: W(w) - S = e + u1 cos w + u2 sin w on the circle. */
void om_srs_wrist_circle(const om_problem *pb, vec3 *e, vec3 *u1, vec3 *u2);
/* circle.c: whether the reach margin, sampled as ms (count samples), may reach zero between
 * samples i and i + 1, both out of reach. */
bool om_margin_may_reach(const double *ms, int i, int count, bool cyclic);
/* The model's hand position at the torus point (w1, w7) (not counted as an evaluation). */
vec3 om_torus_point(const om_problem *pb, double w1, double w7);
vec3 om_lifted_residual(om_problem *pb, vec3 x, double *q);
/* A 6-DOF arm's residual about joint 1's axis (om_six_dof_model_ik_about_axis) at x = (w5, w6, q1,
 * gamma) for p_m = p_d + R delta(w5, w6), one evaluation: the model IK into q (every joint), the
 * four residuals into F. */
void om_axis_residual(om_problem *pb, const double *x, double *q, double *F);
vec3 om_deflated_residual(om_problem *pb, vec3 x, double *q, const double *known, int n_known); /* known: n x 3 */
double om_max_norm(vec3 F);
/* 6-DOF circle arms: the wrist's consistency with q_J = w given (NaN out of reach). */
double om_wrist_residual(om_problem *pb, double w, double *q);

/* scalar.c */
double om_secant(om_problem *pb, double w0, double *q);
/* om_secant from w0 or, out of the model's reach there, the nearest reachable probe around the circle. */
double om_secant_in_reach(om_problem *pb, double w0, double *q);
double om_refine_bracket(om_problem *pb, double a, double ga, double b, double gb, double *q);
double om_reach_edge(om_problem *pb, double inside, double outside, double *q);
/* The secant on om_wrist_residual from w0; returns |residual| at the end. */
double om_wrist_secant(om_problem *pb, double w0, double *q);
/* Brent's search for the max of sign * g (or of the margin); returns argmax, g and margin there. */
double om_extremum(om_problem *pb, double a, double b, double x0, double sign, bool of_margin, double *q,
                   double *g_out, double *margin_out);

/* circle.c: candidates into cands (capacity cap); returns the count; a root known at w = known
 * (NaN: none) is not a candidate again (circle_scan). On an S-R-S arm whose dp turns with q7 the
 * scan's samples take the model's parts from pb->memo where it holds them, and keep them there
 * (the same bits as computed). */
int om_circle_candidates(om_problem *pb, double lo, double hi, int n_pts, bool full_circle, double known, double *q,
                         double *cands, int cap);
/* circle_samples.c: a scan memo for the problems of solver s, none held yet (NULL: an arm whose scans keep none,
 * or out of memory); freed by om_scan_memo_free (NULL: nothing). */
om_scan_memo *om_scan_memo_new(const om_solver_data *s);
void om_scan_memo_free(om_scan_memo *memo);
/* torus.c: a torus memo for the problems of solver s, none held yet (NULL: an arm whose torus
 * grid has no terms, not S-R-S on the torus, or out of memory); freed by om_torus_memo_free. */
om_torus_memo *om_torus_memo_new(const om_solver_data *s);
void om_torus_memo_free(om_torus_memo *memo);
/* torus.c: each ELBOW sign's traced self-motion that from holds moved into into where into holds
 * none for that sign yet (the grid's terms dropped), from left without it: a batch's traces kept
 * for the follows after it (om_problem.traces). Write once: what into holds is never freed
 * before into, so a follow on another thread can read it while a batch takes more. */
void om_torus_memo_take(om_torus_memo *into, om_torus_memo *from);
/* wrist_offset_bands.c: candidates in the bands around the singular wrist of an arm with a4 != 0. */
#define OM_WRIST_BAND_CANDIDATES 256 /* room for them */
int om_wrist_offset_candidates(om_problem *pb, double lo, double hi, bool full_circle, double *q, double *cands,
                               int cap);

/* torus_newton.c */
double om_lifted_solve(om_problem *pb, const double *start, double *q);
/* The candidates a torus search hands to verification, in order: q (dof each) of the first cap
 * of them, count in all (beyond cap: not all kept). */
typedef struct {
    double *q;
    int cap, count;
} om_candidate_log;
int om_torus_roots(om_problem *pb, int n, double *roots, const double *centre, double radius, const double *found,
                   om_candidate_log *log);
/* contraction.c: bounds g1, g7 on the rates of q1 and q7 of the model IK per unit of the
 * shoulder-wrist vector x over the ball of radius rho about that of the hand position p (inf
 * where there is none: a singular shoulder or wrist, the edge of reach, psi's half-line), so
 * that G(w) = (q1, q7) at the torus points w whose x lies in the ball has |dG_i| <= g_i |dx|;
 * and whether the model reaches no point of that ball. q gets the model IK at p where the
 * elbow can be bounded (else NaN as it was). */
typedef struct {
    double g1, g7;
    bool unreachable;
} om_torus_bound;
om_torus_bound om_torus_bound_on(om_problem *pb, vec3 p, double rho, double *q);
/* The bound on the square C' of half-width 2 h about the torus point (w1, w7), which holds
 * the cell of half-width h there (its ball: radius (r_a + r_d) min(2 h, 2) about x(w1, w7);
 * q: the model IK there, G's value); h >= pi: on the whole torus (the ball of radius r_a + r_d
 * that holds it; q: the model IK at its centre). */
om_torus_bound om_torus_cell_bound(om_problem *pb, double w1, double w7, double h, double *q);
/* Where the bounds prove them (cells of the torus without a root, or with exactly one, where G
 * contracts: found and verified), every root of the configuration whose (q1, q7) lies within
 * radius of the centre's (radius >= pi / 4: on the whole torus, a superset) into roots, the
 * count into *count, on an arm whose offsets are small against it; returns whether it did
 * (false: the grid search decides). */
bool om_torus_certified_roots(om_problem *pb, double *roots, int *count, const double *centre, double radius);
/* torus_half_line.c: x = W - S of the model on the torus less its parts that turn with w1 and w7:
 * p_d + R w_F - S + D3 + R D0 (x = it + D4 cos w1 + D5 sin w1 + R (D1 cos w7 + D2 sin w7)). */
vec3 om_shoulder_wrist_centre(const om_problem *pb);

/* verify.c */
/* Whether q is in the configuration (signs, redundancy): every branch quantity of q has the
 * requested sign or lies within OM_BRANCH_BAND of zero (q belongs to both neighbouring
 * configurations there), and the redundancy values, read in the requested branches, are
 * the requested ones. */
bool om_in_configuration(const om_solver_data *s, const double *q, const int64_t *signs, const double *redundancy);
bool om_trig_shared(const om_solver_data *s);
bool om_verify(om_problem *pb, const double *q, double *pos, double *ori); /* returns accepted */
int om_add_root(om_problem *pb, const double *q, double *roots, int count); /* roots: OM_MAX_ROOTS x dof */
bool om_representative(double *q, int dof, const uint8_t *revolute, const double *lower, const double *upper,
                       const double *hint, bool has_hint);
/* The hint as a solve uses it (dof entries into out): a revolute joint's value beyond
 * HUGE_HINT (1e4 rad) reduced exactly into [-pi, pi] by remainder. A joint value of
 * magnitude |h| carries rounding of ulp(|h|) / 2 (3e-11 rad at 3e5), which the FK's
 * q + theta and two FKs' different sums turn into pose errors of 1e-10, and a local solve
 * started there keeps that magnitude; at 1e4 rad the rounding is 1e-12. */
void om_usable_hint(const om_solver_data *s, const double *hint, double *out);

/* polish.c: damped Gauss-Newton on the REAL arm's chain toward the flange pose (R, p) in DH
 * frame 0 and, with P not NULL (an S-R-S model's parameters and model table), the arm angle psi. */
typedef struct {
    const double *table; /* the real arm's DH table, n_rows x 6 */
    int n_rows, dof;
    const double *P, *model_table; /* P NULL: no arm-angle row */
    int n_model_rows;
    mat3 R;
    vec3 p;
    double psi;
    double elbow; /* psi read in this ELBOW branch (+-1); 0: in q's own */
    bool give_up_crawl; /* stop a crawl far from a root (see om_polish) */
} om_polish_task;

/* Refine q in place (at most `iterations` Jacobians); returns the residual's norm at the end. */
double om_polish(const om_polish_task *t, int iterations, double *q);

/* What one problem of a batch keeps for the next (solve_all_rows): the circle search's
 * candidates (search.c), for a next problem that differs from it in the SHOULDER sign alone,
 * the loop search's gate (loop_search.c), for a next problem of the same pose, and the scan
 * memo (circle.c), for the next scan of the same pose in the same ELBOW sign. On an S-R-S arm
 * whose dp turns with q7 the circle residual g(w) is the model's q7 less w, and q7 does not
 * depend on the SHOULDER sign (srs.c, q7_with_elbow): the scan, its brackets and refinements
 * are the same, only the joints that each candidate becomes differ. On the torus the grid
 * search's candidates (joint vectors, dof each) are shared by the problems that differ in the
 * SHOULDER and WRIST signs alone (the lifted residual reads neither). The gate depends on the
 * pose alone. */
typedef struct {
    bool valid;
    double key[OM_SCAN_KEY];  /* the target, psi, the other signs, q_prev, the scan points */
    int count;                /* candidates (on the torus: joint vectors) */
    int64_t evaluations;      /* the residual evaluations they took */
    double q[OM_MAX_DOF];     /* the scratch joints as the search left them */
    double *candidates;       /* capacity of them */
    int capacity;
    bool gate_valid, gate;        /* the gate asked last, and its answer */
    double gate_key[OM_GATE_KEY]; /* what the gate reads of its pose */
    om_scan_memo *memo;           /* the problems' (om_problem.memo; NULL: none) */
    om_torus_memo *torus_memo;    /* the problems' (om_problem.torus_memo; NULL: none) */
} om_scan_cache;
#define OM_SCAN_CAPACITY(n_scan) (8 * (n_scan) + 8 + OM_WRIST_BAND_CANDIDATES)

/* boundary.c */
/* A candidate q that failed verification, refined on the real arm where a branch quantity is
 * within 1e-2 of zero, or (S-R-S) w_hat within 1e-2 rad of psi's singular half-line, or (an
 * arm near a family) where it is within NEAR_POLISH_FROM of the pose (om_near_polish; else
 * left as it is); returns whether it now verifies. */
bool om_polish_candidate(om_problem *pb, double *q, double *pos, double *ori);
/* problem.c: the refinement on the real arm toward pb's goal (with psi, S-R-S: in the
 * requested ELBOW branch), giving up a crawl far from a root (om_polish). */
om_polish_task om_problem_polish_task(const om_problem *pb);
/* self_motion.c: the null vector of the real 6 x 7 Jacobian at q (the kernels' coordinates) by
 * cofactors (not normalised) */
void om_self_motion_null(const om_solver_data *s, const double *q, double *n);
/* det A (n x n row-major, destroyed) into *det (NULL: not wanted) by elimination with partial
 * pivoting and, b not NULL, x of A x = b into b; false where a pivot is zero (*det = 0). */
bool om_eliminate(double *A, double *b, int n, double *det);
/* The null vector of the m x (m + 1) matrix J (row-major, m <= 6) by cofactors into n (m + 1):
 * n_c = (-1)^c det J_{-c}, J without column c (not normalised; 0 where J's rank is short). */
void om_null_vector(const double *J, int m, double *n);
/* boundary.c: om_add_root of q, polished first where it fails verification near the boundary. */
int om_add_candidate(om_problem *pb, double *q, double *roots, int count);
/* problem.c: pb's pose in another configuration (signs, redundancy: kept by the caller), its target's
 * constants for that redundancy, its evaluation counter at zero. */
om_problem om_problem_at(const om_problem *pb, const int64_t *signs, const double *redundancy);

/* bands.c: for a configuration whose bounded search found no root: the roots at its touch points
 * (samples of the free angle where the model's solution meets a branch zero, refined), and
 * those of the neighbouring configurations (one branch flipped) that hold the problem's own
 * (their flipped branch quantity within OM_BRANCH_BAND of zero), verified, into roots
 * (OM_MAX_ROOTS x dof); returns the count. *neighbour_reached: some neighbour had a root.
 * cache: om_loop_roots's. */
int om_band_roots(om_problem *pb, double *roots, bool *neighbour_reached, om_scan_cache *cache);
/* loop_search.c: for a 7-DOF S-R-S configuration without a root whose pose's wrist centre may
 * come within 1e-2 rad of psi's singular half-line, the roots met where psi crosses the
 * requested value along the real arm's self-motion loops through the pose's solutions in the
 * same signs at other arm angles, into roots from count on; returns the count. cache (NULL:
 * none) keeps whether the pose may come near the line for the pose's next configuration. */
int om_loop_roots(om_problem *pb, double *roots, int count, om_scan_cache *cache);
/* loop_pass.c: for q on the pose (within 1e-12) next to psi's half-line: psi's crossings of
 * the requested value where the self-motion loop through q passes by the line; the first root
 * into q (*pos, *ori its errors). Returns whether there was one. */
bool om_loop_pass(om_problem *pb, double *q, double *pos, double *ori);

/* search.c */
int om_all_roots(om_problem *pb, int n_scan, double *roots);
/* om_all_roots on the whole circle with the candidates taken from cache where it holds this
 * problem's, else searched and kept there (cache NULL: om_all_roots). */
int om_all_roots_cached(om_problem *pb, int n_scan, double *roots, om_scan_cache *cache);

#endif
