/* The QP in one redundancy variable, of the climb (om_redundant/redundancy/choice/climb.py)
 * and of the tracking step (tracking.c): maximise the concave, piecewise quadratic
 *     phi(delta) = sum_g w_g min(cap_g, min_{j in g} v_j + a_j delta) - b delta^2 / 2
 * over [lower, upper] where every group with a floor keeps its minimum >= floor. phi's right
 * derivative is non-increasing, and bisection on its sign gives the maximiser to rounding
 * (the kink or stationary point where it changes sign), reading only the pieces that can be
 * their group's least somewhere in the interval (contenders). The multipliers are those of the
 * epigraph's KKT conditions (box_qp.py's module docstring). */
#include <stdlib.h>

#include "redundancy.h"

#define BISECTIONS 80
#define TIE 1e-12 /* pieces within this of their group's minimum meet there (the multipliers) */
/* problems of at most these many pieces and groups (every tracking step's) need no allocation */
#define STACK_PIECES OM_TRACK_MAX_PIECES
#define STACK_GROUPS 8

typedef om_qp_groups qp_groups;

/* [*lo, *hi] cut to where every group with a floor keeps each piece >= floor; false where
 * nothing is left. */
static bool floors(const qp_groups *q, double *lo, double *hi) {
    for (ptrdiff_t g = 0; g < q->G; g++) {
        double floor = q->floor[g];
        if (floor == -INFINITY) continue;
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            double a = q->a[j], gap = floor - q->v[j];
            if (a > 0.0) *lo = fmax(*lo, gap / a);
            else if (a < 0.0) *hi = fmin(*hi, gap / a);
            else if (gap > 0.0) return false;
        }
    }
    return *lo <= *hi;
}

/* The pieces of q that can be their group's least somewhere in [lo, hi] into kept (values v,
 * rates a, ends; the groups' numbers shared), index[k] the piece of q that kept piece k is. A
 * piece is left out where its least value there exceeds the least of the group's greatest
 * values (each at an end: the pieces are linear) by more than the rounding of v + a d can make
 * up (at most 2^-52 (|v| + |a d|) each, so 1e-12 of both pieces' magnitudes is ample): the
 * computed v_j(d) then exceeds that other piece's at every d of [lo, hi], and slope's minima,
 * its tie-breaks and so its every value are q's. A group keeps at least the piece of its least
 * greatest value; every piece of a group that is not a number. */
static void contenders(const qp_groups *q, double lo, double hi, double *v, double *a, int64_t *ends,
                       int64_t *index, qp_groups *kept) {
    double reach = fmax(fabs(lo), fabs(hi));
    int64_t m = 0;
    ends[0] = 0;
    for (ptrdiff_t g = 0; g < q->G; g++) {
        double least_top = INFINITY, size = 0.0;
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            double top = fmax(q->v[j] + q->a[j] * lo, q->v[j] + q->a[j] * hi);
            if (top < least_top) least_top = top, size = fabs(q->v[j]) + fabs(q->a[j]) * reach;
        }
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            double bottom = fmin(q->v[j] + q->a[j] * lo, q->v[j] + q->a[j] * hi);
            double slack = 1e-12 * (1.0 + fabs(q->v[j]) + fabs(q->a[j]) * reach + size);
            if (bottom - least_top > slack) continue; /* (NaN: kept) */
            v[m] = q->v[j], a[m] = q->a[j], index[m++] = j;
        }
        ends[g + 1] = m;
    }
    *kept = (qp_groups){v, a, q->w, q->floor, q->cap, ends, q->G};
}

/* phi's right derivative at d: each group's least piece there (of equal ones, the least rate),
 * its weighted rate where the group is below its cap (at the cap: where it falls), less b d. */
static double slope(const qp_groups *q, double b, double d) {
    double D = -b * d;
    for (ptrdiff_t g = 0; g < q->G; g++) {
        double low = INFINITY, rate = 0.0;
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            double value = q->v[j] + q->a[j] * d;
            if (value < low || (value == low && q->a[j] < rate)) low = value, rate = q->a[j];
        }
        if (low < q->cap[g] || (low == q->cap[g] && rate < 0.0)) D += q->w[g] * rate;
    }
    return D;
}

/* The maximiser of phi over [lo, hi] (within the floors): the end where phi falls (rises)
 * throughout, else the bisection's last point where the right derivative is positive. */
