"""FE compliance of the two members of a gear pair, computed once per sector.

Each member is a sector of ``n`` teeth (:mod:`fegear.mesh.sector`) in its own frame, clamped at the
bore (or the face-gear base) and at both sector cuts. The candidate DOFs are all DOFs of the
nodes on the working flanks of the teeth that can engage (and, for ``hybrid``, of a layer below
them, read but never loaded: the operator keeps only the flank columns): the flank points move
with the teeth, so one Schur complement (``(K⁻¹)_cc``) serves every mesh position and every
torque (:func:`fegear.mechanics.compliance.candidate_operator`, cached on disk by content hash). A
mesh position then costs only locating its cells on the flank facets (sparse ``P``) and
``C = Pᵀ G P``.

Tooth numbering: member tooth ``k`` is sector tooth ``k + n // 2`` (the sector's centre tooth is
member tooth 0); a pair whose tooth falls outside the sector cannot be modelled and is reported.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from fegear.errors import InputError
from fegear.fem.elasticity import ElasticBody, assemble_body
from fegear.geometry.transforms import apply_points, apply_vectors, inverse
from fegear.mechanics.compliance import (
    CandidateOperator,
    body_compliance,
    boundary_normals,
    candidate_operator,
    find_tets,
    load_operator,
    outward_facet_normals,
    prepare_locators,
)
from fegear.mesh.sector import SectorMesh
from fegear.store.cache import cached_file

__all__ = [
    "MemberModel",
    "build_member_model",
    "member_load_operator",
    "member_compliance",
    "cell_load_operators",
]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class MemberModel:
    """One member's FE model over its potential-contact flanks.

    Attributes
    ----------
    name
        Member name.
    sector
        The sector mesh (member frame).
    body
        The elastic body (bases, free DOFs; stiffness assembled only when the operator is built).
    op
        ``(K⁻¹)_cf``: rows on the DOFs of the working flanks of the sector teeth (and the layer),
        columns on the flank DOFs.
    side
        Working flank side ("drive" or "coast").
    layer_mm
        Depth below the working flanks whose DOFs are in the operator too (the ``hybrid``
        fidelity reads the FE displacement at a matching depth); 0 for ``fe`` and ``hertz``.
    layer_tets
        ``(n_tets,)`` bool, the tetrahedra whose DOFs are all in ``op`` (the layer), or None.
    teeth
        Sector teeth whose working flank (and layer) DOFs are in ``op``; None: all.
    """

    name: str
    sector: SectorMesh
    body: ElasticBody
    op: CandidateOperator
    side: str
    layer_mm: float = 0.0
    layer_tets: np.ndarray | None = None
    teeth: tuple[int, ...] | None = None

    def boundary_of(self, tooth: int) -> str:
        """Boundary name of member tooth ``tooth``'s working flank in the sector."""
        t = tooth + self.sector.centre_tooth
        if not 0 <= t < self.sector.n_teeth:
            raise InputError("tooth", tooth, f"within the sector's {self.sector.n_teeth} teeth")
        return f"flank_{self.side}_{t}"

    def has_tooth(self, tooth: int) -> bool:
        """Member tooth ``tooth`` is in the sector and its flank in the operator."""
        t = tooth + self.sector.centre_tooth
        return 0 <= t < self.sector.n_teeth and (self.teeth is None or t in self.teeth)

    def prepare(self) -> None:
        """Build the lazily made structures every mesh position reads: the point locators of
        the mesh and of the working flanks in the operator
        (:func:`fegear.mechanics.compliance.prepare_locators`), the operator's row and column
        maps and its projection's columns.
        Called by a process before it forks the workers that solve the positions (each would
        otherwise build its own); the positions' numbers do not change."""
        teeth = range(self.sector.n_teeth) if self.teeth is None else self.teeth
        prepare_locators(self.body.mesh, [f"flank_{self.side}_{t}" for t in teeth])
        _ = self.op._row_map, self.op._col_maps
        if self.op.projection is not None:
            _ = self.op._projection_columns


