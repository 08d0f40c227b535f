"""Minimal ctypes binding to Intel oneMKL PARDISO: dense Schur complements and sparse Cholesky.

Only what fegear needs: locate and load ``mkl_rt`` (the same search as pypardiso), and on the
upper triangle of a real symmetric positive definite matrix either

- :meth:`MklPardiso.schur_spd` (for :func:`fegear.linalg.schur.schur_complement`): phase 12
  (analysis + numerical factorization) in Schur mode, then always phase -1 (release); or
- :meth:`MklPardiso.factor_spd` (for :func:`fegear.linalg.solve.factorize_spd`): phase 12, the
  factor kept in PARDISO's handle for any number of phase-33 solves (forward and backward
  substitution, several right-hand sides at once), released by phase -1 when the
  :class:`PardisoFactor` is garbage-collected (``weakref.finalize``).

PARDISO settings (oneMKL developer reference, "pardiso iparm Parameter"):

- ``mtype = 2`` (real symmetric positive definite): Cholesky ``L Lᵀ`` without pivoting, so no pivot
  perturbation can alter the Schur complement. A non-SPD input fails with error -4 (zero or negative
  pivot), which we report. The symmetric indefinite type ``-2`` is not needed: Schur mode works with
  ``mtype = 2`` (checked against dense and SuperLU references in ``tests/test_schur.py``).
- ``iparm`` starts from ``pardisoinit`` defaults for that ``mtype`` (``iparm[1] = 3``: the
  OpenMP-parallel METIS nested dissection ordering; ``iparm[7] = 2`` refinement steps, unused as
  there is no solve phase), then:

  - ``iparm[34] = 1``: zero-based ``ia``/``ja`` (no index shift copy needed from SciPy CSR);
  - ``iparm[35] = 1``: Schur mode, "compute the Schur complement only". The Schur block is
    the set of rows ``i`` with ``perm[i] = 1`` (``perm`` is then *not* a fill-reducing
    permutation; the rest of it is 0). PARDISO eliminates all other unknowns and returns the dense
    ``m × m`` Schur matrix in the solution array ``x``, row-major, rows and columns in *increasing
    original index order* whatever order the caller has in mind (both triangles filled, observed
    with MKL 2026.2). ``iparm[35] = 2`` would also keep the factors for later solves (phases
    331–333), which we do not need;
  - ``iparm[26] = 0``: no matrix checker (we build sorted, zero-based CSR ourselves).

  For :meth:`MklPardiso.factor_spd` ``iparm[35] = 0`` (no Schur block) and ``iparm[5] = 0``
  (the solution goes to ``x``, ``b`` is left alone); the right-hand sides of one phase-33 call
  are ``nrhs`` contiguous columns of length ``n`` (Fortran order). ``iparm[7] = 2`` refinement
  steps apply only after perturbed pivots, which ``mtype = 2`` never has (``iparm[6]`` reports
  the steps done).

- Threads: ``MKL_Set_Num_Threads_Local`` around the call (restored afterwards); ``MKL_NUM_THREADS``
  is honoured when set.
- The LP64 interface (32-bit ``MKL_INT``) is requested with ``MKL_Set_Interface_Layer``; a process
  whose ``mkl_rt`` is already locked to ILP64 is reported as "PARDISO not available".
"""

from __future__ import annotations

import contextlib
import ctypes
import glob
import logging
import os
import site
import sys
import threading
import time
import weakref
from collections.abc import Iterator
from ctypes.util import find_library

import numpy as np
import scipy.sparse as sp

from fegear.errors import BackendUnavailable, SolverError

__all__ = ["PARDISO_ERRORS", "MklPardiso", "PardisoFactor", "load_library"]

logger = logging.getLogger(__name__)

#: Meaning of PARDISO's ``error`` output (oneMKL developer reference, "pardiso").
PARDISO_ERRORS: dict[int, str] = {
    -1: "input inconsistent",
    -2: "not enough memory",
    -3: "reordering problem",
    -4: "zero or negative pivot: the matrix is singular or not positive definite "
    "(are all rigid-body modes constrained?)",
    -5: "unclassified (internal) error",
    -6: "reordering failed",
    -7: "diagonal matrix is singular",
    -8: "32-bit integer overflow problem",
    -9: "not enough memory for out-of-core",
    -10: "error opening out-of-core files",
    -11: "read/write error with out-of-core files",
    -12: "pardiso_64 called from a 32-bit library",
    -13: "interrupted by the mkl_progress function",
    -15: "internal error (two-level factorization with matching)",
}

