"""Schur complement / inverse block backends (fegear.linalg).

A small scikit-fem P2 elasticity box (clamped at z = 0), candidate DOFs on the top face. PARDISO
parts are skipped where MKL is absent (macOS arm64), so the suite runs everywhere.
"""

from __future__ import annotations

import logging

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import skfem
from skfem.models.elasticity import lame_parameters, linear_elasticity

from fegear.errors import BackendUnavailable, InputError, SolverError
from fegear.linalg import (
    ENV_SOLVER,
    _mkl_pardiso,
    available_backends,
    inverse_block,
    inverse_columns,
    inverse_off_block,
    resolve_backend,
    schur,
    schur_complement,
)

# Every comparison of two direct solvers on the same SPD matrix: both are backward stable, the
# box's condition number is ~1e5, so they agree to ~1e-12; 1e-10 leaves margin, catches any bug.
TOL_SOLVERS = 1e-10


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


@pytest.fixture(scope="module")
def box() -> tuple[sp.csr_matrix, np.ndarray]:
    """Clamped P2 steel box (3×3×4 cells, ~2.5k free DOFs) and its top-face DOFs (shuffled)."""
    mesh = skfem.MeshTet.init_tensor(
        np.linspace(0.0, 1.0, 4), np.linspace(0.0, 1.0, 4), np.linspace(0.0, 1.5, 5)
    )
    basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()))
    K = linear_elasticity(*lame_parameters(206000.0, 0.3)).assemble(basis)
    clamped = basis.get_dofs(lambda x: np.isclose(x[2], 0.0)).all()
    top = basis.get_dofs(lambda x: np.isclose(x[2], 1.5)).all()
    free = np.setdiff1d(np.arange(basis.N), clamped)
    idx = np.searchsorted(free, top)
    idx = np.random.default_rng(1).permutation(idx)  # not sorted: order handling is exercised
    return K[free][:, free].tocsr(), idx


@pytest.fixture(scope="module")
def reference(box: tuple[sp.csr_matrix, np.ndarray]) -> np.ndarray:
    """(K⁻¹)[idx][:, idx] from plain SuperLU back-solves on the whole K, unit vectors e_j."""
    K, idx = box
    lu = spla.splu(K.tocsc())
    E = np.zeros((K.shape[0], idx.size))
    E[idx, np.arange(idx.size)] = 1.0
    return lu.solve(E)[idx]


@pytest.fixture
def fresh_probe():
    """Forget the cached PARDISO probe before and after a test that patches the loader."""
    schur._clear_backend_cache()
    yield
    schur._clear_backend_cache()


@pytest.fixture
def no_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENV_SOLVER, raising=False)


def _needs_pardiso() -> None:
    if "pardiso" not in available_backends():
        pytest.skip("MKL PARDISO not available on this machine")


def test_superlu_inverse_block_matches_back_solves(box, reference) -> None:
    K, idx = box
    C = inverse_block(K, idx, "superlu")
    assert C.shape == (idx.size, idx.size)
    assert _rel(C, reference) < TOL_SOLVERS


def test_pardiso_schur_matches_superlu(box) -> None:
    _needs_pardiso()
    K, idx = box
    S_p = schur_complement(K, idx, "pardiso")
    S_s = schur_complement(K, idx, "superlu")
    assert _rel(S_p, S_s) < TOL_SOLVERS


def test_pardiso_inverse_block_matches_back_solves(box, reference) -> None:
    _needs_pardiso()
    K, idx = box
    assert _rel(inverse_block(K, idx, "pardiso"), reference) < TOL_SOLVERS


