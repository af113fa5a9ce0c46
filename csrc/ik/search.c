/* The solve strategies on one problem: local solve, bounded search, and what they answer
 * (the method: om_redundant/ik/kernel_data.py). */
#include "om_system.h"

#define TORUS_SIDE 0.75  /* the torus grid has TORUS_SIDE * scan points nodes per side */
#define START_POINTS 8   /* points of the dp circle tried when p_d is out of the model's reach */

/* The roots from the circle's candidates cands[0 .. n), each polished and verified into roots
 * (OM_MAX_ROOTS x dof); returns the count. q: scratch, as the candidates' search left it. */
static int _circle_roots(om_problem *pb, const double *cands, int n, double *q, double *roots)
{
    const om_solver_data *data = pb->s;
    int count = 0;
    bool lifted = data->family == OM_SRS; /* 7-DOF: the lifted system; 6-DOF: the wrist with q6 given */
    for (int i = 0; i < n; i++) {
        double gw = om_g(pb, cands[i], q, true);
        if (!isnan(gw) && fabs(gw) > OM_ROOT_TOL) /* polish the bracket's estimate */
            om_secant(pb, cands[i], q);
        int before = count;
        count = om_add_root(pb, q, roots, count);
        /* (an arm near a family's wrist residual may reach where G does not: its correction's) */
        bool wrist = data->nominal_table && !lifted && data->dp_joint == 5;
        if (count == before && (!isnan(om_g(pb, cands[i], q, true)) || wrist)) {
            /* A steep crossing at a singular wrist: solved where it is smooth, from the
             * crossing itself (q_J = w; the model's q_J is off by the jump of g there). */
            double at_candidate[OM_MAX_DOF];
            memcpy(at_candidate, q, (size_t)data->dof * sizeof(double));
            at_candidate[data->dp_joint] = cands[i];
            if (lifted)
                om_lifted_solve(pb, at_candidate, q);
            else if (data->dp_joint == 5) /* q6 given (not a wrist with a4 != 0, whose w is q1) */
                om_wrist_secant(pb, cands[i], q);
            count = om_add_candidate(pb, q, roots, count);
            if (count == before) /* a touch of zero: refined from the candidate itself */
                count = om_add_candidate(pb, at_candidate, roots, count);
        }
    }
    return count;
}

/* What the circle's candidates of the problem depend on, but for its SHOULDER sign (and, with
 * wrist false, its WRIST sign: the torus search's; om_scan_cache). A 6-DOF arm's ARM sign, which
 * its lifted model IK reads, is always part of it. */
static void _scan_key(const om_problem *pb, int n_scan, bool wrist, double *key)
{
    const mat3 *R = &pb->t.R;
    const vec3 rows[3] = {R->r0, R->r1, R->r2};
    double *k = key;
    *k++ = pb->p.x, *k++ = pb->p.y, *k++ = pb->p.z;
    for (int i = 0; i < 3; i++)
        *k++ = rows[i].x, *k++ = rows[i].y, *k++ = rows[i].z;
    *k++ = pb->t.psi;
    *k++ = pb->s->family == OM_SRS ? 0.0 : (double)pb->signs[0];
    *k++ = (double)pb->signs[1], *k++ = wrist ? (double)pb->signs[2] : 0.0;
    for (int j = 0; j < OM_MAX_DOF; j++)
        *k++ = j < pb->s->dof ? pb->q_prev[j] : 0.0;
    *k = (double)n_scan;
}

/* The torus grid's nodes a side for n_scan scan points. */
static int _torus_side(int n_scan)
{
    int side = (int)(TORUS_SIDE * (double)n_scan);
    return side > 4 ? side : 4;
}

/* A window's grid on the torus (half-width radius), about a root found: as fine as the whole
 * torus' grid for n_scan scan points, and 4 nodes a side at least (the window's fold partners,
 * sought across it, are its search's net, om_torus_roots); none (0) where the window is at most
 * one cell of the whole grid wide, where every other root of the window lies within a cell of
 * the root found, which the whole grid would not show as a dip of its own either: its fold
 * partner search is the net there, as on the whole torus. */
