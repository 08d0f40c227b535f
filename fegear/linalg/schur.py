r"""Schur complements and inverse blocks of sparse SPD stiffness matrices.

The compliance operator of a finite-element body is :math:`C = P^T K^{-1} P`, where :math:`K`
(shape ``(n, n)``, sparse, symmetric positive definite once the Dirichlet DOFs are eliminated) is
the stiffness matrix and :math:`P` touches only a set :math:`c` of ``m`` "candidate" DOFs. So the
operator needs only the dense block :math:`(K^{-1})_{cc}`.

Order the DOFs as interior :math:`i` (all the others) and candidates :math:`c`:

.. math::

    K = \begin{pmatrix} K_{ii} & K_{ic} \\ K_{ci} & K_{cc} \end{pmatrix}, \qquad
    S = K/K_{ii} = K_{cc} - K_{ci} K_{ii}^{-1} K_{ic} .

By the block (Banachiewicz) inversion formula,

.. math::

    K^{-1} = \begin{pmatrix}
        K_{ii}^{-1} + K_{ii}^{-1} K_{ic} S^{-1} K_{ci} K_{ii}^{-1} & -K_{ii}^{-1} K_{ic} S^{-1} \\
        -S^{-1} K_{ci} K_{ii}^{-1} & S^{-1}
    \end{pmatrix}
    \quad\Longrightarrow\quad (K^{-1})_{cc} = S^{-1},

and :math:`K \succ 0` implies :math:`K_{ii} \succ 0` and :math:`S \succ 0` (see F. Zhang (ed.),
*The Schur Complement and Its Applications*, Springer 2005, ch. 1; G. H. Golub and C. F. Van Loan,
*Matrix Computations*, 4th ed., 2013, §3.2 and §4.2). Physically :math:`S` is the condensed
(static, Guyan) stiffness of the body seen from the candidate DOFs, and :math:`S^{-1}` its
flexibility.

Backends
--------
``"pardiso"``
    Intel oneMKL PARDISO in Schur mode (``iparm[35] = 1``): one sparse Cholesky factorization that
    stops at the candidate block and returns :math:`S` dense. Measured 3–7× faster than ``m``
    back-solves (``docs/ltca/contact_formulation.md``). Needs the ``mkl`` wheel (not on macOS
    arm64). See
    :mod:`fegear.linalg._mkl_pardiso` for the ``iparm`` settings.
``"superlu"``
    SciPy SuperLU, the portable fallback: factor :math:`K_{ii}` (symmetric mode, minimum degree on
    :math:`K^T + K`, diagonal pivots) and form :math:`S = K_{cc} - K_{ci} (K_{ii}^{-1} K_{ic})` with
    ``m`` solves, in column blocks to bound memory. Factoring :math:`K_{ii}` rather than :math:`K`
    costs the same ``m`` solves but yields :math:`S` directly: the alternative (solving
    :math:`K x = e_j` for the candidate unit vectors) yields :math:`(K^{-1})_{cc}` and would need a
    dense inversion to get :math:`S` and another to come back in :func:`inverse_block`.
``"auto"``
    ``FEGEAR_SOLVER`` if that environment variable is set (``auto|pardiso|superlu``), else
    ``"pardiso"`` when the MKL library loads and passes a tiny self-check, else ``"superlu"``
    (logged at INFO, with the reason PARDISO is unavailable).
"""

from __future__ import annotations

import logging
import os
import threading
import time
import weakref

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fegear.errors import BackendUnavailable, InputError, SolverError
from fegear.linalg import _mkl_pardiso

__all__ = [
    "BACKENDS",
    "ENV_SOLVER",
    "available_backends",
    "check_spd_matrix",
    "requested_backend",
    "resolve_backend",
    "schur_complement",
    "inverse_block",
    "inverse_columns",
    "inverse_off_block",
]

logger = logging.getLogger(__name__)

