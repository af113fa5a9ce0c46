/* The CPython binding of om_redundant's compiled core: om_redundant.ckernels.
 *
 * Arrays cross as buffers (numpy arrays), checked here for dtype, C-contiguity and size:
 * a wrong one raises TypeError or ValueError naming the argument, never reads past its end.
 * Configurations cross as the tuples of om.Configuration. Every kernel call releases the
 * GIL, so threads solve in parallel.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <string.h>

#include "om_kernels.h"

/* ------------------------------------------------------------------------------------ */
/* Buffers.                                                                               */

enum { F64, I64, U8 };

/* Acquire obj's buffer as n items of the given kind, C-contiguous (writable if asked). */
static int get_buffer(PyObject *obj, Py_buffer *view, int kind, Py_ssize_t n, int writable, const char *name) {
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) < 0) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s must be a C-contiguous%s array", name, writable ? " writable" : "");
        return -1;
    }
    const char *f = view->format ? view->format : "B";
    if (*f == '<' || *f == '=' || *f == '@') f++;
    int ok;
    switch (kind) {
    case F64: ok = view->itemsize == 8 && f[0] == 'd' && f[1] == 0; break;
    case I64: ok = view->itemsize == 8 && (f[0] == 'l' || f[0] == 'q') && f[1] == 0; break;
    default: ok = view->itemsize == 1 && (f[0] == '?' || f[0] == 'B' || f[0] == 'b') && f[1] == 0; break;
    }
    if (!ok) {
        PyErr_Format(PyExc_TypeError, "%s must be %s, got format '%s'", name,
                     kind == F64 ? "float64" : kind == I64 ? "int64" : "bool", view->format ? view->format : "B");
        PyBuffer_Release(view);
        return -1;
    }
    if (n >= 0 && view->len != n * view->itemsize) {
        PyErr_Format(PyExc_ValueError, "%s must have %zd entries, got %zd", name, n, view->len / view->itemsize);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* Parse a sequence of k numbers (ints for signs) into out. */
static int get_signs(PyObject *obj, int64_t *out, int k) {
    PyObject *seq = PySequence_Fast(obj, "signs must be a sequence");
    if (!seq) return -1;
    if (PySequence_Fast_GET_SIZE(seq) != k) {
        PyErr_Format(PyExc_ValueError, "signs must have %d entries, got %zd", k, PySequence_Fast_GET_SIZE(seq));
        Py_DECREF(seq);
        return -1;
    }
    for (int i = 0; i < k; i++) {
        long long v = PyLong_AsLongLong(PySequence_Fast_GET_ITEM(seq, i));
        if (v == -1 && PyErr_Occurred()) {
            Py_DECREF(seq);
            return -1;
        }
        if (v != 1 && v != -1) {
            PyErr_SetString(PyExc_ValueError, "signs must be -1 or +1");
            Py_DECREF(seq);
            return -1;
        }
        out[i] = (int64_t)v;
    }
    Py_DECREF(seq);
    return 0;
}

static int get_doubles(PyObject *obj, double *out, int k, const char *name) {
    PyObject *seq = PySequence_Fast(obj, "redundancy must be a sequence");
    if (!seq) return -1;
    if (PySequence_Fast_GET_SIZE(seq) != k) {
        PyErr_Format(PyExc_ValueError, "%s must have %d entries, got %zd", name, k, PySequence_Fast_GET_SIZE(seq));
        Py_DECREF(seq);
        return -1;
    }
    for (int i = 0; i < k; i++) {
        out[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, i));
        if (out[i] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(seq);
            return -1;
        }
    }
    Py_DECREF(seq);
    return 0;
}

/* ------------------------------------------------------------------------------------ */
/* Solver: the solver's fixed data, copied once.                                          */

typedef struct {
    PyObject_HEAD
    om_solver_data data;
    double *storage; /* params, tables, limits */
    uint8_t revolute[OM_MAX_DOF];
} Solver;