_MKL_INTERFACE_LP64 = 0
_MTYPE_SPD = 2
_PHASE_ANALYSIS_FACTOR = 12
_PHASE_SOLVE = 33
_PHASE_RELEASE_ALL = -1
_INT32_MAX = np.iinfo(np.int32).max
# CBLAS / LAPACKE enumerations (mkl_cblas.h, mkl_lapacke.h)
_COL_MAJOR, _LEFT, _RIGHT, _LOWER, _NO_TRANS, _NON_UNIT = 102, 141, 142, 122, 111, 131


def _candidate_paths() -> list[str]:
    """Where to look for ``mkl_rt``, in the order pypardiso uses (explicit env var first)."""
    paths: list[str] = []
    for var in ("FEGEAR_MKL_RT", "PYPARDISO_MKL_RT"):
        if os.environ.get(var):
            paths.append(os.environ[var])
    for name in ("mkl_rt", "mkl_rt.1", "mkl_rt.2"):
        found = find_library(name)
        if found:
            paths.append(found)
    # The `mkl` wheel puts the library directly in <prefix>/lib (Linux, macOS x86_64) or
    # <prefix>/Library/bin (Windows); try those before pypardiso's recursive glob.
    for prefix in (sys.prefix, site.USER_BASE or ""):
        if not prefix:
            continue
        for pattern in ("lib/libmkl_rt.*", "Library/bin/mkl_rt*.dll"):
            paths.extend(sorted(glob.glob(os.path.join(prefix, pattern)), key=len))
    for prefix in (sys.prefix, site.USER_BASE or ""):
        if prefix:
            paths.extend(
                sorted(glob.glob(f"{prefix}/[Ll]ib*/**/*mkl_rt*", recursive=True), key=len)
            )
    # Drop duplicates, keep order.
    return list(dict.fromkeys(paths))