def build_member_model(
    name: str,
    sector: SectorMesh,
    side: str,
    E: float,
    nu: float,
    backend: str = "auto",
    layer_mm: float = 0.0,
    teeth: tuple[int, ...] | None = None,
) -> MemberModel:
    """Assemble a sector and compute ``(K⁻¹)_cc`` on the working-flank DOFs of the sector
    teeth ``teeth`` (None: all; the teeth that can carry load, :func:`fegear.ltca.build_models`:
    the dense operator costs the cube of its size) and, with ``layer_mm > 0``, on the DOFs of
    the tetrahedra down to that depth below them.

    The operator is cached as blocks
    (:func:`fegear.mechanics.compliance.candidate_operator`): the flank block ``(K⁻¹)_ff`` of
    all those teeth (every fidelity reads it), and with a layer one block ``(K⁻¹)_{l_t f_t}``
    per tooth ``t`` (or one for all teeth where their layers meet)."""
    mesh = sector.to_skfem()
    support = "base" if "base" in mesh.boundaries else "bore"
    clamped = [(support, "xyz"), ("cut_left", "xyz"), ("cut_right", "xyz")]
    body = assemble_body(mesh, E, nu, clamped)
    teeth = tuple(range(sector.n_teeth)) if teeth is None else tuple(sorted(teeth))
    flanks = [f"flank_{side}_{t}" for t in teeth]
    # the whole working flank of each tooth that can touch: a load that closes more of it than
    # the TCA's zone (g_max grows with the lag) stays on the operator
    per_tooth = [np.sort(mesh.boundaries[f]) for f in flanks]
    facets = np.concatenate(per_tooth)
    dofs = _facet_dofs(body.basis, facets)
    # what the operator blocks depend on besides their DOFs: the mesh and its clamped faces (the
    # material and the DOFs join in fegear.mechanics.compliance); not the layer depth or the
    # fidelity, so that every fidelity reads the same flank block
    key = {
        "mesh": str(sector.path.name) if sector.path else repr(sector.parameters),
        "clamped": clamped,
    }
    flank_dofs = dofs  # the cells load only these; the layer is only read
    layer_tets = np.zeros(mesh.t.shape[1], dtype=bool)
    groups = None
    if layer_mm > 0.0:
        # the layer under each tooth is read only under the loads of that tooth's own cells
        # (the hybrid's matching points; other pairs are read at the surface): one block each
        groups = []
        for f, fac in zip(flanks, per_tooth, strict=True):
            tets = _cached_layer_tets(mesh, fac, layer_mm, {**key, "flank": f, "depth": layer_mm})
            layer_tets[tets] = True
            fd = _facet_dofs(body.basis, fac)
            groups.append((fd, np.setdiff1d(body.basis.element_dofs[:, tets].ravel(), flank_dofs)))
        dofs = np.union1d(dofs, body.basis.element_dofs[:, layer_tets].ravel())
        reads = np.concatenate([g[1] for g in groups])
        if np.unique(reads).size != reads.size:  # layers of two teeth meet: one block
            log.info("%s: the layers below the loaded teeth meet; one layer block", name)
            groups = [(flank_dofs, np.setdiff1d(dofs, flank_dofs))]
    # the operator on the normal DOFs of the flank and layer nodes (docs/ltca/normal_operator.md)
    normals = _normals(body, facets, layer_tets if layer_mm > 0.0 else None)
    op = candidate_operator(
        body,
        dofs,
        backend=backend,
        cache_key=key,
        load_dofs=flank_dofs,
        groups=groups,
        normals=normals,
    )
    log.info(
        "%s: %d DOFs, %d candidate DOFs, operator in %.1f s (%s)",
        name,
        body.n_dofs,
        op.dofs.size,
        op.seconds,
        op.backend,
    )
    return MemberModel(
        name=name,
        sector=sector,
        body=body,
        op=op,
        side=side,
        layer_mm=layer_mm,
        layer_tets=layer_tets,
        teeth=teeth,
    )


