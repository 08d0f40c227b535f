"""The compliance operator on the normal DOFs of surface nodes.

:func:`fegear.mechanics.compliance.candidate_operator` with ``normals``.

A P2 block clamped at its base, loaded on its top face by cells of uniform pressure. With the
normal basis the operator keeps, at each top node, only the displacement along the node's normal
under a force along it (``docs/ltca/normal_operator.md``):

* it is the same body: its entries are ``n_sᵀ (K⁻¹)_{st} n_t`` of the Cartesian inverse;
* on a flat face, where every cell force is along the normals, the influence matrix is the
  Cartesian one (nothing is dropped);
* on a curved face the dropped tangential parts make a difference that vanishes as the
  curvature does, at least linearly in ``h / R``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp
import skfem

from fegear.errors import InputError
from fegear.fem.elasticity import assemble_body
from fegear.mechanics.compliance import (
    body_compliance,
    boundary_normals,
    candidate_operator,
    load_operator,
)

# Two direct solves of the same SPD system (condition ~1e5) agree to ~1e-12 relative.
TOL_SOLVE = 1e-9


def _block(radius: float | None, n: int = 6) -> skfem.MeshTet:
    """A 10 x 10 x 6 mm block, clamped face z = 0 ("base"), loaded face on top ("top"); with
    ``radius``, the top is bent into the cylinder ``z = 6 - x² / (2R)`` (the mesh follows)."""
    mesh = skfem.MeshTet.init_tensor(
        np.linspace(-5.0, 5.0, n + 1), np.linspace(-5.0, 5.0, n + 1), np.linspace(0.0, 6.0, 5)
    ).with_boundaries(
        {"base": lambda x: np.isclose(x[2], 0.0), "top": lambda x: np.isclose(x[2], 6.0)}
    )
    if radius is None:
        return mesh
    p = mesh.p.copy()
    p[2] -= (p[2] / 6.0) * p[0] ** 2 / (2.0 * radius)
    return replace(mesh, doflocs=p)


def _top_cells(radius: float | None, m: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """``m x m`` cells of 1 mm around the centre of the top face: 2 x 2 quadrature points each
    on the surface (mm) and the surface's inward normal at the cell centre (the force
    direction on the body), as a contact cell has them."""
    g = (np.arange(m) - (m - 1) / 2.0) * 1.0
    xc, yc = np.meshgrid(g, g, indexing="ij")
    xc, yc = xc.ravel(), yc.ravel()
    off = np.array([[-0.25, -0.25], [0.25, -0.25], [-0.25, 0.25], [0.25, 0.25]])
    x = xc[:, None] + off[None, :, 0]
    y = yc[:, None] + off[None, :, 1]
    curv = 0.0 if radius is None else 1.0 / radius
    z = 6.0 - 0.5 * curv * x**2
    pts = np.stack([x, y, z], axis=-1)
    slope = -curv * xc  # dz/dx at the centre
    outward = np.column_stack([-slope, np.zeros_like(slope), np.ones_like(slope)])
    outward /= np.linalg.norm(outward, axis=1, keepdims=True)
    return pts, -outward


def _operators(radius: float | None):
    mesh = _block(radius)
    body = assemble_body(mesh, 206000.0, 0.3, [("base", "xyz")])
    pts, e = _top_cells(radius)
    P = load_operator(body, "top", pts, np.full(pts.shape[:2], 0.25), e)
    facets = mesh.boundaries["top"]
    dofs = body.basis.get_dofs(facets).all()
    cart = candidate_operator(body, dofs, "superlu")
    turned = candidate_operator(body, dofs, "superlu", normals=boundary_normals(mesh, facets))
    return body, P, cart, turned


def test_turned_operator_is_the_same_body() -> None:
    """G'_st = n_sᵀ (K⁻¹)_st n_t: the turned basis changes the DOFs, not the body."""
    body, _, cart, turned = _operators(20.0)
    s, n = boundary_normals(body.mesh, body.mesh.boundaries["top"])
    G = cart.G  # Cartesian (K⁻¹)_cc on all top DOFs
    pos = {int(d): i for i, d in enumerate(cart.dofs)}
    nodes = turned.cols // 3
    k = np.searchsorted(s, nodes)
    blocks = np.array([[pos[int(3 * v + a)] for a in range(3)] for v in nodes])  # (p, 3)
    expect = np.einsum(
        "ia,iajb,jb->ij", n[k], G[blocks[:, :, None, None], blocks[None, None]], n[k]
    )
    assert turned.G.shape == (nodes.size, nodes.size)
    assert np.allclose(turned.G, expect, rtol=0, atol=TOL_SOLVE * np.abs(expect).max())
    # the tangential DOFs are neither loaded nor read
    assert np.intersect1d(turned.cols, turned.tangential).size == 0
    assert turned.tangential.size == 2 * nodes.size


