/* The climb's QP in one redundancy variable, solved exactly (om_redundant/redundancy/box_qp.py's
 * maximise_1d, whose numpy version is the reference): maximise the concave, piecewise
 * quadratic phi(delta) = sum_g w_g min(cap_g, min_{j in g} v_j + a_j delta) - b delta^2 / 2 over
 * [lower, upper] where every group with a floor keeps its minimum >= floor. The maximiser is a
 * breakpoint (two pieces of a group crossing, a piece crossing its cap), an end, or a
 * segment's stationary point D_k / b (D_k the weighted rates of the uncapped groups' least
 * pieces in the segment); all are evaluated and the first best taken. The multipliers are
 * those of the epigraph's KKT conditions (box_qp.py). Each sum and quotient in box_qp.py's
 * order. */
#include <stdlib.h>

#include "binding.h"

#define TIE 1e-12 /* pieces within this of their group's minimum meet there (box_qp.py) */

typedef struct {
    const double *v, *a, *w, *floor, *cap;
    const int64_t *ends; /* group g's pieces are ends[g] .. ends[g + 1] - 1 */
    Py_ssize_t G;
} qp_groups;

static int compare_doubles(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* The weighted rate of the groups' least pieces at x (0 for a capped group). */
static double rate_at(const qp_groups *q, double x) {
    double slope = 0.0;
    for (Py_ssize_t g = 0; g < q->G; g++) {
        int64_t least = q->ends[g];
        double value = q->v[least] + q->a[least] * x;
        for (int64_t j = least + 1; j < q->ends[g + 1]; j++) {
            double y = q->v[j] + q->a[j] * x;
            if (y < value) value = y, least = j;
        }
        slope += q->w[g] * (value < q->cap[g] ? q->a[least] : 0.0);
    }
    return slope;
}

/* Group g's linearised minimum at x: min_j v_j + a_j x. */
static double group_least(const qp_groups *q, Py_ssize_t g, double x) {
    double least = INFINITY;
    for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) least = fmin(least, q->v[j] + q->a[j] * x);
    return least;
}

/* phi(x). */
static double phi(const qp_groups *q, double b, double x) {
    double value = -0.5 * b * (x * x);
    for (Py_ssize_t g = 0; g < q->G; g++) value += q->w[g] * fmin(q->cap[g], group_least(q, g, x));
    return value;
}

/* The multipliers z at delta (box_qp.py's _multipliers). */
static void multipliers(const qp_groups *q, double b, double delta, double *z, Py_ssize_t n) {
    for (Py_ssize_t j = 0; j < n; j++) z[j] = 0.0;
    double balance = b * delta;
    Py_ssize_t kinks = 0;
    int64_t *falling = PyMem_Malloc((q->G ? q->G : 1) * 2 * sizeof(int64_t)), *rising;
    Py_ssize_t *kink_group = PyMem_Malloc((q->G ? q->G : 1) * sizeof(Py_ssize_t));
    if (!falling || !kink_group) { /* (tiny: cannot fail in practice; leave z at 0) */
        PyMem_Free(falling), PyMem_Free(kink_group);
        return;
    }
    rising = falling + (q->G ? q->G : 1);
    for (Py_ssize_t g = 0; g < q->G; g++) {
        double least = group_least(q, g, delta);
        if (least > q->cap[g] + TIE || q->w[g] == 0.0) continue;
        int64_t first = -1, low = -1, high = -1, count = 0;
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            if (!(q->v[j] + q->a[j] * delta <= least + TIE)) continue;
            if (first < 0) first = j, low = j, high = j;
            if (q->a[j] < q->a[low]) low = j; /* (argmin, argmax: the first extreme) */
            if (q->a[j] > q->a[high]) high = j;
            count++;
        }
        if (count == 1) {
            z[first] = q->w[g];
            balance -= q->w[g] * q->a[first];
        } else
            falling[kinks] = low, rising[kinks] = high, kink_group[kinks++] = g;
    }
    for (Py_ssize_t k = 0; k < kinks; k++) {
        double w = q->w[kink_group[k]], spread = q->a[rising[k]] - q->a[falling[k]];
        double share = balance / (double)kinks;
        z[rising[k]] = spread > 0.0 ? fmin(fmax((share - w * q->a[falling[k]]) / spread, 0.0), w) : w;
        z[falling[k]] = w - z[rising[k]];
    }
    PyMem_Free(falling), PyMem_Free(kink_group);
}

/* The maximiser of phi over [lo, hi] within the floors into *delta, the multipliers into z:
 * 1, or 0 when the floors leave no delta; -1 with MemoryError. */
