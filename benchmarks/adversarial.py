"""Adversarial reliability (issue 18): wrong answers, false "no", stray exceptions, repeatability.

Run: ``python -m benchmarks.adversarial [--arms ...] [--n-random 100000] [--n-singular 10000]
[--seed 0] [--quick] [--jobs 1]``; writes ``results/adversarial.md`` (``--quick``, 1/100 of the
sizes: ``results/adversarial_quick.md``) and the reproducers of every failure found
(at most :data:`KEEP` per class, arm and kind) as ``.json`` beside it. ``--jobs N`` runs N arms
at a time in separate processes; ``--classes`` and ``--no-bad-input`` select what runs. The full
run takes about 12 minutes in one process on a 2-core AMD EPYC (sawyer and gen3 are half of
it); ``--quick`` about 10 s. Sizes per arm: ``--n-random`` random poses, ``--n-singular``
branch-boundary poses plus a quarter as many at joint limits and (7-DOF, ``--n-line``) a tenth
as many next to psi's singular half-line, and 1/50 of ``--n-random`` for huge/tiny, threads
and repeated (1/1000 for layouts, each in about 12 layouts).

Every shipped arm (``om.arm_names()``) gets these attack classes; every answer marked ok is
checked against MuJoCo's own FK of the project's MJCF of the arm (``om.arm_model(arm)``,
``mj_kinematics`` on ``qpos = q``, the arm's end-effector site), not against ``arm.fk``:

* **random**: q uniform within limits (unlimited joints in [-pi, pi]), T = FK(q),
  c = configuration_of(q); ``solve`` without a hint, with the hint q + N(0, 0.05),
  ``solve_batch`` of all, ``solve_all`` (which must hold q). A false "no" is ok False, or an
  empty ``solve_all``.
* **singular**: q moved along one joint, within its limits, to a randomly drawn crossing so
  that a branch quantity (``om.om.families.branch_values``, index 0, 1, 2) is +-10**u, u
  uniform in [-14, -3]; and joints at their limits +- 1e-12. Then ``solve``, hinted ``solve``
  and ``solve_all`` in c = configuration_of(q). Also "the other side": the flipped sign where
  |offset| <= ``om.BRANCH_BAND`` (1e-7), where the pose belongs to both configurations.
* **huge/tiny**: hints of magnitude 1e3 ... 1e300; psi + 2 pi k for huge k (the same answer as
  for ``math.remainder(psi, 2 pi)``); poses translated by 1e3 ... 1e300 m (ok False,
  "unreachable"); translations changed by 1e-300 (a reachable pose) or of size 1e-300.
* **layouts**: Fortran-order, read-only, strided, big-endian and list inputs for T, q_hint,
  batch signs and redundancy: identical answers to the C-order call.
* **threads**: 4 threads sharing one solver agree bit for bit with serial calls;
  ``solve_batch`` equals per-row ``solve``.
* **repeated**: the same questions (random, near-singular, other branches, hinted,
  ``solve_all``, batch rows) asked again in random order, each after another call.
* **bad input** (:mod:`benchmarks.bad_input`): items 5 to 9 of the issue; the exception
  raised and whether it is an ``om.OMError``; for the command, in a subprocess, the exit
  status and the lines on stderr.

An ok answer is **wrong** if MuJoCo's FK differs from T by more than 1e-10 m or 1e-10 rad,
or q is not in the requested configuration (``OMSolver.holds``: signs equal, a branch quantity
within ``om.BRANCH_BAND`` of zero counting for both; psi, read in the requested ELBOW branch,
within 1e-9 modulo 2 pi or within its own rounding next to its singular half-line), or
``within_limits`` is not
``lower <= q <= upper``. A **non-library exception** is anything raised that is not an
``om.OMError``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import pickle
import platform
import sys
import threading
import time
import zlib
from collections import Counter
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

import om_redundant as om
from om_redundant import _core
from om_redundant.mujoco_io.mjcf import DEFAULT_SITE
from om_redundant.om import system
from om_redundant.om.families import branch_values, redundancy_values

from .bad_input import BadInput, bad_input_table, run_bad_inputs
from .report import RESULTS, cpu_model, write_page
from .robots import random_joints

TURN = 2.0 * math.pi
POSITION_TOLERANCE = 1e-10  # m, MuJoCo's FK against T (at |p| up to 1e5 m; see FK_ROUNDING)
#: Relative part of the position check, for poses 1e5 ... 1e300 m away (arms with an unlimited
#: prismatic joint reach them): each coordinate of an FK is a sum of terms of size |p|, each
#: rounded to eps |p| / 2, and MuJoCo sums them in another order than the library, so two
#: exact FKs of the same q differ by a few eps |p| (measured: 0.3 ... 1.1 eps |p| at 1e89 ...
#: 1e125 m). The check's position tolerance is max(POSITION_TOLERANCE, FK_ROUNDING |p|): the
#: checker's rounding, not the library's tolerance (the solver still verifies to 1e-10 m).
FK_ROUNDING = 8.0 * float(np.finfo(np.float64).eps)
ORIENTATION_TOLERANCE = 1e-10  # rad
BRANCH_BAND = om.BRANCH_BAND  # a branch quantity this close to zero counts for both signs
REDUNDANCY_TOLERANCE = 1e-9  # rad, modulo 2 pi
ROOT_MATCH = 1e-6  # rad (or m): q among solve_all's roots
HINT_NOISE = 0.05  # rad, standard deviation of the random class's hint
DECADES = tuple(range(-14, -3))  # floor(log10 |branch quantity|) of the singular cases
CROSSING_GRID = 64  # samples of a joint's range where the singular class looks for crossings
TORUS_SOLVE_ALL_STRIDE = 20  # gen3, sawyer: solve_all on every 20th pose (5 ms a call)
BATCH_CHUNK = 10_000
THREADS = 4
KEEP = 20  # reproducers kept per (class, arm, kind)
WITHIN_SOLVER = "within the solver's own tolerance"
CLASSES = ("random", "singular", "huge/tiny", "layouts", "threads", "repeated")


# ------------------------------------------------------------------------------------------
# Records


@dataclass
class Tally:
    """Counts of one attack class on one arm.

    Attributes:
        cls, arm: The class and the arm.
        poses: Poses (or questions) generated.
        calls: Library calls whose answers were checked.
        ok: Calls answered ok (solve_all: at least one root).
        wrong_ok: Ok answers that fail the check (solve_all: calls with a wrong root).
        false_no: Reachable requests answered no (ok False or an empty solve_all).
        foreign: Exceptions raised that are not ``om.OMError``.
        differs: Answers that differ from the one they must equal (repeated calls, layouts,
            threads, batch rows, a huge psi and its reduction).
        seconds: Wall time of the class on this arm.
        notes: Further counts, by name.
    """

    cls: str
    arm: str
    poses: int = 0
    calls: int = 0
    ok: int = 0
    wrong_ok: int = 0
    false_no: int = 0
    foreign: int = 0
    differs: int = 0
    seconds: float = 0.0
    slowest: tuple[float, str] = (0.0, "")
    notes: Counter = field(default_factory=Counter)

    def line(self) -> str:
        extra = "; ".join(f"{k} {v}" for k, v in sorted(self.notes.items()))
        return (
            f"[{self.arm}] {self.cls}: {self.poses} poses, {self.calls} calls, {self.ok} ok, "
            f"{self.wrong_ok} wrong ok, {self.false_no} false no, {self.foreign} non-library "
            f"exceptions, {self.differs} differ ({self.seconds:.1f} s; slowest call "
            f"{1e3 * self.slowest[0]:.0f} ms)" + (f" [{extra}]" if extra else "")
        )


@dataclass
class Failure:
    """A reproducer: the call, its inputs and what went wrong."""

    cls: str
    arm: str
    kind: str  # "wrong ok", "false no", "non-library exception", "differs", ...
    call: str
    detail: str
    q: list[float] | None = None  # the joint vector T was made from (None: not from a q)
    T: list[list[float]] | None = None
    signs: tuple[int, ...] = ()
    redundancy: tuple[float, ...] = ()
    hint: list[float] | None = None
    T_is_fk: bool = True  # T = arm.fk(q)


@dataclass
class ArmResult:
    """Everything one arm's run found."""

    arm: str
    tallies: list[Tally] = field(default_factory=list)
    decades: dict[str, Counter] = field(default_factory=dict)  # column -> counts
    other_side: Counter = field(default_factory=Counter)
    arm_angle_line: dict[str, Counter] = field(default_factory=dict)  # column -> counts
    failures: list[Failure] = field(default_factory=list)
    failure_counts: Counter = field(default_factory=Counter)
    seconds: float = 0.0


# ------------------------------------------------------------------------------------------
# The check of an answer against MuJoCo


