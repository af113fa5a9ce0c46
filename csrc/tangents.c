/* The self-motion tangents dq/dpsi of many joint vectors of a 7-DOF arm in one call: the
 * samples of the global choose's sweep (om_redundant/redundancy/self_motion.py's
 * self_motion_tangents, whose numpy version is the reference), each om_self_motion_tangent's
 * (self_motion.c), the one that follow.c gives the points it reaches. */
#include "binding.h"

/* self_motion_tangents(solver, q, t) -> None: t (M x 7, row-major) the tangents at the rows
 * of q (M x 7); a row of NaN where psi does not move along the self-motion. */
static PyObject *om_self_motion_tangents(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 3, "self_motion_tangents") < 0) return NULL;
    const om_solver_data *s = om_srs7_solver(args[0], "self_motion_tangents");
    if (s == NULL) return NULL;
    Py_buffer v[2];
    const buffer_spec sp[2] = {{F64, -1, 0, "q"}, {F64, -1, 1, "t"}};
    if (get_buffers(args + 1, v, sp, 2) < 0) return NULL;
    if (v[0].len != v[1].len || v[0].len % (7 * 8)) {
        release_buffers(v, 2);
        PyErr_SetString(PyExc_ValueError, "self_motion_tangents: q and t must both hold M rows of 7");
        return NULL;
    }
    Py_ssize_t rows = v[0].len / (7 * 8);
    const double *q = v[0].buf;
    double *t = v[1].buf;
    Py_BEGIN_ALLOW_THREADS for (Py_ssize_t k = 0; k < rows; k++) {
        if (!om_self_motion_tangent(s, q + 7 * k, t + 7 * k, 0.0))
            for (int i = 0; i < 7; i++) t[7 * k + i] = NAN;
    }
    Py_END_ALLOW_THREADS release_buffers(v, 2);
    Py_RETURN_NONE;
}

PyMethodDef om_tangent_functions[] = {
    {"self_motion_tangents", (PyCFunction)(void (*)(void))om_self_motion_tangents, METH_FASTCALL,
     "self_motion_tangents(solver, q, t) -> None"},
    {NULL, NULL, 0, NULL},
};
