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

static PyMethodDef Solver_methods[] = {
    {"solve", (PyCFunction)(void (*)(void))om_Solver_solve, METH_FASTCALL,
     "solve(T, signs, redundancy, hint, q_out, from_previous) -> Solved: one solve; see om_redundant.ik.solver."},
    {"solve_pose", (PyCFunction)(void (*)(void))om_solver_solve_pose, METH_FASTCALL,
     "solve_pose(T, configuration) -> Solution, or None: the whole unhinted solve in one call."},
    {"solve_rows", (PyCFunction)(void (*)(void))om_solver_solve_rows, METH_FASTCALL,
     "solve_rows(batch, start, stop): rows of a batch (a _core.SolveBatch)."},
    {"solve_all_rows", (PyCFunction)(void (*)(void))om_solver_solve_all_rows, METH_FASTCALL,
     "solve_all_rows(batch, start, stop): every root in each configuration of rows of a batch (a "
     "_core.SolveAllBatch)."},
    {"solve_all", (PyCFunction)(void (*)(void))om_Solver_solve_all, METH_FASTCALL,
     "solve_all(T, signs, redundancy, roots) -> Found: every root in a configuration, into roots (a _core.Roots)."},
    {"configuration_values", (PyCFunction)(void (*)(void))om_Solver_configuration_values, METH_FASTCALL,
     "configuration_values(q, branch, redundancy): branch quantities and redundancy values at q."},
    {"bounded_search", (PyCFunction)(void (*)(void))om_Solver_bounded_search, METH_FASTCALL,
     "bounded_search(T, signs, redundancy, roots, certify) -> Found: the bounded search's roots of a "
     "configuration, with or without the torus certificate."},
    {"torus_bound", (PyCFunction)(void (*)(void))om_Solver_torus_bound, METH_FASTCALL,
     "torus_bound(T, signs, redundancy, w1, w7, h) -> TorusBound: the torus map's rate bounds on a cell "
     "(om_torus_cell_bound)."},
    {"holds", (PyCFunction)(void (*)(void))om_Solver_holds, METH_FASTCALL,
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
