"""Section geometry of a tooth sector: the analytic curves the gmsh solid is lofted through.

A sector of ``n`` teeth is built (in :mod:`fegear.mesh.sector`) as a loft through *section
wires* lying in a family of parallel planes ``p · g = c``, then trimmed by a solid of
revolution (the *envelope*). This module computes, from the exact generated surfaces of a
member, everything that construction needs, in the member frame (axis z):

- per-family *cone coordinates* ``(L, h)``: ``L`` along the face (``z`` for cylindrical gears,
  the radius for a face gear, the cone distance for a bevel gear) and ``h`` across it (radius,
  height ``z``, height above the pitch cone). They map linearly to ``(ρ, z)``:
  ``(ρ, z)ᵀ = M (L, h)ᵀ`` with ``M`` orthogonal, so ``dV = ρ dL dh dφ``.
- surfaces of revolution ``h = a + b L`` (tip, root, trimming bottom) — exact for all three
  families (cylinders, planes, Gleason-taper cones),
- the section of a flank of tooth ``k`` by a plane ``p · g = c`` (1-D Newton on ``v`` for each
  ``u``), with end tangents for G1-continuous splines,
- an independent volume estimate by integrating the ``(φ, h)`` section at constant ``L`` along
  the face (:func:`section_integral_volume`), and closest points on the analytic flank
  (:func:`flank_distance`).

Teeth of the sector are numbered ``j = 0 … n−1`` in the direction of +θ; sector tooth ``j`` is
member tooth ``k = j − n//2`` (tooth ``k`` is tooth 0 turned by ``k τ`` about z), so the centre
tooth ``n//2`` is the member's tooth 0 used by the TCA.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import MeshError
from ..geometry.face_gear import FaceGearMember
from ..geometry.involute import InvoluteMember
from ..geometry.spiral_bevel import SpiralBevelMember
from ..geometry.surface import GeneratedMember, Side
from ..geometry.transforms import rot_z

__all__ = [
    "Line",
    "SectorFrame",
    "Edge",
    "sector_frame",
    "section_edges",
    "sections_edges",
    "section_integral_volume",
    "flank_distance",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


@dataclass(frozen=True)
class Line:
    """A surface of revolution ``h = a + b L`` in cone coordinates."""

    a: float
    b: float

    def __call__(self, L: Array | float) -> Array:
        return self.a + self.b * np.asarray(L, dtype=float)


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


@dataclass(frozen=True)
class SectorFrame:
    """Family-specific data of a sector (see module docstring). Lengths mm, angles rad."""

    member: GeneratedMember
    family: str
    module: float
    g: Array
    meridian: Array
    tip: Line
    root: Line
    bottom: Line
    loft_bottom: Line
    L_start: float
    L_end: float
    c_range: tuple[float, float]
    n_sections: int
    u_root: float
    u_fillet: float
    u_tip: float
    plus_side: Side
    bottom_name: str
    has_fillet: bool

    @property
    def minus_side(self) -> Side:
        return "coast" if self.plus_side == "drive" else "drive"

    @property
    def tau(self) -> float:
        return 2 * math.pi / self.member.n_teeth

    # ---------------------------------------------------------------- coordinates
    def rho_z(self, L: Array, h: Array) -> tuple[Array, Array]:
        """``(ρ, z)`` of cone coordinates."""
        M = self.meridian
        return M[0, 0] * L + M[0, 1] * h, M[1, 0] * L + M[1, 1] * h

    def lh(self, p: Array) -> tuple[Array, Array]:
        """Cone coordinates ``(L, h)`` of points ``(..., 3)``."""
        rho = np.hypot(p[..., 0], p[..., 1])
        Mi = np.linalg.inv(self.meridian)
        return Mi[0, 0] * rho + Mi[0, 1] * p[..., 2], Mi[1, 0] * rho + Mi[1, 1] * p[..., 2]

    def surface_point(self, line: Line, phi: Array, c: float) -> Array:
        """Points ``(..., 3)`` of the revolution surface ``line`` at polar angles ``phi`` in the
        plane ``p · g = c`` (exact: the plane condition is linear in ``L``)."""
        phi = np.asarray(phi, dtype=float)
        M, g = self.meridian, self.g
        ar, br = M[0, 0] + M[0, 1] * line.b, M[0, 1] * line.a
        az, bz = M[1, 0] + M[1, 1] * line.b, M[1, 1] * line.a
        w = np.cos(phi) * g[0] + np.sin(phi) * g[1]
        L = (c - br * w - bz * g[2]) / (ar * w + az * g[2])
        rho, z = ar * L + br, az * L + bz
        return np.stack([rho * np.cos(phi), rho * np.sin(phi), z], -1)

    def surface_tangent(self, line: Line, phi: float, c: float) -> Array:
        """Unit tangent of the section of ``line`` at ``phi``, pointing to +φ."""
        e = 1e-6
        d = self.surface_point(line, phi + e, c) - self.surface_point(line, phi - e, c)
        return d / np.linalg.norm(d)

    # ---------------------------------------------------------------- flanks
    def tooth_points(self, side: Side, k: int, u: Array, v: Array) -> Array:
        """Exact flank points of member tooth ``k`` (broadcast ``u``, ``v``)."""
        p, _ = self.member.point_normal(side, u, v)
        return p @ rot_z(k * self.tau)[:3, :3].T

    def flank_sections(self, side: Side, ks: Array, u: Array, cs: Array) -> Array:
        """Points ``(len(cs), len(ks), len(u), 3)`` of flank ``side`` of member teeth ``ks`` in the
        planes ``p · g = c`` (one vectorised 1-D Newton on ``v`` for all of them)."""
        ks, u, cs = (np.asarray(a, dtype=float) for a in (ks, u, cs))
        K, U, C = np.meshgrid(ks, u, cs, indexing="ij")
        K, U, C = (np.moveaxis(a, 2, 0) for a in (K, U, C))  # (nc, nk, nu)
        ang = -K * self.tau
        gk = np.stack(
            [np.cos(ang) * self.g[0] - np.sin(ang) * self.g[1],
             np.sin(ang) * self.g[0] + np.cos(ang) * self.g[1],
             np.full_like(ang, self.g[2])], -1,
        )  # fmt: skip
        hm = 0.5 * (self.tip((self.L_start + self.L_end) / 2) + self.root(self.L_start))
        p0 = self.surface_point(Line(float(hm), 0.0), K * self.tau, C)
        v = self.lh(p0)[0]
        dv = 1e-5 * (self.L_end - self.L_start)
        for _ in range(30):
            f0 = np.sum(self.member.point_normal(side, U, v)[0] * gk, -1) - C
            if np.max(np.abs(f0)) < 1e-10:
                break
            f1 = np.sum(self.member.point_normal(side, U, v + dv)[0] * gk, -1) - C
            v = v - f0 * dv / (f1 - f0)
        else:
            raise MeshError(f"flank sections ({side}) did not converge: {np.max(np.abs(f0)):.2e}")
        p = self.member.point_normal(side, U, v)[0]
        ca, sa = np.cos(-ang), np.sin(-ang)
        return np.stack(
            [ca * p[..., 0] - sa * p[..., 1], sa * p[..., 0] + ca * p[..., 1], p[..., 2]], -1
        )


def _unit(v: Array) -> Array:
    return v / np.linalg.norm(v)


def sector_frame(member: GeneratedMember, rim_modules: float = 3.0) -> SectorFrame:
    """The :class:`SectorFrame` of a member of any supported family.

    Rims: involute members get a bore of radius ``r_f − rim_modules · m``; the face gear its
    blank (``blank_thickness_mm`` below the root plane, bottom face ``base``); spiral bevel
    members a rim of ``rim_modules · m`` below the root cone (its bottom cone is ``bore``).
    """
    if isinstance(member, InvoluteMember):
        d = member.design
        m = d.module_mm
        bd = member.boundaries("drive")
        b = d.face_width_mm
        if d.helix_angle_deg != 0.0:
            n_sec = 7
        else:
            n_sec = 2
        r_bore = member.r_f - rim_modules * m
        if r_bore <= 0.1 * member.r_f:
            raise MeshError(f"rim of {rim_modules} modules leaves no bore (r_bore = {r_bore:.2f})")
        return SectorFrame(
            member=member, family="involute", module=m, g=np.array([0.0, 0.0, 1.0]),
            meridian=np.array([[0.0, 1.0], [1.0, 0.0]]), tip=Line(member.r_a, 0.0),
            root=Line(member.r_f, 0.0), bottom=Line(r_bore, 0.0),
            loft_bottom=Line(r_bore - 0.5 * m, 0.0), L_start=-b / 2, L_end=b / 2,
            c_range=(-b / 2 - 0.3 * m, b / 2 + 0.3 * m), n_sections=n_sec,
            u_root=bd.u_root, u_fillet=bd.u_fillet, u_tip=bd.u_tip, plus_side="drive",
            bottom_name="bore", has_fillet=True,
        )  # fmt: skip
    if isinstance(member, FaceGearMember):
        d = member.design
        m = d.module_mm
        bd = member.boundaries()
        z_root = -d.dedendum_coeff * m
        z_base = z_root - d.blank_thickness_mm
        # the generated surface exists only inside the undercut limit L1 (~465 mm for the
        # seed): extend the loft by 1 mm inwards, 3 mm outwards
        return SectorFrame(
            member=member, family="face_gear", module=m, g=np.array([1.0, 0.0, 0.0]),
            meridian=np.eye(2), tip=Line(d.addendum_coeff * m, 0.0), root=Line(z_root, 0.0),
            bottom=Line(z_base, 0.0), loft_bottom=Line(z_base - 0.5 * m, 0.0),
            L_start=d.inner_radius_mm, L_end=d.outer_radius_mm,
            c_range=(d.inner_radius_mm - 1.0, d.outer_radius_mm + 3.0), n_sections=7,
            u_root=bd.u_root, u_fillet=bd.u_fillet, u_tip=bd.u_tip, plus_side="drive",
            bottom_name="base", has_fillet=False,
        )  # fmt: skip
    if isinstance(member, SpiralBevelMember):
        bl = member.blank
        i = member.index
        m = bl.module_mm
        gam = member.pitch_angle
        A0 = bl.outer_cone_distance
        F = bl.face_width_mm
        ded = bl.dedenda[i - 1]
        td = math.tan(bl.dedendum_angles[i - 1])
        tj = math.tan(bl.dedendum_angles[1 if i == 1 else 0])
        root = Line(-ded + A0 * td, -td)
        tip = Line(bl.addenda[i - 1] - A0 * tj, tj)
        bot = Line(root.a - rim_modules * m, root.b)
        # plus side: the side whose mean point has the larger polar angle
        um, vm = member.mean_parameters()
        ang = {
            s: float(np.arctan2(*member.point_normal(s, um, vm)[0][[1, 0]]))
            for s in ("drive", "coast")
        }
        plus: Side = "drive" if ang["drive"] > ang["coast"] else "coast"
        bd = member.boundaries()
        # planes p·g = c cut outer teeth at a larger cone distance (factor ~ cos of the polar
        # offset on the pitch cone): extend the loft so every tooth spans the whole face
        sg, cg = math.sin(gam), math.cos(gam)
        return SectorFrame(
            member=member, family="spiral_bevel", module=m, g=np.array([sg, 0.0, cg]),
            meridian=np.array([[sg, cg], [cg, -sg]]), tip=tip, root=root, bottom=bot,
            loft_bottom=Line(bot.a - 0.5 * m, bot.b), L_start=A0 - F, L_end=A0,
            c_range=(A0 - F - 0.2 * F, A0 + 0.1 * F), n_sections=9,
            u_root=bd.u_root, u_fillet=bd.u_fillet, u_tip=bd.u_tip, plus_side=plus,
            bottom_name="bore", has_fillet=False,
        )  # fmt: skip
    raise MeshError(f"no sector geometry for member type {type(member).__name__}")


def _polar(p: Array) -> Array:
    return np.arctan2(p[..., 1], p[..., 0])


def section_edges(frame: SectorFrame, n_teeth: int, c: float, nu: int = 17) -> list[Edge]:
    """The closed section wire in the plane ``p · g = c`` (see :func:`sections_edges`)."""
    return sections_edges(frame, n_teeth, [c], nu)[0]


def sections_edges(
    frame: SectorFrame, n_teeth: int, cs: Sequence[float], nu: int = 17
) -> list[list[Edge]]:
    """The closed section wires of the sector in the planes ``p · g = c``, as ordered edges.

    Order (+θ): for each sector tooth ``j``: ``fillet_j`` (minus side, from the space middle),
    ``flank_<minus>_j``, ``top_j``, ``flank_<plus>_j``, ``fillet_j`` (plus side, to the next
    space middle); then ``cut_right`` (down to the loft bottom), ``bottom`` (trimmed away later),
    ``cut_left``. Labels name the physical group the lofted face will belong to.
    """
    fr = frame
    ks = [j - n_teeth // 2 for j in range(-1, n_teeth + 1)]
    uw = np.linspace(fr.u_fillet, fr.u_tip, nu)
    eps = 1e-5 * (fr.u_tip - fr.u_root)
    uf = np.linspace(fr.u_root, fr.u_fillet, max(5, nu // 2)) if fr.has_fillet else None
    uu = [uw, np.array([fr.u_fillet - eps, fr.u_fillet + eps, fr.u_tip - eps, fr.u_tip])]
    if uf is not None:
        uu.append(uf)
    allu = np.concatenate(uu)
    n1 = len(uw)
    raw = {s: fr.flank_sections(s, np.array(ks), allu, np.asarray(cs)) for s in ("drive", "coast")}
    return [
        _section(fr, n_teeth, float(c), ks, raw, i, n1, uf is not None) for i, c in enumerate(cs)
    ]


def _section(fr, n_teeth, c, ks, raw, ic, n1, with_fillet) -> list[Edge]:
    data: dict[tuple[int, str], dict[str, Array]] = {}
    for ik, k in enumerate(ks):
        for side in ("drive", "coast"):
            pts = raw[side][ic, ik]
            e = pts[n1 : n1 + 4]
            data[(k, side)] = {
                "work": pts[:n1],
                "t_fil": _unit(e[1] - e[0]),
                "t_tip": _unit(e[3] - e[2]),
                "fillet": pts[n1 + 4 :] if with_fillet else pts[:1],
            }
    plus, minus = fr.plus_side, fr.minus_side

    def space_mid(k_left: int) -> tuple[Array, Array]:
        a = data[(k_left, plus)]["fillet"][0]
        b = data[(k_left + 1, minus)]["fillet"][0]
        pa, pb = _polar(a), _polar(b)
        if pb <= pa:
            raise MeshError(f"tooth space after tooth {k_left} is closed at c = {c:.3f}")
        phi = 0.5 * (pa + pb)
        return fr.surface_point(fr.root, phi, c), fr.surface_tangent(fr.root, phi, c)

    edges: list[Edge] = []
    mid, t_mid = space_mid(ks[0])
    mid_left, phi_left = mid, _polar(mid)
    for j in range(n_teeth):
        k = j - n_teeth // 2
        dm, dp = data[(k, minus)], data[(k, plus)]
        # minus fillet: space middle -> fillet limit
        if fr.has_fillet:
            pts = np.vstack([mid, dm["fillet"]])
            edges.append(Edge(f"fillet_{j}", pts, t_mid, dm["t_fil"]))
        else:
            edges.append(Edge(f"fillet_{j}", np.vstack([mid, dm["work"][0]]), t_mid, dm["t_fil"]))
        edges.append(Edge(f"flank_{minus}_{j}", dm["work"], dm["t_fil"], dm["t_tip"]))
        a0, a1 = _polar(dm["work"][-1]), _polar(dp["work"][-1])
        tops = fr.surface_point(fr.tip, np.linspace(a0, a1, 7)[1:-1], c)
        edges.append(Edge(f"top_{j}", np.vstack([dm["work"][-1], tops, dp["work"][-1]])))
        edges.append(Edge(f"flank_{plus}_{j}", dp["work"][::-1], -dp["t_tip"], -dp["t_fil"]))
        nxt, t_nxt = space_mid(k)
        if fr.has_fillet:
            pts = np.vstack([dp["fillet"][::-1], nxt])
            edges.append(Edge(f"fillet_{j}", pts, -dp["t_fil"], t_nxt))
        else:
            edges.append(Edge(f"fillet_{j}", np.vstack([dp["work"][0], nxt]), -dp["t_fil"], t_nxt))
        mid, t_mid = nxt, t_nxt
    phi_right = _polar(mid)
    b_right = fr.surface_point(fr.loft_bottom, phi_right, c)
    b_left = fr.surface_point(fr.loft_bottom, phi_left, c)
    edges.append(Edge("cut_right", np.vstack([mid, b_right]), straight=True))
    phis = np.linspace(phi_right, phi_left, 4 * n_teeth + 3)[1:-1]
    bottom = np.vstack([b_right, fr.surface_point(fr.loft_bottom, phis, c), b_left])
    edges.append(Edge("bottom", bottom))
    edges.append(Edge("cut_left", np.vstack([b_left, mid_left]), straight=True))
    return edges


# --------------------------------------------------------------------------- checks
def section_integral_volume(frame: SectorFrame, n_teeth: int, n_L: int = 21, nu: int = 81) -> float:
    """Sector volume by integrating the ``(φ, h)`` section at constant ``L`` along the face.

    ``V = ∫ dL ∬ ρ(L, h) dφ dh`` over the section bounded by the exact flanks (sampled at ``v = L``
    directly, no plane solves), the tip and root/bottom surfaces and the space-middle cuts;
    Simpson's rule in ``L``. Root blends of families without a modelled fillet are taken as the
    chord from the flank bottom to the space middle (the CAD blend bulges slightly, see tests).
    """
    fr = frame
    M = fr.meridian
    u = np.linspace(fr.u_root, fr.u_tip, nu)
    Ls = np.linspace(fr.L_start, fr.L_end, n_L if n_L % 2 else n_L + 1)
    plus, minus = fr.plus_side, fr.minus_side
    vals = []
    for L in Ls:
        ks = [j - n_teeth // 2 for j in range(-1, n_teeth + 1)]
        fl = {}
        for k in ks:
            for s in (plus, minus):
                p = fr.tooth_points(s, k, u, np.full_like(u, L))
                fl[(k, s)] = np.stack([_polar(p), fr.lh(p)[1]], -1)

        def mid(kl: int, L: float = L, fl: dict = fl) -> Array:
            phi = 0.5 * (fl[(kl, plus)][0, 0] + fl[(kl + 1, minus)][0, 0])
            return np.array([phi, float(fr.root(L))])

        poly = [mid(ks[0])]
        for j in range(n_teeth):
            k = j - n_teeth // 2
            poly += [fl[(k, minus)], fl[(k, plus)][::-1], mid(k)[None, :]]
        hb = float(fr.bottom(L))
        poly += [np.array([[poly[-1][-1][0], hb], [poly[0][0], hb]])]
        P = np.vstack([np.atleast_2d(q) for q in poly])
        x, y = P[:, 0], P[:, 1]
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

    Closest-point Gauss-Newton on ``|p(u, v) − x|²`` from the nearest point of an
    ``n_grid × n_grid`` sample of the flank (finite-difference tangents), no bounds on
    ``(u, v)``. Returns the distances ``(m,)`` mm and the parameters ``(m, 2)``.
    """
    fr = frame
    x = np.asarray(x, dtype=float)
    ang = -np.broadcast_to(np.asarray(k, dtype=float), x.shape[:1]) * fr.tau
    ca, sa = np.cos(ang), np.sin(ang)
    x = np.stack([ca * x[:, 0] - sa * x[:, 1], sa * x[:, 0] + ca * x[:, 1], x[:, 2]], -1)
    ug = np.linspace(fr.u_fillet, fr.u_tip, n_grid)
    vg = np.linspace(fr.L_start, fr.L_end, n_grid)
    G = fr.member.point_normal(side, ug[:, None], vg[None, :])[0].reshape(-1, 3)
    idx = np.argmin(((x[:, None, :] - G[None, :, :]) ** 2).sum(-1), axis=1)
    u = ug[idx // n_grid].copy()
    v = vg[idx % n_grid].copy()
    hu = 1e-6 * (fr.u_tip - fr.u_fillet)
    hv = 1e-6 * (fr.L_end - fr.L_start)
    for _ in range(15):
        U = np.concatenate([u, u + hu, u])
        V = np.concatenate([v, v, v + hv])
        P = fr.member.point_normal(side, U, V)[0].reshape(3, -1, 3)
        p, pu, pv = P[0], (P[1] - P[0]) / hu, (P[2] - P[0]) / hv
        r = p - x
        a11, a12, a22 = (pu * pu).sum(-1), (pu * pv).sum(-1), (pv * pv).sum(-1)
        b1, b2 = -(pu * r).sum(-1), -(pv * r).sum(-1)
        det = a11 * a22 - a12**2
        du, dv = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
        u, v = u + du, v + dv
        if np.max(np.abs(du)) < 1e-9 * (fr.u_tip - fr.u_fillet) and np.max(np.abs(dv)) < 1e-9 * (
            fr.L_end - fr.L_start
        ):
            break
    p = fr.member.point_normal(side, u, v)[0]
    return np.linalg.norm(p - x, axis=-1), np.stack([u, v], -1)
