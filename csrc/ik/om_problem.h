/* The OM system (9): its codes and tolerances, a solver's fixed data, and one problem. Included by om_kernels.h, after what it declares. */
#ifndef OM_PROBLEM_H
#define OM_PROBLEM_H

/* ------------------------------------------------------------------------------------ */
/* The OM system (9) and its solvers.                                                     */

enum { OM_FIXED = 0, OM_CIRCLE = 1, OM_TORUS = 2 }; /* om_solver_data.mode */
enum { OM_OK = 0, OM_UNREACHABLE = 1, OM_NO_SOLUTION_IN_CONFIGURATION = 2 };

#define OM_ROOT_TOL 1e-13   /* a residual (rad) accepted as a root before verification */
#define OM_SAME_ROOT 1e-9   /* joint-space distance under which two roots are one */
#define OM_ONE_ROOT 1e-6    /* ... and under which the more accurate of two is kept */
#define OM_BRANCH_BAND 1e-7 /* |branch quantity| within which q holds both neighbouring configurations */
#define OM_TOUCH 1e-3      /* |g| (rad) of a touch of zero or an edge of reach tried as a candidate */
#define OM_PAIR_SEARCH 1.0  /* |g| (rad) below which a local minimum is searched for a root pair */

/* The solver's fixed data (the binding owns the arrays). */
typedef struct {
    int family, mode, dof, n_signs, n_redundancy;
    int dp_joint; /* J: the joint delta depends on (CIRCLE); 0 on the TORUS and for FIXED */
    const double *params;
    const double *model_table; /* n_model_rows x 6 */
    int n_model_rows;
    const double *real_table; /* n_real_rows x 6 */
    int n_real_rows;
    double D[6][3];         /* rows 0-2: delta(w) = D0 + D1 cos w + D2 sin w; 3-5: a(q1) */
    double T_base_root[16]; /* inverse of the pose of DH frame 0 in the root frame */
    double T_tool_flange[16]; /* inverse of the end-effector frame in the flange frame */
    const uint8_t *revolute;
    const double *lower, *upper;
    int scan_points;
    double tol_pos, tol_ori;
    bool trig_shared; /* om_trig_shared: verify reuses the real FK's cos and sin in the configuration check */
    /* An arm NEAR a family (near.c; ik/nominal.py): the closed form (params, model_table, D) is
     * its nominal arm's model's, real_table its own exact chain in the nominal arm's joint
     * coordinates, lower and upper mapped to them, and nominal_table the nominal arm's chain.
     * NULL: the arm is in its family exactly (real_table is its chain). */
    const double *nominal_table; /* n_nominal_rows x 6 */
    int n_nominal_rows;
    double near_deviation; /* m: how far the nominal arm's flange frame is from the real one's, a bound */
    /* The correction on the left, in DH frame 0: T_nom(q) = L(q) T_real(q) (near.c); false: on
     * the right, in the flange frame, T_nom(q) = T_real(q) C(q). */
    bool near_left;
    bool near_mixed; /* the correction's translation mixed from its last two steps (near.c: _mixed) */
    /* +-1 per joint: the kernels' joint coordinates are flip * q, q the arm's own (-1 where a
     * near arm's axis is reversed, all +1 otherwise); flipped: some is -1. The entry points
     * (solve.c's om_solve_*, near.c's om_solver_*, om_self_motion_tangent) take and give the
     * arm's own. */
    double flip[OM_MAX_DOF];
    bool flipped;
} om_solver_data;

/* What the circle scans of a batch's problems share (circle.c; om_scan_cache owns it). */
typedef struct om_scan_memo om_scan_memo;
/* What the whole-torus searches of a batch's problems share (torus.c; om_scan_cache owns it). */
typedef struct om_torus_memo om_torus_memo;

/* One target. */
typedef struct {
    const om_solver_data *s;
    om_target t; /* flange orientation in DH frame 0, with its per-target constants (those of
                  * redundancy too: other redundancy values need om_target_at again) */
    vec3 p;      /* flange position in DH frame 0 */
    const int64_t *signs;
    const double *redundancy;
    const double *q_prev; /* joints kept at singularities */
    int64_t counter;      /* residual evaluations */
    /* whether om_polish_candidate also refines from starts around the model's split of a
     * singular joint pair where that split is arbitrary (false: the hinted local part alone,
     * om_solve_near, whose model takes the split from its hint) */
    bool split_starts;
    /* whether the torus search takes the certificate's roots where it proves them
     * (contraction.c; false: the grid search, always) */
    bool certify;
    /* the model's parts at the circle scan's samples, which the problem's scans (its own, its
     * neighbours') take from the scans before them and keep for those after (NULL: none) */
    om_scan_memo *memo;
    /* the lifted residual's terms at the whole torus' grid, which the problem's searches take from
     * the searches of its pose before them and keep for those after (NULL: none) */
    om_torus_memo *torus_memo;
    /* the self-motion of the problem's pose traced by a batch's searches and kept for the
     * follows after it (om_torus_memo_take), which its windows start from instead of their grid
     * (torus.c; read only; NULL: none) */
    const om_torus_memo *traces;
    /* The real arm's target, the flange pose in DH frame 0 (with the closed form's constants
     * for its orientation), against which every answer is verified (om_verify) and polished.
     * t and p above are the model's side of system (9): the goal itself, but for an arm near a
     * family within one of its model IKs, which moves them to goal C(q) (near.c). */
    om_target goal;
    vec3 goal_p;
    /* An arm near a family scanned on its nominal arm's system: the model IKs skip the
     * correction (g-tilde of near.c); false for every other evaluation. */
    bool nominal;
    /* A 6-DOF arm near a family scanned on its wrist residual (om_wrist_residual: om_g is it,
     * circle.c's windows at the singular wrist); false for every other evaluation. */
    bool wrist;
} om_problem;

#endif
