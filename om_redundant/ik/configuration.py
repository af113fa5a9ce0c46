"""The configuration vector c: branch signs plus redundancy values."""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import product

from ..angles import wrap_angle
from ..validation import as_instance, as_number, as_redundancy, as_signs


@dataclass(frozen=True)
class Configuration:
    """Which inverse-kinematics solution to take (the paper's c vector).

    Attributes:
        signs: Branch signs of the model arm's closed form, each -1 or +1; for 6-DOF
            arms ``(ARM, ELBOW, WRIST)``. A sequence of numbers; ``True`` is refused.
        redundancy: Redundancy variables appended to c (the arm angle psi of a 7-DOF
            arm); empty for 6-DOF arms. A sequence of finite real numbers, e.g. ``(0.3,)``;
            a bare number, None or text is refused.

    Raises:
        InvalidInput: Signs that are not a sequence of -1 and +1; redundancy that is not a
            sequence of finite real numbers.
    """

    signs: tuple[int, ...]
    redundancy: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        # Tuples of plain ints +-1 and finite floats are kept as given (the solvers make
        # them every call); anything else is checked and converted.
        signs, redundancy = self.signs, self.redundancy
        if not (type(signs) is tuple and all(type(s) is int and (s == 1 or s == -1) for s in signs)):
            object.__setattr__(self, "signs", tuple(as_signs(signs, None, "configuration signs").tolist()))
        if not (type(redundancy) is tuple and all(type(r) is float and math.isfinite(r) for r in redundancy)):
            values = as_redundancy(redundancy, "configuration redundancy")
            object.__setattr__(self, "redundancy", tuple(values.tolist()))

    def isclose(self, other: Configuration, atol: float = 1e-9) -> bool:
        """Same signs, and redundancy values (angles) equal within ``atol`` modulo 2 pi."""
        as_instance(other, Configuration, "other")
        atol = as_number(atol, "atol")
        if self.signs != other.signs or len(self.redundancy) != len(other.redundancy):
            return False
        # Each angle reduced first (exactly, as the solver does): a - b of a huge angle and a
        # small one would lose the small one's digits.
        return all(
            abs(wrap_angle(wrap_angle(a) - wrap_angle(b))) <= atol
            for a, b in zip(self.redundancy, other.redundancy, strict=True)
        )

    @staticmethod
    def all_signs(count: int) -> list[Configuration]:
        """Every sign combination of ``count`` branches, without redundancy values."""
        return [Configuration(signs) for signs in product((1, -1), repeat=count)]
