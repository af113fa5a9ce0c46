/* The binding of the tracking step (csrc/redundancy/tracking.c): track_step reads the optimiser's work, the
 * step's start and the clearances' linearisation from records (om_redundant._core.TrackingWork,
 * TrackingStart, Linearisation) by name, and answers a TrackingStep by name. */
#include "binding.h"
#include "redundancy.h"

/* The fields of a TrackingWork record: the kernel, the arrays, then the numbers. */
enum { W_KERNEL, W_LOWER, W_UPPER, W_SING_JOINTS, W_SING_OFFSETS, W_Q, W_ARRAYS = W_Q, W_MARGIN_WEIGHT = 6, W_N = 13 };
static const char *const work_names[W_N] = {
    "kernel",        "lower",           "upper",         "singular_joints",  "singular_offsets",
    "q",             "margin_weight",   "clearance_weight", "singularity_weight", "clearance_floor",
    "clearance_cap", "singularity_cap", "joint_step"};
/* The fields of a TrackingStart record. */
enum { S_T, S_SIGNS, S_PSI, S_Q, S_CURVATURE, S_N };
static const char *const start_names[S_N] = {"T", "signs", "psi", "q", "curvature"};
/* The fields of a Linearisation record it reads. */
enum { L_Q, L_DISTANCES, L_GRADIENTS, L_N };
static const char *const linearisation_names[L_N] = {"q", "distances", "gradients"};

static PyStructSequence_Field step_fields[] = {
    {"status", "TRACK_OK, or why no step was taken: TRACK_NO_SOLUTION, TRACK_SINGULAR, TRACK_INFEASIBLE, TRACK_LEFT"},
    {"psi", "the new arm angle (the rest: None unless TRACK_OK)"},
    {"step", "the step taken"},
    {"curvature", "the curvature the next step's model takes"},
    {"position_error", "the second solve's position error"},
    {"orientation_error", "its orientation error"},
    {"evaluations", "its residual evaluations"},
    {"within_limits", "its joints within the limits"},
    {NULL, NULL},
};
enum { N_STEP_FIELDS = 8 };
static PyStructSequence_Desc step_desc = {"om_redundant.ckernels.TrackingStep", "What track_step answers.",
                                          step_fields, N_STEP_FIELDS};
static PyTypeObject *step_type;

/* The TrackingStep of status (and *out where OM_TRACK_OK). */
static PyObject *tracking_step(int status, const om_tracked *out) {
    PyObject *items[N_STEP_FIELDS];
    items[0] = PyLong_FromLong(status);
    if (status != OM_TRACK_OK) {
        for (int i = 1; i < N_STEP_FIELDS; i++) items[i] = Py_NewRef(Py_None);
        return new_record(step_type, items, N_STEP_FIELDS);
    }
    const double numbers[5] = {out->psi, out->step, out->curvature, out->position_error, out->orientation_error};
    for (int i = 0; i < 5; i++) items[1 + i] = PyFloat_FromDouble(numbers[i]);
    items[6] = PyLong_FromLongLong(out->evaluations);
    items[7] = PyBool_FromLong(out->within_limits);
    return new_record(step_type, items, N_STEP_FIELDS);
}

/* The work's numbers into tr; -1 with an error. */
static int get_numbers(PyObject *const *w, om_tracking *tr, double *weights, double *clearance_floor) {
    double *numbers[7] = {&weights[0],       &weights[1],          &weights[2],    clearance_floor,
                          &tr->clearance_cap, &tr->singularity_cap, &tr->joint_step};
    for (int i = 0; i < 7; i++) {
        *numbers[i] = PyFloat_AsDouble(w[W_MARGIN_WEIGHT + i]);
        if (*numbers[i] == -1.0 && PyErr_Occurred()) return -1;
    }
    return 0;
}

/* Whether each singularity's joint is a joint index (read as q[j], t[j]). */
static bool joints_within(const double *joints, Py_ssize_t n) {
    bool ok = true;
    for (Py_ssize_t k = 0; k < n; k++) ok &= joints[k] >= 0.0 && joints[k] < 7.0 && joints[k] == floor(joints[k]);
    return ok;
}

/* track_step(work, start, linearisation, max_step) -> TrackingStep: the step from start (T,
 * signs, psi, q, curvature) within max_step, its joints into work.q (7). */