static void Solver_dealloc(Solver *self) {
    PyMem_Free(self->storage);
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

/* Copy the float64 array attribute `name` (n entries, or any size if n < 0) into dst (if
 * not NULL); returns its entry count, -1 on error. */
static Py_ssize_t attr_copy(PyObject *obj, const char *name, double *dst, Py_ssize_t n) {
    PyObject *v = PyObject_GetAttrString(obj, name);
    if (!v) return -1;
    Py_buffer view;
    int rc = get_buffer(v, &view, F64, n, 0, name);
    Py_DECREF(v);
    if (rc < 0) return -1;
    Py_ssize_t count = view.len / 8;
    if (dst) memcpy(dst, view.buf, view.len);
    PyBuffer_Release(&view);
    return count;
}

/* Solver(data): data is an om_redundant SolverData named tuple. */
static int Solver_init(Solver *self, PyObject *args, PyObject *kwds) {
    PyObject *d;
    static char *kwlist[] = {"data", NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "O", kwlist, &d)) return -1;
    om_solver_data *s = &self->data;
    long family, mode, dp_joint, scan_points;
    if (attr_long(d, "family", &family) || attr_long(d, "mode", &mode) || attr_long(d, "dp_joint", &dp_joint) ||
        attr_long(d, "scan_points", &scan_points) || attr_double(d, "position_tolerance", &s->tol_pos) ||
        attr_double(d, "orientation_tolerance", &s->tol_ori))
        return -1;
    Py_ssize_t n_params = attr_copy(d, "params", NULL, -1);
    Py_ssize_t n_model = attr_copy(d, "model_table", NULL, -1);
    Py_ssize_t n_real = attr_copy(d, "real_table", NULL, -1);
    Py_ssize_t dof = attr_copy(d, "lower", NULL, -1);
    if (n_params < 0 || n_model < 0 || n_real < 0 || dof < 0) return -1;
    if (dof < 1 || dof > OM_MAX_DOF || n_model % 6 || n_real % 6) {
        PyErr_SetString(PyExc_ValueError, "malformed solver data (dof or table shape)");
        return -1;
    }
    PyMem_Free(self->storage);
    self->storage = PyMem_Malloc(sizeof(double) * (n_params + n_model + n_real + 2 * dof));
    if (!self->storage) {
        PyErr_NoMemory();
        return -1;
    }
    double *params = self->storage, *model = params + n_params, *real = model + n_model;
    double *lower = real + n_real, *upper = lower + dof;
    double D[18];
    if (attr_copy(d, "params", params, n_params) < 0 || attr_copy(d, "model_table", model, n_model) < 0 ||
        attr_copy(d, "real_table", real, n_real) < 0 || attr_copy(d, "lower", lower, dof) < 0 ||
        attr_copy(d, "upper", upper, dof) < 0 || attr_copy(d, "dp_coefficients", D, 18) < 0 ||
        attr_copy(d, "T_base_root", s->T_base_root, 16) < 0 || attr_copy(d, "T_tool_flange", s->T_tool_flange, 16) < 0)
        return -1;
    PyObject *rev = PyObject_GetAttrString(d, "revolute");
    if (!rev) return -1;
    Py_buffer view;
    int rc = get_buffer(rev, &view, U8, dof, 0, "revolute");
    Py_DECREF(rev);
    if (rc < 0) return -1;
    for (Py_ssize_t j = 0; j < dof; j++) self->revolute[j] = ((const uint8_t *)view.buf)[j] != 0;
    PyBuffer_Release(&view);
    memcpy(s->D, D, sizeof D);
    s->family = (int)family;
    s->mode = (int)mode;
    s->dof = (int)dof;
    s->n_signs = 3;
    s->n_redundancy = family == OM_SRS ? 1 : 0;
    s->dp_joint = (int)dp_joint;
    s->params = params;
    s->model_table = model;
    s->n_model_rows = (int)(n_model / 6);
    s->real_table = real;
    s->n_real_rows = (int)(n_real / 6);
    s->revolute = self->revolute;
    s->lower = lower;
    s->upper = upper;
    s->scan_points = (int)scan_points;
    if (s->scan_points < 8 || (s->mode == OM_CIRCLE && (dp_joint < 0 || dp_joint >= dof))) {
        PyErr_SetString(PyExc_ValueError, "malformed solver data (scan points or dp joint)");
        return -1;
    }
    return 0;
}

static PyObject *result_tuple(om_result r) {
    return Py_BuildValue("(iddLO)", r.status, r.position_error, r.orientation_error, (long long)r.evaluations,
                         r.within_limits ? Py_True : Py_False);
}

/* The target of a solve: signs and redundancy values (the configuration's tuples) and the
 * pose T (16 float64). Returns -1 with an exception set. */
static int get_target(const om_solver_data *s, PyObject *const *args, int64_t *signs, double *redundancy,
                      Py_buffer *T) {
    if (get_signs(args[1], signs, s->n_signs) < 0 || get_doubles(args[2], redundancy, s->n_redundancy, "redundancy") < 0)
        return -1;
    return get_buffer(args[0], T, F64, 16, 0, "T");
}

/* solve(T, signs, redundancy, hint, q_out) -> (status, position error, orientation error,
 * evaluations, within limits). hint None: no hint. */
