/* Damped Newton on the lifted system (w1, w7, phi4) of an arm with shoulder offsets, deflated
 * by the known roots, in a chart around psi's half-line or not (the method:
 * om_redundant/ik/kernel_data.py). */
#include "torus.h"

#define MIN_STEP (1.0 / 256.0) /* the shortest damped Newton step, as a fraction of the full one */
#define STALL 3                /* slow damped Newton steps in a row after which a run gives up */

/* Whether a run at x (lifted) gives up within its limits (see newton_limits). */
static bool _gives_up(const newton_limits *limits, vec3 x, bool deflated)
{
    if (py_max(fabs(om_wrap(x.x - limits->w1)), fabs(om_wrap(x.y - limits->w7))) > limits->reach)
        return true;
    return !deflated && near_known(limits, x);
}

/* Damped Newton on the lifted system from x = (w1, w7, phi4) (chart not NULL: in its
 * coordinates, x and the steps there), forward-difference Jacobian, deflated by the first
 * n_known rows of known (n x 3), giving up within limits (NULL: none). Returns the max norm of
 * the (undeflated) residual at the end (inf if not finite, or where the run gave up); the end
 * point (lifted) in *x_end, q the model IK there (solved once, at the end: the iterations need
 * the residual alone; not where the run gave up). */
double om_lifted_newton(om_problem *pb, const half_line_chart *chart, vec3 x, double *q, const double *known,
                        int n_known, const newton_limits *limits, vec3 *x_end)
{
    vec3 F = om_deflated_residual(pb, lifted_of(chart, x), NULL, known, n_known);
    double r = om_max_norm(F);
    double eps = 1e-7;
    int slow = 0;
    vec3 Fn = v3(NAN, NAN, NAN); /* set by the first damped step; NaN until then */
    for (int it = 0; it < 30; it++) {
        if (!(r < INFINITY) || r < 1e-15 || slow == STALL)
            break;
        /* Rows of the Jacobian, then the step -J^-1 F by cofactors. */
        vec3 F0 = om_deflated_residual(pb, lifted_of(chart, v3(x.x + eps, x.y, x.z)), NULL, known, n_known);
        vec3 F1 = om_deflated_residual(pb, lifted_of(chart, v3(x.x, x.y + eps, x.z)), NULL, known, n_known);
        vec3 F2 = om_deflated_residual(pb, lifted_of(chart, v3(x.x, x.y, x.z + eps)), NULL, known, n_known);
        vec3 rows[3];
        for (int i = 0; i < 3; i++) {
            double Fi = v_get(F, i);
            rows[i] = v3((v_get(F0, i) - Fi) / eps, (v_get(F1, i) - Fi) / eps, (v_get(F2, i) - Fi) / eps);
        }
        vec3 c0 = v_cross(rows[1], rows[2]), c1 = v_cross(rows[2], rows[0]), c2 = v_cross(rows[0], rows[1]);
        double det = v_dot(rows[0], c0);
        if (!(fabs(det) > 0.0)) /* also NaN */
            break;
        vec3 step = v_scale(-1.0 / det, v_add(v_add(v_scale(F.x, c0), v_scale(F.y, c1)), v_scale(F.z, c2)));
        double size = py_max(py_max(fabs(step.x), fabs(step.y)), fabs(step.z));
        double t = size < 0.5 ? 1.0 : 0.5 / size;
        while (t > MIN_STEP) {
            Fn = om_deflated_residual(pb, lifted_of(chart, v_add(x, v_scale(t, step))), NULL, known, n_known);
            if (om_max_norm(Fn) < r) /* false for NaN */
                break;
            t *= 0.5;
        }
        if (t <= MIN_STEP)
            break;
        x = v_add(x, v_scale(t, step));
        F = Fn;
        if (limits && _gives_up(limits, lifted_of(chart, x), n_known > 0)) {
            if (x_end)
                *x_end = lifted_of(chart, x);
            return INFINITY;
        }
        slow = om_max_norm(F) > 0.9 * r ? slow + 1 : 0;
        r = om_max_norm(F);
    }
    /* q must belong to the final iterate. */
    x = lifted_of(chart, x);
    r = om_max_norm(om_lifted_residual(pb, x, q));
    if (x_end)
        *x_end = x;
    return r < INFINITY ? r : INFINITY;
}

/* Damped Newton on the lifted system in (q1, q7, phi4) from the joint vector start;
 * returns the final residual, q holding the model IK there. */
double om_lifted_solve(om_problem *pb, const double *start, double *q)
{
    return om_lifted_newton(pb, NULL, lifted_point(pb->s, start), q, NULL, 0, NULL, NULL);
}
