"""Sparse direct linear algebra: Schur complements and inverse blocks of SPD stiffness matrices.

Backends: MKL PARDISO in Schur mode where the ``mkl`` wheel exists, SciPy SuperLU everywhere
(see :mod:`fegear.linalg.schur`).
"""

from __future__ import annotations

from fegear.linalg.schur import (
    BACKENDS,
    ENV_SOLVER,
    available_backends,
    inverse_block,
    inverse_columns,
    inverse_off_block,
    requested_backend,
    resolve_backend,
    schur_complement,
)

__all__ = [
    "BACKENDS",
    "ENV_SOLVER",
    "available_backends",
    "inverse_block",
    "inverse_columns",
    "inverse_off_block",
    "requested_backend",
    "resolve_backend",
    "schur_complement",
]
