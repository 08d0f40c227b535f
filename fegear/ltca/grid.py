"""Contact grids of the loaded analysis: fine cells on the pinion flank where contact can occur.

The TCA gives, per position and tooth pair, the separation on a coarse grid over the whole
pinion flank. The loaded analysis needs cells small against the contact patch, but only where
the separation is below the largest approach the load can produce (``g_max``): the coarse cells
with separation ``<= g_max`` (:func:`near_cells`, dilated by one coarse cell) bound a box in the
flank coordinates
``(u, v)``, which is divided into cells of about ``cell_mm`` and their separations recomputed
exactly (the pinion normal through the cell centre meets the exact gear flank, as in the TCA).

Each cell carries 2 × 2 Gauss points on the exact pinion flank for the consistent loads, its
centre and normal in the fixed frame, its separation ``g``, its moment arm ``h`` about the
member-2 axis (gap after a further lag ``θ`` of member 2: ``g − θ h``), its area and its position
in a local flank-plane coordinate system (mm) for the patch measures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from fegear.geometry.pair_placement import tooth_transform
from fegear.geometry.transforms import apply_points, apply_vectors, compose
from fegear.ltca.cell_fit import MIN_FITTED, fit_to_boundaries, neighbour_values
from fegear.tca.core import TCA
from fegear.tca.results import PositionResult
from fegear.tca.solve import in_bounds, line_hit

__all__ = [
    "EDGE_TAGS",
    "PairCells",
    "edge_label",
    "edge_names",
    "missing_pairs",
    "near_cells",
    "pair_cells",
    "take_cells",
    "tca_edge_names",
]

Array = NDArray[np.float64]
_GAUSS2 = np.array([-1.0, 1.0]) / math.sqrt(3.0)
#: The working-flank boundaries a contact cell can touch, ``(member, boundary)``, in the bit order
#: of :attr:`PairCells.boundary_edges`: ``root`` is the fillet limit (``u_fillet``), ``tip`` the
#: tip (``u_tip``), ``v_start`` / ``v_end`` the face ends (:func:`edge_names` names them).
EDGE_TAGS = (
    ("pinion", "root"),
    ("pinion", "tip"),
    ("pinion", "v_start"),
    ("pinion", "v_end"),
    ("gear", "root"),
    ("gear", "tip"),
    ("gear", "v_start"),
    ("gear", "v_end"),
)
#: Grid points evaluated at most, in units of ``max_cells`` (see :func:`pair_cells`).
_PRECAP = 16


@dataclass(frozen=True)
class PairCells:
    """The contact cells of one tooth pair at one position (``n`` cells).

    Attributes
    ----------
    k, j
        Pinion and gear tooth indices of the pair (member numbering; tooth 0 is the reference).
    uv
        ``(n, 2)`` pinion flank coordinates of the cell centres.
    centers, normals
        ``(n, 3)`` fixed frame: points on the pinion flank and the pinion's outward unit normals.
    quad_points
        ``(n, 4, 3)`` fixed frame, 2 × 2 Gauss points of each cell on the pinion flank.
    gap
        ``(n,)`` mm, separation along the pinion normal at the TCA-closed position.
    h
        ``(n,)`` mm/rad, moment arm: ``−∂gap/∂θ`` for a lag ``θ`` of member 2.
    area
        ``(n,)`` mm².
    local
        ``(n, 2)`` mm, cell centres in the flank's tangent plane at the pair's closest point
        (along the cell axes ``ξ`` and, in-plane normal to it, ``η``; for the patch measures).
    edges
        ``(n, 2, 3)`` mm, fixed frame: the cell's edge vectors along ``ξ`` and ``η`` on the exact
        flank (``∂r/∂ξ s_ξ``, ``∂r/∂η s_η`` at the cell centre; the half-space near field lays
        each cell out in its own tangent plane from them).
    cell_mm
        ``(2,)`` mm, the grid's cell sizes along the cell axes ``ξ`` and ``η`` (a cell fitted to
        a flank boundary is shorter or longer along ``η``: its own extent is in ``edges``,
        :mod:`fegear.ltca.cell_fit`).
    boundary
        ``(n,)`` bool, the cell touches a boundary of the working flank of either member.
    boundary_edges
        ``(n,)`` uint8, which boundaries it touches: bit ``i`` set for :data:`EDGE_TAGS` ``[i]``
        (``boundary == (boundary_edges != 0)``; None for cells made without it).
    angle
        rad, the cell axes ``ξ, η`` are the ``u, v`` arc-length directions turned by ``angle``.
    origin
        ``(3,)`` fixed frame, the pair's closest point of the TCA on the pinion flank (the grid's
        origin; it rolls along the flank from one position to the next with the contact).
    """

    k: int
    j: int
    uv: Array
    centers: Array
    normals: Array
    quad_points: Array
    gap: Array
    h: Array
    area: Array
    local: Array
    edges: Array
    cell_mm: Array
    boundary: NDArray[np.bool_]
    angle: float = 0.0
    origin: Array | None = None
    boundary_edges: NDArray[np.uint8] | None = None

    @property
    def n(self) -> int:
        return int(self.gap.size)


def edge_label(member: str, tag: str, bounds) -> str:
    """Plain name of a working-flank boundary: ``member`` (``"pinion"``/``"gear"``), ``tag``
    (``"root"``, ``"tip"``, ``"v_start"``, ``"v_end"``, as in the TCA's edge strings) and the
    member's flank ``bounds`` (:class:`~fegear.geometry.surface.FlankBoundaries`, whose
    ``v_name`` says what the face ends are: toe/heel of a bevel, inner/outer end of a face gear,
    the ends −z/+z of a cylindrical gear)."""
    if tag == "tip":
        return f"{member} tip"
    if tag == "root":
        return f"{member} fillet limit (root end of the working flank)"
    v = (getattr(bounds, "v_name", "") or "").lower()
    first = tag == "v_start"
    if "toe" in v:
        end = "toe" if first else "heel"
    elif v.startswith("radius"):
        end = "inner end" if first else "outer end"
    else:
        end = "face end −z" if first else "face end +z"
    return f"{member} {end}"


def edge_names(mask: int | NDArray[np.uint8], bounds1, bounds2) -> tuple[str, ...]:
    """Names of the boundaries in an :attr:`PairCells.boundary_edges` bit mask (or the OR of
    several), in :data:`EDGE_TAGS` order; ``bounds1``/``bounds2`` the pinion's and the gear's
    flank bounds (:func:`edge_label`)."""
    m = (
        int(np.bitwise_or.reduce(np.atleast_1d(np.asarray(mask, dtype=np.uint8))))
        if np.size(mask)
        else 0
    )
    out = []
    for bit, (member, tag) in enumerate(EDGE_TAGS):
        if m >> bit & 1:
            out.append(edge_label(member, tag, bounds1 if member == "pinion" else bounds2))
    return tuple(out)


def tca_edge_names(edge: str, bounds1, bounds2) -> tuple[str, ...]:
    """Names of the boundaries in a TCA edge string (``"pinion:tip,gear:v_start"``,
    :attr:`fegear.tca.results.PositionResult.edge`)."""
    out = []
    for tag in filter(None, edge.split(",")):
        member, _, where = tag.partition(":")
        out.append(edge_label(member, where, bounds1 if member == "pinion" else bounds2))
    return tuple(out)


def separation_at(tca: TCA, phi1: float, ts: float, i: int, U: Array, V: Array):
    """Separations of pinion-flank points ``(U, V)`` (flank parameters, any shape ``S``) of TCA
    pair ``i`` at pinion angle ``phi1`` with the gear turned back by ``ts`` (rad), as the TCA's
    own separation grids compute them: each point is carried into the gear's tooth frame and
    its normal line intersected with the gear flank.

    Returns
    -------
    X, N
        ``S + (3,)``: the points and unit normals in the world frame (mm).
    s
        ``S``: separation along the normal (mm; 0 where ``ok`` is False).
    h
        ``S``: moment arm of the gear rotation along the normal (mm/rad): a rigid turn ``θ``
        of the gear closes the separation by ``θ h``.
    ok
        ``S``: the normal line meets the gear's working flank with ``h > 0``.
    gear_uv
        ``S + (2,)``: the gear-flank parameters of the hit points.
    """
    a = tca.asm
    fm1, fm2 = tca.fm1, tca.fm2
    _, _, P, N = fm1.native_point(U, V)
    T = tca._tooth_frames(np.array([phi1]), np.array([ts]))[0][i]
    Q, NQ = apply_points(T, P), apply_vectors(T, N)
    a0, b0 = tca.gear_start(np.hypot(Q[..., 0], Q[..., 1]), Q[..., 2])
    a2, b2, s, p2, n2, ok = line_hit(fm2, a0, b0, Q, NQ)
    u2, v2 = fm2.flank(a2, b2, p2)
    ok = ok & in_bounds(fm2, u2, v2)
    pdot = -a.sense2 * np.stack([-p2[..., 1], p2[..., 0], np.zeros_like(s)], -1)
    den = np.sum(NQ * n2, -1)
    h = -np.sum(pdot * n2, -1) / np.where(np.abs(den) > 1e-12, den, -1e-12)
    ok = ok & (h > 0) & np.isfinite(s)
    Mk = compose(a.placement1(phi1), tooth_transform(a.n1, tca.pairs[i, 0]))
    gear_uv = np.stack([u2, v2], -1)
    return apply_points(Mk, P), apply_vectors(Mk, N), np.where(ok, s, 0.0), h, ok, gear_uv


def _centres(x0: float, x1: float, dx: float) -> Array:
    """Cell centres ``k dx`` (one at 0, the pair's closest point) covering ``[x0, x1]``."""
    k0 = math.floor(x0 / dx + 0.5)
    k1 = math.ceil(x1 / dx - 0.5)
    return dx * np.arange(k0, k1 + 1)


def _patch_coordinates(centers: Array, normals: Array, edges: Array, origin: Array) -> Array:
    """``(n, 2)`` mm: cell centres in the tangent plane of the cell nearest ``origin`` (the
    pair's closest point), along its ``ξ`` edge and the in-plane normal to it on the ``η`` side,
    each stretched to its chord from that cell (the rule of
    :func:`fegear.mechanics.halfspace.tangent_layout`), less their mean.

    One flat map of a curved flank cannot be exact everywhere; this one is exact at the patch
    (it is laid where the contact is) and keeps the distances from it. Cumulative chord lengths
    along the grid lines, used before, place the cells of a grid turned on a flank whose metric
    varies at their column's mean spacing: measured on the seed face gear, the entering pair's
    patch semi-minor axis 0.27 mm where it is 0.23 mm.
    """
    i0 = int(np.argmin(np.linalg.norm(centers - origin, axis=1)))
    n0 = normals[i0] / np.linalg.norm(normals[i0])
    e1 = edges[i0, 0] - (edges[i0, 0] @ n0) * n0
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n0, e1)
    if e2 @ edges[i0, 1] < 0.0:
        e2 = -e2
    d = centers - centers[i0]
    x, y, z = d @ e1, d @ e2, d @ n0
    stretch = np.sqrt(1.0 + z * z / np.maximum(x * x + y * y, 1e-24))
    local = np.stack([x * stretch, y * stretch], -1)
    return local - local.mean(axis=0)