static PyObject *Solver_solve(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "solve takes (T, signs, redundancy, hint, q_out)");
        return NULL;
    }
    const om_solver_data *s = &self->data;
    int64_t signs[3];
    double redundancy[1];
    Py_buffer T, hint, q;
    if (get_target(s, args, signs, redundancy, &T) < 0) return NULL;
    int has_hint = args[3] != Py_None;
    if (has_hint && get_buffer(args[3], &hint, F64, s->dof, 0, "q_hint") < 0) {
        PyBuffer_Release(&T);
        return NULL;
    }
    if (get_buffer(args[4], &q, F64, s->dof, 1, "q_out") < 0) {
        PyBuffer_Release(&T);
        if (has_hint) PyBuffer_Release(&hint);
        return NULL;
    }
    om_result r;
    Py_BEGIN_ALLOW_THREADS r = om_solve_one(s, T.buf, signs, redundancy, has_hint ? hint.buf : NULL, q.buf);
    Py_END_ALLOW_THREADS PyBuffer_Release(&T);
    if (has_hint) PyBuffer_Release(&hint);
    PyBuffer_Release(&q);
    return result_tuple(r);
}

/* solve_rows(Ts, signs, redundancy, hints, start, stop, q_out, info): rows start:stop of a
 * batch; Ts (M, 4, 4), signs (M, k) int64, redundancy (M, r), hints (M, dof) or None,
 * q_out (M, dof), info (M, 5) gets (status, position error, orientation error,
 * evaluations, within limits). */
static PyObject *Solver_solve_rows(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError, "solve_rows takes (Ts, signs, redundancy, hints, start, stop, q_out, info)");
        return NULL;
    }
    const om_solver_data *s = &self->data;
    Py_ssize_t start = PyLong_AsSsize_t(args[4]), stop = PyLong_AsSsize_t(args[5]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer bufs[6];
    int n_bufs = 0, has_hint = args[3] != Py_None;
    Py_buffer *T = &bufs[n_bufs];
    if (get_buffer(args[0], T, F64, -1, 0, "Ts") < 0) return NULL;
    n_bufs++;
    Py_ssize_t m = T->len / (16 * 8);
    PyObject *result = NULL;
    if (T->len != m * 16 * 8 || start < 0 || stop > m || start > stop) {
        PyErr_SetString(PyExc_ValueError, "Ts must be (M, 4, 4) and 0 <= start <= stop <= M");
        goto done;
    }
    Py_buffer *signs = &bufs[n_bufs];
    if (get_buffer(args[1], signs, I64, m * s->n_signs, 0, "signs") < 0) goto done;
    n_bufs++;
    Py_buffer *red = &bufs[n_bufs];
    if (get_buffer(args[2], red, F64, m * s->n_redundancy, 0, "redundancy") < 0) goto done;
    n_bufs++;
    Py_buffer *hints = NULL;
    if (has_hint) {
        hints = &bufs[n_bufs];
        if (get_buffer(args[3], hints, F64, m * s->dof, 0, "q_hint") < 0) goto done;
        n_bufs++;
    }
    Py_buffer *q = &bufs[n_bufs];
    if (get_buffer(args[6], q, F64, m * s->dof, 1, "q_out") < 0) goto done;
    n_bufs++;
    Py_buffer *info = &bufs[n_bufs];
    if (get_buffer(args[7], info, F64, m * 5, 1, "info") < 0) goto done;
    n_bufs++;
    {
        const double *Tb = T->buf, *rb = red->buf, *hb = has_hint ? hints->buf : NULL;
        const int64_t *sb = signs->buf;
        double *qb = q->buf, *ib = info->buf;
        int dof = s->dof, k = s->n_signs, nr = s->n_redundancy;
        Py_BEGIN_ALLOW_THREADS for (Py_ssize_t i = start; i < stop; i++) {
            om_result r = om_solve_one(s, Tb + 16 * i, sb + k * i, rb + nr * i, hb ? hb + dof * i : NULL, qb + dof * i);
            double *row = ib + 5 * i;
            row[0] = r.status;
            row[1] = r.position_error;
            row[2] = r.orientation_error;
            row[3] = (double)r.evaluations;
            row[4] = r.within_limits;
        }
        Py_END_ALLOW_THREADS
    }
    result = Py_NewRef(Py_None);
done:
    for (int i = 0; i < n_bufs; i++) PyBuffer_Release(&bufs[i]);
    return result;
}

