"""Measured flanks: a deviation surface added to the generated flank in every flank map.

A topography (``[topography]`` of a case, :mod:`fegear.io.topography`, docs/measured_flanks.md)
gives per member and side a grid of normal deviations ``δ`` (µm, positive = material removed)
over the working flank. Here it becomes

- :class:`FlankTopography`: ``δ(u, v)`` (mm) of fegear's flank coordinates, a spline through
  the grid points in the grid's own coordinates, with its first derivatives;
- :class:`DeviatedFlankMap`: a :class:`~fegear.tca.surfaces.FlankMap` that evaluates the base
  (generated) map and moves its points by ``−δ n``;
- :class:`MeasuredMember`: the generated member with its topographies; every other attribute is
  the member's own. :func:`fegear.tca.surfaces.flank_map` asks a member for its
  ``measured_flank_map``, so the TCA, the loaded analysis (``tca.fm1``, ``tca.fm2``: the
  separations and the contact grids), the contact ellipses and the flank views all evaluate the
  measured flank. The sector meshes are the design's (:meth:`MeasuredMember.mesh_member`): a
  deviation of some µm changes neither the stiffness nor elements of tenths of a millimetre, so
  the meshes and compliance operators of the design run are read from the cache; the member's
  ``repr`` holds the grids' content hashes, so the cached TCA, positions and loaded cycles of
  the design are never read for a measured flank.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import BSpline, make_interp_spline

from ..errors import InputError
from .surfaces import FlankMap, SpurInvoluteMap, flank_map

__all__ = [
    "DeviatedFlankMap",
    "FlankTopography",
    "MeasuredMember",
    "flank_topography",
    "normal_deviation",
]

Array = NDArray[np.float64]

#: Tolerance (mm) of a physical grid coordinate past the working flank's limits: a reading of
#: the measuring machine at the form circle or the face end is on the flank.
EDGE_TOL_MM = 1e-3


@dataclass(frozen=True)
class FlankTopography:
    """The deviation ``δ(u, v)`` of one flank (mm, positive = material removed) in fegear's flank
    coordinates ``(u, v)`` (:class:`~fegear.geometry.surface.FlankBoundaries`).

    The grid is interpolated in its own coordinates ``(x, y)`` (profile × face) by the
    tensor-product B-spline that passes through every grid point, of degree 3 in a direction
    with at least 4 points, else of the points' count less one (2 points: linear, 3: quadratic),
    not-a-knot end conditions (:func:`scipy.interpolate.make_interp_spline` per direction: the
    spline in ``x`` of each column, then the cardinal splines of ``y``:
    ``δ(x, y) = Σ_j S_j(x) ℓ_j(y)``, the interpolant ``RectBivariateSpline(..., s=0)`` makes,
    with the derivatives of a linear direction too). Cubic interpolation reproduces polynomials
    of degree ≤ 3 exactly (a lead or profile crowning, a helix slope: to rounding); otherwise
    its error is ``O(h⁴ |δ⁗|)`` in the grid spacing ``h`` (de Boor, *A Practical Guide to
    Splines*, 2001, ch. XVII). The coordinates are separable, ``x = X(u)``, ``y = Y(v)``:

    - ``"normalized"``: ``x = (u − u_fillet)/(u_tip − u_fillet)``, ``y = (v − v_start)/(v_end −
      v_start)``;
    - ``"diameter_mm"`` (cylindrical): ``x = d = 2 √(r_b² + L(u)²)`` with the roll length
      ``L = L_0 + k u`` (:meth:`~fegear.geometry.cylindrical.CylindricalMember.roll_length`),
      ``dx/du = 4 L k / d``; ``y = z = v``;
    - ``"roll_mm"`` (cylindrical): ``x = L = L_0 + k u``, ``dx/du = k``; ``y = z = v``. A
      profile modification is a function of ``L`` (ISO 21771: a profile crowning is a parabola
      in ``L``, reproduced by the cubic), while ``L ∝ √(d − d_b)`` near the base circle makes it
      steep in ``d`` at the form circle: 11 points of an 8 µm profile crowning interpolate to
      1e-13 mm in ``L``, to 9e-5 mm in ``d``.

    Outside the grid's span (a grid inset from the flank's edges, or the Newton solves stepping
    past the working flank) ``δ`` is continued by its tangent plane at the nearest point ``c``
    of the span: ``δ(c) + δ_x(c) (x − x_c) + δ_y(c) (y − y_c)``, continuous with its first
    derivatives (``δ_x = S_x(c) + S_xy(c) (y − y_c)`` where ``x`` is inside, and alike).

    Attributes
    ----------
    coordinates
        ``"normalized"``, ``"diameter_mm"`` or ``"roll_mm"``.
    x, y, deviation_mm
        The grid: ``(n_x,)`` profile and ``(n_y,)`` face coordinates, ``(n_x, n_y)`` δ in mm.
    u_span, v_span
        ``(u_fillet, u_tip)`` and ``(v_start, v_end)`` of the flank.
    roll
        ``(L_0, k, r_b)`` mm of ``"diameter_mm"`` and ``"roll_mm"`` (else unused).
    sha256, name
        The grid's content hash and file name (the hash is what the member's ``repr`` shows).
    """

    coordinates: str
    x: Array = field(repr=False, compare=False)
    y: Array = field(repr=False, compare=False)
    deviation_mm: Array = field(repr=False, compare=False)
    u_span: tuple[float, float] = (0.0, 1.0)
    v_span: tuple[float, float] = (0.0, 1.0)
    roll: tuple[float, float, float] = (0.0, 1.0, 1.0)
    sha256: str = ""
    name: str = field(default="", compare=False)
    _cache: dict = field(default_factory=dict, repr=False, compare=False, hash=False)

    def __repr__(self) -> str:
        return f"FlankTopography({self.coordinates!r}, sha256={self.sha256!r})"

    @property
    def splines(self) -> tuple[BSpline, BSpline]:
        """``(S, ℓ)``: the splines in ``x`` of the grid's columns (vector-valued, ``(n_y,)``)
        and the cardinal splines of ``y`` (built once)."""
        s = self._cache.get("splines")
        if s is None:
            kx, ky = min(3, self.x.size - 1), min(3, self.y.size - 1)
            s = (make_interp_spline(self.x, self.deviation_mm, k=kx),
                 make_interp_spline(self.y, np.eye(self.y.size), k=ky))  # fmt: skip
            self._cache["splines"] = s
        return s

    def ev(self, x: Array, y: Array, dx: int = 0, dy: int = 0) -> Array:
        """The interpolant or a derivative at grid coordinates inside the grid's span."""
        sx, ly = self.splines
        return np.sum(sx(x, nu=dx) * ly(y, nu=dy), axis=-1)

    def grid_coordinates(self, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array, Array, Array]:
        """``(x, y, dx/du, dy/dv)`` of flank coordinates (broadcast)."""
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        v0, v1 = self.v_span
        if self.coordinates == "roll_mm":
            L0, k, _ = self.roll
            return L0 + k * u, v.copy(), np.full(u.shape, k), np.ones(v.shape)
        if self.coordinates == "diameter_mm":
            L0, k, rb = self.roll
            L = L0 + k * u
            x = 2.0 * np.sqrt(rb * rb + L * L)
            return x, v.copy(), 4.0 * L * k / x, np.ones(v.shape)
        u0, u1 = self.u_span
        return (u - u0) / (u1 - u0), (v - v0) / (v1 - v0), np.full(u.shape, 1.0 / (u1 - u0)), \
            np.full(v.shape, 1.0 / (v1 - v0))  # fmt: skip

    def deviation(self, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array, Array]:
        """``(δ, ∂δ/∂u, ∂δ/∂v)`` in mm (per unit of ``u``, ``v``) at flank coordinates."""
        x, y, xu, yv = self.grid_coordinates(u, v)
        xc = np.clip(x, self.x[0], self.x[-1])
        yc = np.clip(y, self.y[0], self.y[-1])
        dx, dy = x - xc, y - yc
        d = self.ev(xc, yc)
        sx, sy = self.ev(xc, yc, dx=1), self.ev(xc, yc, dy=1)
        sxy = self.ev(xc, yc, dx=1, dy=1)
        out_x, out_y = dx != 0.0, dy != 0.0
        if np.any(out_x | out_y):  # the tangent-plane continuation
            d = d + sx * dx + sy * dy
            sx = sx + np.where(out_x, 0.0, sxy * dy)
            sy = sy + np.where(out_y, 0.0, sxy * dx)
        return d, sx * xu, sy * yv


