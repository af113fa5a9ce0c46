/* The Solver's batch methods: solve_rows and solve_all_rows, rows start:stop of a batch's
 * arrays (om_redundant._core.SolveBatch, SolveAllBatch), which OMSolver.solve_batch and
 * solve_all_batch hand to their threads (om_redundant/ik/threads.py). */
#include <string.h>

#include "binding.h"

/* A batch's rows start:stop and inputs: T (M, 4, 4) from rows[0] into v[0], signs (M, k)
 * int64 and redundancy (M, r) from rows[1], rows[2] into v[1], v[2], start and stop from
 * rows[3], rows[4], and the outputs outs[i] by specs[i] (n_out <= OM_MAX_BATCH_OUTPUTS of
 * them; entries given per row, times M here) into v[3 + i]; the rows' signs, each -1 or +1,
 * copied into *signs (k per row from row start on; PyMem_Free it), for the caller's array
 * may change while the GIL is released and the kernels take a sign's value as given.
 * Returns M, or -1 with a TypeError or ValueError (nothing acquired). */
enum { OM_MAX_BATCH_OUTPUTS = 8 };
static Py_ssize_t get_rows(const om_solver_data *s, PyObject *const *rows, PyObject *const *outs,
                           const buffer_spec *specs, int n_out, Py_buffer *v, Py_ssize_t *start, Py_ssize_t *stop,
                           int64_t **signs) {
    *start = PyLong_AsSsize_t(rows[3]), *stop = PyLong_AsSsize_t(rows[4]);
    if (PyErr_Occurred()) return -1;
    if (get_buffer(rows[0], &v[0], F64, -1, 0, "T") < 0) return -1;
    Py_ssize_t m = v[0].len / (16 * 8);
    if (v[0].len != m * 16 * 8 || *start < 0 || *stop > m || *start > *stop) {
        PyErr_SetString(PyExc_ValueError, "T must be (M, 4, 4) and 0 <= start <= stop <= M");
        release_buffers(v, 1);
        return -1;
    }
    PyObject *objs[2 + OM_MAX_BATCH_OUTPUTS] = {rows[1], rows[2]};
    buffer_spec all[2 + OM_MAX_BATCH_OUTPUTS] = {{I64, m * s->n_signs, 0, "signs"},
                                                 {F64, m * s->n_redundancy, 0, "redundancy"}};
    for (int i = 0; i < n_out; i++) {
        objs[2 + i] = outs[i];
        all[2 + i] = specs[i];
        all[2 + i].n *= m;
    }
    if (get_buffers(objs, v + 1, all, 2 + n_out) < 0) {
        release_buffers(v, 1);
        return -1;
    }
    Py_ssize_t n = (*stop - *start) * s->n_signs;
    const int64_t *given = (const int64_t *)v[1].buf + *start * s->n_signs;
    *signs = PyMem_Malloc((size_t)(n + 1) * sizeof(int64_t));
    if (!*signs || copy_signs(given, n, *signs) < 0) {
        if (!*signs) PyErr_NoMemory();
        PyMem_Free(*signs);
        release_buffers(v, 3 + n_out);
        return -1;
    }
    return m;
}

/* The fields of solve_rows' batch (om_redundant._core.SolveBatch) it reads. */
enum { SB_T, SB_SIGNS, SB_REDUNDANCY, SB_HINTS, SB_Q, SB_STATUS, SB_POSITION, SB_ORIENTATION, SB_EVALUATIONS,
       SB_WITHIN, SB_N };
static const char *const solve_batch_names[SB_N] = {"T", "signs", "redundancy", "hints", "q", "status",
                                                    "position_error", "orientation_error", "evaluations",
                                                    "within_limits"};

/* solve_rows(batch, start, stop): rows start:stop of a batch (om_redundant._core.SolveBatch):
 * T (M, 4, 4), signs (M, k) int64, redundancy (M, r), hints (M, dof) or None in; q (M, dof),
 * status (M,) int64, position_error (M,), orientation_error (M,), evaluations (M,) int64 and
 * within_limits (M,) bool out, each row's as solve's. */
PyObject *om_solver_solve_rows(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    PyObject *w[SB_N];
    if (!s || check_nargs(nargs, 3, "solve_rows") < 0 || get_fields(args[0], solve_batch_names, SB_N, w, "solve_rows' batch") < 0)
        return NULL;
    int dof = s->dof, k = s->n_signs, nr = s->n_redundancy, n_out = w[SB_HINTS] != Py_None ? 7 : 6;
    PyObject *rows[5] = {w[SB_T], w[SB_SIGNS], w[SB_REDUNDANCY], args[1], args[2]};
    PyObject *outs[7] = {w[SB_Q],           w[SB_STATUS],      w[SB_POSITION], w[SB_ORIENTATION],
                         w[SB_EVALUATIONS], w[SB_WITHIN],      w[SB_HINTS]};
    const buffer_spec specs[7] = {{F64, dof, 1, "q"},           {I64, 1, 1, "status"},
                                  {F64, 1, 1, "position_error"}, {F64, 1, 1, "orientation_error"},
                                  {I64, 1, 1, "evaluations"},   {U8, 1, 1, "within_limits"},
                                  {F64, dof, 0, "hints"}};
    Py_buffer v[10]; /* T, signs, redundancy, the six outputs, and the hints last */
    Py_ssize_t start, stop;
    int64_t *signs;
    PyObject *result = NULL;
    if (get_rows(s, rows, outs, specs, n_out, v, &start, &stop, &signs) < 0) goto done;
    const double *Tb = v[0].buf, *rb = v[2].buf, *hb = n_out == 7 ? v[9].buf : NULL;
    double *qb = v[3].buf, *position = v[5].buf, *orientation = v[6].buf;
    int64_t *status = v[4].buf, *evaluations = v[7].buf;
    uint8_t *within = v[8].buf;
    Py_BEGIN_ALLOW_THREADS for (Py_ssize_t i = start; i < stop; i++) {
        om_result r = om_solve_one(s, Tb + 16 * i, signs + k * (i - start), rb + nr * i, hb ? hb + dof * i : NULL,
                                   qb + dof * i, NULL, NULL);
        status[i] = r.status;
        position[i] = r.position_error;
        orientation[i] = r.orientation_error;
        evaluations[i] = r.evaluations;
        within[i] = r.within_limits;
    }
    Py_END_ALLOW_THREADS release_buffers(v, 3 + n_out);
    PyMem_Free(signs);
    result = Py_NewRef(Py_None);
done:
    release_fields(w, SB_N);
    return result;
}


