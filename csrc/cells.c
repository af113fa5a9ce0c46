/* The cell test of the global choose's solution paths (om_redundant/redundancy/paths.py's
 * _surprise, whose numpy version is the reference): the feasibility functions g_j of a point
 * and their rates along psi, and where their cubic Hermite models between two neighbouring
 * points predict a feasibility that the ends do not explain. */
#include <string.h>

#include "binding.h"

enum { P_REACH, P_CAP, P_FLOOR, P_N }; /* clearance: 2 d_cap, d_cap, d_min / d_cap */

/* pieces(dof, q, t, distances, gradients, limited, lower, upper, half, numbers, g, dg) -> None:
 * objective.py's Group.constraints of the margin and clearance groups at each of the M rows
 * q (M x dof) with dq/dpsi = t (M x dof), the pairs' distances (M x P) and gradients
 * (M x P x dof), into g and dg (M x (L + P)): per limited joint the smaller of
 * (q_i - l_i)/h_i and (u_i - q_i)/h_i with its rate; then per pair d_k/d_cap - d_min/d_cap
 * with its rate grad d_k . t / d_cap, a pair at 2 d_cap or more taken as 2 d_cap with rate 0
 * when some pair of the row is nearer (objective.py's _clearance). */
static void row_pieces(Py_ssize_t dof, Py_ssize_t L, Py_ssize_t P, const double *q, const double *t, const double *d,
                       const double *grad, const int64_t *limited, const double *lower, const double *upper,
                       const double *half, const double *num, double *g, double *dg) {
    for (Py_ssize_t i = 0; i < L; i++) {
        int64_t j = limited[i];
        double a = (q[j] - lower[i]) / half[i], b = (upper[i] - q[j]) / half[i], s = 1.0 / half[i];
        if (a <= b)
            g[i] = a - 0.0, dg[i] = s * t[j];
        else
            g[i] = b - 0.0, dg[i] = -s * t[j];
    }
    double least = INFINITY;
    for (Py_ssize_t k = 0; k < P; k++) least = fmin(least, d[k]);
    int capped = least < num[P_REACH]; /* then pairs from 2 d_cap on count as 2 d_cap, flat */
    for (Py_ssize_t k = 0; k < P; k++) {
        double *gk = g + L + k, *dgk = dg + L + k;
        if (capped && !(d[k] < num[P_REACH])) {
            *gk = num[P_REACH] / num[P_CAP] - num[P_FLOOR], *dgk = 0.0;
            continue;
        }
        double rate = 0.0;
        for (Py_ssize_t j = 0; j < dof; j++) rate += grad[k * dof + j] / num[P_CAP] * t[j];
        *gk = d[k] / num[P_CAP] - num[P_FLOOR], *dgk = rate;
    }
}

static PyObject *om_pieces(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 12, "pieces") < 0) return NULL;
    Py_ssize_t dof;
    if (get_dof(args[0], &dof, "pieces") < 0) return NULL;
    Py_buffer v[11];
    const buffer_spec sp[11] = {{F64, -1, 0, "q"},     {F64, -1, 0, "t"},      {F64, -1, 0, "distances"},
                                {F64, -1, 0, "gradients"}, {I64, -1, 0, "limited"}, {F64, -1, 0, "lower"},
                                {F64, -1, 0, "upper"}, {F64, -1, 0, "half"},   {F64, P_N, 0, "numbers"},
                                {F64, -1, 1, "g"},     {F64, -1, 1, "dg"}};
    if (get_buffers(args + 1, v, sp, 11) < 0) return NULL;
    Py_ssize_t M = v[0].len / 8 / dof, L = v[4].len / 8;
    Py_ssize_t P = M ? v[2].len / 8 / M : 0;
    const int64_t *limited = v[4].buf;
    int bad = v[0].len != M * dof * 8 || v[1].len != M * dof * 8 || v[2].len != M * P * 8 ||
              v[3].len != M * P * dof * 8 || v[5].len != L * 8 || v[6].len != L * 8 || v[7].len != L * 8 ||
              v[9].len != M * (L + P) * 8 || v[10].len != M * (L + P) * 8;
    bad = bad || !indices_within(limited, L, 1, 0, dof);
    if (bad) {
        release_buffers(v, 11);
        PyErr_SetString(PyExc_ValueError, "pieces: sizes of q, t, the pairs, the joints and g disagree");
        return NULL;
    }
    const double *q = v[0].buf, *t = v[1].buf, *d = v[2].buf, *grad = v[3].buf;
    double *g = v[9].buf, *dg = v[10].buf;
    for (Py_ssize_t m = 0; m < M; m++)
        row_pieces(dof, L, P, q + m * dof, t + m * dof, d + m * P, grad + m * P * dof, limited, v[5].buf, v[6].buf,
                   v[7].buf, v[8].buf, g + m * (L + P), dg + m * (L + P));
    release_buffers(v, 11);
    Py_RETURN_NONE;
}

