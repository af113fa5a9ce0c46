/* The cell test of the global choose's solution paths (om_redundant/redundancy/paths/linking.py's
 * _surprise): the feasibility functions g_j of a point and their rates along psi, and where
 * their cubic Hermite models between two neighbouring points predict a feasibility that the
 * ends do not explain. (Its binding: csrc/binding/cells.c, whose docstrings say what each
 * answers.)
 *
 * The looks model each g_j along the cell's chord (om_chord_spans), not psi: at a fold, where a
 * path turns back in psi, q - q_f ~ (psi_f - psi)^(1/2), and a model in psi takes the end's
 * rate, about 1e4-1e10, as a cubic's slope, which swings by 4/27 of the rate times the span
 * inside the cell: a surprise in nearly every cell that ends at a fold, which was halved
 * towards the fold until shorter than END_TOLERANCE, a follow per half (on the Sawyer, 85 of
 * the 128 looks a pose that took a sample). Along the chord the joints move at the chord's length at both ends, a
 * fold's too (s, the chord's parameter, goes as (psi_f - psi)^(1/2) there); where the path is
 * smooth in psi its speed is |dq/dpsi| to first order in the cell, so there the models are
 * those in psi to that order. */
#include "om_paths.h"

enum { P_REACH, P_CAP, P_FLOOR, P_N }; /* clearance: 2 d_cap, d_cap, d_min / d_cap */

/* objective.py's Group.constraints of the margin and clearance groups at each of the M rows
 * q (M x dof) with dq/dpsi = t (M x dof), the pairs' distances (M x P) and gradients
 * (M x P x dof), into g and dg (M x (L + P)): per limited joint the smaller of
 * (q_i - l_i)/h_i and (u_i - q_i)/h_i with its rate; then per pair d_k/d_cap - d_min/d_cap
 * with its rate grad d_k . t / d_cap, a pair at 2 d_cap or more taken as 2 d_cap with rate 0
 * when some pair of the row is nearer (objective.py's _clearance). */
static void row_pieces(ptrdiff_t dof, ptrdiff_t L, ptrdiff_t P, const double *q, const double *t, const double *d,
                       const double *grad, const int64_t *limited, const double *lower, const double *upper,
                       const double *half, const double *num, double *g, double *dg) {
    for (ptrdiff_t i = 0; i < L; i++) {
        int64_t j = limited[i];
        double a = (q[j] - lower[i]) / half[i], b = (upper[i] - q[j]) / half[i], s = 1.0 / half[i];
        if (a <= b)
            g[i] = a - 0.0, dg[i] = s * t[j];
        else
            g[i] = b - 0.0, dg[i] = -s * t[j];
    }
    double least = INFINITY;
    for (ptrdiff_t k = 0; k < P; k++) least = fmin(least, d[k]);
    int capped = least < num[P_REACH]; /* then pairs from 2 d_cap on count as 2 d_cap, flat */
    for (ptrdiff_t k = 0; k < P; k++) {
        double *gk = g + L + k, *dgk = dg + L + k;
        if (capped && !(d[k] < num[P_REACH])) {
            *gk = num[P_REACH] / num[P_CAP] - num[P_FLOOR], *dgk = 0.0;
            continue;
        }
        double rate = 0.0;
        for (ptrdiff_t j = 0; j < dof; j++) rate += grad[k * dof + j] / num[P_CAP] * t[j];
        *gk = d[k] / num[P_CAP] - num[P_FLOOR], *dgk = rate;
    }
}

void om_pieces(ptrdiff_t dof, ptrdiff_t M, ptrdiff_t L, ptrdiff_t P, const double *q, const double *t,
               const double *d, const double *grad, const int64_t *limited, const double *lower,
               const double *upper, const double *half, const double *numbers, double *g, double *dg) {
    for (ptrdiff_t m = 0; m < M; m++)
        row_pieces(dof, L, P, q + m * dof, t + m * dof, d + m * P, grad + m * P * dof, limited, lower, upper, half,
                   numbers, g + m * (L + P), dg + m * (L + P));
}

/* (om_paths.h) */
void om_chord_spans(int dof, const uint8_t *cyclic, const double *qa, const double *ta, const double *qb,
                    const double *tb, double spans[2]) {
    double chord = 0.0, speed_a = 0.0, speed_b = 0.0;
    for (int i = 0; i < dof; i++) {
        double m = qb[i] - qa[i];
        if (cyclic[i]) m = om_wrap(m);
        chord += m * m, speed_a += ta[i] * ta[i], speed_b += tb[i] * tb[i];
    }
    chord = sqrt(chord);
    spans[0] = speed_a > 0.0 ? chord / sqrt(speed_a) : 0.0;
    spans[1] = speed_b > 0.0 ? chord / sqrt(speed_b) : 0.0;
}

/* Piece j's model at the basis point k. */
static inline double _model(const om_cell_models *c, ptrdiff_t j, ptrdiff_t k)
{
    ptrdiff_t N = c->N;
    return c->ga[j] * c->H[k] + c->da[j] * c->span_a * c->H[N + k] + c->gb[j] * c->H[2 * N + k] +
           c->db[j] * c->span_b * c->H[3 * N + k];
}

