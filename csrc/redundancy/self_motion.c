/* The self-motion of a 7-DOF arm, shared by the tracking step (tracking.c) and the path
 * following of the global choose (follow.c); tests/reference/self_motion.py is the numpy
 * reference it is tested against.
 *
 * The hand stays fixed along the self-motion, J(q) dq = 0, so dq is along the null vector n
 * of the 6 x 7 Jacobian, here by cofactors, n_i = (-1)^i det J_{-i} (J without column i;
 * smooth in q, no factorisation to pick a sign). The arm angle moves by
 * dpsi = Dpsi(q) . n, so dq/dpsi = n / (Dpsi(q) . n). */
#include "om_paths.h"

/* Gaussian elimination with partial pivoting of the n x n matrix A (row-major, destroyed),
 * carrying b along (NULL: none) and then solving A x = b into b by back substitution; det A
 * into *det (NULL: not wanted). False where a pivot is zero: *det = 0, b unsolved. Columns
 * already eliminated are not read again, so the row swap skips those left of the pivot and
 * the update skips the pivot's own (the entries it would zero): the same determinant and x
 * to the last bit, about a fifth fewer updates. */
bool om_eliminate(double *A, double *b, int n, double *det) {
    double d = 1.0;
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > fabs(A[p * n + k])) p = i;
        if (A[p * n + k] == 0.0) {
            if (det) *det = 0.0;
            return false;
        }
        if (p != k) {
            for (int j = k; j < n; j++) {
                double t = A[k * n + j];
                A[k * n + j] = A[p * n + j];
                A[p * n + j] = t;
            }
            if (b) {
                double t = b[k];
                b[k] = b[p], b[p] = t;
            }
            d = -d;
        }
        d *= A[k * n + k];
        for (int i = k + 1; i < n; i++) {
            double f = A[i * n + k] / A[k * n + k];
            for (int j = k + 1; j < n; j++) A[i * n + j] -= f * A[k * n + j];
            if (b) b[i] -= f * b[k];
        }
    }
    if (det) *det = d;
    for (int k = n - 1; b && k >= 0; k--) {
        for (int j = k + 1; j < n; j++) b[k] -= A[k * n + j] * b[j];
        b[k] /= A[k * n + k];
    }
    return true;
}

void om_null_vector(const double *J, int m, double *n) {
    double M[36];
    for (int c = 0; c <= m; c++) {
        for (int i = 0; i < m; i++)
            for (int j = 0, k = 0; j <= m; j++)
                if (j != c) M[i * m + k++] = J[i * (m + 1) + j];
        double d;
        om_eliminate(M, NULL, m, &d);
        n[c] = (c % 2 ? -1.0 : 1.0) * d;
    }
}

void om_self_motion_null(const om_solver_data *s, const double *q, double *n) {
    static const double eye[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    double J[6 * 7];
    om_jacobian(s->real_table, s->n_real_rows, eye, eye, q, 7, J, NULL, NULL);
    om_null_vector(J, 6, n);
}

bool om_self_motion_tangent(const om_solver_data *s, const double *q, double *t, double tol) {
    double grad[7], n[7], at[7];
    om_flip(s, q, at); /* (the kernels' coordinates; the tangent back in the arm's own below) */
    om_self_motion_null(s, at, n);
    om_arm_angle_gradient(s->params, s->model_table, s->n_model_rows, at, grad);
    double dot = 0.0, gn = 0.0, nn = 0.0;
    for (int i = 0; i < 7; i++) {
        dot += grad[i] * n[i];
        gn += grad[i] * grad[i];
        nn += n[i] * n[i];
    }
    if (!(fabs(dot) > tol * sqrt(gn * nn)) || !isfinite(dot)) return false;
    for (int i = 0; i < 7; i++) {
        t[i] = s->flip[i] * (n[i] / dot);
        if (!isfinite(t[i])) return false;
    }
    return true;
}

/* The max-norm joint step |q1 - q0|_inf into *moved and the first-order prediction's error
 * |q1 - q0 - t d|_inf into *error (t NULL: 0), cyclic joints modulo 2 pi (om_continues' terms). */
static void _continuation(int dof, const double *q0, const double *q1, const double *t, double d,
                          const uint8_t *cyclic, double *moved, double *error) {
    *moved = 0.0, *error = 0.0;
    for (int i = 0; i < dof; i++) {
        double m = q1[i] - q0[i];
        if (cyclic && cyclic[i]) m = om_wrap(m);
        *moved = fmax(*moved, fabs(m));
        *error = fmax(*error, t ? fabs(m - t[i] * d) : 0.0);
    }
}

bool om_continues(int dof, const double *q0, const double *q1, const double *t, double d, const uint8_t *cyclic) {
    double moved, error;
    _continuation(dof, q0, q1, t, d, cyclic, &moved, &error);
    return moved <= OM_PATH_JUMP && error <= 0.5 * moved + OM_PATH_SAME;
}

double om_largest_joint_step(int dof, const double *q0, const double *q1, const uint8_t *cyclic) {
    double largest = 0.0;
    for (int i = 0; i < dof; i++) {
        double m = q1[i] - q0[i];
        if (cyclic && cyclic[i]) m = om_wrap(m);
        m = fabs(m);
        if (isnan(m)) return m; /* (numpy's maximum: a NaN step is NaN) */
        if (m > largest) largest = m;
    }
    return largest;
}

bool om_beyond_doubt(int dof, const double *q0, const double *q1, const double *t, double d, const uint8_t *cyclic) {
    double moved, error;
    _continuation(dof, q0, q1, t, d, cyclic, &moved, &error);
    return moved <= OM_PATH_JUMP && error <= 0.25 * moved;
}