class MklPardiso:
    """A loaded ``mkl_rt`` with the PARDISO entry points typed for ctypes.

    Parameters
    ----------
    lib
        The loaded shared library.
    path
        Where it was loaded from (for log messages).
    """

    def __init__(self, lib: ctypes.CDLL, path: str) -> None:
        self.lib = lib
        self.path = path
        self._pardiso = lib.pardiso
        self._pardiso.restype = None
        p_int = ctypes.POINTER(ctypes.c_int32)
        self._pardiso.argtypes = [
            ctypes.c_void_p,  # pt (64 pointer-sized handles)
            p_int,  # maxfct
            p_int,  # mnum
            p_int,  # mtype
            p_int,  # phase
            p_int,  # n
            ctypes.c_void_p,  # a
            ctypes.c_void_p,  # ia
            ctypes.c_void_p,  # ja
            ctypes.c_void_p,  # perm
            p_int,  # nrhs
            ctypes.c_void_p,  # iparm
            p_int,  # msglvl
            ctypes.c_void_p,  # b
            ctypes.c_void_p,  # x
            p_int,  # error
        ]
        self._pardisoinit = lib.pardisoinit
        self._pardisoinit.restype = None
        self._pardisoinit.argtypes = [ctypes.c_void_p, p_int, ctypes.c_void_p]
        self._set_threads_local = lib.MKL_Set_Num_Threads_Local
        self._set_threads_local.restype = ctypes.c_int
        self._set_threads_local.argtypes = [ctypes.c_int]
        self._lock = threading.Lock()

    def version(self) -> str:
        """The MKL version string, e.g. ``"Intel(R) oneAPI Math Kernel Library Version 2026.2"``."""
        buf = ctypes.create_string_buffer(256)
        self.lib.MKL_Get_Version_String(buf, ctypes.c_int(len(buf)))
        return buf.value.decode(errors="replace").strip()

    def _call(
        self,
        pt: np.ndarray,
        phase: int,
        n: int,
        data: np.ndarray,
        indptr: np.ndarray,
        indices: np.ndarray,
        perm: np.ndarray,
        iparm: np.ndarray,
        x: np.ndarray,
        b: np.ndarray | None = None,
        nrhs: int = 1,
    ) -> int:
        if b is None:
            b = np.zeros(max(n, 1))  # never read in phases 12 / -1
        error = ctypes.c_int32(0)
        self._pardiso(
            pt.ctypes.data,
            ctypes.byref(ctypes.c_int32(1)),  # maxfct
            ctypes.byref(ctypes.c_int32(1)),  # mnum
            ctypes.byref(ctypes.c_int32(_MTYPE_SPD)),
            ctypes.byref(ctypes.c_int32(phase)),
            ctypes.byref(ctypes.c_int32(n)),
            data.ctypes.data,
            indptr.ctypes.data,
            indices.ctypes.data,
            perm.ctypes.data,
            ctypes.byref(ctypes.c_int32(nrhs)),
            iparm.ctypes.data,
            ctypes.byref(ctypes.c_int32(0)),  # msglvl: silent
            b.ctypes.data,
            x.ctypes.data,
            ctypes.byref(error),
        )
        return int(error.value)

    def spd_inverse(self, S: np.ndarray, overwrite: bool = False) -> np.ndarray:
        """Inverse of a dense SPD matrix by MKL LAPACK: ``dpotrf`` (``S = Uᵀ U``) then ``dpotri``
        (``S⁻¹ = U⁻¹ U⁻ᵀ``), in place on a row-major copy; the upper triangle is mirrored.

        Used instead of SciPy's LAPACK because the OpenBLAS 0.3.30 of the SciPy wheels
        segfaults in multi-threaded ``potrf`` above about 16 000 unknowns (measured: n = 16 384
        and 17 079 crash with two threads, run with one). ``overwrite``: a C-contiguous float64
        ``S`` is the workspace (and the result), saving a copy of ``n²`` values.

        Raises
        ------
        SolverError
            ``S`` is not numerically positive definite, or LAPACK reports an error.
        """
        n = S.shape[0]
        a = _workspace(S, overwrite)
        # The C array read column-major is Sᵀ = S: factor its lower triangle in LAPACK's own
        # layout (LAPACKE's row-major path would transpose the whole matrix twice).
        self._lapacke_spd("LAPACKE_dpotrf", b"L", a)
        self._lapacke_spd("LAPACKE_dpotri", b"L", a)
        # Column-major lower = row-major upper triangle: mirror it, a block of rows at a time.
        for i0 in range(0, n, 2048):
            i1 = min(i0 + 2048, n)
            blk = a[i0:i1, i0:i1]
            a[i0:i1, i0:i1] = np.triu(blk) + np.triu(blk, 1).T
            a[i1:, i0:i1] = a[i0:i1, i1:].T
        return a

    def _lapacke_spd(
        self,
        name: str,
        uplo: bytes,
        a: np.ndarray,
        n: int | None = None,
        ptr: int | None = None,
        lda: int | None = None,
    ) -> None:
        """``LAPACKE_dpotrf`` / ``dpotri`` in place on the square C array ``a``, read
        column-major (the transpose: the same matrix for an SPD one); or, given ``n``, ``ptr``
        and ``lda``, on the ``n × n`` column-major block at address ``ptr`` inside ``a``."""
        fn = getattr(self.lib, name)
        fn.restype = ctypes.c_int
        fn.argtypes = [ctypes.c_int, ctypes.c_char, ctypes.c_int, ctypes.c_void_p, ctypes.c_int]
        if n is None:
            n, ptr, lda = a.shape[0], a.ctypes.data, a.shape[0]
        info = fn(_COL_MAJOR, ctypes.c_char(uplo), n, ptr, lda)
        if info > 0 and name == "LAPACKE_dpotrf":
            raise SolverError(f"matrix is not positive definite (leading minor {info})")
        if info != 0:
            raise SolverError(f"MKL {name} failed: info = {info}")

    def spd_cholesky(self, S: np.ndarray, overwrite: bool = False) -> np.ndarray:
        """Lower Cholesky factor ``L`` (``S = L Lᵀ``) of a dense SPD matrix by MKL ``dpotrf``, on
        a row-major copy (for the same reason as :meth:`spd_inverse`); the strict upper triangle
        is zeroed. ``overwrite``: as :meth:`spd_inverse`.

        Raises
        ------
        SolverError
            ``S`` is not numerically positive definite, or LAPACK reports an error.
        """
        n = S.shape[0]
        a = _workspace(S, overwrite)
        # Column-major upper factor (S = Uᵀ U) of the C array = row-major lower L = Uᵀ.
        self._lapacke_spd("LAPACKE_dpotrf", b"U", a)
        for i0 in range(0, n, 2048):  # zero the strict upper triangle, a block of rows at a time
            i1 = min(i0 + 2048, n)
            a[i0:i1, i0:i1] = np.tril(a[i0:i1, i0:i1])
            a[i0:i1, i1:] = 0.0
        return a

    def spd_inverse_columns(self, S: np.ndarray, columns: np.ndarray) -> np.ndarray:
        r"""The columns ``f = columns`` of ``S⁻¹`` for a dense SPD ``S`` (``m × m``, both
        triangles filled), by MKL LAPACK and BLAS on one copy of ``S`` ordered ``[l, f]``
        (``l`` the other rows).

        The Cholesky factor of the reordered matrix holds every block the partial inverse needs
        (Golub & Van Loan, *Matrix Computations*, 4th ed., §3.2 and §4.2):

        .. math::

            \begin{pmatrix} S_{ll} & S_{lf} \\ S_{fl} & S_{ff} \end{pmatrix}
            = \begin{pmatrix} L_{ll} & 0 \\ W^T & L_{ff} \end{pmatrix}
              \begin{pmatrix} L_{ll}^T & W \\ 0 & L_{ff}^T \end{pmatrix},
            \qquad W = L_{ll}^{-1} S_{lf},\;
            L_{ff} L_{ff}^T = S_{ff} - W^T W ,

        so ``G_ff = (L_ff L_ffᵀ)⁻¹`` (``dpotri`` on the trailing block) and
        ``G_lf = −L_ll⁻ᵀ W G_ff`` (``dsymm``, then ``dtrsm``): ``m³/3`` flops for ``dpotrf``
        (one call: the ``W`` solve and the ``Wᵀ W`` update (a ``syrk``) inside it),
        ``2 f³/3 + 2 l f² + l² f`` after it: the blocks of
        :func:`fegear.linalg.schur.inverse_columns` without its separate ``f × f``
        factorisation, with half of its ``Wᵀ W`` product, all in MKL (measured on the seed face
        gear's pinion, ``m = 6591``, ``f = 2537``: 3.3 CPU s against 4.6 s for the same blocks
        from SciPy's OpenBLAS and separate copies).

        Parameters
        ----------
        S
            ``(m, m)`` SPD, both triangles filled (only the lower one of the reordered copy is
            read), not modified.
        columns
            ``(m,)`` bool, the columns ``f`` wanted; at least one, and at least one other.

        Returns
        -------
        numpy.ndarray
            ``(m, f)`` C-contiguous: ``(S⁻¹)[:, columns]``, rows in the order of ``S``.

        Raises
        ------
        SolverError
            ``S`` is not numerically positive definite, or LAPACK reports an error.
        """
        cols = np.asarray(columns, dtype=bool)
        f_, l_ = np.flatnonzero(cols), np.flatnonzero(~cols)
        m, f, l = S.shape[0], f_.size, l_.size
        order = np.concatenate([l_, f_])
        # The C array A read column-major is Aᵀ = A: LAPACK's lower triangle of it is the
        # row-major upper one; every block below is addressed in that column-major layout.
        A = np.ascontiguousarray(S[np.ix_(order, order)], dtype=np.float64)
        self._lapacke_spd("LAPACKE_dpotrf", b"L", A)
        base, item = A.ctypes.data, A.itemsize
        trailing = base + (l + l * m) * item  # L_ff, then G_ff (column-major lower)
        self._lapacke_spd("LAPACKE_dpotri", b"L", A, n=f, ptr=trailing, lda=m)
        # Yᵀ = G_ff Wᵀ (f × l, column-major), Wᵀ at rows l.., columns ..l of the factor;
        # a C array (l, f) is that column-major f × l array: Y = W G_ff itself
        Y = np.empty((l, f))
        self._blas("cblas_dsymm")(
            _COL_MAJOR, _LEFT, _LOWER, f, l, 1.0, trailing, m, base + l * item, m, 0.0,
            Y.ctypes.data, f,
        )  # fmt: skip
        # G_lfᵀ = −Yᵀ L_ll⁻¹ (in place): G_lf = −L_ll⁻ᵀ Y
        self._blas("cblas_dtrsm")(
            _COL_MAJOR, _RIGHT, _LOWER, _NO_TRANS, _NON_UNIT, f, l, -1.0, base, m,
            Y.ctypes.data, f,
        )  # fmt: skip
        G = np.empty((m, f))
        G_ff = A[l:, l:]  # row-major upper triangle = LAPACK's lower: mirror it
        G[f_] = np.triu(G_ff) + np.triu(G_ff, 1).T
        del A
        G[l_] = Y
        return G

    def _blas(self, name: str):
        """The CBLAS routine ``name`` of MKL (``cblas_dsymm`` or ``cblas_dtrsm``), typed."""
        fn = getattr(self.lib, name)
        fn.restype = None
        i, d, p = ctypes.c_int, ctypes.c_double, ctypes.c_void_p
        if name == "cblas_dsymm":  # layout, side, uplo, m, n, alpha, a, lda, b, ldb, beta, c, ldc
            fn.argtypes = [i, i, i, i, i, d, p, i, p, i, d, p, i]
        else:  # dtrsm: layout, side, uplo, trans, diag, m, n, alpha, a, lda, b, ldb
            fn.argtypes = [i, i, i, i, i, i, i, d, p, i, p, i]
        return fn

    def schur_spd(
        self, upper: sp.csr_matrix, schur_rows: np.ndarray, n_threads: int | None
    ) -> np.ndarray:
        """Dense Schur complement of an SPD matrix onto the rows flagged in ``schur_rows``.

        Parameters
        ----------
        upper
            Upper triangle (diagonal included) of the SPD matrix ``K``, CSR, shape ``(n, n)``,
            float64, sorted column indices.
        schur_rows
            Sorted, unique row indices ``c`` of the Schur block, shape ``(m,)``, ``0 < m < n``.
        n_threads
            MKL threads for this call; ``None`` keeps MKL's setting (``MKL_NUM_THREADS``).

        Returns
        -------
        numpy.ndarray
            ``S = K_cc − K_ci K_ii⁻¹ K_ic``, shape ``(m, m)``, rows and columns in the order of
            ``schur_rows`` (increasing index), exactly as PARDISO returns it (not symmetrised).

        Raises
        ------
        SolverError
            PARDISO reported an error (message gives the code and its meaning).
        """
        n = upper.shape[0]
        m = schur_rows.size
        _check_lp64(n, upper.nnz)
        data = np.ascontiguousarray(upper.data, dtype=np.float64)
        indptr = np.ascontiguousarray(upper.indptr, dtype=np.int32)
        indices = np.ascontiguousarray(upper.indices, dtype=np.int32)
        perm = np.zeros(n, dtype=np.int32)
        perm[schur_rows] = 1
        pt = np.zeros(64, dtype=np.int64)  # opaque handle, 64 pointer-sized slots
        iparm = np.zeros(64, dtype=np.int32)
        self._pardisoinit(
            pt.ctypes.data, ctypes.byref(ctypes.c_int32(_MTYPE_SPD)), iparm.ctypes.data
        )
        iparm[26] = 0  # matrix checker off: CSR built here, sorted and zero-based
        iparm[34] = 1  # zero-based ia / ja
        iparm[35] = 1  # Schur mode: compute the dense Schur complement only, returned in x
        x = np.zeros(m * m, dtype=np.float64)

        with self._lock:  # one PARDISO call at a time: the thread setting is per calling thread
            previous = self._set_threads_local(int(n_threads)) if n_threads else None
            try:
                t0 = time.perf_counter()
                err = self._call(
                    pt, _PHASE_ANALYSIS_FACTOR, n, data, indptr, indices, perm, iparm, x
                )
                elapsed = time.perf_counter() - t0
            finally:
                rel = self._call(
                    pt, _PHASE_RELEASE_ALL, n, data, indptr, indices, perm, iparm, np.zeros(1)
                )
                if previous is not None:
                    self._set_threads_local(previous)
        if err != 0:
            raise SolverError(f"PARDISO phase 12 (Schur mode) failed: {_explain(err, iparm)}")
        if rel != 0:
            logger.warning("PARDISO memory release (phase -1) returned error %d", rel)
        logger.debug("PARDISO Schur: n=%d m=%d in %.2f s, nnz(L)=%d", n, m, elapsed, int(iparm[17]))
        return x.reshape(m, m)

    def factor_spd(self, upper: sp.csr_matrix, n_threads: int | None) -> PardisoFactor:
        """Sparse Cholesky factorization ``K = L Lᵀ`` (phase 12, ``mtype = 2``), kept for solves.

        Parameters
        ----------
        upper
            Upper triangle (diagonal included) of the SPD matrix ``K``, CSR, shape ``(n, n)``,
            float64, sorted column indices.
        n_threads
            MKL threads for the factorization and the later solves; ``None`` keeps MKL's
            setting (``MKL_NUM_THREADS``).

        Returns
        -------
        PardisoFactor
            The factor; its PARDISO memory is released (phase -1) when it is garbage-collected.

        Raises
        ------
        SolverError
            PARDISO reported an error (the message gives the code and its meaning), e.g. -4 for
            a matrix that is not positive definite.
        """
        n = upper.shape[0]
        _check_lp64(n, upper.nnz)
        data = np.ascontiguousarray(upper.data, dtype=np.float64)
        indptr = np.ascontiguousarray(upper.indptr, dtype=np.int32)
        indices = np.ascontiguousarray(upper.indices, dtype=np.int32)
        perm = np.zeros(n, dtype=np.int32)  # not read: iparm[4] = 0, iparm[35] = 0
        pt = np.zeros(64, dtype=np.int64)
        iparm = np.zeros(64, dtype=np.int32)
        self._pardisoinit(
            pt.ctypes.data, ctypes.byref(ctypes.c_int32(_MTYPE_SPD)), iparm.ctypes.data
        )
        iparm[26] = 0  # matrix checker off: CSR built here, sorted and zero-based
        iparm[34] = 1  # zero-based ia / ja
        iparm[5] = 0  # solution in x, b unchanged
        arrays = (data, indptr, indices, perm)
        with self._lock, self._threads(n_threads):
            t0 = time.perf_counter()
            err = self._call(pt, _PHASE_ANALYSIS_FACTOR, n, *arrays, iparm, np.zeros(1))
            elapsed = time.perf_counter() - t0
            if err != 0:
                self._release(pt, n, arrays, iparm)
        if err != 0:
            raise SolverError(
                f"PARDISO phase 12 (Cholesky factorization) failed: {_explain(err, iparm)}"
            )
        logger.debug(
            "PARDISO Cholesky: n=%d nnz(upper)=%d in %.2f s, nnz(L)=%d",
            n,
            upper.nnz,
            elapsed,
            int(iparm[17]),
        )
        return PardisoFactor(self, n, pt, iparm, arrays, n_threads)

    @contextlib.contextmanager
    def _threads(self, n_threads: int | None) -> Iterator[None]:
        """MKL threads of the calling thread set to ``n_threads`` inside the block (``None``:
        MKL's setting), restored afterwards."""
        previous = self._set_threads_local(int(n_threads)) if n_threads else None
        try:
            yield
        finally:
            if previous is not None:
                self._set_threads_local(previous)

    def _release(self, pt: np.ndarray, n: int, arrays: tuple[np.ndarray, ...], iparm) -> None:
        """Phase -1: free all PARDISO memory of the handle ``pt`` (caller holds the lock)."""
        rel = self._call(pt, _PHASE_RELEASE_ALL, n, *arrays, iparm, np.zeros(1))
        if rel != 0:
            logger.warning("PARDISO memory release (phase -1) returned error %d", rel)