def test_flat_face_loses_nothing() -> None:
    """Forces along the normals of a flat face have no tangential part to drop."""
    _, P, cart, turned = _operators(None)
    C_cart = body_compliance(cart, P)
    C_turned = body_compliance(turned, P)
    assert np.allclose(C_turned, C_cart, rtol=0, atol=TOL_SOLVE * np.abs(C_cart).max())


def test_curved_face_difference_vanishes_with_curvature() -> None:
    """On a bent face the nodes' normals turn within a cell by ~h/R: the influence matrix moves
    by a fraction that falls linearly with 1/R (fitted over R = 10, 40, 160 mm)."""
    radii = np.array([10.0, 40.0, 160.0])
    diff = []
    for R in radii:
        _, P, cart, turned = _operators(float(R))
        C_cart = body_compliance(cart, P)
        C_turned = body_compliance(turned, P)
        diff.append(np.linalg.norm(C_turned - C_cart) / np.linalg.norm(C_cart))
    diff = np.array(diff)
    rate = -np.polyfit(np.log(radii), np.log(diff), 1)[0]
    # first order in h/R: measured 0.91 here, tending to 1 from below (0.95 between 160 and
    # 320 mm) as the bending of the block's own mesh fades; 0.85 leaves the fit's scatter
    assert rate >= 0.85, (diff, rate)
    # h / R = 1.7 / 10, a tighter bend than any flank's: the matrix moves by 0.2 %
    assert diff[0] < 1e-2, diff


def test_projection_is_scipys_product_bit_for_bit() -> None:
    """:meth:`CandidateOperator.project` forms ``T M`` on ``M``'s stored entries only, in
    SciPy's order: the same entries, the same bits, as ``T @ M`` (the loads in CSR and CSC,
    a block of their columns, a column with one force, and a load with cancelling terms)."""
    _, P, _, turned = _operators(20.0)
    T = turned.projection
    f = np.zeros(P.shape[1])
    f[[1, 5]] = [1.0, -1.0]
    Pc = P.tocsc()
    cases = [
        P,
        Pc,
        Pc[:, 3:9],
        sp.csc_matrix(P @ f[:, None]),
        sp.csc_matrix(Pc[:, [2]] - Pc[:, [2]]),
    ]
    for M in cases:
        want = sp.csc_matrix(T @ M)
        got = turned.project(M)
        assert got.shape == want.shape
        np.testing.assert_array_equal(got.indptr, want.indptr)
        np.testing.assert_array_equal(got.indices, want.indices)
        np.testing.assert_array_equal(got.data.view(np.int64), want.data.view(np.int64))


def test_normals_refused_on_partly_clamped_nodes() -> None:
    """A node clamped in one direction only has no normal DOF of its own."""
    mesh = _block(None)
    body = assemble_body(mesh, 206000.0, 0.3, [("base", "z")])
    facets = mesh.boundaries["base"]
    dofs = body.basis.get_dofs(facets).all()
    with pytest.raises(InputError, match="normals"):
        candidate_operator(body, dofs, "superlu", normals=boundary_normals(mesh, facets))
