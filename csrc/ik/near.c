/* Arms NEAR a closed-form family: the OM system (9) with the nominal arm as the model's side,
 * its orientation difference included (om_redundant/ik/nominal.py builds the nominal arm).
 *
 * The real arm's exact chain (in the nominal joint coordinates q) and its nominal arm (twists
 * snapped to right angles, reversed axes flipped, fixed rows merged, small lengths zeroed)
 * differ at the flange by a small rigid motion, the correction
 *
 *     C(q) = T_real(q)^-1 T_nom(q),   |C(q) - I| <= delta (om_solver_data.near_deviation, m at
 *                                     the hand: the snapped angles times the reach and the
 *                                     zeroed lengths, summed),
 *
 * so T_real(q) = T_d exactly where T_nom(q) = T_d C(q): q is a root of the nominal arm, an
 * exact-family arm, for the target T_d C(q). The nominal arm's own OM system reduces, for a
 * target T, to the circle (torus) of its model: with X_T(w) the model's target at the circle's
 * point w (p_d + R delta(w); on the torus also a(w1)) and IK_m(X, c) the model's closed form in
 * configuration c, its roots are the zeros of g_T(w) = wrap(IK_m(X_T(w), c)_J - w). For the real
 * arm the target itself moves with q: at the circle's point w,
 *
 *     q = Phi_w(q) := IK_m(X_{T_d C(q)}(w), c),       G(w) = wrap(q_J - w)  at that fixed point,   (N)
 *
 * and every model IK of its search (om_near_ik, om_near_settle) iterates Phi_w until C settles.
 *
 * Exactness. At a zero of G with its fixed point q: q_J = w, so X_{T_d C(q)}(q_J) is the model's
 * pose at q (IK_m inverts the model's FK), which is T_nom(q) moved by dp(q) (the construction of
 * the exact family's system), so T_nom(q) = T_d C(q) and T_real(q) = T_d. Conversely a real root
 * q* in c is the fixed point of Phi_{w*}, w* = q*_J (IK_m is one-to-one in c off the model's
 * singular set, the paper's condition C2), with G(w*) = 0: the real roots in c are the zeros of
 * G. c is read by the model's branch quantities at q (om_verify), whose signs IK_m gives by
 * construction: no neighbouring configuration holds a root of c that G lacks, and a target that
 * the nominal arm does not reach but the real arm does is reached by the corrected target.
 *
 * The fixed point. |dPhi_w/dq| <= L = |dIK_m/dX| |dC/dq|, with |dC/dq| <= delta per radian.
 * Where L < 1 -- the model IK well conditioned against delta: all of the circle but within
 * about delta |dIK_m/dX| of the model's singular set, where |dIK_m/dX| grows as 1 / |b| (b the
 * branch quantities: a wrist's or shoulder's Euler angle, the elbow's square root at the edge
 * of reach) -- Phi_w is a contraction: the fixed point is unique near q and the iteration
 * converges to it at rate L (from C = I at every evaluation: G is then a function of w alone,
 * as the exact family's g is), and G is as continuous in w as g (its Lipschitz constant grows
 * by 1 / (1 - L)).
 *
 * The search (circle.c). Over the circle G differs from the nominal arm's own g~ = g_{T_d} by
 * |G - g~| <= |dg/dX| delta: small where the model is well conditioned. The bounded search runs
 * on g~ (the exact family's scan at the target, at its cost), every candidate it finds refined
 * on G (om_all_roots), and G is searched -- by the same bounded search, in windows of the circle
 * -- wherever it may cross zero and g~ does not: where g~ comes within a multiple of delta of
 * zero without crossing it (a local minimum, a dip seen by a cell's halving) and G, evaluated
 * there, is of the other sign or within four times its difference from g~ of zero (the
 * difference changes little along a cell: the real arm's folds, a double zero of G, lie there);
 * where g~ swings steeply (a singular wrist, which the correction may move); at each edge of
 * reach, where g turns as a square root and G's edge lies about |m_G| / m' away (m the reach
 * margin), unless G at g~'s edge stays clear of zero by four times its difference and that
 * square root's run-on; between samples out of reach whose margin peaks within a multiple of
 * delta of zero; and about the samples whose model comes within a multiple of delta of its
 * singular set (an S-R-S arm's scan solves q7 alone, as the exact family's does: there the
 * ELBOW quantity sqrt(margin); its SHOULDER's and WRIST's singular swings show in g~ itself).
 * The multiples (OM_NEAR_SENSITIVITY) bound the sensitivity of g, the margins and the branch
 * quantities to the target with room (1 to 20 per metre away from the singular set). So the
 * zeros of G are those of the search of G itself, the exact family's argument (sign changes
 * bracket roots, extremum searches find close pairs, edges and islands of reach are searched),
 * with G read as g~ where both are far from zero. Above OM_NEAR_SCAN (where the windows would
 * take most of the circle) the search is of G throughout; on the torus its grid samples g~ and
 * every Newton run from the grid's starts is on G (torus.c). At a 6-DOF arm's
 * aligned wrist the fixed point need not contract (the model splits the wrist by q_prev, the
 * real arm does not; the correction at the split moves by about delta / |sin q5|), and G's q6
 * need not be the real root's: within a multiple of delta of it the window is searched on the
 * wrist's residual with q6 = w given (om_wrist_residual, smooth there), whose zeros are the
 * real roots as G's are. What the argument does not cover: within about delta |dIK_m/dX| >= 1
 * of the rest of the model's singular set the iteration need not contract (it stops after
 * NEAR_STEPS), and a root whose fixed point exists only there is a candidate like any other,
 * polished on the real arm and verified, or missed: on a set of targets of measure O(delta).
 * Every answer is polished on the exact chain to its last digits (om_near_polish).
 *
 * The local solve (om_near_secant: from the fixed-point start, the hint, the solve's other
 * starts) needs one root, not all: the nominal arm's root from its start (the secant on g~, the
 * exact family's cost), then Newton's steps on the exact chain from it, which is within about
 * delta of the real root, verified as every candidate is; the secant on G only where they do
 * not verify. The search above is unchanged: its every candidate is refined on G.
 *
 * The correction on the left (om_solver_data.near_left): a 7-DOF arm's shoulder offset a2,
 * which the nominal arm zeroes (nominal.py), moves the joints after it by a2 x2(q1, q2), so
 * L(q) = T_nom(q) T_real(q)^-1 is the translation by dp(q1, q2) in DH frame 0 and (N) reads
 * q = IK_m(X_{L(q) T_d}(w), c): the model's target p_d + dp(q), the OM system (9) itself. On
 * the torus q1 = w1 is given, so the fixed point turns with q2 alone, at the rate
 * |dq2/dp| a2, about a2 / |W - S| but growing as 1 / (angle from psi's half-line) near it,
 * where the translation is mixed from the last two steps (_mixed). On the right the same
 * translation, seen from the flange through the iterate's orientation, turned with every
 * joint, and crept (rate 0.95 on the Unitree G1 at a2 = 20 mm, 16 steps short of settling).
 * A 7-DOF wrist offset a5 (the common normal of joints 5 and 6, Baxter's), which the nominal
 * arm zeroes too, moves the flange by a5 x5, which seen from the flange turns with q6 and q7:
 * there the correction stays on the right, and with q7 given on the torus its fixed point
 * turns with q6 alone, mixed as well (om_solver_data.near_mixed); of an arm with both, the
 * larger offset's side is taken, the other's translation turning with the fixed point's
 * other joints at its own (small) rate.
 *
 * Out of the model's reach there is no q to correct from; where the margin is within
 * OM_NEAR_SENSITIVITY times delta of it, the nearest pose the model reaches gives one
 * (om_model_ik_nearest), so that a target which only the corrected system reaches (beyond the
 * nominal arm's shoulder, a real arm reaching a little farther) is reached. */