/* solve_all(T, signs, redundancy, roots, info) -> (count, evaluations); roots (MAX_ROOTS,
 * dof), info (MAX_ROOTS, 3) gets (position error, orientation error, within limits). */
static PyObject *Solver_solve_all(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "solve_all takes (T, signs, redundancy, roots, info)");
        return NULL;
    }
    const om_solver_data *s = &self->data;
    int64_t signs[3];
    double redundancy[1];
    Py_buffer T, roots, info;
    if (get_target(s, args, signs, redundancy, &T) < 0) return NULL;
    if (get_buffer(args[3], &roots, F64, OM_MAX_ROOTS * s->dof, 1, "roots") < 0) {
        PyBuffer_Release(&T);
        return NULL;
    }
    if (get_buffer(args[4], &info, F64, OM_MAX_ROOTS * 3, 1, "info") < 0) {
        PyBuffer_Release(&T);
        PyBuffer_Release(&roots);
        return NULL;
    }
    int n;
    int64_t evaluations;
    Py_BEGIN_ALLOW_THREADS n = om_solve_all(s, T.buf, signs, redundancy, roots.buf, info.buf, &evaluations);
    Py_END_ALLOW_THREADS PyBuffer_Release(&T);
    PyBuffer_Release(&roots);
    PyBuffer_Release(&info);
    return Py_BuildValue("(iL)", n, (long long)evaluations);
}

/* configuration_values(q, branch, redundancy): the branch quantities and redundancy values at q. */
static PyObject *Solver_configuration_values(Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "configuration_values takes (q, branch, redundancy)");
        return NULL;
    }
    const om_solver_data *s = &self->data;
    Py_buffer q, b, r;
    if (get_buffer(args[0], &q, F64, s->dof, 0, "q") < 0) return NULL;
    if (get_buffer(args[1], &b, F64, s->n_signs, 1, "branch") < 0) {
        PyBuffer_Release(&q);
        return NULL;
    }
    if (get_buffer(args[2], &r, F64, s->n_redundancy, 1, "redundancy") < 0) {
        PyBuffer_Release(&q);
        PyBuffer_Release(&b);
        return NULL;
    }
    om_branch_values(s->family, s->params, q.buf, b.buf);
    om_redundancy_values(s->family, s->params, q.buf, r.buf);
    PyBuffer_Release(&q);
    PyBuffer_Release(&b);
    PyBuffer_Release(&r);
    Py_RETURN_NONE;
}

static PyMethodDef Solver_methods[] = {
    {"solve", (PyCFunction)(void (*)(void))Solver_solve, METH_FASTCALL, "One solve; see om_redundant.om.solver."},
    {"solve_rows", (PyCFunction)(void (*)(void))Solver_solve_rows, METH_FASTCALL, "Rows of a batch."},
    {"solve_all", (PyCFunction)(void (*)(void))Solver_solve_all, METH_FASTCALL, "Every root in a configuration."},
    {"configuration_values", (PyCFunction)(void (*)(void))Solver_configuration_values, METH_FASTCALL,
     "Branch quantities and redundancy values at q."},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject SolverType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "om_redundant.ckernels.Solver",
    .tp_doc = "The OM solver's fixed data, compiled: Solver(SolverData).",
    .tp_basicsize = sizeof(Solver),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Solver_init,
    .tp_dealloc = (destructor)Solver_dealloc,
    .tp_methods = Solver_methods,
};

/* ------------------------------------------------------------------------------------ */
/* Module functions: kinematics and the families' closed forms.                           */

/* Parse n buffers; kinds/sizes/writable per argument; -1 size: any. */
typedef struct {
    int kind;
    Py_ssize_t n;
    int writable;
    const char *name;
} spec;

static int get_all(PyObject *const *args, Py_buffer *views, const spec *specs, int n) {
    for (int i = 0; i < n; i++) {
        if (get_buffer(args[i], &views[i], specs[i].kind, specs[i].n, specs[i].writable, specs[i].name) < 0) {
            for (int j = 0; j < i; j++) PyBuffer_Release(&views[j]);
            return -1;
        }
    }
    return 0;
}

static void release_all(Py_buffer *views, int n) {
    for (int i = 0; i < n; i++) PyBuffer_Release(&views[i]);
}

static int check_nargs(Py_ssize_t nargs, Py_ssize_t want, const char *what) {
    if (nargs != want) {
        PyErr_Format(PyExc_TypeError, "%s takes %zd arguments, got %zd", what, want, nargs);
        return -1;
    }
    return 0;
}

static Py_ssize_t table_rows(Py_buffer *table) {
    return table->len / (6 * 8);
}

