/* om_redundant's compiled core: DH kinematics, the model arms' closed forms, and the OM
 * system (9) with its solvers.
 *
 * A 1:1 port of the former numba kernels: same algorithms, same order of floating-point
 * operations, so that results agree with them to the last bit wherever libm agrees.
 * Built with -ffp-contract=off (no fused multiply-add), never -ffast-math.
 *
 * Conventions
 * - Small vectors and matrices travel by value: vec3, and mat3 as three rows.
 * - Arrays are C-contiguous float64 (int64 for branch signs, uint8 for flags), row-major.
 * - A DH table has n_rows rows of 6 doubles: a, d, theta, cos(alpha), sin(alpha), kind
 *   (kind 0 revolute, 1 prismatic, 2 fixed).
 * - Nothing here allocates on the hot path except the bounded searches' scratch arrays.
 */
#ifndef OM_KERNELS_H
#define OM_KERNELS_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define OM_MAX_DOF 16  /* joints of an arm the kernels take (the binding checks) */
#define OM_MAX_ROOTS 16 /* roots kept per configuration */
#define OM_SCAN_KEY (3 + 9 + 1 + 2 + OM_MAX_DOF + 1) /* om_scan_cache's key */
#define OM_GATE_KEY 18 /* om_scan_cache's gate key: 6 vectors */

/* ------------------------------------------------------------------------------------ */
/* om_math.h: tuple math, angle wrapping; common.c: the Euler decomposition of a revolute triple. */

#define OM_SINGULAR 1e-12
#define OM_REACH_SLACK 1e-12 /* relative slack under a square root before out of reach */

#include "om_math.h"

/* (phi_a, phi_b, phi_c) with M = Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(beta) Rz(phi_c),
 * sigma_a = sin(alpha_a) = +-1; see common.py's euler_zxzxz. */
vec3 om_euler_zxzxz(mat3 M, double sigma_a, double sin_b, double cos_b, double sign, double phi_a_singular);
/* (phi_b, phi_c, residual N22) for phi_a given; see euler_zxzxz_given_first. */
vec3 om_euler_zxzxz_given_first(mat3 M, double sin_a, double cos_a, double sigma_b, double phi_a);

/* The residual N22 of om_euler_zxzxz_given_first alone, for ca = cos(phi_a), sa = sin(phi_a):
 * row 2 of Rx(alpha_a)^T Rz(-phi_a) M, its z entry. */
static inline double om_euler_given_first_residual(mat3 M, double sin_a, double cos_a, double ca, double sa)
{
    double r1z = ca * M.r1.z - sa * M.r0.z;
    return cos_a * M.r2.z - sin_a * r1z;
}

/* ------------------------------------------------------------------------------------ */
/* kinematics.c: DH chains.                                                               */

/* Right-multiply the frame (R row-major 3x3, p) in place by a standard DH row with variable qi. */
void om_apply_row(double *R, double *p, const double *row, double qi);
/* The pose of the last DH frame in DH frame 0. */
void om_flange(const double *table, int n_rows, const double *q, double *R, double *p);
void om_flange_trig(const double *table, int n_rows, const double *q, double *R, double *p, double *trig);
/* The flange poses of two chains of the same joints at q (a near arm's exact chain and its
 * nominal arm's), a joint's cos and sin computed once where its rows' theta agree (bit for bit). */
void om_flange_pair(const double *first, int n_first, const double *second, int n_second, const double *q,
                    double *R1, double *p1, double *R2, double *p2);
/* The chain's rows applied to the frame (R, p) in place, up to joint n+1's row (every row for
 * n >= the joints); with frames not NULL, the frame before each joint's row (R row-major, then
 * p: 12 per joint; the joint turns about its z axis, R's column 2, through p); with trig not
 * NULL, cos and sin of each joint row's angle as applied (2 per joint). Returns the joints passed. */
int om_chain(const double *table, int n_rows, const double *q, int n, double *R, double *p, double *frames,
             double *trig);
/* om_chain from DH frame 0 (the identity) for joints 1..n: their frames into frames; R, p end as
 * the frame after every row before joint n+1's (the flange for n >= dof). */
