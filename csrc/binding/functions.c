/* Module functions on arrays: kinematics (fk, the Jacobian, the flange and a target's flange
 * pose), the pose and finiteness checks, and the polish on the exact chain (the closed forms'
 * are closed_forms.c's). */
#include "binding.h"

/* fk(table, base, tool, Q, out): out[m] = base @ A(Q[m]) @ tool; Q (M, dof), out (M, 4, 4). */
static PyObject *k_fk(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 5, "fk") < 0) return NULL;
    Py_buffer v[5];
    buffer_spec sp[5] = {{F64, -1, 0, "table"}, {F64, 16, 0, "base"}, {F64, 16, 0, "tool"}, {F64, -1, 0, "Q"},
                         {F64, -1, 1, "out"}};
    if (get_buffers(args, v, sp, 5) < 0) return NULL;
    Py_ssize_t rows = table_rows(&v[0]), dof = table_joints(&v[0]);
    const double *t = v[0].buf;
    Py_ssize_t m = dof ? v[3].len / (8 * dof) : v[4].len / 128; /* no joints: one pose per out */
    if (v[0].len != rows * 48 || v[3].len != m * dof * 8 || v[4].len != m * 128) {
        release_buffers(v, 5);
        PyErr_SetString(PyExc_ValueError, "fk: shapes of table, Q and out disagree");
        return NULL;
    }
    Py_BEGIN_ALLOW_THREADS for (Py_ssize_t i = 0; i < m; i++) om_fk(t, (int)rows, v[1].buf, v[2].buf,
                                                                       (const double *)v[3].buf + dof * i,
                                                                       (double *)v[4].buf + 16 * i);
    Py_END_ALLOW_THREADS release_buffers(v, 5);
    Py_RETURN_NONE;
}

/* jacobian(table, base, tool, q, J): J (6, dof). */
static PyObject *k_jacobian(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 5, "jacobian") < 0) return NULL;
    Py_buffer v[5];
    buffer_spec sp[5] = {{F64, -1, 0, "table"}, {F64, 16, 0, "base"}, {F64, 16, 0, "tool"}, {F64, -1, 0, "q"},
                         {F64, -1, 1, "J"}};
    if (get_buffers(args, v, sp, 5) < 0) return NULL;
    Py_ssize_t rows = table_rows(&v[0]), dof = v[3].len / 8;
    if (v[0].len != rows * 48 || dof > OM_MAX_DOF || table_joints(&v[0]) != dof || v[4].len != 6 * dof * 8) {
        release_buffers(v, 5);
        PyErr_SetString(PyExc_ValueError, "jacobian: shapes of the table, q and J disagree");
        return NULL;
    }
    om_jacobian(v[0].buf, (int)rows, v[1].buf, v[2].buf, v[3].buf, (int)dof, v[4].buf, NULL, NULL);
    release_buffers(v, 5);
    Py_RETURN_NONE;
}

/* flange(table, q, R, p): the last DH frame's pose in DH frame 0. */
static PyObject *k_flange(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 4, "flange") < 0) return NULL;
    Py_buffer v[4];
    buffer_spec sp[4] = {{F64, -1, 0, "table"}, {F64, -1, 0, "q"}, {F64, 9, 1, "R"}, {F64, 3, 1, "p"}};
    if (get_buffers(args, v, sp, 4) < 0) return NULL;
    if (v[0].len != table_rows(&v[0]) * 48 || table_joints(&v[0]) != v[1].len / 8) {
        release_buffers(v, 4);
        PyErr_SetString(PyExc_ValueError, "flange: shapes of the table and q disagree");
        return NULL;
    }
    om_flange(v[0].buf, (int)table_rows(&v[0]), v[1].buf, v[2].buf, v[3].buf);
    release_buffers(v, 4);
    Py_RETURN_NONE;
}

/* flange_target(T, T_base_root, T_tool_flange, R, p): the flange pose in DH frame 0. */
static PyObject *k_flange_target(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 5, "flange_target") < 0) return NULL;
    Py_buffer v[5];
    buffer_spec sp[5] = {{F64, 16, 0, "T"}, {F64, 16, 0, "T_base_root"}, {F64, 16, 0, "T_tool_flange"},
                         {F64, 9, 1, "R"}, {F64, 3, 1, "p"}};
    if (get_buffers(args, v, sp, 5) < 0) return NULL;
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
    release_buffers(v, 5);
    Py_RETURN_NONE;
}

/* Whether T is a homogeneous transform: finite, last row [0 0 0 1], max|R^T R - I| <= tol, det > 0. */
int om_pose_is_valid(const double *T, double tol) {
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
    return ok;
}

/* pose_is_valid(T, tolerance) -> bool: om_pose_is_valid of a pose (4, 4), or of every pose
 * of a stack (M, 4, 4) (a batch's check costs a few microseconds, numpy's half a millisecond
 * per thousand poses). */
