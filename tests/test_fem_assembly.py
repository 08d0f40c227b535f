"""Fast P2 elasticity assembly (fegear.fem.assembly) against stock scikit-fem."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import skfem
from skfem.models.elasticity import lame_parameters, linear_elasticity

from fegear.errors import InputError
from fegear.fem.assembly import elasticity_stiffness

E, NU = 206000.0, 0.3


def _box(n: tuple[int, int, int] = (4, 3, 5), size=(1.0, 2.0, 0.7)) -> skfem.MeshTet:
    return skfem.MeshTet.init_tensor(
        *[np.linspace(0.0, s, k) for k, s in zip(n, size, strict=True)]
    )


def _volumes(mesh: skfem.MeshTet) -> np.ndarray:
    p = mesh.p[:, mesh.t]  # (3, 4, nel)
    J = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]], axis=1)
    return np.linalg.det(J.transpose(2, 0, 1)) / 6.0


def _distorted(seed: int = 7) -> skfem.MeshTet:
    """Box with randomly moved interior nodes, then a random affine map (fixed seed)."""
    rng = np.random.default_rng(seed)
    mesh = _box((5, 4, 4), (1.0, 1.5, 0.8))
    p = mesh.p.copy()
    lo, hi = p.min(axis=1, keepdims=True), p.max(axis=1, keepdims=True)
    interior = np.all((p > lo + 1e-9) & (p < hi - 1e-9), axis=0)
    p[:, interior] += rng.uniform(-0.07, 0.07, size=(3, interior.sum()))
    A = np.eye(3) + 0.3 * rng.standard_normal((3, 3))
    A *= np.sign(np.linalg.det(A))  # keep the orientation
    p = A @ p + rng.standard_normal((3, 1))
    out = skfem.MeshTet(p, mesh.t)
    vol = _volumes(out)
    assert np.all(vol * np.sign(_volumes(mesh)) > 0), "distortion inverted an element"
    return out


def _stock(mesh: skfem.MeshTet, E: float, nu: float) -> sp.csr_matrix:
    basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()))
    return skfem.asm(linear_elasticity(*lame_parameters(E, nu)), basis).tocsr()


def _rel(A: sp.spmatrix, B: sp.spmatrix) -> float:
    return abs(A - B).max() / abs(B).max()


MESHES = {
    "tensor": lambda: _box(),
    "graded": lambda: skfem.MeshTet.init_tensor(
        np.array([0.0, 0.1, 0.3, 1.0]), np.linspace(0, 1, 3) ** 2, np.array([0.0, 0.5, 0.6])
    ),
    "distorted": _distorted,
}


@pytest.mark.parametrize("name", sorted(MESHES))
@pytest.mark.parametrize(("E", "nu"), [(E, NU), (1.0, 0.49), (70000.0, -0.2)])
def test_equals_stock(name, E, nu):
    mesh = MESHES[name]()
    K0 = _stock(mesh, E, nu)
    K = elasticity_stiffness(mesh, E, nu)
    assert isinstance(K, sp.csr_matrix) and K.has_sorted_indices
    assert K.shape == K0.shape == (3 * skfem.Basis(mesh, skfem.ElementTetP2()).N,) * 2
    assert _rel(K, K0) < 1e-12
    # the stock pattern (exact local zeros dropped) is a subset of the full block pattern
    P0, P = K0.copy(), K.copy()
    P0.data[:], P.data[:] = 1.0, 1.0
    assert P0.multiply(P).nnz == P0.nnz


def test_given_bases_and_chunks():
    """A scalar or vector basis (default 4th-order rule) and any chunk give the same matrix."""
    mesh = _distorted(3)
    K0 = _stock(mesh, E, NU)
    vector = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()))
    scalar = skfem.Basis(mesh, skfem.ElementTetP2())
    K = elasticity_stiffness(mesh, E, NU)
    for kw in ({"basis": vector}, {"basis": scalar}, {"chunk": 7}, {"chunk": 10**6}):
        assert _rel(elasticity_stiffness(mesh, E, NU, **kw), K0) < 1e-12, kw
        assert _rel(elasticity_stiffness(mesh, E, NU, **kw), K) < 1e-14, kw


def test_symmetric_exactly():
    K = elasticity_stiffness(_distorted(), E, NU)
    assert abs(K - K.T).max() == 0.0


def _rigid_modes(doflocs: np.ndarray) -> list[np.ndarray]:
    """3 translations and 3 rotations about the axes, as interleaved nodal vectors."""
    n = doflocs.shape[1]
    modes = []
    for c in range(3):
        u = np.zeros((n, 3))
        u[:, c] = 1.0
        modes.append(u.ravel())
    x = doflocs.T - doflocs.mean(axis=1)
    for c in range(3):
        omega = np.zeros(3)
        omega[c] = 1.0
        modes.append(np.cross(omega, x).ravel())
    return modes


@pytest.mark.parametrize("name", ["tensor", "distorted"])
def test_rigid_body_modes_in_null_space(name):
    mesh = MESHES[name]()
    K = elasticity_stiffness(mesh, E, NU)
    doflocs = skfem.Basis(mesh, skfem.ElementTetP2()).doflocs
    norm_K = abs(K).sum(axis=1).max()  # infinity norm
    for u in _rigid_modes(doflocs):
        assert np.abs(K @ u).max() / (norm_K * np.abs(u).max()) < 1e-10
    # and a non-rigid field is not
    u = (doflocs.T**2).ravel()
    assert np.abs(K @ u).max() / (norm_K * np.abs(u).max()) > 1e-3


@pytest.mark.parametrize("name", ["tensor", "distorted"])
def test_patch_linear_field_energy(name):
    """u = G x + c: 1/2 u.K.u = 1/2 eps:C:eps * volume (eps = sym G), exactly."""
    mesh = MESHES[name]()
    rng = np.random.default_rng(11)
    G = rng.standard_normal((3, 3))
    c = rng.standard_normal(3)
    doflocs = skfem.Basis(mesh, skfem.ElementTetP2()).doflocs
    u = (doflocs.T @ G.T + c).ravel()
    K = elasticity_stiffness(mesh, E, NU)
    lam, mu = lame_parameters(E, NU)
    eps = 0.5 * (G + G.T)
    sigma = lam * np.trace(eps) * np.eye(3) + 2 * mu * eps
    volume = abs(_volumes(mesh)).sum()
    expected = 0.5 * np.sum(sigma * eps) * volume
    assert abs(0.5 * u @ (K @ u) - expected) / expected < 1e-12


def test_rejects_bad_input():
    mesh = _box((3, 3, 3))
    with pytest.raises(InputError):
        elasticity_stiffness(mesh, -1.0, NU)
    with pytest.raises(InputError):
        elasticity_stiffness(mesh, E, 0.5)
    with pytest.raises(InputError):  # wrong element
        elasticity_stiffness(mesh, E, NU, basis=skfem.Basis(mesh, skfem.ElementTetP1()))
    with pytest.raises(InputError):  # another mesh
        elasticity_stiffness(mesh, E, NU, basis=skfem.Basis(_box(), skfem.ElementTetP2()))
    with pytest.raises(InputError):  # one-point rule: not exact for the P2 gradients
        elasticity_stiffness(mesh, E, NU, basis=skfem.Basis(mesh, skfem.ElementTetP2(), intorder=1))
