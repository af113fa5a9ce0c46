/* The circle scan's samples: g and the reach margin at the scan's points and at the edges of
 * reach it meets, through the scan memo of an S-R-S arm whose dp turns with q7 (the model's
 * parts shared by the scans of one pose), and a near arm's branch quantities at the points
 * (the method: om_redundant/ik/kernel_data.py). */
#include "circle.h"

#define MEMO_POINTS 128 /* a scan of at most this many points shares its samples' model parts (scan_memo) */
#define MEMO_EDGES 16   /* edges of reach a scan memo keeps */
#define MEMO_KEY (9 + 3 + 3)

/* An edge of reach a scan met (om_reach_edge(inside, outside) = w), the model's parts there and
 * the wrist's terms for the arm angle psi (terms_valid). */
typedef struct {
    double inside, outside, w;
    om_srs_elbow parts;
    om_srs_wrist_terms terms;
    bool terms_valid;
    double psi;
} memo_edge;

/* What the last scan of the circle of an S-R-S arm whose dp turns with q7 through a memo, in
 * one ELBOW branch, keeps for the next: the model's parts at its samples w_k that do not
 * depend on the arm angle (om_srs_elbow_at: those of the hand position p_d + R delta(w_k),
 * the orientation and the ELBOW sign), those that do not depend on the WRIST sign
 * (om_srs_wrist_terms_of) for the arm angle psi, and the edges of reach it met (the reach
 * margin depends on the pose alone) with the same parts there. A grid of problems of one pose
 * (solve_grid: arm angles, each in 8 branches) scans the same samples again and again; a scan
 * whose key is the last one's takes these instead of computing them again (the same
 * arithmetic on the same inputs: the same bits), and solves q7 alone. */
struct scan_memo {
    bool valid;
    double key[MEMO_KEY]; /* R, p_d, lo, h, the points (the model's parameters: one solver's) */
    om_srs_elbow parts[MEMO_POINTS];
    bool terms_valid;
    double psi;
    om_srs_wrist_terms terms[MEMO_POINTS];
    int n_edges;
    memo_edge edges[MEMO_EDGES];
};

/* The scan memos of the problems of one solver (its parameters and delta fixed: not in the
 * key), one per ELBOW branch; om_scan_cache owns it for a batch. */
struct om_scan_memo {
    scan_memo branches[2]; /* ELBOW -1, +1 */
};

/* Whether the scans of solver s keep a memo: those of an S-R-S arm whose dp turns with q7 (not
 * near a family: its model side moves with the correction at every sample, near.c). */
static bool _keeps_memo(const om_solver_data *s)
{
    return s->family == OM_SRS && s->mode == OM_CIRCLE && s->dp_joint == 6 && !s->nominal_table;
}

/* (86 kB: allocated only for an arm that keeps one, and not zeroed: a branch's parts are
 * written where its key is.) */
om_scan_memo *om_scan_memo_new(const om_solver_data *s)
{
    if (!_keeps_memo(s))
        return NULL;
    om_scan_memo *memo = malloc(sizeof(om_scan_memo));
    if (memo)
        memo->branches[0].valid = memo->branches[1].valid = false;
    return memo;
}

void om_scan_memo_free(om_scan_memo *memo) { free(memo); }

static void _memo_key(const om_problem *pb, double lo, double h, int n_pts, double *key)
{
    const mat3 *R = &pb->t.R;
    const vec3 rows[3] = {R->r0, R->r1, R->r2};
    double *k = key;
    for (int i = 0; i < 3; i++)
        *k++ = rows[i].x, *k++ = rows[i].y, *k++ = rows[i].z;
    *k++ = pb->p.x, *k++ = pb->p.y, *k++ = pb->p.z;
    *k++ = lo, *k++ = h;
    *k = (double)n_pts;
}

/* Whether two doubles have the same bits (cos and sin of -0.0 and 0.0 differ in a sign). */
static bool _same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* g at w and the reach margin as om_g_margin computes them (one residual evaluation; q as it
 * leaves q), from the model's parts e there: the wrist's terms from *terms where fresh (for
 * this arm angle), else computed into it. */
static double _g_of_parts(om_problem *pb, double w, const om_srs_elbow *e, om_srs_wrist_terms *terms, bool fresh,
                          double *q, double *margin)
{
    const double *P = pb->s->params;
    pb->counter++;
    *margin = e->margin;
    if (e->margin < -OM_REACH_SLACK)
        return NAN;
    if (!fresh)
        *terms = om_srs_wrist_terms_of(P, &pb->t, e);
    om_srs_q7_of(P, &pb->t, e, terms, pb->signs, pb->q_prev, q);
    return om_wrap(q[6] - w);
}