void om_joint_frames(const double *table, int n_rows, const double *q, int n, double *frames, double *R, double *p);
/* A joint's axis in a frame of om_chain's (R's column 2); its origin is the frame's p, F + 9. */
static inline vec3 om_frame_axis(const double *F) { return v3(F[2], F[5], F[8]); }
/* base @ A(q) @ tool into out (4x4 row-major). */
void om_fk(const double *table, int n_rows, const double *base, const double *tool, const double *q, double *out);
/* Geometric Jacobian (6 x dof, row-major, rows [v; omega]) of the end-effector frame in the root frame;
 * the pose (R, p) of the chain's end in DH frame 0, after every row before joint dof+1's (the
 * flange where the table has dof joints: om_flange's), into flange_R, flange_p (NULL: not wanted). */
void om_jacobian(const double *table, int n_rows, const double *base, const double *tool, const double *q, int dof,
                 double *J, double *flange_R, double *flange_p);
/* om_jacobian from a walk already made: om_joint_frames' frames (dof of them) and its chain end (R, p). */
void om_jacobian_from_frames(const double *table, int n_rows, const double *base, const double *tool,
                             const double *frames, const double *R, const double *p, int dof, double *J);

/* A DH table: rows of OM_DH_COLUMNS float64, (a, d, theta, cos alpha, sin alpha, kind), kind a
 * row's joint code. Written here alone: Python builds its tables by them (_core.DH_*,
 * _core.JOINT_*; om_redundant/kinematics/chain.py). */
enum { OM_DH_A = 0, OM_DH_D = 1, OM_DH_THETA = 2, OM_DH_COS_ALPHA = 3, OM_DH_SIN_ALPHA = 4, OM_DH_KIND = 5,
       OM_DH_COLUMNS = 6 };
enum { OM_JOINT_REVOLUTE = 0, OM_JOINT_PRISMATIC = 1, OM_JOINT_FIXED = 2 };

/* ------------------------------------------------------------------------------------ */
/* six_dof.c, srs.c, families.c: the model arms' closed forms (the math: the Python modules */
/* om_redundant/ik/families/six_dof.py and srs.py). The family codes and the parameter      */
/* layouts are written here alone: Python reads them from om_redundant._core (module.c).    */

/* The family codes (_core.RRR_SPHERICAL_WRIST, RRP_SPHERICAL_WRIST, SRS). */
enum { OM_RRR_SPHERICAL_WRIST = 0, OM_RRP_SPHERICAL_WRIST = 1, OM_SRS = 2 };

/* A 6-DOF family's parameter vector (_core.SD_*; built by om/model.py's _position_family,
 * _six_dof_model and _wrist_offset). */
enum {
    SD_A1 = 0, SD_D1 = 1, SD_SIGMA1 = 2, SD_THETA1 = 3, SD_LATERAL = 4, SD_A2 = 5, SD_THETA2 = 6,
    SD_ELL3 = 7, SD_BETA = 8, SD_THETA3 = 9, /* RRR */
    SD_SIGMA2 = 7, SD_D3 = 8,                /* RRP */
    SD_SIGMA4 = 10, SD_SIGMA5 = 11, SD_THETA4 = 12, SD_THETA5 = 13, SD_THETA6 = 14,
    SD_WRIST_CENTRE = 15, /* 3 entries: the wrist centre in the flange frame */
    SD_E_ROT = 18,        /* 9, row-major: the rotation from the frame after Rz(phi6) to the flange */
    SD_WRIST_ROW = 27,    /* the index in the model's DH table of joint 4's row */
    /* a wrist with a4 != 0 (zero otherwise; om/model.py's _wrist_offset, wrist_offset.c): */
    SD_WRIST_OFFSET = 28, /* 3: the real arm's a4, d5, a5 */
    SD_AXIS4 = 31,        /* 9: joint 4's axis z3 = C0 + C1 cos q1 + C2 sin q1 in DH frame 0 (rows C0, C1, C2) */
    SD_AXIS6 = 40,        /* 3: joint 6's axis z5 in the flange frame */
    SD_N_PARAMS = 43
};

