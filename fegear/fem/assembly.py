"""Fast assembly of the P2 linear-elasticity stiffness on affine tetrahedra.

:func:`elasticity_stiffness` returns the same matrix as the stock scikit-fem assembly
``skfem.asm(linear_elasticity(lam, mu), Basis(mesh, ElementVector(ElementTetP2())))``, with the
same DOF numbering, in a fraction of the time. scikit-fem stays the FE engine: the mesh, the
element, the DOF numbering, the reference-to-physical mapping, the quadrature and the basis
gradients all come from a scikit-fem :class:`~skfem.assembly.Basis`; only the loop over the
30 × 30 local index pairs (one Python-level form evaluation per pair in stock scikit-fem) is
replaced by batched dense algebra over the elements.

The maths
---------
The bilinear form of isotropic linear elasticity (scikit-fem
``skfem.models.elasticity.linear_elasticity``; Hughes, *The Finite Element Method*, §2.7) is

.. math::

    a(u, v) = \\int_\\Omega \\lambda\\, \\operatorname{div} u\\, \\operatorname{div} v
        + 2\\mu\\, \\varepsilon(u) : \\varepsilon(v)\\; dx ,
    \\qquad \\lambda = \\frac{E\\nu}{(1+\\nu)(1-2\\nu)},\\quad \\mu = \\frac{E}{2(1+\\nu)} ,

the Lamé form of :math:`\\varepsilon(v) : C : \\varepsilon(u)` with
:math:`C_{abcd} = \\lambda\\delta_{ab}\\delta_{cd} + \\mu(\\delta_{ac}\\delta_{bd} +
\\delta_{ad}\\delta_{bc})` (in Voigt notation this is :math:`B^T D B`, Hughes §3.10).
With the vector shape functions :math:`\\phi_i e_a` (scalar P2 function :math:`\\phi_i`,
component :math:`a`) and :math:`g_i = \\nabla\\phi_i`, the element block is

.. math::

    K^e_{ia,jb} = \\int_{T} \\lambda\\, g_i^a g_j^b + \\mu\\, g_i^b g_j^a
        + \\mu\\, \\delta_{ab}\\, g_i \\cdot g_j \\; dx
      = \\lambda M_{ia,jb} + \\mu M_{ib,ja} + \\mu\\,\\delta_{ab} \\textstyle\\sum_c M_{ic,jc},
    \\qquad M_{ia,jb} = \\int_T g_i^a g_j^b\\, dx ,

so the per-element Gram matrix :math:`M = A^T W A` (``A`` the (n_qp, 30) table of
:math:`g_i^a` at the quadrature points, ``W`` the weights × |det J|) gives the whole element
matrix. It is formed, batched over elements, as its six 10 × 10 component blocks
:math:`M_{ab}` (a <= b) with :math:`M_{ba} = M_{ab}^T`, each summed over the points as
:math:`\\sum_q s_q (r_q g_i^a)(r_q g_j^b)` with :math:`r_q = \\sqrt{|W_q|}` and
:math:`s_q = \\operatorname{sign} W_q`,
so the assembled ``K`` is bitwise symmetric (stock scikit-fem's is symmetric only to rounding).

Quadrature
----------
On an affine tetrahedron the P2 gradients are linear, so the integrand :math:`g_i^a g_j^b` is a
quadratic polynomial and any rule exact for degree 2 integrates it exactly. scikit-fem's default
``intorder = 2 * maxdeg = 4`` for P2 selects the 11-point degree-4 Keast rule (with one negative
weight) for ``ElementVector(ElementTetP2())``; this module uses, when it builds its own basis,
``intorder=2``: the 4-point degree-2 rule (points at barycentric (a, b, b, b) with
a = (5 + 3√5)/20, b = (5 − √5)/20, weights |T|/4), which is exact and 11/4 times cheaper. The
two rules give the same matrix up to rounding (≈ 1e-15 relative). A caller-supplied basis is
accepted with any rule that is exact for quadratics (checked on the reference tetrahedron).

Sparsity
--------
The result is the full 3 × 3-block pattern of the scalar P2 couplings (built as a BSR matrix on
the scalar pattern, then converted to CSR with sorted indices). The stock assembly drops the
local entries that are exactly zero before summing (``COOData._assemble_scipy_csr`` calls
``eliminate_zeros`` on the COO data), so its pattern is a subset of this one that depends on
rounding; the values agree to rounding everywhere (the extra entries are 0 or round-off).

Sources: scikit-fem documentation (``Basis``, ``ElementVector``, ``models.elasticity``,
``skfem.quadrature.get_quadrature_tet``), https://scikit-fem.readthedocs.io; T. J. R. Hughes,
*The Finite Element Method: Linear Static and Dynamic Finite Element Analysis*, Dover 2000,
§2.7 (elastostatics: the weak form and the Lamé/Voigt constitutive matrix) and §3.10
(tetrahedral elements, their quadrature and element stiffness ``B^T D B``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
import skfem
from skfem.models.elasticity import lame_parameters

from fegear.errors import InputError

__all__ = ["elasticity_stiffness"]

#: Elements per group of the scatter: the element blocks of a group (7.2 kB per element) are
#: buffered and summed into the global blocks together, so ~0.14 GB at the default.
DEFAULT_CHUNK = 20_000
#: Elements per batch of the element-block computation (cache-sized temporaries).
_BATCH = 2048


def _check_quadrature_exact(X: np.ndarray, W: np.ndarray) -> None:
    """Raise if the reference rule (X, W) does not integrate quadratics exactly on the tet."""
    lam = np.vstack((1.0 - X.sum(axis=0), X))  # barycentric coordinates, (4, nqp)
    # exact: int lam_a lam_b over the reference tet = (1 + delta_ab) / 120
    exact = (np.ones((4, 4)) + np.eye(4)) / 120.0
    got = np.einsum("aq,bq,q->ab", lam, lam, W)
    if not (np.allclose(got, exact, rtol=1e-12, atol=1e-14) and np.isclose(W.sum(), 1 / 6)):
        raise InputError(
            "basis.quadrature", f"{W.size}-point rule", "exact for degree-2 polynomials"
        )


def _scalar_view(basis: skfem.Basis, mesh: skfem.MeshTet) -> tuple[np.ndarray, Callable]:
    """Scalar P2 element DOFs (10, nel) of a basis and a getter of its gradient table.

    The getter maps an element slice to the (3, nel_chunk, nqp, 10) table of the scalar P2
    gradients (physical direction a, element, quadrature point, local scalar function i).
    """
    if basis.mesh is not mesh:
        raise InputError("basis.mesh", type(basis.mesh).__name__, "the mesh being assembled")
    elem = basis.elem
    if isinstance(elem, skfem.ElementTetP2):
        dofs = basis.element_dofs
        fields = [basis.basis[i][0].grad for i in range(10)]
    elif isinstance(elem, skfem.ElementVector) and isinstance(elem.elem, skfem.ElementTetP2):
        if elem.dim != 3:
            raise InputError("basis.elem", f"ElementVector of dim {elem.dim}", "dim 3")
        # local vector function 3 i + c is phi_i e_c, global DOF 3 * scalar + c (interleaved)
        dofs = basis.element_dofs[0::3] // 3
        fields = [basis.basis[3 * i][0].grad[0] for i in range(10)]
    else:
        raise InputError(
            "basis.elem", type(elem).__name__, "ElementTetP2 or ElementVector(ElementTetP2())"
        )
    _check_quadrature_exact(*basis.quadrature)

    def table(sl: slice) -> np.ndarray:
        return np.stack([g[:, sl, :] for g in fields], axis=-1)

    return dofs, table


def _element_blocks(G: np.ndarray, dx: np.ndarray, lam: float, mu: float, out: np.ndarray) -> None:
    """Element stiffness blocks of one batch, by component: out[3 a + b, e, i, j] = K[e, ia, jb].

    ``G`` (3, nc, nqp, 10) scalar gradients, ``dx`` (nc, nqp) weights × |det J|. The Gram
    matrices M_ab[e, i, j] = sum_q dx g_i^a g_j^b are summed as sum_q s_q (r_q g_i^a)(r_q g_j^b)
    with r = sqrt|dx|, s = sign dx, so M_aa is bitwise symmetric; only a <= b is computed and
    K_ba = K_ab^T is copied, so the assembled matrix is bitwise symmetric.
    """
    nc, nq = dx.shape
    H = G * np.sqrt(np.abs(dx))[None, :, :, None]  # (3, nc, nqp, 10)
    negative = dx < 0
    H = np.ascontiguousarray(H.transpose(0, 2, 1, 3))  # (3, nqp, nc, 10)
    M = {}
    p = np.empty((nc, 10, 10))
    for a in range(3):
        for b in range(a, 3):
            acc = np.zeros((nc, 10, 10))
            for q in range(nq):
                np.multiply(H[a, q][:, :, None], H[b, q][:, None, :], out=p)
                if negative[:, q].any():
                    p[negative[:, q]] *= -1.0
                acc += p
            M[a, b] = acc
    S = M[0, 0] + M[1, 1] + M[2, 2]
    for a in range(3):
        np.multiply(M[a, a], lam + mu, out=out[4 * a])
        out[4 * a] += mu * S
        for b in range(a + 1, 3):
            # K_ab[i, j] = lam M_ab[i, j] + mu M_ba[i, j],  M_ba = M_ab^T
            Kab = out[3 * a + b]
            np.multiply(M[a, b], lam, out=Kab)
            Kab += mu * M[a, b].transpose(0, 2, 1)
            out[3 * b + a] = Kab.transpose(0, 2, 1)


def elasticity_stiffness(
    mesh: skfem.MeshTet,
    E: float,
    nu: float,
    basis: skfem.Basis | None = None,
    *,
    chunk: int = DEFAULT_CHUNK,
) -> sp.csr_matrix:
    """Stiffness of isotropic linear elasticity with P2 vector elements on a linear tet mesh.

    The same matrix (to rounding, ≈ 1e-15 relative) and the same DOF numbering
    (``3 * scalar_dof + component``) as
    ``skfem.asm(linear_elasticity(*lame_parameters(E, nu)),
    Basis(mesh, ElementVector(ElementTetP2())))``; see the module docstring for the maths.

    Parameters
    ----------
    mesh
        Linear (affine) tetrahedral mesh.
    E, nu
        Young's modulus (> 0) and Poisson's ratio (in (-1, 0.5)).
    basis
        Optional existing scikit-fem basis on ``mesh`` to take the gradients, weights and DOF
        numbering from: either ``Basis(mesh, ElementTetP2())`` or
        ``Basis(mesh, ElementVector(ElementTetP2()))``, with a quadrature exact for degree 2
        (scikit-fem's default is). If ``None``, ``Basis(mesh, ElementTetP2(), intorder=2)``
        (the 4-point rule) is built. A basis restricted to a subset of elements
        (``elements=``) assembles over that subset only.
    chunk
        Elements per group of the scatter into the global matrix (bounds the temporaries to
        about 7.2 kB per element of a group, plus the 0.8 kB per element of the pattern).

    Returns
    -------
    (3 N, 3 N) CSR matrix with sorted indices, N the number of scalar P2 DOFs.
    """
    if not (np.isfinite(E) and E > 0):
        raise InputError("E", E, "> 0")
    if not (np.isfinite(nu) and -1.0 < nu < 0.5):
        raise InputError("nu", nu, "in (-1, 0.5)")
    if chunk < 1:
        raise InputError("chunk", chunk, ">= 1")
    lam, mu = lame_parameters(E, nu)
    if basis is None:
        basis = skfem.Basis(mesh, skfem.ElementTetP2(), intorder=2)
    dofs, table = _scalar_view(basis, mesh)
    n_scalar = int(basis.N if isinstance(basis.elem, skfem.ElementTetP2) else basis.N // 3)
    nel = dofs.shape[1]
    if nel == 0:
        return sp.csr_matrix((3 * n_scalar, 3 * n_scalar))
    dx = basis.dx  # (nel, nqp): quadrature weight * |det J|

    # Scalar block pattern: unique (row, col) pairs of the 10 x 10 element couplings, element
    # by element, and for every local pair its block index (inverse).
    d = dofs.T.astype(np.int64)  # (nel, 10)
    keys = (d[:, :, None] * n_scalar + d[:, None, :]).ravel()  # (nel * 100,)
    ukeys, inv = np.unique(keys, return_inverse=True)
    del keys, d
    nblocks = ukeys.size
    blocks = np.zeros((9, nblocks))
    group = min(chunk, nel)
    buf = np.empty((9, group, 10, 10))
    for g0 in range(0, nel, group):
        g1 = min(g0 + group, nel)
        for b0 in range(g0, g1, _BATCH):
            b1 = min(b0 + _BATCH, g1)
            sl = slice(b0, b1)
            _element_blocks(table(sl), dx[sl], lam, mu, buf[:, b0 - g0 : b1 - g0])
        ix = inv[100 * g0 : 100 * g1]
        flat = buf[:, : g1 - g0].reshape(9, -1)
        for c in range(9):
            blocks[c] += np.bincount(ix, weights=flat[c], minlength=nblocks)

    brow = ukeys // n_scalar
    bcol = ukeys - brow * n_scalar
    indptr = np.zeros(n_scalar + 1, dtype=np.int64)
    np.cumsum(np.bincount(brow, minlength=n_scalar), out=indptr[1:])
    data = np.ascontiguousarray(blocks.T).reshape(nblocks, 3, 3)
    Kb = sp.bsr_matrix((data, bcol, indptr), shape=(3 * n_scalar, 3 * n_scalar))
    out = Kb.tocsr()
    out.sort_indices()
    return out
