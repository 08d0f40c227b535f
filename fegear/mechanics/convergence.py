"""Observed convergence rates of mesh studies."""

from __future__ import annotations

import numpy as np

from fegear.errors import InputError

__all__ = ["observed_rate"]


def observed_rate(h: np.ndarray, error: np.ndarray) -> float:
    """Least-squares slope of ``log|error|`` against ``log h``: ``|e| ~ C h^rate``.

    Parameters
    ----------
    h
        (n,) mesh or cell sizes, n >= 2, distinct and > 0.
    error
        (n,) errors against the reference (signed; their magnitude is used).
    """
    h = np.asarray(h, dtype=float)
    e = np.abs(np.asarray(error, dtype=float))
    if h.size < 2 or h.shape != e.shape:
        raise InputError("h", h.shape, "at least two sizes, one error each")
    if np.any(h <= 0) or np.any(e <= 0):
        raise InputError("error", e.tolist(), "non-zero errors and positive sizes")
    slope, _ = np.polyfit(np.log(h), np.log(e), 1)
    return float(slope)