static int _window_side(int n_scan, double radius)
{
    int whole = _torus_side(n_scan);
    if (radius <= OM_PI / (double)whole) /* (2 radius: at most a cell, 2 pi / whole) */
        return 0;
    int side = (int)ceil((double)whole * radius / OM_PI);
    return side > 4 ? side : 4;
}

/* A window's samples on the circle (half-width radius): as fine as the whole circle's scan of
 * n_scan points, and 3 at least (its ends and middle: the scan's curvature test then has a
 * second difference to judge the window's two cells by, as every cell of the whole scan). */
static int _window_points(int n_scan, double radius)
{
    int points = (int)ceil((double)n_scan * radius / OM_PI) + 1;
    return points > 3 ? points : 3;
}

/* The torus grid search of the whole torus (om_torus_roots), its candidates taken from cache
 * where it holds this problem's, else searched and kept there: they are those of every
 * problem that differs in the SHOULDER (7-DOF) and WRIST signs alone (torus.c, _candidate), and only
 * their verification, which refines and filters each in the problem's configuration, is the
 * problem's own. The same roots, in the same order, and evaluations, as the search. */
static int _torus_roots_cached(om_problem *pb, int n_scan, double *roots, om_scan_cache *cache)
{
    int dof = pb->s->dof, count = 0;
    double key[OM_SCAN_KEY], zeros[OM_MAX_DOF] = {0.0};
    _scan_key(pb, n_scan, false, key);
    if (cache->valid && memcmp(key, cache->key, sizeof key) == 0) {
        pb->counter += cache->evaluations;
        for (int k = 0; k < cache->count; k++) {
            double q[OM_MAX_DOF];
            memcpy(q, cache->candidates + (size_t)dof * (size_t)k, (size_t)dof * sizeof(double));
            count = om_add_candidate(pb, q, roots, count);
        }
        return count;
    }
    om_candidate_log log = {cache->candidates, cache->capacity / dof, 0};
    int64_t before = pb->counter;
    count = om_torus_roots(pb, _torus_side(n_scan), roots, zeros, INFINITY, NULL, &log);
    cache->valid = log.count <= log.cap; /* else not all kept */
    cache->count = log.count;
    cache->evaluations = pb->counter - before;
    memcpy(cache->key, key, sizeof key);
    return count;
}

/* om_all_roots, or with radius < pi the roots whose scanned joints lie within radius of the
 * centre's (a window), with a root found already there (its joints; NULL: none), which the
 * window starts from (om_torus_roots; on the circle, circle_scan.known). */
static int _all_roots(om_problem *pb, int n_scan, double *roots, const double *centre, double radius,
                      const double *found)
{
    const om_solver_data *data = pb->s;
    double q[OM_MAX_DOF];
    nan_fill(q, OM_MAX_DOF); /* unwritten joints read as NaN, which verify rejects */
    if (data->mode == OM_FIXED) {
        double gw = om_g(pb, 0.0, q, true);
        return isnan(gw) ? 0 : om_add_candidate(pb, q, roots, 0);
    }
    if (data->mode == OM_TORUS) {
        int count;
        if (pb->certify && om_torus_certified_roots(pb, roots, &count, centre, radius))
            return count;
        int side = radius < OM_PI ? _window_side(pb->s->scan_points, radius) : _torus_side(n_scan);
        return om_torus_roots(pb, side, roots, centre, radius, found, NULL);
    }
    int J = data->dp_joint, cap = OM_SCAN_CAPACITY(n_scan);
    double *cands = malloc((size_t)cap * sizeof(double));
    if (!cands)
        return 0;
    bool full_circle = radius >= OM_PI;
    double lo = full_circle ? -OM_PI : centre[J] - radius;
    double hi = full_circle ? OM_PI : centre[J] + radius;
    pb->nominal = om_scans_nominal(data); /* an arm near a family: its nominal arm's g~ first (near.c) */
    int n = om_circle_candidates(pb, lo, hi, n_scan, full_circle, found ? found[J] : NAN, q, cands, cap);
    if (data->family != OM_SRS && data->params[SD_WRIST_OFFSET] != 0.0) /* a4 != 0: the singular wrist's bands */
        n += om_wrist_offset_candidates(pb, lo, hi, full_circle, q, cands + n, cap - n);
    pb->nominal = false;
    int count = _circle_roots(pb, cands, n, q, roots);
    free(cands);
    return count;
}

