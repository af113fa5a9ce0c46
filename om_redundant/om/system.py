r"""The OM system (9) and its solvers: the data of the compiled kernels (``csrc/``).

System (9) asks for the model's hand position :math:`p_m` with

.. math::  p_m = p_d + \Delta p\big(\mathrm{IK}_{model}(R_d, p_m, c)\big).

Every solution has the form :math:`p_m = p_d + R_d\,\delta(w)`, where :math:`\delta` is dp
seen from the flange and depends on one wrist joint, :math:`w = q_J` (see
:mod:`om_redundant.om.model`). So the three equations reduce exactly to one on the circle,

.. math::  g(w) = \mathrm{wrap}\big(\mathrm{IK}_{model}(R_d, p_d + R_d\,\delta(w), c)_J - w\big) = 0,

and a root gives the real arm's joints :math:`q = \mathrm{IK}_{model}(\ldots)` with
:math:`|p_{real}(q) - p_d| = |\delta(w) - \delta(q_J)| \le \Delta p_{max}\,|g(w)|`.
A 6-DOF wrist with :math:`a_4 \ne 0` has the circle :math:`p_m = p_d + \Delta p(w)`,
:math:`w = q_1`, instead (:mod:`om_redundant.om.model`, ``csrc/wrist_offset.c``).

Arms with shoulder offsets (Gen3, Sawyer) add :math:`a(q_1)`, so solutions lie on a torus
:math:`(w_1, w_7) = (q_1, q_7)`: :math:`p_m = p_d + a(w_1) + R_d\,\delta(w_7)`. There the
system is lifted to three unknowns :math:`(w_1, w_7, \varphi_4)` and three residuals that
are smooth everywhere (:func:`~om_redundant.om.families.srs.model_ik_lifted`): the model IK
with q1, q7 and the elbow angle given is consistent with the shoulder, the wrist and the
elbow equation. In (w1, w7) alone the residual has a square-root branch point at the edge of
reach (the straight or folded elbow) and steep Euler angles at the shoulder and wrist
singularities, which is where roots crowd; lifted, Newton's method converges there.

* Local solve: Broyden's method, which in one unknown is the secant method, started with a
  finite-difference slope, from the joint of the paper's fixed-point start
  (:math:`p_m = p_d`) or of a hint; on the torus, damped Newton on the lifted system. On a
  7-DOF circle arm, where the secant fails (g's square root at the edge of reach sends it
  out of reach) or p_d is beyond the model's reach (the start then holds the elbow at the
  edge), the same lifted Newton, with zero shoulder offsets, takes over.
* Bounded search, the paper's guarantee: g is sampled on a grid over the whole circle (the
  image of the ball :math:`|p_m - p_d| \le \Delta p_{max}` that can hold solutions); each sign
  change is refined; near the edges of the model's reach, at local minima of |g| and on
  small islands of reach, where roots come in close pairs, 1-D extremum searches find
  them. On the torus, a grid of the lifted residual seeds Newton's method, with deflation
  and a search along each root's fold direction for close pairs (``csrc/torus.c``);
  this is a thorough search rather than a proof. Before it, a certificate
  (``csrc/contraction.c``) bounds how fast the model's q1 and q7 turn as the wrist centre
  moves over the ball that holds the torus: where the map w -> (q1, q7) contracts (in a
  weighted max norm), on the whole torus or on cells of it, Banach's theorem proves each
  cell's root unique, found by iterating the map, and cells where the residual cannot
  vanish are proved empty; only where it decides nothing (singular shoulder or wrist, the
  edge of reach, psi's half-line, most Sawyer poses) does the grid search run. Every
  candidate is verified with the REAL arm's forward kinematics.

The kernels are C (``csrc/``, one file per idea: ``residual.c``, ``scalar.c`` (secant,
regula falsi, Brent), ``circle.c``, ``torus.c``, ``verify.c``, ``search.c``, ``solve.c``),
compiled when the package is installed: no compile at run time. They work in DH frame 0
with the flange pose. What crosses into them is :class:`SolverData`, copied once per solver
into :class:`om_redundant._core.Solver`, and per call the pose, the configuration's
tuples and C-contiguous float64 arrays.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .. import _core

# Status codes of a solve, and their names by code (defined in csrc/: om_kernels.h, module.c).
OK = _core.OK
UNREACHABLE = _core.UNREACHABLE
NO_SOLUTION_IN_CONFIGURATION = _core.NO_SOLUTION_IN_CONFIGURATION
STATUS_NAMES: tuple[str, ...] = _core.STATUS_NAMES

# How the solutions of system (9) are searched (SolverData.mode; csrc/om_kernels.h).
FIXED = _core.FIXED  # dp = 0: the model is the real arm, one evaluation of the closed form
CIRCLE = _core.CIRCLE  # dp depends on one wrist joint w = q_J: a circle
TORUS = _core.TORUS  # shoulder offsets too: dp depends on (q_1, q_7), a torus

#: Roots kept per configuration.
MAX_ROOTS = _core.MAX_ROOTS

#: A solver's fixed data, as the compiled kernels take it (defined with the kernels' other
#: records in :mod:`om_redundant._core`).
SolverData = _core.SolverData


def flange_target(
    T: np.ndarray, T_base_root: np.ndarray, T_tool_flange: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The flange pose (R, p) in DH frame 0 for an end-effector pose T in the root frame:
    ``T_base_root @ T @ T_tool_flange``, as the kernels compute it."""
    R, p = np.empty((3, 3)), np.empty(3)
    _core.flange_target(
        as_kernel_array(T), as_kernel_array(T_base_root), as_kernel_array(T_tool_flange), R, p
    )
    return R, p


