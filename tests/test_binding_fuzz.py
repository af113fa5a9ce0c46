"""A fuzz test of the compiled binding: every ``ckernels`` function and Solver method called
with its arguments from a real use (a global choice, a tracking step and a way's check past
obstacles, and solves), then changed by hypothesis: an argument replaced (wrong types, None, huge integers,
NaN, strings, arrays of any dtype and shape), an array's entries set to NaN, inf, huge or tiny
values, cast to another dtype, made non-contiguous, read-only, longer or shorter, an argument
dropped or added. Each call either returns or raises TypeError, ValueError, OverflowError,
RuntimeError (a Solver not initialised or initialised twice) or MemoryError; it never crashes or
hangs. The draws run in a fresh interpreter (``fuzz``) with a time limit, so that a crash fails
the test instead of the whole run."""

from __future__ import annotations

import os
import types
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import run_python

pytestmark = pytest.mark.sanitize

#: What a call may raise: a malformed argument, a Solver's state, an allocation refused.
ACCEPTED = (TypeError, ValueError, OverflowError, RuntimeError, MemoryError)
#: Draws per run (about 1 ms each, under ASan too; OM_FUZZ_EXAMPLES sets another number).
EXAMPLES = int(os.environ.get("OM_FUZZ_EXAMPLES", "3000"))
#: Special floats an array entry or a number may take.
SPECIAL = [np.nan, np.inf, -np.inf, 1e308, -1e16, 1e16, 5e-324, -0.0, 1e-300, 2.0**53]
INTS = [0, 1, -1, 2, 7, 16, 255, 2**31, -(2**31), 2**63 - 1, -(2**63), 2**64, -(2**70)]
INT64S = INTS[:11]  # (those an int64 entry holds)


def _snapshot(value: Any) -> Any:
    """value with its arrays copied (lists and tuples followed), the rest as it is."""
    if isinstance(value, np.ndarray):
        return value.copy()
    if hasattr(value, "_fields"):  # (a record of om_redundant._core)
        return type(value)(*(_snapshot(x) for x in value))
    if isinstance(value, list | tuple):
        return type(value)(_snapshot(x) for x in value)
    return value


