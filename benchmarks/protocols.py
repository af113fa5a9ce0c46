"""The measurements: every peer on the same targets, judged by the arm's own FK.

Targets come from joint vectors drawn uniformly within the limits (seeded), so every target
is reachable and its true joint vector ``q`` is known. A returned joint vector counts as a
success when, after shifting revolute joints by multiples of 2 pi into the limits where
possible, it reaches the target within :data:`POSITION_TOLERANCE` and
:data:`ORIENTATION_TOLERANCE` (checked with ``arm.fk``, never with the peer's own report)
and lies within the limits (plus the peer's float32 slack).

Only the library call is timed (``time.perf_counter``, per target, from Python, garbage
collector paused); converting targets and results is not.
"""

from __future__ import annotations

import gc
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

import om_redundant as om

from .adapters import BatchMethod, Method, Peer, shift_into_limits, within_limits
from .robots import pose_errors

POSITION_TOLERANCE = 1e-6
ORIENTATION_TOLERANCE = 1e-6
#: Distinct solutions differ by more than this in some joint (rad, modulo 2 pi).
SAME_SOLUTION = 1e-6
#: Range of an unlimited prismatic joint when drawing targets (the OM paper's +-0.5 m).
PRISMATIC_RANGE = 0.5

#: The protocols, by key, with their titles.
PROTOCOLS = {
    "exact": "Exact solve for a given redundancy",
    "any": "Any in-limit solution for a pose",
    "every": "All solutions for a pose and a redundancy value",
}


@dataclass(frozen=True, eq=False)
class Targets:
    """N target poses and the joint vectors they came from.

    Attributes:
        arm: The arm.
        q: (N, dof) true joint vectors.
        T: (N, 4, 4) their end-effector poses.
    """

    arm: om.Arm
    q: np.ndarray
    T: np.ndarray

    @classmethod
    def random(cls, arm: om.Arm, n: int, seed: int) -> Targets:
        """Joint vectors uniform within limits; unlimited revolute joints in [-pi, pi]."""
        rng = np.random.default_rng(seed)
        span = np.where(arm.revolute, np.pi, PRISMATIC_RANGE)
        lower = np.where(np.isfinite(arm.lower), arm.lower, -span)
        upper = np.where(np.isfinite(arm.upper), arm.upper, span)
        q = rng.uniform(lower, upper, (n, arm.dof))
        return cls(arm, q, np.array([arm.fk(row) for row in q]))


@dataclass(frozen=True)
class Outcome:
    """One peer on one protocol and arm.

    Attributes:
        protocol: Key in :data:`PROTOCOLS`.
        arm: Arm name.
        peer: Peer name.
        n: Number of targets.
        success: Fraction of targets with a successful joint vector.
        median_us: Median time per target (microseconds).
        p99_us: 99th percentile of the time per target.
        median_error: Median over targets of the best returned vector's error,
            max(position in m, orientation in rad); inf where nothing was returned.
        solutions: Mean number of distinct exact solutions per target (``every`` only).
        true_found: Fraction of targets whose true q is among the solutions (``every`` only).
    """

    protocol: str
    arm: str
    peer: str
    n: int
    success: float
    median_us: float
    p99_us: float
    median_error: float
    solutions: float | None = None
    true_found: float | None = None


@dataclass(frozen=True)
class _Judgement:
    success: bool
    best_error: float
    distinct: int
    true_found: bool


def judge(
    arm: om.Arm, T: np.ndarray, q_true: np.ndarray, Q: np.ndarray, limit_tolerance: float
) -> _Judgement:
    """Check joint vectors Q (k, dof) returned for target T against ``arm.fk`` and the limits."""
    if len(Q) == 0:
        return _Judgement(False, np.inf, 0, False)
    Q = shift_into_limits(Q, arm, limit_tolerance)
    errors = np.array([pose_errors(arm.fk(q), T) for q in Q])
    exact = (errors[:, 0] < POSITION_TOLERANCE) & (errors[:, 1] < ORIENTATION_TOLERANCE)
    within = within_limits(Q, arm, limit_tolerance)
    distinct: list[np.ndarray] = []
    for q in Q[exact]:
        if not any(_same(q, other, arm) for other in distinct):
            distinct.append(q)
    return _Judgement(
        success=bool((exact & within).any()),
        best_error=float(errors.max(axis=1).min()),
        distinct=len(distinct),
        true_found=any(_same(q, q_true, arm) for q in distinct),
    )


