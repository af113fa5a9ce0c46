/* The closed forms' binding: the model arms' IK (6-DOF families and S-R-S, at the edge of reach,
 * q7 alone, lifted), their branch and redundancy values and the arm angle's gradient. */
#include "binding.h"

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
        mat3 R = m_load(v[4].buf, 0);
        om_target t = om_target_at((int)family, v[0].buf, &R, v[7].buf);
        double margin = om_model_ik((int)family, v[0].buf, v[1].buf, &t, v_load(v[5].buf, 0), v[6].buf, v[2].buf,
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
    mat3 R = m_load(v[1].buf, 0);
    om_target t = om_target_at(OM_SRS, v[0].buf, &R, v[4].buf);
    vec3 p = v_load(v[2].buf, 0);
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
static PyStructSequence_Field lifted_terms_fields[] = {
    {"shoulder", "the shoulder's residual's terms in 1, cos psi and sin psi"},
    {"wrist", "the wrist's residual's terms in 1, cos psi and sin psi"},
    {"elbow", "the elbow equation's residual, x - cos(phi4 - phi*)"},
    {"phi4", "the elbow's root"},
    {NULL, NULL},
};
static PyStructSequence_Desc lifted_terms_desc = {"om_redundant.ckernels.LiftedTerms",
                                                  "model_lifted_terms' terms (om_srs_lifted_terms).",
                                                  lifted_terms_fields, 4};
static PyTypeObject *lifted_terms_type;

int om_closed_forms_init(PyObject *module) {
    if (add_record_type(module, &lifted_type, &lifted_desc, "Lifted") < 0) return -1;
    return add_record_type(module, &lifted_terms_type, &lifted_terms_desc, "LiftedTerms");
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
    mat3 R = m_load(v[1].buf, 0);
    om_target t = om_target_at(OM_SRS, v[0].buf, &R, v[4].buf);
    vec3 r = om_srs_model_ik_lifted(v[0].buf, &t, v_load(v[2].buf, 0), v[3].buf, q1, q7, phi4, v[5].buf);
    release_buffers(v, 6);
    PyObject *items[3] = {PyFloat_FromDouble(r.x), PyFloat_FromDouble(r.y), PyFloat_FromDouble(r.z)};
    return new_record(lifted_type, items, 3);
}

/* model_lifted_terms(P, target, q1, q7) -> LiftedTerms or None (W = S): model_ik_lifted's residuals
 * with phi4 the elbow's root, in terms of the arm angle (target: a FlangeTarget, its psi not read). */
static PyObject *k_model_lifted_terms(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 4, "model_lifted_terms") < 0) return NULL;
    double q1 = PyFloat_AsDouble(args[2]), q7 = PyFloat_AsDouble(args[3]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer v[5]; /* P, the target's R, p, signs, psi */
    if (get_srs_call(args[0], args[1], NULL, 0, NULL, v, "model_lifted_terms") < 0) return NULL;
    mat3 R = m_load(v[1].buf, 0);
    om_target t = om_target_at(OM_SRS, v[0].buf, &R, v[4].buf);
    om_srs_lifted_terms k;
    bool ok = om_srs_lifted_terms_at(v[0].buf, &t, v_load(v[2].buf, 0), (double)((int64_t *)v[3].buf)[1], q1, q7, NAN, &k);
    release_buffers(v, 5);
    if (!ok) Py_RETURN_NONE;
    PyObject *items[4] = {Py_BuildValue("(ddd)", k.shoulder[0], k.shoulder[1], k.shoulder[2]),
                          Py_BuildValue("(ddd)", k.wrist[0], k.wrist[1], k.wrist[2]), PyFloat_FromDouble(k.elbow),
                          PyFloat_FromDouble(k.phi4)};
    return new_record(lifted_terms_type, items, 4);
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

#define FAST(name, doc) {#name, (PyCFunction)(void (*)(void))k_##name, METH_FASTCALL, doc}

PyMethodDef om_closed_form_functions[] = {
    FAST(model_ik, "model_ik(model, target, q_prev, q, all_joints) -> margin (a FamilyModel, a FlangeTarget)"),
    FAST(model_ik_at_reach, "model_ik_at_reach(P, target, q_prev, q) -> bool (target: a FlangeTarget)"),
    FAST(srs_model_q7, "srs_model_q7(P, target, q_prev, q) -> margin (target: a FlangeTarget)"),
    FAST(model_ik_lifted, "model_ik_lifted(P, target, q1, q7, phi4, q) -> Lifted (target: a FlangeTarget)"),
    FAST(model_lifted_terms, "model_lifted_terms(P, target, q1, q7) -> LiftedTerms or None (target: a FlangeTarget)"),
    FAST(branch_values, "branch_values(family, P, q, out)"),
    FAST(redundancy_values, "redundancy_values(family, P, q, out)"),
    FAST(arm_angle_gradient, "arm_angle_gradient(P, table, q, grad) -> psi"),
    {NULL, NULL, 0, NULL},
};
