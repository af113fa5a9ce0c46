"""Answers compared bit for bit, batch rows shaped as solutions, configurations flipped and reduced."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import om_redundant as om

from .records import TURN


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
