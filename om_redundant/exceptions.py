"""Exceptions specific to om_redundant."""

from __future__ import annotations


class OMError(Exception):
    """Base class for om_redundant exceptions."""


class InvalidInput(OMError, ValueError):
    """A pose, joint vector or configuration given to the library is malformed.

    Raised for wrong shapes, NaN or inf entries, rotations that are not orthonormal,
    branch signs outside {-1, +1} and the like. The message names the argument and
    the problem.
    """


class UnknownArm(OMError, KeyError):
    """An arm name matches no arm file shipped with the package."""

    def __init__(self, name: str, available: list[str]):
        self.name = name
        super().__init__(f"unknown arm '{name}'; available arms: {', '.join(available)}")

    def __str__(self) -> str:  # KeyError would quote the message.
        return self.args[0]


class ArmFileError(OMError, ValueError):
    """An arm file is malformed. The message names the file, the field and the problem."""

    def __init__(self, path: str, field: str, problem: str):
        self.path, self.field, self.problem = path, field, problem
        super().__init__(f"{path}: field '{field}': {problem}")


class ModelError(OMError, ValueError):
    """No offset-modified model arm with a closed form exists for this arm.

    Raised when an arm violates a condition of the OM method's Theorem 2 (or the
    redundant-arm equivalent) or matches none of the closed-form families.
    """
