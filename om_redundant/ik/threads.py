"""The worker threads of batch solves: rows in chunks, the kernels releasing the GIL."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

#: Rows of a batch handed to one thread at a time.
BATCH_CHUNK = 64

_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()
_PREFIX = "om_redundant"  # the pool threads' names
_CORES = os.cpu_count() or 1  # read once: os.cpu_count() reads a file (~30 us a call on Linux)


def _forget_the_pool() -> None:
    """In a forked child: the parent's pool threads do not exist there (a batch would wait for
    them forever); the child makes its own when it needs one."""
    global _pool, _pool_lock
    _pool, _pool_lock = None, threading.Lock()


os.register_at_fork(after_in_child=_forget_the_pool)


def run_rows(
    solve_range: Callable[[int, int], None], rows: int, threads: int | None = None, chunk: int = BATCH_CHUNK
) -> None:
    """Run ``solve_range(start, stop)`` over ``range(rows)`` in chunks of ``chunk`` rows (fewer,
    to give every thread one), on ``threads`` threads.

    The kernels release the GIL, so threads run them in parallel; each thread takes the next
    chunk as it comes free, which balances targets of unequal cost. The calling thread is one
    of them (it would only wait otherwise; on a busy machine a pool thread may be slow to
    wake, and then the caller takes its chunks). ``threads`` None: one per core (at most that
    many in any case); 1: every row on the calling thread, in one call, as from a pool thread
    itself (a chunk that runs a batch of its own: its helpers could wait behind it in the
    pool's queue). An exception in the
    calling thread (Ctrl-C: KeyboardInterrupt, raised between its chunks) stops every thread
    after its current chunk, and is raised at once.
    """
    global _pool
    cores = _CORES
    workers = cores if threads is None else min(cores, threads)
    if rows <= chunk or workers == 1 or threading.current_thread().name.startswith(_PREFIX):
        solve_range(0, rows)
        return
    with _pool_lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(cores, thread_name_prefix=_PREFIX)
    chunk = max(1, min(chunk, -(-rows // workers)))
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
