"""Typed exceptions of fegear.

Every error that bad input can cause is one of these, and its message names the field, the value
and the allowed range, so the command line can print it as one line.
"""

from __future__ import annotations

__all__ = [
    "FegearError",
    "InputError",
    "DesignError",
    "MeshError",
    "SolverError",
    "BackendUnavailable",
]


class FegearError(Exception):
    """Base class of all fegear errors."""


class InputError(FegearError, ValueError):
    """A value given by the user is outside its allowed range.

    Parameters
    ----------
    field
        Dotted name of the offending field, e.g. ``"bodies.roller.radii_mm"``.
    value
        The value that was given.
    allowed
        Human-readable description of the allowed range, e.g. ``"> 0"``.
    """

    def __init__(self, field: str, value: object, allowed: str, detail: str = "") -> None:
        self.field = field
        self.value = value
        self.allowed = allowed
        self.detail = detail
        msg = f"{field} = {value!r} is not allowed: must be {allowed}"
        if detail:
            msg += f" ({detail})"
        super().__init__(msg)

    def __reduce__(self):
        # picklable with its fields (raised in a worker process, re-raised in the caller)
        return (type(self), (self.field, self.value, self.allowed, self.detail))


class DesignError(InputError):
    """Gear design data that cannot make a valid tooth (undercut, pointed tooth, interference)."""


class MeshError(FegearError, RuntimeError):
    """gmsh failed, or produced elements of unacceptable quality."""


class SolverError(FegearError, RuntimeError):
    """A numerical solve failed (singular operator, no convergence)."""


class BackendUnavailable(FegearError, ImportError):
    """A requested optional backend (e.g. MKL PARDISO) cannot be loaded on this machine."""