/* The Hermite models of a cell's pieces (surprise's and crossing's arguments ga, da, gb, db,
 * span and the basis hermite at N points). */
typedef struct {
    const double *ga, *da, *gb, *db, *H;
    double span;
    Py_ssize_t n, N;
} cell_models;

/* The buffers of ga, da, gb, db and hermite into v (released by the caller on success) and c;
 * -1 with a ValueError naming `name` where their sizes disagree. */
static int _cell_models(PyObject *const *args, double span, const char *name, Py_buffer v[5], cell_models *c)
{
    const buffer_spec sp[5] = {{F64, -1, 0, "ga"}, {F64, -1, 0, "da"}, {F64, -1, 0, "gb"}, {F64, -1, 0, "db"},
                               {F64, -1, 0, "hermite"}};
    PyObject *const objs[5] = {args[0], args[1], args[2], args[3], args[5]};
    if (get_buffers(objs, v, sp, 5) < 0) return -1;
    Py_ssize_t n = v[0].len / 8, N = v[4].len / 32;
    if (v[1].len != n * 8 || v[2].len != n * 8 || v[3].len != n * 8 || v[4].len != N * 32) {
        release_buffers(v, 5);
        PyErr_Format(PyExc_ValueError, "%s: sizes of the pieces or the basis disagree", name);
        return -1;
    }
    *c = (cell_models){v[0].buf, v[1].buf, v[2].buf, v[3].buf, v[4].buf, span, n, N};
    return 0;
}

/* Piece j's model at the basis point k. */
static inline double _model(const cell_models *c, Py_ssize_t j, Py_ssize_t k)
{
    Py_ssize_t N = c->N;
    return c->ga[j] * c->H[k] + c->da[j] * c->span * c->H[N + k] + c->gb[j] * c->H[2 * N + k] +
           c->db[j] * c->span * c->H[3 * N + k];
}

/* Whether piece j's model stays above `slack` over the cell by cell_looks' quiet bound
 * (min(ga, gb) - 4/27 span (|da| + |db|)). */
static inline bool _calm(const cell_models *c, Py_ssize_t j, double slack)
{
    return fmin(c->ga[j], c->gb[j]) - 4.0 / 27.0 * fabs(c->span) * (fabs(c->da[j]) + fabs(c->db[j])) > slack;
}

/* The pattern's surprise of surprise()'s docstring below for the cell c with ends feasible
 * fa, fb: the fraction, or -1 where there is none; live: room for c->n piece indices. */
static double _surprise(const cell_models *c, int fa, int fb, double slack, Py_ssize_t *live)
{
    Py_ssize_t n = c->n, N = c->N, m = 0;
    for (Py_ssize_t j = 0; j < n; j++)
        if (!_calm(c, j, slack)) live[m++] = j;
    Py_ssize_t changes[2], count = 0, allowed = fa != fb;
    int previous = fa;
    for (Py_ssize_t k = 0; k <= N && count < 2; k++) { /* (the first two changes tell) */
        int feasible = fb;
        if (k < N) {
            feasible = 1;
            for (Py_ssize_t i = 0; i < m && feasible; i++) feasible = _model(c, live[i], k) >= 0.0;
        }
        if (feasible != previous) changes[count++] = k;
        previous = feasible;
    }
    if (count <= allowed) return -1.0;
    return (double)(changes[0] + 1 + changes[1]) / 2.0 / (double)(N + 1);
}

/* surprise(ga, da, gb, db, span, hermite, feasible_a, feasible_b, slack) -> fraction or None:
 * the models m_j(s) = ga_j H0(s) + span da_j H1(s) + gb_j H2(s) + span db_j H3(s) at the N
 * points s of hermite (4 x N, the basis there); the pattern (feasible_a, all_j m_j >= 0 at
 * each point, feasible_b); None if it changes no more often than its ends (0 times if
 * alike, once if not), else the middle of the first stretch between changes as a fraction
 * of the pattern. A piece whose model stays above `slack` by the bound of cell_looks'
 * quiet test cannot change it and is not evaluated (_calm). */