def grid_map(fm, uc: float, vc: float, coarse: Array, steps, angle: float) -> Array:
    """``(2, 2)``: the map ``A`` from arc lengths ``(ξ, η)`` (mm) along the cell axes to flank
    parameters, ``(u, v) = (uc, vc) + A (ξ, η)``, exact at ``(uc, vc)`` to first order.

    With ``J = [r_u r_v]`` the flank's tangent vectors at ``(uc, vc)`` (central differences on
    the exact flank map ``fm``), ``e_1 = r_u/|r_u|`` and ``e_2`` the unit vector of the tangent
    plane normal to it on the ``r_v`` side, the cell axes are ``[e_1 e_2] R(angle)`` and

        A = (Jᵀ J)⁻¹ Jᵀ [e_1 e_2] R(angle)

    (the least-squares inverse of ``J``: exact in the tangent plane). Where ``u`` and ``v`` are
    orthogonal arc-length-proportional coordinates this is ``diag(1/|r_u|, 1/|r_v|) R(angle)``.
    Where they are not, a map from the mean lengths per unit ``u`` and ``v`` over the flank
    turns the cells by another angle than ``angle`` and stretches them: on an involute helicoid
    the length per unit of the roll parameter grows fourfold from root to tip and the ``u`` and
    ``v`` lines are not orthogonal, and the turn that :func:`fegear.ltca.hybrid.refined_sizes`
    measured on a patch was applied with a gain of two or more, so the grid of a contact line
    100 mm long swung ±0.5 rad from one refinement to the next and never resolved the line
    (ISO/TR 6336-30 example 1 with f_Hβ 10 µm: 19 of 25 positions degenerate).

    ``coarse``: ``(nu, nv, 3)`` points of the coarse TCA grid (their spacing sets the
    difference steps, ``steps``: the grid's parameter spacings ``(Δu, Δv)``).
    """
    b = fm.bounds
    nu, nv = coarse.shape[:2]
    du_c, dv_c = steps
    lu = np.linalg.norm(coarse[1:] - coarse[:-1], axis=-1).mean() / du_c if nu > 1 else 1.0
    lv = np.linalg.norm(coarse[:, 1:] - coarse[:, :-1], axis=-1).mean() / dv_c if nv > 1 else 1.0
    # steps of about 1 µm, the stencil kept on the working flank
    hu = min(1e-3 / lu, 0.25 * (b.u_tip - b.u_fillet))
    hv = min(1e-3 / lv, 0.25 * (b.v_end - b.v_start))
    u0 = min(max(uc, b.u_fillet + hu), b.u_tip - hu)
    v0 = min(max(vc, b.v_start + hv), b.v_end - hv)
    _, _, P, N = fm.native_point(
        np.array([u0 + hu, u0 - hu, u0, u0, u0]), np.array([v0, v0, v0 + hv, v0 - hv, v0])
    )
    J = np.stack([(P[0] - P[1]) / (2.0 * hu), (P[2] - P[3]) / (2.0 * hv)], axis=1)
    n = N[4] / np.linalg.norm(N[4])
    e1 = J[:, 0] - (J[:, 0] @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    if e2 @ J[:, 1] < 0.0:
        e2 = -e2
    ca, sa = math.cos(angle), math.sin(angle)
    E = np.stack([e1, e2], axis=1) @ np.array([[ca, -sa], [sa, ca]])
    return np.linalg.solve(J.T @ J, J.T @ E)


def near_cells(pos: PositionResult, grid_index: int, g_max: float) -> NDArray[np.bool_]:
    """``(nu, nv)`` bool: the coarse cells of the pair ``pos.grids[grid_index]`` whose region
    may hold a separation ``<= g_max``.

    The coarse grid samples the separation at its cell centres only. A separation valley
    narrower than a coarse cell (a localized contact's: the loaded patch of the seed face gear is
    0.5 mm wide, its coarse cells 1.5 × 1.2 mm) can run between the samples with its floor below
    every one of them, and a pair about to enter would be missed (measured on the seed face gear,
    φ1 = −3.74°: pair (−1, −1) 8.8 µm from contact at its closest point, every sample above
    ``g_max`` = 13 µm; it takes 0.5 % of the torque and the loaded TE moves by 0.018″). So the
    coarse cell holding the pair's closest point (where the TCA solved the separation exactly,
    ``pos.backlash_mm``) is near too whenever that separation is within ``g_max``.
    """
    g = pos.grids[grid_index]
    near = g.valid & (g.separation <= g_max)
    ip = int(np.flatnonzero((pos.pairs[:, 0] == g.k) & (pos.pairs[:, 1] == g.j))[0])
    # (backlash_mm is 0 where the TCA's normal missed the gear flank: unknown, not touching)
    known = pos.backlash_mm[ip] > 0.0 or pos.backlash_rad[ip] <= 0.0
    if pos.pair_valid[ip] and known and pos.backlash_mm[ip] <= g_max:
        # the valid cell nearest the closest point (which may lie on a flank edge, where the
        # normal of the cell around it misses the gear flank), in units of the cell sizes
        u, v = pos.pinion_uv[ip]
        du = (g.u[:, None] - u) / max(abs(g.u[-1] - g.u[0]) / max(g.u.size - 1, 1), 1e-300)
        dv = (g.v[None, :] - v) / max(abs(g.v[-1] - g.v[0]) / max(g.v.size - 1, 1), 1e-300)
        d2 = np.where(g.valid, du**2 + dv**2, np.inf)
        iu, iv = np.unravel_index(int(np.argmin(d2)), d2.shape)
        if np.isfinite(d2[iu, iv]):
            near = near.copy()
            near[iu, iv] = True
    return near


def _boundary_mask(CU, CV, A, size, inside, ok, guv, b, b2) -> NDArray[np.uint8]:
    """``(nξ, nη)`` uint8 :data:`EDGE_TAGS` bits of the grid cells on a working-flank boundary.

    A cell is on a boundary when it is the last cell of its row or column before it: it reaches
    the boundary, or its neighbour one cell further (along ``±ξ`` or ``±η``) has its centre off
    the pinion's working flank (the pinion bits, by the side the neighbour leaves by) or on the
    pinion's flank but off the gear's (its normal misses the gear's working flank: the gear bit
    of the gear boundary nearest the cell's gear coordinates). The grid keeps only cells whose
    centre lies on both flanks, so between its last cell and a boundary lies a strip of up to
    one cell that no cell covers, and a boundary oblique to the cell axes staggers that last
    cell from row to row: a contact reaching the boundary loads the last cell of each row, not a
    cell touching the boundary (FZG at 400 N·m on the gear: the pinion-tip contact loaded cells
    one to half a cell short of the tip, which no test of a cell reaching the tip marked).
    ``CU, CV``: the cell centres' flank parameters, ``A`` the map ``(ξ, η) → (u, v)``, ``size``
    the cell sizes ``(s_ξ, s_η)`` mm, ``inside``/``ok`` the grid points on the pinion's flank and
    whose normal meets the gear's, ``guv`` their gear flank parameters, ``b``/``b2`` the
    pinion's and the gear's flank bounds."""
    du, dv = size
    tu, tv = 1e-9 * (b.u_tip - b.u_fillet), 1e-9 * (b.v_end - b.v_start)
    hu = 0.5 * (abs(A[0, 0]) * du + abs(A[0, 1]) * dv)  # half extent of a cell along u, v
    hv = 0.5 * (abs(A[1, 0]) * du + abs(A[1, 1]) * dv)
    su, sv = 0.01 * (b2.u_tip - b2.u_fillet), 0.01 * (b2.v_end - b2.v_start)
    touches = [
        CU - hu <= b.u_fillet + tu,
        CU + hu >= b.u_tip - tu,
        CV - hv <= b.v_start + tv,
        CV + hv >= b.v_end - tv,
        guv[..., 0] <= b2.u_fillet + su,
        guv[..., 0] >= b2.u_tip - su,
        guv[..., 1] <= b2.v_start + sv,
        guv[..., 1] >= b2.v_end - sv,
    ]
    # the gear boundary nearest each cell, in units of the gear flank's extent
    d2 = np.stack(
        [
            (guv[..., 0] - b2.u_fillet) / (b2.u_tip - b2.u_fillet),
            (b2.u_tip - guv[..., 0]) / (b2.u_tip - b2.u_fillet),
            (guv[..., 1] - b2.v_start) / (b2.v_end - b2.v_start),
            (b2.v_end - guv[..., 1]) / (b2.v_end - b2.v_start),
        ]
    )
    nearest = np.argmin(d2, axis=0)
    miss = inside & ~ok  # on the pinion's flank, off the gear's
    nx, ny = CU.shape
    for axis, step in ((0, 1), (0, -1), (1, 1), (1, -1)):
        col = 0 if axis == 0 else 1
        s = du if axis == 0 else dv
        nu = CU + step * A[0, col] * s  # the neighbour's centre
        nv = CV + step * A[1, col] * s
        touches[0] |= nu < b.u_fillet
        touches[1] |= nu > b.u_tip
        touches[2] |= nv < b.v_start
        touches[3] |= nv > b.v_end
        # the neighbour is on the pinion's flank, off the gear's
        off = neighbour_values(miss, axis, step, np.zeros_like(miss))
        for k in range(4):
            touches[4 + k] |= off & (nearest == k)
    mask = np.zeros(CU.shape, dtype=np.uint8)
    for bit, t in enumerate(touches):
        mask |= (t & inside).astype(np.uint8) << np.uint8(bit)
    return mask


def pair_cells(
    tca: TCA,
    pos: PositionResult,
    grid_index: int,
    cell_mm: float | tuple[float, float],
    g_max: float,
    max_cells: int = 4000,
    angle: float = 0.0,
) -> PairCells | None:
    """Fine contact cells of one pair at one position, or None if no cell is within ``g_max``.

    Parameters
    ----------
    tca
        The TCA of the pair (its flank maps and transforms).
    pos
        The TCA position (with coarse separation grids).
    grid_index
        Index into ``pos.grids``.
    cell_mm
        Target cell size (mm), or ``(along ξ, along η)``.
    g_max
        mm, cells with a larger separation cannot take load at the load considered.
    max_cells
        Cap on the cells kept; both sizes grow in proportion if it would be exceeded.
    angle
        rad, rotation of the cell grid: the cell axes ``ξ, η`` are the flank's ``u`` and ``v``
        arc-length directions turned by ``angle`` (the ``hybrid`` fidelity aligns its cells with
        the contact ellipse, which is oblique to the flank grid in general). With ``angle = 0``
        ``ξ = u``, ``η = v``.
    """
    cu_mm, cv_mm = (cell_mm, cell_mm) if np.isscalar(cell_mm) else cell_mm
    g = pos.grids[grid_index]
    i = int(np.flatnonzero((tca.pairs[:, 0] == g.k) & (tca.pairs[:, 1] == g.j))[0])
    near = near_cells(pos, grid_index, g_max)
    if not near.any():
        return None
    b = tca.fm1.bounds
    nu, nv = g.valid.shape
    du_c, dv_c = g.u[1] - g.u[0], g.v[1] - g.v[0]
    # The cell grid: centres (u, v) = (uc, vc) + A (ξ, η), with a centre on the pair's closest
    # point, so that the discretisation is the same for every pair and position (no cell-phase
    # jitter); A maps arc lengths along the turned axes to flank parameters (grid_map).
    ip = int(np.flatnonzero((pos.pairs[:, 0] == g.k) & (pos.pairs[:, 1] == g.j))[0])
    uc, vc = pos.pinion_uv[ip]
    A = grid_map(tca.fm1, float(uc), float(vc), g.points, (du_c, dv_c), angle)
    Ainv = np.linalg.inv(A)
    # The coarse cells within g_max, dilated by one coarse cell, in (ξ, η).
    iu, iv = np.nonzero(near)
    corner_u, corner_v = np.array([-1.5, 1.5, -1.5, 1.5]), np.array([-1.5, -1.5, 1.5, 1.5])
    U_near = np.clip(g.u[iu][:, None] + du_c * corner_u, b.u_fillet, b.u_tip)
    V_near = np.clip(g.v[iv][:, None] + dv_c * corner_v, b.v_start, b.v_end)
    xe = np.einsum("ij,jnk->ink", Ainv, np.stack([U_near - uc, V_near - vc]))
    lo, hi = xe.reshape(2, -1).min(axis=1), xe.reshape(2, -1).max(axis=1)
    # Never evaluate more than 16 max_cells grid points: fine cells over a large zone would
    # (47 million points, 24 GB, were asked for once); the kept cells are capped below anyway.
    n_box = ((hi[0] - lo[0]) / cu_mm + 2.0) * ((hi[1] - lo[1]) / cv_mm + 2.0)
    if n_box > _PRECAP * max_cells:
        f = math.sqrt(n_box / (_PRECAP * max_cells))
        cu_mm, cv_mm = cu_mm * f, cv_mm * f
    for _ in range(3):
        cx, cy = _centres(lo[0], hi[0], cu_mm), _centres(lo[1], hi[1], cv_mm)
        XI, ETA = np.meshgrid(cx, cy, indexing="ij")
        CU = uc + A[0, 0] * XI + A[0, 1] * ETA
        CV = vc + A[1, 0] * XI + A[1, 1] * ETA
        inside = (CU >= b.u_fillet) & (CU <= b.u_tip) & (CV >= b.v_start) & (CV <= b.v_end)
        if not inside.any():
            return None
        # Only grid points on the flank are evaluated (the flank map may not extend far).
        shp = CU.shape
        X, N = np.full(shp + (3,), np.nan), np.full(shp + (3,), np.nan)
        s, h, guv = np.full(shp, np.inf), np.zeros(shp), np.zeros(shp + (2,))
        ok = np.zeros(shp, dtype=bool)
        Xi, Ni, si, hi_, oki, guvi = separation_at(
            tca, pos.phi1, -pos.te_rad, i, CU[inside], CV[inside]
        )
        X[inside], N[inside], s[inside], h[inside], ok[inside], guv[inside] = (
            Xi,
            Ni,
            si,
            hi_,
            oki,
            guvi,
        )
        keep = inside & ok & (s <= g_max)
        if keep.sum() <= max_cells:
            break
        f = math.sqrt(keep.sum() / max_cells) * 1.05
        cu_mm, cv_mm = cu_mm * f, cv_mm * f
    if not keep.any():
        return None

    def on_at(xi: Array, eta: Array) -> NDArray[np.bool_]:
        """Grid points on both working flanks (the pinion's, and the gear's hit)."""
        u = uc + A[0, 0] * xi + A[0, 1] * eta
        v = vc + A[1, 0] * xi + A[1, 1] * eta
        res = (u >= b.u_fillet) & (u <= b.u_tip) & (v >= b.v_start) & (v <= b.v_end)
        if res.any():
            res[res] = separation_at(tca, pos.phi1, -pos.te_rad, i, u[res], v[res])[4]
        return res

    # The cells' edges, the outer ones on the flank boundaries (fegear.ltca.cell_fit).
    lo_e, hi_e = fit_to_boundaries(on_at, XI, ETA, inside & ok, keep, (cu_mm, cv_mm))
    sliver = (hi_e - lo_e)[:, 1] < MIN_FITTED * cv_mm  # keeps its grid cell (cell_fit)
    if sliver.any():
        c0 = np.stack([XI[keep], ETA[keep]], -1)[sliver]
        lo_e[sliver] = c0 - 0.5 * np.array([cu_mm, cv_mm])
        hi_e[sliver] = c0 + 0.5 * np.array([cu_mm, cv_mm])
    mid, size = 0.5 * (lo_e + hi_e), hi_e - lo_e
    moved = np.any(np.abs(mid - np.stack([XI[keep], ETA[keep]], -1)) > 1e-12, axis=1)
    Xk, Nk, sk, hk = X[keep], N[keep], s[keep], h[keep]
    CUk = uc + A[0, 0] * mid[:, 0] + A[0, 1] * mid[:, 1]
    CVk = vc + A[1, 0] * mid[:, 0] + A[1, 1] * mid[:, 1]
    if moved.any():
        Xm, Nm, sm, hm, okm, _ = separation_at(
            tca, pos.phi1, -pos.te_rad, i, CUk[moved], CVk[moved]
        )
        # (a fitted centre lies between the kept centre and its boundary: on both flanks)
        take = np.flatnonzero(moved)[okm]
        Xk[take], Nk[take], sk[take], hk[take] = Xm[okm], Nm[okm], sm[okm], hm[okm]
        back = np.flatnonzero(moved)[~okm]
        mid[back] = np.stack([XI[keep], ETA[keep]], -1)[back]
        size[back] = (cu_mm, cv_mm)
        CUk[back], CVk[back] = CU[keep][back], CV[keep][back]
    # 2 x 2 Gauss points of the kept cells (exact pinion flank, fixed frame).
    su, sv = size[:, 0], size[:, 1]
    gx = mid[:, 0][:, None, None] + 0.5 * su[:, None, None] * _GAUSS2[None, :, None]
    gy = mid[:, 1][:, None, None] + 0.5 * sv[:, None, None] * _GAUSS2[None, None, :]
    gx, gy = np.broadcast_arrays(gx, gy)
    gu = uc + A[0, 0] * gx + A[0, 1] * gy
    gv = vc + A[1, 0] * gx + A[1, 1] * gy
    _, _, Pq, _ = tca.fm1.native_point(gu.reshape(-1), gv.reshape(-1))
    Mk = compose(tca.asm.placement1(pos.phi1), tooth_transform(tca.asm.n1, g.k))
    quad = apply_points(Mk, Pq).reshape(-1, 4, 3)
    # Areas from the Gauss points: |r_ξ x r_η| dξ dη by central differences of the 2x2 points.
    q = quad.reshape(-1, 2, 2, 3)
    rx = (q[:, 1, :, :] - q[:, 0, :, :]).mean(axis=1) / (su[:, None] / math.sqrt(3.0))
    ry = (q[:, :, 1, :] - q[:, :, 0, :]).mean(axis=1) / (sv[:, None] / math.sqrt(3.0))
    area = np.linalg.norm(np.cross(rx, ry), axis=-1) * su * sv
    edges = np.stack([rx * su[:, None], ry * sv[:, None]], axis=1)
    local = _patch_coordinates(Xk, Nk, edges, np.asarray(pos.points[ip], dtype=float))
    du, dv = cu_mm, cv_mm  # cell sizes along ξ, η (mm)
    mask = _boundary_mask(CU, CV, A, (du, dv), inside, ok, guv, b, tca.fm2.bounds)
    return PairCells(
        k=int(g.k),
        j=int(g.j),
        uv=np.stack([CUk, CVk], -1),
        centers=Xk,
        normals=Nk,
        quad_points=quad,
        gap=sk,
        h=hk,
        area=area,
        local=local,
        edges=edges,
        cell_mm=np.array([du, dv]),
        angle=float(angle),
        boundary=mask[keep] != 0,
        origin=np.asarray(pos.points[ip], dtype=float),
        boundary_edges=mask[keep],
    )


def take_cells(cells: PairCells, index: NDArray[np.intp]) -> PairCells:
    """The cells ``index`` of one pair's cells (same grid; ``local`` re-centred on them)."""
    local = cells.local[index]
    if local.shape[0]:
        local = local - local.mean(axis=0)
    return replace(
        cells,
        uv=cells.uv[index],
        centers=cells.centers[index],
        normals=cells.normals[index],
        quad_points=cells.quad_points[index],
        gap=cells.gap[index],
        h=cells.h[index],
        area=cells.area[index],
        local=local,
        edges=cells.edges[index],
        boundary=cells.boundary[index],
        boundary_edges=None if cells.boundary_edges is None else cells.boundary_edges[index],
    )


def missing_pairs(
    pos: PositionResult, cells: list[PairCells], g_max: float, modelled
) -> list[tuple[int, int]]:
    """Pairs ``(k, j)`` of the TCA position whose exact closest point is within ``g_max`` of
    touching (``pos.backlash_mm``) but which have no cell in ``cells`` (a separation valley at a
    flank edge, narrower than the cells around it); ``modelled(k, j)``: the pair's teeth are in
    the sectors."""
    have = {(c.k, c.j) for c in cells}
    out = []
    for (k, j), ok, b in zip(pos.pairs.tolist(), pos.pair_valid, pos.backlash_mm, strict=True):
        if ok and 0.0 < b <= g_max and (k, j) not in have and modelled(k, j):
            out.append((int(k), int(j)))
    return out
