/* The Solver's calls in one configuration (solve, solve_all, bounded_search, torus_bound,
 * configuration_values, holds) and their result types (ckernels.Solved, Found, TorusBound),
 * registered with the type by om_solver_init. */
#include <string.h>

#include "binding.h"

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
    if (add_record_type(module, &solved_type, &solved_desc, "Solved") < 0) return -1;
    if (add_record_type(module, &found_type, &found_desc, "Found") < 0) return -1;
    return add_record_type(module, &torus_bound_type, &torus_bound_desc, "TorusBound");
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

/* A root's errors and limits from om_solve_all's info row (position error, orientation
 * error, within limits) into the named arrays at entry at. */
void om_put_root_info(const double *info, Py_ssize_t at, double *position, double *orientation, uint8_t *within) {
    position[at] = info[0];
    orientation[at] = info[1];
    within[at] = info[2] != 0.0;
}

/* solve(T, signs, redundancy, hint, q_out, from_previous) -> Solved(status, position_error,
 * orientation_error, evaluations, within_limits). hint None: no hint; from_previous true: the
 * hint is the joints at the previous pose (om_solve_from). */
PyObject *om_Solver_solve(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    configuration c;
    if (!s || get_call(s, args, nargs, 6, "solve", &c) < 0) return NULL;
    int from_previous = PyObject_IsTrue(args[5]);
    if (from_previous < 0) return NULL;
    int n = args[3] != Py_None ? 3 : 2; /* the hint last, if there is one */
    PyObject *objs[3] = {args[0], args[4], args[3]};
    buffer_spec specs[3] = {{F64, 16, 0, "T"}, {F64, s->dof, 1, "q_out"}, {F64, s->dof, 0, "q_hint"}};
    Py_buffer v[3];
    if (get_buffers(objs, v, specs, n) < 0) return NULL;
    double T[16]; /* (the caller's array may change while the GIL is released: a copy) */
    memcpy(T, v[0].buf, sizeof T);
    om_result r;
    const double *hint = n == 3 ? v[2].buf : NULL;
    Py_BEGIN_ALLOW_THREADS r = hint && from_previous ? om_solve_from(s, T, c.signs, c.redundancy, hint, v[1].buf)
                                                     : om_solve_one(s, T, c.signs, c.redundancy, hint, v[1].buf, NULL, NULL);
    Py_END_ALLOW_THREADS release_buffers(v, n);
    PyObject *items[5] = {PyLong_FromLong(r.status), PyFloat_FromDouble(r.position_error),
                          PyFloat_FromDouble(r.orientation_error), PyLong_FromLongLong(r.evaluations),
                          PyBool_FromLong(r.within_limits)};
    return new_record(solved_type, items, 5);
}

/* The fields of solve_all's roots (om_redundant._core.Roots) it writes. */
enum { RT_Q, RT_POSITION, RT_ORIENTATION, RT_WITHIN, RT_N };
static const char *const roots_names[RT_N] = {"q", "position_error", "orientation_error", "within_limits"};

/* solve_all(T, signs, redundancy, roots) -> Found(count, evaluations); roots
 * (om_redundant._core.Roots) gets the first count roots: q (MAX_ROOTS, dof), position_error,
 * orientation_error (MAX_ROOTS,) and within_limits (MAX_ROOTS,) bool. */
PyObject *om_Solver_solve_all(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
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
    for (int r = 0; r < n; r++) om_put_root_info(info + 3 * r, r, v[2].buf, v[3].buf, v[4].buf);
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
PyObject *om_Solver_bounded_search(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
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
    n = om_all_roots(&pb, s->scan_points, v[1].buf);
    for (int r = 0; r < n && s->flipped; r++)
        om_flip(s, (double *)v[1].buf + r * s->dof, (double *)v[1].buf + r * s->dof);
    Py_END_ALLOW_THREADS release_buffers(v, 2);
    return new_found(n, pb.counter);
}

/* torus_bound(T, signs, redundancy, w1, w7, h) -> TorusBound(g1, g7, unreachable, q1, q7):
 * om_torus_cell_bound for the configuration (an arm whose search is on the torus), what its
 * tests check against the map itself. */
PyObject *om_Solver_torus_bound(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
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
PyObject *om_Solver_configuration_values(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
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
PyObject *om_Solver_holds(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
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
