/* The binding of the redundancy optimiser's objective (csrc/redundancy/objective.c): evaluate and
 * linearise read the objective's terms from a record (om_redundant._core.ObjectiveTerms);
 * evaluate writes each row's evaluation into the named arrays of another
 * (om_redundant._core.Evaluations), linearise each row's pieces and rates into two arrays. */
#include "binding.h"
#include "redundancy.h"

/* The fields of an ObjectiveTerms record evaluate reads: the arrays, then the numbers. */
enum { T_DOF, T_LIMITED, T_LOWER, T_UPPER, T_HALF, T_JOINTS, T_OFFSETS, T_ARRAYS = T_OFFSETS, T_N = 13 };
static const char *const terms_names[T_N] = {
    "dof",    "limited",       "lower",         "upper",            "half",
    "joints", "offsets",       "margin_weight", "clearance_weight", "singularity_weight",
    "clearance_cap", "min_clearance", "singularity_cap"};
/* The fields of an Evaluations record: each row's om_evaluation, by name. */
enum { E_VALUE, E_MARGIN, E_CLEARANCE, E_SLACK, E_SINGULARITY, E_N };
static const char *const out_names[E_N] = {"value", "margin", "clearance", "slack", "singularity"};

/* The terms' numbers (fields[T_OFFSETS + 1 ...]) into o; -1 with an error. */
static int get_numbers(PyObject *const *fields, om_objective_terms *o) {
    double *numbers[6] = {&o->margin_weight, &o->clearance_weight, &o->singularity_weight,
                          &o->clearance_cap, &o->min_clearance,    &o->singularity_cap};
    for (int i = 0; i < 6; i++) {
        *numbers[i] = PyFloat_AsDouble(fields[T_OFFSETS + 1 + i]);
        if (*numbers[i] == -1.0 && PyErr_Occurred()) return -1;
    }
    return 0;
}

/* A call's objective terms (an ObjectiveTerms record) into o and *dof, their arrays' buffers
 * into v (release_buffers(v, N_TERM_VIEWS) after use); -1 with an error naming `what`. */
enum { N_TERM_VIEWS = T_ARRAYS - T_LIMITED + 1 };
static int get_terms(PyObject *terms, const char *what, om_objective_terms *o, Py_ssize_t *dof, Py_buffer *v) {
    PyObject *t[T_N];
    if (get_fields(terms, terms_names, T_N, t, what) < 0) return -1;
    int got = get_dof(t[T_DOF], dof, what) < 0 || get_numbers(t, o) < 0 ? -1 : 0;
    const buffer_spec sp[N_TERM_VIEWS] = {{I64, -1, 0, "limited"}, {F64, -1, 0, "lower"}, {F64, -1, 0, "upper"},
                                          {F64, -1, 0, "half"},    {I64, -1, 0, "joints"}, {F64, -1, 0, "offsets"}};
    got = got < 0 ? -1 : get_buffers(t + T_LIMITED, v, sp, N_TERM_VIEWS);
    release_fields(t, T_N); /* (the buffers keep the arrays) */
    if (got < 0) return -1;
    Py_ssize_t L = v[0].len / 8, K = v[4].len / 8;
    o->limited = v[0].buf, o->lower = v[1].buf, o->upper = v[2].buf, o->half = v[3].buf, o->L = L;
    o->joints = v[4].buf, o->offsets = v[5].buf, o->K = K;
    if (v[1].len != L * 8 || v[2].len != L * 8 || v[3].len != L * 8 || v[5].len != K * 8 ||
        !indices_within(o->limited, L, 1, 0, *dof) || !indices_within(o->joints, K, 1, 0, *dof)) {
        release_buffers(v, N_TERM_VIEWS);
        PyErr_Format(PyExc_ValueError, "%s: sizes of the limits or the singularities' joints disagree", what);
        return -1;
    }
    return 0;
}

/* A call's arguments (spec: the terms first) into a, its terms into o, *dof and tv (as
 * get_terms), and the fields names[0:n] of its argument a[record] into fields (as get_fields,
 * named `what`); -1 with an error, nothing held. */
static int get_call(PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames, const arg_spec *spec, PyObject **a,
                    om_objective_terms *o, Py_ssize_t *dof, Py_buffer *tv, int record, const char *const *names, int n,
                    PyObject **fields, const char *what) {
    if (bind_args(args, nargs, kwnames, spec, a) < 0 || get_terms(a[0], spec->function, o, dof, tv) < 0) return -1;
    if (get_fields(a[record], names, n, fields, what) < 0) {
        release_buffers(tv, N_TERM_VIEWS);
        return -1;
    }
    return 0;
}

/* evaluate(terms, q, distances, out) -> None: out's arrays (M,) the evaluation (value, margin,
 * clearance, slack, singularity) at the M rows of q (M x terms.dof) with the pairs' distances
 * (M x P; P = 0 without obstacles). */
