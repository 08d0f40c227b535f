r"""One sparse direct solver for symmetric positive definite (SPD) systems: :func:`factorize_spd`.

Every plain solve :math:`K x = b` of fegear (displacement fields, stress sectors, mesh checks)
goes through here; the compliance operators use the Schur complements of
:mod:`fegear.linalg.schur`. Both choose their backend by the same rules
(:func:`fegear.linalg.schur.resolve_backend`): ``"auto"`` is ``FEGEAR_SOLVER`` when set, else MKL
PARDISO when the ``mkl_rt`` library loads and passes its self-check, else SciPy SuperLU (logged
at INFO with the reason); an explicit ``"pardiso"`` that cannot load raises
:class:`~fegear.errors.BackendUnavailable`; an unknown name raises
:class:`~fegear.errors.InputError`.

The choice is made once, before any work: a PARDISO failure during the factorization or a solve
(a matrix that is not positive definite, memory) raises :class:`~fegear.errors.SolverError` with
PARDISO's error code and its meaning. It never falls back to SuperLU silently, so the backend a
result reports is the one that computed it.

Factorizations, on :math:`K = K^T \succ 0` (the stiffness of a body with its rigid-body modes
constrained, Dirichlet DOFs eliminated):

``"pardiso"``
    Intel oneMKL PARDISO, ``mtype = 2`` (real symmetric positive definite): sparse Cholesky
    :math:`K = L L^T` of the upper triangle after a nested-dissection ordering (METIS,
    ``iparm[1] = 3``), phase 12; each :meth:`SparseFactor.solve` is phase 33 (forward and backward
    substitution, all right-hand sides in one call). No pivoting is needed for an SPD matrix
    (Golub & Van Loan, *Matrix Computations*, 4th ed., §4.2), and none is done: a zero or
    negative pivot is PARDISO error -4. ``iparm`` and phases: oneMKL Developer Reference,
    "pardiso" and "pardiso iparm Parameter"; the binding is :mod:`fegear.linalg._mkl_pardiso`
    (ctypes, no ``pypardiso``). The factor's PARDISO memory is released (phase -1) when the
    :class:`SparseFactor` is garbage-collected.
``"superlu"``
    SciPy's SuperLU (:func:`scipy.sparse.linalg.splu`) as an SPD solver: symmetric mode,
    minimum-degree ordering on :math:`K^T + K` and diagonal pivots (``diag_pivot_thresh = 0``):
    the same symmetric permutation on rows and columns, so :math:`P K P^T = L U` with
    :math:`U = D L^T`: Cholesky's fill, stored twice (SuperLU Users' Guide, options
    ``SymmetricMode``, ``DiagPivotThresh``, ``ColPerm = MMD_AT_PLUS_A``; X. S. Li, "An overview
    of SuperLU", *ACM TOMS* 31(3), 2005). Diagonal pivots are stable for an SPD matrix for the
    same reason as Cholesky's. This ordering against SuperLU's default (COLAMD on :math:`K`,
    partial pivoting), and both backends, on the main job's matrices:
    ``benchmarks/results/sparse_solve.md``.
"""

from __future__ import annotations

import logging
import time
from typing import Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fegear.errors import BackendUnavailable, InputError, SolverError
from fegear.linalg import schur
from fegear.linalg._mkl_pardiso import PardisoFactor

__all__ = ["SparseFactor", "factorize_spd"]

logger = logging.getLogger(__name__)


@runtime_checkable
class SparseFactor(Protocol):
    """A factorised sparse SPD matrix ``K`` (from :func:`factorize_spd`).

    Attributes
    ----------
    backend
        ``"pardiso"`` or ``"superlu"``: the backend that factorised ``K`` and solves with it.
    n
        Order of ``K``.
    """

    backend: str
    n: int

    def solve(self, b: np.ndarray, n_threads: int | None = None) -> np.ndarray:
        """``x`` with ``K x = b``; ``b`` of shape ``(n,)`` or ``(n, k)`` (``k`` right-hand sides
        solved together), ``x`` of the same shape, float64. ``n_threads``: MKL threads of a
        PARDISO solve (None: those of the factorization; several factors may solve at once in
        different threads, one thread each)."""
        ...


