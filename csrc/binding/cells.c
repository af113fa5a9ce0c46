/* The binding of the cell test of the global choose's solution paths (csrc/redundancy/cells.c): pieces,
 * surprise, crossing, joint_step and cell_looks. Their records (om_redundant._core's
 * PieceRows, PieceLimits, CellModels, CellSamples) are read by name. */
#include <string.h>

#include "binding.h"

/* The fields of pieces' rows (om_redundant._core.PieceRows) and limits (PieceLimits). */
enum { PR_Q, PR_T, PR_DISTANCES, PR_GRADIENTS, PR_N };
static const char *const piece_row_names[PR_N] = {"q", "t", "distances", "gradients"};
enum { PL_LIMITED, PL_LOWER, PL_UPPER, PL_HALF, PL_N };
static const char *const piece_limit_names[PL_N] = {"limited", "lower", "upper", "half"};

/* pieces(dof, rows, limits, numbers, g, dg) -> None: objective.py's Group.constraints of the
 * margin and clearance groups at each of the M rows (PieceRows: q (M x dof) with dq/dpsi = t
 * (M x dof), the pairs' distances (M x P) and gradients (M x P x dof)), into g and dg (M x (L
 * + P)): per limited joint (PieceLimits: the L joints' indices, lower and upper limits and
 * half ranges) the smaller of (q_i - l_i)/h_i and (u_i - q_i)/h_i with its rate; then per pair
 * d_k/d_cap - d_min/d_cap with its rate grad d_k . t / d_cap, a pair at 2 d_cap or more taken
 * as 2 d_cap with rate 0 when some pair of the row is nearer (objective.py's _clearance);
 * numbers: 2 d_cap, d_cap, d_min / d_cap. */
static PyObject *om_pieces_binding(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"dof", "rows", "limits", "numbers", "g", "dg"};
    static const arg_spec spec = {"pieces", names, 6, 6};
    PyObject *a[6], *f[PR_N + PL_N + 3];
    Py_ssize_t dof;
    if (bind_args(args, nargs, kwnames, &spec, a) < 0 || get_dof(a[0], &dof, "pieces") < 0) return NULL;
    if (get_fields(a[1], piece_row_names, PR_N, f, "pieces' rows") < 0) return NULL;
    if (get_fields(a[2], piece_limit_names, PL_N, f + PR_N, "pieces' limits") < 0) {
        release_fields(f, PR_N);
        return NULL;
    }
    for (int i = 0; i < 3; i++) f[PR_N + PL_N + i] = Py_NewRef(a[3 + i]); /* numbers, g, dg */
    Py_buffer v[11];
    const buffer_spec sp[11] = {{F64, -1, 0, "q"},     {F64, -1, 0, "t"},      {F64, -1, 0, "distances"},
                                {F64, -1, 0, "gradients"}, {I64, -1, 0, "limited"}, {F64, -1, 0, "lower"},
                                {F64, -1, 0, "upper"}, {F64, -1, 0, "half"},   {F64, 3, 0, "numbers"},
                                {F64, -1, 1, "g"},     {F64, -1, 1, "dg"}};
    PyObject *result = NULL;
    if (get_buffers(f, v, sp, 11) < 0) goto done;
    Py_ssize_t M = v[0].len / 8 / dof, L = v[4].len / 8;
    Py_ssize_t P = M ? v[2].len / 8 / M : 0;
    const int64_t *limited = v[4].buf;
    int bad = v[0].len != M * dof * 8 || v[1].len != M * dof * 8 || v[2].len != M * P * 8 ||
              v[3].len != M * P * dof * 8 || v[5].len != L * 8 || v[6].len != L * 8 || v[7].len != L * 8 ||
              v[9].len != M * (L + P) * 8 || v[10].len != M * (L + P) * 8;
    bad = bad || !indices_within(limited, L, 1, 0, dof);
    if (bad)
        PyErr_SetString(PyExc_ValueError, "pieces: sizes of q, t, the pairs, the joints and g disagree");
    else {
        om_pieces(dof, M, L, P, v[0].buf, v[1].buf, v[2].buf, v[3].buf, limited, v[5].buf, v[6].buf, v[7].buf,
                  v[8].buf, v[9].buf, v[10].buf);
        result = Py_NewRef(Py_None);
    }
    release_buffers(v, 11);
