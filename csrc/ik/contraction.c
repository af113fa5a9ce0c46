/* The torus search's certificate: where the OM fixed-point map contracts, on the whole torus or
 * on cells of it, its fixed points are the configuration's roots, each proved unique in its
 * cell, and cells where it cannot vanish are proved empty (the method: om_redundant/ik/kernel_data.py).
 *
 * On an arm with shoulder offsets every root of a configuration c is a fixed point of the map
 * G(w) = (q1, q7)(x(w)) on the torus w = (w1, w7): the model IK in c, at the target's
 * orientation R and arm angle psi, for the shoulder-wrist vector
 *
 *     x(w) = W - S = c0 + A(w1) + R Delta(w7),  A = D4 cos w1 + D5 sin w1,  Delta = D1 cos w7 + D2 sin w7
 *
 * (c0 = om_shoulder_wrist_centre), and every fixed point is a root. With r_a = |(D4, D5)| and
 * r_d = |(D1, D2)| (Frobenius norms), |A|, |A'| <= r_a and |Delta|, |Delta'| <= r_d, so every
 * x(w) lies in the ball |x - c0| <= rho = r_a + r_d, and |dx| <= r_a |dw1| + r_d |dw7|; the
 * points of a square of half-width k about w lie within rho min(k, 2) of x(w).
 *
 * Bounds on a ball |x - x_c| <= rho, with L = |x| in [L_lo, L_hi] = [L_c - rho, L_c + rho], for a
 * step dx = dL x_hat + dx_t (radial and tangential parts, dL^2 + |dx_t|^2 = |dx|^2):
 * - the elbow: x_e = (L^2 - k0) / K = cos(phi4 - phi*), phi4 = phi* + ELBOW acos(x_e), so
 *   |d phi4| <= e4 |dL|, e4 = 2 L_hi / (|K| sin), sin = sqrt(1 - x_e^2) at the largest |x_e| of
 *   the L range (all of it within (-1, 1));
 * - the frame-3 triad B(phi4) turns R03 = A^T B at most at turn3 |d phi4| and R04 = R03 Rz(phi4)
 *   X4 at turn4 |d phi4| (_elbow_turning, over the phi4 range);
 * - the arm angle's reference frame A0 = (x_hat, n, x_hat x n), n = R(up -> x_hat) ref, turns at
 *   |d x_hat| / cos(theta / 2) (theta: the angle of x_hat from up; tight), |d x_hat| = |dx_t| /
 *   L, 2 cos^2(theta / 2) = 1 + up . x_hat >= 1 + up . x_hat_c - 2 rho / L_c: at a_t |dx_t|;
 *   A, which is A0 turned by psi about x_hat, turns with it. So R03 turns at most at a_t |dx_t| + turn3
 *   e4 |dL| <= w03 |dx|, w03 = hypot(a_t, turn3 e4) (Cauchy-Schwarz), and R04 at w04 |dx|, w04 =
 *   hypot(a_t, turn4 e4);
 * - an Euler triple Rz(phi_a) Rx(alpha_a) Rz(phi_b) Rx(beta) Rz(phi_c), alpha_a = +-90 deg, of a
 *   frame turning at w: its joint axes z_a, z_b, z_c give w = sum phi_i' z_i, so by Cramer
 *   |phi_a'|, |phi_c'| <= w / |det|, det = det(z_a, z_b, z_c) = +-sin(beta) sin(phi_b), and
 *   |det'| <= w sqrt(1 + cos^2(beta) / det^2). The shoulder's triple (beta = 90 deg, det =
 *   sin phi2) gives q1, the wrist's (det = sin(beta) sin phi6) q7, at w03 and w04.
 * So |dG_i| <= g_i |dx| <= g_i (r_a |dw1| + r_d |dw7|) with g_1 = w03 / s2, g_7 = w04 / s6 (s2,
 * s6: floors of |det| on the ball, _floor; inf where there is none). In the weighted max norm
 * |w|_g = max(|w1| / g_1, |w7| / g_7) (the rank-one bound's Perron weights) G is Lipschitz with
 *
 *     lambda = r_a g_1 + r_d g_7
 *
 * on any square whose points map into the ball (a segment between two of them does), and F(w) =
 * w - G(w) has |F_i(w) - F_i(c)| <= (1 + g_i rho) h on the cell of half-width h about c.
 * A cell's bound is taken on the ball about x(c) of radius rho min(2 h, 2), which holds the
 * square C' of half-width 2 h about c (the whole torus: the ball about c0 of radius rho).
 * - A cell where some |F_i(c)| exceeds that holds no root.
 * - Where lambda < 1 on a convex region, G has at most one fixed point there (|w - w'|_g <=
 *   lambda |w - w'|_g), and a square S of |.|_g-radius k about a point z lying in the region
 *   with k >= |G(z) - z|_g / (1 - lambda) holds one (G maps S into itself: |G(u) - z|_g <=
 *   lambda k + |G(z) - z|_g <= k; Banach); the iterates of G from a point of the region that
 *   stay in it converge to it. On the whole torus (a complete metric space) this is Banach's
 *   theorem outright.
 * The floors also keep every branch quantity of the ball's model solutions beyond
 * OM_BRANCH_BAND (|sin phi2| >= s2, |sin phi6| >= s6, |sin(phi4 - phi*)| >= sin; the same for
 * every sign, which turns none of them), so no root of a neighbouring configuration holds c by
 * the band contract where the root is proved unique. Where the L range lies wholly beyond
 * the elbow's reach, no configuration has a root in the ball. */