def _same(a: np.ndarray, b: np.ndarray, arm: om.Arm) -> bool:
    difference = a - b
    difference[arm.revolute] = (difference[arm.revolute] + np.pi) % (2 * np.pi) - np.pi
    return bool(np.abs(difference).max() < SAME_SOLUTION)


def measure(peer: Peer, protocol: str, targets: Targets) -> Outcome:
    """Run one peer's method for ``protocol`` on every target."""
    method: Method = getattr(peer, protocol)
    arguments = [method.prepare(T, q) for T, q in zip(targets.T, targets.q, strict=True)]
    method.call(arguments[0])  # warm up (compilation, caches)
    results, seconds = _timed(method.call, arguments)
    judgements = [
        judge(targets.arm, T, q, method.solutions(argument, result), peer.limit_tolerance)
        for T, q, argument, result in zip(targets.T, targets.q, arguments, results, strict=True)
    ]
    us = np.asarray(seconds) * 1e6
    every = protocol == "every"
    return Outcome(
        protocol=protocol,
        arm=targets.arm.name,
        peer=peer.name,
        n=len(arguments),
        success=float(np.mean([j.success for j in judgements])),
        median_us=float(np.median(us)),
        p99_us=float(np.percentile(us, 99)),
        median_error=float(np.median([j.best_error for j in judgements])),
        solutions=float(np.mean([j.distinct for j in judgements])) if every else None,
        true_found=float(np.mean([j.true_found for j in judgements])) if every else None,
    )


def _timed(call: Callable, arguments: list) -> tuple[list, list[float]]:
    clock = time.perf_counter
    results, seconds = [], []
    gc.collect()
    gc.disable()
    try:
        for argument in arguments:
            start = clock()
            result = call(argument)
            seconds.append(clock() - start)
            results.append(result)
    finally:
        gc.enable()
    return results, seconds


# ---------------------------------------------------------------------------------------
# Batch throughput


@dataclass(frozen=True)
class Throughput:
    """Solves per second of one batch call over all targets, by wall time and by CPU time.

    Attributes:
        arm: Arm name.
        peer: Peer name and call.
        n: Targets in the batch.
        seconds: Median wall time of the batch call (its own threads) over the repeats.
        cpu_seconds: Median CPU time of the same call on one thread (``time.process_time``,
            so threads the library starts count too) over the repeats: what the work costs,
            whatever else shares the cores.
        success: Fraction of targets solved (same test as the other protocols).
    """

    arm: str
    peer: str
    n: int
    seconds: float
    cpu_seconds: float
    success: float

    @property
    def per_second(self) -> float:
        return self.n / self.seconds

    @property
    def cpu_ms_per_1000(self) -> float:
        return 1e6 * self.cpu_seconds / self.n


def measure_batches(
    methods: list[tuple[BatchMethod, float]], targets: Targets, repeats: int = 5
) -> list[Throughput]:
    """Time ``repeats`` rounds of every batch method (with its limit tolerance) over all targets.

    Each round runs every method's threaded call (wall time) and its one-thread call (CPU
    time) in turn, so that other work on the machine weighs on all methods alike; the
    medians count.
    """
    arguments = [method.prepare(targets.T, targets.q) for method, _ in methods]
    for (method, _), argument in zip(methods, arguments, strict=True):  # warm up
        method.call(argument)
        method.one_thread(argument)
    walls = np.empty((repeats, len(methods)))
    cpus = np.empty((repeats, len(methods)))
    results: list[Any] = [None] * len(methods)
    gc.collect()
    gc.disable()
    try:
        for r in range(repeats):
            for i, ((method, _), argument) in enumerate(zip(methods, arguments, strict=True)):
                start = time.perf_counter()
                results[i] = method.call(argument)
                walls[r, i] = time.perf_counter() - start
                start = time.process_time()
                method.one_thread(argument)
                cpus[r, i] = time.process_time() - start
    finally:
        gc.enable()
    throughputs = []
    for i, (method, tolerance) in enumerate(methods):
        found = method.solutions(arguments[i], results[i])
        success = np.mean(
            [
                judge(targets.arm, T, q, Q, tolerance).success
                for T, q, Q in zip(targets.T, targets.q, found, strict=True)
            ]
        )
        throughputs.append(
            Throughput(
                targets.arm.name,
                method.name,
                len(targets.q),
                float(np.median(walls[:, i])),
                float(np.median(cpus[:, i])),
                float(success),
            )
        )
    return throughputs