def recorded_calls() -> dict[str, tuple[Callable[..., Any], tuple[Any, ...]]]:
    """Each ckernels entry point with the arguments of one real call: the module functions
    that a global choice, a tracking step and a way's check of the Panda past three obstacles
    make (recorded there), the rest and the Solver's methods written out here."""
    import om_redundant as om
    from benchmarks.control_rate import HOMES, MIN_CLEARANCE, figure_eight, obstacles
    from om_redundant import _core

    functions = {
        name: getattr(_core, name)
        for name in dir(_core)
        if isinstance(getattr(_core, name), types.BuiltinFunctionType)  # (the kernels: C functions)
    }
    seen: dict[str, tuple[Any, ...]] = {}

    def recorder(name: str, function: Callable[..., Any]) -> Callable[..., Any]:
        def call(*args: Any) -> Any:
            seen.setdefault(name, _snapshot(args))
            return function(*args)

        return call

    for name, function in functions.items():
        setattr(_core, name, recorder(name, function))
    try:
        solver = om.OMSolver("panda")
        T_home = solver.arm.fk(HOMES["panda"])
        optimizer = om.RedundancyOptimizer(
            solver, obstacles(T_home[:3, 3], 3), min_clearance=MIN_CLEARANCE, max_step=0.005
        )
        choice = optimizer.choose(figure_eight(T_home, 0, 200))
        optimizer.choose(figure_eight(T_home, 1, 200), choice)
        optimizer.objective.clearance.minimum_along(HOMES["panda"], choice.solution.q, 0.2)  # (a way's check)
    finally:
        for name, function in functions.items():
            setattr(_core, name, function)

    data, kernel, q = solver.solver_data(), solver.kernel, HOMES["panda"]
    T, c = solver.arm.fk(q), solver.configuration_of(q)
    R, p = np.zeros(9), np.zeros(3)
    _core.flange_target(T, data.T_base_root, data.T_tool_flange, R, p)
    signs, psi = np.array(c.signs, dtype=np.int64), np.array(c.redundancy)
    ur5e = om.OMSolver("ur5e").solver_data()
    written = {
        "arm_angle_gradient": (data.params, data.model_table, q, np.zeros(7)),
        "box_overlap": (
            _core.GeomPose(np.zeros(3), R, np.array([0, 0, 0.1]), 0.05),
            _core.GeomPose(np.ones(3), R, np.full(3, 0.2)),
            np.zeros(6),
        ),
        "branch_values": (2, data.params, q, np.zeros(3)),
        "redundancy_values": (2, data.params, q, np.zeros(1)),
        "jacobian": (data.real_table, np.eye(4), np.eye(4), q, np.zeros((6, 7))),
        "flange_target": (T, data.T_base_root, data.T_tool_flange, np.zeros(9), np.zeros(3)),
        "model_ik": (
            _core.FamilyModel(2, data.params, data.model_table),
            _core.FlangeTarget(R.reshape(3, 3), p, signs, psi),
            q,
            np.zeros(7),
            False,
        ),
        "model_ik_at_reach": (data.params, _core.FlangeTarget(R, p, signs, psi), q, np.zeros(7)),
        "srs_model_q7": (data.params, _core.FlangeTarget(R, p, signs, psi), q, np.zeros(7)),
        "model_ik_lifted": (data.params, _core.FlangeTarget(R, p, signs, psi), q[0], q[6], 0.3, np.zeros(7)),
        "model_lifted_terms": (data.params, _core.FlangeTarget(R, p, signs, psi), q[0], q[6]),
        "polish": (
            data.real_table,
            R,
            p,
            q.copy(),
            20,
            _core.ArmAngleRow(data.params, data.model_table, psi[0]),
        ),
    }
    calls = {name: (functions[name], seen.get(name, written.get(name))) for name in functions}
    m, roots = 3, _core.MAX_ROOTS
    Ts, rows, psis = np.stack([T] * m), np.stack([signs] * m), np.stack([psi] * m)
    methods = {
        "solve": (T, c.signs, c.redundancy, None, np.zeros(7), False),
        "solve_pose": (T, c),
        "solve_rows": (
            _core.SolveBatch(
                Ts,
                rows,
                psis,
                None,
                np.zeros((m, 7)),
                np.zeros(m, dtype=np.int64),
                np.zeros(m),
                np.zeros(m),
                np.zeros(m, dtype=np.int64),
                np.zeros(m, dtype=bool),
            ),
            0,
            m,
        ),
        "solve_all_rows": (
            _core.SolveAllBatch(
                Ts,
                rows,
                psis,
                np.ones(m, dtype=bool),
                np.zeros((m, roots, 7)),
                np.zeros(m, dtype=np.int64),
                np.zeros(m, dtype=np.int64),
                np.zeros((m, roots)),
                np.zeros((m, roots)),
                np.zeros((m, roots), dtype=bool),
            ),
            0,
            m,
        ),
        "solve_all": (
            T,
            c.signs,
            c.redundancy,
            _core.Roots(np.zeros((roots, 7)), np.zeros(roots), np.zeros(roots), np.zeros(roots, dtype=bool)),
        ),
        "configuration_values": (q, np.zeros(3), np.zeros(1)),
        "bounded_search": (T, c.signs, c.redundancy, np.zeros((roots, 7)), False),
        "holds": (q, c.signs, c.redundancy),
    }
    # (unbound, the Solver first: swapped as other solver arguments are)
    for name, args in methods.items():
        calls[f"Solver.{name}"] = (getattr(_core.Solver, name), (kernel, *args))
    gen3 = om.OMSolver("gen3")
    torus = (gen3.kernel, gen3.arm.fk(np.zeros(7)), (1, 1, 1), (0.0,), 0.1, 0.1, 0.05)
    calls["Solver.torus_bound"] = (_core.Solver.torus_bound, torus)
    calls["Solver"] = (_core.Solver, (data,))
    calls["Solver (6-DOF)"] = (_core.Solver, (ur5e,))
    missing = [name for name, (_, args) in calls.items() if args is None]
    assert not missing, f"no arguments for {missing}"
    return calls


class _Clearing:
    """An item that empties the list holding it when it is read as a number or a truth."""

    def __init__(self, holder: list[Any]):
        self.holder = holder

    @staticmethod
    def items(n: int) -> list[Any]:
        """A list of n such items."""
        holder: list[Any] = []
        holder += [_Clearing(holder) for _ in range(n)]
        return holder

    def __index__(self) -> int:
        self.holder.clear()
        return 1

    def __float__(self) -> float:
        self.holder.clear()
        return 0.5

    def __bool__(self) -> bool:
        self.holder.clear()
        return True


def _array(rng: np.random.Generator, like: np.ndarray | None = None) -> np.ndarray:
    """An array of a random dtype and shape, or like's shape, of random and special entries."""
    dtype = rng.choice(["float64", "int64", "bool", "float32", "int32", "uint8", "complex128"])
    shape = tuple(rng.integers(0, 5, rng.integers(0, 4)))
    if like is not None and rng.random() < 0.5:
        shape = like.shape
    values = rng.choice([*SPECIAL, 0.0, 1.0, -1.0, 0.5], size=shape) if shape else rng.choice(SPECIAL)
    with np.errstate(all="ignore"):
        return np.asarray(values).astype(dtype)


def _garbage(rng: np.random.Generator, like: Any) -> Any:
    """Any value a caller might pass where `like` was expected."""
    kinds = [
        lambda: None,
        lambda: bool(rng.integers(2)),
        lambda: int(rng.choice(INTS)),
        lambda: float(rng.choice(SPECIAL)),
        lambda: "x" * int(rng.integers(4)),
        lambda: [float(x) for x in rng.choice(SPECIAL, rng.integers(0, 8))],
        lambda: tuple(int(x) for x in rng.choice(INTS, rng.integers(0, 4))),
        lambda: _array(rng, like if isinstance(like, np.ndarray) else None),
        lambda: object(),
        lambda: _Clearing.items(int(rng.integers(1, 8))),
        lambda: {"a": 1},
    ]
    return kinds[int(rng.integers(len(kinds)))]()


