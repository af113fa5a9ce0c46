/* The entry points: one solve, and every root of one configuration
 * (the method: om_redundant/ik/kernel_data.py). */
#include "om_system.h"

#define START_POINTS 8 /* starts on the dp circle where a first root is out of limits */
/* rad^2: a hinted local root farther from the hint than this (squared wrapped distance) may
 * have a nearer twin beyond the window's reach (a straight elbow's: the FR3's at 3.5 rad), so
 * the bounded search decides which root is nearest */
#define NEAR_HINT 1.0

/* The flange pose in DH frame 0 for an end-effector pose T (4x4 row-major) in the root frame. */
void om_flange_target(const double *T, const double *T_base_root, const double *T_tool_flange, mat3 *R, vec3 *p)
{
    double F[3][4]; /* rows 0-2 of T_base_root @ T (row 3 is [0, 0, 0, 1]) */
    const double *B = T_base_root, *X = T_tool_flange;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++)
            F[i][j] = (B[4 * i + 0] * T[0 + j] + B[4 * i + 1] * T[4 + j] + B[4 * i + 2] * T[8 + j]) +
                      B[4 * i + 3] * T[12 + j];
    double Rm[3][3], pv[3];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            Rm[i][j] = F[i][0] * X[0 + j] + F[i][1] * X[4 + j] + F[i][2] * X[8 + j];
        pv[i] = F[i][0] * X[3] + F[i][1] * X[7] + F[i][2] * X[11] + F[i][3];
    }
    R->r0 = v3(Rm[0][0], Rm[0][1], Rm[0][2]);
    R->r1 = v3(Rm[1][0], Rm[1][1], Rm[1][2]);
    R->r2 = v3(Rm[2][0], Rm[2][1], Rm[2][2]);
    *p = v3(pv[0], pv[1], pv[2]);
}

/* Whether joint vectors a and b differ (by the 2 pi shifts of representative). */
static bool _shifted(const double *a, const double *b, int dof)
{
    for (int j = 0; j < dof; j++)
        if (a[j] != b[j])
            return true;
    return false;
}

/* Write the verified root q into q_out (an arm near a family's polished first, om_near_polish),
 * revolute joints shifted by whole turns into the limits, nearest the hint (has_hint) or zero;
 * *pos and *ori hold q's errors on entry and the returned vector's on exit. Shifting toward a
 * huge hint is inexact in floating point (a turn
 * is not representable at 1e8 rad to 1e-10): where the shifted vector no longer verifies,
 * the shift nearest zero is taken, and where that fails too, q itself. So the vector
 * returned always verifies. Returns whether it is within the limits. */
static bool _finish(om_problem *pb, const double *q, const double *hint, bool has_hint, double *q_out, double *pos,
                    double *ori)
{
    const om_solver_data *s = pb->s;
    int dof = s->dof;
    double polished[OM_MAX_DOF];
    if (s->nominal_table) { /* an arm near a family's root to its last digits */
        memcpy(polished, q, (size_t)dof * sizeof(double));
        om_near_finish(pb, polished, pos, ori); /* (*pos, *ori: its errors) */
        q = polished;
    }
    double q_pos = *pos, q_ori = *ori;
    for (int toward_hint = has_hint; toward_hint >= 0; toward_hint--) {
        memcpy(q_out, q, (size_t)dof * sizeof(double));
        bool inside = om_representative(q_out, dof, s->revolute, s->lower, s->upper, hint, toward_hint);
        if (!_shifted(q_out, q, dof)) {
            *pos = q_pos;
            *ori = q_ori;
            return inside;
        }
        if (om_verify(pb, q_out, pos, ori)) /* the errors of the vector returned, to its rounding */
            return inside;
    }
    memcpy(q_out, q, (size_t)dof * sizeof(double));
    *pos = q_pos;
    *ori = q_ori;
    bool inside = true;
    for (int j = 0; j < dof; j++)
        inside = inside && s->lower[j] <= q[j] && q[j] <= s->upper[j];
    return inside;
}

/* The requested redundancy values as the kernels use them: angles reduced into [-pi, pi)
 * exactly (om_wrap), so that a huge psi (1e16) is one well-defined angle rather than one whose
 * rounding in every later subtraction exceeds the check's tolerance. */
static void _reduce(const om_solver_data *s, const double *redundancy, double *reduced)
{
    for (int i = 0; i < s->n_redundancy; i++)
        reduced[i] = om_wrap(redundancy[i]);
}

/* The START_POINTS starts -pi + 2 pi (k + 1/2) / START_POINTS into order, the farthest from
 * w first (w NaN: in order of k). */
