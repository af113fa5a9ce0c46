/* The climb's QP in one redundancy variable, solved exactly (om_redundant/redundancy/choice/box_qp.py's
 * maximise_1d, whose numpy version is the reference): maximise the concave, piecewise
 * quadratic phi(delta) = sum_g w_g min(cap_g, min_{j in g} v_j + a_j delta) - b delta^2 / 2 over
 * [lower, upper] where every group with a floor keeps its minimum >= floor. The maximiser is a
 * breakpoint (two pieces of a group crossing, a piece crossing its cap), an end, or a
 * segment's stationary point D_k / b (D_k the weighted rates of the uncapped groups' least
 * pieces in the segment); all are evaluated and the first best taken. The multipliers are
 * those of the epigraph's KKT conditions (box_qp.py). Each sum and quotient in box_qp.py's
 * order. */
#include <stdlib.h>

#include "redundancy.h"

#define TIE 1e-12 /* pieces within this of their group's minimum meet there (box_qp.py) */

typedef om_qp_groups qp_groups;

static int compare_doubles(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* The weighted rate of the groups' least pieces at x (0 for a capped group). */
static double rate_at(const qp_groups *q, double x) {
    double slope = 0.0;
    for (ptrdiff_t g = 0; g < q->G; g++) {
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
static double group_least(const qp_groups *q, ptrdiff_t g, double x) {
    double least = INFINITY;
    for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) least = fmin(least, q->v[j] + q->a[j] * x);
    return least;
}

/* phi(x). */
static double phi(const qp_groups *q, double b, double x) {
    double value = -0.5 * b * (x * x);
    for (ptrdiff_t g = 0; g < q->G; g++) value += q->w[g] * fmin(q->cap[g], group_least(q, g, x));
    return value;
}

/* The multipliers z at delta (box_qp.py's _multipliers). */
static void multipliers(const qp_groups *q, double b, double delta, double *z, ptrdiff_t n) {
    for (ptrdiff_t j = 0; j < n; j++) z[j] = 0.0;
    double balance = b * delta;
    ptrdiff_t kinks = 0;
    int64_t *falling = malloc((q->G ? q->G : 1) * 2 * sizeof(int64_t)), *rising;
    ptrdiff_t *kink_group = malloc((q->G ? q->G : 1) * sizeof(ptrdiff_t));
    if (!falling || !kink_group) { /* (tiny: cannot fail in practice; leave z at 0) */
        free(falling), free(kink_group);
        return;
    }
    rising = falling + (q->G ? q->G : 1);
    for (ptrdiff_t g = 0; g < q->G; g++) {
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
    for (ptrdiff_t k = 0; k < kinks; k++) {
        double w = q->w[kink_group[k]], spread = q->a[rising[k]] - q->a[falling[k]];
        double share = balance / (double)kinks;
        z[rising[k]] = spread > 0.0 ? fmin(fmax((share - w * q->a[falling[k]]) / spread, 0.0), w) : w;
        z[falling[k]] = w - z[rising[k]];
    }
    free(falling), free(kink_group);
}

/* The maximiser of phi over [lo, hi] within the floors into *delta, the multipliers into z:
 * OM_QP_FOUND, OM_QP_NONE when the floors leave no delta, OM_QP_NO_MEMORY. */
static int solve(const qp_groups *q, double b, double lo, double hi, double *delta, double *z, ptrdiff_t n) {
    /* the floors: lo <= delta <= hi */
    for (ptrdiff_t g = 0; g < q->G; g++) {
        if (isinf(q->floor[g]) && q->floor[g] < 0.0) continue;
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            double gap = q->floor[g] - q->v[j];
            if (q->a[j] == 0.0) {
                if (gap > 0.0) return OM_QP_NONE;
            } else if (q->a[j] > 0.0)
                lo = fmax(lo, gap / q->a[j]);
            else
                hi = fmin(hi, gap / q->a[j]);
        }
    }
    if (!(lo <= hi)) return OM_QP_NONE;
    /* the breakpoints within [lo, hi], sorted, each once */
    ptrdiff_t size = 2;
    for (ptrdiff_t g = 0; g < q->G; g++) {
        ptrdiff_t p = q->ends[g + 1] - q->ends[g];
        size += p * p + p;
    }
    double *points = malloc(2 * size * sizeof(double));
    if (!points) return OM_QP_NO_MEMORY;
    ptrdiff_t m = 0;
    points[m++] = lo, points[m++] = hi;
    for (ptrdiff_t g = 0; g < q->G; g++) {
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
    ptrdiff_t unique = 0;
    for (ptrdiff_t k = 0; k < m; k++)
        if (unique == 0 || points[k] != points[unique - 1]) points[unique++] = points[k];
    /* the candidates: the breakpoints, then each segment's stationary point */
    double *candidates = points, best = -INFINITY;
    ptrdiff_t count = unique;
    *delta = points[0];
    for (ptrdiff_t k = 0; k + 1 < unique; k++) {
        double middle = (points[k] + points[k + 1]) / 2.0;
        candidates[count++] = fmin(fmax(rate_at(q, middle) / b, points[k]), points[k + 1]);
    }
    for (ptrdiff_t k = 0; k < count; k++) {
        double value = phi(q, b, candidates[k]);
        if (value > best || k == 0) best = value, *delta = candidates[k];
    }
    free(points);
    multipliers(q, b, *delta, z, n);
    return OM_QP_FOUND;
}

/* The linearised objective sum_g w_g min(cap_g, min_j v_j + a_j x), summed in the groups'
 * order (box_qp.py's Pieces.model). */
static double model(const qp_groups *q, double x) {
    double total = 0.0;
    for (ptrdiff_t g = 0; g < q->G; g++) total += q->w[g] * fmin(q->cap[g], group_least(q, g, x));
    return total;
}


int om_qp_maximise(const om_qp_groups *q, double b, double lo, double hi, double *delta, double *z) {
    return solve(q, b, lo, hi, delta, z, q->G ? q->ends[q->G] : 0);
}

/* The pieces that can be their group's least somewhere in the box (v_j - |a_j| r <= min_i v_i +
 * |a_i| r over the group, r = max(-lower, upper)) maximised as om_qp_maximise does (box_qp.py's
 * step_1d, the same operations). */
int om_qp_step(const om_qp_groups *q, double b, double lo, double hi, double *delta, double *gain, double *z) {
    ptrdiff_t G = q->G, n = G ? q->ends[G] : 0;
    double reach = fmax(-lo, hi);
    double *kept_v = malloc(3 * n * sizeof(double) + (G + 1) * sizeof(int64_t) + n);
    if (!kept_v) return OM_QP_NO_MEMORY;
    double *kept_a = kept_v + n, *kept_z = kept_a + n;
    int64_t *kept_ends = (int64_t *)(kept_z + n);
    uint8_t *keep = (uint8_t *)(kept_ends + G + 1);
    ptrdiff_t m = 0;
    kept_ends[0] = 0;
    int empty = 0;
    for (ptrdiff_t g = 0; g < G; g++) {
        double least = INFINITY;
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) { /* (a nan propagates, as numpy's minimum) */
            double top = q->v[j] + fabs(q->a[j]) * reach;
            least = least <= top || isnan(least) ? least : top;
        }
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            keep[j] = q->v[j] - fabs(q->a[j]) * reach <= least;
            if (keep[j]) kept_v[m] = q->v[j], kept_a[m++] = q->a[j];
        }
        kept_ends[g + 1] = m;
        empty |= kept_ends[g + 1] == kept_ends[g];
    }
    if (empty) { /* (only where a piece or the box is not a number) */
        free(kept_v);
        return OM_QP_EMPTY_GROUP;
    }
    om_qp_groups kept = {kept_v, kept_a, q->w, q->floor, q->cap, kept_ends, G};
    int found = solve(&kept, b, lo, hi, delta, kept_z, m);
    if (found == OM_QP_FOUND) {
        for (ptrdiff_t j = 0, k = 0; j < n; j++) z[j] = keep[j] ? kept_z[k++] : 0.0;
        *gain = model(q, *delta) - 0.5 * *delta * b * *delta - model(q, 0.0);
    }
    free(kept_v);
    return found;
}
