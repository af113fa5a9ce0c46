/* What the binding's files share: buffer checks and the pieces module.c assembles. */
#ifndef OM_BINDING_H
#define OM_BINDING_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "om_kernels.h"

enum { F64, I64, U8 }; /* buffer kinds: float64, int64, bool */

/* Acquire obj's buffer as n items of the given kind (n < 0: any), C-contiguous (writable if
 * asked). Returns -1 with a TypeError or ValueError naming the argument. */
int get_buffer(PyObject *obj, Py_buffer *view, int kind, Py_ssize_t n, int writable, const char *name);
/* A sequence of k signs, each -1 or +1, into out. */
int get_signs(PyObject *obj, int64_t *out, int k);
/* A sequence of k numbers into out. */
int get_doubles(PyObject *obj, double *out, int k, const char *name);

extern PyTypeObject om_SolverType;        /* solver_type.c: Solver(SolverData) */
extern PyMethodDef om_kernel_functions[]; /* functions.c: kinematics and closed forms */

#endif
