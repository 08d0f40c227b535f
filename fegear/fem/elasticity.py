"""Linear elasticity of one body with scikit-fem: quadratic tetrahedra on a linear tet mesh.

The body is a :class:`skfem.MeshTet` of linear tetrahedra (gmsh order 1, so the named boundary
facets survive the import) with the quadratic vector element ``ElementVector(ElementTetP2())``:
the mid-edge nodes sit on the straight edges. The stiffness is the standard bilinear form of
isotropic linear elasticity (scikit-fem ``models.elasticity.linear_elasticity``), assembled by the
vectorised :func:`fegear.fem.assembly.elasticity_stiffness` on scikit-fem's basis data (the same
matrix to 1e-15, 40-60 times faster at 60k-200k DOFs: ``benchmarks/bench_assembly.py``)

.. math::

    a(u, v) = \\int_\\Omega 2\\mu\\,\\varepsilon(u):\\varepsilon(v) + \\lambda\\,
        \\operatorname{div} u \\operatorname{div} v \\; dx,
    \\qquad \\lambda = \\frac{E\\nu}{(1+\\nu)(1-2\\nu)},\\; \\mu = \\frac{E}{2(1+\\nu)} .

Degrees of freedom are numbered ``3 * scalar_dof + component`` (scikit-fem's interleaved vector
numbering, checked in the tests). Dirichlet conditions are given as sets of clamped DOFs; the
reduced matrix on the free DOFs is what the compliance needs.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import skfem

from fegear.errors import InputError
from fegear.fem.assembly import elasticity_stiffness

__all__ = ["ElasticBody", "assemble_body", "boundary_dofs"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ElasticBody:
    """An assembled elastic body with its clamped DOFs removed.

    Attributes
    ----------
    mesh
        The linear tetrahedral mesh (mm) with named boundaries.
    basis
        ``skfem.Basis`` of ``ElementVector(ElementTetP2())`` on ``mesh``.
    scalar_basis
        ``skfem.Basis`` of ``ElementTetP2()`` (the scalar DOF numbering).
    K
        (n_free, n_free) CSR stiffness (N/mm) on the free DOFs, assembled on first use (a run
        whose compliance operator is cached never needs it).
    free
        (n_free,) indices of the free DOFs in the full numbering.
    E, nu
        Young's modulus (MPa) and Poisson's ratio.
    """

    mesh: skfem.MeshTet
    basis: skfem.Basis
    scalar_basis: skfem.Basis
    free: np.ndarray
    E: float
    nu: float
    _timing: dict[str, float] = field(default_factory=dict, repr=False, compare=False)

    @cached_property
    def K(self) -> sp.csr_matrix:  # noqa: N802 (the stiffness matrix is K)
        """Stiffness on the free DOFs (N/mm), assembled once."""
        t0 = time.perf_counter()
        K = elasticity_stiffness(self.mesh, self.E, self.nu)
        Kf = K[self.free][:, self.free].tocsr()
        self._timing["assembly"] = time.perf_counter() - t0
        log.info(
            "assembled %d DOFs (%d free) in %.2f s",
            self.basis.N,
            self.free.size,
            self._timing["assembly"],
        )
        return Kf

    @property
    def assembly_seconds(self) -> float:
        """Wall time of the stiffness assembly (0 if it was never needed)."""
        return self._timing.get("assembly", 0.0)

    @property
    def n_dofs(self) -> int:
        """Number of DOFs before the Dirichlet conditions."""
        return int(self.basis.N)


def boundary_dofs(basis: skfem.Basis, boundary: str, components: str = "xyz") -> np.ndarray:
    """Vector DOFs (full numbering) of the nodes on a named boundary, for the given components."""
    mesh = basis.mesh
    if boundary not in (mesh.boundaries or {}):
        raise InputError("boundary", boundary, f"one of {sorted(mesh.boundaries or {})}")
    facets = mesh.boundaries[boundary]
    dofs = basis.get_dofs(facets)
    out = []
    for c in components:
        key = "u^" + str("xyz".index(c) + 1)
        out.append(dofs.nodal[key])
        if key in dofs.facet:
            out.append(dofs.facet[key])
        if key in dofs.edge:
            out.append(dofs.edge[key])
    return np.unique(np.concatenate(out))


def assemble_body(
    mesh: skfem.MeshTet, E: float, nu: float, clamped: list[tuple[str, str]]
) -> ElasticBody:
    """Set up a body: its P2 bases and free DOFs (the stiffness is assembled on first use).

    Parameters
    ----------
    mesh
        Linear tet mesh in mm with named boundaries.
    E, nu
        Young's modulus (MPa, > 0) and Poisson's ratio (in (-1, 0.5)).
    clamped
        ``[(boundary name, components)]``, e.g. ``[("bottom", "xyz"), ("sym_x", "x")]``.
    """
    if not (np.isfinite(E) and E > 0):
        raise InputError("E_MPa", E, "> 0")
    if not (np.isfinite(nu) and -1.0 < nu < 0.5):
        raise InputError("nu", nu, "in (-1, 0.5)")
    # The bases serve DOF numbering and shape functions only (the stiffness has its own exact
    # degree-2 rule), so the cheapest quadrature will do: one point (the basis tables skfem
    # builds at its quadrature points took 0.17 s of the 0.58 s a warm face-gear run spent on
    # its two models with the 4-point rule).
    basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()), intorder=1)
    scalar = skfem.Basis(mesh, skfem.ElementTetP2(), quadrature=basis.quadrature)
    fixed = np.unique(
        np.concatenate([boundary_dofs(basis, name, comps) for name, comps in clamped])
        if clamped
        else np.zeros(0, dtype=np.int64)
    )
    free = np.setdiff1d(np.arange(basis.N), fixed)
    return ElasticBody(
        mesh=mesh, basis=basis, scalar_basis=scalar, free=free, E=float(E), nu=float(nu)
    )