static void _starts_away_from(double w, double *order)
{
    int k0 = 0; /* the start farthest from w, then alternately its neighbours */
    if (!isnan(w))
        k0 = py_mod((int)floor((om_wrap(w + OM_PI) + OM_PI) * START_POINTS / (2.0 * OM_PI)), START_POINTS);
    for (int i = 0; i < START_POINTS; i++) {
        int step = (i + 1) / 2, k = isnan(w) ? i : py_mod(k0 + (i % 2 ? step : -step), START_POINTS);
        order[i] = -OM_PI + 2.0 * OM_PI * ((double)k + 0.5) / START_POINTS;
    }
}

static om_result _result(int status, double pos, double ori, int64_t evaluations, bool inside)
{
    om_result result = {status, pos, ori, evaluations, inside};
    return result;
}

/* (om_kernels.h) */
void om_problem_init(om_problem *pb, const om_solver_data *s, const double *T, const int64_t *signs,
                     const double *redundancy, double *reduced, const double *q_prev)
{
    pb->s = s;
    _reduce(s, redundancy, reduced);
    pb->redundancy = reduced;
    mat3 R; /* the target: the flange pose for the end-effector pose T */
    vec3 p;
    om_flange_target(T, s->T_base_root, s->T_tool_flange, &R, &p);
    om_set_goal(pb, &R, p);
    pb->signs = signs;
    pb->q_prev = q_prev;
    pb->counter = 0;
    pb->split_starts = true;
    /* (the certificate's bounds are the model's at the target, not G's; and an S-R-S model's) */
    pb->certify = !s->nominal_table && s->family == OM_SRS;
    pb->memo = NULL;
    pb->torus_memo = NULL;
    pb->traces = NULL;
    pb->nominal = false;
    pb->wrist = false;
}

/* A hinted solve's local part (the hint is pb->q_prev, copied into start): the local solve
 * from the hint, its root replaced by any root nearer the hint (the windowed scan), written
 * into q_out at the representative nearest the hint. as_is (NULL: none) may take the local
 * root as it is, or reject it, without the scan: it sees it in q_out. Returns false where the
 * local solve fails (q_out not written) or as_is rejects; else *pos, *ori are q_out's errors
 * and *inside whether it is within the limits. q: scratch (dof). */
static bool _near_hint(om_problem *pb, double *start, bool *start_complete, double *q, double *q_out, double *pos,
                       double *ori, bool *inside, om_root_test as_is, void *context)
{
    if (!om_local_solve(pb, start, start_complete, q, pos, ori))
        return false;
    if (as_is) {
        double local_pos = *pos, local_ori = *ori;
        *inside = _finish(pb, q, pb->q_prev, true, q_out, pos, ori);
        om_root_verdict verdict = as_is(q_out, context);
        if (verdict != OM_ROOT_SCAN)
            return verdict == OM_ROOT_TAKE;
        *pos = local_pos;
        *ori = local_ori;
    }
    if (pb->s->mode != OM_FIXED && om_nearest_in_window(pb, pb->q_prev, q))
        om_verify(pb, q, pos, ori);
    *inside = _finish(pb, q, pb->q_prev, true, q_out, pos, ori);
    return true;
}

/* One OM solve: the local solve (secant, or lifted Newton), then, with search, the bounded
 * search; without it a hinted solve ends where its local part fails (om_solve_near). hint
 * NULL: no hint; traces: the pose's kept self-motion (om_problem.traces; NULL: none). Writes
 * q_out (dof; NaN when no solution). */
