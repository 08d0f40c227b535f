"""Contact grids of the loaded analysis: fine cells on the pinion flank where contact can occur.

The TCA gives, per position and tooth pair, the separation on a coarse grid over the whole
pinion flank. The loaded analysis needs cells small against the contact patch, but only where
the separation is below the largest approach the load can produce (``g_max``): the coarse cells
with separation ``<= g_max`` (dilated by one coarse cell) bound a box in the flank coordinates
``(u, v)``, which is divided into cells of about ``cell_mm`` and their separations recomputed
exactly (the pinion normal through the cell centre meets the exact gear flank, as in the TCA).

Each cell carries 2 × 2 Gauss points on the exact pinion flank for the consistent loads, its
centre and normal in the fixed frame, its separation ``g``, its moment arm ``h`` about the
member-2 axis (gap after a further lag ``θ`` of member 2: ``g − θ h``), its area and its position
in a local flank-plane coordinate system (mm) for the patch measures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fegear.assembly import tooth_transform
from fegear.geometry.transforms import apply_points, apply_vectors, compose
from fegear.tca.core import TCA
from fegear.tca.results import PositionResult
from fegear.tca.solve import in_bounds, line_hit

__all__ = ["PairCells", "pair_cells"]

Array = NDArray[np.float64]
_GAUSS2 = np.array([-1.0, 1.0]) / math.sqrt(3.0)


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
        ``(n, 2)`` mm, cell centres in intrinsic flank coordinates (arc lengths along the u and
        v grid lines; for patch measures and the half-space near field).
    half_widths
        ``(n, 2)`` mm, half the cell sizes along u and v (from the exact flank tangents).
    cell_mm
        ``(2,)`` mm, cell sizes along ``u`` and ``v``.
    boundary
        ``(n,)`` bool, the cell touches a boundary of the working flank of either member.
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
    half_widths: Array
    cell_mm: Array
    boundary: NDArray[np.bool_]

    @property
    def n(self) -> int:
        return int(self.gap.size)


def _separation(tca: TCA, phi1: float, ts: float, i: int, U: Array, V: Array):
    """Separations of pinion-flank points ``(U, V)`` of pair ``i`` (as ``TCA._grids``)."""
    a = tca.asm
    fm1, fm2 = tca.fm1, tca.fm2
    ca, cb = fm1.native(U, V)
    P, N = fm1.evaluate(ca, cb)
    T = tca._tooth_frames(np.array([phi1]), np.array([ts]))[0][i]
    Q, NQ = apply_points(T, P), apply_vectors(T, N)
    idx = tca.gtree.query(np.stack([np.hypot(Q[..., 0], Q[..., 1]), Q[..., 2]], -1))[1]
    a2, b2, s, p2, n2, ok = line_hit(fm2, tca.ga[idx], tca.gb[idx], Q, NQ)
    u2, v2 = fm2.flank(a2, b2, p2)
    ok = ok & in_bounds(fm2, u2, v2)
    pdot = -a.sense2 * np.stack([-p2[..., 1], p2[..., 0], np.zeros_like(s)], -1)
    den = np.sum(NQ * n2, -1)
    h = -np.sum(pdot * n2, -1) / np.where(np.abs(den) > 1e-12, den, -1e-12)
    ok = ok & (h > 0) & np.isfinite(s)
    Mk = compose(a.placement1(phi1), tooth_transform(a.n1, tca.pairs[i, 0]))
    gear_uv = np.stack([u2, v2], -1)
    return apply_points(Mk, P), apply_vectors(Mk, N), np.where(ok, s, 0.0), h, ok, gear_uv


def _aligned(x0: float, x1: float, dx: float, xc: float, lo: float, hi: float) -> Array:
    """Cell centres of size ``dx`` covering ``[x0, x1]``, one of them at ``xc``, with their
    centres within the flank bounds ``[lo, hi]`` (an end cell may overhang the bound by less
    than half a cell; its load is located on the nearest flank facet)."""
    k0 = math.floor((x0 - xc) / dx + 0.5)
    k1 = math.ceil((x1 - xc) / dx - 0.5)
    c = xc + dx * np.arange(k0, k1 + 1)
    c = c[(c >= lo) & (c <= hi)]
    return c if c.size else np.array([min(max(xc, lo), hi)])


def pair_cells(
    tca: TCA,
    pos: PositionResult,
    grid_index: int,
    cell_mm: float | tuple[float, float],
    g_max: float,
    max_cells: int = 4000,
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
        Target cell size (mm), or ``(along u, along v)``.
    g_max
        mm, cells with a larger separation cannot take load at the load considered.
    max_cells
        Cap on the cells of the box; both sizes grow in proportion if it would be exceeded.
    """
    cu_mm, cv_mm = (cell_mm, cell_mm) if np.isscalar(cell_mm) else cell_mm
    g = pos.grids[grid_index]
    i = int(np.flatnonzero((tca.pairs[:, 0] == g.k) & (tca.pairs[:, 1] == g.j))[0])
    near = g.valid & (g.separation <= g_max)
    if not near.any():
        return None
    # Dilate by one coarse cell and take the bounding box in (u, v).
    iu, iv = np.nonzero(near)
    nu, nv = g.valid.shape
    b = tca.fm1.bounds
    du_c, dv_c = g.u[1] - g.u[0], g.v[1] - g.v[0]
    u0 = max(b.u_fillet, g.u[max(iu.min() - 1, 0)] - 0.5 * du_c)
    u1 = min(b.u_tip, g.u[min(iu.max() + 1, nu - 1)] + 0.5 * du_c)
    v0 = max(b.v_start, g.v[max(iv.min() - 1, 0)] - 0.5 * dv_c)
    v1 = min(b.v_end, g.v[min(iv.max() + 1, nv - 1)] + 0.5 * dv_c)
    # Lengths (mm) per unit u and v from the coarse grid points.
    P = g.points
    lu = np.linalg.norm(P[1:, :, :] - P[:-1, :, :], axis=-1).mean() / du_c if nu > 1 else 1.0
    lv = np.linalg.norm(P[:, 1:, :] - P[:, :-1, :], axis=-1).mean() / dv_c if nv > 1 else 1.0
    n_u = max(1, int(math.ceil((u1 - u0) * lu / cu_mm)))
    n_v = max(1, int(math.ceil((v1 - v0) * lv / cv_mm)))
    if n_u * n_v > max_cells:
        f = math.sqrt(max_cells / (n_u * n_v))
        n_u, n_v = max(1, int(n_u * f)), max(1, int(n_v * f))
    du, dv = (u1 - u0) / n_u, (v1 - v0) / n_v
    # Align the cells on the pair's closest point (a cell centre on it), so that the
    # discretisation is the same for every pair and every position (no cell-phase jitter).
    ip = int(np.flatnonzero((pos.pairs[:, 0] == g.k) & (pos.pairs[:, 1] == g.j))[0])
    uc, vc = pos.pinion_uv[ip]
    cu = _aligned(u0, u1, du, uc, b.u_fillet, b.u_tip)
    cv = _aligned(v0, v1, dv, vc, b.v_start, b.v_end)
    CU, CV = np.meshgrid(cu, cv, indexing="ij")
    ts = -pos.te_rad
    X, N, s, h, ok, guv = _separation(tca, pos.phi1, ts, i, CU, CV)
    keep = ok & (s <= g_max)
    if not keep.any():
        return None
    # 2 x 2 Gauss points of the kept cells (exact pinion flank, fixed frame).
    gu = CU[keep][:, None, None] + 0.5 * du * _GAUSS2[None, :, None]
    gv = CV[keep][:, None, None] + 0.5 * dv * _GAUSS2[None, None, :]
    gu, gv = np.broadcast_arrays(gu, gv)
    qa, qb = tca.fm1.native(gu.reshape(-1), gv.reshape(-1))
    Pq, _ = tca.fm1.evaluate(qa, qb)
    Mk = compose(tca.asm.placement1(pos.phi1), tooth_transform(tca.asm.n1, g.k))
    quad = apply_points(Mk, Pq).reshape(-1, 4, 3)
    # Areas from the Gauss points: |r_u x r_v| du dv by central differences of the 2x2 points.
    q = quad.reshape(-1, 2, 2, 3)
    ru = (q[:, 1, :, :] - q[:, 0, :, :]).mean(axis=1) / (du / math.sqrt(3.0))
    rv = (q[:, :, 1, :] - q[:, :, 0, :]).mean(axis=1) / (dv / math.sqrt(3.0))
    area = np.linalg.norm(np.cross(ru, rv), axis=-1) * du * dv
    # Intrinsic flank coordinates (mm): cumulative chord lengths along the u and v grid lines,
    # so that the cells tile the plane without overlap even where the flank is strongly curved
    # (a projection on one tangent plane would squeeze the far cells together).
    su = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(X, axis=0), axis=-1).mean(1))])
    sv = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(X, axis=1), axis=-1).mean(0))])
    IU, IV = np.meshgrid(np.arange(CU.shape[0]), np.arange(CU.shape[1]), indexing="ij")
    lu_, lv_ = su[IU[keep]], sv[IV[keep]]
    local = np.stack([lu_ - lu_.mean(), lv_ - lv_.mean()], -1)
    half_widths = 0.5 * np.stack(
        [np.linalg.norm(ru, axis=-1) * du, np.linalg.norm(rv, axis=-1) * dv], -1
    )
    # Cells touching a working-flank boundary of the pinion or the gear.
    tu, tv = 1e-9 * (b.u_tip - b.u_fillet), 1e-9 * (b.v_end - b.v_start)
    on_p = (
        (CU - 0.5 * du <= b.u_fillet + tu)
        | (CU + 0.5 * du >= b.u_tip - tu)
        | (CV - 0.5 * dv <= b.v_start + tv)
        | (CV + 0.5 * dv >= b.v_end - tv)
    )
    b2 = tca.fm2.bounds
    su, sv = 0.01 * (b2.u_tip - b2.u_fillet), 0.01 * (b2.v_end - b2.v_start)
    on_g = (
        (guv[..., 0] <= b2.u_fillet + su)
        | (guv[..., 0] >= b2.u_tip - su)
        | (guv[..., 1] <= b2.v_start + sv)
        | (guv[..., 1] >= b2.v_end - sv)
    )
    return PairCells(
        k=int(g.k),
        j=int(g.j),
        uv=np.stack([CU[keep], CV[keep]], -1),
        centers=X[keep],
        normals=N[keep],
        quad_points=quad,
        gap=s[keep],
        h=h[keep],
        area=area,
        local=local,
        half_widths=half_widths,
        cell_mm=np.array([du * lu, dv * lv]),
        boundary=(on_p | on_g)[keep],
    )