static double maximiser(const qp_groups *q, double b, double lo, double hi) {
    if (slope(q, b, lo) <= 0.0) return lo;
    if (slope(q, b, hi) >= 0.0) return hi;
    double left = lo, right = hi;
    for (int k = 0; k < BISECTIONS && right - left > 0.0; k++) {
        double mid = 0.5 * (left + right);
        if (mid == left || mid == right) break;
        if (slope(q, b, mid) > 0.0) left = mid;
        else right = mid;
    }
    return left;
}

/* Group g's linearised minimum at x: min_j v_j + a_j x. */
static double group_least(const qp_groups *q, ptrdiff_t g, double x) {
    double least = INFINITY;
    for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) least = fmin(least, q->v[j] + q->a[j] * x);
    return least;
}

/* The multipliers z (one per piece of q) at delta: each uncapped group's weight on its least
 * piece, or at a kink split between the least and the most increasing of the pieces that meet
 * there so that the slope balances b delta. kink_group, falling, rising: room for G each. */
static void multipliers(const qp_groups *q, double b, double delta, double *z, int64_t *kink_group,
                        int64_t *falling, int64_t *rising) {
    for (int64_t j = 0; j < q->ends[q->G]; j++) z[j] = 0.0;
    double balance = b * delta;
    int64_t kinks = 0;
    for (ptrdiff_t g = 0; g < q->G; g++) {
        double least = group_least(q, g, delta);
        if (least > q->cap[g] + TIE || q->w[g] == 0.0) continue;
        int64_t first = -1, low = -1, high = -1, count = 0;
        for (int64_t j = q->ends[g]; j < q->ends[g + 1]; j++) {
            if (!(q->v[j] + q->a[j] * delta <= least + TIE)) continue;
            if (first < 0) first = j, low = j, high = j;
            if (q->a[j] < q->a[low]) low = j; /* (the first extremes) */
            if (q->a[j] > q->a[high]) high = j;
            count++;
        }
        if (count == 1) {
            z[first] = q->w[g];
            balance -= q->w[g] * q->a[first];
        } else if (count > 1)
            falling[kinks] = low, rising[kinks] = high, kink_group[kinks++] = g;
    }
    for (int64_t k = 0; k < kinks; k++) {
        double w = q->w[kink_group[k]], spread = q->a[rising[k]] - q->a[falling[k]];
        double share = balance / (double)kinks;
        z[rising[k]] = spread > 0.0 ? fmin(fmax((share - w * q->a[falling[k]]) / spread, 0.0), w) : w;
        z[falling[k]] = w - z[rising[k]];
    }
}

/* The linearised objective sum_g w_g min(cap_g, min_j v_j + a_j x), summed in the groups' order. */
static double model(const qp_groups *q, double x) {
    double total = 0.0;
    for (ptrdiff_t g = 0; g < q->G; g++) total += q->w[g] * fmin(q->cap[g], group_least(q, g, x));
    return total;
}

int om_qp_step(const om_qp_groups *q, double b, double lo, double hi, double *delta, double *gain, double *z) {
    if (!floors(q, &lo, &hi)) return OM_QP_NONE;
    ptrdiff_t n = q->ends[q->G], G = q->G;
    /* scratch: the kept pieces' v, a, z (n each); their ends (G + 1), index (n), the kinks (3 G) */
    double numbers[3 * STACK_PIECES];
    int64_t indices[STACK_PIECES + 4 * STACK_GROUPS + 1];
    bool small = n <= STACK_PIECES && G <= STACK_GROUPS;
    double *kept_v = small ? numbers : malloc(3 * (size_t)n * sizeof(double) + 1);
    int64_t *ends = small ? indices : malloc(((size_t)n + 4 * (size_t)G + 1) * sizeof(int64_t));
    if (!kept_v || !ends) {
        if (!small) free(kept_v), free(ends);
        return OM_QP_NO_MEMORY;
    }
    double *kept_a = kept_v + n, *kept_z = kept_a + n;
    int64_t *index = ends + G + 1, *kinks = index + n;
    qp_groups kept;
    contenders(q, lo, hi, kept_v, kept_a, ends, index, &kept);
    *delta = maximiser(&kept, b, lo, hi);
    if (z != NULL) {
        multipliers(&kept, b, *delta, kept_z, kinks, kinks + G, kinks + 2 * G);
        for (ptrdiff_t j = 0; j < n; j++) z[j] = 0.0;
        for (int64_t k = 0; k < ends[G]; k++) z[index[k]] = kept_z[k];
    }
    if (gain != NULL) *gain = model(q, *delta) - 0.5 * *delta * b * *delta - model(q, 0.0);
    if (!small) free(kept_v), free(ends);
    return OM_QP_FOUND;
}
