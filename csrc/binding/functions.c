/* Module functions: kinematics and the families' closed forms, on arrays. */
#include "binding.h"

/* ------------------------------------------------------------------------------------ */
/* Module functions: kinematics and the families' closed forms.                           */

static Py_ssize_t table_rows(const Py_buffer *table) {
    return table->len / (6 * 8);
}

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

static mat3 load_mat(const double *R) {
    return m_load(R, 0);
}

static vec3 load_vec(const double *p) {
    return v_load(p, 0);
}

int check_family(long family, const Py_buffer *P, Py_ssize_t dof, const Py_buffer *table) {
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
    if (!table) return 0;
    /* the 6-DOF closed form applies the rows before the wrist's, P[SD_WRIST_ROW] of them */
    Py_ssize_t rows = table_rows(table);
    double wrist_row = family == OM_SRS ? 0.0 : ((const double *)P->buf)[SD_WRIST_ROW];
    if (table->len != rows * 48 || table_joints(table) != want_dof ||
        !(wrist_row >= 0.0 && wrist_row <= (double)rows && wrist_row == floor(wrist_row))) {
        PyErr_Format(PyExc_ValueError, "family %ld: the model table must hold %zd joints (and the wrist's row)",
                     family, want_dof);
        return -1;
    }
    return 0;
}

/* The fields of a model IK's target (om_redundant._core.FlangeTarget) it reads. */
enum { FT_R, FT_P, FT_SIGNS, FT_REDUNDANCY, FT_N };
static const char *const target_names[FT_N] = {"R", "p", "signs", "redundancy"};

/* A FlangeTarget's arrays into v[0:4] (R (9), p (3), signs (3) int64, redundancy: n_redundancy
 * entries, any if < 0), held until released (release_buffers(v, 4)); -1 with an error naming
 * what. */
static int get_target(PyObject *target, Py_ssize_t n_redundancy, Py_buffer *v, const char *what) {
    PyObject *w[FT_N];
    if (get_fields(target, target_names, FT_N, w, what) < 0) return -1;
    const buffer_spec sp[FT_N] = {{F64, 9, 0, "R"}, {F64, 3, 0, "p"}, {I64, 3, 0, "signs"},
                                  {F64, n_redundancy, 0, "redundancy"}};
    int rc = get_buffers(w, v, sp, FT_N);
    release_fields(w, FT_N); /* (the buffers hold their arrays) */
    return rc;
}

/* The fields of a closed-form model (om_redundant._core.FamilyModel) model_ik reads. */
enum { FM_FAMILY, FM_PARAMS, FM_TABLE, FM_N };
static const char *const model_names[FM_N] = {"family", "params", "table"};

/* model_ik(model, target, q_prev, q, all_joints) -> margin: the closed form of model (a
 * FamilyModel: family, params, table) for target (a FlangeTarget). */
static PyObject *k_model_ik(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    PyObject *w[FM_N];
    if (check_nargs(nargs, 5, "model_ik") < 0 || get_fields(args[0], model_names, FM_N, w, "model_ik's model") < 0)
        return NULL;
    PyObject *result = NULL;
    long family = PyLong_AsLong(w[FM_FAMILY]);
    int all_joints = PyErr_Occurred() ? -1 : PyObject_IsTrue(args[4]);
    if (all_joints < 0) goto done;
    Py_buffer v[8]; /* params, table, q_prev, q, then the target's R, p, signs, redundancy */
    PyObject *const arrays[4] = {w[FM_PARAMS], w[FM_TABLE], args[2], args[3]};
    const buffer_spec sp[4] = {{F64, -1, 0, "params"}, {F64, -1, 0, "table"}, {F64, -1, 0, "q_prev"}, {F64, -1, 1, "q"}};
    if (get_buffers(arrays, v, sp, 4) < 0) goto done;
    if (get_target(args[1], -1, v + 4, "model_ik's target") < 0) {
        release_buffers(v, 4);
        goto done;
    }
    if (check_family(family, &v[0], v[3].len / 8, &v[1]) < 0 || v[2].len != v[3].len ||
        v[7].len != (family == OM_SRS ? 8 : 0)) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "model_ik: shapes disagree");
    } else {
        mat3 R = load_mat(v[4].buf);
        om_target t = om_target_at((int)family, v[0].buf, &R, v[7].buf);
        double margin = om_model_ik((int)family, v[0].buf, v[1].buf, &t, load_vec(v[5].buf), v[6].buf, v[2].buf,
                                    v[3].buf, all_joints);
        result = PyFloat_FromDouble(margin);
    }
    release_buffers(v, 8);
