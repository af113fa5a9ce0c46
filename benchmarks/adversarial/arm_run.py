"""One arm's run: its solver and checker, the calls, their judgements and the reproducers."""

from __future__ import annotations

import math
import time
import zlib
from collections.abc import Callable
from typing import Any

import numpy as np

import om_redundant as om
from om_redundant import _core

from .checker import Checker
from .draws import PoseDraws
from .records import KEEP, ROOT_MATCH, TORUS_SOLVE_ALL_STRIDE, TURN, WITHIN_SOLVER, ArmResult, Failure, Tally


class ArmRun(PoseDraws):
    """One arm's solver, checker, random stream and findings."""

    def __init__(self, name: str, seed: int):
        self.solver = om.OMSolver(name)
        self.arm = self.solver.arm
        self.checker = Checker(self.solver)
        self.rng = np.random.default_rng([seed, zlib.crc32(name.encode())])
        self.result = ArmResult(name)
        self.torus = self.solver.solver_data().mode == _core.TORUS
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