#include "om_system.h"

#define FIXED_POINT_STEPS 60  /* iterations of G at most */
#define FIXED_POINT_STEP 1e-14 /* rad: a step of G this short ends the iteration (a few roundings of an angle) */
#define BEYOND_REACH 1e-9     /* the elbow's |x_e| - 1 beyond which no point is reached (rounding) */
/* cells a side of the torus where the whole does not contract; 4 or more keeps a cell's C' (4 h
 * wide) within pi a side, where the lift's distances are the torus' */
#define FIRST_CELLS 4
#define CELL_DEPTH 5          /* halvings of a cell at most */
#define CELL_BUDGET 400       /* cells examined at most before the search decides */
#define CELL_STACK (FIRST_CELLS * FIRST_CELLS + 3 * CELL_DEPTH + 4)
/* rho / (the model's longest reach) above which the certificate is not tried: lambda is about
 * 15 rho / L where the arm is far from its singularities (the Gen3's 0.016: lambda 0.2 to
 * 0.3), so beyond 0.1 it contracts nowhere and would only add its cells' evaluations to the
 * grid search's (the Sawyer's 0.42: 6 % more) */
#define CERTIFIABLE 0.1

/* A floor of an Euler triple's |det| on the ball, from its value det_c at the centre, for a frame
 * turning at w per unit of |x - c0| (see the top): while |det| >= f > 0, it changes at most at
 * w sqrt(1 + cos_beta^2 / f^2), so along the segment from the centre it stays above least =
 * det_c - rho w sqrt(1 + cos_beta^2 / f^2) wherever least > f: here f is half of det_c - rho w
 * (least's value for cos_beta = 0). Returns that floor, or 0 where there is none. */
static double _floor(double det_c, double w, double cos_beta, double rho)
{
    double f = 0.5 * (det_c - rho * w);
    double least = det_c - rho * w * sqrt(1.0 + (cos_beta / f) * (cos_beta / f));
    return f > 0.0 && least > f ? least : 0.0; /* also NaN */
}

/* r_a = |(D4, D5)|: |a(w1) - D3| and |a'(w1)| are at most r_a. */
static double _rate_a(const om_solver_data *s)
{
    return hypot(v_norm(v_load(s->D[4], 0)), v_norm(v_load(s->D[5], 0)));
}

/* r_d = |(D1, D2)|: |delta(w7) - D0| and |delta'(w7)| are at most r_d. */
static double _rate_d(const om_solver_data *s)
{
    return hypot(v_norm(v_load(s->D[1], 0)), v_norm(v_load(s->D[2], 0)));
}

