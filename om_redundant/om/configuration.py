"""The configuration vector c: branch signs plus redundancy values."""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import product

from ..exceptions import InvalidInput

_TURN = 2.0 * math.pi


@dataclass(frozen=True)
class Configuration:
    """Which inverse-kinematics solution to take (the paper's c vector).

    Attributes:
        signs: Branch signs of the model arm's closed form, each -1 or +1; for 6-DOF
            arms ``(ARM, ELBOW, WRIST)``.
        redundancy: Redundancy variables appended to c (the arm angle psi of a 7-DOF
            arm); empty for 6-DOF arms.
    """

    signs: tuple[int, ...]
    redundancy: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        signs = tuple(self.signs)
        for s in signs:
            if isinstance(s, bool) or s not in (-1, 1):
                raise InvalidInput(f"configuration signs must be -1 or +1, got {signs}")
        redundancy = tuple(float(r) for r in self.redundancy)
        if not all(math.isfinite(r) for r in redundancy):
            raise InvalidInput(f"configuration redundancy values must be finite, got {redundancy}")
        object.__setattr__(self, "signs", tuple(int(s) for s in signs))
        object.__setattr__(self, "redundancy", redundancy)

    def isclose(self, other: Configuration, atol: float = 1e-9) -> bool:
        """Same signs, and redundancy values (angles) equal within ``atol`` modulo 2 pi."""
        if self.signs != other.signs or len(self.redundancy) != len(other.redundancy):
            return False
        # Each angle reduced first (exactly, as the solver does): a - b of a huge angle and a
        # small one would lose the small one's digits.
        return all(
            abs(math.remainder(math.remainder(a, _TURN) - math.remainder(b, _TURN), _TURN)) <= atol
            for a, b in zip(self.redundancy, other.redundancy, strict=True)
        )

    @staticmethod
    def all_signs(count: int) -> list[Configuration]:
        """Every sign combination of ``count`` branches, without redundancy values."""
        return [Configuration(signs) for signs in product((1, -1), repeat=count)]