/* fk(table, base, tool, Q, out): out[m] = base @ A(Q[m]) @ tool; Q (M, dof), out (M, 4, 4). */
static PyObject *k_fk(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 5, "fk") < 0) return NULL;
    Py_buffer v[5];
    spec sp[5] = {{F64, -1, 0, "table"}, {F64, 16, 0, "base"}, {F64, 16, 0, "tool"}, {F64, -1, 0, "Q"},
                  {F64, -1, 1, "out"}};
    if (get_all(args, v, sp, 5) < 0) return NULL;
    Py_ssize_t rows = table_rows(&v[0]), dof = 0;
    const double *t = v[0].buf;
    for (Py_ssize_t i = 0; i < rows; i++) dof += t[6 * i + 5] != 2.0;
    Py_ssize_t m = dof ? v[3].len / (8 * dof) : v[4].len / 128; /* no joints: one pose per out */
    if (v[0].len != rows * 48 || v[3].len != m * dof * 8 || v[4].len != m * 128) {
        release_all(v, 5);
        PyErr_SetString(PyExc_ValueError, "fk: shapes of table, Q and out disagree");
        return NULL;
    }
    Py_BEGIN_ALLOW_THREADS for (Py_ssize_t i = 0; i < m; i++) om_fk(t, (int)rows, v[1].buf, v[2].buf,
                                                                       (const double *)v[3].buf + dof * i,
                                                                       (double *)v[4].buf + 16 * i);
    Py_END_ALLOW_THREADS release_all(v, 5);
    Py_RETURN_NONE;
}

/* jacobian(table, base, tool, q, J): J (6, dof). */
static PyObject *k_jacobian(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 5, "jacobian") < 0) return NULL;
    Py_buffer v[5];
    spec sp[5] = {{F64, -1, 0, "table"}, {F64, 16, 0, "base"}, {F64, 16, 0, "tool"}, {F64, -1, 0, "q"},
                  {F64, -1, 1, "J"}};
    if (get_all(args, v, sp, 5) < 0) return NULL;
    Py_ssize_t rows = table_rows(&v[0]), dof = v[3].len / 8;
    if (dof > OM_MAX_DOF || v[4].len != 6 * dof * 8) {
        release_all(v, 5);
        PyErr_SetString(PyExc_ValueError, "jacobian: shapes of q and J disagree");
        return NULL;
    }
    om_jacobian(v[0].buf, (int)rows, v[1].buf, v[2].buf, v[3].buf, (int)dof, v[4].buf);
    release_all(v, 5);
    Py_RETURN_NONE;
}

/* flange(table, q, R, p): the last DH frame's pose in DH frame 0. */
static PyObject *k_flange(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 4, "flange") < 0) return NULL;
    Py_buffer v[4];
    spec sp[4] = {{F64, -1, 0, "table"}, {F64, -1, 0, "q"}, {F64, 9, 1, "R"}, {F64, 3, 1, "p"}};
    if (get_all(args, v, sp, 4) < 0) return NULL;
    om_flange(v[0].buf, (int)table_rows(&v[0]), v[1].buf, v[2].buf, v[3].buf);
    release_all(v, 4);
    Py_RETURN_NONE;
}

/* flange_target(T, T_base_root, T_tool_flange, R, p): the flange pose in DH frame 0. */
static PyObject *k_flange_target(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 5, "flange_target") < 0) return NULL;
    Py_buffer v[5];
    spec sp[5] = {{F64, 16, 0, "T"}, {F64, 16, 0, "T_base_root"}, {F64, 16, 0, "T_tool_flange"}, {F64, 9, 1, "R"},
                  {F64, 3, 1, "p"}};
    if (get_all(args, v, sp, 5) < 0) return NULL;
    mat3 R;
    vec3 p;
    om_flange_target(v[0].buf, v[1].buf, v[2].buf, &R, &p);
    double *Rb = v[3].buf, *pb = v[4].buf;
    const vec3 rows[3] = {R.r0, R.r1, R.r2};
    for (int i = 0; i < 3; i++) {
        Rb[3 * i] = rows[i].x;
        Rb[3 * i + 1] = rows[i].y;
        Rb[3 * i + 2] = rows[i].z;
    }
    pb[0] = p.x;
    pb[1] = p.y;
    pb[2] = p.z;
    release_all(v, 5);
    Py_RETURN_NONE;
}

static mat3 load_mat(const double *R) {
    return m_load(R, 0);
}

static vec3 load_vec(const double *p) {
    return v_load(p, 0);
}

