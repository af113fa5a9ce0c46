/* What the binding's files share: buffer checks and the pieces module.c assembles. */
#ifndef OM_BINDING_H
#define OM_BINDING_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "om_kernels.h"
#include "om_paths.h"

enum { F64, I64, U8 }; /* buffer kinds: float64, int64, bool */

/* Acquire obj's buffer as n items of the given kind (n < 0: any), C-contiguous (writable if
 * asked). Returns -1 with a TypeError or ValueError naming the argument. */
int get_buffer(PyObject *obj, Py_buffer *view, int kind, Py_ssize_t n, int writable, const char *name);
/* A TypeError naming what takes `want` arguments where nargs came; -1 then. */
int check_nargs(Py_ssize_t nargs, Py_ssize_t want, const char *what);
/* A kernel function's arguments: names[0:n] in order, the first `positional` (<= 6) of them
 * by position or by name, the rest by name only (`f(a, b, *, c, d)`). */
typedef struct {
    const char *function;
    const char *const *names;
    int n, positional;
} arg_spec;
/* The arguments of a METH_FASTCALL | METH_KEYWORDS call into out[0:spec->n] (borrowed
 * references), every one required; -1 with a TypeError naming the function and the argument
 * that is missing, unknown, repeated or given by position beyond spec->positional. */
int bind_args(PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames, const arg_spec *spec, PyObject **out);
/* The fields names[0:n] of a record (a NamedTuple of om_redundant._core) into out[0:n] (new
 * references: release_fields), read by name; -1 with a TypeError naming what and the field. */
int get_fields(PyObject *record, const char *const *names, int n, PyObject **out, const char *what);
/* A new result record of a PyStructSequence type (named fields) from items[0:n], whose
 * references it steals (NULL items: a failed conversion; NULL then, every item released). */
PyObject *new_record(PyTypeObject *type, PyObject **items, int n);
/* A named int constant of the module (ckernels.NAME). */
typedef struct {
    const char *name;
    int value;
} int_constant;
/* Add constants[0:n] to module; -1 with an error. */
int add_int_constants(PyObject *module, const int_constant *constants, size_t n);
/* Make the result type *type from desc, once (kept should the module be initialised again), and
 * add it to module as name; -1 with an error. */
int add_record_type(PyObject *module, PyTypeObject **type, PyStructSequence_Desc *desc, const char *name);
/* Release get_fields' references out[0:n]. */
void release_fields(PyObject **out, int n);
/* An arm's joint count from obj into *dof, 1 ... OM_MAX_DOF; -1 with an error naming what. */
int get_dof(PyObject *obj, Py_ssize_t *dof, const char *what);
/* What get_buffers asks of one argument: kind, entries (n < 0: any), writable, name. */
typedef struct {
    int kind;
    Py_ssize_t n;
    int writable;
    const char *name;
} buffer_spec;
/* Acquire objs[i]'s buffer by specs[i] for i < n, all or none (-1: those acquired released). */
int get_buffers(PyObject *const *objs, Py_buffer *views, const buffer_spec *specs, int n);
/* Release views[0:n]. */
void release_buffers(Py_buffer *views, int n);
/* The rows of a DH table's buffer (rows of 6 float64). */
static inline Py_ssize_t table_rows(const Py_buffer *table) { return table->len / (6 * 8); }
/* The joints (rows of kind 0 or 1, not 2: fixed) of a DH table's buffer (rows of 6 float64). */
Py_ssize_t table_joints(const Py_buffer *table);
/* Whether index[k * stride] lies in [lo, hi) for every k < n (a binding's check of the
 * joint or geom indices it is given, before it reads arrays at them). */
bool indices_within(const int64_t *index, Py_ssize_t n, Py_ssize_t stride, int64_t lo, int64_t hi);
/* A family's parameters P and the joints dof checked against it (and its model's DH table, if
 * not NULL: the family's joints, and a 6-DOF one's wrist row within it); -1 with a ValueError. */
int check_family(long family, const Py_buffer *P, Py_ssize_t dof, const Py_buffer *table);
/* Copy n signs into out, each -1 or +1 (the kernels take a sign's value as given); -1 with a
 * ValueError. */
int copy_signs(const int64_t *signs, Py_ssize_t n, int64_t *out);
/* A call's pose T (16 float64) and k signs copied out of their buffers (copy_signs): what the
 * kernels read while the GIL is released stays as it was checked. -1 with a ValueError. */
int copy_pose_and_signs(const Py_buffer *pose, const Py_buffer *signs, int k, double *T, int64_t *out);
/* A tuple of the sequence obj's k items (k < 0: any number; a new reference), NULL with a
 * TypeError or ValueError naming the argument. A tuple, not the sequence itself: an item's
 * __index__ or __float__ may change a list while it is read, never the tuple. */
PyObject *get_tuple(PyObject *obj, Py_ssize_t k, const char *name);
/* A sequence of k signs, each -1 or +1, into out. */
int get_signs(PyObject *obj, int64_t *out, int k);
/* A sequence of k numbers into out. */
int get_doubles(PyObject *obj, double *out, int k, const char *name);

