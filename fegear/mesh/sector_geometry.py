"""Section geometry of a tooth sector: the analytic curves the gmsh solid is lofted through.

A sector of ``n`` teeth is built (in :mod:`fegear.mesh.sector`) as a loft through *section
wires* lying on the surfaces of constant face coordinate ``L = const``, then trimmed by a solid
of revolution (the *envelope*). This module computes, from the exact generated surfaces of a
member, everything that construction needs, in the member frame (axis z):

- per-family *cone coordinates* ``(L, h)``: ``L`` along the face (``z`` for cylindrical gears,
  the radius for a face gear, the cone distance for a bevel gear) and ``h`` across it (radius,
  height ``z``, height above the pitch cone). They map linearly to ``(ρ, z)``:
  ``(ρ, z)ᵀ = M (L, h)ᵀ`` with ``M`` orthogonal, so ``dV = ρ dL dh dφ``.
- surfaces of revolution ``h = a + b L`` (tip, root, trimming bottom) — exact for all three
  families (cylinders, planes, Gleason-taper cones),
- the *section* of the sector at ``L``: transverse planes ``z = L`` (cylindrical gears),
  cylinders ``ρ = L`` (face gear), back cones ``L = const`` (bevel gears, the cones normal to the
  pitch cone). The flank parameter of every family is ``v = L``, so a section point of a flank is
  an exact surface point ``p(u, v = L)`` with no solve, and every tooth of the sector, however
  far it is turned about the axis, is cut at exactly the same face position (planar sections of a
  wide bevel sector would cut its outer teeth past the heel),
- an independent volume estimate by integrating the ``(φ, h)`` section along the face
  (:func:`section_integral_volume`), and closest points on the analytic flank
  (:func:`flank_distance`).

The family-specific data come from the member through its protocol
(:class:`~fegear.geometry.surface.GeneratedMember`): the blank outline
(:meth:`~fegear.geometry.surface.GeneratedMember.blank_outline`: cone coordinates, tip, root and
bottom lines, face, sections, parameter limits, plus side) and the fastest exact flank and fillet
points (``flank_points``; the spiral bevel's native evaluators, the blade's and the edge radius's
envelopes, are the same surfaces to ~1e-13 mm, ~100× faster than ``point_normal``). This module
names no family: a new one meshes once its member implements the protocol.

Teeth of the sector are numbered ``j = 0 … n−1`` in the direction of +θ; sector tooth ``j`` is
member tooth ``k = j − n//2`` (tooth ``k`` is tooth 0 turned by ``k τ`` about z), so the centre
tooth ``n//2`` is the member's tooth 0 used by the TCA.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import NDArray

from ..errors import MeshError
from ..geometry.surface import ConeLine, GeneratedMember, HasNativeFlank, Side

__all__ = [
    "Line",
    "SectorFrame",
    "Edge",
    "sector_frame",
    "section_edges",
    "sections_edges",
    "hermite_points",
    "section_integral_volume",
    "flank_distance",
    "fillet_distance",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


Line = ConeLine
"""A surface of revolution ``h = a + b L`` in cone coordinates (the geometry's
:class:`~fegear.geometry.surface.ConeLine`)."""


@dataclass(frozen=True)
class Edge:
    """One edge of a section wire: label, points ``(m, 3)`` through which it is interpolated
    (first and last are the shared vertices), optional unit end tangents, ``straight`` for a
    line segment."""

    label: str
    points: Array
    t0: Array | None = None
    t1: Array | None = None
    straight: bool = False


def _rotate(p: Array, ang: Array | float) -> Array:
    """Points ``(..., 3)`` turned by ``ang`` (broadcast to ``p.shape[:-1]``) about z."""
    c, s = np.cos(ang), np.sin(ang)
    x, y, z = np.broadcast_arrays(p[..., 0], p[..., 1], p[..., 2], c)[:3]
    c, s = np.broadcast_arrays(c, s, x)[:2]
    return np.stack([c * x - s * y, s * x + c * y, z], -1)


@dataclass(frozen=True)
class SectorFrame:
    """Family-specific data of a sector (see module docstring). Lengths mm, angles rad.

    The member's :class:`~fegear.geometry.surface.BlankOutline` (its fields, under the same
    names), with the member, its ``family`` name and the bottom of the loft. ``L_range`` is the
    face span of the loft (a little wider than ``L_start … L_end``, which the envelope trims
    exactly); ``n_sections`` section wires are spread evenly over it; each half of a tooth
    space's root and fillet is one section edge through ``n_fillet`` exact points
    (:func:`_root_fillet`).
    """

    member: GeneratedMember
    family: str
    module: float
    meridian: Array
    tip: Line
    root: Line
    bottom: Line
    loft_bottom: Line
    L_start: float
    L_end: float
    L_range: tuple[float, float]
    n_sections: int
    u_root: float
    u_fillet: float
    u_tip: float
    plus_side: Side
    bottom_name: str
    has_fillet: bool
    n_fillet: int = 25

    @property
    def minus_side(self) -> Side:
        return "coast" if self.plus_side == "drive" else "drive"

    @property
    def tau(self) -> float:
        return 2 * math.pi / self.member.n_teeth

    @property
    def e_L(self) -> Array:
        """Unit vector of increasing ``L`` at polar angle 0 (meridian plane x-z)."""
        return np.array([self.meridian[0, 0], 0.0, self.meridian[1, 0]])

    # ---------------------------------------------------------------- coordinates
    def rho_z(self, L: Array, h: Array) -> tuple[Array, Array]:
        """``(ρ, z)`` of cone coordinates."""
        M = self.meridian
        return M[0, 0] * L + M[0, 1] * h, M[1, 0] * L + M[1, 1] * h

    def lh(self, p: Array) -> tuple[Array, Array]:
        """Cone coordinates ``(L, h)`` of points ``(..., 3)`` (``M`` orthogonal: ``M⁻¹ = Mᵀ``)."""
        rho = np.hypot(p[..., 0], p[..., 1])
        M = self.meridian
        return M[0, 0] * rho + M[1, 0] * p[..., 2], M[0, 1] * rho + M[1, 1] * p[..., 2]

    def point(self, L: Array | float, h: Array | float, phi: Array | float) -> Array:
        """Points ``(..., 3)`` of cone coordinates ``(L, h)`` at polar angle ``phi``."""
        rho, z = self.rho_z(np.asarray(L, dtype=float), np.asarray(h, dtype=float))
        phi = np.asarray(phi, dtype=float)
        rho, z, phi = np.broadcast_arrays(rho, z, phi)
        return np.stack([rho * np.cos(phi), rho * np.sin(phi), z], -1)

    def surface_point(self, line: Line, phi: Array | float, L: float) -> Array:
        """Points ``(..., 3)`` of the revolution surface ``line`` in the section ``L``."""
        return self.point(L, line(L), phi)

    @staticmethod
    def surface_tangent(phi: float) -> Array:
        """Unit tangent of any surface of revolution in a section at ``phi``, pointing to +φ."""
        return np.array([-math.sin(phi), math.cos(phi), 0.0])

    # ---------------------------------------------------------------- flanks
    def flank_points(self, side: Side, u: Array, v: Array) -> Array:
        """Exact flank points ``(..., 3)`` of member tooth 0 at ``(u, v)`` (broadcast)."""
        return self.member.flank_points(side, u, v)[0]

    def tooth_points(self, side: Side, k: Array | int, u: Array, v: Array) -> Array:
        """Exact flank points of member teeth ``k`` (broadcast ``k``, ``u``, ``v``)."""
        k, u, v = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (k, u, v)))
        return self.on_tooth(self.flank_points(side, u, v), k)

    def on_tooth(self, points: Array, k: Array | int) -> Array:
        """Points ``(..., 3)`` of tooth 0 carried to member teeth ``k`` (a turn by ``k τ``)."""
        return _rotate(np.asarray(points, dtype=float), np.asarray(k, dtype=float) * self.tau)


def _unit(v: Array) -> Array:
    return v / np.linalg.norm(v)


def sector_frame(member: GeneratedMember, rim_modules: float = 3.0) -> SectorFrame:
    """The :class:`SectorFrame` of a member of any family (a
    :class:`~fegear.geometry.surface.GeneratedMember`): its
    :meth:`~fegear.geometry.surface.GeneratedMember.blank_outline` and a loft bottom half a
    module below the blank's bottom (trimmed away by the envelope).

    Rims (the families' outlines): involute members get a bore of radius
    ``r_f − rim_modules · m``; the face gear its blank (``blank_thickness_mm`` below the root
    plane, bottom face ``base``); spiral bevel members a rim of ``rim_modules · m`` below the root
    cone (its bottom cone is ``bore``).
    """
    if not isinstance(member, GeneratedMember):
        raise MeshError(
            f"no sector geometry for member type {type(member).__name__}: "
            "it does not implement GeneratedMember"
        )
    o = member.blank_outline(rim_modules)
    return SectorFrame(
        member=member,
        family=member.family,
        loft_bottom=Line(o.bottom.a - 0.5 * o.module, o.bottom.b),
        **{f.name: getattr(o, f.name) for f in fields(o)},
    )


def _polar(p: Array) -> Array:
    return np.arctan2(p[..., 1], p[..., 0])


def section_edges(frame: SectorFrame, n_teeth: int, L: float, nu: int = 17) -> list[Edge]:
    """The closed section wire at face coordinate ``L`` (see :func:`sections_edges`)."""
    return sections_edges(frame, n_teeth, [L], nu)[0]


def sections_edges(
    frame: SectorFrame, n_teeth: int, Ls: Sequence[float], nu: int = 17
) -> list[list[Edge]]:
    """The closed section wires of the sector at face coordinates ``Ls``, as ordered edges.

    Order (+θ): for each sector tooth ``j``: ``fillet_j`` (minus side, from the space middle),
    ``flank_<minus>_j``, ``top_j``, ``flank_<plus>_j``, ``fillet_j`` (plus side, to the next
    space middle); then ``cut_right`` (down to the loft bottom), ``bottom`` (trimmed away later),
    ``cut_left``. Labels name the physical group the lofted face will belong to. Flank edges
    interpolate ``nu`` exact points ``p(u, v = L)`` (``u`` fillet limit → tip) with exact end
    tangents (central differences, step ``1e-5`` of the profile), evenly spaced in ``u``
    (cosine spacing was tried: it halves the section error but gives the OCC loft slivers near
    the ends); root and generated fillet as :func:`_root_fillet` gives them.
    """
    fr = frame
    ks = np.array([j - n_teeth // 2 for j in range(-1, n_teeth + 1)], dtype=float)
    s01 = np.linspace(0.0, 1.0, nu)
    uw = fr.u_fillet + (fr.u_tip - fr.u_fillet) * s01
    eps = 1e-5 * (fr.u_tip - fr.u_root)
    allu = np.concatenate([uw, [fr.u_fillet - eps, fr.u_fillet + eps, fr.u_tip - eps, fr.u_tip]])
    n1 = len(uw)
    Ls = np.asarray(Ls, dtype=float)
    raw = {}
    for s in ("drive", "coast"):
        p0 = fr.flank_points(s, allu[None, :], Ls[:, None])  # (nL, nu + 4, 3)
        raw[s] = _rotate(p0[:, None], ks[None, :, None] * fr.tau)  # (nL, nk, nu + 4, 3)
    rf = _root_fillet(fr, Ls, n=fr.n_fillet) if fr.has_fillet else None
    ks_i = [int(k) for k in ks]
    return [_section(fr, n_teeth, float(L), ks_i, raw, i, n1, rf) for i, L in enumerate(Ls)]


def _root_fillet(
    fr: SectorFrame, Ls: Array, n: int = 25, n_dense: int = 97
) -> dict[str, tuple[Array, Array]]:
    """Per side, the root and generated fillet of member tooth 0 at the sections ``Ls``: points
    ``(nL, n, 3)`` from the middle of the tooth space on that side (along the root arc, then up
    the fillet) to the fillet limit, and the polar angles ``(nL,)`` of the space middles.

    Every point is exact (root arc ``h = root(L)``; fillet ``p(u, L)``, ``u_root … u_fillet``)
    and they lie at about equal arc lengths (the fillet's ``u`` interpolated from the chord
    lengths of ``n_dense`` exact samples), so that every section carries the same number of
    points in the same places along its edge and the loft stays regular where a face-gear
    fillet shrinks from 7 mm to a point (where the shaper tip rolls on the root plane, ``L =
    r_as/q``). Raises :class:`~fegear.errors.MeshError` if the fillets of a tooth space cross.
    """
    plus, minus = fr.plus_side, fr.minus_side
    ud = fr.u_root + (fr.u_fillet - fr.u_root) * np.linspace(0.0, 1.0, n_dense)
    dense = {s: fr.flank_points(s, ud[None, :], Ls[:, None]) for s in (plus, minus)}
    phib = {s: _polar(dense[s][:, 0]) for s in (plus, minus)}  # fillet bottoms
    gap = phib[minus] + fr.tau - phib[plus]
    if np.any(gap <= 0):
        L_bad = float(Ls[np.argmin(gap)])
        raise MeshError(f"the fillets of a tooth space cross at L = {L_bad:.3f}")
    mid = {plus: phib[plus] + 0.5 * gap, minus: phib[minus] - 0.5 * gap}
    rho_root = fr.rho_z(Ls, fr.root(Ls))[0]
    out = {}
    for s in (plus, minus):
        root_len = rho_root * np.abs(phib[s] - mid[s])  # (nL,)
        cum = np.concatenate(
            [np.zeros((len(Ls), 1)),
             np.cumsum(np.linalg.norm(np.diff(dense[s], axis=1), axis=-1), axis=1)], axis=1,
        )  # fmt: skip
        total = root_len + cum[:, -1]
        t = total[:, None] * np.linspace(0.0, 1.0, n)[None, :]  # (nL, n)
        on_root = t < root_len[:, None]
        phi = mid[s][:, None] + (phib[s] - mid[s])[:, None] * t / root_len[:, None]
        u = np.stack([np.interp(t[i] - root_len[i], cum[i], ud) for i in range(len(Ls))])
        u[:, -1] = fr.u_fillet
        LL = np.broadcast_to(Ls[:, None], u.shape)
        pts = fr.flank_points(s, u, LL)
        pr = fr.point(LL, fr.root(LL), phi)
        out[s] = (np.where(on_root[..., None], pr, pts), mid[s])
    return out


def _section(fr, n_teeth, L, ks, raw, iL, n1, rf) -> list[Edge]:
    data: dict[tuple[int, str], dict[str, Array]] = {}
    for ik, k in enumerate(ks):
        for side in ("drive", "coast"):
            pts = raw[side][iL, ik]
            e = pts[n1 : n1 + 4]
            data[(k, side)] = {
                "work": pts[:n1],
                "t_fil": _unit(e[1] - e[0]),
                "t_tip": _unit(e[3] - e[2]),
            }
            if rf is not None:
                data[(k, side)]["fillet"] = _rotate(rf[side][0][iL], k * fr.tau)
                data[(k, side)]["mid"] = float(rf[side][1][iL] + k * fr.tau)
    plus, minus = fr.plus_side, fr.minus_side

    def space_mid(k_left: int) -> tuple[Array, Array]:
        if rf is not None:
            phi = data[(k_left, plus)]["mid"]
            return fr.surface_point(fr.root, phi, L), fr.surface_tangent(phi)
        pa, pb = (
            _polar(data[(k_left, plus)]["work"][0]),
            _polar(data[(k_left + 1, minus)]["work"][0]),
        )
        if pb <= pa:
            raise MeshError(f"tooth space after tooth {k_left} is closed at L = {L:.3f}")
        phi = 0.5 * (pa + pb)
        return fr.surface_point(fr.root, phi, L), fr.surface_tangent(phi)

    edges: list[Edge] = []
    mid, t_mid = space_mid(ks[0])
    mid_left, phi_left = mid, _polar(mid)
    for j in range(n_teeth):
        k = j - n_teeth // 2
        dm, dp = data[(k, minus)], data[(k, plus)]
        # minus fillet: space middle -> fillet limit
        if fr.has_fillet:
            pts = np.vstack([mid, dm["fillet"][1:]])
            edges.append(Edge(f"fillet_{j}", pts, t_mid, dm["t_fil"]))
        else:
            edges.append(Edge(f"fillet_{j}", np.vstack([mid, dm["work"][0]]), t_mid, dm["t_fil"]))
        edges.append(Edge(f"flank_{minus}_{j}", dm["work"], dm["t_fil"], dm["t_tip"]))
        a0, a1 = _polar(dm["work"][-1]), _polar(dp["work"][-1])
        tops = fr.surface_point(fr.tip, np.linspace(a0, a1, 7)[1:-1], L)
        edges.append(Edge(f"top_{j}", np.vstack([dm["work"][-1], tops, dp["work"][-1]])))
        edges.append(Edge(f"flank_{plus}_{j}", dp["work"][::-1], -dp["t_tip"], -dp["t_fil"]))
        nxt, t_nxt = space_mid(k)
        if fr.has_fillet:
            pts = np.vstack([dp["fillet"][:0:-1], nxt])
            edges.append(Edge(f"fillet_{j}", pts, -dp["t_fil"], t_nxt))
        else:
            edges.append(Edge(f"fillet_{j}", np.vstack([dp["work"][0], nxt]), -dp["t_fil"], t_nxt))
        mid, t_mid = nxt, t_nxt
    phi_right = _polar(mid)
    b_right = fr.surface_point(fr.loft_bottom, phi_right, L)
    b_left = fr.surface_point(fr.loft_bottom, phi_left, L)
    edges.append(Edge("cut_right", np.vstack([mid, b_right]), straight=True))
    phis = np.linspace(phi_right, phi_left, 4 * n_teeth + 3)[1:-1]
    bottom = np.vstack([b_right, fr.surface_point(fr.loft_bottom, phis, L), b_left])
    edges.append(Edge("bottom", bottom))
    edges.append(Edge("cut_left", np.vstack([b_left, mid_left]), straight=True))
    return edges


def hermite_points(e: Edge, n: int = 7) -> Array:
    """Interior points ``(n, 3)`` of an edge as the sector builds it.

    A two-point edge with end tangents (root blend) is the cubic Hermite curve with the unit
    tangents scaled to the chord length ``ℓ``:
    ``x(t) = h00 p0 + h10 ℓ t0 + h01 p1 + h11 ℓ t1`` (the CAD gives it as the Bézier with control
    points ``p0, p0 + ℓ t0/3, p1 − ℓ t1/3, p1``). For other edges: the interior points (or the
    midpoint of a straight edge).
    """
    if e.straight or e.t0 is None or len(e.points) > 2:
        if len(e.points) > 2:
            return e.points[1:-1]
        return 0.5 * (e.points[:1] + e.points[1:])
    p0, p1 = e.points
    ell = np.linalg.norm(p1 - p0)
    t = np.linspace(0, 1, n + 2)[1:-1, None]
    h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
    h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
    return h00 * p0 + h10 * ell * e.t0 + h01 * p1 + h11 * ell * e.t1


# --------------------------------------------------------------------------- checks
def section_integral_volume(frame: SectorFrame, n_teeth: int, n_L: int = 21, nu: int = 81) -> float:
    """Sector volume by integrating the ``(φ, h)`` section at constant ``L`` along the face.

    ``V = ∫ dL ∬ ρ(L, h) dφ dh`` (``ρ = M₀₀ L + M₀₁ h``) over the section bounded by the exact
    flanks (``nu`` points ``p(u, v = L)`` each), the tip and bottom surfaces (straight lines
    ``h = a + b L`` in ``(φ, h)``) and the space-middle cuts; polygon moments (exact for the
    straight parts), Simpson's rule over ``n_L`` sections in ``L``.

    Independent of the CAD loft, the trimming and the mesh; it models the *same* solid, so the
    root of a family without a generated fillet would be the sector's cubic root blend
    (:func:`hermite_points`, 41 points); every family now has its generated fillet.
    """
    fr = frame
    M = fr.meridian
    Ls = np.linspace(fr.L_start, fr.L_end, n_L if n_L % 2 else n_L + 1)
    keep = {"cut_right", "bottom", "cut_left"}
    vals = []
    for L, edges in zip(Ls, sections_edges(fr, n_teeth, Ls, nu), strict=True):
        chain = []
        for e in edges:
            if e.label in keep:
                continue
            inner = hermite_points(e, 41) if len(e.points) == 2 else e.points[1:-1]
            chain += [e.points[:1], inner]
        chain.append(edges[-4].points[-1:])  # last space middle (start of cut_right)
        P = np.vstack(chain)
        x, y = np.unwrap(_polar(P)), fr.lh(P)[1]
        hb = float(fr.bottom(L))
        x = np.concatenate([x, [x[-1], x[0]]])
        y = np.concatenate([y, [hb, hb]])
        x1, y1 = np.roll(x, -1), np.roll(y, -1)
        cr = x * y1 - x1 * y
        area = 0.5 * np.sum(cr)
        my = np.sum(cr * (y + y1)) / 6.0
        vals.append(abs(M[0, 0] * L * area + M[0, 1] * my))
    vals = np.array(vals)
    hL = Ls[1] - Ls[0]
    w = np.ones(len(Ls))
    w[1:-1:2], w[2:-1:2] = 4, 2
    return float(hL / 3 * np.sum(w * vals))


def flank_distance(
    frame: SectorFrame, side: Side, k: Array | int, x: Array, n_grid: int = 21
) -> tuple[Array, Array]:
    """Distance of points ``x (m, 3)`` to the analytic flank ``side`` of member teeth ``k``
    (scalar or ``(m,)``).

    Closest-point Gauss-Newton on ``|p(a, b) − x|²`` from the nearest point of an
    ``n_grid × n_grid`` sample of the flank. A member with a native flank evaluator
    (:class:`~fegear.geometry.surface.HasNativeFlank`; the spiral bevel, the face gear): in its
    native parameters (the bevel's cutter parameters ``(s, θ)``, the face gear's shaper
    parameters ``(t, u_s)``) with its exact tangents, unbounded;
    other members: in ``(u, v)`` with finite-difference tangents, ``u`` projected onto the working
    flank ``[u_fillet, u_tip]`` (below it the parameters run onto the fillet). Returns the distances
    ``(m,)`` mm and the parameters ``(m, 2)``.
    """
    fr = frame
    x = np.asarray(x, dtype=float)
    ang = -np.broadcast_to(np.asarray(k, dtype=float), x.shape[:1]) * fr.tau
    x = _rotate(x, ang)
    ug = np.linspace(fr.u_fillet, fr.u_tip, n_grid)
    vg = np.linspace(fr.L_start, fr.L_end, n_grid)
    U, V = np.meshgrid(ug, vg, indexing="ij")
    if isinstance(fr.member, HasNativeFlank):
        nf = fr.member.native_flank(side)
        S, T = nf.native(U, V)
        G = nf.evaluate(S, T)[0].reshape(-1, 3)

        def point_tangents(a, b):
            p, _, pa, pb = nf.evaluate(a, b, tangents=True)
            return p, pa, pb

        a0, b0, ha, hb = S.ravel(), T.ravel(), np.ptp(S), np.ptp(T)
        box = None
    else:
        G = fr.member.point_normal(side, U, V)[0].reshape(-1, 3)
        hu = 1e-6 * (fr.u_tip - fr.u_fillet)
        hv = 1e-6 * (fr.L_end - fr.L_start)

        def point_tangents(a, b):
            A = np.concatenate([a, a + hu, a])
            B = np.concatenate([b, b, b + hv])
            P = fr.member.point_normal(side, A, B)[0].reshape(3, -1, 3)
            return P[0], (P[1] - P[0]) / hu, (P[2] - P[0]) / hv

        a0, b0, ha, hb = U.ravel(), V.ravel(), fr.u_tip - fr.u_fillet, fr.L_end - fr.L_start
        # the working flank only: below u_fillet the parameters run onto the fillet, another
        # surface (degenerate where a face-gear fillet shrinks to a point); projected steps
        box = (fr.u_fillet, fr.u_tip)
    idx = np.argmin(((x[:, None, :] - G[None, :, :]) ** 2).sum(-1), axis=1)
    a, b = a0[idx].copy(), b0[idx].copy()
    for _ in range(15):
        p, pa, pb = point_tangents(a, b)
        r = p - x
        a11, a12, a22 = (pa * pa).sum(-1), (pa * pb).sum(-1), (pb * pb).sum(-1)
        b1, b2 = -(pa * r).sum(-1), -(pb * r).sum(-1)
        det = a11 * a22 - a12**2
        da, db = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
        a, b = a + da, b + db
        if box is not None:
            a = np.clip(a, *box)
        if np.max(np.abs(da)) < 1e-9 * ha and np.max(np.abs(db)) < 1e-9 * hb:
            break
    p = point_tangents(a, b)[0]
    return np.linalg.norm(p - x, axis=-1), np.stack([a, b], -1)


def fillet_distance(frame: SectorFrame, k: Array | int, x: Array, n: int = 401) -> Array:
    """Distance (mm) of points ``x (m, 3)`` on the root/fillet faces of member teeth ``k`` to the
    exact root and generated fillet: the distance, within the section ``L = const`` of each
    point, to the nearer of the two exact section curves of that tooth
    (:func:`_root_fillet` with ``n`` points, a polyline whose chords sag ~1e-4 mm). It bounds the
    3-D distance to the surface from above. Families with a generated fillet only."""
    fr = frame
    if not fr.has_fillet:
        raise MeshError(f"{fr.family}: no generated fillet to measure against")
    x = np.asarray(x, dtype=float)
    ang = -np.broadcast_to(np.asarray(k, dtype=float), x.shape[:1]) * fr.tau
    x = _rotate(x, ang)
    L = fr.lh(x)[0]
    best = np.full(len(x), np.inf)
    for pts, _ in _root_fillet(fr, L, n=n).values():
        a, b = pts[:, :-1], pts[:, 1:]  # (m, n - 1, 3) segments
        ab = b - a
        t = np.clip(
            np.sum((x[:, None] - a) * ab, -1) / np.maximum(np.sum(ab * ab, -1), 1e-300), 0, 1
        )
        d = np.linalg.norm(a + t[..., None] * ab - x[:, None], axis=-1).min(axis=1)
        best = np.minimum(best, d)
    return best
