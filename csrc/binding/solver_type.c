/* The Solver type: a solver's fixed data, copied once, and its solve calls. */
#include <string.h>

#include "binding.h"

/* ------------------------------------------------------------------------------------ */
/* Solver: the solver's fixed data, copied once.                                          */

typedef om_Solver Solver;

static void Solver_dealloc(Solver *self) {
    PyMem_Free(self->storage);
    om_solver_clear_types(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int attr_long(PyObject *obj, const char *name, long *out) {
    PyObject *v = PyObject_GetAttrString(obj, name);
    if (!v) return -1;
    *out = PyLong_AsLong(v);
    Py_DECREF(v);
    return (*out == -1 && PyErr_Occurred()) ? -1 : 0;
}

static int attr_double(PyObject *obj, const char *name, double *out) {
    PyObject *v = PyObject_GetAttrString(obj, name);
    if (!v) return -1;
    *out = PyFloat_AsDouble(v);
    Py_DECREF(v);
    return (*out == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

/* The array attribute `name` of obj, of the given kind, into view (n entries; any if n < 0), held until
 * released; -1 with an error. */
static int attr_buffer(PyObject *obj, const char *name, Py_buffer *view, int kind, Py_ssize_t n) {
    PyObject *v = PyObject_GetAttrString(obj, name);
    if (!v) return -1;
    int rc = get_buffer(v, view, kind, n, 0, name);
    Py_DECREF(v);
    return rc;
}

/* Copy the float64 array attribute `name` (n entries) into dst; -1 on error. */
static int attr_copy(PyObject *obj, const char *name, double *dst, Py_ssize_t n) {
    Py_buffer view;
    if (attr_buffer(obj, name, &view, F64, n) < 0) return -1;
    memcpy(dst, view.buf, (size_t)view.len);
    PyBuffer_Release(&view);
    return 0;
}

/* The data's checks beyond their buffers' sizes: what the kernels index or loop by (the
 * family's parameters and tables, the modes, dp_joint, the scan points, flip), so that no
 * SolverData makes them read outside their arrays. -1 with a ValueError. */
static int check_data(const om_solver_data *s, long family, long mode, long dp_joint, long scan_points,
                      const Py_buffer *params, const Py_buffer *model_table, const Py_buffer *real_table,
                      const Py_buffer *nominal_table) {
    const char *problem = NULL;
    if (check_family(family, params, s->dof, model_table) < 0) return -1;
    if (mode != OM_FIXED && mode != OM_CIRCLE && mode != OM_TORUS)
        problem = "mode: FIXED, CIRCLE or TORUS";
    else if (dp_joint < 0 || dp_joint >= s->dof)
        problem = "dp joint: a joint's index";
    else if (scan_points < OM_MIN_SCAN_POINTS || scan_points > OM_MAX_SCAN_POINTS)
        problem = "scan points: MIN_SCAN_POINTS ... MAX_SCAN_POINTS";
    else if (real_table->len % 48 || table_joints(real_table) != s->dof || nominal_table->len % 48 ||
             (nominal_table->len && table_joints(nominal_table) != s->dof))
        problem = "tables: rows of 6, one joint per joint of the arm";
    else if (!(s->tol_pos > 0.0 && s->tol_ori > 0.0 && isfinite(s->tol_pos) && isfinite(s->tol_ori)) ||
             !(s->near_deviation >= 0.0 && isfinite(s->near_deviation)))
        problem = "tolerances: finite, > 0; near deviation: finite, >= 0";
    for (int j = 0; j < s->dof && !problem; j++)
        if (s->flip[j] != 1.0 && s->flip[j] != -1.0) problem = "flip: +-1 per joint";
    if (problem) PyErr_Format(PyExc_ValueError, "malformed solver data (%s)", problem);
    return problem ? -1 : 0;
}

/* Solver(data, solution_type=None, configuration_type=None): data is an
 * om_redundant._core.SolverData, its fields read by name; the two types (Solution, Configuration) let solve_pose answer.
 * Initialised once: the data is read and checked into a new store, kept only if all of it is
 * good (calls on other threads may be reading the store, the GIL released). */
static int Solver_init(Solver *self, PyObject *args, PyObject *kwds) {
    PyObject *d, *solution_type = Py_None, *configuration_type = Py_None;
    static char *kwlist[] = {"data", "solution_type", "configuration_type", NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "O|$OO", kwlist, &d, &solution_type, &configuration_type))
        return -1;
    if (self->storage) {
        PyErr_SetString(PyExc_RuntimeError, "a Solver is initialised once");
        return -1;
    }
    om_solver_data s = {0};
    uint8_t revolute[OM_MAX_DOF];
    long family, mode, dp_joint, scan_points, near_left, near_mixed;
    if (attr_long(d, "family", &family) || attr_long(d, "mode", &mode) || attr_long(d, "dp_joint", &dp_joint) ||
        attr_long(d, "scan_points", &scan_points) || attr_long(d, "near_left", &near_left) ||
        attr_long(d, "near_mixed", &near_mixed) || attr_double(d, "position_tolerance", &s.tol_pos) ||
        attr_double(d, "orientation_tolerance", &s.tol_ori) || attr_double(d, "near_deviation", &s.near_deviation))
        return -1;
    /* the arrays, held while they are checked and copied: params, the three tables, lower, upper */
    enum { N_ARRAYS = 6 };
    static const char *const names[N_ARRAYS] = {"params", "model_table", "real_table", "nominal_table", "lower",
                                                "upper"};
    Py_buffer v[N_ARRAYS];
    int held = 0;
    double *storage = NULL;
    for (; held < N_ARRAYS; held++)
        if (attr_buffer(d, names[held], &v[held], F64, held == 5 ? v[4].len / 8 : -1) < 0) goto fail;
    s.dof = (int)(v[4].len / 8);
    if (s.dof < 1 || s.dof > OM_MAX_DOF) {
        PyErr_Format(PyExc_ValueError, "malformed solver data (dof: 1 ... %d)", OM_MAX_DOF);
        goto fail;
    }
    Py_buffer rev;
    if (attr_copy(d, "flip", s.flip, s.dof) < 0 || attr_copy(d, "dp_coefficients", &s.D[0][0], 18) < 0 ||
        attr_copy(d, "T_base_root", s.T_base_root, 16) < 0 || attr_copy(d, "T_tool_flange", s.T_tool_flange, 16) < 0 ||
        attr_buffer(d, "revolute", &rev, U8, s.dof) < 0)
        goto fail;
    for (int j = 0; j < s.dof; j++) revolute[j] = ((const uint8_t *)rev.buf)[j] != 0;
    PyBuffer_Release(&rev);
    if (check_data(&s, family, mode, dp_joint, scan_points, &v[0], &v[1], &v[2], &v[3]) < 0) goto fail;
    Py_ssize_t total = 0;
    for (int i = 0; i < N_ARRAYS; i++) total += v[i].len;
    if (!(storage = PyMem_Malloc((size_t)total))) {
        PyErr_NoMemory();
        goto fail;
    }
    const double *arrays[N_ARRAYS];
    double *at = storage;
    for (int i = 0; i < N_ARRAYS; at += v[i].len / 8, i++) {
        memcpy(at, v[i].buf, (size_t)v[i].len);
        arrays[i] = at;
    }
    s.family = (int)family;
    s.mode = (int)mode;
    s.n_signs = 3;
    s.n_redundancy = family == OM_SRS ? 1 : 0;
    s.dp_joint = (int)dp_joint;
    s.params = arrays[0];
    s.model_table = arrays[1];
    s.n_model_rows = (int)(v[1].len / 48);
    s.real_table = arrays[2];
    s.n_real_rows = (int)(v[2].len / 48);
    s.nominal_table = v[3].len ? arrays[3] : NULL;
    s.n_nominal_rows = (int)(v[3].len / 48);
    s.lower = arrays[4];
    s.upper = arrays[5];
    s.scan_points = (int)scan_points;
    s.near_left = near_left != 0;
    s.near_mixed = near_mixed != 0;
    for (int j = 0; j < s.dof; j++) s.flipped = s.flipped || s.flip[j] < 0.0;
    release_buffers(v, held);
    held = 0;
    /* (the types' attributes run Python code, which might initialise this Solver meanwhile) */
    if (om_solver_set_types(self, solution_type, configuration_type) < 0) goto fail;
    if (self->storage) {
        PyErr_SetString(PyExc_RuntimeError, "a Solver is initialised once");
        goto fail;
    }
    memcpy(self->revolute, revolute, sizeof revolute);
    s.revolute = self->revolute;
    s.trig_shared = om_trig_shared(&s);
    self->data = s;
    self->storage = storage;
    return 0;
fail:
    release_buffers(v, held);
    PyMem_Free(storage);
    return -1;
}

const om_solver_data *om_solver_ready(const om_Solver *self) {
    if (self->storage) return &self->data;
    PyErr_SetString(PyExc_RuntimeError, "the Solver is not initialised");
    return NULL;
}

/* ------------------------------------------------------------------------------------ */
/* The methods' results, by name: PyStructSequence types made at import (om_solver_init).  */

static PyStructSequence_Field solved_fields[] = {
    {"status", "OK, UNREACHABLE or NO_SOLUTION_IN_CONFIGURATION"},
    {"position_error", "|p_real(q) - p_d| (m)"},
    {"orientation_error", "the angle of R_d^T R_real(q) (rad)"},
    {"evaluations", "the residual evaluations spent"},
    {"within_limits", "whether q is within the joint limits"},
    {NULL, NULL},
};
static PyStructSequence_Desc solved_desc = {"om_redundant.ckernels.Solved", "What Solver.solve found.", solved_fields,
                                            5};
static PyStructSequence_Field found_fields[] = {
    {"count", "the roots found"},
    {"evaluations", "the residual evaluations spent"},
    {NULL, NULL},
};
static PyStructSequence_Desc found_desc = {"om_redundant.ckernels.Found",
                                           "How many roots Solver.solve_all or Solver.bounded_search found.",
                                           found_fields, 2};
static PyStructSequence_Field torus_bound_fields[] = {
    {"g1", "the rate bound of the model's q1 on the cell"},
    {"g7", "the rate bound of the model's q7 on the cell"},
    {"unreachable", "whether the residual cannot vanish on the cell"},
    {"q1", "the model's q1 at the cell's centre"},
    {"q7", "the model's q7 at the cell's centre"},
    {NULL, NULL},
};
static PyStructSequence_Desc torus_bound_desc = {"om_redundant.ckernels.TorusBound",
                                                 "om_torus_cell_bound's bounds on a cell of the torus.",
                                                 torus_bound_fields, 5};
static PyTypeObject *solved_type, *found_type, *torus_bound_type;

int om_solver_init(PyObject *module) {
    if (PyType_Ready(&om_SolverType) < 0 || PyModule_AddObjectRef(module, "Solver", (PyObject *)&om_SolverType) < 0)
        return -1;
    const struct {
        PyTypeObject **type;
        PyStructSequence_Desc *desc;
        const char *name;
    } types[] = {{&solved_type, &solved_desc, "Solved"}, {&found_type, &found_desc, "Found"},
                 {&torus_bound_type, &torus_bound_desc, "TorusBound"}};
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++) {
        if (!*types[i].type && !(*types[i].type = PyStructSequence_NewType(types[i].desc))) return -1;
        if (PyModule_AddObjectRef(module, types[i].name, (PyObject *)*types[i].type) < 0) return -1;
    }
    return 0;
}

static PyObject *new_found(int count, int64_t evaluations) {
    PyObject *items[2] = {PyLong_FromLong(count), PyLong_FromLongLong(evaluations)};
    return new_record(found_type, items, 2);
}

/* A configuration's signs and redundancy values, as the kernels take them. */
typedef struct {
    int64_t signs[3];
    double redundancy[1];
} configuration;

/* The arguments of a call in one configuration: nargs checked against want (the call's name
 * in the error), the configuration's tuples read from args[1] (signs) and args[2]
 * (redundancy). Returns -1 with an exception set. */
static int get_call(const om_solver_data *s, PyObject *const *args, Py_ssize_t nargs, Py_ssize_t want,
                    const char *what, configuration *c) {
    if (check_nargs(nargs, want, what) < 0 || get_signs(args[1], c->signs, s->n_signs) < 0) return -1;
    return get_doubles(args[2], c->redundancy, s->n_redundancy, "redundancy");
}

/* solve(T, signs, redundancy, hint, q_out) -> Solved(status, position_error,
 * orientation_error, evaluations, within_limits). hint None: no hint. */
static PyObject *Solver_solve(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    configuration c;
    if (!s || get_call(s, args, nargs, 5, "solve", &c) < 0) return NULL;
    int n = args[3] != Py_None ? 3 : 2; /* the hint last, if there is one */
    PyObject *objs[3] = {args[0], args[4], args[3]};
    buffer_spec specs[3] = {{F64, 16, 0, "T"}, {F64, s->dof, 1, "q_out"}, {F64, s->dof, 0, "q_hint"}};
    Py_buffer v[3];
    if (get_buffers(objs, v, specs, n) < 0) return NULL;
    double T[16]; /* (the caller's array may change while the GIL is released: a copy) */
    memcpy(T, v[0].buf, sizeof T);
    om_result r;
    Py_BEGIN_ALLOW_THREADS r = om_solve_one(s, T, c.signs, c.redundancy, n == 3 ? v[2].buf : NULL, v[1].buf, NULL, NULL);
    Py_END_ALLOW_THREADS release_buffers(v, n);
    PyObject *items[5] = {PyLong_FromLong(r.status), PyFloat_FromDouble(r.position_error),
                          PyFloat_FromDouble(r.orientation_error), PyLong_FromLongLong(r.evaluations),
                          PyBool_FromLong(r.within_limits)};
    return new_record(solved_type, items, 5);
}

/* A batch's rows start:stop and inputs: T (M, 4, 4) from rows[0] into v[0], signs (M, k)
 * int64 and redundancy (M, r) from rows[1], rows[2] into v[1], v[2], start and stop from
 * rows[3], rows[4], and the outputs outs[i] by specs[i] (n_out <= OM_MAX_BATCH_OUTPUTS of
 * them; entries given per row, times M here) into v[3 + i]; the rows' signs, each -1 or +1,
 * copied into *signs (k per row from row start on; PyMem_Free it), for the caller's array
 * may change while the GIL is released and the kernels take a sign's value as given.
 * Returns M, or -1 with a TypeError or ValueError (nothing acquired). */
enum { OM_MAX_BATCH_OUTPUTS = 8 };
static Py_ssize_t get_rows(const om_solver_data *s, PyObject *const *rows, PyObject *const *outs,
                           const buffer_spec *specs, int n_out, Py_buffer *v, Py_ssize_t *start, Py_ssize_t *stop,
                           int64_t **signs) {
    *start = PyLong_AsSsize_t(rows[3]), *stop = PyLong_AsSsize_t(rows[4]);
    if (PyErr_Occurred()) return -1;
    if (get_buffer(rows[0], &v[0], F64, -1, 0, "T") < 0) return -1;
    Py_ssize_t m = v[0].len / (16 * 8);
    if (v[0].len != m * 16 * 8 || *start < 0 || *stop > m || *start > *stop) {
        PyErr_SetString(PyExc_ValueError, "T must be (M, 4, 4) and 0 <= start <= stop <= M");
        release_buffers(v, 1);
        return -1;
    }
    PyObject *objs[2 + OM_MAX_BATCH_OUTPUTS] = {rows[1], rows[2]};
    buffer_spec all[2 + OM_MAX_BATCH_OUTPUTS] = {{I64, m * s->n_signs, 0, "signs"},
                                                 {F64, m * s->n_redundancy, 0, "redundancy"}};
    for (int i = 0; i < n_out; i++) {
        objs[2 + i] = outs[i];
        all[2 + i] = specs[i];
        all[2 + i].n *= m;
    }
    if (get_buffers(objs, v + 1, all, 2 + n_out) < 0) {
        release_buffers(v, 1);
        return -1;
    }
    Py_ssize_t n = (*stop - *start) * s->n_signs;
    const int64_t *given = (const int64_t *)v[1].buf + *start * s->n_signs;
    *signs = PyMem_Malloc((size_t)(n + 1) * sizeof(int64_t));
    if (!*signs || copy_signs(given, n, *signs) < 0) {
        if (!*signs) PyErr_NoMemory();
        PyMem_Free(*signs);
        release_buffers(v, 3 + n_out);
        return -1;
    }
    return m;
}

/* The fields of solve_rows' batch (om_redundant._core.SolveBatch) it reads. */
enum { SB_T, SB_SIGNS, SB_REDUNDANCY, SB_HINTS, SB_Q, SB_STATUS, SB_POSITION, SB_ORIENTATION, SB_EVALUATIONS,
       SB_WITHIN, SB_N };
static const char *const solve_batch_names[SB_N] = {"T", "signs", "redundancy", "hints", "q", "status",
                                                    "position_error", "orientation_error", "evaluations",
                                                    "within_limits"};

/* solve_rows(batch, start, stop): rows start:stop of a batch (om_redundant._core.SolveBatch):
 * T (M, 4, 4), signs (M, k) int64, redundancy (M, r), hints (M, dof) or None in; q (M, dof),
 * status (M,) int64, position_error (M,), orientation_error (M,), evaluations (M,) int64 and
 * within_limits (M,) bool out, each row's as solve's. */
static PyObject *Solver_solve_rows(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    PyObject *w[SB_N];
    if (!s || check_nargs(nargs, 3, "solve_rows") < 0 || get_fields(args[0], solve_batch_names, SB_N, w, "solve_rows' batch") < 0)
        return NULL;
    int dof = s->dof, k = s->n_signs, nr = s->n_redundancy, n_out = w[SB_HINTS] != Py_None ? 7 : 6;
    PyObject *rows[5] = {w[SB_T], w[SB_SIGNS], w[SB_REDUNDANCY], args[1], args[2]};
    PyObject *outs[7] = {w[SB_Q],           w[SB_STATUS],      w[SB_POSITION], w[SB_ORIENTATION],
                         w[SB_EVALUATIONS], w[SB_WITHIN],      w[SB_HINTS]};
    const buffer_spec specs[7] = {{F64, dof, 1, "q"},           {I64, 1, 1, "status"},
                                  {F64, 1, 1, "position_error"}, {F64, 1, 1, "orientation_error"},
                                  {I64, 1, 1, "evaluations"},   {U8, 1, 1, "within_limits"},
                                  {F64, dof, 0, "hints"}};
    Py_buffer v[10]; /* T, signs, redundancy, the six outputs, and the hints last */
    Py_ssize_t start, stop;
    int64_t *signs;
    PyObject *result = NULL;
    if (get_rows(s, rows, outs, specs, n_out, v, &start, &stop, &signs) < 0) goto done;
    const double *Tb = v[0].buf, *rb = v[2].buf, *hb = n_out == 7 ? v[9].buf : NULL;
    double *qb = v[3].buf, *position = v[5].buf, *orientation = v[6].buf;
    int64_t *status = v[4].buf, *evaluations = v[7].buf;
    uint8_t *within = v[8].buf;
    Py_BEGIN_ALLOW_THREADS for (Py_ssize_t i = start; i < stop; i++) {
        om_result r = om_solve_one(s, Tb + 16 * i, signs + k * (i - start), rb + nr * i, hb ? hb + dof * i : NULL,
                                   qb + dof * i, NULL, NULL);
        status[i] = r.status;
        position[i] = r.position_error;
        orientation[i] = r.orientation_error;
        evaluations[i] = r.evaluations;
        within[i] = r.within_limits;
    }
    Py_END_ALLOW_THREADS release_buffers(v, 3 + n_out);
    PyMem_Free(signs);
    result = Py_NewRef(Py_None);
done:
    release_fields(w, SB_N);
    return result;
}

/* A root's errors and limits from om_solve_all's info row (position error, orientation
 * error, within limits) into the named arrays at entry at. */
static void put_root_info(const double *info, Py_ssize_t at, double *position, double *orientation, uint8_t *within) {
    position[at] = info[0];
    orientation[at] = info[1];
    within[at] = info[2] != 0.0;
}

/* The fields of solve_all_rows' batch (om_redundant._core.SolveAllBatch) it reads. */
enum { SA_T, SA_SIGNS, SA_REDUNDANCY, SA_BAND, SA_Q, SA_COUNT, SA_EVALUATIONS, SA_POSITION, SA_ORIENTATION,
       SA_WITHIN, SA_N };
static const char *const solve_all_batch_names[SA_N] = {"T", "signs", "redundancy", "band", "q", "count",
                                                        "evaluations", "position_error", "orientation_error",
                                                        "within_limits"};

/* solve_all_rows(batch, start, stop): om_solve_all of rows start:stop of a batch
 * (om_redundant._core.SolveAllBatch): T (M, 4, 4), signs (M, k) int64, redundancy (M, r),
 * band (M,) bool (whether a row without a root of its own searches the band) in; q (M,
 * MAX_ROOTS, dof), count (M,) int64, evaluations (M,) int64, and per root position_error,
 * orientation_error (M, MAX_ROOTS) and within_limits (M, MAX_ROOTS) bool out, each row's as
 * solve_all's (the entries beyond a row's count left as they were). */
static PyObject *Solver_solve_all_rows(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    PyObject *w[SA_N];
    if (!s || check_nargs(nargs, 3, "solve_all_rows") < 0 ||
        get_fields(args[0], solve_all_batch_names, SA_N, w, "solve_all_rows' batch") < 0)
        return NULL;
    int dof = s->dof, k = s->n_signs, nr = s->n_redundancy;
    PyObject *rows[5] = {w[SA_T], w[SA_SIGNS], w[SA_REDUNDANCY], args[1], args[2]};
    PyObject *outs[7] = {w[SA_Q],        w[SA_COUNT],   w[SA_EVALUATIONS], w[SA_POSITION],
                         w[SA_ORIENTATION], w[SA_WITHIN], w[SA_BAND]};
    const buffer_spec specs[7] = {{F64, OM_MAX_ROOTS * dof, 1, "q"},      {I64, 1, 1, "count"},
                                  {I64, 1, 1, "evaluations"},             {F64, OM_MAX_ROOTS, 1, "position_error"},
                                  {F64, OM_MAX_ROOTS, 1, "orientation_error"}, {U8, OM_MAX_ROOTS, 1, "within_limits"},
                                  {U8, 1, 0, "band"}};
    Py_buffer v[10];
    Py_ssize_t start, stop;
    int64_t *signs;
    PyObject *result = NULL;
    if (get_rows(s, rows, outs, specs, 7, v, &start, &stop, &signs) < 0) goto done;
    const double *Tb = v[0].buf, *rb = v[2].buf;
    double *roots = v[3].buf, *position = v[6].buf, *orientation = v[7].buf;
    int64_t *count = v[4].buf, *evaluations = v[5].buf;
    uint8_t *within = v[8].buf;
    const uint8_t *band = v[9].buf;
    /* Neighbouring rows that differ in the SHOULDER sign alone share the circle's candidates,
     * and the rows' scans of one pose the model's parts at their samples (the memo). */
    om_scan_cache cache = {.valid = false, .capacity = OM_SCAN_CAPACITY(s->scan_points)};
    Py_BEGIN_ALLOW_THREADS cache.candidates = malloc((size_t)cache.capacity * sizeof(double));
    cache.memo = om_scan_memo_new(s);
    for (Py_ssize_t i = start; i < stop; i++) {
        double info[OM_MAX_ROOTS * 3];
        count[i] = om_solve_all(s, Tb + 16 * i, signs + k * (i - start), rb + nr * i, roots + OM_MAX_ROOTS * dof * i,
                                info, &evaluations[i], band[i], cache.candidates ? &cache : NULL);
        for (int r = 0; r < count[i]; r++) put_root_info(info + 3 * r, OM_MAX_ROOTS * i + r, position, orientation, within);
    }
    free(cache.candidates);
    om_scan_memo_free(cache.memo);
    Py_END_ALLOW_THREADS release_buffers(v, 10);
    PyMem_Free(signs);
    result = Py_NewRef(Py_None);
done:
    release_fields(w, SA_N);
    return result;
}

/* The fields of solve_all's roots (om_redundant._core.Roots) it writes. */
enum { RT_Q, RT_POSITION, RT_ORIENTATION, RT_WITHIN, RT_N };
static const char *const roots_names[RT_N] = {"q", "position_error", "orientation_error", "within_limits"};

/* solve_all(T, signs, redundancy, roots) -> Found(count, evaluations); roots
 * (om_redundant._core.Roots) gets the first count roots: q (MAX_ROOTS, dof), position_error,
 * orientation_error (MAX_ROOTS,) and within_limits (MAX_ROOTS,) bool. */
static PyObject *Solver_solve_all(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    configuration c;
    PyObject *w[RT_N];
    if (!s || get_call(s, args, nargs, 4, "solve_all", &c) < 0 ||
        get_fields(args[3], roots_names, RT_N, w, "solve_all's roots") < 0)
        return NULL;
    PyObject *objs[5] = {args[0], w[RT_Q], w[RT_POSITION], w[RT_ORIENTATION], w[RT_WITHIN]};
    buffer_spec specs[5] = {{F64, 16, 0, "T"}, {F64, OM_MAX_ROOTS * s->dof, 1, "q"},
                            {F64, OM_MAX_ROOTS, 1, "position_error"}, {F64, OM_MAX_ROOTS, 1, "orientation_error"},
                            {U8, OM_MAX_ROOTS, 1, "within_limits"}};
    Py_buffer v[5];
    PyObject *result = NULL;
    if (get_buffers(objs, v, specs, 5) < 0) goto done;
    double T[16], info[OM_MAX_ROOTS * 3]; /* (T: a copy, as solve's) */
    memcpy(T, v[0].buf, sizeof T);
    int n;
    int64_t evaluations;
    Py_BEGIN_ALLOW_THREADS n = om_solve_all(s, T, c.signs, c.redundancy, v[1].buf, info, &evaluations, true, NULL);
    for (int r = 0; r < n; r++) put_root_info(info + 3 * r, r, v[2].buf, v[3].buf, v[4].buf);
    Py_END_ALLOW_THREADS release_buffers(v, 5);
    result = new_found(n, evaluations);
done:
    release_fields(w, RT_N);
    return result;
}

/* bounded_search(T, signs, redundancy, roots, certify) -> Found(count, evaluations): the
 * bounded search's roots of a configuration (om_all_roots on the whole circle or torus; roots
 * (MAX_ROOTS, dof), as found, in the arm's own joints), with the torus certificate where it
 * proves them (certify) or the grid search alone: what the tests compare. */
static PyObject *Solver_bounded_search(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    configuration c;
    if (!s || get_call(s, args, nargs, 5, "bounded_search", &c) < 0) return NULL;
    int certify = PyObject_IsTrue(args[4]);
    if (certify < 0) return NULL;
    PyObject *objs[2] = {args[0], args[3]};
    buffer_spec specs[2] = {{F64, 16, 0, "T"}, {F64, OM_MAX_ROOTS * s->dof, 1, "roots"}};
    Py_buffer v[2];
    if (get_buffers(objs, v, specs, 2) < 0) return NULL;
    double zeros[OM_MAX_DOF] = {0.0}, psi[1], T[16]; /* (T: a copy, as solve's) */
    memcpy(T, v[0].buf, sizeof T);
    om_problem pb;
    int n;
    Py_BEGIN_ALLOW_THREADS om_problem_init(&pb, s, T, c.signs, c.redundancy, psi, zeros);
    pb.certify = certify && pb.certify; /* (never for an arm near a family: om_problem_init) */
    n = om_all_roots(&pb, s->scan_points, v[1].buf, zeros, INFINITY);
    for (int r = 0; r < n && s->flipped; r++)
        om_flip(s, (double *)v[1].buf + r * s->dof, (double *)v[1].buf + r * s->dof);
    Py_END_ALLOW_THREADS release_buffers(v, 2);
    return new_found(n, pb.counter);
}

/* torus_bound(T, signs, redundancy, w1, w7, h) -> TorusBound(g1, g7, unreachable, q1, q7):
 * om_torus_cell_bound for the configuration (an arm whose search is on the torus), what its
 * tests check against the map itself. */
static PyObject *Solver_torus_bound(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    configuration c;
    if (!s || get_call(s, args, nargs, 6, "torus_bound", &c) < 0) return NULL;
    double w1 = PyFloat_AsDouble(args[3]), w7 = PyFloat_AsDouble(args[4]), h = PyFloat_AsDouble(args[5]);
    if (PyErr_Occurred()) return NULL;
    if (s->mode != OM_TORUS) {
        PyErr_SetString(PyExc_ValueError, "torus_bound: the arm's search is not on the torus");
        return NULL;
    }
    Py_buffer T;
    if (get_buffer(args[0], &T, F64, 16, 0, "T") < 0) return NULL;
    double zeros[OM_MAX_DOF] = {0.0}, q[OM_MAX_DOF] = {NAN}, psi[1];
    q[6] = NAN;
    om_problem pb;
    om_problem_init(&pb, s, T.buf, c.signs, c.redundancy, psi, zeros);
    om_torus_bound b = om_torus_cell_bound(&pb, w1, w7, h, q);
    PyBuffer_Release(&T);
    PyObject *items[5] = {PyFloat_FromDouble(b.g1), PyFloat_FromDouble(b.g7), PyBool_FromLong(b.unreachable),
                          PyFloat_FromDouble(q[0]), PyFloat_FromDouble(q[6])};
    return new_record(torus_bound_type, items, 5);
}

/* configuration_values(q, branch, redundancy): the branch quantities and redundancy values at q. */
static PyObject *Solver_configuration_values(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    if (!s || check_nargs(nargs, 3, "configuration_values") < 0) return NULL;
    buffer_spec specs[3] = {{F64, s->dof, 0, "q"}, {F64, s->n_signs, 1, "branch"},
                            {F64, s->n_redundancy, 1, "redundancy"}};
    Py_buffer v[3];
    if (get_buffers(args, v, specs, 3) < 0) return NULL;
    om_solver_configuration_values(s, v[0].buf, v[1].buf, v[2].buf);
    release_buffers(v, 3);
    Py_RETURN_NONE;
}

/* holds(q, signs, redundancy) -> bool: om_in_configuration (the band contract). */
static PyObject *Solver_holds(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    configuration c;
    if (!s || get_call(s, args, nargs, 3, "holds", &c) < 0) return NULL;
    Py_buffer q;
    if (get_buffer(args[0], &q, F64, s->dof, 0, "q") < 0) return NULL;
    double at[OM_MAX_DOF]; /* the kernels' coordinates */
    om_flip(s, q.buf, at);
    bool in = om_in_configuration(s, at, c.signs, c.redundancy);
    PyBuffer_Release(&q);
    return PyBool_FromLong(in);
}

static PyMethodDef Solver_methods[] = {
    {"solve", (PyCFunction)(void (*)(void))Solver_solve, METH_FASTCALL,
     "solve(T, signs, redundancy, hint, q_out) -> Solved: one solve; see om_redundant.ik.solver."},
    {"solve_pose", (PyCFunction)(void (*)(void))om_solver_solve_pose, METH_FASTCALL,
     "solve_pose(T, configuration) -> Solution, or None: the whole unhinted solve in one call."},
    {"solve_rows", (PyCFunction)(void (*)(void))Solver_solve_rows, METH_FASTCALL,
     "solve_rows(batch, start, stop): rows of a batch (a _core.SolveBatch)."},
    {"solve_all_rows", (PyCFunction)(void (*)(void))Solver_solve_all_rows, METH_FASTCALL,
     "solve_all_rows(batch, start, stop): every root in each configuration of rows of a batch (a "
     "_core.SolveAllBatch)."},
    {"solve_all", (PyCFunction)(void (*)(void))Solver_solve_all, METH_FASTCALL,
     "solve_all(T, signs, redundancy, roots) -> Found: every root in a configuration, into roots (a _core.Roots)."},
    {"configuration_values", (PyCFunction)(void (*)(void))Solver_configuration_values, METH_FASTCALL,
     "configuration_values(q, branch, redundancy): branch quantities and redundancy values at q."},
    {"bounded_search", (PyCFunction)(void (*)(void))Solver_bounded_search, METH_FASTCALL,
     "bounded_search(T, signs, redundancy, roots, certify) -> Found: the bounded search's roots of a "
     "configuration, with or without the torus certificate."},
    {"torus_bound", (PyCFunction)(void (*)(void))Solver_torus_bound, METH_FASTCALL,
     "torus_bound(T, signs, redundancy, w1, w7, h) -> TorusBound: the torus map's rate bounds on a cell "
     "(om_torus_cell_bound)."},
    {"holds", (PyCFunction)(void (*)(void))Solver_holds, METH_FASTCALL,
     "holds(q, signs, redundancy) -> bool: whether q is in a configuration (band)."},
    {NULL, NULL, 0, NULL},
};

/* The Solver obj's data if it is a 7-DOF arm's (S-R-S model); NULL with a TypeError or
 * ValueError naming `what` otherwise (follow and track_step walk its self-motion). */
const om_solver_data *om_srs7_solver(PyObject *obj, const char *what) {
    if (!PyObject_TypeCheck(obj, &om_SolverType)) {
        PyErr_Format(PyExc_TypeError, "%s: solver must be a ckernels.Solver", what);
        return NULL;
    }
    const om_solver_data *s = om_solver_ready((om_Solver *)obj);
    if (!s) return NULL;
    if (s->family != OM_SRS || s->dof != 7) {
        PyErr_Format(PyExc_ValueError, "%s: the solver must be a 7-DOF arm's (S-R-S model)", what);
        return NULL;
    }
    return s;
}

PyTypeObject om_SolverType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "om_redundant.ckernels.Solver",
    .tp_doc = "The OM solver's fixed data, compiled: Solver(SolverData, solution_type=None, configuration_type=None).",
    .tp_basicsize = sizeof(Solver),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Solver_init,
    .tp_dealloc = (destructor)Solver_dealloc,
    .tp_methods = Solver_methods,
};