static PyObject *om_evaluate_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"terms", "q", "distances", "out"};
    static const arg_spec spec = {"evaluate", names, 4, 4};
    enum { N_VIEWS = 2 + E_N }; /* q, distances, out's */
    PyObject *a[4], *e[E_N];
    Py_buffer tv[N_TERM_VIEWS], v[N_VIEWS];
    Py_ssize_t dof;
    om_objective_terms o;
    if (get_call(args, nargs, kwnames, &spec, a, &o, &dof, tv, 3, out_names, E_N, e, "evaluate's out") < 0)
        return NULL;
    PyObject *result = NULL;
    PyObject *const objs[N_VIEWS] = {a[1], a[2], e[0], e[1], e[2], e[3], e[4]};
    const buffer_spec sp[N_VIEWS] = {{F64, -1, 0, "q"},     {F64, -1, 0, "distances"}, {F64, -1, 1, "value"},
                                     {F64, -1, 1, "margin"}, {F64, -1, 1, "clearance"}, {F64, -1, 1, "slack"},
                                     {F64, -1, 1, "singularity"}};
    if (get_buffers(objs, v, sp, N_VIEWS) < 0) goto done;
    Py_ssize_t M = v[2].len / 8, P = M ? v[1].len / (8 * M) : 0;
    int bad = v[0].len != M * dof * 8 || v[1].len != M * P * 8;
    for (int i = 1; i < E_N; i++) bad = bad || v[2 + i].len != M * 8;
    if (bad)
        PyErr_SetString(PyExc_ValueError, "evaluate: sizes of q, the distances and out disagree");
    else {
        const double *q = v[0].buf, *d = v[1].buf;
        double *value = v[2].buf, *margin = v[3].buf, *clearance = v[4].buf, *slack = v[5].buf;
        double *singularity = v[6].buf;
        for (Py_ssize_t r = 0; r < M; r++) {
            om_evaluation ev = om_evaluate(&o, q + r * dof, d + r * P, P);
            value[r] = ev.value, margin[r] = ev.margin, clearance[r] = ev.clearance, slack[r] = ev.slack;
            singularity[r] = ev.singularity;
        }
        result = Py_NewRef(Py_None);
    }
    release_buffers(v, N_VIEWS);
done:
    release_buffers(tv, N_TERM_VIEWS);
    release_fields(e, E_N);
    return result;
}

/* The fields of the rows linearise reads (om_redundant._core.PieceRows). */
enum { R_Q, R_T, R_DISTANCES, R_GRADIENTS, R_N };
static const char *const row_names[R_N] = {"q", "t", "distances", "gradients"};

/* linearise(terms, rows, values, rates) -> None: at each of the M rows (PieceRows: q (M x dof)
 * with dq/dpsi = t (M x dof), the pairs' distances (M x P) and gradients (M x P x dof)) the
 * pieces of the objective's groups and their rates along t (om_linearise), into values and
 * rates (M x (2L + P + K)). */
static PyObject *om_linearise_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"terms", "rows", "values", "rates"};
    static const arg_spec spec = {"linearise", names, 4, 4};
    enum { N_VIEWS = R_N + 2 };
    PyObject *a[4], *f[N_VIEWS];
    Py_buffer tv[N_TERM_VIEWS], v[N_VIEWS];
    Py_ssize_t dof;
    om_objective_terms o;
    if (get_call(args, nargs, kwnames, &spec, a, &o, &dof, tv, 1, row_names, R_N, f, "linearise's rows") < 0)
        return NULL;
    f[R_N] = Py_NewRef(a[2]), f[R_N + 1] = Py_NewRef(a[3]);
    PyObject *result = NULL;
    const buffer_spec sp[N_VIEWS] = {{F64, -1, 0, "q"},         {F64, -1, 0, "t"},      {F64, -1, 0, "distances"},
                                     {F64, -1, 0, "gradients"}, {F64, -1, 1, "values"}, {F64, -1, 1, "rates"}};
    if (get_buffers(f, v, sp, N_VIEWS) < 0) goto done;
    Py_ssize_t M = v[0].len / 8 / dof, P = M ? v[2].len / 8 / M : 0, n = 2 * o.L + P + o.K;
    if (v[0].len != M * dof * 8 || v[1].len != M * dof * 8 || v[2].len != M * P * 8 ||
        v[3].len != M * P * dof * 8 || v[4].len != M * n * 8 || v[5].len != M * n * 8)
        PyErr_SetString(PyExc_ValueError, "linearise: sizes of q, t, the pairs and the pieces disagree");
    else {
        const double *q = v[0].buf, *t = v[1].buf, *d = v[2].buf, *grad = v[3].buf;
        double *values = v[4].buf, *rates = v[5].buf;
        for (Py_ssize_t r = 0; r < M; r++)
            om_linearise(&o, dof, q + r * dof, t + r * dof, d + r * P, grad + r * P * dof, P, values + r * n,
                         rates + r * n);
        result = Py_NewRef(Py_None);
    }
    release_buffers(v, N_VIEWS);
done:
    release_buffers(tv, N_TERM_VIEWS);
    release_fields(f, N_VIEWS);
    return result;
}

PyMethodDef om_objective_functions[] = {
    {"evaluate", (PyCFunction)(void (*)(void))om_evaluate_py, METH_FASTCALL | METH_KEYWORDS,
     "evaluate(terms, q, distances, out) -> None"},
    {"linearise", (PyCFunction)(void (*)(void))om_linearise_py, METH_FASTCALL | METH_KEYWORDS,
     "linearise(terms, rows, values, rates) -> None"},
    {NULL, NULL, 0, NULL},
};