done:
    release_fields(w, FM_N);
    return result;
}

/* An S-R-S call's parameters P (SRS_N_PARAMS), target (a FlangeTarget whose redundancy is
 * psi alone) and joint vectors joints[0:n] (7 each; the last written) into v[0], v[1:5],
 * v[5:5 + n]; -1 with an error (nothing held). */
static int get_srs_call(PyObject *P, PyObject *target, PyObject *const *joints, int n, const char *const *names,
                        Py_buffer *v, const char *what) {
    if (get_buffer(P, &v[0], F64, SRS_N_PARAMS, 0, "P") < 0) return -1;
    if (get_target(target, 1, v + 1, what) < 0) {
        release_buffers(v, 1);
        return -1;
    }
    buffer_spec sp[2];
    for (int i = 0; i < n; i++) sp[i] = (buffer_spec){F64, 7, i == n - 1, names[i]};
    if (get_buffers(joints, v + 5, sp, n) < 0) {
        release_buffers(v, 5);
        return -1;
    }
    return 0;
}

/* model_ik_at_reach(P, target, q_prev, q) -> bool and srs_model_q7(the same) -> margin: the
 * S-R-S closed form's variants (q7_alone: q7 alone, as the circle residual takes it), for
 * target (a FlangeTarget, its redundancy the arm angle psi). */
static PyObject *srs_variant(PyObject *const *args, Py_ssize_t nargs, int q7_alone) {
    const char *what = q7_alone ? "srs_model_q7" : "model_ik_at_reach";
    if (check_nargs(nargs, 4, what) < 0) return NULL;
    static const char *const names[2] = {"q_prev", "q"};
    Py_buffer v[7]; /* P, the target's R, p, signs, psi, then q_prev, q */
    if (get_srs_call(args[0], args[1], args + 2, 2, names, v, what) < 0) return NULL;
    mat3 R = load_mat(v[1].buf);
    om_target t = om_target_at(OM_SRS, v[0].buf, &R, v[4].buf);
    vec3 p = load_vec(v[2].buf);
    PyObject *out = q7_alone ? PyFloat_FromDouble(om_srs_model_q7(v[0].buf, &t, p, v[3].buf, v[5].buf, v[6].buf))
                             : PyBool_FromLong(om_srs_model_ik_at_reach(v[0].buf, &t, p, v[3].buf, v[5].buf, v[6].buf));
    release_buffers(v, 7);
    return out;
}

static PyObject *k_model_ik_at_reach(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    return srs_variant(args, nargs, 0);
}

static PyObject *k_srs_model_q7(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    return srs_variant(args, nargs, 1);
}

static PyStructSequence_Field lifted_fields[] = {
    {"shoulder", "the shoulder's consistency residual"},
    {"wrist", "the wrist's consistency residual"},
    {"elbow", "the elbow equation's residual, x - cos(phi4 - phi*)"},
    {NULL, NULL},
};
static PyStructSequence_Desc lifted_desc = {"om_redundant.ckernels.Lifted", "model_ik_lifted's residuals.",
                                            lifted_fields, 3};
static PyTypeObject *lifted_type;

int om_functions_init(PyObject *module) {
    if (!lifted_type && !(lifted_type = PyStructSequence_NewType(&lifted_desc))) return -1;
    return PyModule_AddObjectRef(module, "Lifted", (PyObject *)lifted_type);
}

/* model_ik_lifted(P, target, q1, q7, phi4, q) -> Lifted(shoulder, wrist, elbow): the residuals
 * of the S-R-S model IK with q1, q7 and phi4 given, for target (a FlangeTarget, its redundancy
 * the arm angle psi). */
