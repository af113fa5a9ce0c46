/* The bound of what a climb from a start can reach (om_redundant/redundancy/choice/start_bounds.py's
 * StartBounds.within, whose numpy version, tests/reference/start_bounds.py, is the reference; the
 * same operations in its order): from the cones u_i + L |x - psi_i| of every sample of the
 * start's run within its reach R, of f (column 0) and of each group's functions (the other
 * columns), L the run's slope bounds (the start's row of slopes). Minima and maxima
 * are numpy's (om_least, om_most): a NaN bound is NaN as the reference's, and no start is skipped
 * for it (optimizer.py compares). */
#include "redundancy.h"

typedef om_start_samples start_bounds;

/* The smaller of f's bound row[0] and sum_g w_g min(cap_g, min_j row_j) (the groups summed in
 * their order; 0 without groups). */
static double bound(const start_bounds *s, const double *row) {
    double total = 0.0;
    for (ptrdiff_t g = 0; g < s->G; g++) {
        ptrdiff_t end = g + 1 < s->G ? s->groups[g + 1] : s->columns;
        double least = row[s->groups[g]];
        for (ptrdiff_t j = s->groups[g] + 1; j < end; j++) least = om_least(least, row[j]);
        total = total + s->weights[g] * om_least(s->caps[g], least);
    }
    return om_least(row[0], total);
}

/* The bound of the cell of samples c, c + 1 (slope bounds L): the cones' meeting points, at
 * least the ends. */
static double cell(const start_bounds *s, const double *L, ptrdiff_t c, double *row) {
    const double *u = s->values + c * s->columns, *v = u + s->columns;
    double h = s->psi[c + 1] - s->psi[c];
    for (ptrdiff_t j = 0; j < s->columns; j++) {
        double peak = 0.5 * (u[j] + v[j] + L[j] * h), top = om_most(u[j], v[j]);
        row[j] = om_most(peak, top);
    }
    return bound(s, row);
}

/* The bound beyond sample e (slope bounds L), reach - |psi_e - x| of the reach left. */
static double beyond(const start_bounds *s, const double *L, ptrdiff_t e, double x, double reach, double *row) {
    const double *u = s->values + e * s->columns;
    double left = om_most(reach - fabs(s->psi[e] - x), 0.0);
    for (ptrdiff_t j = 0; j < s->columns; j++) row[j] = u[j] + L[j] * left;
    return bound(s, row);
}

double om_start_cone(const om_start_samples *s, ptrdiff_t k, double reach, double *row) {
    const double *u = s->values + k * s->columns, *L = s->slopes + k * s->columns;
    for (ptrdiff_t j = 0; j < s->columns; j++) row[j] = u[j] + L[j] * reach;
    return bound(s, row);
}

/* Every whole cell within reach, and the cells reach cuts (or the run's ends) each the smaller
 * of its bound and the cut end's; the largest, at least f_k. */
double om_start_bound(const om_start_samples *s, ptrdiff_t k, ptrdiff_t a, ptrdiff_t b, double reach, double *row) {
    ptrdiff_t C = s->columns;
    const double *L = s->slopes + k * C;
    double x = s->psi[k], low = x - reach, high = x + reach;
    ptrdiff_t lo = a, hi = b; /* the samples within reach: lo .. hi (k among them) */
    while (s->psi[lo] < low) lo++;
    while (s->psi[hi] > high) hi--;
    double best = s->values[k * C]; /* f_k */
    for (ptrdiff_t c = lo; c < hi; c++) best = om_most(best, cell(s, L, c, row));
    double cut = beyond(s, L, lo, x, reach, row);
    if (lo > a) cut = om_least(cut, cell(s, L, lo - 1, row));
    best = om_most(best, cut);
    cut = beyond(s, L, hi, x, reach, row);
    if (hi < b) cut = om_least(cut, cell(s, L, hi, row));
    return om_most(best, cut);
}