def as_kernel_array(array: np.ndarray) -> np.ndarray:
    """The array as the kernels take it: C-contiguous float64 (a copy only if needed)."""
    return np.ascontiguousarray(array, dtype=np.float64)


#: Rows of a batch handed to one thread at a time.
BATCH_CHUNK = 64

_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()
_CORES = os.cpu_count() or 1  # read once: os.cpu_count() reads a file (~30 us a call on Linux)


def _forget_the_pool() -> None:
    """In a forked child: the parent's pool threads do not exist there (a batch would wait for
    them forever); the child makes its own when it needs one."""
    global _pool, _pool_lock
    _pool, _pool_lock = None, threading.Lock()


os.register_at_fork(after_in_child=_forget_the_pool)


def run_rows(solve_range: Callable[[int, int], None], rows: int, threads: int | None = None) -> None:
    """Run ``solve_range(start, stop)`` over ``range(rows)`` in chunks, on ``threads`` threads.

    The kernels release the GIL, so threads run them in parallel; each thread takes the next
    chunk as it comes free, which balances targets of unequal cost. The calling thread is one
    of them (it would only wait otherwise; on a busy machine a pool thread may be slow to
    wake, and then the caller takes its chunks). ``threads`` None: one per core (at most that
    many in any case); 1: every row on the calling thread, in one call. An exception in the
    calling thread (Ctrl-C: KeyboardInterrupt, raised between its chunks) stops every thread
    after its current chunk, and is raised at once.
    """
    global _pool
    cores = _CORES
    workers = cores if threads is None else min(cores, threads)
    if rows <= BATCH_CHUNK or workers == 1:
        solve_range(0, rows)
        return
    with _pool_lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(cores, thread_name_prefix="om_redundant")
    chunk = max(1, min(BATCH_CHUNK, -(-rows // workers)))
    starts, lock, stop = iter(range(0, rows, chunk)), threading.Lock(), threading.Event()

    def drain() -> None:
        while not stop.is_set():
            with lock:
                start = next(starts, None)
            if start is None:
                return
            solve_range(start, min(start + chunk, rows))

    helpers = [_pool.submit(drain) for _ in range(workers - 1)]
    try:
        drain()
        for future in helpers:
            future.result()
    except BaseException:
        stop.set()  # (the helpers finish the chunk they are in, into the abandoned batch's arrays)
        raise