def flank_topography(grid: Any, member: Any, side: str) -> FlankTopography:
    """The :class:`FlankTopography` of a grid (:class:`fegear.io.topography.TopographyGrid`) on
    ``member``'s ``side`` flank.

    Raises
    ------
    InputError
        A grid point outside the working flank (``"diameter_mm"``, ``"roll_mm"``: a diameter or
        roll length outside the form circle … tip, an axial position outside the face, each by
        more than :data:`EDGE_TOL_MM`), or physical coordinates on a member without roll
        lengths (not cylindrical); the field names the file, row and column (``grid.where``).
    """
    bd = member.flank_coordinates(side).bounds
    roll = (0.0, 1.0, 1.0)
    if grid.coordinates in ("diameter_mm", "roll_mm"):
        if not hasattr(member, "roll_length"):
            raise InputError(grid.where(grid.header_row, 1), grid.coordinates, "'normalized' "
                             f"({grid.coordinates}: kind 'cylindrical' only)")  # fmt: skip
        L0 = float(member.roll_length(0.0))
        k = float(member.roll_length(1.0)) - L0
        rb = float(member.r_b)
        roll = (L0, k, rb)
        what = "roll length" if grid.coordinates == "roll_mm" else "diameter"
        x_lo, x_hi = (L0 + k * u if grid.coordinates == "roll_mm" else
                      2 * math.hypot(rb, L0 + k * u) for u in (bd.u_fillet, bd.u_tip))  # fmt: skip
        for i, d in enumerate(grid.profile):
            if not x_lo - EDGE_TOL_MM <= d <= x_hi + EDGE_TOL_MM:
                raise InputError(grid.where(grid.rows[i], 1), float(d),
                                 f"in [{x_lo:.4f}, {x_hi:.4f}] mm (the working flank of "
                                 f"{member.name}: form circle to tip, as a {what})")  # fmt: skip
        for j, z in enumerate(grid.face):
            if not bd.v_start - EDGE_TOL_MM <= z <= bd.v_end + EDGE_TOL_MM:
                raise InputError(grid.where(grid.header_row, grid.cols[j]), float(z),
                                 f"in [{bd.v_start:g}, {bd.v_end:g}] mm (the face of "
                                 f"{member.name}, z from its centre)")  # fmt: skip
    return FlankTopography(
        coordinates=grid.coordinates, x=np.asarray(grid.profile, float),
        y=np.asarray(grid.face, float), deviation_mm=1e-3 * np.asarray(grid.deviation_um, float),
        u_span=(bd.u_fillet, bd.u_tip), v_span=(bd.v_start, bd.v_end), roll=roll,
        sha256=grid.sha256, name=grid.path.name,
    )  # fmt: skip


