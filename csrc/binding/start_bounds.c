/* The binding of the bound of a climb's start (csrc/start_bounds.c): start_bound reads the runs'
 * samples from a record (om_redundant._core.StartSamples) by name. */
#include "binding.h"
#include "redundancy.h"

enum { S_PSI, S_VALUES, S_SLOPES, S_GROUPS, S_WEIGHTS, S_CAPS, S_N };
static const char *const samples_names[S_N] = {"psi", "values", "slopes", "groups", "weights", "caps"};

/* start_bound(samples, k, first, last, reach) -> float: samples.psi (M,) the runs' samples,
 * values (M, C) f and the groups' functions there, slopes (C,) their bounds L, groups (G,) int64
 * each group's first column, weights, caps (G,); sample k, its run's first and last samples,
 * the reach R (om_start_bound). */
static PyObject *om_start_bound_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"samples", "k", "first", "last", "reach"};
    static const arg_spec spec = {"start_bound", names, 5, 5};
    PyObject *a[5], *f[S_N];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    Py_ssize_t k = PyLong_AsSsize_t(a[1]), first = PyLong_AsSsize_t(a[2]), last = PyLong_AsSsize_t(a[3]);
    double reach = PyFloat_AsDouble(a[4]);
    if (PyErr_Occurred()) return NULL;
    if (get_fields(a[0], samples_names, S_N, f, "start_bound's samples") < 0) return NULL;
    Py_buffer v[S_N];
    const buffer_spec sp[S_N] = {{F64, -1, 0, "psi"},    {F64, -1, 0, "values"},  {F64, -1, 0, "slopes"},
                                 {I64, -1, 0, "groups"}, {F64, -1, 0, "weights"}, {F64, -1, 0, "caps"}};
    int got = get_buffers(f, v, sp, S_N);
    release_fields(f, S_N);
    if (got < 0) return NULL;
    Py_ssize_t M = v[S_PSI].len / 8, C = v[S_SLOPES].len / 8, G = v[S_GROUPS].len / 8;
    om_start_samples s = {v[S_PSI].buf, v[S_VALUES].buf, v[S_SLOPES].buf, v[S_WEIGHTS].buf, v[S_CAPS].buf,
                          v[S_GROUPS].buf, C, G};
    int bad = C < 1 || v[S_VALUES].len != M * C * 8 || v[S_WEIGHTS].len != G * 8 || v[S_CAPS].len != G * 8 ||
              !(0 <= first && first <= k && k <= last && last < M) || !(reach >= 0.0);
    for (Py_ssize_t g = 0; g < G && !bad; g++) /* each group's first column, increasing */
        bad = s.groups[g] < 1 || s.groups[g] >= C || (g && s.groups[g] <= s.groups[g - 1]);
    double *row = bad ? NULL : PyMem_Malloc(C * sizeof(double));
    if (bad || !row) {
        release_buffers(v, S_N);
        if (bad) PyErr_SetString(PyExc_ValueError, "start_bound: sizes or indices of the samples disagree");
        return bad ? NULL : PyErr_NoMemory();
    }
    double best = om_start_bound(&s, k, first, last, reach, row);
    PyMem_Free(row);
    release_buffers(v, S_N);
    return PyFloat_FromDouble(best);
}

PyMethodDef om_start_bound_functions[] = {
    {"start_bound", (PyCFunction)(void (*)(void))om_start_bound_py, METH_FASTCALL | METH_KEYWORDS,
     "start_bound(samples, k, first, last, reach) -> float"},
    {NULL, NULL, 0, NULL},
};
