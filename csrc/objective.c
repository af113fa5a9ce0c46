/* The redundancy optimiser's objective at joint vectors (om_redundant/redundancy/objective.py's
 * Objective.evaluate and evaluations, which call it): the normalised joint-limit margin
 * M = min_i min((q_i - l_i)/h_i, (u_i - q_i)/h_i), the clearance D = min_k d_k (the pairs'
 * distances, computed by MuJoCo and clearance.c), the singularity distance
 * S = min_k |sin(q_{j_k} + c_k)|, and
 *   f = w_m M + w_c min(1, D/d_cap) + w_s min(1, S/s_cap),  slack = min(M, (D - d_min)/d_cap),
 * each sum and quotient in objective.py's order (its numpy reference rounds the same). */
#include "binding.h"

enum { W_MARGIN, W_CLEARANCE, W_SINGULARITY, D_CAP, D_MIN, S_CAP, N_NUMBERS };
enum { E_VALUE, E_MARGIN, E_CLEARANCE, E_SLACK, E_SINGULARITY, E_N };

/* One row: q (dof), d (P distances; P = 0 without obstacles) into e (E_N). */
static void evaluate(const double *q, const double *d, Py_ssize_t P, const int64_t *limited, const double *lower,
                     const double *upper, const double *half, Py_ssize_t L, const int64_t *joints,
                     const double *offsets, Py_ssize_t K, const double *w, double *e) {
    double value = 0.0, slack = INFINITY, margin = INFINITY, clearance = INFINITY, singular = INFINITY;
    if (L > 0) {
        for (Py_ssize_t i = 0; i < L; i++) {
            double x = q[limited[i]], a = (x - lower[i]) / half[i], b = (upper[i] - x) / half[i];
            margin = fmin(margin, fmin(a, b));
        }
        value += w[W_MARGIN] * margin;
        slack = fmin(slack, margin - 0.0);
    }
    if (P > 0) {
        double least = d[0];
        for (Py_ssize_t k = 1; k < P; k++) least = fmin(least, d[k]);
        double scaled = least / w[D_CAP];
        value += w[W_CLEARANCE] * fmin(1.0, scaled);
        slack = fmin(slack, scaled - w[D_MIN] / w[D_CAP]);
        clearance = scaled * w[D_CAP];
    }
    if (K > 0) {
        double least = INFINITY;
        for (Py_ssize_t k = 0; k < K; k++) least = fmin(least, fabs(sin(q[joints[k]] + offsets[k])));
        double scaled = least / w[S_CAP];
        value += w[W_SINGULARITY] * fmin(1.0, scaled);
        singular = scaled * w[S_CAP];
    }
    e[E_VALUE] = value, e[E_MARGIN] = margin, e[E_CLEARANCE] = clearance, e[E_SLACK] = slack;
    e[E_SINGULARITY] = singular;
}

/* evaluate(dof, q, distances, limited, lower, upper, half, joints, offsets, numbers, out) -> None:
 * out (M x 5: value, margin, clearance, slack, singularity) at the M rows of q (M x dof) with
 * the pairs' distances (M x P; P = 0 without obstacles); numbers = (w_m, w_c, w_s, d_cap,
 * d_min, s_cap). No limited joint (L = 0) or no singularity (K = 0): no such term. */
static PyObject *om_evaluate(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 11, "evaluate") < 0) return NULL;
    Py_ssize_t dof;
    if (get_dof(args[0], &dof, "evaluate") < 0) return NULL;
    Py_buffer v[10];
    const buffer_spec sp[10] = {{F64, -1, 0, "q"},     {F64, -1, 0, "distances"}, {I64, -1, 0, "limited"},
                                {F64, -1, 0, "lower"}, {F64, -1, 0, "upper"},     {F64, -1, 0, "half"},
                                {I64, -1, 0, "joints"}, {F64, -1, 0, "offsets"},  {F64, N_NUMBERS, 0, "numbers"},
                                {F64, -1, 1, "out"}};
    if (get_buffers(args + 1, v, sp, 10) < 0) return NULL;
    Py_ssize_t M = v[9].len / (8 * E_N), L = v[2].len / 8, K = v[6].len / 8, P = M ? v[1].len / (8 * M) : 0;
    const int64_t *limited = v[2].buf, *joints = v[6].buf;
    int bad = v[9].len != M * E_N * 8 || v[0].len != M * dof * 8 || v[1].len != M * P * 8 || v[3].len != L * 8 ||
              v[4].len != L * 8 || v[5].len != L * 8 || v[7].len != K * 8;
    bad = bad || !indices_within(limited, L, 1, 0, dof) || !indices_within(joints, K, 1, 0, dof);
    if (bad) {
        release_buffers(v, 10);
        PyErr_SetString(PyExc_ValueError, "evaluate: sizes of q, the distances, the joints and out disagree");
        return NULL;
    }
    const double *q = v[0].buf, *d = v[1].buf;
    double *out = v[9].buf;
    for (Py_ssize_t r = 0; r < M; r++)
        evaluate(q + r * dof, d + r * P, P, limited, v[3].buf, v[4].buf, v[5].buf, L, joints, v[7].buf, K,
                 v[8].buf, out + r * E_N);
    release_buffers(v, 10);
    Py_RETURN_NONE;
}

PyMethodDef om_objective_functions[] = {
    {"evaluate", (PyCFunction)(void (*)(void))om_evaluate, METH_FASTCALL,
     "evaluate(dof, q, distances, limited, lower, upper, half, joints, offsets, numbers, out) -> None"},
    {NULL, NULL, 0, NULL},
};
