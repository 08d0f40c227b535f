"""Stress recovery on the P2 sectors and the root stress of each tooth (``docs/architecture.md``:
the result model).

The displacement ``u`` of a sector is quadratic on each tetrahedron (``ElementTetP2`` on the
linear tet mesh, :mod:`fegear.fem.elasticity`), so the strain is linear on each element and
exact at any point from the element's ten nodal vectors:

.. math::

    \\nabla u(x) = \\sum_{a=1}^{10} u_a \\otimes \\nabla N_a(x), \\qquad
    \\nabla N_a = A^{-T} \\hat\\nabla N_a(\\hat x), \\qquad
    \\varepsilon = \\tfrac12(\\nabla u + \\nabla u^T), \\qquad
    \\sigma = \\lambda \\operatorname{tr}(\\varepsilon) I + 2 \\mu \\varepsilon,

with ``A = [x1 − x0, x2 − x0, x3 − x0]`` the affine map of the element (scikit-fem's
``MappingAffine``) and the reference gradients ``∇̂N_a`` taken from scikit-fem's own
``ElementTetP2.lbasis`` (so the local numbering is the one of ``basis.element_dofs``).

**Recovery at the vertices.** Each element's linear stress is evaluated at its four vertices
and the values of the elements sharing a vertex are averaged (unweighted mean: Hinton & Campbell
1974, "Local and global smoothing of discontinuous finite element functions using a least
squares method", IJNME 8; the vertex average is the lumped form of their global L2
projection). Why: the fillet maximum lies on the surface, where quadrature points (inside the
elements, a fraction of ``h`` below the surface) under-read a stress that falls steeply into
the tooth; the element's own value at a surface vertex is its linear extrapolation there, and
averaging removes most of the inter-element jump, which is of the order of the error itself.
``recovery="element"`` keeps the largest unaveraged element value at each vertex instead (an
upper reading); the refinement study (``benchmarks/bench_root_stress.py``) reports both and
measures the rate of the averaged one.

**Fillet regions** are selected geometrically: the facets of the named group ``fillet_j`` of
sector tooth ``j`` (space middle → root → generated fillet → fillet limit, on both sides of
the tooth: :mod:`fegear.mesh.sector`), split into the side of the loaded flank (the nearer of
the two flanks of the tooth, by vertex distance: the *tension* side, where the bending
moment of the contact force stretches the root) and the other side (*compression*). Per tooth
the root stress is the largest maximum principal stress ``σ1`` on the tension side, the
smallest (most compressive) minimum principal stress ``σ3`` on the compression side and the
largest von Mises stress ``σ_v = √(½((σ1−σ2)² + (σ2−σ3)² + (σ3−σ1)²))`` over both.

**Equilibrium** of each solve (:func:`reactions`): the reaction on the clamped DOFs,
``R = (K u − f)_c`` with the full (unconstrained) stiffness, balances the applied load in force
and moment about the member origin; the residual is reported relative to the applied force
(and to the applied force times the sector radius for the moment).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from fegear.errors import InputError

__all__ = [
    "CONTACT_CLEARANCE_MODULES",
    "FILLET_MODULES",
    "FilletRegion",
    "ToothRootStress",
    "Equilibrium",
    "VertexStress",
    "vertex_stress",
    "principal_stresses",
    "von_mises",
    "fillet_regions",
    "tooth_root_stress",
    "reactions",
]

Array = NDArray[np.float64]

RECOVERIES = ("average", "element")

#: Element size on the fillets of the root-stress sectors, in modules
#: (:func:`fegear.pipeline.fields.stress_sector`). The refinement study of the FZG pair
#: (``benchmarks/results/root_stress_refinement.md``: fillet sizes 0.4 m … 0.05 m, ratio √2)
#: extrapolates the tension-fillet maximum to 179.5 MPa (pinion) and 170.3 MPa (gear); with the
#: averaged recovery every level from 0.1 m on is within 2 % of that (pinion −0.6 %, gear +0.8 %
#: at 0.1 m; 0.14 m: pinion −3.4 %).
FILLET_MODULES = 0.1

#: Fillet vertices closer than this (in modules) to a loaded contact cell of their tooth are
#: not read: the contact stress of a load at the start of the active profile (FZG pinion:
#: the entering gear tip's corner contact 0.13 mm above the fillet limit) reaches the top of the
#: fillet; the bending stress peaks lower, near the 30° tangent point. Measured on the FZG pair
#: (hybrid level 0, 9 positions): 0.25 m = 1.1 mm takes the entering tooth's fillet reading from
#: 210 to 67 MPa (von Mises 486 to 64 MPa) and leaves the readings of the other positions as
#: they were.
CONTACT_CLEARANCE_MODULES = 0.25


def _reference_gradients() -> Array:
    """``(4, 10, 3)``: ``∇̂N_a`` of the ten P2 shape functions at the four reference vertices."""
    import skfem

    e = skfem.ElementTetP2()
    X = np.array([[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    return np.stack([e.lbasis(X, a)[1].T for a in range(10)], axis=1)


def _lame(E: float, nu: float) -> tuple[float, float]:
    if not (np.isfinite(E) and E > 0):
        raise InputError("E_MPa", E, "> 0")
    if not (np.isfinite(nu) and -1.0 < nu < 0.5):
        raise InputError("nu", nu, "in (-1, 0.5)")
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


class VertexStress:
    """Stress recovery at chosen vertices of one mesh (see the module docstring): set up once
    (element gradients, averaging matrix), then applied to each displacement.

    Parameters
    ----------
    points
        ``(n, 3)`` mm, mesh vertices.
    tets
        ``(m, 4)`` vertex indices.
    element_dofs
        ``(10, m)`` scalar P2 DOFs of each element (``ElementTetP2`` basis ``element_dofs``);
        the vector DOF of component ``c`` is ``3 s + c`` (scikit-fem's interleaved numbering).
    E, nu
        MPa and Poisson's ratio.
    vertices
        Vertex indices wanted (None: all); only the elements around them are evaluated.
    recovery
        ``"average"``: the mean of the values of the elements sharing the vertex;
        ``"element"``: the element value of largest maximum principal stress.
    """

    def __init__(
        self, points: Array, tets: NDArray[np.int_], element_dofs: NDArray[np.int_], E: float,
        nu: float, vertices: NDArray[np.int_] | None = None, recovery: str = "average",
    ) -> None:  # fmt: skip
        if recovery not in RECOVERIES:
            raise InputError("recovery", recovery, f"one of {RECOVERIES}")
        self.lam, self.mu = _lame(E, nu)
        self.recovery = recovery
        n = points.shape[0]
        self.vertices = np.arange(n) if vertices is None else np.asarray(vertices, np.int64)
        sel = np.zeros(n, dtype=bool)
        sel[self.vertices] = True
        self.elements = np.flatnonzero(sel[tets].any(axis=1))
        t = tets[self.elements]
        x0 = points[t[:, 0]]
        A = np.stack([points[t[:, k]] - x0 for k in (1, 2, 3)], axis=-1)  # columns x_k - x_0
        # ∇N = A^{-T} ∇̂N at the four vertices: (m', 4, 10, 3)
        self.G = np.einsum("kaj,mji->mkai", _reference_gradients(), np.linalg.inv(A))
        self.dofs = element_dofs[:, self.elements]  # (10, m')
        rows = t.ravel()  # the vertex of each (element, local vertex)
        self.keep = np.flatnonzero(sel[rows])
        where = -np.ones(n, dtype=np.int64)
        where[self.vertices] = np.arange(self.vertices.size)
        self.rows = where[rows[self.keep]]
        ones = np.ones(self.rows.size)
        M = sp.csr_matrix((ones, (self.rows, self.keep)), shape=(self.vertices.size, rows.size))
        self.M = sp.diags(1.0 / np.asarray(M.sum(axis=1)).ravel()) @ M

    def element_stress(self, u: Array) -> Array:
        """``(m', 4, 3, 3)`` MPa: each element's stress at its vertices under ``u`` (``(N,)``
        mm, full DOF numbering)."""
        Ue = np.stack([u[3 * self.dofs + c] for c in range(3)], axis=-1)  # (10, m', 3)
        grad = np.einsum("mkai,amc->mkci", self.G, Ue)  # ∂u_c/∂x_i
        eps = 0.5 * (grad + np.swapaxes(grad, -1, -2))
        tr = np.trace(eps, axis1=-2, axis2=-1)
        return 2.0 * self.mu * eps + self.lam * tr[..., None, None] * np.eye(3)

    def __call__(self, u: Array) -> Array:
        """``(k, 3, 3)`` MPa, the recovered stress at the ``k`` vertices under ``u``."""
        flat = self.element_stress(u).reshape(-1, 9)
        if self.recovery == "average":
            return (self.M @ flat).reshape(-1, 3, 3)
        vals = flat[self.keep]
        s1 = principal_stresses(vals.reshape(-1, 3, 3))[:, 2]
        order = np.lexsort((s1, self.rows))  # per vertex, the largest σ1 last
        last = np.r_[self.rows[order][1:] != self.rows[order][:-1], True]
        out = np.empty((self.vertices.size, 9))
        out[self.rows[order][last]] = vals[order][last]
        return out.reshape(-1, 3, 3)


def vertex_stress(
    points: Array, tets: NDArray[np.int_], element_dofs: NDArray[np.int_], u: Array, E: float,
    nu: float, vertices: NDArray[np.int_] | None = None, recovery: str = "average",
) -> Array:  # fmt: skip
    """Recovered stress tensors at vertices: ``(k, 3, 3)`` MPa for ``u (N,)``, ``(p, k, 3, 3)``
    for ``u (N, p)`` (:class:`VertexStress`, whose parameters these are)."""
    rec = VertexStress(points, tets, element_dofs, E, nu, vertices, recovery)
    if u.ndim == 1:
        return rec(u)
    return np.stack([rec(u[:, p]) for p in range(u.shape[1])])


def principal_stresses(sigma: Array) -> Array:
    """``(..., 3)`` principal stresses (ascending: σ3 ≤ σ2 ≤ σ1) of ``(..., 3, 3)`` tensors."""
    return np.linalg.eigvalsh(0.5 * (sigma + np.swapaxes(sigma, -1, -2)))


def von_mises(sigma: Array) -> Array:
    """``(...)`` von Mises stress ``√(3/2 s:s)`` (``s`` the deviator) of ``(..., 3, 3)``."""
    s = sigma - np.trace(sigma, axis1=-2, axis2=-1)[..., None, None] * np.eye(3) / 3.0
    return np.sqrt(1.5 * np.einsum("...ij,...ij->...", s, s))


@dataclass(frozen=True)
class FilletRegion:
    """The fillet vertices of one tooth, split by side.

    Attributes
    ----------
    tooth
        Member tooth (sector tooth ``tooth + n // 2``).
    tension, compression
        Vertex indices on the loaded-flank side and on the other side of the tooth.
    """

    tooth: int
    tension: NDArray[np.int64]
    compression: NDArray[np.int64]

    @property
    def vertices(self) -> NDArray[np.int64]:
        return np.concatenate([self.tension, self.compression])


def fillet_regions(sector, side: str, teeth: tuple[int, ...] | None = None) -> list[FilletRegion]:
    """Fillet vertices of the sector teeth ``teeth`` (sector indices; None: all but the outer
    two), each assigned to the side of the nearer flank of its tooth (see the module
    docstring). ``sector``: :class:`fegear.mesh.sector.SectorMesh`; ``side``: the loaded
    flank (``"drive"`` or ``"coast"``)."""
    from scipy.spatial import cKDTree

    other = {"drive": "coast", "coast": "drive"}.get(side)
    if other is None:
        raise InputError("side", side, "'drive' or 'coast'")
    n = sector.n_teeth
    teeth = tuple(range(1, n - 1) if n >= 3 else range(n)) if teeth is None else teeth
    out = []
    for t in teeth:
        nodes = sector.boundary_nodes(f"fillet_{t}")
        x = sector.points[nodes]
        d_load = cKDTree(sector.points[sector.boundary_nodes(f"flank_{side}_{t}")]).query(x)[0]
        d_other = cKDTree(sector.points[sector.boundary_nodes(f"flank_{other}_{t}")]).query(x)[0]
        near = d_load <= d_other
        out.append(FilletRegion(t - sector.centre_tooth, nodes[near], nodes[~near]))
    return out


@dataclass(frozen=True)
class ToothRootStress:
    """Root stress of one tooth at one position (MPa; points in the member frame, mm).

    Attributes
    ----------
    tooth
        Member tooth.
    loaded
        The tooth carries contact force at this position.
    tension_MPa, tension_point
        Largest maximum principal stress σ1 in the fillet on the loaded-flank side, where.
    compression_MPa, compression_point
        Smallest minimum principal stress σ3 (most compressive, negative) on the other side.
    von_mises_MPa, von_mises_point
        Largest von Mises stress in both fillets, where.
    """

    tooth: int
    loaded: bool
    tension_MPa: float
    tension_point: tuple[float, float, float]
    compression_MPa: float
    compression_point: tuple[float, float, float]
    von_mises_MPa: float
    von_mises_point: tuple[float, float, float]


def tooth_root_stress(
    points: Array,
    region: FilletRegion,
    sigma: Array,
    loaded: bool,
    contact: Array | None = None,
    clearance_mm: float = 0.0,
) -> ToothRootStress:
    """:class:`ToothRootStress` of ``region`` from the recovered vertex stresses ``sigma``
    (``(n, 3, 3)`` MPa, ``sigma[i]`` the stress at vertex ``i`` of ``points``).

    ``contact``: ``(q, 3)`` mm, the loaded contact cells on this tooth (member frame); the
    fillet vertices closer than ``clearance_mm`` to one of them are left out (a contact at the
    start of the active profile, just above the fillet limit, puts its own local stress
    there: see :data:`CONTACT_CLEARANCE_MODULES`). If that leaves a side empty, it is kept
    whole."""
    from scipy.spatial import cKDTree

    t, c = region.tension, region.compression
    if contact is not None and len(contact) and clearance_mm > 0.0:
        tree = cKDTree(np.asarray(contact, dtype=float).reshape(-1, 3))
        far_t = tree.query(points[t])[0] > clearance_mm
        far_c = tree.query(points[c])[0] > clearance_mm
        t = t[far_t] if far_t.any() else t
        c = c[far_c] if far_c.any() else c
        region = FilletRegion(region.tooth, t, c)
    s1 = principal_stresses(sigma[t])[:, 2]
    s3 = principal_stresses(sigma[c])[:, 0]
    allv = region.vertices
    vm = von_mises(sigma[allv])
    it, ic, iv = t[np.argmax(s1)], c[np.argmin(s3)], allv[np.argmax(vm)]

    def pt(i: int) -> tuple[float, float, float]:
        return tuple(float(v) for v in points[i])  # type: ignore[return-value]

    return ToothRootStress(
        tooth=region.tooth,
        loaded=bool(loaded),
        tension_MPa=float(s1.max()),
        tension_point=pt(it),
        compression_MPa=float(s3.min()),
        compression_point=pt(ic),
        von_mises_MPa=float(vm.max()),
        von_mises_point=pt(iv),
    )


@dataclass(frozen=True)
class Equilibrium:
    """Reaction at the clamped DOFs against the applied load of one solve.

    Attributes
    ----------
    applied_N, reaction_N
        ``(3,)`` resultant of the applied load and of the reactions (N).
    force_residual
        ``|applied + reaction| / |applied|``.
    moment_residual
        ``|M_applied + M_reaction| / (|applied| r)`` (moments about the member origin,
        ``r`` the largest distance of a loaded DOF from it).
    """

    applied_N: Array
    reaction_N: Array
    force_residual: float
    moment_residual: float


def reactions(
    K_full: sp.spmatrix, doflocs: Array, fixed: NDArray[np.int_], u: Array, f: Array
) -> Equilibrium:
    """Equilibrium of one solve: ``R = (K u − f)`` on the ``fixed`` DOFs against ``f``.

    Parameters
    ----------
    K_full
        ``(N, N)`` N/mm, stiffness without the Dirichlet conditions.
    doflocs
        ``(3, N)`` mm, the location of each DOF (``basis.doflocs``).
    fixed
        Clamped DOFs.
    u, f
        ``(N,)`` mm and N, displacement and applied nodal load (full numbering).
    """
    r = np.zeros_like(u)
    r[fixed] = (K_full @ u - f)[fixed]
    x = doflocs.T[0::3]  # (N/3, 3): DOFs 3 s + c of one node share its location

    def resultant(v: Array) -> tuple[Array, Array]:
        vec = v.reshape(-1, 3)
        return vec.sum(axis=0), np.cross(x, vec).sum(axis=0)

    Fa, Ma = resultant(f)
    Fr, Mr = resultant(r)
    scale = float(np.linalg.norm(Fa))
    if scale == 0.0:
        return Equilibrium(Fa, Fr, 0.0, 0.0)
    loaded = np.flatnonzero(np.any(f.reshape(-1, 3) != 0.0, axis=1))
    arm = float(np.max(np.linalg.norm(x[loaded], axis=1)))
    return Equilibrium(
        applied_N=Fa,
        reaction_N=Fr,
        force_residual=float(np.linalg.norm(Fa + Fr) / scale),
        moment_residual=float(np.linalg.norm(Ma + Mr) / (scale * arm)),
    )
