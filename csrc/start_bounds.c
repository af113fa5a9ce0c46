/* The bound of what a climb from a start can reach (om_redundant/redundancy/optimizer.py's
 * _StartBounds.within, whose numpy version is the reference; the same operations in its
 * order): from the cones u_i + L |x - psi_i| of every sample of the start's run within its
 * reach R, of f (column 0) and of each group's functions (the other columns). Minima and maxima
 * are numpy's (om_least, om_most): a NaN bound is NaN as the reference's, and no start is skipped
 * for it (optimizer.py compares). */
#include "binding.h"

typedef struct {
    const double *psi, *values, *slopes, *weights, *caps;
    const int64_t *groups; /* each group's first column */
    Py_ssize_t columns, G;
} start_bounds;

/* The smaller of f's bound row[0] and sum_g w_g min(cap_g, min_j row_j) (the groups summed in
 * their order; 0 without groups). */
static double bound(const start_bounds *s, const double *row) {
    double total = 0.0;
    for (Py_ssize_t g = 0; g < s->G; g++) {
        Py_ssize_t end = g + 1 < s->G ? s->groups[g + 1] : s->columns;
        double least = row[s->groups[g]];
        for (Py_ssize_t j = s->groups[g] + 1; j < end; j++) least = om_least(least, row[j]);
        total = total + s->weights[g] * om_least(s->caps[g], least);
    }
    return om_least(row[0], total);
}

/* The bound of the cell of samples c, c + 1: the cones' meeting points, at least the ends. */
static double cell(const start_bounds *s, Py_ssize_t c, double *row) {
    const double *u = s->values + c * s->columns, *v = u + s->columns;
    double h = s->psi[c + 1] - s->psi[c];
    for (Py_ssize_t j = 0; j < s->columns; j++) {
        double peak = 0.5 * (u[j] + v[j] + s->slopes[j] * h), top = om_most(u[j], v[j]);
        row[j] = om_most(peak, top);
    }
    return bound(s, row);
}

/* The bound beyond sample e, reach - |psi_e - x| of the reach left. */
static double beyond(const start_bounds *s, Py_ssize_t e, double x, double reach, double *row) {
    const double *u = s->values + e * s->columns;
    double left = om_most(reach - fabs(s->psi[e] - x), 0.0);
    for (Py_ssize_t j = 0; j < s->columns; j++) row[j] = u[j] + s->slopes[j] * left;
    return bound(s, row);
}

/* start_bound(psi, values, slopes, groups, weights, caps, k, first, last, reach) -> float:
 * psi (M,) the runs' samples, values (M, C) f and the groups' functions there, slopes (C,)
 * their bounds L, groups (G,) int64 each group's first column, weights, caps (G,); sample k,
 * its run's first and last samples, the reach R. Every whole cell within R, and the cells R
 * cuts (or the run's ends) each the smaller of its bound and the cut end's; the largest, at
 * least f_k. */
static PyObject *om_start_bound(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 10, "start_bound") < 0) return NULL;
    Py_ssize_t k = PyLong_AsSsize_t(args[6]), a = PyLong_AsSsize_t(args[7]), b = PyLong_AsSsize_t(args[8]);
    double reach = PyFloat_AsDouble(args[9]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer v[6];
    const buffer_spec sp[6] = {{F64, -1, 0, "psi"}, {F64, -1, 0, "values"}, {F64, -1, 0, "slopes"},
                               {I64, -1, 0, "groups"}, {F64, -1, 0, "weights"}, {F64, -1, 0, "caps"}};
    if (get_buffers(args, v, sp, 6) < 0) return NULL;
    Py_ssize_t M = v[0].len / 8, C = v[2].len / 8, G = v[3].len / 8;
    start_bounds s = {v[0].buf, v[1].buf, v[2].buf, v[4].buf, v[5].buf, v[3].buf, C, G};
    int bad = C < 1 || v[1].len != M * C * 8 || v[4].len != G * 8 || v[5].len != G * 8 ||
              !(0 <= a && a <= k && k <= b && b < M) || !(reach >= 0.0);
    for (Py_ssize_t g = 0; g < G && !bad; g++) /* each group's first column, increasing */
        bad = s.groups[g] < 1 || s.groups[g] >= C || (g && s.groups[g] <= s.groups[g - 1]);
    double *row = bad ? NULL : PyMem_Malloc(C * sizeof(double));
    if (bad || !row) {
        release_buffers(v, 6);
        if (bad) PyErr_SetString(PyExc_ValueError, "start_bound: sizes or indices of the samples disagree");
        return bad ? NULL : PyErr_NoMemory();
    }
    double x = s.psi[k], low = x - reach, high = x + reach;
    Py_ssize_t lo = a, hi = b; /* the samples within reach: lo .. hi (k among them) */
    while (s.psi[lo] < low) lo++;
    while (s.psi[hi] > high) hi--;
    double best = s.values[k * C]; /* f_k */
    for (Py_ssize_t c = lo; c < hi; c++) best = om_most(best, cell(&s, c, row));
    double cut = beyond(&s, lo, x, reach, row);
    if (lo > a) cut = om_least(cut, cell(&s, lo - 1, row));
    best = om_most(best, cut);
    cut = beyond(&s, hi, x, reach, row);
    if (hi < b) cut = om_least(cut, cell(&s, hi, row));
    best = om_most(best, cut);
    PyMem_Free(row);
    release_buffers(v, 6);
    return PyFloat_FromDouble(best);
}

PyMethodDef om_start_bound_functions[] = {
    {"start_bound", (PyCFunction)(void (*)(void))om_start_bound, METH_FASTCALL,
     "start_bound(psi, values, slopes, groups, weights, caps, k, first, last, reach) -> float"},
    {NULL, NULL, 0, NULL},
};