done:
    release_fields(f, PR_N + PL_N + 3);
    return result;
}

/* The fields of a cell's models (om_redundant._core.CellModels). */
enum { M_GA, M_DA, M_GB, M_DB, M_SPAN_A, M_SPAN_B, M_HERMITE, M_N };
static const char *const model_names[M_N] = {"ga", "da", "gb", "db", "span_a", "span_b", "hermite"};

/* The record models' buffers of ga, da, gb, db and hermite into v (released by the caller on
 * success) and c; -1 with a TypeError or ValueError naming `name` where a field is missing or
 * their sizes disagree. */
static int cell_models(PyObject *models, const char *name, Py_buffer v[5], om_cell_models *c) {
    PyObject *f[M_N];
    if (get_fields(models, model_names, M_N, f, name) < 0) return -1;
    double span_a = PyFloat_AsDouble(f[M_SPAN_A]), span_b = PyErr_Occurred() ? 0.0 : PyFloat_AsDouble(f[M_SPAN_B]);
    const buffer_spec sp[5] = {{F64, -1, 0, "ga"}, {F64, -1, 0, "da"}, {F64, -1, 0, "gb"}, {F64, -1, 0, "db"},
                               {F64, -1, 0, "hermite"}};
    PyObject *const objs[5] = {f[M_GA], f[M_DA], f[M_GB], f[M_DB], f[M_HERMITE]};
    int got = PyErr_Occurred() ? -1 : get_buffers(objs, v, sp, 5);
    release_fields(f, M_N); /* (the buffers keep the arrays) */
    if (got < 0) return -1;
    Py_ssize_t n = v[0].len / 8, N = v[4].len / 32;
    if (v[1].len != n * 8 || v[2].len != n * 8 || v[3].len != n * 8 || v[4].len != N * 32) {
        release_buffers(v, 5);
        PyErr_Format(PyExc_ValueError, "%s: sizes of the pieces or the basis disagree", name);
        return -1;
    }
    *c = (om_cell_models){v[0].buf, v[1].buf, v[2].buf, v[3].buf, v[4].buf, span_a, span_b, n, N};
    return 0;
}

/* surprise(models, feasible_a, feasible_b, slack) -> fraction or None: the models (CellModels)
 * m_j(s) = ga_j H0(s) + span_a da_j H1(s) + gb_j H2(s) + span_b db_j H3(s) at the N points s of
 * hermite (4 x N, the basis there); the pattern (feasible_a, all_j m_j >= 0 at each point,
 * feasible_b); None if it changes no more often than its ends (0 times if alike, once if
 * not), else the middle of the first stretch between changes as a fraction of the pattern. A
 * piece whose model stays above `slack` by the bound of cell_looks' quiet test cannot change
 * it and is not evaluated. */
static PyObject *om_surprise_binding(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"models", "feasible_a", "feasible_b", "slack"};
    static const arg_spec spec = {"surprise", names, 4, 4};
    PyObject *a[4];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    double slack = PyFloat_AsDouble(a[3]);
    int fa = PyObject_IsTrue(a[1]), fb = PyObject_IsTrue(a[2]);
    if (PyErr_Occurred() || fa < 0 || fb < 0) return NULL;
    Py_buffer v[5];
    om_cell_models c;
    if (cell_models(a[0], "surprise", v, &c) < 0) return NULL;
    ptrdiff_t *live = PyMem_Malloc((c.n ? c.n : 1) * sizeof(ptrdiff_t));
    if (!live) {
        release_buffers(v, 5);
        return PyErr_NoMemory();
    }
    double found = om_surprise(&c, fa, fb, slack, live);
    PyMem_Free(live);
    release_buffers(v, 5);
    if (found < 0.0) Py_RETURN_NONE;
    return PyFloat_FromDouble(found);
}

/* crossing(models) -> fraction or None: where the first of surprise's models m_j
 * (CellModels) reaches zero from a feasible end a (s = 0): the first of the N points s_k =
 * (k + 1) / (N + 1) where one is negative, refined by the secant of the most negative one
 * from the point before (from s = 0, where that model is ga_j, at the first point); None
 * where none is negative there. A piece that surprise's bound keeps positive is skipped. */