static PyObject *om_surprise(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 9, "surprise") < 0) return NULL;
    double span = PyFloat_AsDouble(args[4]), slack = PyFloat_AsDouble(args[8]);
    int fa = PyObject_IsTrue(args[6]), fb = PyObject_IsTrue(args[7]);
    if (PyErr_Occurred() || fa < 0 || fb < 0) return NULL;
    Py_buffer v[5];
    cell_models c;
    if (_cell_models(args, span, "surprise", v, &c) < 0) return NULL;
    Py_ssize_t *live = PyMem_Malloc((c.n ? c.n : 1) * sizeof(Py_ssize_t));
    if (!live) {
        release_buffers(v, 5);
        return PyErr_NoMemory();
    }
    double found = _surprise(&c, fa, fb, slack, live);
    PyMem_Free(live);
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

/* Whether the cell c with ends feasible fa, fb is quiet by the bounds of cell_looks. The
 * minimum and maximum propagate NaN as numpy's do. */
static bool _quiet(const cell_models *c, int fa, int fb, double slack)
{
    if (fa != fb) return false;
    for (Py_ssize_t j = 0; j < c->n; j++) {
        double ga = c->ga[j], gb = c->gb[j];
        double spread = 4.0 / 27.0 * fabs(c->span) * (fabs(c->da[j]) + fabs(c->db[j])) + slack;
        if (fa && !(om_least(ga, gb) - spread > 0.0)) return false; /* a model may dip */
        if (!fa && om_most(ga, gb) + spread < 0.0) return true;    /* one stays below */
    }
    return fa;
}

/* Row m of rows (M x n) from obj, a float64 array of n entries (-1 with a TypeError or
 * ValueError naming what, as get_buffer's). */
static int _row(PyObject *obj, double *rows, Py_ssize_t m, Py_ssize_t n, const char *what)
{
    Py_buffer view;
    if (get_buffer(obj, &view, F64, n, 0, what) < 0) return -1;
    memcpy(rows + m * n, view.buf, n * sizeof(double));
    PyBuffer_Release(&view);
    return 0;
}

/* The M samples' joints (M x dof), psi, feasibility functions and rates (M x n each) and
 * feasibility from cell_looks' lists (each of M items) into the arrays of s; -1 with an
 * error where an item is not what cell_looks takes. */
typedef struct {
    double *q, *psi, *g, *dg;
    uint8_t *feasible;
} samples;

static int _samples(PyObject *const *lists, Py_ssize_t M, Py_ssize_t dof, Py_ssize_t n, samples *s)
{
    for (Py_ssize_t m = 0; m < M; m++) {
        PyObject *pieces = PyTuple_GET_ITEM(lists[2], m);
        if (!PyTuple_Check(pieces) || PyTuple_GET_SIZE(pieces) != 2) {
            PyErr_SetString(PyExc_TypeError, "cell_looks: each pieces item must be a tuple (g, dg)");
            return -1;
        }
        if (_row(PyTuple_GET_ITEM(lists[0], m), s->q, m, dof, "q") < 0 ||
            _row(PyTuple_GET_ITEM(pieces, 0), s->g, m, n, "g") < 0 ||
            _row(PyTuple_GET_ITEM(pieces, 1), s->dg, m, n, "dg") < 0)
            return -1;
        s->psi[m] = PyFloat_AsDouble(PyTuple_GET_ITEM(lists[1], m));
        int f = PyObject_IsTrue(PyTuple_GET_ITEM(lists[3], m));
        if (f < 0 || PyErr_Occurred()) return -1;
        s->feasible[m] = (uint8_t)f;
    }
    return 0;
}

/* The looks of the cells of one path, samples a .. b - 1 of s (cell k: samples k, k + 1),
 * into first (cell_looks' docstring); live: room for n piece indices. */