def _changed(rng: np.random.Generator, value: Any) -> Any:
    """value changed a little: an array's entries, dtype, contiguity, writability or length; a
    number made special; a sequence's item."""
    if isinstance(value, np.ndarray):
        how = int(rng.integers(10))  # (0 - 4: the entries)
        array = value.copy()
        if how <= 4 and array.size and array.dtype.kind in "fi":
            flat = array.reshape(-1)
            at = rng.integers(0, flat.size, rng.integers(1, 4))
            with np.errstate(all="ignore"):
                flat[at] = rng.choice(SPECIAL if array.dtype.kind == "f" else INT64S, at.size)
            return array
        if how == 5:
            with np.errstate(all="ignore"):
                return array.astype(rng.choice(["float32", "int64", "int32", "bool", "float64", "uint8"]))
        if how == 6:  # the same entries, not C-contiguous
            return np.repeat(array[..., None], 2, axis=-1)[..., 0] if array.ndim else array
        if how == 7:
            array.flags.writeable = False
            return array
        if how == 8 and array.ndim:
            return array.T
        flat = array.reshape(-1)
        return np.concatenate([flat, flat[:1]]) if rng.random() < 0.5 else flat[: max(flat.size - 1, 0)]
    if isinstance(value, bool):
        return not value
    if isinstance(value, int | float | np.floating | np.integer):
        return type(value)(rng.choice(INTS if isinstance(value, int | np.integer) else SPECIAL))
    if isinstance(value, list | tuple) and value:
        items = list(value)
        at = int(rng.integers(len(items)))
        items[at] = _changed(rng, items[at])
        return type(value)(items) if not hasattr(value, "_fields") else type(value)(*items)
    return _garbage(rng, value)


def _mutated(rng: np.random.Generator, args: tuple[Any, ...]) -> tuple[Any, ...]:
    """args with one to three changes (_changed, _garbage, or an argument dropped or added)."""
    args = list(_snapshot(args))
    for _ in range(int(rng.choice([1, 1, 1, 2, 2, 3]))):
        how = rng.random()
        if how < 0.05:
            args = args[:-1]
        elif how < 0.1:
            args.append(_garbage(rng, None))
        elif args:
            at = int(rng.integers(len(args)))
            args[at] = _changed(rng, args[at]) if how < 0.7 else _garbage(rng, args[at])
    return tuple(args)


def _swapped(value: Any, other: Any) -> Any:
    """value, or a record's fields, with a Solver (other's type) replaced by other."""
    if type(value) is type(other):
        return other
    if hasattr(value, "_fields"):
        return type(value)(*(other if type(x) is type(other) else x for x in value))
    return value


def fuzz(examples: int = EXAMPLES) -> None:
    """Draw `examples` calls (tests/test_binding_fuzz.py's docstring); an exception other than
    ACCEPTED fails, a crash ends the interpreter. Prints, per entry point, the calls that
    returned and the calls made."""
    import om_redundant as om
    from om_redundant import _core

    calls = recorded_calls()
    names = sorted(calls)
    counts = dict.fromkeys(names, 0)
    returned = {}
    # what a solver argument may become: a bare Solver, a 6-DOF arm's, a torus arm's
    others = [
        _core.Solver.__new__(_core.Solver),
        *(om.OMSolver(name).kernel for name in ("ur5e", "gen3")),
    ]

    @settings(
        max_examples=examples,
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
    )
    @given(name=st.sampled_from(names), seed=st.integers(0, 2**32 - 1))
    def one_call(name: str, seed: int) -> None:
        rng = np.random.default_rng(seed)
        function, args = calls[name]
        if name.startswith("Solver") and not name.startswith("Solver."):  # the data's fields
            data = args[0]
            fields = rng.choice(data._fields, 2)
            args = (data._replace(**{f: _changed(rng, getattr(data, f)) for f in fields}),)
        else:
            args = _mutated(rng, args)
            swap = rng.random() < 0.2
            args = tuple(_swapped(a, others[rng.integers(3)]) if swap else a for a in args)
        counts[name] += 1
        try:
            function(*args)
            returned[name] = returned.get(name, 0) + 1
        except ACCEPTED:
            pass

    with warnings.catch_warnings():  # (complex arrays cast to real ones, as drawn)
        warnings.simplefilter("ignore", np.exceptions.ComplexWarning)
        one_call()
    print(" ".join(f"{name}:{returned.get(name, 0)}/{count}" for name, count in counts.items()))


def test_the_binding_returns_or_raises_for_any_arguments():
    script = (
        f"import faulthandler; faulthandler.dump_traceback_later(280, exit=True)\n"
        f"from tests.test_binding_fuzz import fuzz; fuzz({EXAMPLES})"
    )
    done = run_python("-c", script, timeout=300)
    assert done.returncode == 0, f"exit {done.returncode}\n{done.stdout[-2000:]}\n{done.stderr[-6000:]}"