static PyObject *om_crossing_binding(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"models"};
    static const arg_spec spec = {"crossing", names, 1, 1};
    PyObject *a[1];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    Py_buffer v[5];
    om_cell_models c;
    if (cell_models(a[0], "crossing", v, &c) < 0) return NULL;
    double found = om_crossing(&c);
    release_buffers(v, 5);
    if (found < 0.0) Py_RETURN_NONE;
    return PyFloat_FromDouble(found);
}

/* joint_step(cyclic, a, b) -> float: the largest joint step from a to b (dof,), the cyclic
 * (bool, dof) joints compared modulo 2 pi (probe.py's Probe.step). */
static PyObject *om_joint_step(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 3, "joint_step") < 0) return NULL;
    Py_buffer v[3];
    const buffer_spec sp[3] = {{U8, -1, 0, "cyclic"}, {F64, -1, 0, "a"}, {F64, -1, 0, "b"}};
    if (get_buffers(args, v, sp, 3) < 0) return NULL;
    Py_ssize_t dof = v[0].len;
    if (v[1].len != dof * 8 || v[2].len != dof * 8) {
        release_buffers(v, 3);
        PyErr_SetString(PyExc_ValueError, "joint_step: sizes of cyclic, a and b disagree");
        return NULL;
    }
    double step = om_largest_joint_step((int)dof, v[1].buf, v[2].buf, v[0].buf);
    release_buffers(v, 3);
    return PyFloat_FromDouble(step);
}

/* cell_spans(cyclic, qa, ta, qb, tb) -> (span_a, span_b): dpsi/ds at the ends a and b of a
 * cell of a path (joints qa, qb and tangents dq/dpsi ta, tb, dof entries each; the cyclic
 * (bool, dof) joints compared modulo 2 pi) for the parameter s in [0, 1] along the cell's
 * chord: the joints move at the chord's length |qb - qa|_2 at both ends, so span = that length
 * over |t|_2 (0 where t = 0, whose rates along psi are 0). Where the path is smooth in psi, to
 * first order in the cell both are psi_b - psi_a. */
static PyObject *om_cell_spans(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 5, "cell_spans") < 0) return NULL;
    Py_buffer v[5];
    const buffer_spec sp[5] = {
        {U8, -1, 0, "cyclic"}, {F64, -1, 0, "qa"}, {F64, -1, 0, "ta"}, {F64, -1, 0, "qb"}, {F64, -1, 0, "tb"}};
    if (get_buffers(args, v, sp, 5) < 0) return NULL;
    Py_ssize_t dof = v[0].len;
    int bad = dof < 1 || dof > OM_MAX_DOF;
    for (int i = 1; i < 5; i++) bad = bad || v[i].len != dof * 8;
    if (bad) {
        release_buffers(v, 5);
        PyErr_SetString(PyExc_ValueError, "cell_spans: sizes of cyclic, qa, ta, qb and tb disagree");
        return NULL;
    }
    double spans[2];
    om_chord_spans((int)dof, v[0].buf, v[1].buf, v[2].buf, v[3].buf, v[4].buf, spans);
    release_buffers(v, 5);
    return Py_BuildValue("(dd)", spans[0], spans[1]);
}

/* Row m of rows (M x n) from obj, a float64 array of n entries (-1 with a TypeError or
 * ValueError naming what, as get_buffer's). */
static int row(PyObject *obj, double *rows, Py_ssize_t m, Py_ssize_t n, const char *what) {
    Py_buffer view;
    if (get_buffer(obj, &view, F64, n, 0, what) < 0) return -1;
    memcpy(rows + m * n, view.buf, n * sizeof(double));
    PyBuffer_Release(&view);
    return 0;
}

/* The M samples' joints and tangents (M x dof each), psi, feasibility functions and rates (M x
 * n each) and feasibility from cell_looks' tuples (each of M items: q, tangent, psi, pieces,
 * feasible) into the arrays of s; -1 with an error where an item is not what cell_looks takes. */