#include "om_system.h"

#define NEAR_STEPS 16      /* fixed-point steps of the correction per model IK, at most */
#define NEAR_SETTLED 1e-14 /* a correction moving by at most this (R, p in m: ten of their rounding) has settled */
#define NEAR_RATE 0.1      /* a convergence rate below which the next move is predicted from the last two */
/* Where the evaluation's residual r is not near zero, the correction settles to NEAR_RELATIVE |r|
 * (at most NEAR_COARSE): r is then off by about that times the model IK's sensitivity to its
 * target (some units), relative 1e-8, which its sign and the search's steps do not notice; at
 * a root, r -> 0, to NEAR_SETTLED */
#define NEAR_RELATIVE 1e-9
#define NEAR_COARSE 1e-10
#define NEAR_POLISH 3         /* Gauss-Newton steps of a root's polish on the exact chain */
#define NEAR_POLISH_FROM 1e-8 /* m + rad: the pose errors of a root polished, from ... */
#define NEAR_POLISHED 1e-14   /* ... down to (rounding: left as it is) */
#define NEAR_CHORD 3          /* chord steps (at most) from the nominal arm's root to the real one's (om_near_secant) ... */
#define NEAR_NEWTON 4         /* ... and Gauss-Newton steps where they do not verify */

/* C(q) = T_real(q)^-1 T_nom(q), or on the left (s->near_left) L(q) = T_nom(q) T_real(q)^-1, into
 * (*R, *p) (q in the kernels' coordinates). */