/* The S-R-S family's parameter vector (_core.SRS_*; built by om/model.py's _srs_model). */
enum {
    SRS_SIGMA1 = 0, SRS_SIGMA2 = 1, SRS_SIGMA5 = 2,
    SRS_SIN_BETA = 3,  /* sin(beta), the wrist's middle twist (joints 6 to 7); +-1 on most arms */
    SRS_THETA = 4,     /* 7 entries: theta_1..theta_7 (theta_6, theta_7 with a, b of the wrist twist) */
    SRS_SHOULDER = 11, /* 3: S in DH frame 0 */
    SRS_WRIST = 14,    /* 3: W in the flange frame */
    SRS_S3 = 17,       /* 3: S in DH frame 3 */
    SRS_U = 20,        /* 3: v(phi4) = Rz(phi4) u - s3 */
    SRS_K0 = 23, SRS_K = 24, SRS_PHI_STAR = 25, /* |W - S|^2 = k0 + K cos(phi4 - phi*) */
    SRS_R_PRE = 26,    /* 9 (row-major): DH frame 0 to the frame joint 1 turns */
    SRS_X3 = 35,       /* 9: Rx(alpha_3) */
    SRS_X4 = 44,       /* 9: Rx(alpha_4) */
    SRS_E_ROT = 53,    /* 9: from the frame after Rz(phi7) to the flange */
    SRS_UP = 62,       /* 3: the root frame's up axis, in DH frame 0 */
    SRS_REF = 65,      /* 3: the arm angle's reference direction r, in DH frame 0 */
    SRS_BEND = 68,     /* sigma: the bend direction's sign */
    SRS_COS_BETA = 69, /* cos(beta); 0 on most arms */
    SRS_COS_PHI_STAR = 70, SRS_SIN_PHI_STAR = 71, /* cos and sin of phi*: the elbow's without trig */
    SRS_N_PARAMS = 72
};

/* A model solve's target orientation, with what depends on it alone computed once
 * (om_target_at): every residual evaluation of one solve shares it. */
typedef struct {
    mat3 R;       /* the flange orientation in DH frame 0 */
    mat3 RE;      /* R E^T, E the family's constant wrist rotation (SD_E_ROT, SRS_E_ROT) */
    vec3 wrist;   /* R w - s: the wrist centre for hand position p is p + wrist (S-R-S: less the shoulder s) */
    double psi;   /* S-R-S: the arm angle, and its cos and sin */
    double cos_psi, sin_psi;
} om_target;

/* Returns the reach margin (negative beyond OM_REACH_SLACK: out of reach, q not written; with
 * nearest, written: the nearest pose's the model reaches, the reach's square roots at zero). */
double om_six_dof_model_ik(int family, const double *P, const double *table, const om_target *t, vec3 p,
                           const int64_t *signs, const double *q_prev, double *q, bool nearest);
void om_six_dof_branch_values(int family, const double *P, const double *q, double *out);
/* q6 given: smooth at the wrist singularity; *residual the wrist's consistency. Returns the margin. */
double om_six_dof_model_ik_q6(int family, const double *P, const double *table, const om_target *t, vec3 p,
                              const int64_t *signs, const double *q_prev, double q6, double *q, double *residual);
void om_six_dof_target(const double *P, om_target *t); /* fills RE and wrist from t->R */
/* wrist_offset.c: for a4 != 0 (P[SD_WRIST_OFFSET] != 0), the model's hand position
 * p_m = p_d + dp(w) on the circle w = q1 of the WRIST sign wrist (NaN at a singular wrist). */
vec3 om_wrist_offset_point(const double *P, const om_target *t, vec3 p, double wrist, double w);

/* With shoulder false, joints 1-3 are not written. Returns the reach margin 1 - x^2. */
double om_srs_model_ik(const double *P, const om_target *t, vec3 p, const int64_t *signs, const double *q_prev,
                       double *q, bool shoulder);
/* The reach margin of om_srs_model_ik alone (the same arithmetic) and, unless W = S, the elbow's x. */
double om_srs_reach(const double *P, const om_target *t, vec3 p, double *x);
/* q7 alone (q[6]; the rest of q untouched), for the circle residual. Returns the margin. */
double om_srs_model_q7(const double *P, const om_target *t, vec3 p, const int64_t *signs, const double *q_prev,
                       double *q);
/* om_srs_model_q7 in three parts, for a caller that shares the first two between problems:
 * what depends on the hand position p, the target's orientation and the ELBOW sign alone
 * (om_srs_elbow_at; the rest unset where the margin is below -OM_REACH_SLACK), what the
 * target's arm angle adds (om_srs_wrist_terms_of), and q7 for the WRIST sign (om_srs_q7_of:
 * q[6]; near the wrist's singularity from every joint, with q_prev). */