static int read_samples(PyObject *const *lists, Py_ssize_t M, Py_ssize_t dof, Py_ssize_t n, om_cell_samples *s) {
    for (Py_ssize_t m = 0; m < M; m++) {
        PyObject *pieces = PyTuple_GET_ITEM(lists[3], m);
        if (!PyTuple_Check(pieces) || PyTuple_GET_SIZE(pieces) != 2) {
            PyErr_SetString(PyExc_TypeError, "cell_looks: each pieces item must be a tuple (g, dg)");
            return -1;
        }
        if (row(PyTuple_GET_ITEM(lists[0], m), s->q, m, dof, "q") < 0 ||
            row(PyTuple_GET_ITEM(lists[1], m), s->t, m, dof, "tangent") < 0 ||
            row(PyTuple_GET_ITEM(pieces, 0), s->g, m, n, "g") < 0 ||
            row(PyTuple_GET_ITEM(pieces, 1), s->dg, m, n, "dg") < 0)
            return -1;
        s->psi[m] = PyFloat_AsDouble(PyTuple_GET_ITEM(lists[2], m));
        int f = PyObject_IsTrue(PyTuple_GET_ITEM(lists[4], m));
        if (f < 0 || PyErr_Occurred()) return -1;
        s->feasible[m] = (uint8_t)f;
    }
    return 0;
}

/* The fields of cell_looks' samples (om_redundant._core.CellSamples). */
enum { S_Q, S_TANGENT, S_PSI, S_PIECES, S_FEASIBLE, S_BOUNDS, S_CYCLIC, S_N };
static const char *const sample_names[S_N] = {"q", "tangent", "psi", "pieces", "feasible", "bounds", "cyclic"};

/* cell_looks(samples, fine_step, slack, hermite, first) -> None: the first tests of the cells
 * between neighbouring samples of paths (paths.py's _with_hidden). The M samples of every
 * path, path after path (CellSamples), as sequences of M items: their joints q and tangents
 * dq/dpsi (float64 arrays of dof entries), psi (floats), pieces ((g, dg), float64 arrays (n,): the feasibility
 * functions and their rates, Point.pieces) and feasibility (bools); bounds (int64, P + 1) each
 * path's first sample, then M; cyclic (bool, P x dof) each path's joints compared modulo 2 pi.
 * Cell k lies between samples k and k + 1 of one path; into first (M,) where _hidden first
 * samples it: NaN where it does not look inside, the cell being calm (no joint_step above
 * fine_step, and the bounds of its cubic models quiet), or where surprise finds nothing; 1/2
 * where a step is above fine_step; else surprise's fraction. The models are along the cell's
 * chord (cell_spans). A path's last sample's entry is
 * NaN. Quiet: on [0, 1] the Hermite basis functions of the values are >= 0 and sum to 1 and
 * those of the slopes stay within 4/27 in size, so a model lies within (4/27) (|span_a g'_a| +
 * |span_b g'_b|) (+ slack, for rounding) of the ends' range: both ends feasible and every model stays
 * > 0, or both infeasible and one function's model stays < 0; then surprise finds no change
 * (it skips the pieces that this bound keeps positive). */
