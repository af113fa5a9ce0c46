/* The model arms' closed forms: the family codes, their parameter layouts and entry points. Included by om_kernels.h, after what it declares. */
#ifndef OM_FAMILIES_H
#define OM_FAMILIES_H

/* ------------------------------------------------------------------------------------ */
/* six_dof.c, srs.c, families.c: the model arms' closed forms (the math: the Python modules */
/* om_redundant/ik/families/six_dof.py and srs.py). The family codes and the parameter      */
/* layouts are written here alone: Python reads them from om_redundant._core (module.c).    */

/* The family codes (_core.RRR_SPHERICAL_WRIST, RRP_SPHERICAL_WRIST, SRS). */
enum { OM_RRR_SPHERICAL_WRIST = 0, OM_RRP_SPHERICAL_WRIST = 1, OM_SRS = 2 };

/* A 6-DOF family's parameter vector (_core.SD_*; built by ik/six_dof_model.py's position_family,
 * _six_dof_model and _wrist_offset). */
enum {
    SD_A1 = 0, SD_D1 = 1, SD_SIGMA1 = 2, SD_THETA1 = 3, SD_LATERAL = 4, SD_A2 = 5, SD_THETA2 = 6,
    SD_ELL3 = 7, SD_BETA = 8, SD_THETA3 = 9, /* RRR */
    SD_SIGMA2 = 7, SD_D3 = 8,                /* RRP */
    SD_SIGMA4 = 10, SD_SIGMA5 = 11, SD_THETA4 = 12, SD_THETA5 = 13, SD_THETA6 = 14,
    SD_WRIST_CENTRE = 15, /* 3 entries: the wrist centre in the flange frame */
    SD_E_ROT = 18,        /* 9, row-major: the rotation from the frame after Rz(phi6) to the flange */
    SD_WRIST_ROW = 27,    /* the index in the model's DH table of joint 4's row */
    /* a wrist with a4 != 0 (zero otherwise; ik/six_dof_model.py's wrist_offset, wrist_offset.c): */
    SD_WRIST_OFFSET = 28, /* 3: the real arm's a4, d5, a5 */
    SD_AXIS4 = 31,        /* 9: joint 4's axis z3 = C0 + C1 cos q1 + C2 sin q1 in DH frame 0 (rows C0, C1, C2) */
    SD_AXIS6 = 40,        /* 3: joint 6's axis z5 in the flange frame */
    /* a PUMA-like wrist with a4 != 0, joint 4 across joint 2 (zero otherwise; ik/six_dof_model.py's
     * wrist_torus): dp seen from the flange, delta(q5, q6) = sum_ij C_ij t_i(q5) t_j(q6), t = (1,
     * cos, sin); C_ij at 3 (3 i + j) */
    SD_WRIST_TORUS = 43,  /* 27 */
    SD_N_PARAMS = 70
};

/* The S-R-S family's parameter vector (_core.SRS_*; built by ik/srs_model.py's srs_model). */
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
/* A PUMA-like wrist's torus (q5, q6): the lifted model IK with q5, q6 and the elbow angle gamma
 * given (gamma NaN: the ELBOW branch's); returns the (wrist, joint 5, elbow) residuals. */
vec3 om_six_dof_model_ik_lifted(const double *P, const double *table, const om_target *t, vec3 p,
                                const int64_t *signs, const double *q_prev, double q5, double q6, double gamma,
                                double *q);
/* The same about joint 1's axis: x = (q5, q6, q1, gamma) given (gamma NaN: the ELBOW branch's);
 * writes q and the (wrist, joint 5, shoulder, elbow) residuals into F (4). */
void om_six_dof_model_ik_about_axis(const double *P, const double *table, const om_target *t, vec3 p,
                                    const int64_t *signs, const double *q_prev, const double *x, double *q, double *F);
/* dp seen from the flange on that torus, delta(w5, w6) = sum_ij C_ij t_i(w5) t_j(w6)
 * (SD_WRIST_TORUS), and (d5 not NULL) its derivatives in w5 and w6 into *d5, *d6. */
vec3 om_six_dof_wrist_delta(const double *P, double w5, double w6, vec3 *d5, vec3 *d6);
/* The model's hand position p_d + R delta(w5, w6) on that torus. */
vec3 om_six_dof_torus_point(const double *P, const mat3 *R, vec3 p, double w5, double w6);
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
/* om_srs_model_ik_lifted's residuals with phi4 the elbow's root, at every arm angle at once: with
 * q1, q7 and the hand position given, the elbow's root and the frames of W - S do not depend on
 * psi, and psi enters R03 = A^T B only through A's rows m = cos psi n + sin psi (w_hat x n) and
 * w_hat x m, linearly; the shoulder's and wrist's residuals are linear in R03 (an entry of a
 * fixed rotation of it), so each is [0] + [1] cos psi + [2] sin psi (om_srs_lifted_at). */
typedef struct {
    double shoulder[3], wrist[3]; /* the residuals' terms in 1, cos psi, sin psi */
    double elbow;                 /* the elbow's residual, x - cos(phi4 - phi*) */
    double phi4;                  /* the elbow's root */
} om_srs_lifted_terms;
/* The terms at (q1, q7) for the hand position p, target t (its psi not read), ELBOW sign elbow and
 * the elbow angle phi4 (NaN: the elbow's root in the ELBOW branch, its residual then 0) into *out;
 * false where W = S (om_srs_model_ik_lifted's NaN). */
bool om_srs_lifted_terms_at(const double *P, const om_target *t, vec3 p, double elbow, double q1, double q7,
                            double phi4, om_srs_lifted_terms *out);
/* The (shoulder, wrist, elbow) residuals of the terms k at the arm angle whose cos and sin are c, s. */
static inline vec3 om_srs_lifted_at(const om_srs_lifted_terms *k, double c, double s)
{
    return v3(k->shoulder[0] + k->shoulder[1] * c + k->shoulder[2] * s,
              k->wrist[0] + k->wrist[1] * c + k->wrist[2] * s, k->elbow);
}
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

#endif