class PardisoFactor:
    """A PARDISO Cholesky factor (the handle ``pt`` of :meth:`MklPardiso.factor_spd`).

    Holds the matrix arrays PARDISO was given (phase 33 reads them again) and releases the
    solver memory (phase -1) once, when garbage-collected or on :meth:`release`.

    Solves of *different* factors may run at the same time in different threads (ctypes
    releases the GIL; each factor has its own handle ``pt``, and the MKL thread count is set
    per calling thread): the two members of a gear pair solve together, one MKL thread each,
    in about the wall time of one two-thread solve and half its CPU (phase 33 is memory bound:
    a second thread gains 10 % on the seed face-gear sectors, 13–17 M entries in ``L``).
    One factor's own solves and its release are serialised by its lock.
    """

    def __init__(
        self,
        lib: MklPardiso,
        n: int,
        pt: np.ndarray,
        iparm: np.ndarray,
        arrays: tuple[np.ndarray, ...],
        n_threads: int | None,
    ) -> None:
        self.n = n
        self._lib = lib
        self._pt = pt
        self._iparm = iparm
        self._arrays = arrays
        self._n_threads = n_threads
        self._lock = threading.Lock()
        self._finalizer = weakref.finalize(
            self, _release_locked, lib, self._lock, pt, n, arrays, iparm
        )

    def solve(self, B: np.ndarray, n_threads: int | None = None) -> np.ndarray:
        """Phase 33 on ``B`` of shape ``(n, k)``: returns ``X`` with ``K X = B``, shape ``(n, k)``.
        ``n_threads``: MKL threads of this solve (None: those of the factorization).

        Raises
        ------
        SolverError
            PARDISO reported an error, or the factor was released.
        """
        if not self._finalizer.alive:
            raise SolverError("PARDISO factor used after its memory was released")
        n, k = B.shape
        b = np.asfortranarray(B, dtype=np.float64)  # read only (iparm[5] = 0)
        x = np.zeros((n, k), dtype=np.float64, order="F")
        iparm = self._iparm.copy()  # phase 33 writes outputs (iparm[6]); keep the factor's own
        threads = self._n_threads if n_threads is None else n_threads
        with self._lock, self._lib._threads(threads):
            if not self._finalizer.alive:
                raise SolverError("PARDISO factor used after its memory was released")
            err = self._lib._call(self._pt, _PHASE_SOLVE, n, *self._arrays, iparm, x, b=b, nrhs=k)
        if err != 0:
            raise SolverError(f"PARDISO phase 33 (solve) failed: {_explain(err, iparm)}")
        return x

    def release(self) -> None:
        """Free PARDISO's memory now (phase -1); later solves raise :class:`SolverError`."""
        self._finalizer()


