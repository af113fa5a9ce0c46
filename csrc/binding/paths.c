/* The binding of the solution paths' kernels (csrc/redundancy/om_paths.h): follow (follow.c), link_paths
 * (link.c) and self_motion_tangents (tangents.c). Their records (om_redundant._core's
 * FollowWork, LinkRoots, LinkRows) are read by name; their results are named
 * (ckernels.Followed, Linked) or written into the records' arrays. */
#include <stdlib.h>
#include <string.h>

#include "binding.h"

static PyStructSequence_Field followed_fields[] = {
    {"psi", "the arm angle reached"},
    {"status", "FOLLOW_ARRIVED, FOLLOW_ENDED or FOLLOW_STALLED"},
    {"steps", "the accepted steps"},
    {NULL, NULL},
};
static PyStructSequence_Desc followed_desc = {"om_redundant.ckernels.Followed", "What follow reached.",
                                              followed_fields, 3};
static PyTypeObject *followed_type;

static PyStructSequence_Field linked_fields[] = {
    {"status", "LINK_DONE or LINK_FULL (more rows added than the rows' capacity)"},
    {"added", "the rows that following added"},
    {"paths", "the paths (LINK_DONE), else 0"},
    {NULL, NULL},
};
static PyStructSequence_Desc linked_desc = {"om_redundant.ckernels.Linked", "What link_paths linked.", linked_fields,
                                            3};
static PyTypeObject *linked_type;

/* The fields of the branch record (om_redundant._core.FollowWork) that follow and link_paths
 * read: the branch's (W_BRANCH of them: link_paths'; the buffers from W_T on) and the point
 * followed. */
enum { W_KERNEL, W_TRACES, W_T, W_SIGNS, W_CYCLIC, W_CENTRED, W_CENTRE, W_BRANCH, W_Q = W_BRANCH, W_T7, W_N };
static const char *const work_names[W_N] = {"kernel", "traces", "T", "signs", "cyclic", "centred", "centre", "q", "t"};

/* follow(work, psi, target, min_step) -> Followed(psi, status, steps): work.q and work.t (7,
 * in place) become the point reached. */
static PyObject *om_follow(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"work", "psi", "target", "min_step"};
    static const arg_spec spec = {"follow", names, 4, 4};
    PyObject *a[4], *w[W_N];
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    double psi = PyFloat_AsDouble(a[1]), target = PyFloat_AsDouble(a[2]), min_step = PyFloat_AsDouble(a[3]);
    if (PyErr_Occurred()) return NULL;
    if (get_fields(a[0], work_names, W_N, w, "follow's work") < 0) return NULL;
    PyObject *result = NULL;
    const om_solver_data *s = om_srs7_solver(w[W_KERNEL], "follow");
    Py_buffer v[7];
    const buffer_spec sp[7] = {{F64, 16, 0, "T"}, {I64, s ? s->n_signs : 0, 0, "signs"}, {U8, 7, 0, "cyclic"},
                               {U8, 7, 0, "centred"}, {F64, 7, 0, "centre"}, {F64, 7, 1, "q"},
                               {F64, 7, 1, "t"}};
    const om_torus_memo *traces = s ? om_traces_of(w[W_TRACES], s, "follow") : NULL;
    if (s == NULL || PyErr_Occurred() || get_buffers(w + W_T, v, sp, 7) < 0) goto done;
    double T[16];
    int64_t signs[3];
    if (copy_pose_and_signs(&v[0], &v[1], s->n_signs, T, signs) == 0) {
        int steps = 0, status;
        om_branch branch = {s, T, v[4].buf, signs, v[2].buf, v[3].buf, traces};
        Py_BEGIN_ALLOW_THREADS status = om_follow_path(&branch, &psi, v[5].buf, v[6].buf, target, min_step, &steps);
        Py_END_ALLOW_THREADS PyObject *items[3] = {PyFloat_FromDouble(psi), PyLong_FromLong(status),
                                                   PyLong_FromLong(steps)};
        result = new_record(followed_type, items, 3);
    }
    release_buffers(v, 7);
