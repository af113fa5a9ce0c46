/* The binding of the climb's QP in one variable (csrc/redundancy/box_qp.c): step_1d reads its pieces from a
 * record (om_redundant._core.Pieces) by name. */
#include "binding.h"
#include "redundancy.h"

/* The fields of a Pieces record the functions read. */
enum { P_VALUES, P_RATES, P_ENDS, P_WEIGHTS, P_FLOORS, P_CAPS, P_N };
static const char *const pieces_names[P_N] = {"values", "rates", "ends", "weights", "floors", "caps"};

static PyStructSequence_Field step_fields[] = {
    {"delta", "the step"},
    {"gain", "the model's gain model(delta) - b delta^2 / 2 - model(0)"},
    {NULL, NULL},
};
static PyStructSequence_Desc step_desc = {"om_redundant.ckernels.QPStep", "The climb's step (step_1d).",
                                          step_fields, 2};
static PyTypeObject *step_type;

/* A call's arguments (pieces, curvature, lower, upper, z): the pieces' buffers and z's into
 * views (7; released by the caller when 0 is returned), the groups into *q, b, lo, hi; -1 with
 * an error. */
static int get_problem(PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames, const char *what,
                       Py_buffer *views, om_qp_groups *q, double *b, double *lo, double *hi) {
    static const char *const names[] = {"pieces", "curvature", "lower", "upper", "z"};
    const arg_spec spec = {what, names, 5, 5};
    PyObject *a[5], *f[P_N + 1];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return -1;
    *b = PyFloat_AsDouble(a[1]), *lo = PyFloat_AsDouble(a[2]), *hi = PyFloat_AsDouble(a[3]);
    if (PyErr_Occurred()) return -1;
    if (get_fields(a[0], pieces_names, P_N, f, "pieces") < 0) return -1;
    f[P_N] = Py_NewRef(a[4]);
    const buffer_spec sp[P_N + 1] = {{F64, -1, 0, "values"},  {F64, -1, 0, "rates"},  {I64, -1, 0, "ends"},
                                     {F64, -1, 0, "weights"}, {F64, -1, 0, "floors"}, {F64, -1, 0, "caps"},
                                     {F64, -1, 1, "z"}};
    int got = get_buffers(f, views, sp, P_N + 1);
    release_fields(f, P_N + 1); /* (the buffers hold their arrays) */
    if (got < 0) return -1;
    Py_ssize_t n = views[P_VALUES].len / 8, G = views[P_WEIGHTS].len / 8;
    *q = (om_qp_groups){views[P_VALUES].buf, views[P_RATES].buf, views[P_WEIGHTS].buf, views[P_FLOORS].buf,
                        views[P_CAPS].buf,   views[P_ENDS].buf,  G};
    int bad = views[P_RATES].len != n * 8 || views[P_ENDS].len != (G + 1) * 8 || views[P_FLOORS].len != G * 8 ||
              views[P_CAPS].len != G * 8 || views[P_N].len != n * 8 || q->ends[0] != 0 || q->ends[G] != n;
    for (Py_ssize_t g = 0; g < G && !bad; g++) bad = q->ends[g + 1] <= q->ends[g];
    const char *why = bad ? "sizes of the pieces, the groups and z disagree" : NULL;
    for (Py_ssize_t j = 0; j < n && !why; j++)
        if (!isfinite(q->v[j]) || !isfinite(q->a[j])) why = "a piece is not a number";
    if (!why && !(*b > 0.0 && isfinite(*b))) why = "the curvature is not a positive number";
    if (!why && !(*lo <= *hi && isfinite(*lo) && isfinite(*hi))) why = "the bounds are not numbers lower <= upper";
    if (why) {
        release_buffers(views, P_N + 1);
        PyErr_Format(PyExc_ValueError, "%s: %s", what, why);
        return -1;
    }
    return 0;
}

/* step_1d(pieces, curvature, lower, upper, z) -> QPStep(delta, gain) or None: the climb's step
 * (om_qp_step), z (in place) every piece's multiplier (0 for those left out). */
static PyObject *om_step_1d_py(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    Py_buffer v[P_N + 1];
    om_qp_groups q;
    double b, lo, hi, delta, gain;
    if (get_problem(args, nargs, kwnames, "step_1d", v, &q, &b, &lo, &hi) < 0) return NULL;
    int found = om_qp_step(&q, b, lo, hi, &delta, &gain, v[P_N].buf);
    release_buffers(v, P_N + 1);
    switch (found) {
    case OM_QP_NO_MEMORY: return PyErr_NoMemory();
    case OM_QP_NONE: Py_RETURN_NONE;
    default: {
        PyObject *items[2] = {PyFloat_FromDouble(delta), PyFloat_FromDouble(gain)};
        return new_record(step_type, items, 2);
    }
    }
}

static PyMethodDef functions[] = {
    {"step_1d", (PyCFunction)(void (*)(void))om_step_1d_py, METH_FASTCALL | METH_KEYWORDS,
     "step_1d(pieces, curvature, lower, upper, z) -> QPStep(delta, gain) or None"},
    {NULL, NULL, 0, NULL},
};

int om_box_qp_init(PyObject *module) {
    if (PyModule_AddFunctions(module, functions) < 0) return -1;
    return add_record_type(module, &step_type, &step_desc, "QPStep");
}