/* Families' arguments are checked against the parameter vector's length and q's size. */
static int check_family(long family, Py_buffer *P, Py_ssize_t dof) {
    Py_ssize_t need = family == OM_SRS ? SRS_N_PARAMS : SD_N_PARAMS;
    Py_ssize_t want_dof = family == OM_SRS ? 7 : 6;
    if (family < 0 || family > OM_SRS) {
        PyErr_Format(PyExc_ValueError, "unknown family %ld", family);
        return -1;
    }
    if (P->len != need * 8 || dof != want_dof) {
        PyErr_Format(PyExc_ValueError, "family %ld takes %zd parameters and %zd joints", family, need, want_dof);
        return -1;
    }
    return 0;
}

/* model_ik(family, P, table, R, p, signs, redundancy, q_prev, q, all_joints) -> margin. */
static PyObject *k_model_ik(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 10, "model_ik") < 0) return NULL;
    long family = PyLong_AsLong(args[0]);
    int all_joints = PyObject_IsTrue(args[9]);
    if (PyErr_Occurred() || all_joints < 0) return NULL;
    Py_buffer v[8];
    spec sp[8] = {{F64, -1, 0, "P"}, {F64, -1, 0, "table"}, {F64, 9, 0, "R"}, {F64, 3, 0, "p"},
                  {I64, 3, 0, "signs"}, {F64, -1, 0, "redundancy"}, {F64, -1, 0, "q_prev"}, {F64, -1, 1, "q"}};
    if (get_all(args + 1, v, sp, 8) < 0) return NULL;
    if (check_family(family, &v[0], v[7].len / 8) < 0 || v[6].len != v[7].len ||
        v[5].len != (family == OM_SRS ? 8 : 0)) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "model_ik: shapes disagree");
        release_all(v, 8);
        return NULL;
    }
    mat3 R = load_mat(v[2].buf);
    double margin = om_model_ik((int)family, v[0].buf, v[1].buf, &R, load_vec(v[3].buf), v[4].buf, v[5].buf,
                                v[6].buf, v[7].buf, all_joints);
    release_all(v, 8);
    return PyFloat_FromDouble(margin);
}

/* model_ik_at_reach(P, R, p, signs, psi, q_prev, q) -> bool (S-R-S). */
static PyObject *k_model_ik_at_reach(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 7, "model_ik_at_reach") < 0) return NULL;
    double psi = PyFloat_AsDouble(args[4]);
    if (PyErr_Occurred()) return NULL;
    PyObject *const a[6] = {args[0], args[1], args[2], args[3], args[5], args[6]};
    Py_buffer v[6];
    spec sp[6] = {{F64, SRS_N_PARAMS, 0, "P"}, {F64, 9, 0, "R"}, {F64, 3, 0, "p"}, {I64, 3, 0, "signs"},
                  {F64, 7, 0, "q_prev"}, {F64, 7, 1, "q"}};
    if (get_all(a, v, sp, 6) < 0) return NULL;
    mat3 R = load_mat(v[1].buf);
    bool ok = om_srs_model_ik_at_reach(v[0].buf, &R, load_vec(v[2].buf), v[3].buf, psi, v[4].buf, v[5].buf);
    release_all(v, 6);
    return PyBool_FromLong(ok);
}

/* model_ik_lifted(P, R, p, signs, psi, q1, q7, phi4, q) -> (shoulder, wrist, elbow) residuals. */
static PyObject *k_model_ik_lifted(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 9, "model_ik_lifted") < 0) return NULL;
    double psi = PyFloat_AsDouble(args[4]), q1 = PyFloat_AsDouble(args[5]), q7 = PyFloat_AsDouble(args[6]),
           phi4 = PyFloat_AsDouble(args[7]);
    if (PyErr_Occurred()) return NULL;
    PyObject *const a[5] = {args[0], args[1], args[2], args[3], args[8]};
    Py_buffer v[5];
    spec sp[5] = {{F64, SRS_N_PARAMS, 0, "P"}, {F64, 9, 0, "R"}, {F64, 3, 0, "p"}, {I64, 3, 0, "signs"},
                  {F64, 7, 1, "q"}};
    if (get_all(a, v, sp, 5) < 0) return NULL;
    mat3 R = load_mat(v[1].buf);
    vec3 r = om_srs_model_ik_lifted(v[0].buf, &R, load_vec(v[2].buf), v[3].buf, psi, q1, q7, phi4, v[4].buf);
    release_all(v, 5);
    return Py_BuildValue("(ddd)", r.x, r.y, r.z);
}