#: Concrete backends, in order of preference.
BACKENDS: tuple[str, ...] = ("pardiso", "superlu")
#: Environment variable that overrides ``backend="auto"``.
ENV_SOLVER = "FEGEAR_SOLVER"
#: MKL threads used when ``MKL_NUM_THREADS`` is not set (the reference machine has 2 cores).
DEFAULT_MKL_THREADS = 2
#: Largest dense right-hand-side block of the SuperLU path, in bytes.
_SUPERLU_BLOCK_BYTES = 256 * 2**20
#: Relative asymmetry ``max|K - Kᵀ| / max|K|`` above which K is rejected: assembled FE matrices are
#: symmetric to round-off (~1e-16); PARDISO reads only the upper triangle, so a truly asymmetric K
#: would silently give a different answer than SuperLU.
_SYMMETRY_RTOL = 1e-10

_CHOICES = ("auto", *BACKENDS)
_probe_lock = threading.Lock()
_pardiso_state: tuple[_mkl_pardiso.MklPardiso | None, str] | None = None


def _self_check(lib: _mkl_pardiso.MklPardiso) -> None:
    """Schur complement of a 6×6 SPD tridiagonal matrix against the dense formula, and a
    Cholesky factor + solve against the dense solve."""
    n = 6
    K = sp.diags([-np.ones(n - 1), 4.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    c = np.array([1, 4])
    i = np.setdiff1d(np.arange(n), c)
    Kd = K.toarray()
    expected = Kd[np.ix_(c, c)] - Kd[np.ix_(c, i)] @ np.linalg.solve(
        Kd[np.ix_(i, i)], Kd[np.ix_(i, c)]
    )
    upper = sp.triu(K, format="csr")
    got = lib.schur_spd(upper, c, n_threads=1)
    # Well-conditioned 6×6 matrix with O(1) entries: the two agree to round-off (~1e-16).
    if not np.allclose(got, expected, rtol=1e-12, atol=1e-12):
        raise SolverError(
            f"PARDISO self-check failed: got {got.tolist()}, want {expected.tolist()}"
        )
    # The plain Cholesky factor and solve (fegear.linalg.solve), two right-hand sides.
    B = np.stack([np.arange(1.0, n + 1.0), np.ones(n)], axis=1)
    x = lib.factor_spd(upper, n_threads=1).solve(B)
    if not np.allclose(x, np.linalg.solve(Kd, B), rtol=1e-12, atol=1e-12):
        raise SolverError(f"PARDISO self-check failed: solve gave {x.tolist()}")


def _pardiso() -> tuple[_mkl_pardiso.MklPardiso | None, str]:
    """Load MKL PARDISO once per process and self-check it: ``(library or None, reason)``."""
    global _pardiso_state
    with _probe_lock:
        if _pardiso_state is None:
            try:
                lib = _mkl_pardiso.load_library()
                _self_check(lib)
            except (BackendUnavailable, SolverError, OSError, AttributeError) as exc:
                _pardiso_state = (None, str(exc))
            else:
                _pardiso_state = (lib, lib.path)
        return _pardiso_state


def _clear_backend_cache() -> None:
    """Forget the PARDISO probe result, so the next call probes again (for tests)."""
    global _pardiso_state
    with _probe_lock:
        _pardiso_state = None


def available_backends() -> tuple[str, ...]:
    """Backends usable on this machine, in order of preference.

    Returns
    -------
    tuple of str
        ``("pardiso", "superlu")`` where MKL PARDISO loads and passes its self-check, else
        ``("superlu",)``.
    """
    lib, _ = _pardiso()
    return BACKENDS if lib is not None else ("superlu",)


def _check_name(field: str, name: object) -> str:
    if not isinstance(name, str) or name.strip().lower() not in _CHOICES:
        raise InputError(field, name, "one of " + ", ".join(repr(c) for c in _CHOICES))
    return name.strip().lower()


def requested_backend(name: str = "auto") -> str:
    """The backend asked for: ``name`` or, for ``"auto"``, ``FEGEAR_SOLVER`` if set; validated
    (:class:`InputError` for an unknown name) without loading any library. Returns ``"auto"``,
    ``"pardiso"`` or ``"superlu"``."""
    choice = _check_name("backend", name)
    if choice == "auto":
        env = os.environ.get(ENV_SOLVER, "").strip()
        if env:
            choice = _check_name(ENV_SOLVER, env)
            if choice != "auto":
                logger.info("Sparse direct solver: %s (from %s)", choice, ENV_SOLVER)
    return choice


def resolve_backend(name: str = "auto") -> str:
    """Turn a backend request into the concrete backend to use.

    Parameters
    ----------
    name
        ``"auto"``, ``"pardiso"`` or ``"superlu"`` (case-insensitive). ``"auto"`` defers to the
        ``FEGEAR_SOLVER`` environment variable when it is set and not empty.

    Returns
    -------
    str
        ``"pardiso"`` or ``"superlu"``.

    Raises
    ------
    InputError
        Unknown name (in the argument or in ``FEGEAR_SOLVER``).
    BackendUnavailable
        ``"pardiso"`` was asked for explicitly (argument or environment) but MKL PARDISO cannot be
        loaded or fails its self-check.
    """
    choice = requested_backend(name)
    if choice == "superlu":
        return "superlu"
    lib, reason = _pardiso()
    if choice == "pardiso":
        if lib is None:
            raise BackendUnavailable(f"PARDISO was requested but is not available ({reason})")
        return "pardiso"
    if lib is None:
        logger.info("PARDISO not available (%s); using SciPy SuperLU", reason)
        return "superlu"
    logger.info("Sparse direct solver: MKL PARDISO (%s)", reason)
    return "pardiso"


def _check_inputs(K: object, idx: object) -> tuple[sp.csr_matrix, np.ndarray]:
    """Validate ``K`` (sparse, square, real, symmetric) and ``idx`` (unique, in range)."""
    n = _check_shape(K)
    arr = _check_idx(idx, n)
    known = _LAST_K.get("K")
    if known is not None and known[0]() is K and known[1] == K.nnz:
        return known[2], arr  # validated by the previous call (a body's K: one per operator)
    Kc = check_spd_matrix(K)
    try:
        _LAST_K["K"] = (weakref.ref(K, _forget_k), K.nnz, Kc)
        _LAST_K.pop("upper", None)
    except TypeError:  # an object without weak references: checked every time
        _LAST_K.clear()
    return Kc, arr


def _check_shape(K: object) -> int:
    """``n`` of a sparse, square, non-empty, real ``K`` (:class:`InputError` otherwise)."""
    if not sp.issparse(K):
        raise InputError("K", type(K).__name__, "a scipy.sparse matrix")
    if K.ndim != 2 or K.shape[0] != K.shape[1] or K.shape[0] == 0:
        raise InputError("K.shape", K.shape, "square and non-empty, (n, n)")
    if np.iscomplexobj(K.data) or not (
        np.issubdtype(K.dtype, np.floating) or np.issubdtype(K.dtype, np.integer)
    ):
        raise InputError("K.dtype", str(K.dtype), "real")
    return K.shape[0]


def check_spd_matrix(K: object) -> sp.csr_matrix:
    """``K`` as canonical CSR float64 (a copy where conversion is needed; the caller's matrix is
    never modified), checked: sparse, square, non-empty, real, finite, positive diagonal (every
    diagonal entry stored, as PARDISO needs), symmetric to ``_SYMMETRY_RTOL``.

    Positive definiteness itself is left to the factorization (PARDISO error -4, a SuperLU zero
    pivot).

    Raises
    ------
    InputError
        Any of the checks fails; the message names it.
    """
    _check_shape(K)
    Kc = sp.csr_matrix(K, dtype=np.float64)
    if not Kc.has_canonical_format:  # copy first: never modify the caller's matrix in place
        Kc = Kc.copy()
        Kc.sum_duplicates()  # also sorts the column indices
    if not np.all(np.isfinite(Kc.data)):
        raise InputError("K", "non-finite entries", "finite")
    diag = Kc.diagonal()
    bad = np.flatnonzero(~(diag > 0.0))
    if bad.size:
        # SPD needs a positive diagonal; PARDISO also needs every diagonal entry stored.
        raise InputError(
            "K",
            f"diagonal entry K[{int(bad[0])}, {int(bad[0])}] = {diag[bad[0]]:.3g} "
            f"({bad.size} such)",
            "positive definite (positive diagonal; all rigid-body modes constrained)",
        )
    scale = float(np.abs(Kc.data).max()) if Kc.nnz else 0.0
    asym = abs(Kc - Kc.T)
    asym_max = float(asym.data.max()) if asym.nnz else 0.0
    if asym_max > _SYMMETRY_RTOL * scale:
        raise InputError("K", f"max|K - Kᵀ| = {asym_max:.3g} (max|K| = {scale:.3g})", "symmetric")
    return Kc


#: The last matrix :func:`_check_inputs` validated (``"K"``: a weak reference to the caller's
#: matrix, its stored-entry count, the validated CSR) and, once PARDISO has used it, its sorted
#: upper triangle (``"upper"``): an operator in groups takes several Schur complements of one
#: body's ``K`` (the checks and the triangle cost ~0.15 s each on 40 000 DOFs). The caller's
#: matrices are not modified between calls (fegear's never are).
_LAST_K: dict[str, object] = {}


def _forget_k(ref: weakref.ref) -> None:
    """Drop the validated copy and triangle with the caller's matrix (if it is still the last)."""
    known = _LAST_K.get("K")
    if known is not None and known[0] is ref:
        _LAST_K.clear()


def _check_idx(idx: object, n: int) -> np.ndarray:
    """``idx`` as int64, checked: 1-D, unique, in ``[0, n)``."""
    arr = np.asarray(idx)
    if arr.ndim != 1 or not (np.issubdtype(arr.dtype, np.integer) or arr.size == 0):
        raise InputError("idx", f"array of shape {arr.shape}, dtype {arr.dtype}", "1-D integer")
    arr = arr.astype(np.int64)
    if arr.size:
        lo, hi = int(arr.min()), int(arr.max())
        if lo < 0 or hi >= n:
            raise InputError("idx", f"values in [{lo}, {hi}]", f"DOF indices in [0, {n - 1}]")
        uniq, counts = np.unique(arr, return_counts=True)
        if uniq.size != arr.size:
            dup = uniq[counts > 1]
            raise InputError(
                "idx", f"{dup.size} repeated indices (first {int(dup[0])})", "unique DOF indices"
            )
    return arr


def _mkl_threads(n_threads: int | None) -> int | None:
    """Threads for PARDISO: the argument, else ``None`` (MKL reads MKL_NUM_THREADS), else 2."""
    if n_threads is not None:
        if int(n_threads) < 1:
            raise InputError("n_threads", n_threads, ">= 1")
        return int(n_threads)
    if os.environ.get("MKL_NUM_THREADS", "").strip():
        return None
    return DEFAULT_MKL_THREADS


def _schur_pardiso(K: sp.csr_matrix, c: np.ndarray, n_threads: int | None) -> np.ndarray:
    lib, reason = _pardiso()
    if lib is None:  # resolve_backend has checked; kept for direct callers
        raise BackendUnavailable(f"PARDISO is not available ({reason})")
    known = _LAST_K.get("K")
    upper = _LAST_K.get("upper") if known is not None and known[2] is K else None
    if upper is None:
        upper = sp.triu(K, format="csr")
        upper.sort_indices()
        if known is not None and known[2] is K:
            _LAST_K["upper"] = upper
    return lib.schur_spd(upper, c, _mkl_threads(n_threads))


def _schur_superlu(K: sp.csr_matrix, c: np.ndarray) -> np.ndarray:
    n = K.shape[0]
    m = c.size
    interior = np.ones(n, dtype=bool)
    interior[c] = False
    i = np.flatnonzero(interior)
    K_i = K[i]
    K_ii = K_i[:, i].tocsc()
    K_ic = K_i[:, c].tocsc()
    K_ci = K_ic.T.tocsr()
    S = K[c][:, c].toarray()
    try:
        # SPD: symmetric mode + minimum degree on Kᵀ+K + diagonal pivots is sparse Cholesky-like
        # (much less fill than the default COLAMD with partial pivoting).
        lu = spla.splu(
            K_ii,
            permc_spec="MMD_AT_PLUS_A",
            diag_pivot_thresh=0.0,
            options={"SymmetricMode": True},
        )
    except RuntimeError as exc:
        raise SolverError(f"SuperLU factorization of K_ii failed: {exc}") from exc
    block = int(max(1, min(m, _SUPERLU_BLOCK_BYTES // (8 * max(i.size, 1)))))
    for j0 in range(0, m, block):
        j1 = min(m, j0 + block)
        X = lu.solve(K_ic[:, j0:j1].toarray())
        S[:, j0:j1] -= K_ci @ X
    return S


def schur_complement(
    K: sp.spmatrix | sp.sparray,
    idx: np.ndarray,
    backend: str = "auto",
    *,
    n_threads: int | None = None,
) -> np.ndarray:
    r"""Dense Schur complement of a sparse SPD matrix onto the DOFs ``idx``.

    .. math::

        S = K_{cc} - K_{ci} K_{ii}^{-1} K_{ic}, \qquad c = \mathrm{idx},\;
        i = \{0, \dots, n-1\} \setminus c,

    the condensed stiffness seen from the DOFs ``c``; :math:`(K^{-1})_{cc} = S^{-1}`
    (see the module docstring).

    Parameters
    ----------
    K
        Stiffness matrix, sparse, shape ``(n, n)``, symmetric positive definite (Dirichlet DOFs
        eliminated). Only real values; converted to CSR float64.
    idx
        DOF indices ``c``, shape ``(m,)``, unique, in ``[0, n)``, in any order.
    backend
        ``"auto"``, ``"pardiso"`` or ``"superlu"``; see :func:`resolve_backend`.
    n_threads
        MKL threads for PARDISO. Default: ``MKL_NUM_THREADS`` when set, else 2. SuperLU is serial.

    Returns
    -------
    numpy.ndarray
        ``S``, shape ``(m, m)``, symmetric; ``S[a, b]`` belongs to DOFs ``idx[a]``, ``idx[b]``
        (the order given, whatever order the backend works in).

    Raises
    ------
    InputError
        ``K`` not sparse/square/real/symmetric, or ``idx`` not unique integers in range, or an
        unknown backend name.
    BackendUnavailable
        PARDISO asked for explicitly but not available.
    SolverError
        The factorization failed (e.g. ``K`` singular or not positive definite).
    """
    Kc, c = _check_inputs(K, idx)
    n, m = Kc.shape[0], c.size
    name = resolve_backend(backend)
    if m == 0:
        return np.zeros((0, 0))
    t0 = time.perf_counter()
    order = np.argsort(c, kind="stable")
    c_sorted = c[order]
    if m == n:  # no interior DOFs: S = K itself
        S_sorted = Kc[c_sorted][:, c_sorted].toarray()
    elif name == "pardiso":
        S_sorted = _schur_pardiso(Kc, c_sorted, n_threads)
    else:
        S_sorted = _schur_superlu(Kc, c_sorted)
    # Back from increasing-index order (PARDISO's output order) to the caller's order (no copy
    # when the caller's order is increasing already: the compliance operators' is).
    if np.any(order != np.arange(m)):
        rank = np.empty(m, dtype=np.intp)
        rank[order] = np.arange(m)
        S_sorted = S_sorted[np.ix_(rank, rank)]
    S = _symmetrize(S_sorted)
    if not _all_finite(S):
        raise SolverError(f"{name}: Schur complement has non-finite entries (K singular?)")
    logger.info(
        "Schur complement with %s: n=%d DOFs onto m=%d in %.2f s",
        name,
        n,
        m,
        time.perf_counter() - t0,
    )
    return S


#: Rows per block of the in-place dense passes (a 2048 x 2048 float64 block is 32 MiB).
_BLOCK_ROWS = 2048


def _symmetrize(S: np.ndarray) -> np.ndarray:
    """``S ← (S + Sᵀ) / 2`` in place, a block pair at a time (no ``m × m`` temporaries): every
    entry is ``0.5 * (S_ij + S_ji)``, bit for bit what ``0.5 * (S + S.T)`` gives. Returns ``S``.

    A block pair that is already exactly symmetric is left as it is (``0.5 * (a + a) = a`` in
    floating point, barring overflow; a pair of opposite zeros keeps its signs): PARDISO fills
    both triangles of its Schur complement with the same values (observed with MKL 2026.2), so
    the pass only reads them."""
    m = S.shape[0]
    for i0 in range(0, m, _BLOCK_ROWS):
        i1 = min(i0 + _BLOCK_ROWS, m)
        d = S[i0:i1, i0:i1]
        if not np.array_equal(d, d.T):
            d[...] = 0.5 * (d + d.T)
        for j0 in range(i1, m, _BLOCK_ROWS):
            j1 = min(j0 + _BLOCK_ROWS, m)
            upper, lower = S[i0:i1, j0:j1], S[j0:j1, i0:i1]
            if np.array_equal(upper, lower.T):
                continue
            avg = 0.5 * (upper + lower.T)
            S[i0:i1, j0:j1] = avg
            S[j0:j1, i0:i1] = avg.T
    return S


def _all_finite(S: np.ndarray) -> bool:
    """Every entry of ``S`` is finite (checked a block of rows at a time)."""
    return all(
        bool(np.isfinite(S[i0 : i0 + _BLOCK_ROWS]).all())
        for i0 in range(0, S.shape[0], _BLOCK_ROWS)
    )


#: Smallest dense Cholesky / inverse given to MKL when it is at hand (SciPy's OpenBLAS below).
#: Measured on a 2-core AVX-512 EPYC, MKL 2026.2 vs SciPy 1.17's OpenBLAS, the same load on
#: both: Cholesky n = 1000 / 5802 / 9000: 0.05 / 2.2 / 7.0 s vs 0.52 / 8.8 / 12.1 s; inverse
#: (potrf + potri) n = 3000 / 5802: 1.4 / 6.7 s vs 8.1 / 22.2 s. (OpenBLAS was the faster one
#: at n = 3000 on an AVX2 host, 0.35 vs 0.70 s; it also crashed on multi-threaded potrf at
#: 16 384.) Every size that matters here goes to MKL.
_MKL_DENSE_MIN = 500


def inverse_block(
    K: sp.spmatrix | sp.sparray,
    idx: np.ndarray,
    backend: str = "auto",
    *,
    n_threads: int | None = None,
) -> np.ndarray:
    r"""Dense block :math:`(K^{-1})_{cc}` of the inverse of a sparse SPD matrix, ``c = idx``.

    Computed as :math:`S^{-1}` with :math:`S` from :func:`schur_complement`, through a dense
    Cholesky factorization :math:`S = U^T U` (``scipy.linalg.cho_factor``) and the LAPACK
    ``potri`` inverse from that factor (:math:`S^{-1} = U^{-1} U^{-T}`, about a third of the flops
    of ``cho_solve`` against the identity), then symmetrised exactly from its upper triangle.

    Parameters
    ----------
    K
        Stiffness matrix, sparse, shape ``(n, n)``, symmetric positive definite.
    idx
        DOF indices ``c``, shape ``(m,)``, unique, in ``[0, n)``, in any order.
    backend
        ``"auto"``, ``"pardiso"`` or ``"superlu"``; see :func:`resolve_backend`.
    n_threads
        MKL threads for PARDISO (see :func:`schur_complement`).

    Returns
    -------
    numpy.ndarray
        ``(K⁻¹)[idx][:, idx]``, shape ``(m, m)``, symmetric positive definite: entry ``[a, b]`` is
        the displacement of DOF ``idx[a]`` under a unit force on DOF ``idx[b]``.

    Raises
    ------
    InputError, BackendUnavailable
        As :func:`schur_complement`.
    SolverError
        The factorization failed, or ``S`` is not numerically positive definite.
    """
    S = schur_complement(K, idx, backend, n_threads=n_threads)
    if S.size == 0:
        return S
    return _spd_inverse(S)


def inverse_columns(
    K: sp.spmatrix | sp.sparray,
    idx: np.ndarray,
    columns: np.ndarray,
    backend: str = "auto",
    *,
    n_threads: int | None = None,
) -> np.ndarray:
    r"""The columns ``columns`` of the block :math:`(K^{-1})_{cc}`, ``c = idx``: the displacement
    of every DOF of ``c`` under a unit force on each DOF of ``f = c[columns]``.

    Where only the forces on a subset ``f`` of ``c`` are ever applied (the contact cells load the
    flank; the other DOFs of ``c`` are only read, e.g. the ``hybrid`` fidelity's layer), the
    block :math:`G_{cf}` is all that is needed. With ``l = c \setminus f`` and :math:`S` the Schur
    complement onto ``c`` (:func:`schur_complement`), block elimination of :math:`S G = I`
    (Golub & Van Loan, *Matrix Computations*, 4th ed., §3.2 and §4.2) gives

    .. math::

        S_{ll} = L L^T,\quad W = L^{-1} S_{lf},\quad
        G_{ff} = ig(S_{ff} - W^T Wig)^{-1},\quad
        G_{lf} = -L^{-T} W\, G_{ff},

    about :math:`l^3/3 + 2 l^2 f + 3 l f^2 + f^3` flops, mostly matrix products, against
    :math:`m^3` for the whole inverse (:func:`inverse_block`). Measured on 2 cores (AMD EPYC,
    OpenBLAS), ``m = 9570``, ``f = 0.4 m``: 11.1 s against 18.0 s. Where MKL is at hand (and
    ``m >= _MKL_DENSE_MIN``) the same blocks come from one Cholesky factorisation of ``S``
    reordered ``[l, f]`` (:meth:`fegear.linalg._mkl_pardiso.MklPardiso.spd_inverse_columns`:
    ``m³/3 + 2 f³/3 + 2 l f² + l² f`` flops, the ``Wᵀ W`` update a ``syrk`` inside ``dpotrf``,
    no separate factorisation of the ``f × f`` block); the two agree to round-off (6e-15 of
    the largest entry on the seed face gear's sectors).

    Parameters
    ----------
    K, idx, backend, n_threads
        As :func:`inverse_block`.
    columns
        ``(m,)`` bool, the entries of ``idx`` that are columns (load DOFs).

    Returns
    -------
    numpy.ndarray
        ``(m, f)``: rows in the order of ``idx``, columns in the order of ``idx[columns]``.

    Raises
    ------
    InputError
        ``columns`` is not a boolean mask of the length of ``idx``; and as :func:`inverse_block`.
    SolverError
        As :func:`inverse_block`.
    """
    cols = np.asarray(columns)
    if cols.dtype != bool or cols.shape != np.shape(idx):
        raise InputError("columns", f"shape {cols.shape}", f"a bool mask of shape {np.shape(idx)}")
    S = schur_complement(K, idx, backend, n_threads=n_threads)
    m = S.shape[0]
    if S.size == 0:
        return np.zeros((m, int(cols.sum())))
    if cols.all():
        return _spd_inverse(S, overwrite=True)
    lib, _ = _pardiso()
    if lib is not None and m >= _MKL_DENSE_MIN and cols.any():
        # the same blocks from one factorisation of S reordered [l, f], all in MKL
        return lib.spd_inverse_columns(S, cols)
    f, l_ = np.flatnonzero(cols), np.flatnonzero(~cols)
    S_lf = S[np.ix_(l_, f)]
    S_ff = S[np.ix_(f, f)]
    S_ll = S[np.ix_(l_, l_)]
    del S
    L = _spd_cholesky(S_ll, overwrite=True)
    del S_ll
    W = la.solve_triangular(L, S_lf, lower=True, check_finite=False, overwrite_b=True)
    G_ff = _spd_inverse(S_ff - W.T @ W, overwrite=True)
    G_lf = la.solve_triangular(L, W @ G_ff, lower=True, trans="T", check_finite=False)
    G = np.empty((m, f.size))
    G[f] = G_ff
    G[l_] = -G_lf
    return G


def inverse_off_block(
    K: sp.spmatrix | sp.sparray,
    idx: np.ndarray,
    columns: np.ndarray,
    G_ff: np.ndarray,
    backend: str = "auto",
    *,
    n_threads: int | None = None,
) -> np.ndarray:
    r"""The rows off ``columns`` of the columns ``columns`` of :math:`(K^{-1})_{cc}`,
    ``c = idx``, given its square block on ``columns`` (``G_ff``, computed before, e.g. as part of
    a larger block: :func:`inverse_columns` on more load DOFs).

    With ``f = c[columns]``, ``l = c \setminus f`` and :math:`S` the Schur complement onto ``c``,
    the rows ``l`` of :math:`S G = I` in the columns ``f`` read
    :math:`S_{ll} G_{lf} + S_{lf} G_{ff} = 0`, so

    .. math::

        S_{ll} = L L^T,\quad W = L^{-1} S_{lf},\quad G_{lf} = -L^{-T} (W\, G_{ff}),

    :math:`l^3/3 + 2 l^2 f + 2 l f^2` flops: :func:`inverse_columns` without its
    :math:`f^3 + l f^2` for a :math:`G_{ff}` already known (Golub & Van Loan, *Matrix
    Computations*, 4th ed., §3.2 and §4.2).

    Parameters
    ----------
    K, idx, backend, n_threads
        As :func:`inverse_block`.
    columns
        ``(m,)`` bool, the entries of ``idx`` that are columns (load DOFs), at least one of each.
    G_ff
        ``(f, f)`` mm/N, :math:`(K^{-1})_{ff}` (rows and columns in the order of ``idx[columns]``).

    Returns
    -------
    numpy.ndarray
        ``(l, f)``: :math:`(K^{-1})_{lf}`, rows in the order of ``idx[~columns]``, columns in the
        order of ``idx[columns]``.

    Raises
    ------
    InputError
        ``columns`` is not a boolean mask of the length of ``idx`` with both values, or ``G_ff``
        has not the shape ``(f, f)``; and as :func:`inverse_block`.
    SolverError
        As :func:`inverse_block`.
    """
    cols = np.asarray(columns)
    if cols.dtype != bool or cols.shape != np.shape(idx) or cols.all() or not cols.any():
        raise InputError(
            "columns", f"shape {cols.shape}", f"a bool mask of shape {np.shape(idx)}, mixed"
        )
    f, l_ = np.flatnonzero(cols), np.flatnonzero(~cols)
    if np.shape(G_ff) != (f.size, f.size):
        raise InputError("G_ff", f"shape {np.shape(G_ff)}", f"({f.size}, {f.size})")
    S = schur_complement(K, idx, backend, n_threads=n_threads)
    S_lf = S[np.ix_(l_, f)]
    S_ll = S[np.ix_(l_, l_)]
    del S
    L = _spd_cholesky(S_ll, overwrite=True)
    del S_ll
    W = la.solve_triangular(L, S_lf, lower=True, check_finite=False, overwrite_b=True)
    Y = W @ np.asarray(G_ff)
    del W
    Y = la.solve_triangular(L, Y, lower=True, trans="T", check_finite=False, overwrite_b=True)
    np.negative(Y, out=Y)
    return Y


def _spd_cholesky(S: np.ndarray, overwrite: bool = False) -> np.ndarray:
    """Lower Cholesky factor of a dense SPD matrix (MKL where available, see
    ``_MKL_DENSE_MIN``); ``overwrite``: ``S`` may be used as the workspace."""
    lib, _ = _pardiso()
    if lib is not None and S.shape[0] >= _MKL_DENSE_MIN:
        return lib.spd_cholesky(S, overwrite=overwrite)
    try:
        return la.cholesky(S, lower=True, check_finite=False, overwrite_a=overwrite)
    except la.LinAlgError as exc:
        raise SolverError(f"Schur complement is not positive definite: {exc}") from exc


def _spd_inverse(S: np.ndarray, overwrite: bool = False) -> np.ndarray:
    """Inverse of a dense SPD matrix: LAPACK ``potrf`` + ``potri``, symmetrised exactly;
    ``overwrite``: ``S`` may be used as the workspace (MKL)."""
    lib, _ = _pardiso()
    if lib is not None and S.shape[0] >= _MKL_DENSE_MIN:  # see _MKL_DENSE_MIN
        return lib.spd_inverse(S, overwrite=overwrite)
    try:
        U, lower = la.cho_factor(S, lower=False, check_finite=False)
    except la.LinAlgError as exc:
        raise SolverError(f"Schur complement is not positive definite: {exc}") from exc
    (potri,) = la.get_lapack_funcs(("potri",), (U,))
    inv, info = potri(U, lower=lower)
    if info != 0:
        raise SolverError(f"LAPACK potri failed on the Schur complement: info = {info}")
    inv = np.triu(inv)
    return inv + np.triu(inv, 1).T
