/* DH chains (om_redundant/kinematics/chain.py is the typed front): FK and the Jacobian as
 * explicit 4x4 products and rigid transforms, sums left to right.
 * A table row is (a, d, theta, cos(alpha), sin(alpha), kind): OM_DH_*, kind an OM_JOINT_* code. */
#include <string.h>

#include "om_kernels.h"

/* Right-multiply the frame (R, p) in place by the standard DH row Rz(theta) Tz(d) Tx(a) Rx(alpha),
 * the variable qi added to theta (revolute, kind 0) or d (prismatic, kind 1), with ct and st the
 * cos and sin of theta (apply_row computes them, and gives them into *ct_out, *st_out). */
static inline void apply_row_cs(double *R, double *p, const double *row, double qi, double ct, double st)
{
    double d = row[OM_DH_KIND] == OM_JOINT_PRISMATIC ? row[OM_DH_D] + qi : row[OM_DH_D];
    double ca = row[OM_DH_COS_ALPHA], sa = row[OM_DH_SIN_ALPHA], a = row[OM_DH_A];
    double Rl[9] = {R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8]}; /* in registers: R, p do not alias */
    for (int i = 0; i < 3; i++) {
        double r0 = Rl[3 * i], r1 = Rl[3 * i + 1], r2 = Rl[3 * i + 2];
        p[i] += r0 * a * ct + r1 * a * st + r2 * d;
        R[3 * i] = r0 * ct + r1 * st;
        R[3 * i + 1] = -r0 * st * ca + r1 * ct * ca + r2 * sa;
        R[3 * i + 2] = r0 * st * sa - r1 * ct * sa + r2 * ca;
    }
}

static inline void apply_row(double *R, double *p, const double *row, double qi, double *ct_out, double *st_out)
{
    double theta = row[OM_DH_KIND] == OM_JOINT_REVOLUTE ? row[OM_DH_THETA] + qi : row[OM_DH_THETA];
    double ct = cos(theta), st = sin(theta);
    apply_row_cs(R, p, row, qi, ct, st);
    *ct_out = ct;
    *st_out = st;
}

void om_apply_row(double *R, double *p, const double *row, double qi)
{
    double ct, st;
    apply_row(R, p, row, qi, &ct, &st);
}

static void set_identity(double *R, double *p)
{
    for (int i = 0; i < 9; i++)
        R[i] = 0.0;
    R[0] = R[4] = R[8] = 1.0;
    p[0] = p[1] = p[2] = 0.0;
}

/* The rows from (R, p) on, each joint's frame before its row kept (om_kernels.h). */
int om_chain(const double *table, int n_rows, const double *q, int n, double *R, double *p, double *frames,
             double *trig)
{
    int j = 0;
    double cs[2];
    for (int k = 0; k < n_rows; k++) {
        const double *row = table + 6 * k;
        if (row[OM_DH_KIND] == OM_JOINT_FIXED) {
            apply_row(R, p, row, 0.0, &cs[0], &cs[1]);
            continue;
        }
        if (j == n)
            break;
        if (frames) {
            memcpy(frames + 12 * j, R, 9 * sizeof(double));
            memcpy(frames + 12 * j + 9, p, 3 * sizeof(double));
        }
        double *out = trig ? trig + 2 * j : cs;
        apply_row(R, p, row, q[j], &out[0], &out[1]);
        j++;
    }
    return j;
}

/* The frames in DH frame 0 of joints 1..n (joint_axes_kernel): a standard row's joint acts
 * about the z-axis of the frame it starts from. (R, p) end as the frame before joint n+1's row. */
void om_joint_frames(const double *table, int n_rows, const double *q, int n, double *frames, double *R, double *p)
{
    set_identity(R, p);
    om_chain(table, n_rows, q, n, R, p, frames, NULL);
}

/* The pose (R, p) of the last DH frame in DH frame 0: every row applied (no row has more
 * than n_rows joints before it). */
void om_flange(const double *table, int n_rows, const double *q, double *R, double *p)
{
    set_identity(R, p);
    om_chain(table, n_rows, q, n_rows, R, p, NULL, NULL);
}

/* om_flange, also giving cos and sin of each joint row's angle theta + q_j as the product used
 * them (trig: cos, sin per joint; a prismatic joint's are of its fixed theta). */
void om_flange_trig(const double *table, int n_rows, const double *q, double *R, double *p, double *trig)
{
    set_identity(R, p);
    om_chain(table, n_rows, q, n_rows, R, p, NULL, trig);
}