/* The smallest |branch quantity| of the model at q (margin its reach margin; q NULL: out of
 * reach, INFINITY) into *nearest, its WRIST quantity's into *wrist. On an S-R-S arm, whose scan
 * of its nominal arm solves q7 alone, the ELBOW quantity's alone, |sin(phi4 - phi*)| =
 * sqrt(margin) (the SHOULDER's and the WRIST's singular swings show in g~ itself, and the
 * scan searches G there: _bracket), and no WRIST quantity (its wrist residual is not searched:
 * _near_singular). */
static void _near_branches(const om_solver_data *s, const double *q, double margin, double *nearest, double *wrist)
{
    double values[3];
    *nearest = *wrist = INFINITY;
    if (!q)
        return;
    if (s->family == OM_SRS) {
        *nearest = sqrt(py_max(margin, 0.0));
        return;
    }
    om_branch_values(s->family, s->params, q, values);
    for (int i = 0; i < s->n_signs; i++)
        *nearest = py_min(*nearest, fabs(values[i]));
    *wrist = fabs(values[2]);
}

/* g and the reach margin at the scan's points ws[k] = lo + h k, k < n_pts, into gs and ms as
 * om_g_margin computes them, the parts that the problem's memo holds for them taken from it;
 * for an arm near a family (which keeps no memo), the model's smallest |branch quantity| there
 * into bs[k], its |WRIST quantity| into bs[n_pts + k] (INFINITY out of reach).
 * Returns that memo's branch, now this scan's (NULL where the problem or the arm keeps
 * none), valid until the memo's next scan. */
scan_memo *om_circle_sample(om_problem *pb, double lo, double h, int n_pts, double *ws, double *gs, double *ms,
                            double *bs, double *q)
{
    const om_solver_data *s = pb->s;
    for (int k = 0; k < n_pts; k++)
        ws[k] = lo + h * (double)k;
    if (!pb->memo || n_pts > MEMO_POINTS) { /* (pb->memo: an arm that keeps one, om_scan_memo_new) */
        for (int k = 0; k < n_pts; k++) {
            gs[k] = om_g_margin(pb, ws[k], q, false, &ms[k]);
            if (s->nominal_table)
                _near_branches(s, isnan(gs[k]) ? NULL : q, ms[k], &bs[k], &bs[n_pts + k]);
        }
        return NULL;
    }
    double elbow = (double)pb->signs[1];
    scan_memo *memo = &pb->memo->branches[elbow > 0.0];
    double key[MEMO_KEY];
    _memo_key(pb, lo, h, n_pts, key);
    if (!memo->valid || memcmp(key, memo->key, sizeof key) != 0) {
        for (int k = 0; k < n_pts; k++)
            om_srs_elbow_at(s->params, &pb->t, om_on_circle(pb, ws[k]), elbow, &memo->parts[k]);
        memcpy(memo->key, key, sizeof key);
        memo->valid = true;
        memo->terms_valid = false;
        memo->n_edges = 0;
    }
    bool fresh = memo->terms_valid && _same_bits(memo->psi, pb->t.psi);
    for (int k = 0; k < n_pts; k++)
        gs[k] = _g_of_parts(pb, ws[k], &memo->parts[k], &memo->terms[k], fresh, q, &ms[k]);
    memo->psi = pb->t.psi;
    memo->terms_valid = true;
    return memo;
}

const om_srs_elbow *om_scan_memo_parts(const scan_memo *memo) { return memo->parts; }

/* The edge of reach om_reach_edge(inside, outside) and g there (om_g) into *g, through this
 * scan's memo (NULL: none): an edge that the memo's scans met is the same, and g there is
 * evaluated from the parts kept. */
double om_circle_edge(om_problem *pb, scan_memo *memo, double inside, double outside, double *q, double *g)
{
    memo_edge *edge = NULL;
    for (int i = 0; memo && i < memo->n_edges && !edge; i++)
        if (_same_bits(memo->edges[i].inside, inside) && _same_bits(memo->edges[i].outside, outside))
            edge = &memo->edges[i];
    if (!edge) {
        double w = om_reach_edge(pb, inside, outside, q);
        if (!memo || memo->n_edges == MEMO_EDGES) {
            *g = om_g(pb, w, q, false);
            return w;
        }
        edge = &memo->edges[memo->n_edges++];
        edge->inside = inside, edge->outside = outside, edge->w = w;
        om_srs_elbow_at(pb->s->params, &pb->t, om_on_circle(pb, w), (double)pb->signs[1], &edge->parts);
        edge->terms_valid = false;
    }
    double margin;
    *g = _g_of_parts(pb, edge->w, &edge->parts, &edge->terms, edge->terms_valid && _same_bits(edge->psi, pb->t.psi),
                     q, &margin);
    edge->psi = pb->t.psi;
    edge->terms_valid = true;
    return edge->w;
}