static int solve(const qp_groups *q, double b, double lo, double hi, double *delta, double *z, Py_ssize_t n) {
    /* the floors: lo <= delta <= hi */
    for (Py_ssize_t g = 0; g < q->G; g++) {
        if (isinf(q->floor[g]) && q->floor[g] < 0.0) continue;
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            double gap = q->floor[g] - q->v[j];
            if (q->a[j] == 0.0) {
                if (gap > 0.0) return 0;
            } else if (q->a[j] > 0.0)
                lo = fmax(lo, gap / q->a[j]);
            else
                hi = fmin(hi, gap / q->a[j]);
        }
    }
    if (!(lo <= hi)) return 0;
    /* the breakpoints within [lo, hi], sorted, each once */
    Py_ssize_t size = 2;
    for (Py_ssize_t g = 0; g < q->G; g++) {
        Py_ssize_t p = q->ends[g + 1] - q->ends[g];
        size += p * p + p;
    }
    double *points = PyMem_Malloc(2 * size * sizeof(double));
    if (!points) {
        PyErr_NoMemory();
        return -1;
    }
    Py_ssize_t m = 0;
    points[m++] = lo, points[m++] = hi;
    for (Py_ssize_t g = 0; g < q->G; g++) {
        for (int64_t i = q->ends[g]; i < q->ends[g + 1]; i++) {
            for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
                double x = (q->v[j] - q->v[i]) / (q->a[i] - q->a[j]);
                if (isfinite(x) && x >= lo && x <= hi) points[m++] = x;
            }
            double x = (q->cap[g] - q->v[i]) / q->a[i];
            if (isfinite(x) && x >= lo && x <= hi) points[m++] = x;
        }
    }
    qsort(points, m, sizeof(double), compare_doubles);
    Py_ssize_t unique = 0;
    for (Py_ssize_t k = 0; k < m; k++)
        if (unique == 0 || points[k] != points[unique - 1]) points[unique++] = points[k];
    /* the candidates: the breakpoints, then each segment's stationary point */
    double *candidates = points, best = -INFINITY;
    Py_ssize_t count = unique;
    *delta = points[0];
    for (Py_ssize_t k = 0; k + 1 < unique; k++) {
        double middle = (points[k] + points[k + 1]) / 2.0;
        candidates[count++] = fmin(fmax(rate_at(q, middle) / b, points[k]), points[k + 1]);
    }
    for (Py_ssize_t k = 0; k < count; k++) {
        double value = phi(q, b, candidates[k]);
        if (value > best || k == 0) best = value, *delta = candidates[k];
    }
    PyMem_Free(points);
    multipliers(q, b, *delta, z, n);
    return 1;
}

/* The linearised objective sum_g w_g min(cap_g, min_j v_j + a_j x), summed in the groups'
 * order (box_qp.py's Pieces.model). */
static double model(const qp_groups *q, double x) {
    double total = 0.0;
    for (Py_ssize_t g = 0; g < q->G; g++) total += q->w[g] * fmin(q->cap[g], group_least(q, g, x));
    return total;
}

/* The arguments both functions read: the pieces of G groups concatenated (v, a; group g's are
 * ends[g] .. ends[g + 1] - 1; a floor of -inf: none), b, lower, upper, and z (n, written):
 * their buffers into views (released by the caller when 0 is returned), -1 with an error. */
static int get_groups(PyObject *const *args, Py_ssize_t nargs, const char *what, Py_buffer *views, qp_groups *q,
                      double *b, double *lo, double *hi) {
    if (check_nargs(nargs, 10, what) < 0) return -1;
    *b = PyFloat_AsDouble(args[6]), *lo = PyFloat_AsDouble(args[7]), *hi = PyFloat_AsDouble(args[8]);
    if (PyErr_Occurred()) return -1;
    const buffer_spec sp[7] = {{F64, -1, 0, "v"},      {F64, -1, 0, "a"},    {I64, -1, 0, "ends"},
                               {F64, -1, 0, "weights"}, {F64, -1, 0, "floors"}, {F64, -1, 0, "caps"},
                               {F64, -1, 1, "z"}};
    PyObject *const objs[7] = {args[0], args[1], args[2], args[3], args[4], args[5], args[9]};
    if (get_buffers(objs, views, sp, 7) < 0) return -1;
    Py_ssize_t n = views[0].len / 8, G = views[3].len / 8;
    *q = (qp_groups){views[0].buf, views[1].buf, views[3].buf, views[4].buf, views[5].buf, views[2].buf, G};
    int bad = views[1].len != n * 8 || views[2].len != (G + 1) * 8 || views[4].len != G * 8 ||
              views[5].len != G * 8 || views[6].len != n * 8 || q->ends[0] != 0 || q->ends[G] != n;
    for (Py_ssize_t g = 0; g < G && !bad; g++) bad = q->ends[g + 1] <= q->ends[g];
    if (bad) {
        release_buffers(views, 7);
        PyErr_Format(PyExc_ValueError, "%s: sizes of the pieces, the groups and z disagree", what);
        return -1;
    }
    return 0;
}