void om_flange_pair(const double *first, int n_first, const double *second, int n_second, const double *q,
                    double *R1, double *p1, double *R2, double *p2)
{
    double trig[2 * OM_MAX_DOF], theta[OM_MAX_DOF], cs[2];
    om_flange_trig(first, n_first, q, R1, p1, trig);
    for (int k = 0, j = 0; k < n_first; k++)
        if (first[OM_DH_COLUMNS * k + OM_DH_KIND] != OM_JOINT_FIXED)
            theta[j++] = first[6 * k + 2];
    set_identity(R2, p2);
    for (int k = 0, j = 0; k < n_second; k++) {
        const double *row = second + 6 * k;
        if (row[OM_DH_KIND] == OM_JOINT_FIXED) {
            apply_row(R2, p2, row, 0.0, &cs[0], &cs[1]);
        } else {
            if (memcmp(&row[OM_DH_THETA], &theta[j], sizeof(double)) == 0) /* the same angle, bit for bit */
                apply_row_cs(R2, p2, row, q[j], trig[2 * j], trig[2 * j + 1]);
            else
                apply_row(R2, p2, row, q[j], &cs[0], &cs[1]);
            j++;
        }
    }
}

/* out = A @ B for 4x4 row-major matrices (_matmul4). */
static void matmul4(const double *A, const double *B, double *out)
{
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            out[4 * i + j] = A[4 * i] * B[j] + A[4 * i + 1] * B[4 + j] + A[4 * i + 2] * B[8 + j] +
                             A[4 * i + 3] * B[12 + j];
}

/* base @ A(q) @ tool (fk_kernel): two explicit 4x4 products. */
void om_fk(const double *table, int n_rows, const double *base, const double *tool, const double *q, double *out)
{
    double R[9], p[3], T[16] = {0.0}, BT[16];
    om_flange(table, n_rows, q, R, p);
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            T[4 * i + j] = R[3 * i + j];
        T[4 * i + 3] = p[i];
    }
    T[15] = 1.0;
    matmul4(base, T, BT);
    matmul4(BT, tool, out);
}

/* T applied to x in homogeneous coordinates (x, w): a point (w = 1) or a direction (w = 0) (_rigid). */
static void rigid(const double *T, const double *x, double w, double *out)
{
    for (int i = 0; i < 3; i++)
        out[i] = T[4 * i] * x[0] + T[4 * i + 1] * x[1] + T[4 * i + 2] * x[2] + T[4 * i + 3] * w;
}

/* Geometric Jacobian [v; omega] (6 x dof, row-major) of the end-effector frame in the root frame
 * from om_joint_frames' frames and chain end (R, p) (jacobian_kernel): z_j x (p_ee - o_j) and z_j
 * for a revolute joint, z_j and 0 for a prismatic one. */
void om_jacobian_from_frames(const double *table, int n_rows, const double *base, const double *tool,
                             const double *frames, const double *R, const double *p, int dof, double *J)
{
    double kinds[OM_MAX_DOF];
    int j = 0;
    for (int k = 0; k < n_rows; k++) {
        if (table[OM_DH_COLUMNS * k + OM_DH_KIND] != OM_JOINT_FIXED && j < dof) {
            kinds[j] = table[OM_DH_COLUMNS * k + OM_DH_KIND];
            j++;
        }
    }
    /* p_ee = Rb (p + R t) + b for the base (Rb, b) and the tool offset t. */
    double flange_ee[3], p_ee[3];
    for (int i = 0; i < 3; i++)
        flange_ee[i] = p[i] + R[3 * i] * tool[3] + R[3 * i + 1] * tool[7] + R[3 * i + 2] * tool[11];
    rigid(base, flange_ee, 1.0, p_ee);
    for (int i = 0; i < 6 * dof; i++)
        J[i] = 0.0;
    for (j = 0; j < dof; j++) {
        const double *F = frames + 12 * j, axis[3] = {F[2], F[5], F[8]};
        double z[3], o[3], r[3];
        rigid(base, axis, 0.0, z);
        if (kinds[j] == OM_JOINT_PRISMATIC) {
            for (int i = 0; i < 3; i++)
                J[i * dof + j] = z[i];
        } else {
            rigid(base, F + 9, 1.0, o);
            for (int i = 0; i < 3; i++)
                r[i] = p_ee[i] - o[i];
            J[0 * dof + j] = z[1] * r[2] - z[2] * r[1];
            J[1 * dof + j] = z[2] * r[0] - z[0] * r[2];
            J[2 * dof + j] = z[0] * r[1] - z[1] * r[0];
            for (int i = 0; i < 3; i++)
                J[(3 + i) * dof + j] = z[i];
        }
    }
}

/* The geometric Jacobian at q (om_jacobian_from_frames of one walk of the chain). The chain's
 * end (R, p) into flange_R, flange_p (NULL: not wanted). */
void om_jacobian(const double *table, int n_rows, const double *base, const double *tool, const double *q, int dof,
                 double *J, double *flange_R, double *flange_p)
{
    double frames[OM_MAX_DOF * 12], R[9], p[3];
    om_joint_frames(table, n_rows, q, dof, frames, R, p);
    om_jacobian_from_frames(table, n_rows, base, tool, frames, R, p, dof, J);
    if (flange_R)
        memcpy(flange_R, R, sizeof R);
    if (flange_p)
        memcpy(flange_p, p, sizeof p);
}