class Checker:
    """Judges a returned joint vector with MuJoCo's FK of the project's MJCF of the arm."""

    def __init__(self, solver: om.OMSolver):
        self.solver = solver
        self.arm = solver.arm
        self.model = om.arm_model(solver.arm)
        self.data = mujoco.MjData(self.model)
        self.site = self.model.site(solver.arm.frame_name or DEFAULT_SITE).id
        self.family, self.params = int(solver.om.family), np.ascontiguousarray(solver.om.params)
        self.n_signs = len(solver.sign_names)
        self.n_redundancy = len(solver.redundancy_names)
        self._lock = threading.Lock()

    def mujoco_pose(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        with self._lock:
            self.data.qpos[:] = q
            mujoco.mj_kinematics(self.model, self.data)
            return self.data.site_xpos[self.site].copy(), self.data.site_xmat[self.site].reshape(3, 3).copy()

    def branch(self, q: np.ndarray) -> np.ndarray:
        out = np.empty(self.n_signs)
        branch_values(self.family, self.params, np.ascontiguousarray(q, dtype=np.float64), out)
        return out

    def redundancy(self, q: np.ndarray) -> np.ndarray:
        out = np.empty(self.n_redundancy)
        if self.n_redundancy:
            redundancy_values(self.family, self.params, np.ascontiguousarray(q, dtype=np.float64), out)
        return out

    def screen(
        self, Q: np.ndarray, Ts: np.ndarray, signs: np.ndarray, red: np.ndarray, within: np.ndarray
    ) -> np.ndarray:
        """Rows that may be wrong, vectorised, at half the tolerances (:meth:`wrong` decides)."""
        m = len(Q)
        P, R = np.empty((m, 3)), np.empty((m, 9))
        for i in range(m):
            self.data.qpos[:] = Q[i]
            mujoco.mj_kinematics(self.model, self.data)
            P[i], R[i] = self.data.site_xpos[self.site], self.data.site_xmat[self.site]
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(Q).all(axis=1)
            bad |= ~(np.linalg.norm(P - Ts[:, :3, 3], axis=1) <= position_tolerance(Ts[:, :3, 3]) / 2)
            chord = np.linalg.norm(R.reshape(m, 3, 3) - Ts[:, :3, :3], axis=(1, 2)) / (2.0 * math.sqrt(2.0))
            bad |= ~(2.0 * np.arcsin(np.minimum(chord, 1.0)) <= ORIENTATION_TOLERANCE / 2)
            B = np.array([self.branch(q) for q in Q]).reshape(m, self.n_signs)
            bad |= ((np.abs(B) > BRANCH_BAND / 2) & (np.where(B > 0, 1, -1) != signs)).any(axis=1)
            if self.n_redundancy:
                got = np.array([self.redundancy(q) for q in Q]).reshape(m, self.n_redundancy)
                d = np.abs(np.remainder(got - red + math.pi, TURN) - math.pi)
                bad |= ~(d <= REDUNDANCY_TOLERANCE / 2).all(axis=1)
            inside = ((self.arm.lower <= Q) & (self.arm.upper >= Q)).all(axis=1)
            bad |= inside != within
        return bad

    def wrong(self, q: np.ndarray, T: np.ndarray, c: om.Configuration, within: bool) -> str | None:
        """Why an ok answer is wrong, or None if it is right."""
        q = np.asarray(q, dtype=np.float64)
        if not np.isfinite(q).all():
            return "q is not finite"
        p, R = self.mujoco_pose(q)
        dp = float(np.linalg.norm(p - T[:3, 3]))
        solver_position, orientation_tolerance = self.solver.tolerances
        if not dp <= position_tolerance(T[:3, 3]):
            size = float(np.linalg.norm(T[:3, 3]))
            within = f"; {WITHIN_SOLVER}" if dp <= solver_position else ""
            return f"MuJoCo's FK misses the position by {dp:.3e} m (|p| = {size:.3g} m{within})"
        chord = float(np.linalg.norm(R - T[:3, :3])) / (2.0 * math.sqrt(2.0))
        angle = 2.0 * math.asin(min(1.0, chord))
        if not angle <= ORIENTATION_TOLERANCE:
            within = (
                f" ({WITHIN_SOLVER} {orientation_tolerance:g} rad)" if angle <= orientation_tolerance else ""
            )
            return f"MuJoCo's FK misses the orientation by {angle:.3e} rad{within}"
        for i, (b, s) in enumerate(zip(self.branch(q), c.signs, strict=True)):
            if abs(b) > BRANCH_BAND and (1 if b > 0 else -1) != s:
                return f"branch {self.solver.sign_names[i]} is {b:.3e}, sign {s:+d} requested"
        if not self.solver.holds(q, c):  # the branches hold: psi, read in the requested ELBOW branch
            got = self.redundancy(q)
            return f"redundancy is {list(map(float, got))} (q's own branch), {list(c.redundancy)} requested"
        inside = bool(np.all((self.arm.lower <= q) & (q <= self.arm.upper)))
        if bool(within) != inside:
            return f"within_limits is {bool(within)}, q is {'inside' if inside else 'outside'} the limits"
        return None


def position_tolerance(p: np.ndarray) -> np.ndarray | float:
    """The check's position tolerance at the target position(s) p (last axis 3), in m."""
    return np.maximum(POSITION_TOLERANCE, FK_ROUNDING * np.linalg.norm(p, axis=-1))


def angle_distance(a: float, b: float) -> float:
    """|a - b| modulo 2 pi, each angle reduced exactly first."""
    return abs(math.remainder(math.remainder(a, TURN) - math.remainder(b, TURN), TURN))


# ------------------------------------------------------------------------------------------
# One arm's run: calls, judgements and reproducers


def answer_key(sol: Any) -> tuple:
    """What must be identical between two answers to the same question (bit for bit)."""
    if isinstance(sol, list):
        return tuple(answer_key(s) for s in sol)
    return (
        sol.status,
        np.asarray(sol.q, dtype=np.float64).tobytes(),
        np.array([sol.position_error, sol.orientation_error], dtype=np.float64).tobytes(),
        bool(sol.within_limits),
    )


@dataclass(frozen=True)
class Row:
    """One row of a BatchSolution, shaped like a Solution for the checks."""

    q: np.ndarray
    ok: bool
    status: str
    position_error: float
    orientation_error: float
    within_limits: bool


def batch_rows(batch: om.BatchSolution) -> list[Row]:
    status = batch.status
    return [
        Row(
            batch.q[i],
            bool(batch.ok[i]),
            status[i],
            float(batch.position_error[i]),
            float(batch.orientation_error[i]),
            bool(batch.within_limits[i]),
        )
        for i in range(len(batch.ok))
    ]


def reduced(c: om.Configuration) -> om.Configuration:
    return om.Configuration(c.signs, tuple(math.remainder(r, TURN) for r in c.redundancy))


def flipped(c: om.Configuration, index: int, names: Sequence[str]) -> om.Configuration:
    """c with branch ``index`` flipped. The arm angle's reference (the elbow plane's normal)
    flips with the ELBOW branch: a straight elbow at psi in one is at psi + pi in the other."""
    signs = list(c.signs)
    signs[index] = -signs[index]
    turn = math.pi if names[index] == "ELBOW" else 0.0
    return om.Configuration(tuple(signs), tuple(math.remainder(r + turn, TURN) for r in c.redundancy))


def redundancy_rows(configurations: Sequence[om.Configuration]) -> np.ndarray | None:
    if not configurations or not configurations[0].redundancy:
        return None
    return np.array([c.redundancy for c in configurations], dtype=np.float64)


class ArmRun:
    """One arm's solver, checker, random stream and findings."""

    def __init__(self, name: str, seed: int):
        self.solver = om.OMSolver(name)
        self.arm = self.solver.arm
        self.checker = Checker(self.solver)
        self.rng = np.random.default_rng([seed, zlib.crc32(name.encode())])
        self.result = ArmResult(name)
        self.torus = self.solver.solver_data().mode == system.TORUS
        self.limited = np.flatnonzero(np.isfinite(self.arm.lower) & np.isfinite(self.arm.upper))
        self.pending: list | None = None  # deferred checks, see judge()

    # --- bookkeeping

    def tally(self, cls: str) -> Tally:
        t = Tally(cls, self.arm.name)
        self.result.tallies.append(t)
        return t

    def record(self, t: Tally, kind: str, call: str, detail: str, **inputs: Any) -> None:
        key = (t.cls, kind)
        self.result.failure_counts[key] += 1
        if self.result.failure_counts[key] > KEEP:
            return
        q, T, c, hint = inputs.get("q"), inputs.get("T"), inputs.get("c"), inputs.get("hint")
        if inputs.get("context"):
            detail = f"{detail} ({inputs['context']})"
        self.result.failures.append(
            Failure(
                t.cls,
                self.arm.name,
                kind,
                call,
                detail,
                q=None if q is None else [float(x) for x in np.asarray(q).ravel()],
                T=None if T is None else np.asarray(T, dtype=np.float64).tolist(),
                signs=() if c is None else tuple(c.signs),
                redundancy=() if c is None else tuple(c.redundancy),
                hint=None if hint is None else [float(x) for x in np.asarray(hint).ravel()],
                T_is_fk=inputs.get("T_is_fk", True),
            )
        )

    def count_wrong(self, t: Tally, reason: str) -> None:
        t.wrong_ok += 1
        if WITHIN_SOLVER in reason:
            t.notes[f"wrong ok {WITHIN_SOLVER}"] += 1

    def attempt(self, t: Tally, call: str, fn: Callable[[], Any], **inputs: Any) -> tuple[bool, Any]:
        """Run one library call; (True, result), or (False, None) after an exception."""
        t.calls += 1
        start = time.perf_counter()
        try:
            return True, fn()
        except om.OMError as error:
            t.notes[f"library exception {type(error).__name__}"] += 1
            self.record(t, "library exception", call, f"{type(error).__name__}: {error}", **inputs)
        except Exception as error:
            t.foreign += 1
            self.record(t, "non-library exception", call, f"{type(error).__name__}: {error}", **inputs)
        finally:
            seconds = time.perf_counter() - start
            if seconds > t.slowest[0]:
                t.slowest = (seconds, call)
        return False, None

    def judge(
        self,
        t: Tally,
        call: str,
        sol: Any,
        T: np.ndarray,
        c: om.Configuration,
        expect_ok: bool,
        **inputs: Any,
    ) -> bool | None:
        """Check a Solution (or batch Row); True if ok and right, False if wrong, None if not ok.

        While :attr:`pending` is a list, the check of an ok answer is deferred to :meth:`flush`
        (vectorised; the return value is then True)."""
        if sol.ok:
            t.ok += 1
            if self.pending is not None:
                self.pending.append(
                    (t, call, np.array(sol.q, dtype=np.float64), sol.within_limits, T, c, inputs, None)
                )
                return True
            reason = self.checker.wrong(sol.q, T, c, sol.within_limits)
            if reason is None:
                return True
            self.count_wrong(t, reason)
            self.record(
                t, "wrong ok", call, f"{reason}; returned q = {list(map(float, sol.q))}", T=T, c=c, **inputs
            )
            return False
        if expect_ok:
            t.false_no += 1
            t.notes[f"false no ({call})"] += 1
            self.record(t, "false no", call, f"status '{sol.status}'", T=T, c=c, **inputs)
        return None

    def judge_all(
        self,
        t: Tally,
        roots: list,
        T: np.ndarray,
        c: om.Configuration,
        expect_ok: bool,
        q: np.ndarray | None = None,
        hold_q: bool = False,
        **inputs: Any,
    ) -> bool | None:
        """Check the roots of a solve_all (and, with hold_q, that q is among them); None when empty."""
        if not roots:
            if expect_ok:
                t.false_no += 1
                t.notes["false no (solve_all)"] += 1
                self.record(t, "false no", "solve_all", "no root", T=T, c=c, q=q, **inputs)
            return None
        t.ok += 1
        if self.pending is not None:
            group = object()  # one wrong ok per call, however many roots are wrong
            for s in roots:
                self.pending.append(
                    (t, "solve_all", np.array(s.q), s.within_limits, T, c, {"q": q, **inputs}, group)
                )
            reasons = []
        else:
            reasons = [r for r in (self.checker.wrong(s.q, T, c, s.within_limits) for s in roots) if r]
        if reasons:
            self.count_wrong(t, "; ".join(reasons))
            self.record(t, "wrong ok", "solve_all", "; ".join(reasons), T=T, c=c, q=q, **inputs)
        if hold_q and q is not None and not any(self.same_joints(s.q, q) for s in roots):
            t.notes["solve_all without q"] += 1
            self.record(
                t,
                "solve_all without q",
                "solve_all",
                f"{len(roots)} roots, none is q",
                T=T,
                c=c,
                q=q,
                **inputs,
            )
        return not reasons

    def flush(self) -> None:
        """Check the deferred ok answers (see :meth:`judge`) and stop deferring."""
        items, self.pending = self.pending or [], None
        if not items:
            return
        Q = np.array([item[2] for item in items])
        Ts = np.array([item[4] for item in items])
        signs = np.array([item[5].signs for item in items])
        red = np.array([item[5].redundancy for item in items]).reshape(len(items), -1)
        within = np.array([bool(item[3]) for item in items])
        counted = set()
        for i in np.flatnonzero(self.checker.screen(Q, Ts, signs, red, within)):
            t, call, q, w, T, c, inputs, group = items[i]
            reason = self.checker.wrong(q, T, c, w)
            if reason is None or (group is not None and id(group) in counted):
                continue
            if group is not None:
                counted.add(id(group))
            self.count_wrong(t, reason)
            self.record(
                t, "wrong ok", call, f"{reason}; returned q = {list(map(float, q))}", T=T, c=c, **inputs
            )

    def same_joints(self, a: np.ndarray, b: np.ndarray) -> bool:
        d = np.asarray(a, dtype=np.float64) - b
        d = np.where(self.arm.revolute, np.remainder(d + math.pi, TURN) - math.pi, d)
        return bool(np.abs(d).max() <= ROOT_MATCH)

    def differ(self, t: Tally, call: str, detail: str, **inputs: Any) -> None:
        t.differs += 1
        self.record(t, "differs", call, detail, **inputs)

    def solve_all_here(self, i: int) -> bool:
        return not self.torus or i % TORUS_SOLVE_ALL_STRIDE == 0

    # --- inputs

    def random_q(self, n: int) -> np.ndarray:
        return random_joints(self.arm, n, self.rng)

    def boundary_q(self, index: int, value: float) -> np.ndarray | None:
        """A random q moved along one joint so that branch quantity ``index`` is ``value``.

        The joints are tried in order of the quantity's slope at q. On each, b_index - value is
        sampled at :data:`CROSSING_GRID` points over the joint's range (its limits; one turn
        around q_j for an unlimited joint), one of the sign changes is drawn at random and
        bisected down to adjacent doubles, and the end whose branch quantity has value's sign
        and is nearest it is kept. So every crossing within the limits can be drawn (also
        those next to a limit), and the branch quantity is value to its last bits (at 1e-14 a
        joint near pi resolves it to 4 %: the decade table reads the value made). None if no
        joint crosses value within its limits (a new random q is drawn then).
        """
        q = self.random_q(1)[0]
        slopes = np.empty(self.arm.dof)
        for j in range(self.arm.dof):
            e = np.zeros(self.arm.dof)
            e[j] = 1e-6
            slopes[j] = abs(self.checker.branch(q + e)[index] - self.checker.branch(q - e)[index])
        for j in np.argsort(-slopes, kind="stable"):
            if not slopes[j] > 0.0:
                break
            found = self._crossing(q, int(j), index, value)
            if found is not None:
                return found
        return None

    def _crossing(self, q: np.ndarray, j: int, index: int, value: float) -> np.ndarray | None:
        """q with joint j at a random crossing of b_index = value within j's range, or None."""
        lo = self.arm.lower[j] if math.isfinite(self.arm.lower[j]) else q[j] - math.pi
        hi = self.arm.upper[j] if math.isfinite(self.arm.upper[j]) else q[j] + math.pi
        x = q.copy()

        def f(t: float) -> float:
            x[j] = t
            return float(self.checker.branch(x)[index]) - value

        grid = np.linspace(lo, hi, CROSSING_GRID)
        fs = np.array([f(t) for t in grid])
        cells = np.flatnonzero(np.sign(fs[:-1]) * np.sign(fs[1:]) <= 0.0)
        if not len(cells):
            return None
        k = int(self.rng.choice(cells))
        a, b, fa = float(grid[k]), float(grid[k + 1]), float(fs[k])
        ends = [(abs(fa), a), (abs(float(fs[k + 1])), b)]
        while True:
            m = 0.5 * (a + b)
            if not a < m < b:
                break
            fm = f(m)
            ends.append((abs(fm), m))
            if fm == 0.0:
                break
            if (fm < 0.0) == (fa < 0.0):
                a, fa = m, fm
            else:
                b = m
        for _, t in sorted(ends):
            x[j] = t
            if float(self.checker.branch(x)[index]) * value > 0.0:
                return x
        return None

    def near_arm_angle_line(self, delta: float, side: float) -> np.ndarray | None:
        """A random q (7-DOF) whose model's shoulder-wrist direction w_hat is at the angle delta
        from the arm angle's singular half-line w_hat = -up (``side`` -1: the wrist centre
        straight below the shoulder, where the reference n(w_hat) = R(up -> w_hat) r is
        undefined) or from w_hat = +up (``side`` +1). Gauss-Newton on joints 2-7, within the
        limits, for the part of w across up equal to delta |w| in a random direction; None if
        it does not get within half of that.
        """
        up, across, w = self._arm_angle_frame()
        q = self.random_q(1)[0]
        angle = self.rng.uniform(0.0, TURN)
        direction = np.array([math.cos(angle), math.sin(angle)])
        steps = 1e-7 * np.eye(self.arm.dof)[1:]
        for _ in range(40):
            v = w(q)
            length = float(np.linalg.norm(v))
            miss = across @ v - delta * length * direction
            if np.abs(miss).max() <= 0.5 * delta * length:
                return q if side * float(v @ up) > 0.0 else None
            J = (across @ (w(q + steps) - w(q - steps)).T) / 2e-7
            q[1:] = np.clip(
                q[1:] + np.linalg.lstsq(J, -miss, rcond=None)[0], self.arm.lower[1:], self.arm.upper[1:]
            )
        return None

    def _arm_angle_frame(self) -> tuple[np.ndarray, np.ndarray, Callable[[np.ndarray], np.ndarray]]:
        """The model's up axis, two unit vectors across it, and w(Q): W - S of the model at Q,
        all in DH frame 0 (where the kernels' up, shoulder and flange-frame wrist offset are;
        the model's FK is in the root frame, turned on the Gen3: z down)."""
        model, P, data = self.solver.om.model, self.solver.om.params, self.solver.solver_data()
        up = P[_core.SRS_UP : _core.SRS_UP + 3]
        e1 = np.cross(up, [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        wrist = P[_core.SRS_WRIST : _core.SRS_WRIST + 3]
        shoulder = P[_core.SRS_SHOULDER : _core.SRS_SHOULDER + 3]

        def w(Q: np.ndarray) -> np.ndarray:
            T = data.T_base_root @ model.fk(Q) @ data.T_tool_flange  # the flange in DH frame 0
            return T[..., :3, 3] + T[..., :3, :3] @ wrist - shoulder

        return up, np.array([e1, np.cross(up, e1)]), w

    def arm_angle_line_angle(self, q: np.ndarray, side: float) -> float:
        """The angle of the model's w_hat at q from side * up."""
        up, across, w = self._arm_angle_frame()
        v = w(q)
        return math.atan2(float(np.linalg.norm(across @ v)), side * float(v @ up))

    def at_limits(self) -> np.ndarray | None:
        """A random q with some limited joints at a limit +- 1e-12."""
        if not len(self.limited):
            return None
        q = self.random_q(1)[0]
        joints = self.rng.choice(
            self.limited, size=int(self.rng.integers(1, len(self.limited) + 1)), replace=False
        )
        for j in joints:
            limit = self.arm.lower[j] if self.rng.random() < 0.5 else self.arm.upper[j]
            q[j] = limit + (1e-12 if self.rng.random() < 0.5 else -1e-12)
        return q


# ------------------------------------------------------------------------------------------
# The attack classes


def run_random(run: ArmRun, n: int) -> Tally:
    """solve, hinted solve, solve_batch and solve_all of T = FK(q) in c = configuration_of(q)."""
    t = run.tally("random")
    solver, start = run.solver, time.perf_counter()
    run.pending = []
    Q = run.random_q(n)
    Ts = run.arm.fk(Q) if n else np.empty((0, 4, 4))
    hints = Q + run.rng.normal(0.0, HINT_NOISE, Q.shape)
    configurations: list[om.Configuration] = []
    for i in range(n):
        q, T = Q[i], Ts[i]
        c = solver.configuration_of(q)
        configurations.append(c)
        t.poses += 1
        done, sol = run.attempt(t, "solve", lambda T=T, c=c: solver.solve(T, c), q=q, T=T, c=c)
        if done:
            run.judge(t, "solve", sol, T, c, True, q=q)
        h = hints[i]
        done, sol = run.attempt(
            t, "hinted solve", lambda T=T, c=c, h=h: solver.solve(T, c, q_hint=h), q=q, T=T, c=c
        )
        if done:
            run.judge(t, "hinted solve", sol, T, c, True, q=q, hint=h)
        if run.solve_all_here(i):
            done, roots = run.attempt(t, "solve_all", lambda T=T, c=c: solver.solve_all(T, c), q=q, T=T, c=c)
            if done:
                run.judge_all(t, roots, T, c, True, q=q, hold_q=True)
    for lo in range(0, n, BATCH_CHUNK):
        hi = min(n, lo + BATCH_CHUNK)
        cs = configurations[lo:hi]
        signs = np.array([c.signs for c in cs])
        red = redundancy_rows(cs)
        t.calls += hi - lo - 1  # attempt counts one
        done, batch = run.attempt(
            t, "solve_batch", lambda s=signs, r=red, lo=lo, hi=hi: solver.solve_batch(Ts[lo:hi], s, r)
        )
        if done:
            for k, row in enumerate(batch_rows(batch)):
                run.judge(t, "solve_batch", row, Ts[lo + k], cs[k], True, q=Q[lo + k])
    run.flush()
    t.seconds = time.perf_counter() - start
    return t


def run_singular(run: ArmRun, n: int, n_limits: int, n_line: int = 0) -> Tally:
    """Poses at 1e-14 ... 1e-3 from a branch boundary, joints at their limits +- 1e-12, and
    (7-DOF) the wrist centre 1e-14 ... 1e-3 rad from the arm angle's singular half-line."""
    t = run.tally("singular")
    solver, start = run.solver, time.perf_counter()
    decades = run.result.decades
    other = run.result.other_side
    k = len(solver.sign_names)
    made = tries = 0
    while made < n and tries < 4 * n:
        tries += 1
        index = made % k
        value = float(run.rng.choice([-1.0, 1.0]) * 10.0 ** run.rng.uniform(-14.0, -3.0))
        q = run.boundary_q(index, value)
        if q is None:
            t.notes["no crossing within the limits (a new random q)"] += 1
            continue
        made += 1
        b = run.checker.branch(q)[index]
        column = str(math.floor(math.log10(abs(b)))) if b != 0.0 else "0"
        context = f"branch {solver.sign_names[index]} = {b:.3e}"
        bad = singular_case(run, t, q, decades.setdefault(column, Counter()), context)
        decades[column]["cases"] += 1
        decades[column]["any"] += bad
        if abs(b) <= BRANCH_BAND:
            other_side(run, t, q, index, other, context)
    if made < n:
        t.notes["branch poses short of the size asked"] += n - made
    for _ in range(n_limits):
        q = run.at_limits()
        if q is None:
            break
        counts = decades.setdefault("limits", Counter())
        counts["cases"] += 1
        at = np.flatnonzero(np.minimum(np.abs(q - run.arm.lower), np.abs(q - run.arm.upper)) < 1e-9)
        counts["any"] += singular_case(
            run, t, q, counts, f"joints {[int(j) + 1 for j in at]} at a limit +- 1e-12"
        )
    made = tries = 0
    while solver.redundancy_names and made < n_line and tries < 20 * n_line:
        tries += 1
        side = -1.0 if made % 4 else 1.0  # three of four below the shoulder
        q = run.near_arm_angle_line(float(10.0 ** run.rng.uniform(-14.0, -3.0)), side)
        if q is None:
            continue
        made += 1
        delta = run.arm_angle_line_angle(q, side)
        column = f"{'below' if side < 0 else 'above'} {math.floor(math.log10(delta)) if delta > 0 else '0'}"
        counts = run.result.arm_angle_line.setdefault(column, Counter())
        counts["cases"] += 1
        counts["any"] += singular_case(
            run, t, q, counts, f"wrist centre {delta:.3e} rad from straight {column.split()[0]} the shoulder"
        )
    if solver.redundancy_names and made < n_line:
        t.notes["arm angle line poses short of the size asked"] += n_line - made
    t.seconds = time.perf_counter() - start
    return t


def singular_case(run: ArmRun, t: Tally, q: np.ndarray, counts: Counter, context: str) -> bool:
    """solve, hinted solve and solve_all of T = FK(q) in configuration_of(q); whether any failed."""
    solver = run.solver
    T = run.arm.fk(q)
    c = solver.configuration_of(q)
    t.poses += 1
    before = (t.false_no, t.wrong_ok, t.foreign)
    calls = [("solve", lambda: solver.solve(T, c)), ("hinted solve", lambda: solver.solve(T, c, q_hint=q))]
    for call, fn in calls:
        done, sol = run.attempt(t, call, fn, q=q, T=T, c=c, context=context)
        if done:
            hint = q if call == "hinted solve" else None
            verdict = run.judge(t, call, sol, T, c, True, q=q, hint=hint, context=context)
            counts[f"false no ({call})"] += verdict is None
            counts["wrong ok"] += verdict is False
    if run.solve_all_here(t.poses):
        done, roots = run.attempt(
            t, "solve_all", lambda: solver.solve_all(T, c), q=q, T=T, c=c, context=context
        )
        if done:
            verdict = run.judge_all(t, roots, T, c, True, q=q, context=context)
            counts["false no (solve_all)"] += verdict is None
            counts["wrong ok"] += verdict is False
    return (t.false_no, t.wrong_ok, t.foreign) != before


def other_side(run: ArmRun, t: Tally, q: np.ndarray, index: int, counts: Counter, context: str) -> None:
    """The flipped sign of the branch at |offset| <= BRANCH_BAND: by the band contract the pose
    belongs to both configurations, so "no" there is a false no."""
    solver = run.solver
    T = run.arm.fk(q)
    c = flipped(solver.configuration_of(q), index, solver.sign_names)
    counts["cases"] += 1
    for call, fn in (
        ("solve", lambda: solver.solve(T, c)),
        ("hinted solve", lambda: solver.solve(T, c, q_hint=q)),
    ):
        done, sol = run.attempt(t, f"other side {call}", fn, q=q, T=T, c=c, context=context)
        if done:
            verdict = run.judge(t, f"other side {call}", sol, T, c, True, q=q, context=context)
            counts[f"ok ({call})"] += verdict is not None
            counts[f"false no ({call})"] += verdict is None
            counts["wrong ok"] += verdict is False


def run_huge_tiny(run: ArmRun, n: int) -> Tally:
    """Huge hints, huge arm angles, poses translated far away, tiny translations."""
    t = run.tally("huge/tiny")
    solver, arm, rng, start = run.solver, run.arm, run.rng, time.perf_counter()
    Q = run.random_q(n)
    Ts = arm.fk(Q) if n else np.empty((0, 4, 4))
    for i in range(n):
        q, T = Q[i], Ts[i]
        c = solver.configuration_of(q)
        red = np.array([c.redundancy]) if c.redundancy else None
        t.poses += 1
        # A hint of magnitude 1e3 ... 1e300: every ok exact, and still ok.
        if i % 2:
            hint = np.full(arm.dof, rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(3.0, 300.0))
        else:
            hint = rng.choice([-1.0, 1.0], arm.dof) * 10.0 ** rng.uniform(3.0, 300.0, arm.dof)
        done, sol = run.attempt(
            t, "huge hint", lambda T=T, c=c, h=hint: solver.solve(T, c, q_hint=h), q=q, T=T, c=c, hint=hint
        )
        if done:
            run.judge(t, "huge hint", sol, T, c, True, q=q, hint=hint)
        done, batch = run.attempt(
            t,
            "huge hint batch",
            lambda T=T, c=c, r=red, h=hint: solver.solve_batch(T[None], c.signs, r, q_hint=h[None]),
            q=q,
            T=T,
            c=c,
            hint=hint,
        )
        if done:
            run.judge(t, "huge hint batch", batch_rows(batch)[0], T, c, True, q=q, hint=hint)
        # psi + 2 pi k, k huge: the same answer as for its exact reduction.
        if c.redundancy:
            huge_psi(run, t, q, T, c)
        # Translated by 1e3 ... 1e300 m: ok False, "unreachable".
        far = T.copy()
        far[:3, 3] += unit(rng) * 10.0 ** rng.uniform(3.0, 300.0)
        for call, fn in (
            ("far solve", lambda far=far, c=c: solver.solve(far, c)),
            ("far hinted solve", lambda far=far, c=c, q=q: solver.solve(far, c, q_hint=q)),
            (
                "far solve_batch",
                lambda far=far, c=c, r=red: batch_rows(solver.solve_batch(far[None], c.signs, r))[0],
            ),
        ):
            done, sol = run.attempt(t, call, fn, T=far, c=c, T_is_fk=False)
            if done:
                run.judge(t, call, sol, far, c, False, T_is_fk=False)
                if sol.status != "unreachable":
                    t.notes["far: status not 'unreachable'"] += 1
                    run.record(
                        t, "far: not unreachable", call, f"status '{sol.status}'", T=far, c=c, T_is_fk=False
                    )
        done, roots = run.attempt(
            t, "far solve_all", lambda far=far, c=c: solver.solve_all(far, c), T=far, c=c, T_is_fk=False
        )
        if done:
            run.judge_all(t, roots, far, c, False, T_is_fk=False)
        # Translation changed by 1e-300 (the same reachable pose) and a translation of size 1e-300.
        near = T.copy()
        near[:3, 3] += unit(rng) * 1e-300
        done, sol = run.attempt(t, "tiny shift", lambda n_=near, c=c: solver.solve(n_, c), q=q, T=near, c=c)
        if done:
            run.judge(t, "tiny shift", sol, near, c, True, q=q)
        tiny = T.copy()
        tiny[:3, 3] = unit(rng) * 1e-300
        for call, fn in (
            ("tiny position solve", lambda x=tiny, c=c: solver.solve(x, c)),
            (
                "tiny position batch",
                lambda x=tiny, c=c, r=red: batch_rows(solver.solve_batch(x[None], c.signs, r))[0],
            ),
        ):
            done, sol = run.attempt(t, call, fn, T=tiny, c=c, T_is_fk=False)
            if done:
                run.judge(t, call, sol, tiny, c, False, T_is_fk=False)
    t.seconds = time.perf_counter() - start
    return t


def huge_psi(run: ArmRun, t: Tally, q: np.ndarray, T: np.ndarray, c: om.Configuration) -> None:
    solver, rng = run.solver, run.rng
    # Half the draws keep psi + 2 pi k within 1e-9 of psi (k <= 1e5 or so), half do not.
    exponent = rng.uniform(3.0, 16.0) if rng.random() < 0.5 else rng.uniform(16.0, 300.0)
    k = math.floor(10.0**exponent)
    psi = c.redundancy[0] + TURN * k
    huge = om.Configuration(c.signs, (psi,))
    small = reduced(huge)
    exact = angle_distance(small.redundancy[0], c.redundancy[0]) <= REDUNDANCY_TOLERANCE
    t.notes["huge psi within 1e-9 of psi"] += exact
    done_h, a = run.attempt(t, "huge psi", lambda: solver.solve(T, huge), q=q, T=T, c=huge)
    done_r, b = run.attempt(t, "reduced psi", lambda: solver.solve(T, small), q=q, T=T, c=small)
    if done_h:
        run.judge(t, "huge psi", a, T, huge, exact, q=q)
    if done_h and done_r and answer_key(a) != answer_key(b):
        run.differ(t, "huge psi", f"'{a.status}' vs reduced '{b.status}'", q=q, T=T, c=huge)
    rows = []
    for cfg in (huge, small):
        done, batch = run.attempt(
            t,
            "huge psi batch",
            lambda cfg=cfg: solver.solve_batch(T[None], cfg.signs, [cfg.redundancy]),
            q=q,
            T=T,
            c=cfg,
        )
        rows.append(batch_rows(batch)[0] if done else None)
    if rows[0] is not None:
        run.judge(t, "huge psi batch", rows[0], T, huge, exact, q=q)
    if rows[0] is not None and rows[1] is not None and answer_key(rows[0]) != answer_key(rows[1]):
        run.differ(t, "huge psi batch", f"'{rows[0].status}' vs reduced '{rows[1].status}'", q=q, T=T, c=huge)


def unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def layouts_of(a: np.ndarray) -> dict[str, Any]:
    """The same array as Fortran-order, read-only, strided, big-endian and list inputs."""
    read_only = a.copy()
    read_only.flags.writeable = False
    strided = np.repeat(a, 2, axis=-1)[..., ::2]
    out = {
        "read-only": read_only,
        "strided": strided,
        "big-endian": a.astype(">f8") if a.dtype.kind == "f" else a.astype(">i8"),
        "list": a.tolist(),
    }
    if a.ndim >= 2:
        out["fortran"] = np.asfortranarray(a)
        out["reversed rows"] = np.ascontiguousarray(a[::-1])[::-1]
    else:
        out["tuple"] = tuple(a.tolist())
    return out


def run_layouts(run: ArmRun, n: int) -> Tally:
    """Every layout of pose, hint, batch signs and redundancy: the C-order call's answer."""
    t = run.tally("layouts")
    solver, start = run.solver, time.perf_counter()
    Q = run.random_q(n)
    if not n:
        return t
    Ts = np.ascontiguousarray(run.arm.fk(Q))
    hints = Q + run.rng.normal(0.0, HINT_NOISE, Q.shape)
    configurations = [solver.configuration_of(q) for q in Q]
    for i in range(n):
        q, T, h, c = Q[i], Ts[i], hints[i], configurations[i]
        t.poses += 1
        calls = {
            "solve": (lambda T_, h_, c=c: solver.solve(T_, c), T, None),
            "hinted solve": (lambda T_, h_, c=c: solver.solve(T_, c, q_hint=h_), T, h),
        }
        if run.solve_all_here(i):
            calls["solve_all"] = (lambda T_, h_, c=c: solver.solve_all(T_, c), T, None)
        for call, (fn, T0, h0) in calls.items():
            done, base = run.attempt(t, call, lambda fn=fn, T0=T0, h0=h0: fn(T0, h0), q=q, T=T, c=c)
            if not done:
                continue
            if call == "solve_all":
                run.judge_all(t, base, T, c, True, q=q, hold_q=True)
            else:
                run.judge(t, call, base, T, c, True, q=q, hint=h0)
            variants = [(f"T {k}", v, h0) for k, v in layouts_of(T).items()]
            if h0 is not None:
                variants += [(f"q_hint {k}", T, v) for k, v in layouts_of(h0).items()]
            for name, Tv, hv in variants:
                done, other = run.attempt(
                    t, f"{call}, {name}", lambda fn=fn, Tv=Tv, hv=hv: fn(Tv, hv), q=q, T=T, c=c
                )
                if done and answer_key(other) != answer_key(base):
                    run.differ(t, f"{call}, {name}", "differs from the C-order call", q=q, T=T, c=c, hint=h0)
    # Batches: the whole sample at once, every argument in every layout.
    signs = np.array([c.signs for c in configurations], dtype=np.int64)
    red = redundancy_rows(configurations)
    base_args = {"T": Ts, "signs": signs, "redundancy": red, "q_hint": hints}
    done, base = run.attempt(t, "solve_batch", lambda: solver.solve_batch(Ts, signs, red, q_hint=hints))
    if done:
        rows = batch_rows(base)
        for k, row in enumerate(rows):
            run.judge(t, "solve_batch", row, Ts[k], configurations[k], True, q=Q[k], hint=hints[k])
        variants = []
        for arg, value in base_args.items():
            if value is None:
                continue
            variants += [(f"{arg} {k}", arg, v) for k, v in layouts_of(value).items()]
            if arg == "redundancy":
                variants.append(("redundancy (M,)", arg, value[:, 0].copy()))
            if arg == "signs" and len({c.signs for c in configurations}) == 1:
                variants.append(("signs (k,)", arg, signs[0].copy()))
        for name, arg, value in variants:
            args = {**base_args, arg: value}
            done, other = run.attempt(
                t,
                f"solve_batch, {name}",
                lambda a=args: solver.solve_batch(a["T"], a["signs"], a["redundancy"], q_hint=a["q_hint"]),
            )
            t.calls += n - 1
            if done:
                for k, (x, y) in enumerate(zip(batch_rows(other), rows, strict=True)):
                    if answer_key(x) != answer_key(y):
                        run.differ(
                            t,
                            f"solve_batch, {name}",
                            f"row {k} differs",
                            q=Q[k],
                            T=Ts[k],
                            c=configurations[k],
                        )
    t.seconds = time.perf_counter() - start
    return t


def questions(
    run: ArmRun, n: int, singular: bool
) -> list[tuple[str, np.ndarray, om.Configuration, Any, Any]]:
    """(call, T, c, hint, q) mixes: random, other branches, hinted, near-singular, solve_all."""
    solver, rng = run.solver, run.rng
    out = []
    k = len(solver.sign_names)
    while len(out) < n:
        q = None
        if singular and rng.random() < 0.3:
            q = run.boundary_q(
                int(rng.integers(k)), float(rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-14, -3))
            )
        if q is None:
            q = run.random_q(1)[0]
        T = run.arm.fk(q)
        c = solver.configuration_of(q)
        r = rng.random()
        if r < 0.2:
            c = flipped(c, int(rng.integers(k)), solver.sign_names)
        hint = q + rng.normal(0.0, HINT_NOISE, q.shape) if rng.random() < 0.4 else None
        call = "solve"
        if rng.random() < 0.15 and (not run.torus or rng.random() < 0.1):
            call, hint = "solve_all", None
        out.append((call, T, c, hint, q))
    return out


def ask(solver: om.OMSolver, call: str, T: np.ndarray, c: om.Configuration, hint: Any) -> Any:
    if call == "solve_all":
        return solver.solve_all(T, c)
    return solver.solve(T, c, q_hint=hint)


def answer_all(run: ArmRun, t: Tally, qs: list) -> list[Any]:
    """Ask every question once, judging each answer; returns their keys (None where a call
    raised), the reference that later answers must equal."""
    keys: list[Any] = []
    for call, T, c, hint, q in qs:
        done, answer = run.attempt(
            t, call, lambda call=call, T=T, c=c, h=hint: ask(run.solver, call, T, c, h), q=q, T=T, c=c
        )
        keys.append(answer_key(answer) if done else None)
        if done and call == "solve_all":
            run.judge_all(t, answer, T, c, False, q=q)
        elif done:
            run.judge(t, call, answer, T, c, False, q=q, hint=hint)
    return keys


def run_threads(run: ArmRun, n: int) -> Tally:
    """4 threads sharing the solver agree bit for bit with serial calls; batches equal rows."""
    t = run.tally("threads")
    solver, start = run.solver, time.perf_counter()
    qs = questions(run, n, singular=False)
    t.poses = len(qs)
    serial = answer_all(run, t, qs)
    orders = [run.rng.permutation(len(qs)) for _ in range(THREADS)]

    def worker(order: np.ndarray) -> list[tuple[int, Any]]:
        found = []
        for i in order:
            call, T, c, hint, _ = qs[i]
            try:
                found.append((int(i), answer_key(ask(solver, call, T, c, hint))))
            except Exception as error:  # compared with the serial answer below
                found.append((int(i), f"{type(error).__name__}: {error}"))
        return found

    with ThreadPoolExecutor(THREADS) as pool:
        for found in pool.map(worker, orders):
            for i, key in found:
                t.calls += 1
                if key != serial[i]:
                    call, T, c, hint, q = qs[i]
                    run.differ(
                        t, f"{call} in a thread", "differs from the serial call", q=q, T=T, c=c, hint=hint
                    )
    # solve_batch equals per-row solve, with and without hints; also 4 batches at once.
    rows = [i for i, x in enumerate(qs) if x[0] == "solve"]
    for hinted in (False, True):
        idx = [i for i in rows if (qs[i][3] is not None) == hinted]
        if not idx:
            continue
        Ts = np.stack([qs[i][1] for i in idx])
        cs = [qs[i][2] for i in idx]
        signs, red = np.array([c.signs for c in cs]), redundancy_rows(cs)
        hints = np.stack([qs[i][3] for i in idx]) if hinted else None
        batches = []
        done, batch = run.attempt(
            t, "solve_batch", lambda Ts=Ts, s=signs, r=red, h=hints: solver.solve_batch(Ts, s, r, q_hint=h)
        )
        if not done:
            continue
        batches.append(("solve_batch", batch))
        with ThreadPoolExecutor(THREADS) as pool:
            futures = [pool.submit(solver.solve_batch, Ts, signs, red, hints) for _ in range(THREADS)]
            batches += [("solve_batch in a thread", f.result()) for f in futures]
        for name, b in batches:
            t.calls += len(idx) - (name == "solve_batch")
            for k, row in enumerate(batch_rows(b)):
                if answer_key(row) != serial[idx[k]]:
                    call, T, c, hint, q = qs[idx[k]]
                    run.differ(t, name, "row differs from the per-row solve", q=q, T=T, c=c, hint=hint)
    t.seconds = time.perf_counter() - start
    return t


def run_repeated(run: ArmRun, n: int) -> Tally:
    """The same question, asked again in random order after another call: the same answer."""
    t = run.tally("repeated")
    solver, rng, start = run.solver, run.rng, time.perf_counter()
    qs = questions(run, n, singular=True)
    t.poses = len(qs)

    def batch_ask(T: np.ndarray, c: om.Configuration, hint: Any) -> Row:
        red = [c.redundancy] if c.redundancy else None
        return batch_rows(
            solver.solve_batch(T[None], c.signs, red, q_hint=None if hint is None else hint[None])
        )[0]

    first = answer_all(run, t, qs)
    for i in rng.permutation(len(qs)):
        j = int(rng.integers(len(qs)))  # another question first, by another call
        call, T, c, hint, q = qs[j]
        before = rng.choice(["solve", "hinted", "solve_all", "batch"])
        if before == "solve_all" and run.torus and rng.random() > 0.1:
            before = "batch"
        try:
            if before == "solve":
                solver.solve(T, c)
            elif before == "hinted":
                solver.solve(T, c, q_hint=q)
            elif before == "solve_all":
                solver.solve_all(T, c)
            else:
                batch_ask(T, c, hint)
        except Exception:
            pass  # only the answer to question i is compared
        call, T, c, hint, q = qs[i]
        done, again = run.attempt(
            t, call, lambda call=call, T=T, c=c, h=hint: ask(solver, call, T, c, h), q=q, T=T, c=c
        )
        if done and answer_key(again) != first[i]:
            run.differ(t, call, f"asked again after a {before} call: differs", q=q, T=T, c=c, hint=hint)
        if call == "solve":  # the same question as a batch row
            done, row = run.attempt(
                t, "solve_batch row", lambda T=T, c=c, h=hint: batch_ask(T, c, h), q=q, T=T, c=c
            )
            if done and answer_key(row) != first[i]:
                run.differ(t, "solve_batch row", "differs from solve", q=q, T=T, c=c, hint=hint)
    t.seconds = time.perf_counter() - start
    return t


# ------------------------------------------------------------------------------------------
# Running and reporting


@dataclass(frozen=True)
class Sizes:
    random: int
    singular: int
    limits: int
    line: int
    huge: int
    layouts: int
    threads: int
    repeated: int

    @staticmethod
    def of(n_random: int, n_singular: int, n_line: int | None = None) -> Sizes:
        return Sizes(
            random=n_random,
            singular=n_singular,
            limits=max(n_singular // 4, 1),
            line=max(n_singular // 10, 1) if n_line is None else n_line,
            huge=max(n_random // 50, 10),
            layouts=max(n_random // 1000, 5),
            threads=max(n_random // 50, 20),
            repeated=max(n_random // 50, 20),
        )


def run_arm(name: str, sizes: Sizes, seed: int, classes: Sequence[str] = CLASSES) -> ArmResult:
    """Every attack class on one arm, printing a summary line per class."""
    start = time.perf_counter()
    run = ArmRun(name, seed)
    steps = {
        "random": lambda: run_random(run, sizes.random),
        "singular": lambda: run_singular(run, sizes.singular, sizes.limits, sizes.line),
        "huge/tiny": lambda: run_huge_tiny(run, sizes.huge),
        "layouts": lambda: run_layouts(run, sizes.layouts),
        "threads": lambda: run_threads(run, sizes.threads),
        "repeated": lambda: run_repeated(run, sizes.repeated),
    }
    for cls in classes:
        print(steps[cls]().line(), flush=True)
    run.result.seconds = time.perf_counter() - start
    return run.result


def _cells(values: Sequence[Any]) -> str:
    return "| " + " | ".join(str(v) for v in values) + " |"


def _fmt(x: float) -> str:
    return repr(float(x))


def reproducer(f: Failure) -> str:
    c = f"Configuration({f.signs}{', ' + repr(f.redundancy) if f.redundancy else ''})"
    parts = [f"`{f.arm}` {f.cls}, {f.call}: {f.detail}.", f"c = `{c}`"]
    if f.q is not None:
        parts.append(f"q = `[{', '.join(map(_fmt, f.q))}]`")
    if f.T is not None:
        parts.append("T = `arm.fk(q)`" if f.T_is_fk and f.q is not None else f"T = `{f.T}`")
    if f.hint is not None:
        parts.append(f"q_hint = `[{', '.join(map(_fmt, f.hint))}]`")
    return "* " + "; ".join(parts)


def unlimited_prismatic_note(arms: Sequence[str]) -> list[str]:
    """A note on arms with an unlimited prismatic joint: any distance is within their reach."""
    found = []
    for name in arms:
        arm = om.load_arm(name)
        if (~arm.revolute & ~(np.isfinite(arm.lower) & np.isfinite(arm.upper))).any():
            found.append(name)
    if not found:
        return []
    return [
        "",
        f"Arms with an unlimited prismatic joint ({', '.join(found)}) reach any distance: their "
        "translated poses are not unreachable, and at |p| = 1e120 m no float64 FK agrees with "
        "another to 1e-10 m (MuJoCo's rounding alone is about 1e-16 |p|): the position check there "
        f"is relative, {FK_ROUNDING:.1e} |p|.",
    ]


def arm_angle_line_table(results: list[ArmResult]) -> list[str]:
    """The 7-DOF arms' poses next to the arm angle's singular half-line, per decade of delta."""
    rows = [r for r in results if r.arm_angle_line]
    if not rows:
        return []
    found = {k for r in rows for k in r.arm_angle_line}
    columns = sorted(found, key=lambda k: (k.split()[0], int(k.split()[1])))
    return [
        "",
        "## The arm angle's singular half-line",
        "",
        "7-DOF arms: the model's wrist centre at the angle delta from straight below the shoulder "
        "(w_hat = -up, where psi's reference n(w_hat) = R(up -> w_hat) r is undefined) or straight above; "
        "solve, hinted solve and solve_all in c = configuration_of(q) (counted in the singular class "
        "above). Cell: poses with any false no, wrong ok or non-library exception / poses, by "
        "floor(log10 delta).",
        "",
        _cells(["arm", *[f"{k.split()[0]} 1e{k.split()[1]}" for k in columns]]),
        "|" + "---|" * (len(columns) + 1),
        *(
            _cells(
                [
                    r.arm,
                    *[f"{d['any']}/{d['cases']}" if (d := r.arm_angle_line.get(k)) else "-" for k in columns],
                ]
            )
            for r in rows
        ),
    ]


def markdown(
    results: list[ArmResult],
    bad: list[BadInput],
    sizes: Sizes,
    args: argparse.Namespace,
    seconds: float,
    load,
    run_line: str | None = None,
) -> str:
    tallies = [t for r in results for t in r.tallies]
    out = [
        "# Adversarial reliability (issue 18)",
        "",
        f"Machine: {cpu_model()}, {os.cpu_count()} cores, {platform.system()} {platform.machine()}, "
        f"Python {platform.python_version()}; load average {load[0]:.2f} at the start, {load[1]:.2f} "
        "at the end (the machine was shared).  ",
        run_line
        or (
            f"Run: `{' '.join(['python -m benchmarks.adversarial', *sys.argv[1:]])}`, seed {args.seed}, "
            f"{args.jobs} process(es); **{seconds:.0f} s** wall time in all.  "
        ),
        f"Sizes per arm: random {sizes.random} poses, singular {sizes.singular} branch poses and "
        f"{sizes.limits} poses at limits, {sizes.line} next to psi's half-line (7-DOF), "
        f"huge/tiny {sizes.huge}, layouts {sizes.layouts}, "
        f"threads {sizes.threads} questions x {THREADS} threads, repeated {sizes.repeated} questions.",
        "",
        "Every answer marked ok is checked against MuJoCo's FK of the project's MJCF of the arm "
        f"(`om.arm_model(arm)`, `mj_kinematics`, the end-effector site): **wrong ok** if it misses T by "
        f"more than {POSITION_TOLERANCE:g} m (or {FK_ROUNDING:.1e} |p| where that is more: two FKs' "
        f"rounding far away) or {ORIENTATION_TOLERANCE:g} rad, or q is not in the "
        f"requested configuration (a branch quantity within {BRANCH_BAND:g} of zero counts for both "
        f"signs; psi within {REDUNDANCY_TOLERANCE:g} rad modulo 2 pi, or within its own rounding "
        "next to its singular half-line: `OMSolver.holds`), or `within_limits` is not "
        "`lower <= q <= upper`. **false no**: ok False (or an empty `solve_all`) for T = FK(q) in "
        "c = configuration_of(q) (for huge psi: only where the reduced psi is within 1e-9 of q's). "
        "**non-library**: an exception that is not an `om.OMError`. **differ**: an answer (status, q, "
        "errors, within_limits, bit for bit) that differs from one it must equal: the same call again, "
        "another layout, a thread, a batch row, a huge psi's exact reduction. **calls**: library calls "
        "checked (a batch counts its rows).",
        "",
        f"`solve_all` on the torus arms (gen3, sawyer; about 5 ms a call) runs on every "
        f"{TORUS_SOLVE_ALL_STRIDE}th pose of the random, singular and layouts classes, and in 1.5 % of "
        "their thread and repeated questions; on every pose for the other arms.",
        "",
        "Reading the notes: a wrong ok marked *within the solver's own tolerance* misses by more "
        "than this page's 1e-10 but less than the solver's own `position_tolerance` / "
        "`orientation_tolerance` (defaults 1e-10 m and 1e-10 rad); *solve_all without q*: "
        f"`solve_all` returned roots, none within {ROOT_MATCH:g} of q; *far: status not 'unreachable'*: "
        "a pose translated 1e3 ... 1e300 m answered otherwise; *library exception*: an `om.OMError` "
        "raised for a valid input.",
        *unlimited_prismatic_note([r.arm for r in results]),
        "",
        "## Summary",
        "",
        _cells(
            [
                "class",
                "arm",
                "poses",
                "calls",
                "ok",
                "wrong ok",
                "false no",
                "non-library",
                "differ",
                "s",
                "slowest call",
                "notes",
            ]
        ),
        "|" + "---|" * 12,
    ]
    for cls in CLASSES:
        for t in (t for t in tallies if t.cls == cls):
            notes = "; ".join(f"{k}: {v}" for k, v in sorted(t.notes.items()))
            out.append(
                _cells(
                    [
                        cls,
                        t.arm,
                        t.poses,
                        t.calls,
                        t.ok,
                        t.wrong_ok,
                        t.false_no,
                        t.foreign,
                        t.differs,
                        f"{t.seconds:.0f}",
                        f"{1e3 * t.slowest[0]:.0f} ms ({t.slowest[1]})",
                        notes,
                    ]
                )
            )
    out += ["", "Totals per class:", ""]
    out += [
        _cells(["class", "poses", "calls", "ok", "wrong ok", "false no", "non-library", "differ"]),
        "|" + "---|" * 8,
    ]
    for cls in CLASSES:
        rows = [t for t in tallies if t.cls == cls]
        if rows:
            sums = [
                sum(getattr(t, a) for t in rows)
                for a in ("poses", "calls", "ok", "wrong_ok", "false_no", "foreign", "differs")
            ]
            out.append(_cells([cls, *sums]))
    if any(r.decades for r in results):
        found = {k for r in results for k in r.decades if k != "limits"}
        columns = [str(d) for d in sorted({*DECADES, *map(int, found)})] + ["limits"]
        out += [
            "",
            "## Singular and boundary poses per decade of the branch offset",
            "",
            "Cell: poses with any false no, wrong ok or non-library exception / poses, by "
            "floor(log10 |branch quantity|) of the moved branch; *limits*: joints at a limit +- 1e-12.",
            "",
            _cells(["arm", *[f"1e{d}" if d != "limits" else d for d in columns]]),
            "|" + "---|" * (len(columns) + 1),
        ]
        for r in results:
            cells = [r.arm]
            for col in columns:
                d = r.decades.get(col)
                cells.append(f"{d['any']}/{d['cases']}" if d else "-")
            out.append(_cells(cells))
        kinds = ["false no (solve)", "false no (hinted solve)", "false no (solve_all)", "wrong ok"]
        out += ["", "The same, by call (all decades and limits together):", ""]
        out += [_cells(["arm", "poses", *kinds]), "|" + "---|" * (len(kinds) + 2)]
        for r in results:
            total = Counter()
            for d in r.decades.values():
                total.update(d)
            out.append(_cells([r.arm, total["cases"], *[total[k] for k in kinds]]))
        out += arm_angle_line_table(results)
        out += [
            "",
            "## The other side of the boundary",
            "",
            f"Poses with |branch offset| <= {BRANCH_BAND:g} (`om.BRANCH_BAND`), asked in the configuration "
            "with that branch's sign flipped: by the band contract such a pose belongs to both, so a "
            "'no' there is a false no (counted in the singular class above).",
            "",
            _cells(
                [
                    "arm",
                    "poses",
                    "ok (solve)",
                    "ok (hinted)",
                    "false no (solve / hinted)",
                    "wrong ok",
                ]
            ),
            "|---|---|---|---|---|---|",
        ]
        for r in results:
            o = r.other_side
            out.append(
                _cells(
                    [
                        r.arm,
                        o["cases"],
                        o["ok (solve)"],
                        o["ok (hinted solve)"],
                        f"{o['false no (solve)']} / {o['false no (hinted solve)']}",
                        o["wrong ok"],
                    ]
                )
            )
    out += bad_input_table(bad)
    failures = [f for r in results for f in r.failures]
    counts = Counter()
    for r in results:
        for (cls, kind), v in r.failure_counts.items():
            counts[(r.arm, cls, kind)] += v
    out += ["", "## Reproducers", ""]
    if not failures:
        out.append("None: nothing failed.")
    else:
        out += [
            "Counts of every failure kind, then up to 5 reproducers of each (all kept ones, up to "
            f"{KEEP} per kind, in the `.json` beside this page). q, T and c as given to the call.",
            "",
            _cells(["arm", "class", "kind", "count"]),
            "|---|---|---|---|",
        ]
        out += [_cells([a, c, k, v]) for (a, c, k), v in sorted(counts.items())]
        out.append("")
        shown: Counter = Counter()
        for f in failures:
            key = (f.arm, f.cls, f.kind)
            shown[key] += 1
            if shown[key] <= 5:
                out.append(reproducer(f))
    out.append("")
    return "\n".join(out)


def merge(parts: Sequence[ArmResult]) -> ArmResult:
    """One arm's results from several runs (different classes of it) as one."""
    out = ArmResult(parts[0].arm)
    for r in parts:
        out.tallies += r.tallies
        for mine, theirs in ((out.decades, r.decades), (out.arm_angle_line, r.arm_angle_line)):
            for key, counts in theirs.items():
                mine.setdefault(key, Counter()).update(counts)
        out.other_side.update(r.other_side)
        out.failures += r.failures
        out.failure_counts.update(r.failure_counts)
        out.seconds += r.seconds
    return out


def combine(paths: Sequence[str]) -> str:
    """The page of several ``--save-results`` pickles (runs of different arms or classes on the
    same code), arms in :func:`om.arm_names` order; writes it as ``adversarial.md``."""
    runs = []
    for path in paths:
        with open(path, "rb") as f:
            runs.append(pickle.load(f))
    by_arm: dict[str, list[ArmResult]] = {}
    for run in runs:
        for r in run["results"]:
            by_arm.setdefault(r.arm, []).append(r)
    results = [merge(by_arm[name]) for name in om.arm_names() if name in by_arm]
    bad = [b for run in runs for b in run["bad"]]
    run_line = "Runs, combined with `--combine`: " + "; ".join(
        f"`python -m benchmarks.adversarial {' '.join(run['argv'])}` ({run['seconds']:.0f} s)" for run in runs
    )
    args = argparse.Namespace(seed=0, jobs=len(runs))
    load = os.getloadavg()[0]
    sizes = runs[0].get("sizes", Sizes.of(100_000, 10_000))
    text = markdown(results, bad, sizes, args, 0.0, (load, load), run_line + ".  ")
    write_page("adversarial.md", text)
    failures = [f.__dict__ for r in results for f in r.failures]
    (RESULTS / "adversarial.json").write_text(json.dumps(failures, indent=1) + "\n")
    return text


def main(argv: list[str] | None = None) -> list[ArmResult]:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--arms", nargs="+", default=om.arm_names(), choices=om.arm_names())
    parser.add_argument("--n-random", type=int, default=100_000, help="random poses per arm (default 1e5)")
    parser.add_argument("--n-singular", type=int, default=10_000, help="branch-boundary poses per arm (1e4)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--quick", action="store_true", help="1/100 of the sizes; writes adversarial_quick.md"
    )
    parser.add_argument(
        "--n-line",
        type=int,
        help="poses next to psi's half-line per 7-DOF arm, in the singular class (--n-singular / 10)",
    )
    parser.add_argument("--jobs", type=int, default=1, help="processes, one arm each at a time (default 1)")
    parser.add_argument("--classes", nargs="+", default=list(CLASSES), choices=CLASSES)
    parser.add_argument("--no-bad-input", action="store_true", help="skip the bad-input table")
    parser.add_argument(
        "--save-results", metavar="PATH", help="also pickle the per-arm results (for --combine)"
    )
    parser.add_argument("--combine", nargs="+", metavar="PATH", help="only write the page of these pickles")
    args = parser.parse_args(argv)
    if args.combine:
        combine(args.combine)
        return []
    n_random, n_singular = args.n_random, args.n_singular
    if args.quick:
        n_random, n_singular = max(n_random // 100, 1), max(n_singular // 100, 1)
    sizes = Sizes.of(n_random, n_singular, args.n_line)
    load_start = os.getloadavg()[0]
    start = time.perf_counter()
    bad = [] if args.no_bad_input else run_bad_inputs()
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            # The torus arms (slowest) first, so that they do not finish last alone.
            order = sorted(args.arms, key=lambda name: name not in ("sawyer", "gen3"))
            futures = {name: pool.submit(run_arm, name, sizes, args.seed, args.classes) for name in order}
            results = [futures[name].result() for name in args.arms]
    else:
        results = [run_arm(name, sizes, args.seed, args.classes) for name in args.arms]
    seconds = time.perf_counter() - start
    text = markdown(results, bad, sizes, args, seconds, (load_start, os.getloadavg()[0]))
    stem = "adversarial_quick" if args.quick else "adversarial"
    write_page(f"{stem}.md", text)
    if args.save_results:
        with open(args.save_results, "wb") as f:
            pickle.dump(
                {"results": results, "bad": bad, "seconds": seconds, "argv": sys.argv[1:], "sizes": sizes}, f
            )
    failures = [f.__dict__ for r in results for f in r.failures]
    (RESULTS / f"{stem}.json").write_text(json.dumps(failures, indent=1) + "\n")
    print(f"total wall time {seconds:.1f} s")
    return results


if __name__ == "__main__":
    main()