/* Piece j's largest move of a model from the ends' range over the cell: 4/27 (|span_a da| +
 * |span_b db|) (binding/cells.c: cell_looks' quiet bound). */
static inline double _spread(const om_cell_models *c, ptrdiff_t j)
{
    return 4.0 / 27.0 * (fabs(c->span_a * c->da[j]) + fabs(c->span_b * c->db[j]));
}

/* Whether piece j's model stays above `slack` over the cell by cell_looks' quiet bound. */
static inline bool _calm(const om_cell_models *c, ptrdiff_t j, double slack)
{
    return fmin(c->ga[j], c->gb[j]) - _spread(c, j) > slack;
}

/* (om_paths.h) The pattern's surprise (binding/cells.c: surprise) of the cell c with ends feasible
 * fa, fb: the fraction, or -1 where there is none; live: room for c->n piece indices. */
double om_surprise(const om_cell_models *c, int fa, int fb, double slack, ptrdiff_t *live)
{
    ptrdiff_t n = c->n, N = c->N, m = 0;
    for (ptrdiff_t j = 0; j < n; j++)
        if (!_calm(c, j, slack)) live[m++] = j;
    ptrdiff_t changes[2], count = 0, allowed = fa != fb;
    int previous = fa;
    for (ptrdiff_t k = 0; k <= N && count < 2; k++) { /* (the first two changes tell) */
        int feasible = fb;
        if (k < N) {
            feasible = 1;
            for (ptrdiff_t i = 0; i < m && feasible; i++) feasible = _model(c, live[i], k) >= 0.0;
        }
        if (feasible != previous) changes[count++] = k;
        previous = feasible;
    }
    if (count <= allowed) return -1.0;
    return (double)(changes[0] + 1 + changes[1]) / 2.0 / (double)(N + 1);
}

/* Whether the cell c with ends feasible fa, fb is quiet by the bounds of cell_looks. The
 * minimum and maximum propagate NaN as numpy's do. */
static bool _quiet(const om_cell_models *c, int fa, int fb, double slack)
{
    if (fa != fb) return false;
    for (ptrdiff_t j = 0; j < c->n; j++) {
        double ga = c->ga[j], gb = c->gb[j], spread = _spread(c, j) + slack;
        if (fa && !(om_least(ga, gb) - spread > 0.0)) return false; /* a model may dip */
        if (!fa && om_most(ga, gb) + spread < 0.0) return true;    /* one stays below */
    }
    return fa;
}

/* The looks of the cells of one path, samples a .. b - 1 of s (cell k: samples k, k + 1),
 * into first (binding/cells.c: cell_looks' docstring); live: room for n piece indices. */
void om_path_looks(const om_cell_samples *s, ptrdiff_t a, ptrdiff_t b, ptrdiff_t dof, ptrdiff_t n,
                        const uint8_t *cyclic, double fine, double slack, const double *H, ptrdiff_t N,
                        double *first, ptrdiff_t *live)
{
    for (ptrdiff_t k = a; k + 1 < b; k++) {
        const double *g = s->g, *dg = s->dg, *q = s->q + k * dof, *t = s->t + k * dof;
        double spans[2];
        om_chord_spans((int)dof, cyclic, q, t, q + dof, t + dof, spans);
        om_cell_models c = {g + k * n, dg + k * n, g + (k + 1) * n, dg + (k + 1) * n, H, spans[0], spans[1], n, N};
        int fa = s->feasible[k], fb = s->feasible[k + 1];
        double step = om_largest_joint_step((int)dof, q, q + dof, cyclic);
        if (step <= fine && _quiet(&c, fa, fb, slack))
            first[k] = NAN;
        else if (step > fine)
            first[k] = 0.5;
        else {
            double t = n ? om_surprise(&c, fa, fb, slack, live) : -1.0;
            first[k] = t < 0.0 ? NAN : t;
        }
    }
    if (b > a) first[b - 1] = NAN; /* (the path's last sample starts no cell) */
}

/* (om_paths.h) The first of the N points s_k = (k + 1) / (N + 1) where a model is negative,
 * refined by the secant of the most negative one from the point before (binding/cells.c:
 * crossing); a piece that surprise's bound keeps positive is skipped. */
double om_crossing(const om_cell_models *c) {
    ptrdiff_t n = c->n, N = c->N;
    double found = -1.0;
    ptrdiff_t first = N; /* the first point where a model is negative */
    ptrdiff_t j_first = -1;
    double m_first = 0.0;
    for (ptrdiff_t j = 0; j < n; j++) {
        if (_calm(c, j, 0.0)) continue;
        for (ptrdiff_t k = 0; k < N && k <= first; k++) { /* (up to the first found so far) */
            double model = _model(c, j, k);
            if (model < 0.0) {
                if (k < first || model < m_first) first = k, j_first = j, m_first = model;
                break;
            }
        }
    }
    if (j_first >= 0) {
        ptrdiff_t k = first;
        double s1 = (double)(k + 1) / (double)(N + 1), s0 = (double)k / (double)(N + 1);
        double m0 = k > 0 ? _model(c, j_first, k - 1) : c->ga[j_first];
        found = s0 + (s1 - s0) * m0 / (m0 - m_first);
    }
    return found;
}
