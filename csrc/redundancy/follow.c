/* A solution path of one branch followed along the arm angle in one call: the loop of
 * Probe.follow (om_redundant/redundancy/paths/probe.py) for a 7-DOF arm's compiled solver (also link.c's).
 *
 * From the point (psi_0, q_0) with tangent t_0 = dq/dpsi towards psi*: the step h starts at
 * psi* - psi_0; at x = psi_k + h (psi* once within reach) the exact solution q nearest q_k
 * (the solve's hint; where the local solve's root lies on the path beyond doubt, see
 * on_path, it is taken without the scan for a nearer one, and where no root as near can
 * continue the path, the attempt fails without it) is taken at its representative
 * (revolute joints with both limits moved by whole turns nearest mid-range c_i:
 * c_i + wrap(q_i - c_i), for the feasible intervals)
 * and accepted when it continues the path (om_continues: no joint moved more than 1 rad,
 * |Delta q - t_k (x - psi_k)|_inf <= |Delta q|_inf / 2 + 1e-6, cyclic joints compared modulo
 * 2 pi); then h doubles, else it halves; where the path's last two points predict its end
 * short of the next step, h aims just short of it (see follow). The solve is the hinted
 * one's local part alone (om_solve_near): where the local solve from q_k fails, the step is
 * halved without the bounded search, whose answer there is mostly a costly "no" (q_k is
 * nearer the solution at a shorter step, where the local solve succeeds); at a singular
 * boundary it refines from q_k's split of the singular joints alone (om_problem.split_starts:
 * the split starts were half the cost of a follow into an aligned wrist). A step whose
 * prediction moves a joint farther than any continuing root can (farthest) is not solved.
 * Below min_step (probe.py's END_TOLERANCE) the path has ended there; min_step = |psi* -
 * psi_0| makes it one attempt (Probe.next).
 * Each accepted point's tangent is om_self_motion_tangent's; where it does not exist (a
 * fold met exactly) the call stops and says so: the caller's own loop then decides. */
#include <string.h>

#include "om_paths.h"

static void represent(int dof, const uint8_t *centred, const double *centre, double *q) {
    for (int i = 0; i < dof; i++)
        if (centred[i]) q[i] = centre[i] + om_wrap(q[i] - centre[i]);
}

/* The largest joint move max_i |t_i d| of a step d along the tangent t. A root that continues the path
 * (om_continues) moves each joint by m_i with |m_i| <= moved <= 1 and |m_i - t_i d| <= moved / 2
 * + 1e-6, so |t_i d| <= 1.5 moved + 1e-6 <= 1.5 + 1e-6: a step whose prediction moves a joint
 * farther than 1.5 + 2e-6 (1e-6 more for the representatives' rounding) fails whatever the
 * solve would find, and is not solved (the steps into a fold, where |t| grows without bound). */
static double farthest(int dof, const double *t, double d) {
    double r = 0.0;
    for (int i = 0; i < dof; i++) r = fmax(r, fabs(t[i] * d));
    return r;
}
#define FARTHEST_CONTINUED (1.5 + 2e-6)

/* A step's prediction from the path's last point: (q, t) at psi, d ahead, its largest joint
 * move farthest(t, d). */
typedef struct {
    int dof;
    const uint8_t *cyclic, *centred;
    const double *centre, *q, *t;
    double d, farthest;
} prediction;

/* What the attempt makes of the local solve's root x (at its representative; om_solve_near's
 * as_is test). Taken without the windowed scan for a nearer root where it lies on the
 * prediction's path beyond doubt (om_beyond_doubt). Rejected, without the scan, where no root at
 * most as far from q as x can continue the path, the attempt's answer whatever the scan finds:
 * such a root is within d = |x - q|_2 of q (every joint wrapped, the scan's distance), so it
 * moves each joint by m_i with |m_i| <= moved <= r = min(d, 1) and |m_i - t_i h| <= moved / 2 +
 * 1e-6 (om_continues; h the step, the prediction's d), whence |t_i h| <= 1.5 r + 1e-6 and
 * |m_i| >= a_i = max(0, |t_i h| - r / 2 - 1e-6), so sum_i a_i^2 <= |m|_2^2 < d^2 (x itself: = d^2);
 * a prediction that moves some joint farther, or whose a_i exceed that, leaves none (with 1e-6
 * more in each for the representatives' rounding: the a_i are then short of |m_i| by 1e-6 each,
 * far more than d^2's rounding). Else the scan decides. */
static om_root_verdict on_path(const double *x, void *context) {
    const prediction *p = context;
    double r[OM_MAX_DOF], d2 = 0.0, least = 0.0; /* least: sum_i a_i^2 */
    memcpy(r, x, (size_t)p->dof * sizeof(double));
    represent(p->dof, p->centred, p->centre, r);
    if (om_beyond_doubt(p->dof, p->q, r, p->t, p->d, p->cyclic)) return OM_ROOT_TAKE;
    for (int i = 0; i < p->dof; i++) {
        double e = om_wrap(r[i] - p->q[i]);
        d2 += e * e;
    }
    double reach = fmin(sqrt(d2), 1.0);
    for (int i = 0; i < p->dof; i++) {
        double a = fabs(p->t[i] * p->d) - 0.5 * reach - 2e-6;
        if (a > 0.0) least += a * a;
    }
    return p->farthest > 1.5 * reach + 2e-6 || (least > 0.0 && least >= d2) ? OM_ROOT_REJECT : OM_ROOT_SCAN;
}

