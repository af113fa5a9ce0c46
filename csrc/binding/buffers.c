/* Buffers and sequences from Python, checked: the binding's only way to read arguments. */
#include <string.h>

#include "binding.h"

/* ------------------------------------------------------------------------------------ */
/* Buffers.                                                                               */


/* Acquire obj's buffer as n items of the given kind, C-contiguous (writable if asked). */
int get_buffer(PyObject *obj, Py_buffer *view, int kind, Py_ssize_t n, int writable, const char *name) {
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

int check_nargs(Py_ssize_t nargs, Py_ssize_t want, const char *what) {
    if (nargs != want) {
        PyErr_Format(PyExc_TypeError, "%s takes %zd arguments, got %zd", what, want, nargs);
        return -1;
    }
    return 0;
}

int bind_args(PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames, const arg_spec *spec, PyObject **out) {
    if (nargs > spec->positional) {
        PyErr_Format(PyExc_TypeError, "%s takes at most %d positional arguments, got %zd", spec->function,
                     spec->positional, nargs);
        return -1;
    }
    for (int i = 0; i < spec->n; i++) out[i] = i < nargs ? args[i] : NULL;
    Py_ssize_t nkw = kwnames ? PyTuple_GET_SIZE(kwnames) : 0;
    for (Py_ssize_t k = 0; k < nkw; k++) {
        const char *key = PyUnicode_AsUTF8(PyTuple_GET_ITEM(kwnames, k));
        if (!key) return -1;
        int i = 0;
        while (i < spec->n && strcmp(key, spec->names[i]) != 0) i++;
        if (i == spec->n) {
            PyErr_Format(PyExc_TypeError, "%s got an unknown argument '%s'", spec->function, key);
            return -1;
        }
        if (out[i]) {
            PyErr_Format(PyExc_TypeError, "%s got argument '%s' twice", spec->function, key);
            return -1;
        }
        out[i] = args[nargs + k];
    }
    for (int i = 0; i < spec->n; i++)
        if (!out[i]) {
            PyErr_Format(PyExc_TypeError, "%s missing argument '%s'", spec->function, spec->names[i]);
            return -1;
        }
    return 0;
}

/* Where a record type (a NamedTuple's: a tuple with _fields) keeps the fields names[0:n]: their
 * indices in its _fields, resolved by name once per type and names array. Its records are then
 * read at those indices, by name as getattr reads them and without its cost (a string made and
 * looked up per field: most of a small kernel's call). The types are kept (a reference each):
 * the records' few types are the module's classes, alive anyway. */
enum { FIELD_TYPES = 64, MAX_INDEXED_FIELDS = 16 };
typedef struct {
    PyTypeObject *type;
    const char *const *names;
    int n;
    Py_ssize_t index[MAX_INDEXED_FIELDS];
} field_indices;
static field_indices indexed[FIELD_TYPES];
static int n_indexed;

/* The index of the field `name` in the tuple fields, or -1. */
static Py_ssize_t field_index(PyObject *fields, const char *name) {
    for (Py_ssize_t k = 0; k < PyTuple_GET_SIZE(fields); k++) {
        PyObject *field = PyTuple_GET_ITEM(fields, k);
        if (PyUnicode_Check(field) && PyUnicode_CompareWithASCIIString(field, name) == 0) return k;
    }
    return -1;
}

/* The indices of names[0:n] in record's type, or NULL where they cannot be had (not a tuple with
 * those _fields, whose getattr gives the tuple's items): then getattr reads them. */
static const field_indices *indices_of(PyObject *record, const char *const *names, int n) {
    PyTypeObject *type = Py_TYPE(record);
    if (!PyTuple_Check(record) || n > MAX_INDEXED_FIELDS) return NULL;
    for (int i = 0; i < n_indexed; i++)
        if (indexed[i].type == type && indexed[i].names == names && indexed[i].n == n) return &indexed[i];
    if (n_indexed == FIELD_TYPES) return NULL;
    PyObject *fields = PyObject_GetAttrString((PyObject *)type, "_fields");
    if (!fields || !PyTuple_Check(fields)) {
        PyErr_Clear();
        Py_XDECREF(fields);
        return NULL;
    }
    field_indices *entry = &indexed[n_indexed];
    bool found = true;
    for (int i = 0; i < n && found; i++) { /* (and getattr reads that item: no property overrides it) */
        Py_ssize_t k = entry->index[i] = field_index(fields, names[i]);
        PyObject *item = k >= 0 && k < PyTuple_GET_SIZE(record) ? PyObject_GetAttrString(record, names[i]) : NULL;
        found = item != NULL && item == PyTuple_GET_ITEM(record, k);
        Py_XDECREF(item);
    }
    Py_DECREF(fields);
    PyErr_Clear();
    if (!found) return NULL;
    entry->type = (PyTypeObject *)Py_NewRef(type), entry->names = names, entry->n = n;
    n_indexed++;
    return entry;
}

int get_fields(PyObject *record, const char *const *names, int n, PyObject **out, const char *what) {
    const field_indices *at = indices_of(record, names, n);
    for (int i = 0; i < n; i++) {
        if (at && at->index[i] < PyTuple_GET_SIZE(record)) {
            out[i] = Py_NewRef(PyTuple_GET_ITEM(record, at->index[i]));
            continue;
        }
        out[i] = PyObject_GetAttrString(record, names[i]);
        if (!out[i]) {
            PyErr_Clear();
            PyErr_Format(PyExc_TypeError, "%s must have a field '%s'", what, names[i]);
            release_fields(out, i);
            return -1;
        }
    }
    return 0;
}

PyObject *new_record(PyTypeObject *type, PyObject **items, int n) {
    PyObject *record = PyStructSequence_New(type);
    for (int i = 0; i < n; i++)
        if (!items[i]) Py_CLEAR(record);
    if (!record) {
        release_fields(items, n);
        return NULL;
    }
    for (int i = 0; i < n; i++) PyStructSequence_SET_ITEM(record, i, items[i]);
    return record;
}

int add_int_constants(PyObject *module, const int_constant *constants, size_t n) {
    for (size_t i = 0; i < n; i++)
        if (PyModule_AddIntConstant(module, constants[i].name, constants[i].value) < 0) return -1;
    return 0;
}

int add_record_type(PyObject *module, PyTypeObject **type, PyStructSequence_Desc *desc, const char *name) {
    if (!*type && !(*type = PyStructSequence_NewType(desc))) return -1;
    return PyModule_AddObjectRef(module, name, (PyObject *)*type);
}

void release_fields(PyObject **out, int n) {
    for (int i = 0; i < n; i++) Py_CLEAR(out[i]);
}

int get_dof(PyObject *obj, Py_ssize_t *dof, const char *what) {
    *dof = PyLong_AsSsize_t(obj);
    if (*dof == -1 && PyErr_Occurred()) return -1;
    if (*dof < 1 || *dof > OM_MAX_DOF) {
        PyErr_Format(PyExc_ValueError, "%s: dof must be 1 ... %d, got %zd", what, OM_MAX_DOF, *dof);
        return -1;
    }
    return 0;
}

int get_buffers(PyObject *const *objs, Py_buffer *views, const buffer_spec *specs, int n) {
    for (int i = 0; i < n; i++) {
        if (get_buffer(objs[i], &views[i], specs[i].kind, specs[i].n, specs[i].writable, specs[i].name) < 0) {
            release_buffers(views, i);
            return -1;
        }
    }
    return 0;
}

void release_buffers(Py_buffer *views, int n) {
    for (int i = 0; i < n; i++) PyBuffer_Release(&views[i]);
}

int copy_signs(const int64_t *signs, Py_ssize_t n, int64_t *out) {
    for (Py_ssize_t i = 0; i < n; i++) {
        if (signs[i] != 1 && signs[i] != -1) {
            PyErr_SetString(PyExc_ValueError, "signs must be -1 or +1");
            return -1;
        }
        out[i] = signs[i];
    }
    return 0;
}

int copy_pose_and_signs(const Py_buffer *pose, const Py_buffer *signs, int k, double *T, int64_t *out) {
    memcpy(T, pose->buf, 16 * sizeof(double));
    return copy_signs(signs->buf, k, out);
}

Py_ssize_t table_joints(const Py_buffer *table) {
    const double *t = table->buf;
    Py_ssize_t joints = 0;
    for (Py_ssize_t i = 0; i < table->len / 48; i++) joints += t[OM_DH_COLUMNS * i + OM_DH_KIND] != OM_JOINT_FIXED;
    return joints;
}

bool indices_within(const int64_t *index, Py_ssize_t n, Py_ssize_t stride, int64_t lo, int64_t hi) {
    for (Py_ssize_t k = 0; k < n; k++)
        if (index[k * stride] < lo || index[k * stride] >= hi) return false;
    return true;
}

PyObject *get_tuple(PyObject *obj, Py_ssize_t k, const char *name) {
    PyObject *seq = PySequence_Check(obj) ? PySequence_Tuple(obj) : NULL;
    if (!seq) {
        if (!PyErr_Occurred() || PyErr_ExceptionMatches(PyExc_TypeError)) {
            PyErr_Clear();
            PyErr_Format(PyExc_TypeError, "%s must be a sequence", name);
        }
        return NULL;
    }
    if (k >= 0 && PyTuple_GET_SIZE(seq) != k) {
        PyErr_Format(PyExc_ValueError, "%s must have %zd entries, got %zd", name, k, PyTuple_GET_SIZE(seq));
        Py_DECREF(seq);
        return NULL;
    }
    return seq;
}

/* Parse a sequence of k signs into out. */
int get_signs(PyObject *obj, int64_t *out, int k) {
    PyObject *seq = get_tuple(obj, k, "signs");
    if (!seq) return -1;
    for (int i = 0; i < k; i++) {
        long long v = PyLong_AsLongLong(PyTuple_GET_ITEM(seq, i));
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

int get_doubles(PyObject *obj, double *out, int k, const char *name) {
    PyObject *seq = get_tuple(obj, k, name);
    if (!seq) return -1;
    for (int i = 0; i < k; i++) {
        out[i] = PyFloat_AsDouble(PyTuple_GET_ITEM(seq, i));
        if (out[i] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(seq);
            return -1;
        }
    }
    Py_DECREF(seq);
    return 0;
}