static void _path_looks(const samples *s, Py_ssize_t a, Py_ssize_t b, Py_ssize_t dof, Py_ssize_t n,
                        const uint8_t *cyclic, double fine, double slack, const double *H, Py_ssize_t N,
                        double *first, Py_ssize_t *live)
{
    for (Py_ssize_t k = a; k + 1 < b; k++) {
        const double *g = s->g, *dg = s->dg;
        cell_models c = {g + k * n, dg + k * n, g + (k + 1) * n, dg + (k + 1) * n, H, s->psi[k + 1] - s->psi[k], n, N};
        int fa = s->feasible[k], fb = s->feasible[k + 1];
        double step = om_largest_joint_step((int)dof, s->q + k * dof, s->q + (k + 1) * dof, cyclic);
        if (step <= fine && _quiet(&c, fa, fb, slack))
            first[k] = NAN;
        else if (step > fine)
            first[k] = 0.5;
        else {
            double t = n ? _surprise(&c, fa, fb, slack, live) : -1.0;
            first[k] = t < 0.0 ? NAN : t;
        }
    }
    if (b > a) first[b - 1] = NAN; /* (the path's last sample starts no cell) */
}

/* cell_looks(q, psi, pieces, feasible, bounds, cyclic, fine_step, slack, hermite, first) -> None: the first tests of the cells between neighbouring samples of paths (paths.py's
 * _with_hidden). The M samples of every path, path after path, as lists of M items: their
 * joints q (float64 arrays (dof,)), psi (floats), pieces ((g, dg), float64 arrays (n,): the
 * feasibility functions and their rates, Point.pieces) and feasibility (bools); bounds
 * (int64, P + 1) each path's first sample, then M; cyclic (bool, P x dof) each path's joints
 * compared modulo 2 pi. Cell k lies between samples k and k + 1 of one path; into first
 * (M,) where _hidden first samples it: NaN where it does not look inside, the cell being
 * calm (no joint_step above fine_step, and the bounds of its cubic models quiet), or where
 * surprise finds nothing; 1/2 where a step is above fine_step; else surprise's fraction. A
 * path's last sample's entry is NaN. Quiet:
 * on [0, 1] the Hermite basis functions of the values are >= 0 and sum to 1 and those of the
 * slopes stay within 4/27 in size, so a model lies within (4/27) |span| (|g'_a| + |g'_b|)
 * (+ slack, for rounding) of the ends' range: both ends feasible and every model stays > 0,
 * or both infeasible and one function's model stays < 0; then surprise finds no change (it
 * skips the pieces that this bound keeps positive). */
static PyObject *om_cell_looks(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 10, "cell_looks") < 0) return NULL;
    double fine = PyFloat_AsDouble(args[6]), slack = PyFloat_AsDouble(args[7]);
    if (PyErr_Occurred()) return NULL;
    PyObject *lists[4] = {NULL, NULL, NULL, NULL};
    Py_buffer v[4];
    const buffer_spec sp[4] = {
        {I64, -1, 0, "bounds"}, {U8, -1, 0, "cyclic"}, {F64, -1, 0, "hermite"}, {F64, -1, 1, "first"}};
    PyObject *const objs[4] = {args[4], args[5], args[8], args[9]};
    for (int i = 0; i < 4; i++) {
        lists[i] = get_tuple(args[i], -1, "cell_looks: q, psi, pieces and feasible each");
        if (!lists[i]) goto lists_fail;
    }
    if (get_buffers(objs, v, sp, 4) < 0) goto lists_fail;
    Py_ssize_t M = PyTuple_GET_SIZE(lists[0]), P = v[0].len / 8 - 1, N = v[2].len / 32;
    const int64_t *bounds = v[0].buf;
    Py_ssize_t dof = P > 0 ? v[1].len / P : 0, n = 0;
    int bad = P < 0 || v[1].len != P * dof || v[2].len != N * 32 || v[3].len != M * 8 ||
              (P > 0 && (dof < 1 || dof > OM_MAX_DOF));
    for (int i = 1; i < 4; i++) bad = bad || PyTuple_GET_SIZE(lists[i]) != M;
    bad = bad || bounds[0] != 0 || bounds[P] != M; /* each path's first sample, from 0 to M, increasing */
    for (Py_ssize_t p = 1; p <= P && !bad; p++) bad = bounds[p] < bounds[p - 1];
    if (bad) {
        PyErr_SetString(PyExc_ValueError, "cell_looks: sizes of the samples, bounds, cyclic or the outputs disagree");
        goto fail;
    }
    if (M) { /* the pieces' count from the first sample's */
        PyObject *pieces = PyTuple_GET_ITEM(lists[2], 0);
        if (PyTuple_Check(pieces) && PyTuple_GET_SIZE(pieces) == 2) n = PyObject_Length(PyTuple_GET_ITEM(pieces, 0));
        if (n < 0) goto fail;
    }
    double *store = PyMem_Malloc((M * (dof + 1 + 2 * n) + 1) * sizeof(double));
    uint8_t *feasible = PyMem_Malloc(M + 1);
    Py_ssize_t *live = PyMem_Malloc((n + 1) * sizeof(Py_ssize_t));
    if (!store || !feasible || !live) {
        PyMem_Free(store), PyMem_Free(feasible), PyMem_Free(live);
        PyErr_NoMemory();
        goto fail;
    }
    samples s = {store, store + M * dof, store + M * (dof + 1), store + M * (dof + 1 + n), feasible};
    int ok = _samples(lists, M, dof, n, &s) == 0;
    const uint8_t *cyclic = v[1].buf;
    for (Py_ssize_t p = 0; p < P && ok; p++)
        _path_looks(&s, bounds[p], bounds[p + 1], dof, n, cyclic + p * dof, fine, slack, v[2].buf, N, v[3].buf, live);
    PyMem_Free(store), PyMem_Free(feasible), PyMem_Free(live);
    release_buffers(v, 4);
    for (int i = 0; i < 4; i++) Py_DECREF(lists[i]);
    if (!ok) return NULL;
    Py_RETURN_NONE;