/* What ends a path, as functions of its point (q, t) that fall to zero there linearly in psi
 * (into f, 1 + n_signs): 1 / |t|^2 at a fold (q - q_f ~ (psi_f - psi)^(1/2), so |t|^2 ~
 * 1 / (psi_f - psi)), and s_i b_i + OM_BRANCH_BAND where a branch quantity b_i leaves its
 * sign s_i beyond the band that verify allows (verify.c). */
static void end_measures(const om_solver_data *s, const int64_t *signs, const double *q, const double *t,
                         double *f) {
    double tt = 0.0, b[3];
    for (int i = 0; i < s->dof; i++) tt += t[i] * t[i];
    f[0] = 1.0 / tt;
    om_solver_configuration_values(s, q, b, NULL);
    for (int i = 0; i < s->n_signs; i++) f[1 + i] = (double)signs[i] * b[i] + OM_BRANCH_BAND;
}

/* The distance in psi ahead of the last point (measures f) to the nearest end that the
 * secant of a measure falling towards zero predicts, from the point before (f_prev, a
 * distance d behind); INFINITY where none falls. */
static double predicted_end(int n, const double *f_prev, const double *f, double d) {
    double r = INFINITY;
    for (int i = 0; i < n; i++)
        if (f[i] > 0.0 && f[i] < f_prev[i]) r = fmin(r, d * f[i] / (f_prev[i] - f[i]));
    return r;
}

/* Follow from (psi, q, t) towards target; q and t are updated in place to the point reached
 * (om_paths.h). Where the secant of an end measure predicts the path's end short of the next step, the step
 * aims just short of it instead (OM_FOLLOW_AIM of the way, at least 1.5 min_step): the end is then
 * approached in a few successful steps rather than by halving, each halving costing about
 * two attempts, most of them failing beyond the end, where a failed local solve is the
 * costliest. A step of 1.5 min_step that fails ends the path as the halving would (below
 * min_step); an aimed step that fails is halved, one that succeeds doubled, as any other. */
int om_follow_path(const om_branch *branch, double *psi, double *q, double *t, double target, double min_step,
                   int *steps) {
    const om_solver_data *s = branch->s;
    const int64_t *signs = branch->signs;
    const uint8_t *cyclic = branch->cyclic, *centred = branch->centred;
    const double *centre = branch->centre;
    int dof = s->dof, n_ends = 1 + s->n_signs;
    double step = target - *psi, x_q[OM_MAX_DOF], x_t[OM_MAX_DOF];
    double ends[4], ends_prev[4], moved = 0.0; /* moved: psi from the point before (0: none yet) */
    end_measures(s, signs, q, t, ends);
    *steps = 0;
    for (int attempts = 0, crawled = 0; *psi != target; attempts++) {
        if (fabs(step) < min_step) return OM_FOLLOW_ENDED;
        if (attempts == OM_FOLLOW_MAX_ATTEMPTS || crawled == OM_FOLLOW_CRAWL_STEPS) return OM_FOLLOW_STALLED;
        double x = fabs(target - *psi) <= fabs(step) ? target : *psi + step;
        double aim = moved > 0.0 ? fmax(OM_FOLLOW_AIM * predicted_end(n_ends, ends_prev, ends, moved), 1.5 * min_step) : INFINITY;
        if (aim < fabs(x - *psi)) x = *psi + copysign(aim, step);
        prediction p = {dof, cyclic, centred, centre, q, t, x - *psi, farthest(dof, t, x - *psi)};
        bool ok = p.farthest <= FARTHEST_CONTINUED &&
                  om_solve_near(s, branch->T, signs, &x, q, x_q, on_path, &p, NULL, branch->traces);
        if (ok) { /* (a root without a tangent, a fold met exactly, fails as any other) */
            represent(dof, centred, centre, x_q);
            ok = om_continues(dof, q, x_q, t, x - *psi, cyclic) && om_self_motion_tangent(s, x_q, x_t, 0.0);
        }
        if (!ok) { /* (halved from x, not from step: psi* nearer than step is not tried again) */
            step = 0.5 * (x - *psi);
            continue;
        }
        moved = fabs(x - *psi);
        crawled = moved < OM_FOLLOW_CRAWL ? crawled + 1 : 0;
        step = 2.0 * (x - *psi);
        *psi = x;
        memcpy(q, x_q, (size_t)dof * sizeof(double));
        memcpy(t, x_t, (size_t)dof * sizeof(double));
        memcpy(ends_prev, ends, sizeof ends);
        end_measures(s, signs, q, t, ends);
        (*steps)++;
    }
    return OM_FOLLOW_ARRIVED;
}