static PyObject *om_track_step_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"work", "start", "linearisation", "max_step"};
    static const arg_spec spec = {"track_step", names, 4, 4};
    enum { N = 11 }; /* the views: the work's arrays, the start's, the linearisation's */
    PyObject *a[4], *w[W_N], *s[S_N], *l[L_N];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    if (get_fields(a[0], work_names, W_N, w, "track_step's work") < 0) return NULL;
    PyObject *result = NULL;
    const om_solver_data *data = om_srs7_solver(w[W_KERNEL], "track_step");
    if (data == NULL || get_fields(a[1], start_names, S_N, s, "track_step's start") < 0) goto work;
    if (get_fields(a[2], linearisation_names, L_N, l, "track_step's linearisation") < 0) goto start;
    om_tracking tr = {.s = data};
    double weights[3], clearance_floor, psi = PyFloat_AsDouble(s[S_PSI]), curvature = PyFloat_AsDouble(s[S_CURVATURE]);
    double max_step = PyFloat_AsDouble(a[3]);
    if (PyErr_Occurred() || get_numbers(w, &tr, weights, &clearance_floor) < 0) goto linearisation;
    PyObject *const objs[N] = {w[W_LOWER], w[W_UPPER], w[W_SING_JOINTS], w[W_SING_OFFSETS], w[W_Q], s[S_T],
                               s[S_SIGNS], s[S_Q],     l[L_Q],         l[L_DISTANCES],    l[L_GRADIENTS]};
    const buffer_spec sp[N] = {{F64, 7, 0, "lower"},  {F64, 7, 0, "upper"},           {F64, -1, 0, "singular_joints"},
                               {F64, -1, 0, "singular_offsets"}, {F64, 7, 1, "q"}, {F64, 16, 0, "T"},
                               {I64, data->n_signs, 0, "signs"}, {F64, 7, 0, "start's q"},
                               {F64, 7, 0, "linearisation's q"}, {F64, -1, 0, "distances"},
                               {F64, -1, 0, "gradients"}};
    Py_buffer v[N];
    if (get_buffers(objs, v, sp, N) < 0) goto linearisation;
    double T[16];
    int64_t signs[3];
    Py_ssize_t n_sing = v[2].len / 8, n_clear = v[9].len / 8;
    if (copy_pose_and_signs(&v[5], &v[6], data->n_signs, T, signs) < 0)
        ;
    else if (v[3].len != v[2].len || v[10].len != n_clear * 7 * 8 || 14 + n_clear + n_sing > OM_TRACK_MAX_PIECES)
        PyErr_SetString(PyExc_ValueError, "track_step: sizes of the singularities and clearances disagree");
    else if (!joints_within(v[2].buf, n_sing))
        PyErr_SetString(PyExc_ValueError, "track_step: a singularity's joint is not a joint index in [0, 7)");
    else {
        tr.lower = v[0].buf, tr.upper = v[1].buf, tr.sing_joint = v[2].buf, tr.sing_offset = v[3].buf;
        tr.n_sing = (int)n_sing, tr.q_ref = v[8].buf, tr.clear_d = v[9].buf, tr.clear_g = v[10].buf;
        tr.n_clear = (int)n_clear;
        om_tracking_groups(&tr, weights[0], weights[1], weights[2], clearance_floor);
        om_tracked out;
        int status = om_track(&tr, T, signs, psi, v[7].buf, max_step, curvature, v[4].buf, &out);
        result = tracking_step(status, &out);
    }
    release_buffers(v, N);
linearisation:
    release_fields(l, L_N);
start:
    release_fields(s, S_N);
work:
    release_fields(w, W_N);
    return result;
}

static PyMethodDef functions[] = {
    {"track_step", (PyCFunction)(void (*)(void))om_track_step_py, METH_FASTCALL | METH_KEYWORDS,
     "track_step(work, start, linearisation, max_step) -> TrackingStep"},
    {NULL, NULL, 0, NULL},
};

int om_tracking_init(PyObject *module) {
    static const int_constant statuses[] = {{"TRACK_OK", OM_TRACK_OK}, {"TRACK_NO_SOLUTION", OM_TRACK_NO_SOLUTION},
                    {"TRACK_SINGULAR", OM_TRACK_SINGULAR}, {"TRACK_INFEASIBLE", OM_TRACK_INFEASIBLE},
                    {"TRACK_LEFT", OM_TRACK_LEFT}};
    if (PyModule_AddFunctions(module, functions) < 0) return -1;
    if (add_int_constants(module, statuses, sizeof statuses / sizeof statuses[0]) < 0) return -1;
    return add_record_type(module, &step_type, &step_desc, "TrackingStep");
}
