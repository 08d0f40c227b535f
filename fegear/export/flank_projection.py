"""Closest points on a member's exact working flank: where a deck puts the nodes of its flank
faces (:func:`fegear.export.inp.tet10_body`, ``project``).

A C3D10 face with its mid-edge nodes at the chord midpoints lies inside a convex flank by up to
``h² / (8 R)`` (``h`` the element size, ``R`` the flank's radius of curvature): 2.5 µm for
``h`` = 0.5 mm on the 12 mm profile radius of the FZG pinion at its pitch point, a quarter of the
elastic approach there, and as much as the separation that decides whether a second pair carries
load. On the exact surface the quadratic face follows it to ``O(h³)``.

**The surface.** The member's own flank (:meth:`~fegear.mesh.sector_geometry.SectorFrame.
flank_points`, modifications included: a member with flank modifications is meshed as its
unmodified solid, :func:`fegear.mesh.sector.sector_mesh`, and its flank nodes moved onto the
modified flank put the modification, some µm, into the deck), evaluated exactly on a
:data:`GRID` × :data:`GRID` grid of the working flank ``[u_fillet, u_tip] × [L_start, L_end]``
and interpolated by bicubic splines per coordinate. A face-gear flank point is an iterative
envelope solve (about a millisecond): Gauss-Newton on the exact flank for the 10⁴-10⁵ flank nodes
of a deck takes minutes, on the splines a second. The splines' error is checked on the cell
midpoints of the grid when they are made (:class:`~fegear.errors.MeshError` beyond
:data:`MAX_SPLINE_ERROR_MM`).

**The closest point.** Gauss-Newton on ``|p(u, v) − x|²`` from the nearest grid point, ``u``
kept within the working flank (below ``u_fillet`` the parameters run onto the fillet).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import RectBivariateSpline
from scipy.spatial import cKDTree

from fegear.errors import MeshError
from fegear.mesh.sector_geometry import sector_frame

__all__ = ["flank_projection", "GRID", "MAX_SPLINE_ERROR_MM"]

Array = NDArray[np.float64]
#: Exact flank points per parameter direction of the interpolating splines.
GRID = 81
#: Largest tolerated spline error (mm) at the grid's cell midpoints (0.1 µm): far below the sags it
#: corrects (µm) and the separations of the second pairs.
MAX_SPLINE_ERROR_MM = 1e-4


#: the splines of the last few (member, side): every tooth of a member shares them
_SPLINES: dict[tuple[int, str, float], tuple[object, tuple]] = {}


def _splines(member, side: str, rim_modules: float) -> tuple:
    """``(frame, splines, u, v, grid points)`` of a member's working flank (tooth 0)."""
    key = (id(member), side, rim_modules)
    hit = _SPLINES.get(key)
    if hit is not None and hit[0] is member:
        return hit[1]
    fr = sector_frame(member, rim_modules)
    u = np.linspace(fr.u_fillet, fr.u_tip, GRID)
    v = np.linspace(fr.L_start, fr.L_end, GRID)
    G = fr.flank_points(side, u[:, None], v[None, :])  # (GRID, GRID, 3), tooth 0
    sp = [RectBivariateSpline(u, v, G[..., c]) for c in range(3)]
    um, vm = 0.5 * (u[1:] + u[:-1]), 0.5 * (v[1:] + v[:-1])
    iu = np.arange(0, GRID - 1, 8)
    exact = fr.flank_points(side, um[iu][:, None], vm[iu][None, :])
    approx = np.stack([s(um[iu], vm[iu]) for s in sp], axis=-1)
    err = float(np.max(np.linalg.norm(exact - approx, axis=-1)))
    if err > MAX_SPLINE_ERROR_MM:
        raise MeshError(
            f"flank splines of {getattr(member, 'name', member)!r} miss the flank by {err:.2g} mm"
            f" (at most {MAX_SPLINE_ERROR_MM} mm)"
        )
    out = (fr, sp, u, v, G)
    if len(_SPLINES) >= 4:
        _SPLINES.pop(next(iter(_SPLINES)))
    _SPLINES[key] = (member, out)
    return out


def flank_projection(
    member, side: str, tooth: int, rim_modules: float = 3.0
) -> Callable[[Array], Array]:
    """``f(points (q, 3)) -> (q, 3)``: closest points on the working ``side`` flank (with its
    modifications) of member tooth ``tooth`` (member frame, mm).

    Raises
    ------
    MeshError
        The splines miss the exact flank by more than :data:`MAX_SPLINE_ERROR_MM`.
    """
    fr, sp, u, v, G = _splines(member, side, rim_modules)
    tree = cKDTree(G.reshape(-1, 3))
    U, V = np.meshgrid(u, v, indexing="ij")
    U, V = U.ravel(), V.ravel()

    def at(a: Array, b: Array, da: int = 0, db: int = 0) -> Array:
        return np.stack([s(a, b, dx=da, dy=db, grid=False) for s in sp], axis=-1)

    def project(x: Array) -> Array:
        x0 = fr.on_tooth(np.asarray(x, dtype=float), -tooth)  # onto tooth 0
        k = tree.query(x0)[1]
        a, b = U[k].copy(), V[k].copy()
        for _ in range(20):
            r = at(a, b) - x0
            pa, pb = at(a, b, 1, 0), at(a, b, 0, 1)
            a11, a12, a22 = (pa * pa).sum(-1), (pa * pb).sum(-1), (pb * pb).sum(-1)
            b1, b2 = -(pa * r).sum(-1), -(pb * r).sum(-1)
            det = a11 * a22 - a12**2
            da, db = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
            a = np.clip(a + da, fr.u_fillet, fr.u_tip)
            b = np.clip(b + db, fr.L_start, fr.L_end)
            if np.max(np.abs(da)) < 1e-10 * (u[-1] - u[0]) and np.max(np.abs(db)) < 1e-10 * (
                v[-1] - v[0]
            ):
                break
        return fr.on_tooth(at(a, b), tooth)

    return project
