"""The one sparse SPD solver (fegear.linalg.solve.factorize_spd): both backends, their agreement,
several right-hand sides, the backend rules, and failures that surface.

The matrix is a clamped scikit-fem P2 elasticity box (3×3×4 cells, 1176 free DOFs, steel, mm):
condition number 6.8e3, ‖K‖₂‖x‖/‖b‖ ≈ 270 for random ``b``. PARDISO parts are skipped where MKL
is absent (macOS arm64), so the suite runs everywhere.
"""

from __future__ import annotations

import gc
import logging

import numpy as np
import pytest
import scipy.sparse as sp
import skfem
from skfem.models.elasticity import lame_parameters, linear_elasticity

from fegear.errors import BackendUnavailable, InputError, SolverError
from fegear.linalg import ENV_SOLVER, _mkl_pardiso, available_backends, schur
from fegear.linalg.solve import SparseFactor, factorize_spd

# A backward-stable Cholesky / LU solve has ‖K x − b‖ ≤ c(n) ε ‖K‖ ‖x‖ (Higham, *Accuracy and
# Stability of Numerical Algorithms*, 2nd ed., thm. 10.4): here ε ‖K‖‖x‖/‖b‖ ≈ 2.2e-16 × 270
# = 6e-14, measured 1.8e-14 (PARDISO) and 2.0e-14 (SuperLU). 1e-11 allows c(n) up to ~170 and
# still fails on any wrong factor (those give O(1)).
TOL_RESIDUAL = 1e-11
# Two backward-stable solutions differ by at most ~cond(K) times their backward errors:
# 6.8e3 × 1e-13 ≈ 7e-10 in the worst case (measured 1e-14); 1e-9 catches any real disagreement.
TOL_AGREE = 1e-9


def _rel_residual(K: sp.csr_matrix, x: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(K @ x - b) / np.linalg.norm(b))


@pytest.fixture(scope="module")
def box() -> sp.csr_matrix:
    """Free-DOF stiffness of a P2 steel box clamped at z = 0 (1176 DOFs)."""
    mesh = skfem.MeshTet.init_tensor(
        np.linspace(0.0, 1.0, 4), np.linspace(0.0, 1.0, 4), np.linspace(0.0, 1.5, 5)
    )
    basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()))
    K = linear_elasticity(*lame_parameters(206000.0, 0.3)).assemble(basis)
    clamped = basis.get_dofs(lambda x: np.isclose(x[2], 0.0)).all()
    free = np.setdiff1d(np.arange(basis.N), clamped)
    return K[free][:, free].tocsr()


@pytest.fixture(scope="module")
def rhs(box: sp.csr_matrix) -> np.ndarray:
    return np.random.default_rng(7).standard_normal((box.shape[0], 4))


@pytest.fixture
def fresh_probe():
    """Forget the cached PARDISO probe before and after a test that patches the loader."""
    schur._clear_backend_cache()
    yield
    schur._clear_backend_cache()


@pytest.fixture(autouse=True)
def no_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENV_SOLVER, raising=False)


def _backends() -> list:
    return [
        pytest.param(
            "pardiso",
            marks=pytest.mark.skipif(
                "pardiso" not in available_backends(), reason="MKL PARDISO not available"
            ),
        ),
        "superlu",
    ]


def _raise_unavailable() -> _mkl_pardiso.MklPardiso:
    raise BackendUnavailable("mkl_rt shared library not found (test)")


@pytest.mark.parametrize("backend", _backends())
def test_residual_small(box, rhs, backend) -> None:
    f = factorize_spd(box, backend)
    assert isinstance(f, SparseFactor)
    assert f.backend == backend and f.n == box.shape[0]
    x = f.solve(rhs[:, 0])
    assert x.shape == (box.shape[0],) and x.dtype == np.float64
    assert _rel_residual(box, x, rhs[:, 0]) < TOL_RESIDUAL


@pytest.mark.parametrize("backend", _backends())
def test_several_right_hand_sides_at_once(box, rhs, backend) -> None:
    f = factorize_spd(box, backend)
    b = rhs.copy()
    X = f.solve(b)
    np.testing.assert_array_equal(b, rhs)  # b is not overwritten
    assert X.shape == rhs.shape
    assert _rel_residual(box, X, rhs) < TOL_RESIDUAL
    for j in range(rhs.shape[1]):
        # the same as one at a time, to the round-off of a reordered sum (PARDISO blocks the
        # substitution over the right-hand sides: measured 1e-14 relative)
        x = f.solve(rhs[:, j])
        assert np.linalg.norm(X[:, j] - x) / np.linalg.norm(x) < 1e-12
    assert f.solve(np.zeros((box.shape[0], 0))).shape == (box.shape[0], 0)
    Xc = f.solve(np.ascontiguousarray(rhs[:, :2]))  # C or Fortran order: the same numbers
    np.testing.assert_array_equal(Xc, f.solve(np.asfortranarray(rhs[:, :2])))


def test_backends_agree(box, rhs) -> None:
    if "pardiso" not in available_backends():
        pytest.skip("MKL PARDISO not available")
    xp = factorize_spd(box, "pardiso").solve(rhs)
    xs = factorize_spd(box, "superlu").solve(rhs)
    assert np.linalg.norm(xp - xs) / np.linalg.norm(xs) < TOL_AGREE


