"""The dense passes after PARDISO's Schur complement (fegear.linalg.schur,
fegear.linalg._mkl_pardiso): the symmetrisation that leaves an exactly symmetric matrix as it
is, and the columns of the inverse from one MKL factorisation of the reordered matrix."""

from __future__ import annotations

import numpy as np
import pytest

from fegear.errors import SolverError
from fegear.linalg import available_backends, schur


def _lib():
    if "pardiso" not in available_backends():
        pytest.skip("MKL not available")
    lib, _ = schur._pardiso()
    return lib


def _spd(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    S = A @ A.T / n + np.eye(n)
    return 0.5 * (S + S.T)


@pytest.mark.parametrize("n", [7, 23])
def test_symmetrize_is_the_average_bit_for_bit(monkeypatch, n) -> None:
    """Blocks of 4 rows (several block pairs, one ragged): an exactly symmetric matrix comes
    back as it was, an asymmetric one as ``0.5 * (S + S.T)``, bit for bit, whichever block
    pairs differ."""
    monkeypatch.setattr(schur, "_BLOCK_ROWS", 4)
    S = _spd(n, 1)
    out = schur._symmetrize(S.copy())
    assert np.array_equal(out, S)
    rng = np.random.default_rng(2)
    T = S.copy()
    T[rng.integers(0, n, 5), rng.integers(0, n, 5)] += 1e-9  # a few pairs off, some diagonal
    expected = 0.5 * (T + T.T)
    np.testing.assert_array_equal(schur._symmetrize(T.copy()), expected)


@pytest.mark.parametrize("n_cols", [1, 3, 40, 59])
def test_mkl_inverse_columns_are_the_columns_of_the_inverse(n_cols) -> None:
    """``spd_inverse_columns`` against NumPy's inverse, columns scattered among the rows; one
    column and one other row included. cond(S) ~ 10: agreement to 1e-13 leaves a wide margin
    over round-off (~1e-15)."""
    lib = _lib()
    n = 60
    S = _spd(n, 3)
    cols = np.zeros(n, bool)
    cols[np.random.default_rng(4).choice(n, n_cols, replace=False)] = True
    S0 = S.copy()
    G = lib.spd_inverse_columns(S, cols)
    assert np.array_equal(S, S0)  # the input is not modified
    assert G.shape == (n, n_cols) and G.flags.c_contiguous
    ref = np.linalg.inv(S)[:, cols]
    assert np.abs(G - ref).max() < 1e-13 * np.abs(ref).max()
    G_ff = G[cols]
    assert np.array_equal(G_ff, G_ff.T)  # mirrored from one triangle


def test_mkl_inverse_columns_refuses_an_indefinite_matrix() -> None:
    lib = _lib()
    S = np.diag([1.0, 2.0, -1.0, 3.0])
    with pytest.raises(SolverError, match="not positive definite"):
        lib.spd_inverse_columns(S, np.array([True, False, False, True]))
