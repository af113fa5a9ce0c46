/* Private helpers of the OM system's kernels (residual.c ... solve.c): Python's float
 * semantics where the algorithm relies on them. Not part of the binding's contract. */
#ifndef OM_SYSTEM_H
#define OM_SYSTEM_H

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "om_kernels.h"


/* Python's a % n for n > 0 (never negative). */
static inline int py_mod(int a, int n) { int r = a % n; return r < 0 ? r + n : r; }

/* A scratch joint vector starts as NaN: a check of joints never written (a local solve whose
 * first point is out of reach) then always fails, never depends on what a previous call left. */
static inline void nan_fill(double *q, int n) { for (int j = 0; j < n; j++) q[j] = NAN; }

#endif