/* maximise_1d(v, a, ends, weights, floors, caps, curvature, lower, upper, z) -> delta or None:
 * z (in place) the pieces' multipliers; None when the floors leave no delta. */
static PyObject *om_maximise_1d(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    Py_buffer v[7];
    qp_groups q;
    double b, lo, hi, delta;
    if (get_groups(args, nargs, "maximise_1d", v, &q, &b, &lo, &hi) < 0) return NULL;
    int found = solve(&q, b, lo, hi, &delta, v[6].buf, v[0].len / 8);
    release_buffers(v, 7);
    if (found < 0) return NULL;
    if (!found) Py_RETURN_NONE;
    return PyFloat_FromDouble(delta);
}

/* step_1d(v, a, ends, weights, floors, caps, curvature, lower, upper, z) -> (delta, gain) or
 * None: the climb's step (box_qp.py's step_1d, the same operations): the pieces that can be
 * their group's least somewhere in the box (v_j - |a_j| r <= min_i v_i + |a_i| r over the
 * group, r = max(-lower, upper)) maximised as maximise_1d does, the model's gain
 * model(delta) - b delta^2 / 2 - model(0) over all pieces, z (in place) every piece's
 * multiplier (0 for those left out). */
static PyObject *om_step_1d(PyObject *mod, PyObject *const *args, Py_ssize_t nargs) {
    Py_buffer v[7];
    qp_groups q;
    double b, lo, hi, delta;
    if (get_groups(args, nargs, "step_1d", v, &q, &b, &lo, &hi) < 0) return NULL;
    Py_ssize_t n = v[0].len / 8, G = q.G;
    double *z = v[6].buf, reach = fmax(-lo, hi);
    double *kept_v = PyMem_Malloc(3 * n * sizeof(double) + (G + 1) * sizeof(int64_t) + n);
    if (!kept_v) {
        release_buffers(v, 7);
        return PyErr_NoMemory();
    }
    double *kept_a = kept_v + n, *kept_z = kept_a + n;
    int64_t *kept_ends = (int64_t *)(kept_z + n);
    uint8_t *keep = (uint8_t *)(kept_ends + G + 1);
    Py_ssize_t m = 0;
    kept_ends[0] = 0;
    int empty = 0;
    for (Py_ssize_t g = 0; g < G; g++) {
        double least = INFINITY;
        for (int64_t j = q.ends[g]; j < q.ends[g + 1]; j++) { /* (a nan propagates, as numpy's minimum) */
            double top = q.v[j] + fabs(q.a[j]) * reach;
            least = least <= top || isnan(least) ? least : top;
        }
        for (int64_t j = q.ends[g]; j < q.ends[g + 1]; j++) {
            keep[j] = q.v[j] - fabs(q.a[j]) * reach <= least;
            if (keep[j]) kept_v[m] = q.v[j], kept_a[m++] = q.a[j];
        }
        kept_ends[g + 1] = m;
        empty |= kept_ends[g + 1] == kept_ends[g];
    }
    if (empty) { /* (only where a piece or the box is not a number) */
        PyMem_Free(kept_v);
        release_buffers(v, 7);
        PyErr_SetString(PyExc_ValueError, "step_1d: a group keeps no piece (a piece or a bound is not a number)");
        return NULL;
    }
    qp_groups kept = {kept_v, kept_a, q.w, q.floor, q.cap, kept_ends, G};
    int found = solve(&kept, b, lo, hi, &delta, kept_z, m);
    PyObject *result = NULL;
    if (found > 0) {
        for (Py_ssize_t j = 0, k = 0; j < n; j++) z[j] = keep[j] ? kept_z[k++] : 0.0;
        double gain = model(&q, delta) - 0.5 * delta * b * delta - model(&q, 0.0);
        result = Py_BuildValue("(dd)", delta, gain);
    } else if (found == 0) {
        result = Py_None;
        Py_INCREF(result);
    }
    PyMem_Free(kept_v);
    release_buffers(v, 7);
    return result;
}

PyMethodDef om_box_qp_functions[] = {
    {"maximise_1d", (PyCFunction)(void (*)(void))om_maximise_1d, METH_FASTCALL,
     "maximise_1d(v, a, ends, weights, floors, caps, curvature, lower, upper, z) -> delta or None"},
    {"step_1d", (PyCFunction)(void (*)(void))om_step_1d, METH_FASTCALL,
     "step_1d(v, a, ends, weights, floors, caps, curvature, lower, upper, z) -> (delta, gain) or None"},
    {NULL, NULL, 0, NULL},
};