typedef struct {
    double margin;     /* the reach margin */
    vec3 w;            /* W - S */
    double L2, x;      /* |W - S|^2 and the elbow's x (x also out of reach; NaN where W = S) */
    vec3 w_hat, n, nw; /* w / |w|, the arm angle's reference n there and w_hat x n */
    mat3 B;            /* the frame-3 triad (v_hat, b3_hat, v_hat x b3_hat), rows */
    mat3 X4;           /* Rz(phi4) X4 */
} om_srs_elbow;
typedef struct {
    double radial, v, m20, m21; /* the wrist's |u|, v and M[2][0], M[2][1] (srs.c) */
} om_srs_wrist_terms;
double om_srs_elbow_at(const double *P, const om_target *t, vec3 p, double elbow, om_srs_elbow *e);
om_srs_wrist_terms om_srs_wrist_terms_of(const double *P, const om_target *t, const om_srs_elbow *e);
void om_srs_q7_of(const double *P, const om_target *t, const om_srs_elbow *e, const om_srs_wrist_terms *terms,
                  const int64_t *signs, const double *q_prev, double *q);
bool om_srs_model_q7_at_reach(const double *P, const om_target *t, vec3 p, const int64_t *signs,
                              const double *q_prev, double *q);
bool om_srs_model_ik_at_reach(const double *P, const om_target *t, vec3 p, const int64_t *signs,
                              const double *q_prev, double *q);
/* phi4 NaN: the elbow equation's root in the ELBOW branch. Returns (shoulder, wrist, elbow) residuals. */
vec3 om_srs_model_ik_lifted(const double *P, const om_target *t, vec3 p, const int64_t *signs, double q1, double q7,
                            double phi4, double *q);
void om_srs_target(const double *P, om_target *t); /* fills RE, wrist, cos_psi, sin_psi from t->R, t->psi */
/* The arm angle's reference direction n(w_hat) into *n, and w_hat x n into *nw. */
void om_srs_reference(const double *P, vec3 w_hat, vec3 *n, vec3 *nw);
double om_srs_arm_angle(const double *P, const double *q);
double om_srs_arm_angle_in(const double *P, const double *q, double elbow);
double om_srs_arm_angle_trig(const double *P, const double *trig, double elbow); /* trig: cos, sin of q_j + theta_j, j < 4 */
void om_srs_branch_values(const double *P, const double *q, double *out);
void om_srs_branch_values_trig(const double *P, const double *q, const double *trig, double *out);
double om_srs_half_line_angle(const double *P, const double *q); /* w_hat's angle from -up at q */
vec3 om_srs_half_line_across(const double *P, const double *q);  /* up x (W - S) of the model at q */
/* The three at q from one shoulder-wrist vector: om_srs_half_line_across's into *across,
 * om_srs_half_line_angle's into *angle; returns om_srs_arm_angle_in's psi (the same bits). */
double om_srs_half_line_psi(const double *P, const double *q, double elbow, vec3 *across, double *angle);
/* psi at q of the S-R-S model with parameters P and DH table; writes d psi / dq (7). */
double om_arm_angle_gradient(const double *P, const double *table, int n_rows, const double *q, double *grad);

/* Dispatch on the family (families.c). */
/* The target for flange orientation R and the redundancy values (S-R-S: the arm angle). */
om_target om_target_at(int family, const double *P, const mat3 *R, const double *redundancy);
double om_model_ik(int family, const double *P, const double *table, const om_target *t, vec3 p,
                   const int64_t *signs, const double *q_prev, double *q, bool all_joints);
/* om_model_ik of every joint where p is within reach; beyond it, the closed form of the nearest
 * pose the model reaches (S-R-S: the elbow held at the edge of reach; 6-DOF: the reach's square
 * roots at zero) into q. Returns the reach margin, NaN where nothing is written (W = S). */
double om_model_ik_nearest(int family, const double *P, const double *table, const om_target *t, vec3 p,
                           const int64_t *signs, const double *q_prev, double *q);
void om_branch_values(int family, const double *P, const double *q, double *out);
void om_redundancy_values(int family, const double *P, const double *q, double *out);

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
    /* An arm NEAR a family (near.c; om/nominal.py): the closed form (params, model_table, D) is
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
bool om_margin_may_reach(const double *ms, int i, int count, bool cyclic);
/* The model's hand position at the torus point (w1, w7) (not counted as an evaluation). */
vec3 om_torus_point(const om_problem *pb, double w1, double w7);
vec3 om_lifted_residual(om_problem *pb, vec3 x, double *q);
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