done:
    release_fields(w, W_N);
    return result;
}

/* The fields of link_paths' roots (om_redundant._core.LinkRoots) and rows (LinkRows). */
enum { R_PSI, R_COUNTS, R_Q, R_T, R_N };
static const char *const root_names[R_N] = {"psi", "counts", "q", "t"};
enum { O_PSI, O_Q, O_T, O_MEMBERS, O_PATHS, O_N };
static const char *const row_names[O_N] = {"psi", "q", "t", "members", "paths"};

/* Whether the grid (n psi) is increasing, finite and within a turn, and its counts (n) are
 * those of the m roots. */
static bool grid_holds(const double *grid, const int64_t *counts, Py_ssize_t n, Py_ssize_t m) {
    int64_t total = 0;
    for (Py_ssize_t k = 0; k < n; k++) {
        if (!(counts[k] >= 0 && counts[k] <= m && isfinite(grid[k]) && (k == 0 || grid[k] > grid[k - 1])))
            return false;
        total += counts[k];
    }
    return total == m && grid[n - 1] - grid[0] < 2.0 * OM_PI;
}

/* link_paths(work, roots, rows) -> Linked(status, added, paths): the paths of the branch of
 * work (FollowWork: its kernel, T, signs, cyclic, centred, centre) through its roots
 * (LinkRoots: counts[k] of them at the grid's psi[k], n, increasing within a turn; their joints
 * q and tangents t, (M, 7)), link.c's top comment. Into rows (LinkRows): the points that
 * following adds (psi (R,), q and t (R, 7)); each path's rows, in order, into members (M + R,
 * 2: the row, roots first then rows added, and the turns of psi it is taken at), and into paths (M + R,
 * 2) where its members end and its turns (a loop's, else 0). Where the status is not
 * LINK_DONE the caller's loop decides. */
