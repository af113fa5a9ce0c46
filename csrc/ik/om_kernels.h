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
#define OM_SCAN_KEY (3 + 9 + 1 + 3 + OM_MAX_DOF + 1) /* om_scan_cache's key */
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

/* The closed forms, system (9), its searches and its solves, each in its header. */
#include "om_families.h"
#include "om_problem.h"
#include "om_search.h"
#include "om_solve.h"

#endif