/* circle.c: candidates into cands (capacity cap); returns the count. On an S-R-S arm whose
 * dp turns with q7 the scan's samples take the model's parts from pb->memo where it holds
 * them, and keep them there (the same bits as computed). */
int om_circle_candidates(om_problem *pb, double lo, double hi, int n_pts, bool full_circle, double *q,
                         double *cands, int cap);
/* A scan memo for the problems of solver s, none held yet (NULL: an arm whose scans keep none,
 * or out of memory); freed by om_scan_memo_free (NULL: nothing). */
om_scan_memo *om_scan_memo_new(const om_solver_data *s);
void om_scan_memo_free(om_scan_memo *memo);
/* wrist_offset.c: candidates in the bands around the singular wrist of an arm with a4 != 0. */
#define OM_WRIST_BAND_CANDIDATES 256 /* room for them */
int om_wrist_offset_candidates(om_problem *pb, double lo, double hi, bool full_circle, double *q, double *cands,
                               int cap);

/* torus.c */
double om_newton(om_problem *pb, vec3 x, double *q, const double *known, int n_known, vec3 *x_end);
double om_lifted_solve(om_problem *pb, const double *start, double *q);
/* The candidates a torus search hands to verification, in order: q (dof each) of the first cap
 * of them, count in all (beyond cap: not all kept). */
typedef struct {
    double *q;
    int cap, count;
} om_candidate_log;
int om_torus_roots(om_problem *pb, int n, double *roots, const double *centre, double radius, om_candidate_log *log);
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
/* x = W - S of the model on the torus less its parts that turn with w1 and w7:
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
} om_scan_cache;
#define OM_SCAN_CAPACITY(n_scan) (8 * (n_scan) + 8 + OM_WRIST_BAND_CANDIDATES)

/* boundary.c */
/* A candidate q that failed verification, refined on the real arm where a branch quantity is
 * within 1e-2 of zero, or (S-R-S) w_hat within 1e-2 rad of psi's singular half-line, or (an
 * arm near a family) where it is within NEAR_POLISH_FROM of the pose (om_near_polish; else
 * left as it is); returns whether it now verifies. */
bool om_polish_candidate(om_problem *pb, double *q, double *pos, double *ori);
/* The refinement on the real arm toward pb's goal (with psi, S-R-S: in the requested ELBOW
 * branch), giving up a crawl far from a root (om_polish). */
om_polish_task om_problem_polish_task(const om_problem *pb);
/* self_motion.c: the null vector of the real 6 x 7 Jacobian at q (the kernels' coordinates) by
 * cofactors (not normalised) */
void om_self_motion_null(const om_solver_data *s, const double *q, double *n);
/* det A (n x n row-major, destroyed) into *det (NULL: not wanted) by elimination with partial
 * pivoting and, b not NULL, x of A x = b into b; false where a pivot is zero (*det = 0). */
bool om_eliminate(double *A, double *b, int n, double *det);
/* om_add_root of q, polished first where it fails verification near the boundary. */
int om_add_candidate(om_problem *pb, double *q, double *roots, int count);
/* pb's pose in another configuration (signs, redundancy: kept by the caller), its target's
 * constants for that redundancy, its evaluation counter at zero. */
om_problem om_problem_at(const om_problem *pb, const int64_t *signs, const double *redundancy);

/* For a configuration whose bounded search found no root: the roots at its touch points
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
/* For q on the pose (within 1e-12) next to psi's half-line: psi's crossings of the requested
 * value where the self-motion loop through q passes by the line; the first root into q (*pos,
 * *ori its errors). Returns whether there was one. */
bool om_loop_pass(om_problem *pb, double *q, double *pos, double *ori);

/* search.c */
int om_all_roots(om_problem *pb, int n_scan, double *roots, const double *centre, double radius);
/* om_all_roots on the whole circle with the candidates taken from cache where it holds this
 * problem's, else searched and kept there (cache NULL: om_all_roots). */
int om_all_roots_cached(om_problem *pb, int n_scan, double *roots, om_scan_cache *cache);
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
 * for the root. */
bool om_solve_near(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                   const double *hint, double *q_out, om_root_test as_is, void *context, om_result *result);
/* Every root (OM_MAX_ROOTS x dof) with per root (position error, orientation error, within limits)
 * in info (OM_MAX_ROOTS x 3). Returns the count; *evaluations the residual evaluations. */
int om_solve_all(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                 double *roots, double *info, int64_t *evaluations, bool band, om_scan_cache *cache);

#endif