/* branch_values(family, P, q, out) and redundancy_values(family, P, q, out). */
static PyObject *configuration_values(PyObject *const *args, Py_ssize_t nargs, int redundancy) {
    if (check_nargs(nargs, 4, redundancy ? "redundancy_values" : "branch_values") < 0) return NULL;
    long family = PyLong_AsLong(args[0]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer v[3];
    spec sp[3] = {{F64, -1, 0, "P"}, {F64, -1, 0, "q"}, {F64, -1, 1, "out"}};
    if (get_all(args + 1, v, sp, 3) < 0) return NULL;
    Py_ssize_t want = redundancy ? (family == OM_SRS ? 1 : 0) : 3;
    if (check_family(family, &v[0], v[1].len / 8) < 0 || v[2].len < want * 8) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "out is too short");
        release_all(v, 3);
        return NULL;
    }
    if (redundancy)
        om_redundancy_values((int)family, v[0].buf, v[1].buf, v[2].buf);
    else
        om_branch_values((int)family, v[0].buf, v[1].buf, v[2].buf);
    release_all(v, 3);
    Py_RETURN_NONE;
}

static PyObject *k_branch_values(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    return configuration_values(args, nargs, 0);
}

static PyObject *k_redundancy_values(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    return configuration_values(args, nargs, 1);
}

/* arm_angle_gradient(P, table, q, grad) -> psi (S-R-S). */
static PyObject *k_arm_angle_gradient(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 4, "arm_angle_gradient") < 0) return NULL;
    Py_buffer v[4];
    spec sp[4] = {{F64, SRS_N_PARAMS, 0, "P"}, {F64, -1, 0, "table"}, {F64, 7, 0, "q"}, {F64, 7, 1, "grad"}};
    if (get_all(args, v, sp, 4) < 0) return NULL;
    double psi = om_arm_angle_gradient(v[0].buf, v[1].buf, (int)table_rows(&v[1]), v[2].buf, v[3].buf);
    release_all(v, 4);
    return PyFloat_FromDouble(psi);
}

/* pose_is_valid(T, tolerance) -> bool: finite, last row [0 0 0 1], max|R^T R - I| <= tolerance, det > 0. */
static PyObject *k_pose_is_valid(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 2, "pose_is_valid") < 0) return NULL;
    double tol = PyFloat_AsDouble(args[1]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer v;
    if (get_buffer(args[0], &v, F64, 16, 0, "T") < 0) return NULL;
    const double *T = v.buf;
    int ok = 1;
    for (int i = 0; i < 16; i++) ok = ok && isfinite(T[i]);
    ok = ok && T[12] == 0.0 && T[13] == 0.0 && T[14] == 0.0 && T[15] == 1.0;
    for (int i = 0; i < 3 && ok; i++)
        for (int j = 0; j < 3; j++) {
            double dot = T[i] * T[j] + T[4 + i] * T[4 + j] + T[8 + i] * T[8 + j];
            if (fabs(dot - (i == j ? 1.0 : 0.0)) > tol) ok = 0;
        }
    if (ok) {
        double det = T[0] * (T[5] * T[10] - T[6] * T[9]) - T[1] * (T[4] * T[10] - T[6] * T[8]) +
                     T[2] * (T[4] * T[9] - T[5] * T[8]);
        ok = det > 0.0;
    }
    PyBuffer_Release(&v);
    return PyBool_FromLong(ok);
}

/* all_finite(values) -> bool: no NaN or inf among any number of float64 (numpy's
 * isfinite(...).all() costs microseconds on a 7-vector). */
static PyObject *k_all_finite(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 1, "all_finite") < 0) return NULL;
    Py_buffer v;
    if (get_buffer(args[0], &v, F64, -1, 0, "values") < 0) return NULL;
    const double *x = v.buf;
    int ok = 1;
    for (Py_ssize_t i = 0; i < v.len / 8; i++) ok = ok && isfinite(x[i]);
    PyBuffer_Release(&v);
    return PyBool_FromLong(ok);
}

#define FAST(name, doc) {#name, (PyCFunction)(void (*)(void))k_##name, METH_FASTCALL, doc}