static PyObject *om_cell_looks(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"samples", "fine_step", "slack", "hermite", "first"};
    static const arg_spec spec = {"cell_looks", names, 5, 5};
    PyObject *a[5], *f[S_N], *lists[5] = {NULL, NULL, NULL, NULL, NULL}, *result = NULL;
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    double fine = PyFloat_AsDouble(a[1]), slack = PyFloat_AsDouble(a[2]);
    if (PyErr_Occurred()) return NULL;
    if (get_fields(a[0], sample_names, S_N, f, "cell_looks' samples") < 0) return NULL;
    Py_buffer v[4];
    const buffer_spec sp[4] = {
        {I64, -1, 0, "bounds"}, {U8, -1, 0, "cyclic"}, {F64, -1, 0, "hermite"}, {F64, -1, 1, "first"}};
    PyObject *const objs[4] = {f[S_BOUNDS], f[S_CYCLIC], a[3], a[4]};
    for (int i = 0; i < 5; i++) {
        lists[i] = get_tuple(f[S_Q + i], -1, "cell_looks: q, tangent, psi, pieces and feasible each");
        if (!lists[i]) goto lists_fail;
    }
    if (get_buffers(objs, v, sp, 4) < 0) goto lists_fail;
    Py_ssize_t M = PyTuple_GET_SIZE(lists[0]), P = v[0].len / 8 - 1, N = v[2].len / 32;
    const int64_t *bounds = v[0].buf;
    Py_ssize_t dof = P > 0 ? v[1].len / P : 0, n = 0;
    int bad = P < 0 || v[1].len != P * dof || v[2].len != N * 32 || v[3].len != M * 8 ||
              (P > 0 && (dof < 1 || dof > OM_MAX_DOF));
    for (int i = 1; i < 5; i++) bad = bad || PyTuple_GET_SIZE(lists[i]) != M;
    bad = bad || bounds[0] != 0 || bounds[P] != M; /* each path's first sample, from 0 to M, increasing */
    for (Py_ssize_t p = 1; p <= P && !bad; p++) bad = bounds[p] < bounds[p - 1];
    if (bad) {
        PyErr_SetString(PyExc_ValueError, "cell_looks: sizes of the samples, bounds, cyclic or the outputs disagree");
        goto fail;
    }
    if (M) { /* the pieces' count from the first sample's */
        PyObject *pieces = PyTuple_GET_ITEM(lists[3], 0);
        if (PyTuple_Check(pieces) && PyTuple_GET_SIZE(pieces) == 2) n = PyObject_Length(PyTuple_GET_ITEM(pieces, 0));
        if (n < 0) goto fail;
    }
    double *store = PyMem_Malloc((M * (2 * dof + 1 + 2 * n) + 1) * sizeof(double));
    uint8_t *feasible = PyMem_Malloc(M + 1);
    ptrdiff_t *live = PyMem_Malloc((n + 1) * sizeof(ptrdiff_t));
    if (!store || !feasible || !live) {
        PyMem_Free(store), PyMem_Free(feasible), PyMem_Free(live);
        PyErr_NoMemory();
        goto fail;
    }
    double *t = store + M * dof, *psi = t + M * dof, *g = psi + M, *dg = g + M * n;
    om_cell_samples s = {store, t, psi, g, dg, feasible};
    int ok = read_samples(lists, M, dof, n, &s) == 0;
    const uint8_t *cyclic = v[1].buf;
    for (Py_ssize_t p = 0; p < P && ok; p++)
        om_path_looks(&s, bounds[p], bounds[p + 1], dof, n, cyclic + p * dof, fine, slack, v[2].buf, N, v[3].buf,
                      live);
    PyMem_Free(store), PyMem_Free(feasible), PyMem_Free(live);
    if (ok) result = Py_NewRef(Py_None);
fail:
    release_buffers(v, 4);
lists_fail:
    for (int i = 0; i < 5; i++) Py_XDECREF(lists[i]);
    release_fields(f, S_N);
    return result;
}

PyMethodDef om_cell_functions[] = {
    {"pieces", (PyCFunction)(void (*)(void))om_pieces_binding, METH_FASTCALL | METH_KEYWORDS,
     "pieces(dof, rows, limits, numbers, g, dg) -> None"},
    {"surprise", (PyCFunction)(void (*)(void))om_surprise_binding, METH_FASTCALL | METH_KEYWORDS,
     "surprise(models, feasible_a, feasible_b, slack) -> fraction or None"},
    {"crossing", (PyCFunction)(void (*)(void))om_crossing_binding, METH_FASTCALL | METH_KEYWORDS,
     "crossing(models) -> fraction or None"},
    {"joint_step", (PyCFunction)(void (*)(void))om_joint_step, METH_FASTCALL, "joint_step(cyclic, a, b) -> float"},
    {"cell_spans", (PyCFunction)(void (*)(void))om_cell_spans, METH_FASTCALL,
     "cell_spans(cyclic, qa, ta, qb, tb) -> (span_a, span_b)"},
    {"cell_looks", (PyCFunction)(void (*)(void))om_cell_looks, METH_FASTCALL | METH_KEYWORDS,
     "cell_looks(samples, fine_step, slack, hermite, first) -> None"},
    {NULL, NULL, 0, NULL},
};
