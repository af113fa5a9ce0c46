/* A damped Gauss-Newton refinement of a joint vector on the REAL arm's chain: the last
 * digits of a candidate that the model's closed form loses where it is singular (a branch
 * quantity at zero, where an angle comes from acos or atan2 of a vanishing pair). Any start
 * q; whatever it returns is checked by the caller with the real FK and the configuration. */
#include "om_system.h"

#define POLISH_ROWS 7          /* pose (6) + the arm angle */
#define POLISH_DAMPING 1e-12   /* initial lambda^2, relative to the largest diagonal of J J^T */
#define POLISH_DAMPING_MIN 1e-18 /* its floor as steps succeed */
#define POLISH_DAMPING_MAX 1e-2 /* a step refused at this damping ends the refinement */
#define POLISH_DONE 1e-15      /* residual (m, rad) below which the refinement stops */
#define POLISH_WINDOW 10       /* Jacobians over which |e| must at least halve while above POLISH_FAR */
#define POLISH_FAR 1e-6        /* residual (m, rad) above which a crawl is given up */
/* |grad psi| beyond which the arm-angle row is divided by |grad psi| / PSI_ROW_SCALE: next to
 * psi's singular half-line |grad psi| grows as 1 / rho, and that row would swamp the pose rows
 * (the damping is relative to the largest row) while its residual is psi's rounding there */
#define PSI_ROW_SCALE 1e3