/* The fields of solve_all_rows' batch (om_redundant._core.SolveAllBatch) it reads. */
enum { SA_T, SA_SIGNS, SA_REDUNDANCY, SA_BAND, SA_Q, SA_COUNT, SA_EVALUATIONS, SA_POSITION, SA_ORIENTATION,
       SA_WITHIN, SA_TRACES, SA_N };
static const char *const solve_all_batch_names[SA_N] = {"T", "signs", "redundancy", "band", "q", "count",
                                                        "evaluations", "position_error", "orientation_error",
                                                        "within_limits", "traces"};

/* solve_all_rows(batch, start, stop): om_solve_all of rows start:stop of a batch
 * (om_redundant._core.SolveAllBatch): T (M, 4, 4), signs (M, k) int64, redundancy (M, r),
 * band (M,) bool (whether a row without a root of its own searches the band) in; q (M,
 * MAX_ROOTS, dof), count (M,) int64, evaluations (M,) int64, and per root position_error,
 * orientation_error (M, MAX_ROOTS) and within_limits (M, MAX_ROOTS) bool out, each row's as
 * solve_all's (the entries beyond a row's count left as they were); the self-motion the rows
 * traced kept in traces (None: dropped), each ELBOW sign's first (om_torus_memo_take: the GIL
 * held, so the calls of the batch's threads take turns). */
PyObject *om_solver_solve_all_rows(om_Solver *self, PyObject *const *args, Py_ssize_t nargs) {
    const om_solver_data *s = om_solver_ready(self);
    PyObject *w[SA_N];
    if (!s || check_nargs(nargs, 3, "solve_all_rows") < 0 ||
        get_fields(args[0], solve_all_batch_names, SA_N, w, "solve_all_rows' batch") < 0)
        return NULL;
    int dof = s->dof, k = s->n_signs, nr = s->n_redundancy;
    PyObject *rows[5] = {w[SA_T], w[SA_SIGNS], w[SA_REDUNDANCY], args[1], args[2]};
    PyObject *outs[7] = {w[SA_Q],        w[SA_COUNT],   w[SA_EVALUATIONS], w[SA_POSITION],
                         w[SA_ORIENTATION], w[SA_WITHIN], w[SA_BAND]};
    const buffer_spec specs[7] = {{F64, OM_MAX_ROOTS * dof, 1, "q"},      {I64, 1, 1, "count"},
                                  {I64, 1, 1, "evaluations"},             {F64, OM_MAX_ROOTS, 1, "position_error"},
                                  {F64, OM_MAX_ROOTS, 1, "orientation_error"}, {U8, OM_MAX_ROOTS, 1, "within_limits"},
                                  {U8, 1, 0, "band"}};
    Py_buffer v[10];
    Py_ssize_t start, stop;
    int64_t *signs;
    PyObject *result = NULL;
    om_torus_memo *traces = om_traces_of(w[SA_TRACES], s, "solve_all_rows");
    if (PyErr_Occurred() || get_rows(s, rows, outs, specs, 7, v, &start, &stop, &signs) < 0) goto done;
    const double *Tb = v[0].buf, *rb = v[2].buf;
    double *roots = v[3].buf, *position = v[6].buf, *orientation = v[7].buf;
    int64_t *count = v[4].buf, *evaluations = v[5].buf;
    uint8_t *within = v[8].buf;
    const uint8_t *band = v[9].buf;
    /* Neighbouring rows that differ in the SHOULDER sign alone share the circle's candidates,
     * and the rows' scans of one pose the model's parts at their samples (the memo), the
     * torus' grid the lifted residual's terms (the torus memo). */
    om_scan_cache cache = {.valid = false, .capacity = OM_SCAN_CAPACITY(s->scan_points)};
    Py_BEGIN_ALLOW_THREADS cache.candidates = malloc((size_t)cache.capacity * sizeof(double));
    cache.memo = om_scan_memo_new(s);
    cache.torus_memo = om_torus_memo_new(s);
    for (Py_ssize_t i = start; i < stop; i++) {
        double info[OM_MAX_ROOTS * 3];
        count[i] = om_solve_all(s, Tb + 16 * i, signs + k * (i - start), rb + nr * i, roots + OM_MAX_ROOTS * dof * i,
                                info, &evaluations[i], band[i], cache.candidates ? &cache : NULL);
        for (int r = 0; r < count[i]; r++) om_put_root_info(info + 3 * r, OM_MAX_ROOTS * i + r, position, orientation, within);
    }
    free(cache.candidates);
    om_scan_memo_free(cache.memo);
    Py_END_ALLOW_THREADS om_torus_memo_take(traces, cache.torus_memo);
    om_torus_memo_free(cache.torus_memo);
    release_buffers(v, 10);
    PyMem_Free(signs);
    result = Py_NewRef(Py_None);
done:
    release_fields(w, SA_N);
    return result;
}