static PyObject *k_model_ik_lifted(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 6, "model_ik_lifted") < 0) return NULL;
    double q1 = PyFloat_AsDouble(args[2]), q7 = PyFloat_AsDouble(args[3]), phi4 = PyFloat_AsDouble(args[4]);
    if (PyErr_Occurred()) return NULL;
    static const char *const names[1] = {"q"};
    Py_buffer v[6]; /* P, the target's R, p, signs, psi, then q */
    if (get_srs_call(args[0], args[1], args + 5, 1, names, v, "model_ik_lifted") < 0) return NULL;
    mat3 R = load_mat(v[1].buf);
    om_target t = om_target_at(OM_SRS, v[0].buf, &R, v[4].buf);
    vec3 r = om_srs_model_ik_lifted(v[0].buf, &t, load_vec(v[2].buf), v[3].buf, q1, q7, phi4, v[5].buf);
    release_buffers(v, 6);
    PyObject *items[3] = {PyFloat_FromDouble(r.x), PyFloat_FromDouble(r.y), PyFloat_FromDouble(r.z)};
    return new_record(lifted_type, items, 3);
}

/* branch_values(family, P, q, out) and redundancy_values(family, P, q, out). */
static PyObject *configuration_values(PyObject *const *args, Py_ssize_t nargs, int redundancy) {
    if (check_nargs(nargs, 4, redundancy ? "redundancy_values" : "branch_values") < 0) return NULL;
    long family = PyLong_AsLong(args[0]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer v[3];
    buffer_spec sp[3] = {{F64, -1, 0, "P"}, {F64, -1, 0, "q"}, {F64, -1, 1, "out"}};
    if (get_buffers(args + 1, v, sp, 3) < 0) return NULL;
    Py_ssize_t want = redundancy ? (family == OM_SRS ? 1 : 0) : 3;
    if (check_family(family, &v[0], v[1].len / 8, NULL) < 0 || v[2].len < want * 8) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "out is too short");
        release_buffers(v, 3);
        return NULL;
    }
    if (redundancy)
        om_redundancy_values((int)family, v[0].buf, v[1].buf, v[2].buf);
    else
        om_branch_values((int)family, v[0].buf, v[1].buf, v[2].buf);
    release_buffers(v, 3);
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
    buffer_spec sp[4] = {{F64, SRS_N_PARAMS, 0, "P"}, {F64, -1, 0, "table"}, {F64, 7, 0, "q"}, {F64, 7, 1, "grad"}};
    if (get_buffers(args, v, sp, 4) < 0) return NULL;
    if (check_family(OM_SRS, &v[0], 7, &v[1]) < 0) {
        release_buffers(v, 4);
        return NULL;
    }
    double psi = om_arm_angle_gradient(v[0].buf, v[1].buf, (int)table_rows(&v[1]), v[2].buf, v[3].buf);
    release_buffers(v, 4);
    return PyFloat_FromDouble(psi);
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
    t.R = load_mat(v[1].buf);
    t.p = load_vec(v[2].buf);
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
    FAST(model_ik, "model_ik(model, target, q_prev, q, all_joints) -> margin (a FamilyModel, a FlangeTarget)"),
    FAST(model_ik_at_reach, "model_ik_at_reach(P, target, q_prev, q) -> bool (target: a FlangeTarget)"),
    FAST(srs_model_q7, "srs_model_q7(P, target, q_prev, q) -> margin (target: a FlangeTarget)"),
    FAST(model_ik_lifted, "model_ik_lifted(P, target, q1, q7, phi4, q) -> Lifted (target: a FlangeTarget)"),
    FAST(branch_values, "branch_values(family, P, q, out)"),
    FAST(redundancy_values, "redundancy_values(family, P, q, out)"),
    FAST(arm_angle_gradient, "arm_angle_gradient(P, table, q, grad) -> psi"),
    FAST(pose_is_valid, "pose_is_valid(T, tolerance) -> bool"),
    FAST(all_finite, "all_finite(values) -> bool"),
    FAST(polish, "polish(table, R, p, q, iterations, arm_angle) -> residual (arm_angle: None or an ArmAngleRow)"),
    {NULL, NULL, 0, NULL},
};
