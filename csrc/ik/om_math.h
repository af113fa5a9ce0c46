/* Tuple math and angle wrapping: small vectors and 3x3 matrices by value, inlined.
 * A port of om_redundant's former numba tuple helpers; every expression keeps the Python
 * operand order (numba evaluated left to right), so results agree to the bit. */
#ifndef OM_MATH_H
#define OM_MATH_H

#include <math.h>

typedef struct {
    double x, y, z;
} vec3;

typedef struct {
    vec3 r0, r1, r2; /* rows */
} mat3;

#define OM_PI 3.141592653589793 /* np.pi */

/* The package's one angle wrap (om_redundant/angles.py's wrap_angle and wrap_angles, alike to
 * the bit): x - k 2 pi in [-pi, pi), exactly (2 pi the double 2.0 * OM_PI). x itself in range
 * (-0.0 included); else fmod, which is exact, and r -+ 2 pi for |r| in [pi, 2 pi), exact too
 * (Sterbenz). NaN for an infinite x. */
static inline double om_wrap(double x)
{
    if (x >= -OM_PI && x < OM_PI) return x;
    double r = fmod(x, 2.0 * OM_PI);
    return r >= OM_PI ? r - 2.0 * OM_PI : r < -OM_PI ? r + 2.0 * OM_PI : r;
}

/* numpy's minimum and maximum of two floats: a NaN operand gives NaN (fmin and fmax drop it). */
static inline double om_least(double a, double b) { return isnan(a) ? a : isnan(b) ? b : fmin(a, b); }
static inline double om_most(double a, double b) { return isnan(a) ? a : isnan(b) ? b : fmax(a, b); }

/* np.sign of a float as numba computes it: +-1, and x itself for 0 (keeping -0) and NaN. */
static inline double om_sign(double x)
{
    if (x > 0.0)
        return 1.0;
    if (x < 0.0)
        return -1.0;
    return x;
}

static inline vec3 v3(double x, double y, double z)
{
    vec3 a = {x, y, z};
    return a;
}

/* a[i], i in 0..2. */
static inline double v_get(vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }

/* The 3-vector P[i:i+3]. */
static inline vec3 v_load(const double *P, int i) { return v3(P[i], P[i + 1], P[i + 2]); }

static inline vec3 v_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }

static inline vec3 v_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }

static inline vec3 v_scale(double k, vec3 a) { return v3(k * a.x, k * a.y, k * a.z); }

static inline double v_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static inline double v_norm(vec3 a) { return sqrt(v_dot(a, a)); }

static inline vec3 v_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

static inline vec3 v_unit(vec3 a) { return v_scale(1.0 / sqrt(v_dot(a, a)), a); }

/* The row-major 3x3 matrix P[i:i+9]. */
static inline mat3 m_load(const double *P, int i)
{
    mat3 A = {v_load(P, i), v_load(P, i + 3), v_load(P, i + 6)};
    return A;
}

static inline vec3 m_row(mat3 A, int i) { return i == 0 ? A.r0 : (i == 1 ? A.r1 : A.r2); }

static inline vec3 m_col(mat3 A, int j) { return v3(v_get(A.r0, j), v_get(A.r1, j), v_get(A.r2, j)); }

static inline mat3 m_transpose(mat3 A)
{
    mat3 T = {m_col(A, 0), m_col(A, 1), m_col(A, 2)};
    return T;
}

/* A @ v. */
static inline vec3 m_mv(mat3 A, vec3 v) { return v3(v_dot(A.r0, v), v_dot(A.r1, v), v_dot(A.r2, v)); }

/* A @ B. */
static inline mat3 m_mm(mat3 A, mat3 B)
{
    mat3 Bt = m_transpose(B);
    mat3 C = {m_mv(Bt, A.r0), m_mv(Bt, A.r1), m_mv(Bt, A.r2)};
    return C;
}

/* A @ B.T. */
static inline mat3 m_mmt(mat3 A, mat3 B)
{
    mat3 C = {m_mv(B, A.r0), m_mv(B, A.r1), m_mv(B, A.r2)};
    return C;
}

/* A.T @ B. */
static inline mat3 m_mtm(mat3 A, mat3 B) { return m_mm(m_transpose(A), B); }

/* Rz(phi) @ X for c = cos(phi), s = sin(phi). */
static inline mat3 m_rz_cs_times(double c, double s, mat3 X)
{
    mat3 C = {v_sub(v_scale(c, X.r0), v_scale(s, X.r1)), v_add(v_scale(s, X.r0), v_scale(c, X.r1)), X.r2};
    return C;
}

/* Python's max(a, b) on floats: b if b > a else a (so max(NaN, x) is NaN, max(x, NaN) is x). */
static inline double py_max(double a, double b) { return b > a ? b : a; }
/* Python's min(a, b) on floats: b if b < a else a. */
static inline double py_min(double a, double b) { return b < a ? b : a; }

/* sum_j wrap(a_j - b_j)^2 over n joints: the squared distance of joint vectors modulo turns. */
static inline double om_wrapped_distance2(const double *a, const double *b, int n)
{
    double d = 0.0;
    for (int j = 0; j < n; j++) {
        double e = om_wrap(a[j] - b[j]);
        d += e * e;
    }
    return d;
}

/* max_j |wrap(a_j - b_j)| over n joints. */
static inline double om_wrapped_distance_max(const double *a, const double *b, int n)
{
    double d = 0.0;
    for (int j = 0; j < n; j++)
        d = py_max(d, fabs(om_wrap(a[j] - b[j])));
    return d;
}

#endif