static PyMethodDef module_methods[] = {
    FAST(fk, "fk(table, base, tool, Q, out)"),
    FAST(jacobian, "jacobian(table, base, tool, q, J)"),
    FAST(flange, "flange(table, q, R, p)"),
    FAST(flange_target, "flange_target(T, T_base_root, T_tool_flange, R, p)"),
    FAST(model_ik, "model_ik(family, P, table, R, p, signs, redundancy, q_prev, q, all_joints) -> margin"),
    FAST(model_ik_at_reach, "model_ik_at_reach(P, R, p, signs, psi, q_prev, q) -> bool"),
    FAST(model_ik_lifted, "model_ik_lifted(P, R, p, signs, psi, q1, q7, phi4, q) -> residuals"),
    FAST(branch_values, "branch_values(family, P, q, out)"),
    FAST(redundancy_values, "redundancy_values(family, P, q, out)"),
    FAST(arm_angle_gradient, "arm_angle_gradient(P, table, q, grad) -> psi"),
    FAST(pose_is_valid, "pose_is_valid(T, tolerance) -> bool"),
    FAST(all_finite, "all_finite(values) -> bool"),
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "ckernels", "om_redundant's compiled core (see csrc/om_kernels.h).", -1, module_methods,
};

PyMODINIT_FUNC PyInit_ckernels(void) {
    if (PyType_Ready(&SolverType) < 0) return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m) return NULL;
    /* The parameter layouts, for the Python side to check its own against (tests). */
    static const struct {
        const char *name;
        int value;
    } constants[] = {
        {"MAX_ROOTS", OM_MAX_ROOTS}, {"MAX_DOF", OM_MAX_DOF},
        {"SD_A1", SD_A1}, {"SD_D1", SD_D1}, {"SD_SIGMA1", SD_SIGMA1}, {"SD_THETA1", SD_THETA1},
        {"SD_LATERAL", SD_LATERAL}, {"SD_A2", SD_A2}, {"SD_THETA2", SD_THETA2}, {"SD_ELL3", SD_ELL3},
        {"SD_BETA", SD_BETA}, {"SD_THETA3", SD_THETA3}, {"SD_SIGMA2", SD_SIGMA2}, {"SD_D3", SD_D3},
        {"SD_SIGMA4", SD_SIGMA4}, {"SD_SIGMA5", SD_SIGMA5}, {"SD_THETA4", SD_THETA4}, {"SD_THETA5", SD_THETA5},
        {"SD_THETA6", SD_THETA6}, {"SD_WRIST_CENTRE", SD_WRIST_CENTRE}, {"SD_E_ROT", SD_E_ROT},
        {"SD_WRIST_ROW", SD_WRIST_ROW}, {"SD_N_PARAMS", SD_N_PARAMS},
        {"SRS_SIGMA1", SRS_SIGMA1}, {"SRS_SIGMA2", SRS_SIGMA2}, {"SRS_SIGMA5", SRS_SIGMA5},
        {"SRS_SIN_BETA", SRS_SIN_BETA}, {"SRS_THETA", SRS_THETA}, {"SRS_SHOULDER", SRS_SHOULDER},
        {"SRS_WRIST", SRS_WRIST}, {"SRS_S3", SRS_S3}, {"SRS_U", SRS_U}, {"SRS_K0", SRS_K0}, {"SRS_K", SRS_K},
        {"SRS_PHI_STAR", SRS_PHI_STAR}, {"SRS_R_PRE", SRS_R_PRE}, {"SRS_X3", SRS_X3}, {"SRS_X4", SRS_X4},
        {"SRS_E_ROT", SRS_E_ROT}, {"SRS_UP", SRS_UP}, {"SRS_REF", SRS_REF}, {"SRS_BEND", SRS_BEND},
        {"SRS_COS_BETA", SRS_COS_BETA}, {"SRS_N_PARAMS", SRS_N_PARAMS},
        {"RRR_SPHERICAL_WRIST", OM_RRR_SPHERICAL_WRIST}, {"RRP_SPHERICAL_WRIST", OM_RRP_SPHERICAL_WRIST},
        {"SRS", OM_SRS}, {"FIXED", OM_FIXED}, {"CIRCLE", OM_CIRCLE}, {"TORUS", OM_TORUS}, {"OK", OM_OK},
        {"UNREACHABLE", OM_UNREACHABLE}, {"NO_SOLUTION_IN_CONFIGURATION", OM_NO_SOLUTION_IN_CONFIGURATION},
    };
    if (PyModule_AddObjectRef(m, "Solver", (PyObject *)&SolverType) < 0) goto fail;
    for (size_t i = 0; i < sizeof constants / sizeof constants[0]; i++)
        if (PyModule_AddIntConstant(m, constants[i].name, constants[i].value) < 0) goto fail;
    PyObject *slack = PyFloat_FromDouble(OM_REACH_SLACK);
    if (!slack || PyModule_AddObject(m, "REACH_SLACK", slack) < 0) {
        Py_XDECREF(slack);
        goto fail;
    }
    return m;
fail:
    Py_DECREF(m);
    return NULL;
}