def _normals(
    body: ElasticBody, facets: np.ndarray, layer_tets: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """``(s, n)`` for :func:`fegear.mechanics.compliance.candidate_operator`: the P2 nodes of
    the working flank ``facets`` with their normals
    (:func:`fegear.mechanics.compliance.boundary_normals`) and, with a layer (``layer_tets``,
    bool per tetrahedron), the other nodes of its tetrahedra, each with the normal of the
    nearest flank node (the direction the ``hybrid`` fidelity reads at depth below that flank
    point), sorted by node."""
    s, n = boundary_normals(body.mesh, facets)
    if layer_tets is None or not layer_tets.any():
        return s, n
    xs = body.scalar_basis.doflocs
    lay = np.setdiff1d(body.scalar_basis.element_dofs[:, layer_tets].ravel(), s)
    _, near = cKDTree(xs[:, s].T).query(xs[:, lay].T)
    nodes = np.concatenate([s, lay])
    order = np.argsort(nodes)
    return nodes[order], np.concatenate([n, n[near]])[order]


def _facet_dofs(basis, facets: np.ndarray) -> np.ndarray:
    """Vector DOFs (full numbering) of the nodes, edges and faces of ``facets``."""
    dofs = basis.get_dofs(facets)
    out = [dofs.nodal[k] for k in dofs.nodal]
    out += [dofs.facet[k] for k in dofs.facet] + [dofs.edge[k] for k in dofs.edge]
    return np.unique(np.concatenate(out))


def _cached_layer_tets(mesh, facets: np.ndarray, depth: float, key: dict) -> np.ndarray:
    """:func:`_layer_tets`, read from the cache when the same mesh was layered before (0.2 s)."""

    def build(path) -> None:
        with open(path, "wb") as fh:
            np.save(fh, _layer_tets(mesh, facets, depth))

    path, _ = cached_file("layer", {"kind": "layer_tets_v2", **key}, ".npy", build)
    return np.load(path)


def _layer_tets(mesh, facets: np.ndarray, depth: float) -> np.ndarray:
    """Tetrahedra met by the points below the flank ``facets`` down to ``depth`` (mm).

    Every flank facet is sampled at its corners, edge midpoints, centroid and three points half a
    facet beyond its edges (contact cells may overhang the flank's edge), and each sample is
    moved along the facet's inward normal by ``depth · (0.1, 0.25, 0.5, 0.75, 1, 1.15)``: the
    tetrahedra containing those points carry every displacement the ``hybrid`` fidelity reads at
    a matching depth ``<= depth`` (it halves the depth near thin edges, which stays covered).
    Every tetrahedron with a vertex on a flank is added (cells overhanging a flank edge).
    """
    tri = mesh.p[:, mesh.facets[:, facets]].transpose(2, 1, 0)  # (nf, 3, 3)
    normal = outward_facet_normals(mesh, facets)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    w = np.array(
        [
            [1, 0, 0],
            [0, 1, 0],
            [0, 0, 1],
            [0.5, 0.5, 0],
            [0, 0.5, 0.5],
            [0.5, 0, 0.5],
            [1 / 3, 1 / 3, 1 / 3],
            [-0.5, 0.75, 0.75],
            [0.75, -0.5, 0.75],
            [0.75, 0.75, -0.5],
        ]
    )
    samples = np.einsum("sk,fkx->fsx", w, tri)  # (nf, 10, 3)
    out = []
    for f in (0.1, 0.25, 0.5, 0.75, 1.0, 1.15):
        pts = samples - f * depth * normal[:, None, :]
        tets, _ = find_tets(mesh, pts.reshape(-1, 3))
        out.append(tets[tets >= 0])
    # ... and every tetrahedron with a vertex on a flank (cells overhang the flank edges).
    on_flank = np.zeros(mesh.p.shape[1], dtype=bool)
    on_flank[mesh.facets[:, facets].ravel()] = True
    out.append(np.flatnonzero(on_flank[mesh.t].any(axis=0)))
    return np.unique(np.concatenate(out))


def member_load_operator(
    model: MemberModel,
    placement: np.ndarray,
    tooth: int,
    quad_points: np.ndarray,
    directions: np.ndarray,
) -> sp.csr_matrix:
    """Consistent-load matrix ``P`` (n_dofs × n) of one pair's cells on one member.

    Parameters
    ----------
    model
        The member model.
    placement
        (4, 4) member frame → fixed frame at this position.
    tooth
        Member tooth carrying the cells.
    quad_points
        (n, q, 3) fixed frame, quadrature points of the cells on this member's flank.
    directions
        (n, 3) fixed frame, unit direction of the cell force on this member (into the member).
    """
    Minv = inverse(placement)
    pts = apply_points(Minv, quad_points)
    e = apply_vectors(Minv, directions)
    n, q = pts.shape[:2]
    return load_operator(model.body, model.boundary_of(tooth), pts, np.full((n, q), 1.0 / q), e)


def member_compliance(model: MemberModel, P: sp.csr_matrix) -> np.ndarray:
    """``C = Pᵀ (K⁻¹) P`` of all cells on this member (cross-tooth coupling included)."""
    return body_compliance(model.op, P)


def cell_load_operators(models, M1, M2, cells) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Consistent loads of the contact cells ``cells`` (:class:`~fegear.ltca.grid.PairCells`) on
    both members (``models.pinion``, ``models.gear`` placed by ``M1``, ``M2``): along ``−n1`` on
    the pinion flank, along ``+n1`` at the same points moved across the gap onto the gear flank.
    Returns ``(P1, P2)``, (n_dofs × Σ n) each."""
    P1 = sp.hstack(
        [member_load_operator(models.pinion, M1, c.k, c.quad_points, -c.normals) for c in cells]
    ).tocsr()
    P2 = sp.hstack(
        [
            member_load_operator(
                models.gear,
                M2,
                c.j,
                c.quad_points + c.gap[:, None, None] * c.normals[:, None],
                c.normals,
            )
            for c in cells
        ]
    ).tocsr()
    return P1, P2