/* The largest cos(phi) for phi in [a, b] (b - a < 2 pi). */
static double _max_cos(double a, double b)
{
    double turn = 2.0 * OM_PI * ceil(a / (2.0 * OM_PI));
    return turn <= b ? 1.0 : py_max(cos(a), cos(b));
}

/* The elbow's angle phi4 over the ball: the interval [lo, hi] of phi* + ELBOW acos(x_e) for
 * x_e in [x_min, x_max]. */
static void _elbow_range(const double *P, double elbow, double x_min, double x_max, double *lo, double *hi)
{
    *lo = P[SRS_PHI_STAR] + (elbow > 0.0 ? acos(x_max) : -acos(x_min));
    *hi = P[SRS_PHI_STAR] + (elbow > 0.0 ? acos(x_min) : -acos(x_max));
}

/* The least |v_xy| = |(Rz(phi4) u - s3)_xy| for phi4 in [lo, hi]: |v_xy|^2 = |u_xy|^2 + |s3_xy|^2 -
 * 2 |u_xy| |s3_xy| cos(phi4 + offset). */
static double _least_v_xy(const double *P, double lo, double hi)
{
    vec3 u = v_load(P, SRS_U), s3 = v_load(P, SRS_S3);
    double u_xy = hypot(u.x, u.y), s3_xy = hypot(s3.x, s3.y);
    double offset = atan2(u.y, u.x) - atan2(s3.y, s3.x);
    double v2 = u_xy * u_xy + s3_xy * s3_xy - 2.0 * u_xy * s3_xy * _max_cos(lo + offset, hi + offset);
    return sqrt(py_max(v2, 0.0));
}

/* How fast R03 and R04 turn per unit of the elbow's angle, for phi4 in [lo, hi], the reference
 * frame A held: into *w3 and *w4 (see the top). In frame 3, with v = Rz(phi4) u - s3 (v' = z x
 * Rz(phi4) u, |v'| = |v''| = mu = |u_xy|) and the triad's rows a = v_hat, b = +-unit(z x v_xy)
 * (turning in the xy plane at theta' = (v_xy x v_xy')_z / |v_xy|^2), c = a x b: R03 = A^T B
 * turns at omega_B = (-b'.c, a'.c, -a'.b) (the axial vector of B' B^T), and R04 = R03 Rz(phi4) X4
 * at omega_B + B z; the sign of b changes neither length. Their values at the interval's centre,
 * plus its half-width times a bound on their derivatives: a unit vector n = v / |v| has |n'| <=
 * |v'| / |v| and |n''| <= |v''| / |v| + 3 |v'|^2 / |v|^2, so with |v| >= L_lo and |v_xy| >= m,
 * |a'| <= al1 = mu / L_lo, |a''| <= al2 = al1 + 3 al1^2, |b'| <= be1 = mu / m, |b''| <= be2 = be1 +
 * 3 be1^2, |c'| <= al1 + be1, b_z = 0, and the product rule bounds each component's derivative. */
static void _elbow_turning(const double *P, double lo, double hi, double L_lo, double *w3, double *w4)
{
    vec3 u = v_load(P, SRS_U), s3 = v_load(P, SRS_S3);
    double phi = 0.5 * (lo + hi), c4 = cos(phi), s4 = sin(phi);
    vec3 ru = v3(c4 * u.x - s4 * u.y, s4 * u.x + c4 * u.y, u.z);
    vec3 v = v_sub(ru, s3), dv = v3(-ru.y, ru.x, 0.0);
    vec3 a = v_unit(v), da = v_scale(1.0 / v_norm(v), v_sub(dv, v_scale(v_dot(a, dv), a)));
    double vxy2 = v.x * v.x + v.y * v.y;
    vec3 b = v_scale(1.0 / sqrt(vxy2), v3(-v.y, v.x, 0.0));
    vec3 db = v_scale((v.x * dv.y - v.y * dv.x) / vxy2, v3(-b.y, b.x, 0.0)), c = v_cross(a, b);
    vec3 omega = v3(-v_dot(db, c), v_dot(da, c), -v_dot(da, b));
    double mu = hypot(u.x, u.y), m = _least_v_xy(P, lo, hi), al1 = mu / L_lo, be1 = mu / m;
    double al2 = al1 + 3.0 * al1 * al1, be2 = be1 + 3.0 * be1 * be1, ga1 = al1 + be1;
    double change3 = (be2 + be1 * ga1) + (al2 + al1 * ga1) + (al2 + al1 * be1), change4 = change3 + al1 + ga1;
    double half = 0.5 * (hi - lo);
    *w3 = v_norm(omega) + change3 * half;
    *w4 = v_norm(v_add(omega, v3(a.z, b.z, c.z))) + change4 * half;
}