static PyObject *k_pose_is_valid(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 2, "pose_is_valid") < 0) return NULL;
    double tol = PyFloat_AsDouble(args[1]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer v;
    if (get_buffer(args[0], &v, F64, -1, 0, "T") < 0) return NULL;
    Py_ssize_t m = v.len / (16 * 8);
    if (m == 0 || v.len != m * 16 * 8) {
        PyBuffer_Release(&v);
        PyErr_SetString(PyExc_ValueError, "T must be (4, 4) or (M, 4, 4) with M > 0");
        return NULL;
    }
    const double *T = v.buf;
    int ok = 1;
    for (Py_ssize_t i = 0; i < m && ok; i++) ok = om_pose_is_valid(T + 16 * i, tol);
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

/* The most Gauss-Newton steps a polish call takes (each a few microseconds, the GIL released). */
#define MAX_POLISH_ITERATIONS 10000

/* The fields of a polish's arm-angle row (om_redundant._core.ArmAngleRow) it reads. */
enum { AR_PARAMS, AR_TABLE, AR_PSI, AR_N };
static const char *const arm_angle_names[AR_N] = {"params", "model_table", "psi"};

/* polish(table, R, p, q, iterations, arm_angle) -> residual: om_polish of q in place toward
 * the flange pose (R (9), p (3)) in DH frame 0 of the chain `table`; arm_angle None: no
 * arm-angle row, else an ArmAngleRow: an S-R-S model's params and model_table, and the
 * target psi. */
static PyObject *k_polish(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 6, "polish") < 0) return NULL;
    long iterations = PyLong_AsLong(args[4]);
    if (PyErr_Occurred()) return NULL;
    if (iterations < 0 || iterations > MAX_POLISH_ITERATIONS) {
        PyErr_Format(PyExc_ValueError, "polish: iterations must be 0 ... %d", MAX_POLISH_ITERATIONS);
        return NULL;
    }
    int with_psi = args[5] != Py_None;
    PyObject *w[AR_N] = {NULL, NULL, NULL};
    if (with_psi && get_fields(args[5], arm_angle_names, AR_N, w, "polish's arm_angle") < 0) return NULL;
    double psi = with_psi ? PyFloat_AsDouble(w[AR_PSI]) : 0.0;
    PyObject *result = NULL;
    if (PyErr_Occurred()) goto done;
    PyObject *const a[6] = {args[0], args[1], args[2], args[3], w[AR_PARAMS], w[AR_TABLE]};
    Py_buffer v[6];
    buffer_spec sp[6] = {{F64, -1, 0, "table"}, {F64, 9, 0, "R"}, {F64, 3, 0, "p"}, {F64, -1, 1, "q"},
                         {F64, SRS_N_PARAMS, 0, "params"}, {F64, -1, 0, "model_table"}};
    if (get_buffers(a, v, sp, with_psi ? 6 : 4) < 0) goto done;
    om_polish_task t;
    t.table = v[0].buf;
    t.n_rows = (int)table_rows(&v[0]);
    t.dof = (int)(v[3].len / 8);
    if (v[0].len != t.n_rows * 48 || table_joints(&v[0]) != t.dof || t.dof > OM_MAX_DOF || (with_psi && t.dof != 7) ||
        (with_psi && check_family(OM_SRS, &v[4], 7, &v[5]) < 0)) {
        release_buffers(v, with_psi ? 6 : 4);
        PyErr_SetString(PyExc_ValueError, "polish: table, q (and a 7-joint arm for psi) disagree");
        goto done;
    }
    t.P = with_psi ? v[4].buf : NULL;
    t.model_table = with_psi ? v[5].buf : NULL;
    t.n_model_rows = with_psi ? (int)table_rows(&v[5]) : 0;
    t.R = m_load(v[1].buf, 0);
    t.p = v_load(v[2].buf, 0);
    t.psi = psi;
    t.elbow = 0.0;
    t.give_up_crawl = false;
    double r;
    Py_BEGIN_ALLOW_THREADS r = om_polish(&t, (int)iterations, v[3].buf);
    Py_END_ALLOW_THREADS release_buffers(v, with_psi ? 6 : 4);
    result = PyFloat_FromDouble(r);
done:
    release_fields(w, with_psi ? AR_N : 0);
    return result;
}

#define FAST(name, doc) {#name, (PyCFunction)(void (*)(void))k_##name, METH_FASTCALL, doc}

PyMethodDef om_kernel_functions[] = {
    FAST(fk, "fk(table, base, tool, Q, out)"),
    FAST(jacobian, "jacobian(table, base, tool, q, J)"),
    FAST(flange, "flange(table, q, R, p)"),
    FAST(flange_target, "flange_target(T, T_base_root, T_tool_flange, R, p)"),
    FAST(pose_is_valid, "pose_is_valid(T, tolerance) -> bool"),
    FAST(all_finite, "all_finite(values) -> bool"),
    FAST(polish, "polish(table, R, p, q, iterations, arm_angle) -> residual (arm_angle: None or an ArmAngleRow)"),
    {NULL, NULL, 0, NULL},
};