def _release_locked(
    lib: MklPardiso,
    lock: threading.Lock,
    pt: np.ndarray,
    n: int,
    arrays: tuple[np.ndarray, ...],
    iparm: np.ndarray,
) -> None:
    with lock:
        lib._release(pt, n, arrays, iparm)


def _explain(err: int, iparm: np.ndarray) -> str:
    """``"error -4, zero or negative pivot ..."``: PARDISO's code, its meaning, the bad pivot."""
    meaning = PARDISO_ERRORS.get(err, "unknown error code")
    detail = ""
    if err == -4 and iparm[29] > 0:
        detail = f"; first bad pivot at equation {int(iparm[29])}"
    return f"error {err}, {meaning}{detail}"


def _check_lp64(n: int, nnz: int) -> None:
    if nnz > _INT32_MAX or n > _INT32_MAX:
        raise SolverError(f"PARDISO (LP64): matrix too large for 32-bit indices (n={n}, nnz={nnz})")


def _workspace(S: np.ndarray, overwrite: bool) -> np.ndarray:
    """``S`` itself when it may be overwritten and is a C-contiguous float64 array, else a
    C-contiguous float64 copy."""
    if overwrite and S.dtype == np.float64 and S.flags.c_contiguous and S.flags.writeable:
        return S
    return np.array(S, dtype=np.float64, order="C", copy=True)