def test_schur_matches_dense_formula(box) -> None:
    """S = K_cc − K_ci K_ii⁻¹ K_ic, dense, on a 60-DOF subset (independent of both backends)."""
    K, idx = box
    c = idx[:60]
    i = np.setdiff1d(np.arange(K.shape[0]), c)
    Kd = K.toarray()
    S_ref = Kd[np.ix_(c, c)] - Kd[np.ix_(c, i)] @ la.solve(
        Kd[np.ix_(i, i)], Kd[np.ix_(i, c)], assume_a="pos"
    )
    for backend in available_backends():
        assert _rel(schur_complement(K, c, backend), S_ref) < TOL_SOLVERS, backend


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_blocks_symmetric_positive_definite(box, backend) -> None:
    if backend == "pardiso":
        _needs_pardiso()
    K, idx = box
    for block in (schur_complement(K, idx, backend), inverse_block(K, idx, backend)):
        # Both blocks are symmetrised on return: exact symmetry, not just to round-off.
        np.testing.assert_array_equal(block, block.T)
        la.cholesky(block)  # raises LinAlgError unless positive definite


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_idx_order_respected(box, backend) -> None:
    if backend == "pardiso":
        _needs_pardiso()
    K, idx = box
    p = np.random.default_rng(7).permutation(idx.size)
    S = schur_complement(K, idx, backend)
    S_perm = schur_complement(K, idx[p], backend)
    # Same factorization up to the elimination order: round-off only.
    assert _rel(S_perm, S[np.ix_(p, p)]) < TOL_SOLVERS
    C_sorted = inverse_block(K, np.sort(idx), backend)
    rank = np.argsort(np.argsort(idx))  # position of idx[a] in sorted order
    assert _rel(inverse_block(K, idx, backend), C_sorted[np.ix_(rank, rank)]) < TOL_SOLVERS


def test_all_dofs_candidates_gives_K() -> None:
    K = sp.diags([-np.ones(4), 3.0 * np.ones(5), -np.ones(4)], [-1, 0, 1], format="csr")
    idx = np.array([4, 0, 2, 1, 3])
    for backend in available_backends():
        # No interior DOFs: S is K itself, copied exactly.
        np.testing.assert_array_equal(
            schur_complement(K, idx, backend), K.toarray()[np.ix_(idx, idx)]
        )


def test_loader_failure_falls_back_to_superlu(
    monkeypatch, caplog, fresh_probe, no_env, box
) -> None:
    def broken_loader() -> _mkl_pardiso.MklPardiso:
        raise BackendUnavailable("mkl_rt shared library not found (test)")

    monkeypatch.setattr(_mkl_pardiso, "load_library", broken_loader)
    with caplog.at_level(logging.INFO, logger="fegear.linalg.schur"):
        assert resolve_backend("auto") == "superlu"
    assert "PARDISO not available (mkl_rt shared library not found (test))" in caplog.text
    assert "using SciPy SuperLU" in caplog.text
    assert available_backends() == ("superlu",)
    with pytest.raises(BackendUnavailable, match="PARDISO"):
        resolve_backend("pardiso")
    K, idx = box
    with pytest.raises(BackendUnavailable):
        schur_complement(K, idx[:10], "pardiso")
    assert schur_complement(K, idx[:10]).shape == (10, 10)  # auto still works, via SuperLU


def test_auto_picks_pardiso_when_available(caplog, no_env) -> None:
    _needs_pardiso()
    with caplog.at_level(logging.INFO, logger="fegear.linalg.schur"):
        assert resolve_backend("auto") == "pardiso"
    assert "MKL PARDISO" in caplog.text


def test_env_var_honoured(monkeypatch, fresh_probe) -> None:
    monkeypatch.setenv(ENV_SOLVER, "superlu")
    assert resolve_backend() == "superlu"
    assert resolve_backend("auto") == "superlu"
    monkeypatch.setenv(ENV_SOLVER, "SuperLU ")  # case and whitespace do not matter
    assert resolve_backend() == "superlu"
    monkeypatch.setenv(ENV_SOLVER, "cholmod")
    with pytest.raises(InputError, match=ENV_SOLVER):
        resolve_backend()
    monkeypatch.setenv(ENV_SOLVER, "pardiso")
    if "pardiso" in available_backends():
        assert resolve_backend() == "pardiso"
    monkeypatch.setattr(_mkl_pardiso, "load_library", _raise_unavailable)
    schur._clear_backend_cache()
    with pytest.raises(BackendUnavailable):  # asked for by the environment: explicit
        resolve_backend()
    assert resolve_backend("superlu") == "superlu"  # an explicit argument beats the environment


def _raise_unavailable() -> _mkl_pardiso.MklPardiso:
    raise BackendUnavailable("patched out")