static om_result _solve(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                        const double *hint, double *q_out, om_root_test as_is, void *context, bool search,
                        const om_torus_memo *traces)
{
    int family = s->family, mode = s->mode, dof = s->dof;
    const double *P = s->params;
    const uint8_t *revolute = s->revolute;
    const double *lower = s->lower, *upper = s->upper;
    bool has_hint = hint != NULL;
    double zeros[OM_MAX_DOF] = {0.0}, usable[OM_MAX_DOF];
    if (has_hint)
        om_usable_hint(s, hint, usable);
    hint = has_hint ? usable : zeros; /* zeros: what the Python side passes without a hint */
    om_problem problem;
    double psi[1];
    om_problem_init(&problem, s, T, signs, redundancy, psi, hint);
    problem.split_starts = search;
    problem.traces = traces;
    om_problem *pb = &problem;
    double q[OM_MAX_DOF], start[OM_MAX_DOF];
    /* local_solve verifies q even where the secant's first point is out of reach and q was
     * never written; NaN makes that verification fail deterministically. */
    nan_fill(q, OM_MAX_DOF);
    memcpy(start, hint, (size_t)dof * sizeof(double));
    bool found = has_hint;
    vec3 pd = problem.p;
    double pos = NAN, ori = NAN, outside_w = NAN; /* q_J of a local root out of the limits */
    /* Whether start holds every joint; on an S-R-S circle arm whose dp turns with q7, the
     * local solve needs q7 alone, and the rest is computed where needed (om_complete_start),
     * but near a family, where the correction needs them all. */
    bool start_complete =
        has_hint || !(mode == OM_CIRCLE && family == OM_SRS && s->dp_joint == 6) || s->nominal_table;
    if (!start_complete) { /* the fixed-point start's q7, at the edge of reach beyond it */
        found = om_srs_model_q7(P, &problem.t, pd, signs, problem.q_prev, start) >= -OM_REACH_SLACK ||
                om_srs_model_q7_at_reach(P, &problem.t, pd, signs, problem.q_prev, start);
    } else if (!has_hint) { /* the paper's fixed-point start, p_m = p_d */
        found = om_fixed_point_start(pb, q, start);
    }
    double local[OM_MAX_DOF], local_pos = NAN, local_ori = NAN, local_dist = INFINITY;
    bool local_inside = false;
    if (has_hint) {
        if (_near_hint(pb, start, &start_complete, q, q_out, &pos, &ori, &local_inside, as_is, context)) {
            local_dist = om_wrapped_distance2(q_out, hint, dof);
            if (!search || local_dist <= NEAR_HINT)
                return _result(OM_OK, pos, ori, problem.counter, local_inside);
            memcpy(local, q_out, (size_t)dof * sizeof(double));
            local_pos = pos;
            local_ori = ori;
        } else if (!search) { /* not a verdict: a solution may still exist */
            return _result(OM_NO_SOLUTION_IN_CONFIGURATION, NAN, NAN, problem.counter, false);
        }
    } else if (found && om_local_solve(pb, start, &start_complete, q, &pos, &ori)) {
        bool inside = _finish(pb, q, hint, false, q_out, &pos, &ori);
        if (inside || mode == OM_FIXED)
            return _result(OM_OK, pos, ori, problem.counter, inside);
        /* Without a hint, a root within the limits is preferred: search for one. */
        outside_w = q[s->dp_joint];
    }
    if (!has_hint && mode == OM_CIRCLE) {
        /* Other starts on the circle first: cheaper than the bounded search, and a root
         * within the limits is usually among their roots. Where the local root lies out of
         * the limits, the starts farthest from it go first (the nearer ones mostly find it
         * again). */
        double order[START_POINTS];
        _starts_away_from(outside_w, order);
        for (int k = 0; k < START_POINTS; k++) {
            bool verified = om_near_secant(pb, order[k], false, q, &pos, &ori) || om_verify(pb, q, &pos, &ori);
            if (verified && _finish(pb, q, hint, false, q_out, &pos, &ori))
                return _result(OM_OK, pos, ori, problem.counter, true);
        }
    }
    double roots[OM_MAX_ROOTS * OM_MAX_DOF];
    int n = om_all_roots(pb, s->scan_points, roots);
    bool neighbour_reached = false;
    if (n == 0) /* the boundary contract: a neighbour's root in the band holds this configuration */
        n = om_band_roots(pb, roots, &neighbour_reached, NULL);
    if (n == 0 && local_dist < INFINITY) { /* the local root, which the search did not find again */
        memcpy(q_out, local, (size_t)dof * sizeof(double));
        return _result(OM_OK, local_pos, local_ori, problem.counter, local_inside);
    }
    if (n == 0) {
        for (int j = 0; j < dof; j++)
            q_out[j] = NAN;
        bool other = neighbour_reached || om_exists_other(pb, true);
        return _result(other ? OM_NO_SOLUTION_IN_CONFIGURATION : OM_UNREACHABLE, NAN, NAN, problem.counter, false);
    }
    if (found)
        om_complete_start(pb, start, &start_complete);
    /* The root nearest the hint; without one, a root within the limits first, then the one
     * nearest the fixed-point start. */
    int best = 0;
    double best_dist = INFINITY;
    for (int r = 0; r < n; r++) {
        double dist = found ? om_wrapped_distance2(roots + r * dof, start, dof) : 0.0;
        if (!has_hint) {
            double shifted[OM_MAX_DOF];
            memcpy(shifted, roots + r * dof, (size_t)dof * sizeof(double));
            if (!om_representative(shifted, dof, revolute, lower, upper, hint, false))
                dist += (double)dof * ((2.0 * OM_PI) * (2.0 * OM_PI)); /* after every root within the limits */
        }
        if (dist < best_dist) {
            best = r;
            best_dist = dist;
        }
    }
    om_verify(pb, roots + best * dof, &pos, &ori);
    bool inside = _finish(pb, roots + best * dof, hint, has_hint, q_out, &pos, &ori);
    if (local_dist <= om_wrapped_distance2(q_out, hint, dof)) { /* the local root is (one of) the nearest */
        memcpy(q_out, local, (size_t)dof * sizeof(double));
        return _result(OM_OK, local_pos, local_ori, problem.counter, local_inside);
    }
    return _result(OM_OK, pos, ori, problem.counter, inside);
}