static const double IDENTITY[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/* The divisor of the arm-angle row at q with d psi / dq = grad: max(1, |grad| / PSI_ROW_SCALE). */
static double psi_row_scale(const double *grad, int dof)
{
    double g2 = 0.0;
    for (int j = 0; j < dof; j++)
        g2 += grad[j] * grad[j];
    return py_max(1.0, sqrt(g2) / PSI_ROW_SCALE);
}

/* The residual e (rows: p - p(q); the rotation vector of R R(q)^T; psi - psi(q), divided by
 * psi_row_scale) in DH frame 0; returns its squared norm. With the arm angle, its Jacobian row
 * (d psi / dq over the same scale) into psi_row (dof): computed here, with psi. The chain's walk
 * to the flange keeps the joints' frames (frames, 12 per joint) and the flange (chain_end: R, then
 * p), from which the Jacobian at q follows without a second walk (jacobian). */
static double residual(const om_polish_task *t, const double *q, double *e, double *psi_row, double *frames,
                       double *chain_end)
{
    double *Rc = chain_end, *pc = chain_end + 9;
    om_joint_frames(t->table, t->n_rows, q, t->dof, frames, Rc, pc); /* (every row: the table has dof joints) */
    e[0] = t->p.x - pc[0];
    e[1] = t->p.y - pc[1];
    e[2] = t->p.z - pc[2];
    mat3 E = m_mmt(t->R, m_load(Rc, 0)); /* R R(q)^T: the rotation still to go, in frame 0 */
    vec3 w = v3(0.5 * (E.r2.y - E.r1.z), 0.5 * (E.r0.z - E.r2.x), 0.5 * (E.r1.x - E.r0.y));
    double s = sqrt(v_dot(w, w));
    double angle = atan2(s, 0.5 * (E.r0.x + E.r1.y + E.r2.z - 1.0));
    double k = s > 0.0 ? angle / s : 1.0; /* rotation vector = angle * axis */
    e[3] = k * w.x;
    e[4] = k * w.y;
    e[5] = k * w.z;
    int rows = t->P ? 7 : 6;
    if (t->P) {
        double psi = om_arm_angle_gradient(t->P, t->model_table, t->n_model_rows, q, psi_row);
        double scale = psi_row_scale(psi_row, t->dof);
        for (int j = 0; j < t->dof; j++)
            psi_row[j] /= scale;
        /* psi's reference flips by pi with the ELBOW branch: read it in the requested one */
        double own = sin(q[3] + t->P[SRS_THETA + 3] - t->P[SRS_PHI_STAR]) < 0.0 ? -1.0 : 1.0;
        bool flipped = t->elbow != 0.0 && own != t->elbow;
        e[6] = om_wrap(t->psi + (flipped ? OM_PI : 0.0) - psi) / scale;
    }
    double cost = 0.0;
    for (int i = 0; i < rows; i++)
        cost += e[i] * e[i];
    return cost;
}

/* The Jacobian of the pose and of psi at q (rows x dof) from residual's outputs at q. */
static void jacobian(const om_polish_task *t, const double *frames, const double *chain_end, const double *psi_row,
                     double *J)
{
    om_jacobian_from_frames(t->table, t->n_rows, IDENTITY, IDENTITY, frames, chain_end, chain_end + 9, t->dof, J);
    if (t->P)
        memcpy(J + 6 * t->dof, psi_row, (size_t)t->dof * sizeof(double));
}

/* A's Cholesky factor L (n x n symmetric positive definite, its lower triangle overwritten by
 * L); returns false if A is not positive definite to working precision. */
static bool cholesky_factor(double *A, int n)
{
    for (int j = 0; j < n; j++) {
        double d = A[j * n + j];
        for (int k = 0; k < j; k++)
            d -= A[j * n + k] * A[j * n + k];
        if (!(d > 0.0))
            return false;
        A[j * n + j] = sqrt(d);
        for (int i = j + 1; i < n; i++) {
            double v = A[i * n + j];
            for (int k = 0; k < j; k++)
                v -= A[i * n + k] * A[j * n + k];
            A[i * n + j] = v / A[j * n + j];
        }
    }
    return true;
}

/* b replaced by y with L L^T y = b (L: cholesky_factor's). */
static void cholesky_substitute(const double *L, double *b, int n)
{
    const double *A = L;
    for (int i = 0; i < n; i++) { /* L z = b */
        for (int k = 0; k < i; k++)
            b[i] -= A[i * n + k] * b[k];
        b[i] /= A[i * n + i];
    }
    for (int i = n - 1; i >= 0; i--) { /* L^T y = z */
        for (int k = i + 1; k < n; k++)
            b[i] -= A[k * n + i] * b[k];
        b[i] /= A[i * n + i];
    }
}

/* Solve the symmetric positive definite A y = b (n x n, A overwritten by its Cholesky
 * factor); returns false if A is not positive definite to working precision. */
static bool cholesky_solve(double *A, double *b, int n)
{
    if (!cholesky_factor(A, n))
        return false;
    cholesky_substitute(A, b, n);
    return true;
}

/* J J^T (rows x rows, from J: rows x dof) into G; returns its largest diagonal entry. */
static double gram(const double *J, int rows, int dof, double *G)
{
    double scale = 0.0;
    for (int a = 0; a < rows; a++) { /* symmetric: each product sum once */
        for (int b = 0; b <= a; b++) {
            double d = 0.0;
            for (int j = 0; j < dof; j++)
                d += J[a * dof + j] * J[b * dof + j];
            G[a * rows + b] = G[b * rows + a] = d;
        }
        scale = py_max(scale, G[a * rows + a]);
    }
    return scale;
}

/* Refine q in place by damped Gauss-Newton steps dq = J^T (J J^T + lambda^2 I)^-1 e: the
 * minimum-norm step, well defined where J loses rank (the singular boundary). lambda grows
 * by 100 on a step that does not lower |e| and shrinks by 10 on one that does; at most
 * `iterations` Jacobians; with t->give_up_crawl, none more once |e|, still above POLISH_FAR,
 * has not halved over the last POLISH_WINDOW (near a root, even a double one, it falls by far
 * more; far from one, that is a crawl along a valley of |e| that does not reach zero).
 * Returns |e| at the end (q is only ever replaced by a better one). */
double om_polish(const om_polish_task *t, int iterations, double *q)
{
    int dof = t->dof, rows = t->P ? 7 : 6;
    double e[POLISH_ROWS], e_try[POLISH_ROWS], J[POLISH_ROWS * OM_MAX_DOF], A[POLISH_ROWS * POLISH_ROWS];
    double G[POLISH_ROWS * POLISH_ROWS];
    double y[POLISH_ROWS], q_try[OM_MAX_DOF], psi_row[OM_MAX_DOF], psi_row_try[OM_MAX_DOF];
    double frames[12 * OM_MAX_DOF], chain_end[12];
    double cost = residual(t, q, e, psi_row, frames, chain_end);
    jacobian(t, frames, chain_end, psi_row, J);
    double damping = POLISH_DAMPING;
    double window_cost = cost; /* the cost POLISH_WINDOW Jacobians ago */
    for (int it = 0; it < iterations && cost > POLISH_DONE * POLISH_DONE && isfinite(cost); it++) {
        if (it > 0 && it % POLISH_WINDOW == 0) { /* a crawl, not a root's convergence */
            if (t->give_up_crawl && cost > POLISH_FAR * POLISH_FAR && cost > 0.25 * window_cost)
                break;
            window_cost = cost;
        }
        double scale = gram(J, rows, dof, G); /* J J^T, its largest diagonal */
        bool improved = false;
        while (!improved && damping <= POLISH_DAMPING_MAX) {
            memcpy(A, G, (size_t)(rows * rows) * sizeof(double));
            for (int a = 0; a < rows; a++) {
                A[a * rows + a] += damping * scale;
                y[a] = e[a];
            }
            if (cholesky_solve(A, y, rows)) {
                for (int j = 0; j < dof; j++) {
                    double dq = 0.0;
                    for (int a = 0; a < rows; a++)
                        dq += J[a * dof + j] * y[a];
                    q_try[j] = q[j] + dq;
                }
                double c = residual(t, q_try, e_try, psi_row_try, frames, chain_end);
                improved = c < cost;
                if (improved) {
                    memcpy(q, q_try, (size_t)dof * sizeof(double));
                    memcpy(e, e_try, sizeof e);
                    cost = c;
                    jacobian(t, frames, chain_end, psi_row_try, J);
                    damping = py_max(damping / 10.0, POLISH_DAMPING_MIN);
                    break;
                }
            }
            damping *= 100.0;
        }
        if (!improved)
            break;
    }
    return sqrt(cost);
}

/* Newton's steps with the start's Jacobian (the chord method; the minimum-norm step, damped as
 * om_polish's first): from a start within e of a simple root, where the Jacobian changes by
 * about e relative over the steps, each step multiplies the residual by about e, so that from
 * e = 1e-6 two steps reach rounding, for one Jacobian and one factorization (om_polish: one of
 * each per step). No step is tested: the caller verifies q. Stops early at |e| below
 * POLISH_DONE, where the last two residuals' rate puts the next below it (not computed to show
 * it: from 1e-6, two steps and two residuals), or where the residual is not finite or the
 * factorization fails. */
void om_polish_chord(const om_polish_task *t, int steps, double *q)
{
    int dof = t->dof, rows = t->P ? 7 : 6;
    double e[POLISH_ROWS], J[POLISH_ROWS * OM_MAX_DOF], A[POLISH_ROWS * POLISH_ROWS];
    double psi_row[OM_MAX_DOF], frames[12 * OM_MAX_DOF], chain_end[12];
    double cost = residual(t, q, e, psi_row, frames, chain_end);
    if (!(cost > POLISH_DONE * POLISH_DONE && isfinite(cost)))
        return;
    jacobian(t, frames, chain_end, psi_row, J);
    double scale = gram(J, rows, dof, A);
    for (int a = 0; a < rows; a++)
        A[a * rows + a] += POLISH_DAMPING * scale;
    if (!cholesky_factor(A, rows))
        return;
    double last = NAN; /* the cost before the last step (squared norms, as cost) */
    for (int k = 0; k < steps; k++) {
        if (k > 0) {
            /* at the last two steps' rate, cost / last, the next cost is below POLISH_DONE^2:
             * no residual is computed to show it */
            if (cost * cost < POLISH_DONE * POLISH_DONE * last)
                return;
            last = cost;
            cost = residual(t, q, e, psi_row, frames, chain_end);
            if (!(cost > POLISH_DONE * POLISH_DONE && isfinite(cost)))
                return;
        }
        cholesky_substitute(A, e, rows);
        for (int j = 0; j < dof; j++) {
            double dq = 0.0;
            for (int a = 0; a < rows; a++)
                dq += J[a * dof + j] * e[a];
            q[j] += dq;
        }
    }
}