/* Largest accepted deviation max|R^T R - I| of a pose's rotation block (validation.py takes it
 * from here: ckernels.ORTHONORMALITY_TOLERANCE). */
#define OM_ORTHONORMALITY_TOL 1e-9
/* T (16 float64, row-major 4x4): finite, last row [0 0 0 1], max|R^T R - I| <= tol, det R > 0. */
int om_pose_is_valid(const double *T, double tol);

/* The bounded search's grid points a Solver takes (ckernels.MIN_SCAN_POINTS, MAX_SCAN_POINTS;
 * om_redundant.ik.solver takes its bounds from here). */
#define OM_MIN_SCAN_POINTS 8
#define OM_MAX_SCAN_POINTS 1024

/* The status names by status code (ckernels.STATUS_NAMES), made at import (module.c). */
extern PyObject *om_status_names;

/* The fields of a solve's result type (om_redundant.ik.solver.Solution), in this order. */
#define OM_SOLUTION_FIELDS \
    { "q", "ok", "status", "configuration", "position_error", "orientation_error", "iterations", "within_limits" }
enum { OM_N_SOLUTION_FIELDS = 8 };

/* A Solver: the solver's fixed data, copied once (solver_type.c), and what solve_pose needs
 * to answer a whole solve in one call (solve_pose.c). */
typedef struct {
    PyObject_HEAD
    om_solver_data data;
    double *storage; /* params, tables, limits */
    uint8_t revolute[OM_MAX_DOF];
    PyObject *solution_type, *configuration_type; /* NULL: solve_pose answers None */
    PyObject *solution_fields[OM_N_SOLUTION_FIELDS]; /* solution_type's slot descriptors */
    PyObject *empty;                                 /* numpy.empty */
} om_Solver;

/* solver_type.c: the Solver's data, or NULL with a RuntimeError where it was never initialised. */
const om_solver_data *om_solver_ready(const om_Solver *self);
/* solve_pose.c: Solver(..., solution_type=, configuration_type=) and Solver.solve_pose. */
int om_solver_set_types(om_Solver *self, PyObject *solution_type, PyObject *configuration_type);
void om_solver_clear_types(om_Solver *self);
PyObject *om_solver_solve_pose(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);
/* solver_calls.c: the Solver's calls in one configuration (its methods of these names). */
PyObject *om_Solver_solve(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *om_Solver_solve_all(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *om_Solver_bounded_search(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *om_Solver_torus_bound(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *om_Solver_configuration_values(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *om_Solver_holds(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);
/* solver_calls.c: a root's (position error, orientation error, within limits) from a kernel's
 * info row into the result arrays at index at. */
void om_put_root_info(const double *info, Py_ssize_t at, double *position, double *orientation, uint8_t *within);
/* solver_batches.c: Solver.solve_rows and solve_all_rows (batch, start, stop). */
PyObject *om_solver_solve_rows(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *om_solver_solve_all_rows(om_Solver *self, PyObject *const *args, Py_ssize_t nargs);

extern PyTypeObject om_SolverType;        /* solver_type.c: Solver(SolverData) */
/* solver_type.c: the Solver type and its methods' result types (ckernels.Solver, Solved, Found,
 * TorusBound) into the module; -1 with an error. */
int om_solver_init(PyObject *module);
/* solver_type.c: obj's data if it is a 7-DOF (S-R-S) Solver; NULL with an error naming what. */
const om_solver_data *om_srs7_solver(PyObject *obj, const char *what);
extern PyMethodDef om_kernel_functions[]; /* functions.c: kinematics and closed forms */
extern PyMethodDef om_closed_form_functions[]; /* closed_forms.c: the model arms' closed forms */
int om_closed_forms_init(PyObject *module);     /* closed_forms.c: their result type (ckernels.Lifted) */
int om_tracking_init(PyObject *module);       /* binding/tracking.c: track_step, its statuses and result type */
int om_clearance_init(PyObject *module);      /* binding/clearance.c: arm and obstacle geoms */
/* binding/paths.c: follow, link_paths and self_motion_tangents (follow.c, link.c, tangents.c) */
extern PyMethodDef om_path_functions[];
int om_paths_init(PyObject *module); /* binding/paths.c: their result types, ckernels.Followed and Linked */
extern PyMethodDef om_objective_functions[]; /* binding/objective.c: the redundancy optimiser's objective */
extern PyMethodDef om_cell_functions[];      /* binding/cells.c: the cell test of the solution paths (cells.c) */
int om_box_qp_init(PyObject *module);         /* binding/box_qp.c: the climb's QP in one variable */
extern PyMethodDef om_start_bound_functions[]; /* binding/start_bounds.c: what a climb from a start can reach */
extern PyMethodDef om_traces_functions[];      /* binding/traces.c: torus_traces */
/* binding/traces.c: the traces that obj (None, or a torus_traces(solver) capsule) keeps; NULL for
 * None, and NULL with a TypeError or ValueError naming what where obj is neither, or another
 * solver's (PyErr_Occurred tells the two apart). */
om_torus_memo *om_traces_of(PyObject *obj, const om_solver_data *s, const char *what);

#endif