om_torus_bound om_torus_bound_on(om_problem *pb, vec3 p, double rho, double *q)
{
    const double *P = pb->s->params, *th = P + SRS_THETA;
    om_torus_bound bound = {INFINITY, INFINITY, false};
    vec3 c0 = v_add(p, pb->t.wrist);
    double L_c = v_norm(c0), L_lo = py_max(L_c - rho, 0.0), L_hi = L_c + rho, K = P[SRS_K];
    double x_a = (L_lo * L_lo - P[SRS_K0]) / K, x_b = (L_hi * L_hi - P[SRS_K0]) / K;
    double x_min = py_min(x_a, x_b), x_max = py_max(x_a, x_b);
    if (x_min > 1.0 + BEYOND_REACH || x_max < -1.0 - BEYOND_REACH) {
        bound.unreachable = true;
        return bound;
    }
    double x_far = py_max(fabs(x_min), fabs(x_max)), sin_far = sqrt(1.0 - x_far * x_far);
    double up_c = v_dot(v_load(P, SRS_UP), c0) / L_c, half_cos2 = 1.0 + up_c - 2.0 * rho / L_c;
    if (!(L_lo > 0.0) || !(sin_far > OM_BRANCH_BAND) || !(half_cos2 > 0.0)) /* also NaN */
        return bound;
    double lo, hi, turn3, turn4;
    _elbow_range(P, (double)pb->signs[1], x_min, x_max, &lo, &hi);
    _elbow_turning(P, lo, hi, L_lo, &turn3, &turn4);
    double e4 = 2.0 * L_hi / (fabs(K) * sin_far), a_t = sqrt(2.0 / half_cos2) / L_lo;
    double w03 = hypot(a_t, turn3 * e4), w04 = hypot(a_t, turn4 * e4);
    pb->counter++;
    if (om_srs_model_ik(P, &pb->t, p, pb->signs, pb->q_prev, q, true) < 0.0)
        return bound;
    double s2 = _floor(fabs(sin(q[1] + th[1])), w03, 0.0, rho);
    double s6 = _floor(fabs(P[SRS_SIN_BETA] * sin(q[5] + th[5])), w04, P[SRS_COS_BETA], rho);
    bound.g1 = s2 > OM_BRANCH_BAND ? w03 / s2 : INFINITY;
    bound.g7 = s6 > OM_BRANCH_BAND ? w04 / s6 : INFINITY;
    return bound;
}

om_torus_bound om_torus_cell_bound(om_problem *pb, double w1, double w7, double h, double *q)
{
    const om_solver_data *s = pb->s;
    double rho = _rate_a(s) + _rate_d(s);
    if (h >= OM_PI) {
        const double(*D)[3] = s->D;
        vec3 centre = v_add(pb->p, v_add(v_load(D[3], 0), m_mv(pb->t.R, v_load(D[0], 0))));
        return om_torus_bound_on(pb, centre, rho, q);
    }
    return om_torus_bound_on(pb, om_torus_point(pb, w1, w7), rho * py_min(2.0 * h, 2.0), q);
}