static void _correction(const om_solver_data *s, const double *q, mat3 *R, vec3 *p)
{
    double Rr[9], pr[3], Rn[9], pn[3];
    om_flange_pair(s->real_table, s->n_real_rows, s->nominal_table, s->n_nominal_rows, q, Rr, pr, Rn, pn);
    mat3 real = m_load(Rr, 0);
    if (s->near_left) {
        *R = m_mmt(m_load(Rn, 0), real);
        *p = v_sub(v_load(pn, 0), m_mv(*R, v_load(pr, 0)));
        return;
    }
    *R = m_mtm(real, m_load(Rn, 0));
    *p = m_mv(m_transpose(real), v_sub(v_load(pn, 0), v_load(pr, 0)));
}

/* The largest entry of |A - B| and |a - b|. */
static double _moved(mat3 A, vec3 a, mat3 B, vec3 b)
{
    const vec3 d[4] = {v_sub(A.r0, B.r0), v_sub(A.r1, B.r1), v_sub(A.r2, B.r2), v_sub(a, b)};
    double most = 0.0;
    for (int i = 0; i < 4; i++)
        most = py_max(most, py_max(py_max(fabs(d[i].x), fabs(d[i].y)), fabs(d[i].z)));
    return most;
}

void om_set_goal(om_problem *pb, const mat3 *R, vec3 p)
{
    const om_solver_data *s = pb->s;
    pb->goal = om_target_at(s->family, s->params, R, pb->redundancy);
    pb->goal_p = p;
    pb->t = pb->goal;
    pb->p = p;
}

/* pb's model side moved to goal C (or L goal, s->near_left) for the correction (R, p). */
static void _apply(om_problem *pb, mat3 R, vec3 p)
{
    const om_solver_data *s = pb->s;
    mat3 target;
    if (s->near_left) {
        target = m_mm(R, pb->goal.R);
        pb->p = v_add(m_mv(R, pb->goal_p), p);
    } else {
        target = m_mm(pb->goal.R, R);
        pb->p = v_add(pb->goal_p, m_mv(pb->goal.R, p));
    }
    pb->t = om_target_at(s->family, s->params, &target, pb->redundancy);
}

/* The correction's translation, the fixed point's variable, mixed from its last two steps
 * (Anderson's): the translation next tried is g - gamma (g - g_prev), g = Phi(x) the step's
 * image of its variable x, f = g - x, gamma = f . (f - f_prev) / |f - f_prev|^2, the root of
 * the secant through the two steps' f. With q1 and q7 given (the torus) a shoulder offset's
 * translation turns with q2 alone, a wrist offset's with q6, a curve: the mixed iteration
 * converges where the plain one creeps or diverges, near psi's half-line, where q2 turns fast
 * with the target (rate a2 / |W - S| over the distance from the line, above 1 within about
 * a2 / |W - S| rad of it). */
typedef struct {
    bool known;
    vec3 g, f; /* the last step's image and f */
} near_mix;

static vec3 _mixed(near_mix *mix, vec3 x, vec3 g)
{
    vec3 f = v_sub(g, x), next = g;
    if (mix->known) {
        vec3 df = v_sub(f, mix->f);
        double dd = v_dot(df, df), gamma = dd > 0.0 ? v_dot(f, df) / dd : NAN;
        if (isfinite(gamma))
            next = v_sub(g, v_scale(gamma, v_sub(g, mix->g)));
    }
    mix->known = true, mix->g = g, mix->f = f;
    return next;
}

/* pb's model side moved to goal C(q) (or L(q) goal), the correction into (*R, *p): C(q) itself,
 * or a left one's translation mixed (mix not NULL, _mixed). Returns how far C(q) is from them. */