def load_library() -> MklPardiso:
    """Locate and load ``mkl_rt`` and type its PARDISO entry points.

    The search follows pypardiso: ``FEGEAR_MKL_RT`` / ``PYPARDISO_MKL_RT`` (explicit path),
    ``ctypes.util.find_library``, then ``<sys.prefix>/lib`` (and ``Library/bin`` on Windows) and a
    recursive search under ``sys.prefix`` and the user site.

    Returns
    -------
    MklPardiso
        The loaded library.

    Raises
    ------
    BackendUnavailable
        No loadable ``mkl_rt`` with PARDISO, or it is locked to the ILP64 interface.
    """
    errors: list[str] = []
    for path in _candidate_paths():
        try:
            lib = ctypes.CDLL(path)
        except OSError as exc:
            errors.append(f"{path}: {exc}")
            continue
        try:
            lib.pardiso  # noqa: B018 - attribute lookup is the existence check
            lib.pardisoinit  # noqa: B018
            lib.MKL_Set_Num_Threads_Local  # noqa: B018
        except AttributeError as exc:
            errors.append(f"{path}: {exc}")
            continue
        layer = lib.MKL_Set_Interface_Layer(ctypes.c_int(_MKL_INTERFACE_LP64))
        if layer != _MKL_INTERFACE_LP64:
            raise BackendUnavailable(
                f"{path} is locked to the ILP64 interface (layer {layer}); need LP64"
            )
        return MklPardiso(lib, path)
    reason = "mkl_rt shared library not found (pip install mkl, or set FEGEAR_MKL_RT)"
    if errors:
        reason += "; tried: " + "; ".join(errors)
    raise BackendUnavailable(reason)
