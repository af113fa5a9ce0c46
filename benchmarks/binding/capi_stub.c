#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <string.h>
#include <math.h>
/* The binding work of Solver.solve_pose (csrc/binding/solve_pose.c) around a stub solve. */
static PyObject *solution_type, *configuration_type, *fields[8], *empty, *status_ok;
static int read_configuration(PyObject *c, long *signs, double *red) {
    if (!PyObject_TypeCheck(c, (PyTypeObject *)configuration_type)) return 0;
    static PyObject *sn, *rn;
    if (!sn) sn = PyUnicode_InternFromString("signs"), rn = PyUnicode_InternFromString("redundancy");
    PyObject *sg = PyObject_GetAttr(c, sn), *rd = sg ? PyObject_GetAttr(c, rn) : NULL;
    int ok = rd && PyTuple_Check(sg) && PyTuple_GET_SIZE(sg) == 3 && PyTuple_Check(rd) && PyTuple_GET_SIZE(rd) == 1;
    for (int i = 0; ok && i < 3; i++) { signs[i] = PyLong_AsLong(PyTuple_GET_ITEM(sg, i)); ok = signs[i] == 1 || signs[i] == -1; }
    for (int i = 0; ok && i < 1; i++) { red[i] = PyFloat_AsDouble(PyTuple_GET_ITEM(rd, i)); ok = isfinite(red[i]); }
    Py_XDECREF(sg); Py_XDECREF(rd); PyErr_Clear();
    return ok;
}
static int read_pose(PyObject *T, double *pose) {
    Py_buffer v;
    if (PyObject_GetBuffer(T, &v, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) { PyErr_Clear(); return 0; }
    const char *f = v.format ? v.format : "B";
    if (*f == '<' || *f == '=' || *f == '@') f++;
    int ok = v.ndim == 2 && v.shape[0] == 4 && v.shape[1] == 4 && v.itemsize == 8 && f[0] == 'd' && f[1] == 0;
    if (ok) memcpy(pose, v.buf, 128);
    PyBuffer_Release(&v);
    return ok;
}
static PyObject *new_vector(const double *q) {
    PyObject *dof = PyLong_FromLong(7), *vec = PyObject_CallOneArg(empty, dof);
    Py_DECREF(dof);
    Py_buffer v;
    if (!vec || PyObject_GetBuffer(vec, &v, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) { Py_XDECREF(vec); return NULL; }
    memcpy(v.buf, q, 56);
    PyBuffer_Release(&v);
    return vec;
}
static PyObject *solve_pose(PyObject *m, PyObject *const *args, Py_ssize_t nargs) {
    long signs[3]; double red[1], T[16], q[7];
    if (nargs != 2 || !read_configuration(args[1], signs, red) || !read_pose(args[0], T)) Py_RETURN_NONE;
    Py_BEGIN_ALLOW_THREADS for (int i = 0; i < 7; i++) q[i] = T[i] * signs[i % 3] + red[0];
    Py_END_ALLOW_THREADS
    PyObject *values[8] = {new_vector(q), PyBool_FromLong(1), Py_NewRef(status_ok), Py_NewRef(args[1]),
                           PyFloat_FromDouble(0.0), PyFloat_FromDouble(0.0), PyLong_FromLong(3), PyBool_FromLong(1)};
    PyTypeObject *type = (PyTypeObject *)solution_type;
    PyObject *s = type->tp_alloc(type, 0);
    for (int i = 0; s && i < 8; i++) if (Py_TYPE(fields[i])->tp_descr_set(fields[i], s, values[i]) < 0) Py_CLEAR(s);
    for (int i = 0; i < 8; i++) Py_XDECREF(values[i]);
    return s;
}
static PyObject *set_types(PyObject *m, PyObject *const *args, Py_ssize_t nargs) {
    solution_type = Py_NewRef(args[0]); configuration_type = Py_NewRef(args[1]);
    const char *names[8] = {"q", "ok", "status", "configuration", "position_error", "orientation_error", "iterations", "within_limits"};
    for (int i = 0; i < 8; i++) fields[i] = PyObject_GetAttrString(solution_type, names[i]);
    PyObject *np = PyImport_ImportModule("numpy"); empty = PyObject_GetAttrString(np, "empty"); Py_DECREF(np);
    status_ok = PyUnicode_FromString("ok");
    Py_RETURN_NONE;
}
static PyMethodDef methods[] = {{"solve_pose", (PyCFunction)(void (*)(void))solve_pose, METH_FASTCALL, ""},
                                {"set_types", (PyCFunction)(void (*)(void))set_types, METH_FASTCALL, ""}, {0}};
static struct PyModuleDef mod = {PyModuleDef_HEAD_INIT, "capi_stub", "", -1, methods};
PyMODINIT_FUNC PyInit_capi_stub(void) { return PyModule_Create(&mod); }