static PyObject *om_link(PyObject *mod, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames) {
    static const char *const names[] = {"work", "roots", "rows"};
    static const arg_spec spec = {"link_paths", names, 3, 3};
    PyObject *a[3], *f[W_BRANCH + R_N + O_N] = {NULL}, *result = NULL;
    if (bind_args(args, nargs, kwnames, &spec, a) < 0) return NULL;
    if (get_fields(a[0], work_names, W_BRANCH, f, "link_paths' work") < 0) return NULL;
    if (get_fields(a[1], root_names, R_N, f + W_BRANCH, "link_paths' roots") < 0) {
        release_fields(f, W_BRANCH);
        return NULL;
    }
    if (get_fields(a[2], row_names, O_N, f + W_BRANCH + R_N, "link_paths' rows") < 0) {
        release_fields(f, W_BRANCH + R_N);
        return NULL;
    }
    const om_solver_data *s = om_srs7_solver(f[W_KERNEL], "link_paths");
    enum { V = W_BRANCH - W_T + R_N + O_N }; /* the buffers: all but the kernel and the traces */
    Py_buffer v[V];
    const buffer_spec sp[V] = {
        {F64, 16, 0, "T"},     {I64, s ? s->n_signs : 0, 0, "signs"}, {U8, 7, 0, "cyclic"},
        {U8, 7, 0, "centred"}, {F64, 7, 0, "centre"},                 {F64, -1, 0, "psi"},
        {I64, -1, 0, "counts"}, {F64, -1, 0, "q"},                    {F64, -1, 0, "t"},
        {F64, -1, 1, "psi"},   {F64, -1, 1, "q"},                     {F64, -1, 1, "t"},
        {I64, -1, 1, "members"}, {I64, -1, 1, "paths"},
    };
    const om_torus_memo *traces = s ? om_traces_of(f[W_TRACES], s, "link_paths") : NULL;
    if (s == NULL || PyErr_Occurred() || get_buffers(f + W_T, v, sp, V) < 0) goto done;
    enum { GRID = W_BRANCH - W_T, COUNTS, Q, T7, NEW_PSI, NEW_Q, NEW_T, MEMBERS, PATHS };
    Py_ssize_t n = v[COUNTS].len / 8, m = v[Q].len / 8 / 7, capacity = v[NEW_PSI].len / 8, rows = m + capacity;
    bool ok = n >= 1 && v[GRID].len / 8 == n && v[Q].len == 8 * 7 * m && v[T7].len == v[Q].len;
    ok = ok && v[NEW_Q].len == 8 * 7 * capacity && v[NEW_T].len == v[NEW_Q].len &&
         v[MEMBERS].len == 8 * 2 * rows && v[PATHS].len == v[MEMBERS].len;
    /* the pose, signs, grid and counts copied, then checked: the kernels read them with the
     * GIL released, while the caller's arrays may change */
    double T[16], *grid = ok ? malloc(sizeof(double) * (size_t)n) : NULL;
    int64_t signs[3], *counts = ok ? malloc(sizeof(int64_t) * (size_t)n) : NULL;
    if (ok && (!grid || !counts))
        PyErr_NoMemory();
    else if (ok && copy_pose_and_signs(&v[0], &v[1], s->n_signs, T, signs) == 0) {
        memcpy(counts, v[COUNTS].buf, (size_t)n * sizeof(int64_t));
        memcpy(grid, v[GRID].buf, (size_t)n * sizeof(double));
        ok = grid_holds(grid, counts, n, m);
        if (ok) {
            om_link_job job = {.branch = {s, T, v[4].buf, signs, v[2].buf, v[3].buf, traces},
                               .n = n, .m = m, .grid = grid, .q = v[Q].buf, .t = v[T7].buf,
                               .counts = counts, .capacity = capacity, .new_psi = v[NEW_PSI].buf,
                               .new_q = v[NEW_Q].buf, .new_t = v[NEW_T].buf, .members = v[MEMBERS].buf,
                               .paths = v[PATHS].buf};
            int64_t added, paths;
            int status;
            Py_BEGIN_ALLOW_THREADS status = om_link_paths(&job, &added, &paths);
            Py_END_ALLOW_THREADS

            if (status == OM_LINK_NO_MEMORY)
                PyErr_NoMemory();
            else {
                PyObject *items[3] = {PyLong_FromLong(status), PyLong_FromLongLong(added),
                                      PyLong_FromLongLong(paths)};
                result = new_record(linked_type, items, 3);
            }
        }
    }
    if (!ok)
        PyErr_SetString(PyExc_ValueError, "link_paths: sizes of the grid, counts, roots and outputs disagree, or "
                                          "the grid is not increasing within a turn");
    free(grid), free(counts);
    release_buffers(v, V);
done:
    release_fields(f, W_BRANCH + R_N + O_N);
    return result;
}

/* self_motion_tangents(solver, q, t) -> None: t (M x 7, row-major) the tangents at the rows
 * of q (M x 7); a row of NaN where psi does not move along the self-motion. */
static PyObject *om_tangents(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
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
    Py_BEGIN_ALLOW_THREADS om_self_motion_tangents(s, v[0].buf, v[1].buf, rows);
    Py_END_ALLOW_THREADS release_buffers(v, 2);
    Py_RETURN_NONE;
}

int om_paths_init(PyObject *module) {
    if (add_record_type(module, &followed_type, &followed_desc, "Followed") < 0) return -1;
    return add_record_type(module, &linked_type, &linked_desc, "Linked");
}

PyMethodDef om_path_functions[] = {
    {"follow", (PyCFunction)(void (*)(void))om_follow, METH_FASTCALL | METH_KEYWORDS,
     "follow(work, psi, target, min_step) -> Followed(psi, status, steps)"},
    {"link_paths", (PyCFunction)(void (*)(void))om_link, METH_FASTCALL | METH_KEYWORDS,
     "link_paths(work, roots, rows) -> Linked(status, added, paths)"},
    {"self_motion_tangents", (PyCFunction)(void (*)(void))om_tangents, METH_FASTCALL,
     "self_motion_tangents(solver, q, t) -> None"},
    {NULL, NULL, 0, NULL},
};