/* Bounded search: every verified solution in this configuration into roots (OM_MAX_ROOTS x
 * dof), on the whole circle or torus; returns the count. (A window about a hint:
 * om_nearest_in_window.) */
int om_all_roots(om_problem *pb, int n_scan, double *roots)
{
    static const double anywhere[OM_MAX_DOF] = {0.0}; /* (the whole circle or torus has no centre) */
    return _all_roots(pb, n_scan, roots, anywhere, INFINITY, NULL);
}

int om_all_roots_cached(om_problem *pb, int n_scan, double *roots, om_scan_cache *cache)
{
    const om_solver_data *data = pb->s;
    double zeros[OM_MAX_DOF] = {0.0};
    int count;
    /* (an arm near a family shares no search between signs: its corrected target moves with
     * the joints the signs choose) */
    if (cache && data->mode == OM_TORUS && !data->nominal_table)
        return pb->certify && om_torus_certified_roots(pb, roots, &count, zeros, INFINITY)
                   ? count
                   : _torus_roots_cached(pb, n_scan, roots, cache);
    if (!cache || data->mode != OM_CIRCLE || data->family != OM_SRS || data->dp_joint != 6 || data->nominal_table ||
        OM_SCAN_CAPACITY(n_scan) > cache->capacity)
        return om_all_roots(pb, n_scan, roots);
    double key[OM_SCAN_KEY], q[OM_MAX_DOF];
    _scan_key(pb, n_scan, true, key);
    if (cache->valid && memcmp(key, cache->key, sizeof key) == 0) {
        pb->counter += cache->evaluations;
        memcpy(q, cache->q, sizeof q);
    } else {
        nan_fill(q, OM_MAX_DOF); /* as om_all_roots */
        int64_t before = pb->counter;
        cache->count = om_circle_candidates(pb, -OM_PI, OM_PI, n_scan, true, NAN, q, cache->candidates, cache->capacity);
        cache->evaluations = pb->counter - before;
        memcpy(cache->q, q, sizeof q);
        memcpy(cache->key, key, sizeof key);
        cache->valid = true;
    }
    return _circle_roots(pb, cache->candidates, cache->count, q, roots);
}

/* The model IK at the paper's fixed-point start p_m = p_d, every joint (om_model_eval: a start,
 * no residual). */
static double _start_ik(om_problem *pb, const void *args, double *q, bool nearest, double *residual)
{
    const om_solver_data *s = pb->s;
    *residual = INFINITY;
    if (nearest)
        return om_model_ik_nearest(s->family, s->params, s->model_table, &pb->t, pb->p, pb->signs, pb->q_prev, q);
    return om_model_ik(s->family, s->params, s->model_table, &pb->t, pb->p, pb->signs, pb->q_prev, q, true);
}

/* The start's model IK (_start_ik): an arm near a family that scans its nominal arm starts
 * from the nominal arm's. */
static double _start_at(om_problem *pb, double *start)
{
    pb->nominal = om_scans_nominal(pb->s);
    double margin = om_near_ik(pb, _start_ik, NULL, start);
    pb->nominal = false;
    return margin;
}

void om_complete_start(om_problem *pb, double *start, bool *complete)
{
    const om_solver_data *s = pb->s;
    if (!*complete && _start_at(pb, start) < -OM_REACH_SLACK)
        om_srs_model_ik_at_reach(s->params, &pb->t, pb->p, pb->signs, pb->q_prev, start);
    *complete = true;
}

bool om_fixed_point_start(om_problem *pb, double *q, double *start)
{
    const om_solver_data *s = pb->s;
    const int64_t *signs = pb->signs;
    if (_start_at(pb, start) >= -OM_REACH_SLACK)
        return true;
    if (s->family == OM_SRS && s->mode != OM_FIXED) /* the elbow held at the edge of reach */
        return om_srs_model_ik_at_reach(s->params, &pb->t, pb->p, signs, pb->q_prev, start);
    if (s->mode == OM_TORUS) /* a 6-DOF arm's torus: the nearest pose the model reaches (NaN: none) */
        return om_model_ik_nearest(s->family, s->params, s->model_table, &pb->t, pb->p, signs, pb->q_prev, start) >=
               -INFINITY;
    if (s->mode != OM_CIRCLE)
        return false;
    bool found = false; /* the point of the dp circle the model reaches with the smallest residual */
    double best = INFINITY;
    for (int k = 0; k < START_POINTS; k++) {
        double gk = om_g(pb, -OM_PI + 2.0 * OM_PI * (double)k / START_POINTS, q, true);
        if (fabs(gk) < best) { /* false for NaN */
            best = fabs(gk);
            found = true;
            memcpy(start, q, (size_t)s->dof * sizeof(double));
        }
    }
    return found;
}