static double _retarget(om_problem *pb, const double *q, mat3 *R, vec3 *p, near_mix *mix)
{
    mat3 C_R;
    vec3 C_p;
    _correction(pb->s, q, &C_R, &C_p);
    double moved = _moved(C_R, C_p, *R, *p);
    *R = C_R;
    *p = mix ? _mixed(mix, *p, C_p) : C_p;
    _apply(pb, *R, *p);
    return moved;
}

/* How far a correction must settle for an evaluation whose residual is r (see NEAR_RELATIVE). */
static double _settled(double r)
{
    return py_max(NEAR_SETTLED, py_min(NEAR_COARSE, NEAR_RELATIVE * fabs(r))); /* (NaN r: NEAR_COARSE) */
}

/* Each evaluation starts from the goal (C = I), not from the last one's correction: the
 * evaluation is then a function of its arguments, as the exact family's is -- the same w
 * evaluated twice is in reach both times or neither (an edge of reach found by bisection
 * stays inside), and the search's brackets and extremum searches see one function. */
double om_near_settle(om_problem *pb, om_model_eval eval, const void *args, double *q)
{
    mat3 C_R = {v3(1.0, 0.0, 0.0), v3(0.0, 1.0, 0.0), v3(0.0, 0.0, 1.0)};
    vec3 C_p = v3(0.0, 0.0, 0.0);
    double nearest[OM_MAX_DOF], residual, ignored, last = INFINITY;
    near_mix mix = {false, v3(0.0, 0.0, 0.0), v3(0.0, 0.0, 0.0)};
    double margin = eval(pb, args, q, false, &residual);
    for (int k = 0; k < NEAR_STEPS; k++) {
        const double *at = q;
        if (!(margin >= -OM_REACH_SLACK)) { /* out of reach: correct from the nearest pose, if near */
            if (!(margin >= -OM_NEAR_SENSITIVITY * pb->s->near_deviation) ||
                !(eval(pb, args, nearest, true, &ignored) >= -INFINITY))
                break;
            at = nearest;
        }
        double moved = _retarget(pb, at, &C_R, &C_p, pb->s->near_mixed ? &mix : NULL), settled = _settled(residual);
        if (moved <= settled)
            break;
        margin = eval(pb, args, q, false, &residual);
        settled = _settled(residual);
        /* converging at the rate moved / last: the next move would be below settled */
        if (last < INFINITY && moved < NEAR_RATE * last && moved * moved <= settled * last &&
            margin >= -OM_REACH_SLACK)
            break;
        last = moved;
    }
    pb->t = pb->goal;
    pb->p = pb->goal_p;
    return margin;
}

/* The correction's fixed point settles to NEAR_SETTLED and the search's root of G to
 * OM_ROOT_TOL: their effect on the pose, times the model IK's sensitivity, is 1e-14 to 1e-11
 * (m, rad); NEAR_POLISH Gauss-Newton steps on the exact chain take a root within
 * NEAR_POLISH_FROM of the pose (quadratically) to its rounding. The polish's minimum-norm
 * steps keep it at that root. */
static bool _polished(om_problem *pb, double *q, double p0, double o0, bool verified, double *pos, double *ori)
{
    double polished[OM_MAX_DOF], p1, o1;
    if (!(p0 + o0 > NEAR_POLISHED && p0 + o0 < NEAR_POLISH_FROM)) {
        if (pos)
            *pos = p0, *ori = o0;
        return verified;
    }
    om_polish_task t = om_problem_polish_task(pb);
    memcpy(polished, q, (size_t)pb->s->dof * sizeof(double));
    om_polish(&t, NEAR_POLISH, polished);
    if (om_verify(pb, polished, &p1, &o1) && p1 + o1 < p0 + o0) {
        memcpy(q, polished, (size_t)pb->s->dof * sizeof(double));
        p0 = p1, o0 = o1, verified = true;
    }
    if (pos)
        *pos = p0, *ori = o0;
    return verified;
}

bool om_near_polish(om_problem *pb, double *q, double *pos, double *ori)
{
    double p0, o0;
    bool verified = om_verify(pb, q, &p0, &o0);
    return _polished(pb, q, p0, o0, verified, pos, ori);
}

/* A returned root's polish, its errors known from its verification: most are within
 * NEAR_POLISHED already, and the FK is not walked again. */
void om_near_finish(om_problem *pb, double *q, double *pos, double *ori)
{
    _polished(pb, q, *pos, *ori, true, pos, ori);
}

