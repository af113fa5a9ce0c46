/* Solver.solve_pose: the common solve (a pose array, a configuration, no hint) in one call,
 * its result object built here. What the Python call of OMSolver.solve cost besides the
 * kernel (the pose check, the configuration check, the result dataclass) was most of a
 * microsecond-scale solve.
 *
 * Arguments it does not take as they are (a pose that is not a valid C-contiguous float64
 * 4x4 buffer, a configuration of another type or size) answer None: the caller's general
 * path then checks them and names the problem, so every error message stays in one place
 * (om_redundant/validation.py, OMSolver.check_configuration). */
#include <string.h>

#include "binding.h"

void om_solver_clear_types(om_Solver *self) {
    Py_CLEAR(self->solution_type);
    Py_CLEAR(self->configuration_type);
    for (int i = 0; i < OM_N_SOLUTION_FIELDS; i++) Py_CLEAR(self->solution_fields[i]);
    Py_CLEAR(self->empty);
}

/* Keep the result and configuration types (both None: solve_pose answers None) and the
 * result type's slot descriptors, written directly (a frozen dataclass refuses setattr). */
int om_solver_set_types(om_Solver *self, PyObject *solution_type, PyObject *configuration_type) {
    om_solver_clear_types(self);
    if (solution_type == Py_None && configuration_type == Py_None) return 0;
    if (!PyType_Check(solution_type) || !PyType_Check(configuration_type)) {
        PyErr_SetString(PyExc_TypeError, "solution_type and configuration_type must both be types");
        return -1;
    }
    static const char *const names[OM_N_SOLUTION_FIELDS] = OM_SOLUTION_FIELDS;
    for (int i = 0; i < OM_N_SOLUTION_FIELDS; i++) {
        PyObject *field = PyObject_GetAttrString(solution_type, names[i]);
        if (!field || !Py_TYPE(field)->tp_descr_set) {
            Py_XDECREF(field);
            om_solver_clear_types(self);
            PyErr_Format(PyExc_TypeError, "solution_type must have a slot '%s'", names[i]);
            return -1;
        }
        self->solution_fields[i] = field;
    }
    PyObject *numpy = PyImport_ImportModule("numpy");
    if (!numpy) return -1;
    self->empty = PyObject_GetAttrString(numpy, "empty");
    Py_DECREF(numpy);
    if (!self->empty) return -1;
    self->solution_type = Py_NewRef(solution_type);
    self->configuration_type = Py_NewRef(configuration_type);
    return 0;
}

/* The configuration's signs and redundancy values, if it is one of this solver's type and
 * size: 1; 0 if not (no exception set). */
static int read_configuration(const om_Solver *self, PyObject *configuration, int64_t *signs, double *redundancy) {
    const om_solver_data *s = &self->data;
    if (!PyObject_TypeCheck(configuration, (PyTypeObject *)self->configuration_type)) return 0;
    static PyObject *signs_name, *redundancy_name; /* interned once */
    if (!signs_name && !(signs_name = PyUnicode_InternFromString("signs"))) return PyErr_Clear(), 0;
    if (!redundancy_name && !(redundancy_name = PyUnicode_InternFromString("redundancy"))) return PyErr_Clear(), 0;
    PyObject *sg = PyObject_GetAttr(configuration, signs_name);
    PyObject *rd = sg ? PyObject_GetAttr(configuration, redundancy_name) : NULL;
    int ok = rd && PyTuple_Check(sg) && PyTuple_GET_SIZE(sg) == s->n_signs && PyTuple_Check(rd) &&
             PyTuple_GET_SIZE(rd) == s->n_redundancy;
    for (int i = 0; ok && i < s->n_signs; i++) {
        long v = PyLong_AsLong(PyTuple_GET_ITEM(sg, i));
        ok = v == 1 || v == -1;
        signs[i] = v;
    }
    for (int i = 0; ok && i < s->n_redundancy; i++) {
        redundancy[i] = PyFloat_AsDouble(PyTuple_GET_ITEM(rd, i));
        ok = isfinite(redundancy[i]);
    }
    Py_XDECREF(sg);
    Py_XDECREF(rd);
    PyErr_Clear();
    return ok;
}