def test_input_checks(box) -> None:
    K, idx = box
    n = K.shape[0]
    with pytest.raises(InputError, match="scipy.sparse"):
        schur_complement(K.toarray(), idx)
    with pytest.raises(InputError, match="K.shape"):
        schur_complement(K[:, :-1], idx[idx < n - 1])
    with pytest.raises(InputError, match="unique"):
        schur_complement(K, np.array([3, 5, 3]))
    with pytest.raises(InputError, match="idx"):
        schur_complement(K, np.array([0, n]))
    with pytest.raises(InputError, match="idx"):
        schur_complement(K, np.array([-1, 2]))
    with pytest.raises(InputError, match="idx"):
        schur_complement(K, np.array([0.0, 1.0]))
    with pytest.raises(InputError, match="backend"):
        schur_complement(K, idx, "mumps")
    asym = K.tolil()
    asym[0, 1] += 1.0  # max|K| ~ 1e5: an asymmetry of 1 is far above round-off
    with pytest.raises(InputError, match="symmetric"):
        schur_complement(asym.tocsr(), idx)
    assert schur_complement(K, np.array([], dtype=int)).shape == (0, 0)


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_indefinite_matrix_raises_solver_error(backend) -> None:
    if backend == "pardiso":
        _needs_pardiso()
    # Tridiagonal (-1, 1, -1), n = 30: eigenvalues 1 - 2 cos(k pi / 31), ten of them negative;
    # its interior block (n = 28) has nine, so by Haynsworth's inertia additivity S has one.
    n = 30
    K = sp.diags([-np.ones(n - 1), np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    with pytest.raises(SolverError):
        inverse_block(K, np.array([0, n - 1]), backend)


def test_nonpositive_diagonal_rejected() -> None:
    # A DOF with no stiffness at all (unconstrained, no element): zero diagonal, explicit.
    K = sp.diags([-np.ones(4), 2.0 * np.ones(5), -np.ones(4)], [-1, 0, 1]).tolil()
    K[4, 4], K[3, 4], K[4, 3] = 0.0, 0.0, 0.0
    for backend in available_backends():
        with pytest.raises(InputError, match="diagonal"):
            schur_complement(K.tocsr(), np.array([0, 1]), backend)


def test_mkl_dense_spd_inverse_matches_numpy() -> None:
    """The MKL LAPACK inverse used above SciPy's potrf limit (column-major lower factor of the
    C array, mirrored by blocks): n spans several 2048-row mirror blocks."""
    _needs_pardiso()
    from fegear.linalg.schur import _pardiso

    lib, _ = _pardiso()
    rng = np.random.default_rng(3)
    n = 4500
    A = rng.standard_normal((n, 60))
    S = A @ A.T + n * np.eye(n) + np.triu(rng.standard_normal((n, n)) * 1e-3, 1)
    S = 0.5 * (S + S.T)
    X = lib.spd_inverse(S)
    assert np.array_equal(X, X.T)  # exactly symmetric: mirrored from one triangle
    # Relative residual at round-off (cond(S) ~ 1): 1e-12 leaves a wide margin over 1e-15.
    assert np.abs(X @ S - np.eye(n)).max() < 1e-12


def test_mkl_dense_spd_inverse_refuses_an_indefinite_matrix() -> None:
    _needs_pardiso()
    from fegear.linalg.schur import _pardiso

    lib, _ = _pardiso()
    S = np.diag([1.0, 2.0, -1.0, 3.0])
    with pytest.raises(SolverError, match="not positive definite"):
        lib.spd_inverse(S)


def test_a_bad_backend_name_is_refused_on_an_operator_cache_hit(tmp_path, monkeypatch) -> None:
    """The operator cache skips the solver (and MKL's loading), not the check of the request."""
    import skfem

    from fegear.fem.elasticity import assemble_body
    from fegear.mechanics.compliance import candidate_operator

    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path))
    mesh = skfem.MeshTet.init_tensor(*[np.linspace(0.0, 1.0, 3)] * 3).with_boundaries(
        {"bottom": lambda x: x[2] < 1e-9}
    )
    body = assemble_body(mesh, 206000.0, 0.3, [("bottom", "xyz")])
    dofs = body.free[-12:]
    key = {"mesh": "unit cube 2x2x2", "clamped": "bottom"}
    first = candidate_operator(body, dofs, "superlu", cache_key=key)
    again = candidate_operator(body, dofs, "superlu", cache_key=key)
    assert not first.cache_hit and again.cache_hit
    np.testing.assert_array_equal(np.asarray(again.G), first.G)  # read back bit for bit
    with pytest.raises(InputError, match="backend"):
        candidate_operator(body, dofs, "mumps", cache_key=key)


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_inverse_columns_are_the_columns_of_the_inverse_block(box, reference, backend) -> None:
    """Block elimination onto the load DOFs gives the same columns as the whole inverse."""
    if backend == "pardiso":
        _needs_pardiso()
    K, idx = box
    cols = np.zeros(idx.size, dtype=bool)
    cols[np.random.default_rng(3).choice(idx.size, idx.size // 3, replace=False)] = True
    G = inverse_columns(K, idx, cols, backend)
    assert G.shape == (idx.size, cols.sum())
    assert _rel(G, reference[:, cols]) < TOL_SOLVERS
    # every column mask, all-True included, gives the square symmetric block
    np.testing.assert_array_equal(
        inverse_columns(K, idx, np.ones(idx.size, bool), backend), inverse_block(K, idx, backend)
    )


@pytest.mark.parametrize("mkl_min", [10, 10**9], ids=["mkl-dense", "openblas-dense"])
def test_inverse_columns_through_either_dense_cholesky(box, reference, monkeypatch, mkl_min):
    """The dense Cholesky and inverse of MKL (used where MKL is at hand) and of SciPy's
    OpenBLAS give the same columns."""
    _needs_pardiso()
    monkeypatch.setattr(schur, "_MKL_DENSE_MIN", mkl_min)
    K, idx = box
    cols = np.arange(idx.size) % 4 == 0
    assert _rel(inverse_columns(K, idx, cols, "pardiso"), reference[:, cols]) < TOL_SOLVERS
    full = np.ones(idx.size, bool)
    assert _rel(inverse_columns(K, idx, full, "pardiso"), reference) < TOL_SOLVERS


def test_inverse_columns_refuses_a_bad_mask(box) -> None:
    K, idx = box
    with pytest.raises(InputError, match="columns"):
        inverse_columns(K, idx, np.arange(idx.size) % 2, "superlu")


def test_operator_on_load_columns_and_its_guard() -> None:
    """An operator kept only on its load columns gives the same loads-to-readings compliance as
    the square one; a load on a free DOF outside its columns is an error, never a silent clamp;
    a load on a clamped DOF does no work and is ignored."""
    from fegear.fem.elasticity import assemble_body
    from fegear.mechanics.compliance import body_compliance, candidate_operator, cross_compliance

    mesh = skfem.MeshTet.init_tensor(*[np.linspace(0.0, 1.0, 3)] * 3).with_boundaries(
        {"bottom": lambda x: x[2] < 1e-9}
    )
    body = assemble_body(mesh, 206000.0, 0.3, [("bottom", "xyz")])
    cand = body.free[-30:]
    loads, reads = cand[-10:], cand[:20]
    square = candidate_operator(body, cand, "superlu")
    narrow = candidate_operator(body, cand, "superlu", load_dofs=loads)
    assert narrow.G.shape == (30, 10) and square.G.shape == (30, 30)
    rng = np.random.default_rng(5)

    def spread(dofs, n):  # (n_dofs, n) with random entries on ``dofs``
        M = np.zeros((body.n_dofs, n))
        M[dofs] = rng.standard_normal((dofs.size, n))
        return sp.csr_matrix(M)

    P, Q = spread(loads, 4), spread(reads, 3)
    # two eliminations of the same matrix: round-off apart
    assert _rel(body_compliance(narrow, P), body_compliance(square, P)) < TOL_SOLVERS
    assert _rel(cross_compliance(narrow, Q, P), cross_compliance(square, Q, P)) < TOL_SOLVERS
    with pytest.raises(SolverError, match="outside the compliance operator"):
        body_compliance(narrow, spread(reads[:1], 1))
    clamped = np.setdiff1d(np.arange(body.n_dofs), body.free)[:3]
    P_c = spread(np.concatenate([clamped, loads]), 2)
    P_only = sp.csr_matrix(P_c.toarray() * np.isin(np.arange(body.n_dofs), loads)[:, None])
    np.testing.assert_array_equal(body_compliance(narrow, P_c), body_compliance(narrow, P_only))


def test_an_operator_in_groups_has_the_blocks_of_the_whole_one() -> None:
    """Groups (per loaded tooth: its load DOFs and the layer DOFs read only under them) give
    ``G_ff`` and each group's ``G_{read, load}`` as the whole operator has them (each block the
    inverse of its own Schur complement); the blocks no group asks for are NaN."""
    from fegear.fem.elasticity import assemble_body
    from fegear.mechanics.compliance import candidate_operator

    mesh = skfem.MeshTet.init_tensor(*[np.linspace(0.0, 1.0, 4)] * 3).with_boundaries(
        {"bottom": lambda x: x[2] < 1e-9}
    )
    body = assemble_body(mesh, 206000.0, 0.3, [("bottom", "xyz")])
    free = body.free
    f1, f2 = free[-12:-6], free[-6:]
    l1, l2 = free[-40:-30], free[-30:-20]
    cand = np.concatenate([f1, f2, l1, l2])
    loads = np.concatenate([f1, f2])
    whole = candidate_operator(body, cand, "superlu", load_dofs=loads)
    grouped = candidate_operator(
        body, cand, "superlu", load_dofs=loads, groups=[(f1, l1), (f2, l2)]
    )
    row = {int(d): i for i, d in enumerate(whole.dofs)}
    col = {int(d): i for i, d in enumerate(whole.cols)}

    def block(op, rows, cols):
        return op.G[np.ix_([row[int(d)] for d in rows], [col[int(d)] for d in cols])]

    for rows, cols in ((loads, loads), (l1, f1), (l2, f2)):
        # two eliminations of the same matrix: round-off apart
        assert _rel(block(grouped, rows, cols), block(whole, rows, cols)) < TOL_SOLVERS
    assert np.isnan(block(grouped, l1, f2)).all() and np.isnan(block(grouped, l2, f1)).all()
    with pytest.raises(InputError, match="groups"):
        candidate_operator(body, cand, "superlu", load_dofs=loads, groups=[(f1, l1), (f2, l1)])


@pytest.mark.parametrize("backend", ["superlu", "pardiso"])
def test_inverse_off_block_is_the_rows_off_the_columns(box, reference, backend) -> None:
    """Given ``G_ff``, the rows off the columns of ``(K⁻¹)_cc`` are those of the whole inverse;
    a mask without both values, or a ``G_ff`` of another size, is refused."""
    if backend == "pardiso":
        _needs_pardiso()
    K, idx = box
    cols = np.arange(idx.size) % 3 == 0
    G_ff = reference[np.ix_(cols, cols)]
    G_lf = inverse_off_block(K, idx, cols, G_ff, backend)
    assert _rel(G_lf, reference[np.ix_(~cols, cols)]) < TOL_SOLVERS
    with pytest.raises(InputError, match="columns"):
        inverse_off_block(K, idx, np.ones(idx.size, bool), reference, backend)
    with pytest.raises(InputError, match="G_ff"):
        inverse_off_block(K, idx, cols, G_ff[1:, 1:], backend)


def test_an_operator_in_groups_is_read_back_block_for_block(tmp_path, monkeypatch) -> None:
    """An operator in groups is stored as its blocks and read back bit for bit (memory-mapped);
    ``take`` gives any rows and columns, NaN where no block holds them, as ``G`` does."""
    from fegear.fem.elasticity import assemble_body
    from fegear.mechanics.compliance import candidate_operator

    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path))
    mesh = skfem.MeshTet.init_tensor(*[np.linspace(0.0, 1.0, 4)] * 3).with_boundaries(
        {"bottom": lambda x: x[2] < 1e-9}
    )
    body = assemble_body(mesh, 206000.0, 0.3, [("bottom", "xyz")])
    free = body.free
    f1, f2, l1, l2 = free[-12:-6], free[-6:], free[-40:-30], free[-30:-20]
    cand, loads = np.concatenate([f1, f2, l1, l2]), np.concatenate([f1, f2])
    key, groups = {"mesh": "unit cube 3x3x3", "clamped": "bottom"}, [(f1, l1), (f2, l2)]
    first = candidate_operator(body, cand, "superlu", key, load_dofs=loads, groups=groups)
    again = candidate_operator(body, cand, "superlu", key, load_dofs=loads, groups=groups)
    assert not first.cache_hit and again.cache_hit and len(again.blocks) == 3
    for a, b in zip(first.blocks, again.blocks, strict=True):
        np.testing.assert_array_equal(np.asarray(b.G), a.G)
    rows = np.random.default_rng(7).permutation(again.dofs.size)[:25]
    cols = np.random.default_rng(8).permutation(again.cols.size)[:7]
    np.testing.assert_array_equal(again.take(rows, cols), again.G[np.ix_(rows, cols)])