fail:
    release_buffers(v, 4);
lists_fail:
    for (int i = 0; i < 4; i++) Py_XDECREF(lists[i]);
    return NULL;
}

/* crossing(ga, da, gb, db, span, hermite) -> fraction or None: where the first of surprise's
 * models m_j reaches zero from a feasible end a (s = 0): the first of the N points s_k =
 * (k + 1) / (N + 1) where one is negative, refined by the secant of the most negative one
 * from the point before (from s = 0, where that model is ga_j, at the first point); None
 * where none is negative there. A piece that surprise's bound keeps positive is skipped. */
static PyObject *om_crossing(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    if (check_nargs(nargs, 6, "crossing") < 0) return NULL;
    double span = PyFloat_AsDouble(args[4]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer v[5];
    cell_models c;
    if (_cell_models(args, span, "crossing", v, &c) < 0) return NULL;
    Py_ssize_t n = c.n, N = c.N;
    double found = -1.0;
    Py_ssize_t first = N; /* the first point where a model is negative */
    Py_ssize_t j_first = -1;
    double m_first = 0.0;
    for (Py_ssize_t j = 0; j < n; j++) {
        if (_calm(&c, j, 0.0)) continue;
        for (Py_ssize_t k = 0; k < N && k <= first; k++) { /* (up to the first found so far) */
            double model = _model(&c, j, k);
            if (model < 0.0) {
                if (k < first || model < m_first) first = k, j_first = j, m_first = model;
                break;
            }
        }
    }
    if (j_first >= 0) {
        Py_ssize_t k = first;
        double s1 = (double)(k + 1) / (double)(N + 1), s0 = (double)k / (double)(N + 1);
        double m0 = k > 0 ? _model(&c, j_first, k - 1) : c.ga[j_first];
        found = s0 + (s1 - s0) * m0 / (m0 - m_first);
    }
    release_buffers(v, 5);
    if (found < 0.0) Py_RETURN_NONE;
    return PyFloat_FromDouble(found);
}

PyMethodDef om_cell_functions[] = {
    {"pieces", (PyCFunction)(void (*)(void))om_pieces, METH_FASTCALL,
     "pieces(dof, q, t, distances, gradients, limited, lower, upper, half, numbers, g, dg) -> None"},
    {"surprise", (PyCFunction)(void (*)(void))om_surprise, METH_FASTCALL,
     "surprise(ga, da, gb, db, span, hermite, feasible_a, feasible_b, slack) -> fraction or None"},
    {"crossing", (PyCFunction)(void (*)(void))om_crossing, METH_FASTCALL,
     "crossing(ga, da, gb, db, span, hermite) -> fraction or None"},
    {"joint_step", (PyCFunction)(void (*)(void))om_joint_step, METH_FASTCALL, "joint_step(cyclic, a, b) -> float"},
    {"cell_looks", (PyCFunction)(void (*)(void))om_cell_looks, METH_FASTCALL,
     "cell_looks(q, psi, pieces, feasible, bounds, cyclic, fine_step, slack, hermite, first) -> None"},
    {NULL, NULL, 0, NULL},
};