def test_auto_follows_the_backend_rules(box, monkeypatch) -> None:
    expected = "pardiso" if "pardiso" in available_backends() else "superlu"
    assert factorize_spd(box).backend == expected
    assert factorize_spd(box, "auto").backend == expected
    monkeypatch.setenv(ENV_SOLVER, "superlu")
    assert factorize_spd(box).backend == "superlu"
    with pytest.raises(InputError, match="backend"):
        factorize_spd(box, "cholmod")


def test_explicit_pardiso_unavailable_raises(box, monkeypatch, caplog, fresh_probe) -> None:
    monkeypatch.setattr(_mkl_pardiso, "load_library", _raise_unavailable)
    with pytest.raises(BackendUnavailable, match="PARDISO was requested"):
        factorize_spd(box, "pardiso")
    monkeypatch.setenv(ENV_SOLVER, "pardiso")  # asked for by the environment: explicit too
    with pytest.raises(BackendUnavailable):
        factorize_spd(box)
    monkeypatch.delenv(ENV_SOLVER)
    with caplog.at_level(logging.INFO, logger="fegear.linalg.schur"):
        f = factorize_spd(box)  # auto: SuperLU, and the log says why
    assert f.backend == "superlu"
    assert "PARDISO not available (mkl_rt shared library not found (test))" in caplog.text


def test_pardiso_failure_surfaces_not_a_superlu_result(fresh_probe) -> None:
    """An indefinite matrix with a positive diagonal passes the input checks; PARDISO's Cholesky
    stops at its negative pivot (error -4). SuperLU would solve it: no silent fallback."""
    if "pardiso" not in available_backends():
        pytest.skip("MKL PARDISO not available")
    n = 30  # tridiagonal (-1, 1, -1): eigenvalues 1 - 2 cos(k π / 31), ten of them negative
    K = sp.diags([-np.ones(n - 1), np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")
    for backend in ("pardiso", "auto"):
        with pytest.raises(SolverError, match="error -4"):
            factorize_spd(K, backend)


def test_pardiso_error_in_the_solve_phase_surfaces(box, rhs, monkeypatch) -> None:
    if "pardiso" not in available_backends():
        pytest.skip("MKL PARDISO not available")
    f = factorize_spd(box, "pardiso")
    real_call = _mkl_pardiso.MklPardiso._call

    def failing_call(self, pt, phase, *args, **kwargs):
        if phase == 33:
            return -2  # not enough memory
        return real_call(self, pt, phase, *args, **kwargs)

    monkeypatch.setattr(_mkl_pardiso.MklPardiso, "_call", failing_call)
    with pytest.raises(SolverError, match=r"phase 33 .*error -2, not enough memory"):
        f.solve(rhs)


def test_pardiso_memory_released_with_the_factor(box, rhs, monkeypatch) -> None:
    if "pardiso" not in available_backends():
        pytest.skip("MKL PARDISO not available")
    calls: list[tuple[np.ndarray, int]] = []  # (handle array, phase)
    real_call = _mkl_pardiso.MklPardiso._call

    def spy(self, pt, phase, *args, **kwargs):
        calls.append((pt, phase))
        return real_call(self, pt, phase, *args, **kwargs)

    def phases(f) -> list[int]:  # the calls on one factor's handle (others may be collected)
        return [ph for h, ph in calls if h is f._factor._pt]

    monkeypatch.setattr(_mkl_pardiso.MklPardiso, "_call", spy)
    f = factorize_spd(box, "pardiso")
    f.solve(rhs)
    handle, finalizer = f._factor._pt, f._factor._finalizer
    assert finalizer.alive and phases(f) == [12, 33]
    del f
    gc.collect()
    assert not finalizer.alive  # phase -1 (release all memory) ran on the handle, once
    assert [ph for h, ph in calls if h is handle] == [12, 33, -1]

    g = factorize_spd(box, "pardiso")
    g._factor.release()
    assert phases(g) == [12, -1]
    with pytest.raises(SolverError, match="released"):
        g.solve(rhs)
    g._factor.release()  # a second release (or the collection) does nothing
    assert phases(g) == [12, -1]


def test_singular_matrix_superlu_raises_solver_error() -> None:
    # A floating block: rows 2-3 are [[1, -1], [-1, 1]] (singular, positive diagonal).
    K = sp.csr_matrix(np.array([[2.0, -1, 0, 0], [-1, 2, 0, 0], [0, 0, 1, -1], [0, 0, -1, 1]]))
    with pytest.raises(SolverError):
        factorize_spd(K, "superlu").solve(np.ones(4))


def test_input_checks(box) -> None:
    with pytest.raises(InputError, match="scipy.sparse"):
        factorize_spd(box.toarray())
    with pytest.raises(InputError, match="K.shape"):
        factorize_spd(box[:, :-1])
    asym = box.tolil()
    asym[0, 1] += 1.0  # max|K| ~ 1e5: an asymmetry of 1 is far above round-off
    with pytest.raises(InputError, match="symmetric"):
        factorize_spd(asym.tocsr())
    zero_diag = sp.diags([1.0, 0.0, 1.0], format="csr")
    with pytest.raises(InputError, match="diagonal"):
        factorize_spd(zero_diag)
    f = factorize_spd(box, "superlu")
    n = box.shape[0]
    with pytest.raises(InputError, match="shape"):
        f.solve(np.ones(n + 1))
    with pytest.raises(InputError, match="shape"):
        f.solve(np.ones((n, 2, 2)))
    with pytest.raises(InputError, match="real"):
        f.solve(np.ones(n, dtype=complex))
    with pytest.raises(InputError, match="finite"):
        f.solve(np.full(n, np.nan))