/* A caller's root test, of the arm's own joint coordinates, asked of the kernels' roots. */
typedef struct {
    const om_solver_data *s;
    om_root_test test;
    void *context;
} own_test;

static om_root_verdict _own_test(const double *q, void *context)
{
    const own_test *own = context;
    double q_own[OM_MAX_DOF];
    om_flip(own->s, q, q_own);
    return own->test(q_own, own->context);
}

/* _solve in the arm's own joint coordinates (a near arm's reversed axes, om_solver_data.flip):
 * the hint in, q_out out, and the roots that as_is judges, flipped. */
static om_result _solve_own(const om_solver_data *s, const double *T, const int64_t *signs,
                            const double *redundancy, const double *hint, double *q_out, om_root_test as_is,
                            void *context, bool search, const om_torus_memo *traces)
{
    if (!s->flipped)
        return _solve(s, T, signs, redundancy, hint, q_out, as_is, context, search, traces);
    double flipped[OM_MAX_DOF];
    if (hint) {
        om_flip(s, hint, flipped);
        hint = flipped;
    }
    own_test own = {s, as_is, context};
    om_result r = _solve(s, T, signs, redundancy, hint, q_out, as_is ? _own_test : NULL, &own, search, traces);
    om_flip(s, q_out, q_out);
    return r;
}

om_result om_solve_one(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                       const double *hint, double *q_out, om_root_test as_is, void *context)
{
    return _solve_own(s, T, signs, redundancy, hint, q_out, as_is, context, true, NULL);
}

/* The hinted solve's local part alone (see om_solve_near in om_kernels.h). */
bool om_solve_near(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                   const double *hint, double *q_out, om_root_test as_is, void *context, om_result *result,
                   const om_torus_memo *traces)
{
    om_result r = _solve_own(s, T, signs, redundancy, hint, q_out, as_is, context, false, traces);
    if (r.status == OM_OK && result)
        *result = r;
    return r.status == OM_OK;
}

/* Every solution in one configuration (the bounded search): roots (OM_MAX_ROOTS x dof,
 * revolute joints shifted into the limits where possible) and per root (position error,
 * orientation error, within limits) in info (OM_MAX_ROOTS x 3). Returns the count. band:
 * where the bounded search finds none, the band's roots and the local solve's. cache (NULL:
 * none): the circle search's candidates shared with the previous problem where they are
 * the same, and the scan memo that this problem's scans share with the batch's
 * (om_scan_cache). */
int om_solve_all(const om_solver_data *s, const double *T, const int64_t *signs, const double *redundancy,
                 double *roots, double *info, int64_t *evaluations, bool band, om_scan_cache *cache)
{
    double zeros[OM_MAX_DOF] = {0.0};
    int dof = s->dof;
    double psi[1];
    om_problem problem;
    om_problem_init(&problem, s, T, signs, redundancy, psi, zeros);
    problem.memo = cache ? cache->memo : NULL;
    problem.torus_memo = cache ? cache->torus_memo : NULL;
    int n = om_all_roots_cached(&problem, s->scan_points, roots, cache);
    bool neighbour_reached, complete = true;
    if (n == 0 && band) { /* the band's roots, and what solve finds: its local solve from the fixed-point start */
        n = om_band_roots(&problem, roots, &neighbour_reached, cache);
        double q[OM_MAX_DOF], start[OM_MAX_DOF], pos, ori;
        nan_fill(q, OM_MAX_DOF);
        if (om_fixed_point_start(&problem, q, start) && om_local_solve(&problem, start, &complete, q, &pos, &ori))
            n = om_add_root(&problem, q, roots, n);
    }
    for (int r = 0; r < n; r++) {
        double root[OM_MAX_DOF];
        memcpy(root, roots + r * dof, (size_t)dof * sizeof(double));
        om_verify(&problem, root, &info[3 * r], &info[3 * r + 1]);
        bool inside = _finish(&problem, root, zeros, false, roots + r * dof, &info[3 * r], &info[3 * r + 1]);
        info[3 * r + 2] = inside ? 1.0 : 0.0;
        if (s->flipped)
            om_flip(s, roots + r * dof, roots + r * dof);
    }
    if (evaluations)
        *evaluations = problem.counter;
    return n;
}