/* lambda = r_a g_1 + r_d g_7, G's Lipschitz constant in |.|_g where the bound holds (inf where it does not). */
static double _lipschitz(const om_solver_data *s, om_torus_bound b)
{
    return b.g1 < INFINITY && b.g7 < INFINITY ? _rate_a(s) * b.g1 + _rate_d(s) * b.g7 : INFINITY;
}

/* What the iteration of G in a region where it contracts gives: a root (verified, kept), no
 * decision (it left the region, or the root is not shown to lie in it), or a fixed point that
 * does not verify on the real arm. */
typedef enum { FIXED_POINT_ROOT, FIXED_POINT_UNDECIDED, FIXED_POINT_UNVERIFIED } fixed_point_outcome;

/* G at the torus point (w1, w7): the model IK there into q (G = (q[0], q[6])), one residual
 * evaluation; returns whether the model reaches it. */
static bool _map(om_problem *pb, double w1, double w7, double *q)
{
    pb->counter++;
    return om_srs_model_ik(pb->s->params, &pb->t, om_torus_point(pb, w1, w7), pb->signs, pb->q_prev, q, true) >=
           -OM_REACH_SLACK;
}

/* |(q1, q7) - (w1, w7)|_g on the torus, for the bound's weights g. */
static double _distance(const double *q, double w1, double w7, om_torus_bound b)
{
    return py_max(fabs(om_wrap(q[0] - w1)) / b.g1, fabs(om_wrap(q[6] - w7)) / b.g7);
}

/* Whether the square of |.|_g-radius k about z lies in the square of half-width half about c
 * (half >= pi: the whole torus). */
static bool _inside(double z1, double z7, double k, om_torus_bound b, double c1, double c7, double half)
{
    return half >= OM_PI ||
           (fabs(om_wrap(z1 - c1)) + k * b.g1 <= half && fabs(om_wrap(z7 - c7)) + k * b.g7 <= half);
}

/* G's fixed point in the square C' of half-width half about c = (c1, c7) (half >= pi: the whole
 * torus), where the bound b holds with lambda < 1, by iteration from c (q: the model IK at c,
 * G(c) = (q[0], q[6])) while the iterates stay in C'; with z the last iterate and k = |G(z) -
 * z|_g / (1 - lambda), where the square of |.|_g-radius k about z lies in C' it holds C''s
 * only fixed point (see the top), verified on the real arm and kept in roots (*count of them,
 * deduplicated). */
static fixed_point_outcome _fixed_point(om_problem *pb, double c1, double c7, double half, om_torus_bound b,
                                        double *q, double *roots, int *count)
{
    double lambda = _lipschitz(pb->s, b), z1 = c1, z7 = c7;
    double step = py_max(fabs(om_wrap(q[0] - z1)), fabs(om_wrap(q[6] - z7))), d = _distance(q, z1, z7, b);
    for (int k = 0; k < FIXED_POINT_STEPS && step > FIXED_POINT_STEP; k++) {
        z1 = q[0];
        z7 = q[6];
        if (!_inside(z1, z7, 0.0, b, c1, c7, half) || !_map(pb, z1, z7, q))
            return FIXED_POINT_UNDECIDED; /* (the model reaches every point where the bound holds) */
        step = py_max(fabs(om_wrap(q[0] - z1)), fabs(om_wrap(q[6] - z7)));
        d = _distance(q, z1, z7, b);
    }
    if (!_inside(z1, z7, d / (1.0 - lambda), b, c1, c7, half))
        return FIXED_POINT_UNDECIDED;
    if (!om_verify(pb, q, NULL, NULL) && !om_polish_candidate(pb, q, NULL, NULL))
        return FIXED_POINT_UNVERIFIED;
    *count = om_add_root(pb, q, roots, *count);
    return FIXED_POINT_ROOT;
}

/* A square cell of the torus: centre (w1, w7), half-width h. */
typedef struct {
    double w1, w7, h;
} torus_cell;

/* Whether the cell holds no root: some |F_i(c)| > (1 + g_i rho) h (see the top; q: the model IK
 * at the cell's centre). */
