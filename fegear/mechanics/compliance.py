"""Finite-element compliance on a contact grid of cells with piecewise-constant pressure.

A contact cell ``j`` carries a force ``F_j`` spread uniformly over its area, in a direction ``e_j``
into the body. Its consistent load on the FE degrees of freedom is, with the P2 shape functions
``N_i`` and a cell quadrature ``(x_q, w_q)`` (weights summing to one),

.. math::

    P_{(3i+k)\\,j} = \\sum_q w_q\\, N_i(x_q)\\, e_{jk} ,

so that ``f = P F``. The approach of cell ``i`` (the cell-averaged displacement along ``e_i``) is
``w = P^T u``, and with ``K u = f`` the body's influence matrix is

.. math::

    C = P^T K^{-1} P = P_c^T \\,(K^{-1})_{cc}\\, P_c ,

where ``c`` are the DOFs ``P`` touches (the candidate DOFs). ``(K^{-1})_{cc}`` is the inverse of the
Schur complement of ``K`` onto ``c`` (one sparse factorisation; :mod:`fegear.linalg`). ``C`` is
symmetric positive definite because averaging and spreading use the same ``P`` (Galerkin form).

This is not nodal force divided by area: with quadratic elements a uniform pressure puts no force
on a triangle's corner nodes, so pressures are always the cell forces divided by cell areas.

Only its columns on the DOFs that cells load (the flank) are ever needed: the other candidate DOFs
(the ``hybrid`` fidelity's layer below the flank) are read, never loaded, so the operator keeps
``(K^{-1})_{cf}``, ``f ⊂ c`` (:func:`fegear.linalg.inverse_columns`, ~40 % less work than the
square block on the seed face gear's pinion). The block depends only on the mesh, material,
clamped DOFs, ``c`` and ``f``; it is cached on disk under a content hash of those
(:mod:`fegear.store.cache`), so a second run, or another grid on the same candidate region, costs
only the sparse products.
"""

from __future__ import annotations

import logging
import time
import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
import skfem
from scipy.spatial import cKDTree

from fegear.errors import InputError, SolverError
from fegear.fem.elasticity import ElasticBody
from fegear.linalg import inverse_columns, inverse_off_block, requested_backend, resolve_backend
from fegear.store.cache import cached_file

__all__ = [
    "SurfacePoints",
    "CandidateOperator",
    "OperatorBlock",
    "locate_on_boundary",
    "load_operator",
    "candidate_operator",
    "body_compliance",
    "boundary_normals",
    "outward_facet_normals",
]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SurfacePoints:
    """Points located on boundary facets of a tet mesh.

    Attributes
    ----------
    tets
        (n,) index of the tetrahedron owning the facet that holds each point.
    local
        (n, 3) reference coordinates of the point in that tetrahedron.
    distance
        (n,) mm, distance from the query point to the faceted surface.
    """

    tets: np.ndarray
    local: np.ndarray
    distance: np.ndarray


class OperatorBlock(NamedTuple):
    """One dense block ``G[rows][:, cols]`` of a :class:`CandidateOperator`.

    Attributes
    ----------
    rows
        (r,) sorted positions in the operator's ``dofs``.
    cols
        (k,) sorted positions in the operator's ``cols``.
    G
        (r, k) mm/N, memory-mapped when read from the cache.
    """

    rows: np.ndarray
    cols: np.ndarray
    G: np.ndarray