/* T, a C-contiguous float64 4x4, copied into pose (the caller's array may change while the GIL
 * is released: the copy is what is checked and solved): 1 if it is valid (om_pose_is_valid);
 * 0 if not (no exception set). */
static int read_pose(PyObject *T, double *pose) {
    Py_buffer view;
    if (PyObject_GetBuffer(T, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        PyErr_Clear();
        return 0;
    }
    const char *f = view.format ? view.format : "B";
    if (*f == '<' || *f == '=' || *f == '@') f++;
    int ok = view.ndim == 2 && view.shape[0] == 4 && view.shape[1] == 4 && view.itemsize == 8 && f[0] == 'd' &&
             f[1] == 0;
    if (ok) memcpy(pose, view.buf, 16 * sizeof(double));
    PyBuffer_Release(&view);
    return ok && om_pose_is_valid(pose, OM_ORTHONORMALITY_TOL);
}

/* A new solution_type object with its fields set to values (references stolen). */
static PyObject *make_solution(const om_Solver *self, PyObject **values) {
    PyTypeObject *type = (PyTypeObject *)self->solution_type;
    PyObject *solution = NULL;
    for (int i = 0; i < OM_N_SOLUTION_FIELDS; i++)
        if (!values[i]) goto done;
    solution = type->tp_alloc(type, 0);
    for (int i = 0; solution && i < OM_N_SOLUTION_FIELDS; i++) {
        PyObject *field = self->solution_fields[i];
        if (Py_TYPE(field)->tp_descr_set(field, solution, values[i]) < 0) Py_CLEAR(solution);
    }
done:
    for (int i = 0; i < OM_N_SOLUTION_FIELDS; i++) Py_XDECREF(values[i]);
    return solution;
}

/* A new numpy vector holding the self->data.dof values of q. */
static PyObject *new_vector(const om_Solver *self, const double *q) {
    Py_buffer view;
    PyObject *dof = PyLong_FromLong(self->data.dof);
    PyObject *vector = dof ? PyObject_CallOneArg(self->empty, dof) : NULL;
    Py_XDECREF(dof);
    if (!vector || get_buffer(vector, &view, F64, self->data.dof, 1, "q") < 0) {
        Py_XDECREF(vector);
        return NULL;
    }
    memcpy(view.buf, q, (size_t)self->data.dof * sizeof(double));
    PyBuffer_Release(&view);
    return vector;
}

/* solve_pose(T, configuration) -> Solution, or None (see the top of this file). */
PyObject *om_solver_solve_pose(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    if (!om_solver_ready(self)) return NULL;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "solve_pose takes (T, configuration)");
        return NULL;
    }
    int64_t signs[3];
    double redundancy[1], q[OM_MAX_DOF], T[16];
    if (!self->solution_type || !read_configuration(self, args[1], signs, redundancy) || !read_pose(args[0], T))
        Py_RETURN_NONE;
    om_result r;
    Py_BEGIN_ALLOW_THREADS r = om_solve_one(&self->data, T, signs, redundancy, NULL, q, NULL, NULL);
    Py_END_ALLOW_THREADS
    PyObject *values[OM_N_SOLUTION_FIELDS] = {
        new_vector(self, q),
        PyBool_FromLong(r.status == OM_OK),
        Py_NewRef(PyTuple_GET_ITEM(om_status_names, r.status)),
        Py_NewRef(args[1]),
        PyFloat_FromDouble(r.position_error),
        PyFloat_FromDouble(r.orientation_error),
        PyLong_FromLongLong(r.evaluations),
        PyBool_FromLong(r.within_limits),
    };
    return make_solution(self, values);
}