/* The nominal arm's root q (every joint: T_nom(q) = T_d, psi and c met on the model) is within
 * about delta of the real arm's root nearest it, whose pose error it is (|C(q) - I| <= delta):
 * Newton's steps on the exact chain from q take it there, NEAR_CHORD of them with q's Jacobian
 * (om_polish_chord: each multiplies the error by about delta, 1e-6 -> 1e-12 -> rounding; at
 * delta = 1e-4 to 1e-12, which om_near_polish takes to rounding), where the secant on G from q
 * takes three or four evaluations of G, each a fixed point of two or three model IKs and
 * corrections. The root it reaches is verified like every other (pose to the tolerances, c by
 * the model's branch quantities and psi at it); where it does not, NEAR_NEWTON damped
 * Gauss-Newton steps from q (om_polish) are, and where their root does not verify either -- q
 * next to the model's singular set, where the real root need not be the nearest one, or no
 * real root there -- q is left as it was, and om_near_secant goes on with the secant on G. */
static bool _newton(om_problem *pb, double *q, double *pos, double *ori)
{
    double x[OM_MAX_DOF];
    size_t size = (size_t)pb->s->dof * sizeof(double);
    om_polish_task t = om_problem_polish_task(pb);
    memcpy(x, q, size);
    om_polish_chord(&t, NEAR_CHORD, x);
    if (!om_verify(pb, x, pos, ori)) {
        memcpy(x, q, size);
        om_polish(&t, NEAR_NEWTON, x);
        if (!om_verify(pb, x, pos, ori))
            return false;
    }
    memcpy(q, x, size);
    return true;
}

bool om_near_secant(om_problem *pb, double w, bool in_reach, double *q, double *pos, double *ori)
{
    double (*secant)(om_problem *, double, double *) = in_reach ? om_secant_in_reach : om_secant;
    if (om_scans_nominal(pb->s) && pb->s->mode == OM_CIRCLE) { /* the nominal arm's root first */
        pb->nominal = true;
        bool touched = secant(pb, w, q) < OM_TOUCH;
        pb->nominal = false;
        if (touched && _newton(pb, q, pos, ori)) /* the real root nearest it, verified */
            return true;
        if (touched) /* G's from it */
            w = q[pb->s->dp_joint];
    }
    secant(pb, w, q);
    return false;
}

bool om_near_lifted(om_problem *pb, const double *start, double *q, double *pos, double *ori)
{
    pb->nominal = true;
    bool touched = om_lifted_solve(pb, start, q) < OM_TOUCH;
    pb->nominal = false;
    return touched && _newton(pb, q, pos, ori);
}

/* ------------------------------------------------------------------------------------ */
/* The arm's own joint coordinates: q = flip * q_n, q_n the kernels' (a near arm's reversed
 * axes turn the other way in its nominal arm). */

void om_flip(const om_solver_data *s, const double *in, double *out)
{
    for (int j = 0; j < s->dof; j++)
        out[j] = s->flip[j] * in[j];
}

/* q in the kernels' coordinates into scratch, returned (q itself where nothing is flipped). */
static const double *_kernels(const om_solver_data *s, const double *q, double *scratch)
{
    if (!s->flipped)
        return q;
    om_flip(s, q, scratch);
    return scratch;
}

void om_solver_jacobian(const om_solver_data *s, const double *q, double *J, double *R, double *p)
{
    static const double eye[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    double scratch[OM_MAX_DOF];
    int dof = s->dof;
    om_jacobian(s->real_table, s->n_real_rows, eye, eye, _kernels(s, q, scratch), dof, J, R, p);
    for (int i = 0; i < 6 && s->flipped; i++)
        for (int j = 0; j < dof; j++)
            J[i * dof + j] *= s->flip[j];
}

double om_solver_psi_gradient(const om_solver_data *s, const double *q, double *grad)
{
    double scratch[OM_MAX_DOF];
    double psi = om_arm_angle_gradient(s->params, s->model_table, s->n_model_rows, _kernels(s, q, scratch), grad);
    if (s->flipped)
        om_flip(s, grad, grad);
    return psi;
}

void om_solver_configuration_values(const om_solver_data *s, const double *q, double *branch, double *redundancy)
{
    double scratch[OM_MAX_DOF];
    const double *at = _kernels(s, q, scratch);
    om_branch_values(s->family, s->params, at, branch);
    if (redundancy)
        om_redundancy_values(s->family, s->params, at, redundancy);
}