/* Local solve from the joint vector start, verified with the real arm: the secant on g from
 * its q_J; on the torus, and on a 7-DOF circle arm where the secant fails, the lifted Newton
 * (from the whole start: see om_complete_start); near the singular boundary, the refinement
 * on the real arm last. An arm near a family takes its nominal arm's root first and Newton's
 * steps on its exact chain from there (om_near_secant), the secant on G where they fail.
 * Returns accepted (errors into *pos, *ori); q holds the model IK at the end (or the root
 * Newton's steps reached). */
bool om_local_solve(om_problem *pb, double *start, bool *start_complete, double *q, double *pos, double *ori)
{
    const om_solver_data *data = pb->s;
    if (data->mode == OM_TORUS) {
        if (data->nominal_table && om_near_lifted(pb, start, q, pos, ori)) /* the nominal arm's root first */
            return true;
        om_lifted_solve(pb, start, q);
        return om_verify(pb, q, pos, ori);
    }
    double w = data->mode == OM_CIRCLE ? start[data->dp_joint] : 0.0;
    if (om_near_secant(pb, w, true, q, pos, ori)) /* (near a family: a root verified) */
        return true;
    bool accepted = om_verify(pb, q, pos, ori);
    if (!accepted && data->family == OM_SRS && data->mode == OM_CIRCLE) {
        om_complete_start(pb, start, start_complete);
        om_lifted_solve(pb, start, q);
        accepted = om_verify(pb, q, pos, ori);
    }
    return accepted || om_polish_candidate(pb, q, pos, ori);
}

/* Whether any configuration other than the problem's has a solution (with skip_neighbours,
 * those one branch away are not searched: om_band_roots has). The other configurations'
 * evaluations count in pb->counter (one counter per solve). */
bool om_exists_other(om_problem *pb, bool skip_neighbours)
{
    const int64_t *signs = pb->signs;
    int k = pb->s->n_signs;
    int64_t other[64];
    double roots[OM_MAX_ROOTS * OM_MAX_DOF];
    for (int64_t code = 0; code < ((int64_t)1 << k); code++) {
        int flips = 0;
        for (int i = 0; i < k; i++) {
            other[i] = ((code >> i) & 1) ? 1 : -1;
            flips += other[i] != signs[i];
        }
        if (flips == 0 || (skip_neighbours && flips == 1))
            continue;
        om_problem with_signs = *pb;
        with_signs.signs = other;
        with_signs.counter = 0;
        int n = om_all_roots(&with_signs, pb->s->scan_points, roots);
        pb->counter += with_signs.counter;
        if (n)
            return true;
    }
    return false;
}

/* Replace root q by any root nearer the hint; returns whether one was. A nearer root has
 * |q_J - hint_J| below that distance: scanning that window is enough. */
bool om_nearest_in_window(om_problem *pb, const double *hint, double *q)
{
    int dof = pb->s->dof;
    double d2 = om_wrapped_distance2(q, hint, dof);
    double radius = sqrt(d2);
    if (radius < 1e-12)
        return false;
    double roots[OM_MAX_ROOTS * OM_MAX_DOF];
    int n = _all_roots(pb, _window_points(pb->s->scan_points, radius), roots, hint, radius, q);
    bool replaced = false;
    for (int r = 0; r < n; r++) {
        double e2 = om_wrapped_distance2(roots + r * dof, hint, dof);
        if (e2 < d2) {
            d2 = e2;
            replaced = true;
            memcpy(q, roots + r * dof, (size_t)dof * sizeof(double));
        }
    }
    return replaced;
}