static bool _empty(const om_solver_data *s, torus_cell c, om_torus_bound b, const double *q)
{
    double rho = _rate_a(s) + _rate_d(s);
    return fabs(om_wrap(q[0] - c.w1)) > (1.0 + b.g1 * rho) * c.h || fabs(om_wrap(q[6] - c.w7)) > (1.0 + b.g7 * rho) * c.h;
}

/* Every root in the cells (a stack of n, room for CELL_STACK) into roots (*count of them): each
 * cell proved empty (_empty, or beyond reach), or holding one root in the C' about it (found,
 * verified), or split, down to CELL_DEPTH halvings of the first cell's width. Returns whether
 * every cell was decided (false: a cell left undecided, examined more than CELL_BUDGET, or a
 * fixed point that does not verify on the real arm). */
static bool _decide_cells(om_problem *pb, torus_cell *cells, int n, double *roots, int *count)
{
    const om_solver_data *s = pb->s;
    double q[OM_MAX_DOF], smallest = cells[0].h / (double)(1 << CELL_DEPTH);
    for (int examined = 0; n > 0; examined++) {
        torus_cell c = cells[--n];
        nan_fill(q, OM_MAX_DOF);
        om_torus_bound b = om_torus_cell_bound(pb, c.w1, c.w7, c.h, q);
        if (b.unreachable || _empty(s, c, b, q))
            continue;
        if (_lipschitz(s, b) < 1.0) {
            fixed_point_outcome outcome = _fixed_point(pb, c.w1, c.w7, 2.0 * c.h, b, q, roots, count);
            if (outcome == FIXED_POINT_UNVERIFIED)
                return false;
            if (outcome == FIXED_POINT_ROOT)
                continue;
        }
        if (c.h <= smallest || examined >= CELL_BUDGET) /* (the stack has room for 4 more then) */
            return false;
        double h = 0.5 * c.h;
        for (int k = 0; k < 4; k++)
            cells[n++] = (torus_cell){c.w1 + (k & 1 ? h : -h), c.w7 + (k & 2 ? h : -h), h};
    }
    return true;
}

bool om_torus_certified_roots(om_problem *pb, double *roots, int *count, const double *centre, double radius)
{
    const om_solver_data *s = pb->s;
    const double *P = s->params;
    if (!(_rate_a(s) + _rate_d(s) < CERTIFIABLE * sqrt(P[SRS_K0] + fabs(P[SRS_K]))))
        return false;
    torus_cell cells[CELL_STACK];
    *count = 0;
    if (radius < OM_PI / FIRST_CELLS) { /* a window about the centre's (q1, q7): its one cell */
        cells[0] = (torus_cell){centre[0], centre[6], radius};
        return _decide_cells(pb, cells, 1, roots, count);
    }
    /* the whole torus (a superset of a wider window's roots) */
    double q[OM_MAX_DOF];
    nan_fill(q, OM_MAX_DOF);
    om_torus_bound whole = om_torus_cell_bound(pb, 0.0, 0.0, OM_PI, q);
    if (whole.unreachable)
        return true;
    double c1 = q[0], c7 = q[6]; /* G at the ball's centre: a point of the torus to start from */
    if (_lipschitz(s, whole) < 1.0 && _map(pb, c1, c7, q)) {
        fixed_point_outcome outcome = _fixed_point(pb, c1, c7, OM_PI, whole, q, roots, count);
        if (outcome != FIXED_POINT_UNDECIDED) /* unverified: the search decides */
            return outcome == FIXED_POINT_ROOT;
    }
    int n = 0;
    for (int i = 0; i < FIRST_CELLS; i++)
        for (int j = 0; j < FIRST_CELLS; j++)
            cells[n++] = (torus_cell){-OM_PI + (i + 0.5) * 2.0 * OM_PI / FIRST_CELLS,
                                      -OM_PI + (j + 0.5) * 2.0 * OM_PI / FIRST_CELLS, OM_PI / FIRST_CELLS};
    return _decide_cells(pb, cells, n, roots, count);
}