class _Factor:
    """Shared part of the two backends: checks ``b``, solves as ``(n, k)``, checks ``x``."""

    backend: str = ""

    def __init__(self, n: int) -> None:
        self.n = n

    def solve(self, b: np.ndarray, n_threads: int | None = None) -> np.ndarray:
        """``x`` with ``K x = b``.

        Parameters
        ----------
        b
            Right-hand side(s), shape ``(n,)`` or ``(n, k)``, real.
        n_threads
            MKL threads of a PARDISO solve (None: those of the factorization); SuperLU has one.

        Returns
        -------
        numpy.ndarray
            ``x``, the shape of ``b``, float64.

        Raises
        ------
        InputError
            ``b`` has the wrong shape, is complex or has non-finite entries.
        SolverError
            The backend failed, or the solution has non-finite entries.
        """
        arr = np.asarray(b)
        if arr.ndim not in (1, 2) or arr.shape[0] != self.n:
            raise InputError(
                "b", f"array of shape {arr.shape}", f"shape ({self.n},) or ({self.n}, k)"
            )
        if np.iscomplexobj(arr) or not (
            np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)
        ):
            raise InputError("b.dtype", str(arr.dtype), "real")
        B = arr.reshape(self.n, -1)
        if not np.all(np.isfinite(B)):
            raise InputError("b", "non-finite entries", "finite")
        if B.shape[1] == 0:
            return np.zeros(arr.shape)
        X = self._solve(B, n_threads)
        if not np.all(np.isfinite(X)):
            raise SolverError(f"{self.backend}: the solution has non-finite entries (K singular?)")
        return X.reshape(arr.shape)

    def _solve(self, B: np.ndarray, n_threads: int | None) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<SparseFactor {self.backend} n={self.n}>"


class _PardisoSparseFactor(_Factor):
    backend = "pardiso"

    def __init__(self, factor: PardisoFactor) -> None:
        super().__init__(factor.n)
        self._factor = factor  # its weakref.finalize releases PARDISO's memory with it

    def _solve(self, B: np.ndarray, n_threads: int | None) -> np.ndarray:
        return self._factor.solve(B, n_threads)


class _SuperLUSparseFactor(_Factor):
    backend = "superlu"

    def __init__(self, lu: spla.SuperLU) -> None:
        super().__init__(lu.shape[0])
        self._lu = lu

    def _solve(self, B: np.ndarray, n_threads: int | None) -> np.ndarray:
        return self._lu.solve(np.asarray(B, dtype=np.float64))


def factorize_spd(K: sp.spmatrix | sp.sparray, backend: str = "auto") -> SparseFactor:
    """Factorise a sparse symmetric positive definite matrix once, for any number of solves.

    Parameters
    ----------
    K
        Sparse, shape ``(n, n)``, symmetric positive definite (e.g. a stiffness matrix with the
        Dirichlet DOFs eliminated). Real values; converted to CSR float64 (never modified).
    backend
        ``"auto"``, ``"pardiso"`` or ``"superlu"`` (case-insensitive); see the module docstring
        and :func:`fegear.linalg.schur.resolve_backend`.

    Returns
    -------
    SparseFactor
        ``.solve(b)`` for ``b`` of shape ``(n,)`` or ``(n, k)``; ``.backend`` is the backend
        used, ``.n`` the order.

    Raises
    ------
    InputError
        ``K`` is not sparse, square, real, finite, symmetric with a positive diagonal; or an
        unknown backend name.
    BackendUnavailable
        ``"pardiso"`` asked for (argument or ``FEGEAR_SOLVER``) but MKL PARDISO cannot be loaded.
    SolverError
        The factorization failed: ``K`` is singular or not positive definite (PARDISO error -4,
        SuperLU zero pivot), or PARDISO reports another error (its code is in the message).
    """
    Kc = schur.check_spd_matrix(K)
    name = schur.resolve_backend(backend)
    n = Kc.shape[0]
    t0 = time.perf_counter()
    factor: _Factor
    if name == "pardiso":
        lib, reason = schur._pardiso()
        if lib is None:  # resolve_backend has checked; kept for a probe reset in between
            raise BackendUnavailable(f"PARDISO is not available ({reason})")
        upper = sp.triu(Kc, format="csr")
        upper.sort_indices()
        factor = _PardisoSparseFactor(lib.factor_spd(upper, schur._mkl_threads(None)))
    else:
        try:
            lu = spla.splu(
                Kc.tocsc(),
                permc_spec="MMD_AT_PLUS_A",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except RuntimeError as exc:  # "Factor is exactly singular"
            raise SolverError(f"SuperLU factorization failed: {exc} (K singular?)") from exc
        factor = _SuperLUSparseFactor(lu)
    logger.info(
        "Sparse SPD factorization with %s: n=%d, nnz=%d in %.2f s",
        name,
        n,
        Kc.nnz,
        time.perf_counter() - t0,
    )
    return factor