@dataclass(frozen=True)
class CandidateOperator:
    """``(K^{-1})_{cf}`` of a body: displacements of its candidate DOFs ``c`` under unit forces
    on its load DOFs ``f ⊂ c``, stored as dense blocks (:class:`OperatorBlock`): one block
    ``(m, k)``, or, for an operator built in groups (:func:`candidate_operator`), ``G_ff`` and
    one block ``G_{read_g, load_g}`` per group. Entries in no block are never computed:
    :meth:`take` gives them as NaN.

    Attributes
    ----------
    dofs
        (m,) candidate DOFs ``c`` in the full vector numbering, sorted.
    blocks
        The dense blocks; no two hold the same entry.
    cols
        (k,) load DOFs ``f`` (full numbering, sorted, a subset of ``dofs``).
    fixed
        Sorted constrained DOFs of the body: a load on them does no work and is ignored; a load
        on any other DOF outside ``cols`` is an error (:func:`body_compliance`).
    seconds
        Wall time to obtain it (factorisation, or reading the cache).
    cache_hit
        Whether it was read from the on-disk cache.
    backend
        The sparse direct backend used ("pardiso", "superlu"), or "cache".
    projection
        ``T`` (n_dofs × n_dofs, CSR) for an operator on the normal DOFs of surface nodes
        (:func:`candidate_operator` with ``normals``): row ``3s`` of a normal node ``s`` is its
        unit normal ``n_s`` on the DOFs ``3s..3s+2``, rows ``3s+1, 3s+2`` are empty, every other
        row is the identity's. None: the Cartesian DOFs themselves.
    tangential
        Sorted DOFs ``3s+1, 3s+2`` of the normal nodes (full numbering): in this basis they are
        the nodes' tangential components, never loaded or read.
    """

    dofs: np.ndarray
    blocks: tuple[OperatorBlock, ...]
    seconds: float
    cache_hit: bool
    backend: str
    cols: np.ndarray
    fixed: np.ndarray
    projection: sp.csr_matrix | None = None
    tangential: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    @property
    def load_support(self) -> np.ndarray:
        """Sorted DOFs (full numbering) a load may sit on: the load DOFs, the tangential DOFs
        of their nodes that :attr:`projection` folds onto the normal, and the clamped DOFs."""
        return np.union1d(np.union1d(self.cols, self.tangential), self.fixed)

    def project(self, M: sp.spmatrix) -> sp.spmatrix:
        """``M`` (n_dofs × n, loads or readings in the full Cartesian numbering) in the
        operator's DOF basis: unchanged without a :attr:`projection`, else ``T M`` (CSC), the
        Cartesian components at each normal node folded onto its normal (``n · (·)``) and the
        tangential ones dropped (:func:`candidate_operator`).

        The product is formed on the stored entries of ``M`` only (a cell's load touches ~100
        of the body's ~50 000 DOFs; SciPy's product passes over every row of ``T``), entry by
        entry as SciPy's ``T @ M`` forms it, so that it is the same bits:
        ``(T M)_rj = ((0 + T_rk₁ M_k₁j) + T_rk₂ M_k₂j) + …`` over the entries of row ``r`` of
        ``T`` in their stored order, and a sum that is exactly zero is not stored. A
        non-canonical ``M`` (duplicate entries) goes through SciPy."""
        if self.projection is None:
            return M
        M = M if sp.isspmatrix_csc(M) else sp.csc_matrix(M)
        if not M.has_canonical_format:
            return sp.csc_matrix(self.projection @ M)
        T = self.projection
        row_of, by_col, col_ptr = self._projection_columns
        k = M.indices
        j = np.repeat(np.arange(M.shape[1]), np.diff(M.indptr))
        # the entries of T in the columns k (each M entry meets those of its column)
        count = col_ptr[k + 1] - col_ptr[k]
        first = np.repeat(col_ptr[k] - np.cumsum(count) + count, count)
        t = by_col[first + np.arange(first.size)]  # positions in T's stored (row) order
        e = np.repeat(np.arange(k.size), count)
        term = T.data[t] * M.data[e]
        je = j[e]
        # by column of M, then T's stored order (rows ascending); usually already so (M's
        # rows ascending in each column, and T's rows follow its columns)
        key = je * np.int64(T.data.size) + t
        if np.any(key[1:] < key[:-1]):
            order = np.argsort(key, kind="stable")
            je, t, term = je[order], t[order], term[order]
        r = row_of[t]
        new = np.ones(je.size, dtype=bool)
        new[1:] = (je[1:] != je[:-1]) | (r[1:] != r[:-1])
        group = np.cumsum(new) - 1
        total = np.bincount(group, weights=term)  # ((0 + a) + b) + …, in order
        keep = total != 0.0
        cols = je[new][keep]
        indptr = np.concatenate([[0], np.cumsum(np.bincount(cols, minlength=M.shape[1]))])
        return sp.csc_matrix((total[keep], r[new][keep], indptr), shape=(T.shape[0], M.shape[1]))

    @cached_property
    def _projection_columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(row, by_col, col_ptr)`` of :attr:`projection`: the row of each stored entry, the
        entries' positions grouped by column (``by_col[col_ptr[k]:col_ptr[k + 1]]``: column
        ``k``, in stored order)."""
        T = self.projection
        row = np.repeat(np.arange(T.shape[0]), np.diff(T.indptr))
        by_col = np.argsort(T.indices, kind="stable")
        col_ptr = np.concatenate([[0], np.cumsum(np.bincount(T.indices, minlength=T.shape[1]))])
        return row, by_col, col_ptr

    @cached_property
    def _row_map(self) -> tuple[np.ndarray, np.ndarray]:
        """``(block, index)``, (m,) each: the block holding each row and the row's index in it
        (-1: in none)."""
        block = np.full(self.dofs.size, -1, dtype=np.intp)
        index = np.full(self.dofs.size, -1, dtype=np.intp)
        for b, blk in enumerate(self.blocks):
            block[blk.rows] = b
            index[blk.rows] = np.arange(blk.rows.size)
        return block, index

    @cached_property
    def _col_maps(self) -> tuple[np.ndarray, ...]:
        """Per block, (k,) the index of each column in it (-1: not in it)."""
        out = []
        for blk in self.blocks:
            index = np.full(self.cols.size, -1, dtype=np.intp)
            index[blk.cols] = np.arange(blk.cols.size)
            out.append(index)
        return tuple(out)

    def take(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """``G[rows][:, cols]`` (len(rows), len(cols)) mm/N, ``rows`` positions in ``dofs``,
        ``cols`` positions in ``cols``; NaN where no block holds the entry. Only the entries
        asked for are read (the blocks may be memory-mapped)."""
        rows = np.asarray(rows, dtype=np.intp)
        cols = np.asarray(cols, dtype=np.intp)
        block, index = self._row_map
        bid = block[rows]
        if bid.size and np.all(bid == bid[0]) and bid[0] >= 0:  # one block: no NaN fill
            cm = self._col_maps[bid[0]][cols]
            if np.all(cm >= 0):
                return np.asarray(self.blocks[bid[0]].G[np.ix_(index[rows], cm)])
        out = np.full((rows.size, cols.size), np.nan)
        for b in np.unique(bid[bid >= 0]):
            sel = np.flatnonzero(bid == b)
            cm = self._col_maps[b][cols]
            ok = np.flatnonzero(cm >= 0)
            if ok.size:
                out[np.ix_(sel, ok)] = self.blocks[b].G[np.ix_(index[rows[sel]], cm[ok])]
        return out

    @property
    def G(self) -> np.ndarray:  # noqa: N802 (the operator is G)
        """(m, k) mm/N, the whole block ``(K^{-1})_{cf}`` (rows ``dofs``, columns ``cols``), NaN
        where no block holds the entry; materialised in memory on each call (for checks: a
        position reads its entries with :meth:`take`)."""
        if len(self.blocks) == 1 and self.blocks[0].G.shape == (self.dofs.size, self.cols.size):
            return self.blocks[0].G
        return self.take(np.arange(self.dofs.size), np.arange(self.cols.size))


_MEMO: dict[tuple[int, str], tuple[weakref.ref, object]] = {}


def _memo(mesh: skfem.MeshTet, what: str, build):
    """``build()`` once per mesh object and ``what`` (mesh positions query the same sector
    hundreds of times), dropped with the mesh."""
    key = (id(mesh), what)
    hit = _MEMO.get(key)
    if hit is not None and hit[0]() is mesh:
        return hit[1]
    value = build()
    _MEMO[key] = (weakref.ref(mesh), value)
    weakref.finalize(mesh, _MEMO.pop, key, None)
    return value


def _tree(mesh: skfem.MeshTet, what: str, centres) -> cKDTree:
    """KD-tree of the tetrahedron (``what = "tets"``) or boundary-facet centroids of ``mesh``."""
    return _memo(mesh, "tree:" + what, lambda: cKDTree(centres()))


def _tet_affine(mesh: skfem.MeshTet) -> tuple[np.ndarray, np.ndarray]:
    """First vertices ``p0`` (n_tets, 3) and inverse Jacobians ``J⁻¹`` (n_tets, 3, 3) of the
    affine maps ``x = p0 + J ξ`` of all tetrahedra (scikit-fem's reference tetrahedron)."""

    def build():
        tv = np.moveaxis(mesh.p[:, mesh.t], 0, -1)  # (4, n_tets, 3)
        J = np.stack([tv[1] - tv[0], tv[2] - tv[0], tv[3] - tv[0]], axis=-1)
        return tv[0], np.linalg.inv(J)

    return _memo(mesh, "affine", build)


class _FacetFrames(NamedTuple):
    """Per facet of a boundary (nf,): first vertex ``a`` and edges ``e1``, ``e2`` (nf, 3) mm,
    their Gram entries ``g11, g12, g22`` and determinant ``det`` (nf,) mm⁴, centroid (nf, 3)."""

    a: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    g11: np.ndarray
    g12: np.ndarray
    g22: np.ndarray
    det: np.ndarray
    centroid: np.ndarray


def _facet_frames(mesh: skfem.MeshTet, boundary: str) -> _FacetFrames:
    """:class:`_FacetFrames` of ``boundary``, once per mesh (every cell location reads them)."""

    def build() -> _FacetFrames:
        tri = mesh.p[:, mesh.facets[:, mesh.boundaries[boundary]]].transpose(2, 1, 0)  # (nf,3,3)
        a = tri[:, 0]
        e1 = tri[:, 1] - a
        e2 = tri[:, 2] - a
        g11 = np.einsum("...i,...i", e1, e1)
        g12 = np.einsum("...i,...i", e1, e2)
        g22 = np.einsum("...i,...i", e2, e2)
        return _FacetFrames(a, e1, e2, g11, g12, g22, g11 * g22 - g12 * g12, tri.mean(axis=1))

    return _memo(mesh, "frames:" + boundary, build)


def prepare_locators(mesh: skfem.MeshTet, boundaries: Sequence[str] = ()) -> None:
    """Build now the search structures that locating points on ``mesh`` builds on first use:
    the facet-to-tetrahedron map ``f2t``, the tetrahedra's affine maps and centroid KD-tree
    (:func:`find_tets`), and the facet frames and centroid KD-tree of each of ``boundaries``
    (:func:`locate_on_boundary`).

    For a process about to fork workers that locate cells on the mesh
    (:func:`fegear.ltca.cycle.run_ltca`): built once here, the children share them
    copy-on-write instead of each building its own. The structures are the ones the lazy path
    builds (same inputs, same code), so the located points are identical."""
    _ = mesh.f2t
    _tet_affine(mesh)
    _tree(mesh, "tets", lambda: mesh.p[:, mesh.t].mean(axis=1).T)
    for b in boundaries:
        if b in (mesh.boundaries or {}):
            F = _facet_frames(mesh, b)
            _tree(mesh, b, lambda F=F: F.centroid)


def locate_on_boundary(
    mesh: skfem.MeshTet, boundary: str, points: np.ndarray, k: int = 12
) -> SurfacePoints:
    """Find, for each point, the boundary facet it lies on and its reference coordinates.

    The point is projected orthogonally on the planes of the ``k`` facets with the nearest
    centroids; the facet whose barycentric coordinates are all non-negative (or, for a point
    slightly off a curved surface, the least negative) and which is nearest wins. The projected
    point is expressed in the reference coordinates of the facet's tetrahedron.

    Parameters
    ----------
    mesh
        Tet mesh with named boundaries.
    boundary
        Name of the boundary holding the points.
    points
        (n, 3) mm.
    """
    if boundary not in (mesh.boundaries or {}):
        raise InputError("boundary", boundary, f"one of {sorted(mesh.boundaries or {})}")
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    fac = mesh.boundaries[boundary]
    F = _facet_frames(mesh, boundary)
    tree = _tree(mesh, boundary, lambda: F.centroid)
    kk = min(k, fac.size)
    _, cand = tree.query(pts, k=kk)
    cand = cand.reshape(pts.shape[0], kk)
    a, e1, e2 = F.a[cand], F.e1[cand], F.e2[cand]
    g11, g12, g22, det = F.g11[cand], F.g12[cand], F.g22[cand], F.det[cand]
    r = pts[:, None, :] - a
    # Least-squares barycentric coordinates (= orthogonal projection on the facet plane).
    b1 = np.einsum("...i,...i", r, e1)
    b2 = np.einsum("...i,...i", r, e2)
    s = (g22 * b1 - g12 * b2) / det
    t = (g11 * b2 - g12 * b1) / det
    bary_min = np.minimum(np.minimum(s, t), 1.0 - s - t)
    # Prefer facets containing the projection, nearest first; otherwise the least outside. The
    # distance to the projection is formed for the containing candidates only (one or two of
    # the k per point): each entry the same numbers as over all k.
    score = 1e30 - bary_min
    ii = np.nonzero(bary_min >= -1e-9)
    proj = a[ii] + s[ii][:, None] * e1[ii] + t[ii][:, None] * e2[ii]
    score[ii] = np.linalg.norm(pts[ii[0]] - proj, axis=-1)
    best = np.argmin(score, axis=1)
    rows = np.arange(pts.shape[0])
    sb = np.clip(s[rows, best], 0.0, 1.0)
    tb = np.clip(t[rows, best], 0.0, 1.0 - sb)
    f_best = cand[rows, best]
    x = a[rows, best] + sb[:, None] * e1[rows, best] + tb[:, None] * e2[rows, best]
    tets = mesh.f2t[0, fac[f_best]]
    # Reference coordinates in the tetrahedron: x = p0 + J xi (scikit-fem's affine mapping).
    tv = mesh.p[:, mesh.t[:, tets]].transpose(2, 1, 0)  # (n, 4, 3)
    J = np.stack([tv[:, 1] - tv[:, 0], tv[:, 2] - tv[:, 0], tv[:, 3] - tv[:, 0]], axis=-1)
    xi = np.linalg.solve(J, (x - tv[:, 0])[..., None])[..., 0]
    return SurfacePoints(tets=tets, local=xi, distance=np.linalg.norm(pts - x, axis=1))


def load_operator(
    body: ElasticBody,
    boundary: str,
    points: np.ndarray,
    weights: np.ndarray,
    directions: np.ndarray,
) -> sp.csr_matrix:
    """The consistent-load matrix ``P`` (n_dofs × n_cells) of unit cell forces.

    Parameters
    ----------
    body
        The assembled body.
    boundary
        Name of the boundary the cells lie on.
    points
        (n_cells, q, 3) mm, quadrature points of each cell on (or within round-off of) the surface.
    weights
        (n_cells, q), quadrature weights of each cell, summing to one per cell.
    directions
        (n_cells, 3), unit direction of the cell force on this body (into the body).
    """
    pts = np.asarray(points, dtype=float)
    w = np.asarray(weights, dtype=float)
    e = np.asarray(directions, dtype=float)
    if (
        pts.ndim != 3
        or pts.shape[2] != 3
        or w.shape != pts.shape[:2]
        or e.shape
        != (
            pts.shape[0],
            3,
        )
    ):
        raise InputError(
            "points/weights/directions",
            f"{pts.shape}/{w.shape}/{e.shape}",
            "(n, q, 3) / (n, q) / (n, 3)",
        )
    n, q = w.shape
    loc = locate_on_boundary(body.mesh, boundary, pts.reshape(-1, 3))
    return _shape_operator(body, loc, w.reshape(-1), np.repeat(np.arange(n), q), e, n, True)


def _shape_operator(
    body: ElasticBody,
    loc: SurfacePoints,
    wq: np.ndarray,
    cell: np.ndarray,
    e: np.ndarray,
    n: int,
    on_facet: bool = False,
) -> sp.csr_matrix:
    """Sparse ``Σ_q w_q N_i(x_q) e_k`` from located points (one column per cell).

    ``on_facet``: the points lie on boundary facets, where the shape functions of the nodes off
    the facet vanish identically; their round-off values (~1e-16) are dropped, so that ``P``
    loads the facet's DOFs only."""
    elem = skfem.ElementTetP2()
    sdofs = body.scalar_basis.element_dofs[:, loc.tets]  # (10, n*q)
    phi = np.stack([elem.lbasis(loc.local.T, i)[0] for i in range(10)])  # (10, n*q)
    if on_facet:
        phi[np.abs(phi) < 1e-12] = 0.0
    rows, cols, vals = [], [], []
    for k in range(3):
        rows.append(3 * sdofs + k)
        cols.append(np.broadcast_to(cell, sdofs.shape))
        vals.append(phi * (wq * e[cell, k])[None, :])
    P = sp.coo_matrix(
        (
            np.concatenate([v.ravel() for v in vals]),
            (np.concatenate([r.ravel() for r in rows]), np.concatenate([c.ravel() for c in cols])),
        ),
        shape=(body.n_dofs, n),
    ).tocsr()
    P.eliminate_zeros()
    return P


#: :func:`find_tets`: candidates tested first, and the ``b_min`` that settles a point on them.
_FIRST = 4
_CLEAR = 1e-6


def find_tets(
    mesh: skfem.MeshTet, points: np.ndarray, k: int = 16
) -> tuple[np.ndarray, np.ndarray]:
    """Tetrahedron containing each point (-1 if none of the ``k`` nearest by centroid does) and
    the point's reference coordinates in it. Vectorised barycentric test: the candidate with
    the largest smallest barycentric coordinate ``b_min`` wins.

    The ``_FIRST`` nearest candidates are tested first: a point whose best ``b_min`` among them
    exceeds ``_CLEAR`` lies inside that tetrahedron, away from its faces, hence outside every
    other tetrahedron of the (conforming) mesh (their ``b_min < 0``), and the full test would
    pick the same one with the same coordinates; the other points take all ``k``."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    tree = _tree(mesh, "tets", lambda: mesh.p[:, mesh.t].mean(axis=1).T)
    kk = min(k, mesh.t.shape[1])
    _, cand = tree.query(pts, k=kk)
    cand = cand.reshape(pts.shape[0], kk)
    p0, Jinv = _tet_affine(mesh)

    def best_of(rows: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, ...]:
        xi = np.einsum("nkij,nkj->nki", Jinv[c], pts[rows, None, :] - p0[c])  # (n, kc, 3)
        bmin = np.minimum(xi.min(axis=-1), 1.0 - xi.sum(axis=-1))
        best = np.argmax(bmin, axis=1)
        at = np.arange(rows.size)
        return c[at, best], xi[at, best], bmin[at, best]

    rows = np.arange(pts.shape[0])
    tets, xi, bmin = best_of(rows, cand[:, : min(_FIRST, kk)])
    again = np.flatnonzero(~(bmin > _CLEAR)) if kk > _FIRST else rows[:0]
    if again.size:
        tets[again], xi[again], bmin[again] = best_of(again, cand[again])
    return np.where(bmin >= -1e-9, tets, -1), xi


def locate_inside(mesh: skfem.MeshTet, points: np.ndarray) -> SurfacePoints:
    """Tetrahedra and reference coordinates of interior points (``distance`` is zero)."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    tets, xi = find_tets(mesh, pts)
    miss = np.flatnonzero(tets < 0)
    if miss.size:  # graded meshes: the containing tet may not be among the nearest centroids
        try:
            t = mesh.element_finder()(pts[miss, 0], pts[miss, 1], pts[miss, 2])
        except ValueError:
            t = None
        if t is not None:
            tv = np.moveaxis(mesh.p[:, mesh.t[:, t]], 0, -1)  # (4, n, 3)
            J = np.stack([tv[1] - tv[0], tv[2] - tv[0], tv[3] - tv[0]], axis=-1)
            xi[miss] = np.linalg.solve(J, (pts[miss] - tv[0])[..., None])[..., 0]
            tets[miss] = t
    if np.any(tets < 0):
        raise InputError("points", f"{int(np.sum(tets < 0))} outside the mesh", "inside the body")
    return SurfacePoints(tets=tets, local=xi, distance=np.zeros(pts.shape[0]))


def probe_operator(
    body: ElasticBody,
    points: np.ndarray,
    directions: np.ndarray,
    located: SurfacePoints | None = None,
) -> sp.csr_matrix:
    """``Q`` (n_dofs × n): column ``i`` reads the displacement at ``points[i]`` along
    ``directions[i]`` (``w_i = Q_i^T u``); the points may be anywhere inside the body.
    ``located``: their tetrahedra and reference coordinates if known (:func:`find_tets`, every
    point found), else :func:`locate_inside` finds them."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    e = np.asarray(directions, dtype=float).reshape(-1, 3)
    n = pts.shape[0]
    loc = locate_inside(body.mesh, pts) if located is None else located
    return _shape_operator(body, loc, np.ones(n), np.arange(n), e, n)


def candidate_operator(
    body: ElasticBody,
    dofs: np.ndarray,
    backend: str = "auto",
    cache_key: dict | None = None,
    load_dofs: np.ndarray | None = None,
    groups: Sequence[tuple[np.ndarray, np.ndarray]] | None = None,
    normals: tuple[np.ndarray, np.ndarray] | None = None,
) -> CandidateOperator:
    """``(K^{-1})_{cf}`` on the candidate DOFs ``c = dofs`` and the load DOFs ``f = load_dofs``
    (full numbering; default all of ``dofs``; clamped ones dropped from both; ``f ⊂ c``).

    With ``cache_key`` (a mapping describing the mesh and the boundary conditions), the blocks
    are read from / written to the on-disk cache (:mod:`fegear.store.cache`), each an entry of
    its own keyed on the body, the material and the DOFs it holds.

    ``groups`` (``[(load_g, read_g), ...]``, e.g. one per loaded tooth: its flank DOFs and the
    DOFs of the layer below them) says which read-only rows are ever read under which loads: then
    only ``G_ff`` (every load DOF under every load: the coupling of all teeth) and the blocks
    ``G_{read_g, load_g}`` are computed and stored, ``G_ff`` as the inverse of the Schur
    complement onto ``f`` and each ``G_{read_g, load_g}`` from the Schur complement onto
    ``load_g ∪ read_g`` and the block ``G_{load_g, load_g}`` of ``G_ff``
    (:func:`~fegear.linalg.inverse_off_block`): ``Σ_g cost(l_g, f_g) + f³`` instead of
    ``cost(Σ l_g, f)``, the dense work being cubic. The other entries of ``G`` (a layer under one
    tooth read under the load of another) are never computed (NaN in
    :meth:`CandidateOperator.take`). Measured on the seed face gear's level-0 sector (3 loaded
    teeth, f = 6246, l = 10 902): 31.7 s against 127.9 s for the whole block (2 cores, with
    another process running). ``G_ff`` is the same cache entry as the square operator on ``f``
    alone (what the ``fe`` and ``hertz`` fidelities read), and each group's block is an entry of
    its own (``(K⁻¹)_{read_g, load_g}`` depends on ``K`` alone), so the fidelities share what
    they have in common and only a missing block is ever computed.

    ``normals`` (``(s, n)``: scalar DOFs ``(p,)`` of surface nodes and their unit normals
    ``(p, 3)``, :func:`boundary_normals`) puts the operator on the normal DOFs of those nodes:
    at each node the Cartesian DOFs are turned into ``(n, t₁, t₂)`` by an orthonormal
    ``R_s = [n t₁ t₂]`` (``u = R u'``, ``K' = Rᵀ K R``, the same body), and of those nodes only
    the normal DOF ``n · u`` is a candidate or load DOF. A cell load ``P`` is then applied
    through its normal components ``n_s · P_s`` (:meth:`CandidateOperator.project`) and the
    approach is read the same way, so that

    .. math::

        C = (T P)^T \\, G'\\, (T P), \\qquad G'_{st} = n_s^T (K^{-1})_{st}\\, n_t ,

    the normal-load, normal-displacement influence coefficients of the LTCA literature
    (e.g. Conry & Seireg 1973; Vijayakar 1991): the tangential components a cell force has
    at a node (the angle between the node's normal and the cell's force direction, a fraction
    of a degree to a few degrees) are not applied, nor their tangential displacements read.
    The dense work falls by the cube of the load DOFs (a third of them): measured on the seed
    face gear (``docs/ltca/normal_operator.md``). The nodes must be free or clamped in all
    three directions.
    """
    c = np.intersect1d(np.asarray(dofs, dtype=np.int64), body.free)
    f = c if load_dofs is None else np.intersect1d(np.asarray(load_dofs, np.int64), body.free)
    rot = None if normals is None else _normal_basis(body, *normals)
    if rot is not None:  # only the normal DOF of each normal node stays a candidate
        c = np.setdiff1d(c, rot.tangential, assume_unique=True)
        f = np.setdiff1d(f, rot.tangential, assume_unique=True)
        if groups is not None:
            groups = [
                (np.setdiff1d(fg, rot.tangential), np.setdiff1d(lg, rot.tangential))
                for fg, lg in groups
            ]
    if not np.all(np.isin(f, c)):
        raise InputError("load_dofs", f"{int(np.sum(~np.isin(f, c)))} outside dofs", "within dofs")
    groups_ = None if groups is None else _groups(c, f, body.free, groups)
    pos = np.searchsorted(body.free, c)
    rf = np.searchsorted(c, f)
    if groups_ is None:
        layout = [(np.arange(c.size), np.arange(f.size))]
    else:
        layout = [(rf, np.arange(f.size))]
        layout += [(np.searchsorted(c, lg), np.searchsorted(f, fg)) for fg, lg in groups_]
    t0 = time.perf_counter()
    requested_backend(backend)  # a bad name is refused on a cache hit too
    used = ""

    def solver() -> str:
        nonlocal used
        used = used or resolve_backend(backend)  # only when computing: loading MKL takes 0.3 s
        return used

    base = {"body": cache_key, "E": body.E, "nu": body.nu, "n_free": int(body.free.size)}
    stiffness = _Stiffness(body, rot)
    if groups_ is None:
        params = {"kind": "inverse_block_v1", **base, "dofs": c, **_turned(rot, c)}
        if f.size < c.size:
            params.update(kind="inverse_columns_v1", cols=f)
        G, hit = _cached_block(
            params,
            cache_key is not None,
            lambda: inverse_columns(stiffness(), pos, np.isin(c, f), backend=solver()),
        )
        arrays, hits = [G], [hit]
    else:
        # G_ff is the entry a square operator on f alone is (the ``fe`` fidelity's): every
        # fidelity on the same flanks shares it; each group's block is an entry of its own, so
        # that a block missing from the cache is the only one computed
        # With few candidate DOFs in all (the normal DOFs of the flanks and layers), one Schur
        # complement onto all of them gives G_ff and every group's block at once (one sparse
        # factorisation instead of one per block); it is made when G_ff is missing, and the
        # group blocks missing from the cache are cut from it.
        union: list[np.ndarray] = []

        def square() -> np.ndarray:
            if c.size > UNION_MAX_DOFS:
                return inverse_columns(stiffness(), pos[rf], np.ones(f.size, bool), solver())
            union.append(inverse_columns(stiffness(), pos, np.isin(c, f), backend=solver()))
            return np.ascontiguousarray(union[0][rf])

        G_ff, hit = _cached_block(
            {"kind": "inverse_block_v1", **base, "dofs": f, **_turned(rot, f)},
            cache_key is not None,
            square,
        )
        arrays, hits = [G_ff], [hit]
        for (fg, lg), (rows_g, cols_g) in zip(groups_, layout[1:], strict=True):
            cg = np.union1d(fg, lg)

            def off(cg=cg, fg=fg, rows_g=rows_g, cols_g=cols_g) -> np.ndarray:
                if union:
                    return np.ascontiguousarray(union[0][np.ix_(rows_g, cols_g)])
                return inverse_off_block(
                    stiffness(),
                    np.searchsorted(body.free, cg),
                    np.isin(cg, fg),
                    G_ff[np.ix_(cols_g, cols_g)],
                    solver(),
                )

            params = {"kind": "inverse_off_block_v1", **base, "load": fg, "read": lg}
            params.update(_turned(rot, cg))
            B, hit = _cached_block(params, cache_key is not None, off)
            arrays.append(B)
            hits.append(hit)
    hit = all(hits)
    dt = time.perf_counter() - t0
    log.info(
        "candidate operator: %d DOFs, %d load DOFs in %.2f s (%d of %d blocks from the cache%s)",
        c.size,
        f.size,
        dt,
        sum(hits),
        len(hits),
        "" if hit else f", {used}",
    )
    fixed = np.setdiff1d(np.arange(body.n_dofs), body.free)
    blocks = tuple(OperatorBlock(r, k, G) for (r, k), G in zip(layout, arrays, strict=True))
    return CandidateOperator(
        dofs=c,
        blocks=blocks,
        seconds=dt,
        cache_hit=hit,
        backend="cache" if hit else used,
        cols=f,
        fixed=fixed,
        projection=None if rot is None else rot.projection,
        tangential=np.zeros(0, np.int64) if rot is None else rot.tangential,
    )


class _NormalBasis(NamedTuple):
    """The turned DOF basis of :func:`candidate_operator` with ``normals``: the free nodes
    ``nodes`` (p,), their unit normals (p, 3), ``R`` (n_free × n_free, ``u = R u'``), the
    projection ``T`` (n_dofs × n_dofs) and the nodes' tangential DOFs (sorted, full numbering)."""

    nodes: np.ndarray
    normals: np.ndarray
    R: sp.csr_matrix
    projection: sp.csr_matrix
    tangential: np.ndarray


def _normal_basis(body: ElasticBody, nodes: np.ndarray, normals: np.ndarray) -> _NormalBasis:
    """:class:`_NormalBasis` of the scalar DOFs ``nodes`` with unit ``normals``; nodes clamped
    in all three directions are left out (they do not move); a node clamped in one or two
    directions is refused."""
    s = np.asarray(nodes, dtype=np.int64)
    nv = np.asarray(normals, dtype=float)
    if s.ndim != 1 or nv.shape != (s.size, 3) or np.unique(s).size != s.size:
        raise InputError("normals", f"{s.shape} / {nv.shape}", "unique (p,) nodes, (p, 3)")
    nv = nv / np.linalg.norm(nv, axis=1, keepdims=True)
    full = 3 * s[:, None] + np.arange(3)  # (p, 3)
    free = np.isin(full, body.free)
    if np.any(free.any(axis=1) & ~free.all(axis=1)):
        raise InputError("normals", "nodes clamped in some directions", "free or clamped nodes")
    keep = free.all(axis=1)
    s, nv, full = s[keep], nv[keep], full[keep]
    # an orthonormal frame (n, t1, t2) per node: t1 from the axis least aligned with n
    axis = np.eye(3)[np.argmin(np.abs(nv), axis=1)]
    t1 = np.cross(nv, axis)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(nv, t1)
    frame = np.stack([nv, t1, t2], axis=1)  # (p, 3 basis vectors, 3 components)
    pos = np.searchsorted(body.free, full)  # (p, 3) free numbering
    n_free = body.free.size
    other = np.setdiff1d(np.arange(n_free), pos.ravel())
    # R[pos[k], pos[j]] = frame[j, k]: column j of a node's block is its j-th basis vector
    rows = np.concatenate([np.repeat(pos, 3, axis=1).ravel(), other])
    cols = np.concatenate([np.tile(pos, (1, 3)).ravel(), other])
    vals = np.concatenate([frame.transpose(0, 2, 1).reshape(-1), np.ones(other.size)])
    R = sp.csr_matrix((vals, (rows, cols)), shape=(n_free, n_free))
    n_dofs = body.n_dofs
    rest = np.setdiff1d(np.arange(n_dofs), full.ravel())
    T = sp.csr_matrix(
        (
            np.concatenate([nv.ravel(), np.ones(rest.size)]),
            (
                np.concatenate([np.repeat(full[:, 0], 3), rest]),
                np.concatenate([full.ravel(), rest]),
            ),
        ),
        shape=(n_dofs, n_dofs),
    )
    return _NormalBasis(s, nv, R, T, np.sort(full[:, 1:].ravel()))


def _turned(rot: _NormalBasis | None, dofs: np.ndarray) -> dict[str, object]:
    """What a block on ``dofs`` depends on of the turned basis: the normals of its nodes
    (``(Rᵀ K⁻¹ R)`` on those DOFs reads no other node's frame), so that the flank block of a
    ``hybrid`` operator, whose basis also turns its layer's nodes, is the ``fe`` one's."""
    if rot is None:
        return {}
    keep = np.isin(rot.nodes, np.unique(dofs // 3))
    return {"normals": {"nodes": rot.nodes[keep], "n": rot.normals[keep]}}


class _Stiffness:
    """The body's free stiffness in the operator's DOF basis (``Rᵀ K R`` with a
    :class:`_NormalBasis`), made on first call: a run whose blocks are cached never needs it."""

    def __init__(self, body: ElasticBody, rot: _NormalBasis | None) -> None:
        self.body, self.rot, self._K = body, rot, None

    def __call__(self) -> sp.csr_matrix:
        if self._K is None:
            K = self.body.K
            if self.rot is not None:
                R = self.rot.R
                K = (R.T @ K @ R).tocsr()
                K.sort_indices()
            self._K = K
        return self._K


def outward_facet_normals(mesh: skfem.MeshTet, facets: np.ndarray) -> np.ndarray:
    """``(nf, 3)`` outward normals of the boundary ``facets`` of a tet mesh, each as long as its
    facet's area: ``½ (x1 − x0) × (x2 − x0)``, turned away from the centroid of the one
    tetrahedron that owns the facet (a boundary facet has one)."""
    fac = np.asarray(facets, dtype=np.int64)
    tri = mesh.p[:, mesh.facets[:, fac]].transpose(2, 1, 0)  # (nf, 3, 3)
    area_normal = 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    far = mesh.p[:, mesh.t[:, mesh.f2t[0, fac]]].mean(axis=1).T  # owning tet's centroid
    flip = np.sum((far - tri.mean(axis=1)) * area_normal, axis=1) > 0
    area_normal[flip] *= -1.0
    return area_normal


def boundary_normals(mesh: skfem.MeshTet, facets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The P2 nodes of the boundary ``facets`` and their normals.

    Returns ``(s, n)``: the scalar DOFs ``s`` (p,) of the facets' vertices and edge midpoints
    (scikit-fem's P2 numbering: vertex ``v`` is DOF ``v``, edge ``e`` is ``n_vertices + e``) and
    unit normals ``n`` (p, 3): at each node the mean of the outward normals of the facets
    holding it, weighted by their areas (the normal of a smooth surface sampled by flat
    facets, to the order of the facets' size times its curvature)."""
    fac = np.asarray(facets, dtype=np.int64)
    area_normal = outward_facet_normals(mesh, fac)
    node = np.concatenate([mesh.facets[:, fac], mesh.p.shape[1] + mesh.f2e[:, fac]])  # (6, nf)
    s, inv = np.unique(node.ravel(), return_inverse=True)
    acc = np.zeros((s.size, 3))
    np.add.at(acc, inv, np.tile(area_normal, (6, 1)))
    return s, acc / np.linalg.norm(acc, axis=1, keepdims=True)


#: Above this many candidate DOFs the blocks of a grouped operator are computed group by group
#: (:func:`candidate_operator`): the dense work of one Schur complement onto all of them grows as
#: the cube of their number.
UNION_MAX_DOFS = 12_000


def _cached_block(
    params: dict, cached: bool, compute: Callable[[], np.ndarray]
) -> tuple[np.ndarray, bool]:
    """``(block, hit)``: one dense operator block, from the ``compliance`` cache entry of
    ``params`` (memory-mapped: a position reads only the rows and columns its cells touch) or
    computed by ``compute()`` (and written there when ``cached``)."""
    if not cached:
        return compute(), False

    def build(path: Path) -> None:
        with open(path, "wb") as fh:
            np.save(fh, compute())

    path, hit = cached_file("compliance", params, ".npy", build)
    return np.load(path, mmap_mode="r"), hit


def _groups(c, f, free, groups) -> list[tuple[np.ndarray, np.ndarray]]:
    """The groups of :func:`candidate_operator` on free DOFs, checked: load DOFs within ``f``,
    read DOFs within ``c \\ f``, no DOF in two groups."""
    out, seen = [], []
    for i, (fg, lg) in enumerate(groups):
        fg = np.intersect1d(np.asarray(fg, np.int64), free)
        lg = np.intersect1d(np.asarray(lg, np.int64), free)
        if not (np.all(np.isin(fg, f)) and np.all(np.isin(lg, c)) and not np.isin(lg, f).any()):
            raise InputError(f"groups[{i}]", "DOFs", "load DOFs within load_dofs, read DOFs in "
                             "dofs and not load DOFs")  # fmt: skip
        out.append((fg, lg))
        seen.append(np.concatenate([fg, lg]))
    allg = np.concatenate(seen) if seen else np.zeros(0, np.int64)
    if np.unique(allg).size != allg.size:
        raise InputError("groups", "overlapping", "disjoint groups")
    return out


def _compact(
    op: CandidateOperator, M: sp.spmatrix, on: np.ndarray, what: str
) -> tuple[np.ndarray, sp.csc_matrix]:
    """``(pos, M_c)``: the sorted positions in ``on`` (``op.dofs`` or ``op.cols``) of the DOFs on
    which ``M`` (n_dofs × n) has stored entries, and ``M`` on those rows only
    (``M_c = M[on[pos]]``, CSC, entries in ``M``'s order). Entries on fixed DOFs are dropped
    (they do not move). Any other row outside ``on`` means the operator does not cover the load
    or the reading: an error, never a silent clamp. Works on ``M``'s index arrays (no format
    conversion of the whole matrix, no sparse fancy indexing)."""
    M = M if sp.isspmatrix_csc(M) else sp.csc_matrix(M)
    if not M.has_sorted_indices:
        M = M.sorted_indices()
    nz, inverse = np.unique(M.indices, return_inverse=True)
    pos = np.minimum(np.searchsorted(on, nz), max(on.size - 1, 0))
    inside = on[pos] == nz if on.size else np.zeros(nz.size, dtype=bool)
    if inside.all():
        return pos, sp.csc_matrix((M.data, inverse, M.indptr), shape=(nz.size, M.shape[1]))
    out = nz[~inside]
    free_out = out[~np.isin(out, op.fixed)]
    if free_out.size:
        raise SolverError(
            f"{free_out.size} free DOFs {what} lie outside the compliance operator "
            f"(e.g. DOF {int(free_out[0])}): the operator was built for other flanks"
        )
    keep = inside[inverse]
    row = np.cumsum(inside) - 1  # new row of each kept DOF
    col = np.repeat(np.arange(M.shape[1]), np.diff(M.indptr))
    counts = np.bincount(col[keep], minlength=M.shape[1])
    indptr = np.concatenate([[0], np.cumsum(counts)])
    Mc = sp.csc_matrix(
        (M.data[keep], row[inverse[keep]], indptr), shape=(int(inside.sum()), M.shape[1])
    )
    return pos[inside], Mc


def body_compliance(op: CandidateOperator, P: sp.csr_matrix) -> np.ndarray:
    """``C = P_f^T G_ff P_f`` (n_cells × n_cells, mm/N), symmetrised.

    ``P`` may have non-zero rows outside the load DOFs only on clamped DOFs, which do not move
    (any other row raises :class:`~fegear.errors.SolverError`). Only the DOFs ``P`` touches enter
    the product (``G`` restricted to them), so the cost is set by the cells, not by the size of
    the operator.
    """
    return cross_compliance(op, P, P, symmetric=True)


def cross_compliance(
    op: CandidateOperator,
    Q: sp.csr_matrix,
    P: sp.csr_matrix,
    symmetric: bool = False,
    projected: bool = False,
) -> np.ndarray:
    """``Q_c^T G P_f`` (n_probe × n_cells, mm/N): readings ``Q`` (on any candidate DOFs) per unit
    cell force ``P`` (on the load DOFs); ``symmetric``: the symmetric part (``Q = P``).
    ``projected``: ``Q`` and ``P`` are already in the operator's DOF basis
    (:meth:`CandidateOperator.project`; the columns of a projected matrix are the projected
    columns, so a caller reading blocks of cells projects each matrix once)."""
    rq, Qs = _compact(op, Q if projected else op.project(Q), op.dofs, "read")
    rp, Ps = _compact(op, P if projected else op.project(P), op.cols, "loaded")
    # Sparse times dense (a column of P or Q has 30-120 entries): measured 2.7x faster than
    # densifying them for a BLAS product at the sizes of a contact zone (500 x 700 rows). Read
    # first (Qᵀ G, on G's rows as gathered): only the (n_probe, n_rp) product is transposed for
    # SciPy's kernel, not the (n_rq, n_rp) block of G. A NaN of G (an entry no block holds)
    # reaches only the entries of C whose reading and load touch it: the sparse products add
    # only the stored entries of Q and P.
    A = Qs.T @ op.take(rq, rp)  # (n_probe, n_rp)
    C = np.asarray(Ps.T @ A.T).T
    return 0.5 * (C + C.T) if symmetric else C