@dataclass(frozen=True)
class DeviatedFlankMap(FlankMap):
    """The base (generated) flank map with a measured deviation: ``X = p − δ n``.

    Native parameters, flank coordinates and the native box are the base map's: a native point
    ``(a, b)`` is the generated point's, moved along its normal. With the base point ``p``, unit
    normal ``n``, tangents ``r_a, r_b`` and ``δ_a = δ_u u_a + δ_v v_a`` (``u_a``... the
    derivatives of the flank coordinates, exact where native = flank coordinates, else forward
    differences of the base map's ``flank`` over its ``step`` with the points ``p + h r``):

    - **point** ``X = p − δ n``;
    - **tangents** ``X_a = r_a − δ_a n − δ n_a``. With Weingarten's ``n_a = −W r_a`` (``W`` the
      shape operator, tangent) the last term ``δ W r_a`` is in the tangent plane and of relative
      size ``δ κ`` (10 µm on a 5 mm radius of curvature: 2e-3); it is left out:
      ``X_a ≈ r_a − δ_a n``. The tangents only build the Newton solves' Jacobians (the
      residuals are the points and normals), so this changes the rate of the Newton
      iterations, not the points they converge to;
    - **normal**. Write ``A = I + δ W`` on the tangent plane, so ``X_a = A r_a − δ_a n``. A unit
      vector ``N ∝ n + g`` (``g`` tangent) is normal to ``X_a`` and ``X_b`` when
      ``g · A r_a = δ_a``, ``g · A r_b = δ_b``, i.e. (``W`` self-adjoint) ``A g = ∇_S δ``, the
      surface gradient ``∇_S δ = (δ_a (G r_a − F r_b) + δ_b (E r_b − F r_a)) / (E G − F²)``
      (``E, F, G`` the metric of ``r_a, r_b``). So ``N ∝ n + A⁻¹ ∇_S δ = n + ∇_S δ − δ W ∇_S δ
      + O(δ²κ²|∇δ|)``; fegear takes ``n' = (n + ∇_S δ)/|n + ∇_S δ|``, whose error is the
      second-order ``O(δ κ |∇_S δ|)`` (10 µm, κ = 0.2/mm, a slope of 1e-3: 2e-6 rad). (The sign:
      removing more material towards ``+a`` tilts the outward normal towards ``+a``; on the plane
      ``z = 0`` with ``δ = c x``, ``X = (x, y, −c x)`` has the normal ``(c, 0, 1)``.)

    Where ``δ`` and its gradient vanish, the base map's numbers are returned bit for bit (a zero
    grid reproduces the design run exactly).
    """

    base: FlankMap | None = None
    topo: FlankTopography | None = None

    @property
    def pointwise(self) -> bool:  # type: ignore[override]
        return self.base.pointwise

    @property
    def native_pointwise(self) -> bool:  # type: ignore[override]
        return self.base.native_pointwise

    def native(self, u, v):
        return self.base.native(u, v)

    def native_box(self):
        return self.base.native_box()

    def native_point(self, u, v):
        a, b = self.base.native(u, v)
        p, n = self.evaluate(a, b)
        return a, b, p, n

    def _flank_uses_points(self) -> bool:
        return type(self.base).flank not in (FlankMap.flank, SpurInvoluteMap.flank)

    def flank(self, a, b, p):
        # the flank coordinates of the generated point of (a, b), not of the moved one
        if self._flank_uses_points():
            p = self.base.evaluate(a, b)[0]
        return self.base.flank(a, b, p)

    def _flank_jacobian(self, a, b, p, ra, rb):
        """``(u, v, u_a, u_b, v_a, v_b)`` at native ``(a, b)``."""
        base = self.base
        if type(base).flank is FlankMap.flank:  # native = flank coordinates
            one, zero = np.ones(a.shape), np.zeros(a.shape)
            return a, b, one, zero, zero, one
        ha, hb = base.step
        u, v = base.flank(a, b, p)
        u1, v1 = base.flank(a + ha, b, p + ha * ra)
        u2, v2 = base.flank(a, b + hb, p + hb * rb)
        return u, v, (u1 - u) / ha, (u2 - u) / hb, (v1 - v) / ha, (v2 - v) / hb

    def point_jacobian(self, a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        p, n, ra, rb = self.base.point_jacobian(a, b)
        u, v, ua, ub, va, vb = self._flank_jacobian(a, b, p, ra, rb)
        d, du, dv = self.topo.deviation(u, v)
        da, db = du * ua + dv * va, du * ub + dv * vb
        E, F, G = (np.sum(x * y, -1) for x, y in ((ra, ra), (ra, rb), (rb, rb)))
        det = E * G - F * F
        grad = ((da * G - db * F) / det)[..., None] * ra + ((db * E - da * F) / det)[..., None] * rb
        moved = (d != 0.0)[..., None]
        tilted = ((da != 0.0) | (db != 0.0))[..., None]
        P = np.where(moved, p - d[..., None] * n, p)
        m = n + grad
        N = np.where(tilted, m / np.linalg.norm(m, axis=-1, keepdims=True), n)
        Ra = np.where((da != 0.0)[..., None], ra - da[..., None] * n, ra)
        Rb = np.where((db != 0.0)[..., None], rb - db[..., None] * n, rb)
        return P, N, Ra, Rb

    def evaluate(self, a, b):
        return self.point_jacobian(a, b)[:2]

    def jacobian(self, a, b, p):
        return self.point_jacobian(a, b)[2:]


@dataclass(frozen=True, repr=False)
class MeasuredMember:
    """A generated member whose flanks carry measured topographies (see the module docstring).

    Every attribute but those below is the generated member's own (``name``, ``n_teeth``,
    ``flank_coordinates``, ``point_normal``: the *design* flank; the measured one is its flank
    maps').

    Attributes
    ----------
    base
        The generated member (:class:`~fegear.geometry.surface.GeneratedMember`).
    topographies
        ``((side, FlankTopography), ...)``.
    """

    base: Any
    topographies: tuple[tuple[str, FlankTopography], ...]

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__") or name in ("base", "topographies"):
            raise AttributeError(name)
        return getattr(self.base, name)

    def __repr__(self) -> str:
        # what the cache keys of the TCA, the positions and the loaded cycle hold
        topo = ", ".join(f"{s}={t!r}" for s, t in self.topographies)
        return f"MeasuredMember({self.base!r}, {topo})"

    def topography(self, side: str) -> FlankTopography | None:
        """The topography of ``side`` (None: the generated flank)."""
        return dict(self.topographies).get(side)

    def measured_flank_map(self, side: str, generic: bool = False) -> FlankMap:
        """The flank map of ``side`` (:func:`~fegear.tca.surfaces.flank_map` asks for it): the
        generated member's map, deviated where ``side`` has a topography."""
        fm = flank_map(self.base, side, generic)
        t = self.topography(side)
        if t is None:
            return fm
        return DeviatedFlankMap(fm.member, fm.side, fm.bounds, fm.step, base=fm, topo=t)

    def mesh_member(self) -> Any:
        """The member the sector meshes are made of: the generated member's (its own
        ``mesh_member()`` where it has one), so that the meshes and compliance operators of the
        design are shared (µm deviations do not change the compliance)."""
        b = self.base
        return b.mesh_member() if hasattr(b, "mesh_member") else b


def normal_deviation(
    nominal: FlankMap, modified: FlankMap, u: ArrayLike, v: ArrayLike, tol: float = 1e-13
) -> Array:
    """What a measuring machine reads on ``modified`` at the nominal flank coordinates
    ``(u, v)``: the distance ``δ`` (mm, positive = material removed) along the nominal outward
    normal ``n`` from the nominal point ``P`` to the modified flank.

    Newton on ``X(a', b') + δ n = P`` for ``(a', b', δ)`` (``X`` the modified map, its tangents
    from :meth:`~fegear.tca.surfaces.FlankMap.point_jacobian`), from ``(a, b, 0)``; stops when
    the residual is below ``tol`` mm (at most 20 steps). Used to make a topography grid of an
    analytic modification (``tests/test_topography_runs.py``, ``cases/helical_measured*``).
    """
    a, b = nominal.native(u, v)
    P, n = nominal.evaluate(a, b)
    x, y = a.copy(), b.copy()
    d = np.zeros(a.shape)
    for _ in range(20):
        X, _, Xa, Xb = modified.point_jacobian(x, y)
        F = X - P + d[..., None] * n
        if F.size == 0 or np.abs(F).max() < tol:
            break
        J = np.stack([Xa, Xb, n], -1)
        step = np.linalg.solve(J, -F[..., None])[..., 0]
        x, y, d = x + step[..., 0], y + step[..., 1], d + step[..., 2]
    return d
