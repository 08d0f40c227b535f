"""Sparse direct linear algebra of SPD stiffness matrices: one solver dispatcher for the plain
solves (:func:`factorize_spd`, :mod:`fegear.linalg.solve`) and the Schur complements and inverse
blocks of the compliance operators (:mod:`fegear.linalg.schur`).

Backends, chosen by the same rules for both (:func:`resolve_backend`): MKL PARDISO where the
``mkl`` wheel is installed (extra ``pardiso``, x86-64), SciPy SuperLU everywhere.
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
from fegear.linalg.solve import SparseFactor, factorize_spd

__all__ = [
    "BACKENDS",
    "ENV_SOLVER",
    "SparseFactor",
    "available_backends",
    "factorize_spd",
    "inverse_block",
    "inverse_columns",
    "inverse_off_block",
    "requested_backend",
    "resolve_backend",
    "schur_complement",
]
