/* The binding of the bound of a climb's start (csrc/redundancy/start_bounds.c): start_bound reads the runs'
 * samples from a record (om_redundant._core.StartSamples) by name. */
#include "binding.h"
#include "redundancy.h"

enum { S_PSI, S_VALUES, S_SLOPES, S_GROUPS, S_WEIGHTS, S_CAPS, S_N };
static const char *const samples_names[S_N] = {"psi", "values", "slopes", "groups", "weights", "caps"};

/* The samples' buffers (S_N, from a StartSamples record) checked into *s; -1 with an error naming
 * the function (the views released). */
static int get_samples(PyObject *record, Py_buffer *v, om_start_samples *s, const char *function) {
    PyObject *f[S_N];
    if (get_fields(record, samples_names, S_N, f, "samples") < 0) return -1;
    const buffer_spec sp[S_N] = {{F64, -1, 0, "psi"},    {F64, -1, 0, "values"},  {F64, -1, 0, "slopes"},
                                 {I64, -1, 0, "groups"}, {F64, -1, 0, "weights"}, {F64, -1, 0, "caps"}};
    int got = get_buffers(f, v, sp, S_N);
    release_fields(f, S_N);
    if (got < 0) return -1;
    Py_ssize_t M = v[S_PSI].len / 8, C = M ? v[S_VALUES].len / 8 / M : 0, G = v[S_GROUPS].len / 8;
    *s = (om_start_samples){v[S_PSI].buf, v[S_VALUES].buf, v[S_SLOPES].buf, v[S_WEIGHTS].buf, v[S_CAPS].buf,
                            v[S_GROUPS].buf, C, G};
    int bad = C < 1 || v[S_VALUES].len != M * C * 8 || v[S_SLOPES].len != M * C * 8 || v[S_WEIGHTS].len != G * 8 ||
              v[S_CAPS].len != G * 8;
    for (Py_ssize_t g = 0; g < G && !bad; g++) /* each group's first column, increasing */
        bad = s->groups[g] < 1 || s->groups[g] >= C || (g && s->groups[g] <= s->groups[g - 1]);
    if (bad) {
        release_buffers(v, S_N);
        PyErr_Format(PyExc_ValueError, "%s: sizes or indices of the samples disagree", function);
        return -1;
    }
    return 0;
}

/* start_bound(samples, k, first, last, reach) -> float: samples.psi (M,) the runs' samples,
 * values (M, C) f and the groups' functions there, slopes (M, C) their bounds L on each
 * sample's run, groups (G,) int64
 * each group's first column, weights, caps (G,); sample k, its run's first and last samples,
 * the reach R (om_start_bound). */
static PyObject *om_start_bound_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"samples", "k", "first", "last", "reach"};
    static const arg_spec spec = {"start_bound", names, 5, 5};
    PyObject *a[5];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    Py_ssize_t k = PyLong_AsSsize_t(a[1]), first = PyLong_AsSsize_t(a[2]), last = PyLong_AsSsize_t(a[3]);
    double reach = PyFloat_AsDouble(a[4]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer v[S_N];
    om_start_samples s;
    if (get_samples(a[0], v, &s, "start_bound") < 0) return NULL;
    Py_ssize_t M = v[S_PSI].len / 8;
    double *row = NULL;
    if (!(0 <= first && first <= k && k <= last && last < M) || !(reach >= 0.0))
        PyErr_SetString(PyExc_ValueError, "start_bound: sizes or indices of the samples disagree");
    else if (!(row = PyMem_Malloc(s.columns * sizeof(double))))
        PyErr_NoMemory();
    if (!row) {
        release_buffers(v, S_N);
        return NULL;
    }
    double best = om_start_bound(&s, k, first, last, reach, row);
    PyMem_Free(row);
    release_buffers(v, S_N);
    return PyFloat_FromDouble(best);
}

/* start_cones(samples, starts, reach, out) -> None: out[i] (K,) the bound of start starts[i]
 * (K, int64) from its own cones with reach[i] (K,) (om_start_cone). */
static PyObject *om_start_cones_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"samples", "starts", "reach", "out"};
    static const arg_spec spec = {"start_cones", names, 4, 4};
    PyObject *a[4];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    Py_buffer v[S_N + 3];
    om_start_samples s;
    if (get_samples(a[0], v, &s, "start_cones") < 0) return NULL;
    const buffer_spec sp[3] = {{I64, -1, 0, "starts"}, {F64, -1, 0, "reach"}, {F64, -1, 1, "out"}};
    if (get_buffers(a + 1, v + S_N, sp, 3) < 0) {
        release_buffers(v, S_N);
        return NULL;
    }
    Py_ssize_t K = v[S_N].len / 8, M = v[S_PSI].len / 8;
    const int64_t *starts = v[S_N].buf;
    const double *reach = v[S_N + 1].buf;
    double *out = v[S_N + 2].buf, *row = NULL;
    if (v[S_N + 1].len != K * 8 || v[S_N + 2].len != K * 8 || !indices_within(starts, K, 1, 0, M))
        PyErr_SetString(PyExc_ValueError, "start_cones: sizes or indices of the starts disagree");
    else if (!(row = PyMem_Malloc(s.columns * sizeof(double))))
        PyErr_NoMemory();
    if (row)
        for (Py_ssize_t i = 0; i < K; i++) out[i] = om_start_cone(&s, starts[i], reach[i], row);
    PyMem_Free(row);
    release_buffers(v, S_N + 3);
    if (!row) return NULL;
    Py_RETURN_NONE;
}

PyMethodDef om_start_bound_functions[] = {
    {"start_cones", (PyCFunction)(void (*)(void))om_start_cones_py, METH_FASTCALL | METH_KEYWORDS,
     "start_cones(samples, starts, reach, out) -> None"},
    {"start_bound", (PyCFunction)(void (*)(void))om_start_bound_py, METH_FASTCALL | METH_KEYWORDS,
     "start_bound(samples, k, first, last, reach) -> float"},
    {NULL, NULL, 0, NULL},
};
