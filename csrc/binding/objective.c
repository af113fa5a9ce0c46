/* The binding of the redundancy optimiser's objective (csrc/redundancy/objective.c): evaluate reads the
 * objective's terms from a record (om_redundant._core.ObjectiveTerms) and writes each row's
 * evaluation into the named arrays of another (om_redundant._core.Evaluations). */
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

/* evaluate(terms, q, distances, out) -> None: out's arrays (M,) the evaluation (value, margin,
 * clearance, slack, singularity) at the M rows of q (M x terms.dof) with the pairs' distances
 * (M x P; P = 0 without obstacles). */
static PyObject *om_evaluate_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"terms", "q", "distances", "out"};
    static const arg_spec spec = {"evaluate", names, 4, 4};
    enum { N_VIEWS = 2 + T_ARRAYS + E_N }; /* q, distances, the terms' arrays, out's */
    PyObject *a[4], *t[T_N], *e[E_N];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    if (get_fields(a[0], terms_names, T_N, t, "evaluate's terms") < 0) return NULL;
    if (get_fields(a[3], out_names, E_N, e, "evaluate's out") < 0) {
        release_fields(t, T_N);
        return NULL;
    }
    Py_ssize_t dof;
    om_objective_terms o;
    PyObject *result = NULL;
    if (get_dof(t[T_DOF], &dof, "evaluate") < 0 || get_numbers(t, &o) < 0) goto done;
    PyObject *const objs[N_VIEWS] = {a[1], a[2], t[T_LIMITED], t[T_LOWER], t[T_UPPER], t[T_HALF],
                                     t[T_JOINTS], t[T_OFFSETS], e[0], e[1], e[2], e[3], e[4]};
    const buffer_spec sp[N_VIEWS] = {
        {F64, -1, 0, "q"},      {F64, -1, 0, "distances"}, {I64, -1, 0, "limited"}, {F64, -1, 0, "lower"},
        {F64, -1, 0, "upper"},  {F64, -1, 0, "half"},      {I64, -1, 0, "joints"},  {F64, -1, 0, "offsets"},
        {F64, -1, 1, "value"},  {F64, -1, 1, "margin"},    {F64, -1, 1, "clearance"}, {F64, -1, 1, "slack"},
        {F64, -1, 1, "singularity"}};
    Py_buffer v[N_VIEWS];
    if (get_buffers(objs, v, sp, N_VIEWS) < 0) goto done;
    Py_ssize_t M = v[8].len / 8, L = v[2].len / 8, K = v[6].len / 8, P = M ? v[1].len / (8 * M) : 0;
    o.limited = v[2].buf, o.lower = v[3].buf, o.upper = v[4].buf, o.half = v[5].buf, o.L = L;
    o.joints = v[6].buf, o.offsets = v[7].buf, o.K = K;
    int bad = v[0].len != M * dof * 8 || v[1].len != M * P * 8 || v[3].len != L * 8 || v[4].len != L * 8 ||
              v[5].len != L * 8 || v[7].len != K * 8;
    for (int i = 1; i < E_N; i++) bad = bad || v[8 + i].len != M * 8;
    bad = bad || !indices_within(o.limited, L, 1, 0, dof) || !indices_within(o.joints, K, 1, 0, dof);
    if (bad)
        PyErr_SetString(PyExc_ValueError, "evaluate: sizes of q, the distances, the joints and out disagree");
    else {
        const double *q = v[0].buf, *d = v[1].buf;
        double *value = v[8].buf, *margin = v[9].buf, *clearance = v[10].buf, *slack = v[11].buf;
        double *singularity = v[12].buf;
        for (Py_ssize_t r = 0; r < M; r++) {
            om_evaluation ev = om_evaluate(&o, q + r * dof, d + r * P, P);
            value[r] = ev.value, margin[r] = ev.margin, clearance[r] = ev.clearance, slack[r] = ev.slack;
            singularity[r] = ev.singularity;
        }
        result = Py_NewRef(Py_None);
    }
    release_buffers(v, N_VIEWS);
done:
    release_fields(t, T_N);
    release_fields(e, E_N);
    return result;
}

PyMethodDef om_objective_functions[] = {
    {"evaluate", (PyCFunction)(void (*)(void))om_evaluate_py, METH_FASTCALL | METH_KEYWORDS,
     "evaluate(terms, q, distances, out) -> None"},
    {NULL, NULL, 0, NULL},
};
