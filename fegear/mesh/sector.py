"""Tooth-sector FE meshes (``docs/mesh/README.md``): ``n`` teeth plus rim, refined only where
contact can happen.

Construction (gmsh, OpenCASCADE kernel; :mod:`fegear.mesh.sector_geometry` computes the curves):

1. *Section wires* on the surfaces of constant face coordinate ``L`` (transverse planes
   ``z = L`` for cylindrical gears, cylinders ``ρ = L`` for the face gear, back cones
   ``L = const`` for bevel gears), so every tooth of the sector is cut at the same face
   position however far it is turned (parallel planes cut the outer teeth of the 36-tooth
   bevel gear's ±20° sector up to 10 % past the heel): exact flank points ``p(u, v = L)``
   interpolated by splines (``addSpline`` with exact end tangents, so flank/fillet joins are
   G1), tip and root lines on the exact surfaces of revolution, straight cut lines through the
   middles of the two outer tooth spaces, a bottom line below the rim. The section curves and
   their interpolation points are removed once lofted.
2. ``addThruSections`` lofts them into one solid (one face per section edge; ruled for spur
   gears, whose flanks are straight along the face).
3. The loft, built a little longer than the face and deeper than the rim, is intersected with
   a solid of revolution (a quadrilateral in the meridian half-plane φ = π revolved about z, so
   its seam lies opposite the sector instead of splitting the centre tooth's faces into
   slivers) whose faces are the exact face ends (planes ``z = ±b/2``; cylinders
   ``r = 471 / 560`` mm of the face gear; toe/heel back cones of bevel gears) and the exact
   bore / blank base / rim-bottom cone.
4. Faces are named *geometrically*: envelope faces by their cone coordinates, loft faces by the
   nearest section edge (majority vote of a 5 × 5 parametric sample of the face).

Fillets: every family models the generated fillet (the involute's trochoid from the rack tip,
the face gear's trace of the shaper's tip edge, :mod:`fegear.geometry.face_gear_fillet`, the
spiral bevel's envelope of the blade's edge radius, :mod:`fegear.geometry.bevel`) and the
root between the fillets of a tooth space. Each section carries them as one edge per space half
(space middle → root → fillet → fillet limit) through 25 exact points at about equal arc lengths
(:func:`~.sector_geometry._root_fillet`), so that the loft stays regular where the face-gear
fillet shrinks from 7 mm at the inner end to a point at 555 mm (where the shaper tip rolls on
the root plane); fillet nodes lie within 0.011 mm of the exact fillet on the level-0 seed sector
(``tests/test_mesh_sector.py``); the spiral bevel's (an edge radius of 0.81 mm, fillets about
1 mm high, 13 points per space half) within 2e-5 of the local element size. (A family without a
generated fillet would close each tooth space with a *root blend*: a cubic Hermite curve from the
flank bottom to the space middle on the root surface, given to OCC as the equivalent Bézier;
none is left.)

Boundary conditions meant for this mesh (applied by the compliance stage): ``bore`` (involute
and spiral bevel members: bore, or rim-bottom cone ``rim_modules · m`` below the root cone) or
``base`` (face gear: the blank bottom ``blank_thickness_mm`` below the root plane) fixed, and
both sector cuts ``cut_left`` / ``cut_right`` fixed. Measured effect of the cut BC on the
compliance of the centre tooth (FZG pinion, 3 teeth): see ``docs/mesh/README.md``.

Quality: min SICN ≥ ``min_sicn``; attempts (2-D/3-D algorithm) Frontal-Delaunay/HXT,
MeshAdapt/HXT, Frontal-Delaunay/Delaunay, MeshAdapt/Delaunay, each in a fresh gmsh session, else
:class:`~fegear.errors.MeshError` listing every attempt.

Sizes: one knob ``level`` (0 coarse … 4 fine). With ``m`` the module, the contact zone gets
``h_fine = FINE[level] m``, the fillets of the loaded teeth ``1.25 h_fine``, and the size grows
linearly with the distance to them (slope 0.4) to ``h_coarse = COARSE[level] m`` (gmsh
Distance + Threshold fields, Min of both). ``fillet_mm`` sets the size on those fillets
alone (the root-stress meshes, :mod:`fegear.fem.stress`): the fine layer is then ``2 fillet_mm``
deep, the distance field samples each fillet face at about ``fillet_mm`` and the size grows
with the same slope; it enters the cache key only when given, so the contact meshes keep theirs.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from fegear.store.files import atomic_write

from ..errors import InputError, MeshError
from ..geometry.surface import GeneratedMember, Side
from ..store.cache import Entry, cached_record
from .gmsh_session import initialize as initialize_gmsh
from .gmsh_session import native_output_to_log
from .sector_geometry import (
    SectorFrame,
    flank_distance,
    hermite_points,
    sections_edges,
    sector_frame,
)

__all__ = [
    "FINE",
    "COARSE",
    "FILLET_TRIANGLES",
    "FlankZone",
    "SectorMesh",
    "mesh_sizes",
    "default_zone",
    "sector_mesh",
    "load_sector_mesh",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]

#: fine (contact-zone) element size per level, in modules
FINE = (0.45, 0.32, 0.22, 0.16, 0.11)
#: coarse (far-field) element size per level, in modules
COARSE = (1.6, 1.3, 1.0, 0.8, 0.6)
#: At most this many triangles on the refined fillets of a sector meshed with ``fillet_mm``
#: (:func:`sector_mesh`): a larger fillet area gets a coarser size. The FZG pinion sector (3
#: refined teeth, 340 mm² of fillets at 0.45 mm: 3 900 triangles, 41 000 tetrahedra) keeps its
#: size; the seed face gear's 89 mm wide fillets at 0.635 mm made 127 000-149 000 tetrahedra and
#: a 14 GB solve (killed on a 23 GB machine).
FILLET_TRIANGLES = 5000


class FlankZone(NamedTuple):
    """A potential-contact box on one flank: sector tooth ``tooth`` (0 … n−1), ``side``, and
    parameter ranges ``u = (u0, u1)``, ``v = (v0, v1)`` of the member's flank parameters."""

    tooth: int
    side: Side
    u: tuple[float, float]
    v: tuple[float, float]


def mesh_sizes(module: float, level: int) -> tuple[float, float]:
    """``(h_fine, h_coarse)`` in mm for a size ``level`` in 0 … 4."""
    if level not in range(len(FINE)):
        raise InputError("mesh.level", level, f"an integer in 0..{len(FINE) - 1}")
    return FINE[level] * module, COARSE[level] * module


def default_zone(frame: SectorFrame, n_teeth: int, side: Side = "drive") -> tuple[FlankZone, ...]:
    """The whole working ``side`` flank of the centre teeth (all but one tooth at each end;
    all teeth if ``n_teeth < 3``)."""
    teeth = range(1, n_teeth - 1) if n_teeth >= 3 else range(n_teeth)
    return tuple(
        FlankZone(j, side, (frame.u_fillet, frame.u_tip), (frame.L_start, frame.L_end))
        for j in teeth
    )


@dataclass(frozen=True)
class SectorMesh:
    """A linear-tetrahedron sector mesh with named boundary facets (member frame, mm).

    Attributes
    ----------
    member
        Member name (``"pinion"``, ``"gear"``, ``"face_gear"``).
    family
        ``"involute"``, ``"face_gear"`` or ``"spiral_bevel"``.
    points
        ``(n, 3)`` node coordinates.
    tets
        ``(m, 4)`` node indices of the tetrahedra.
    boundaries
        ``{name: (k, 3) triangles}``: ``flank_drive_j``, ``flank_coast_j``, ``fillet_j``,
        ``top_j`` (sector tooth ``j`` = member tooth ``j − n//2``), ``cut_left``,
        ``cut_right``, ``bore`` or ``base``, ``face_start``, ``face_end``.
    parameters
        What the mesh was built from (teeth, level, sizes, zone, rim, algorithm).
    diagnostics
        Measured numbers: mesh time, minimum SICN, CAD volume, flank CAD deviation, …
    path
        The cached ``.msh`` file.
    """

    member: str
    family: str
    points: Array
    tets: NDArray[np.int64]
    boundaries: Mapping[str, NDArray[np.int64]]
    parameters: Mapping[str, object]
    diagnostics: Mapping[str, object] = field(default_factory=dict)
    path: Path | None = None

    def __reduce__(self):
        """Pickled with plain dicts for its read-only mappings (a mesh made in a forked process
        comes back: :func:`fegear.ltca.analysis.build_models`), read-only again when loaded."""
        fields = (self.member, self.family, self.points, self.tets, dict(self.boundaries),
                  dict(self.parameters), dict(self.diagnostics), self.path)  # fmt: skip
        return (_sector_from_fields, fields)

    @property
    def n_teeth(self) -> int:
        return int(self.parameters["n_teeth"])

    @property
    def centre_tooth(self) -> int:
        """Sector index of the centre tooth (member tooth 0)."""
        return self.n_teeth // 2

    def volume(self) -> float:
        """Sum of the tetrahedron volumes (mm³)."""
        p = self.points[self.tets]
        d = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])
        return float(np.sum(np.abs(d)) / 6.0)

    def boundary_nodes(self, name: str) -> NDArray[np.int64]:
        """Sorted unique node indices of a named boundary."""
        return np.unique(self.boundaries[name])

    def to_skfem(self):
        """``skfem.MeshTet`` with the named boundaries set (facet indices)."""
        from skfem import MeshTet

        mesh = MeshTet(self.points.T.copy(), self.tets.T.copy())
        f = np.sort(mesh.facets, axis=0).T
        key = {tuple(r): i for i, r in enumerate(f.tolist())}
        bnd = {}
        for name, tri in self.boundaries.items():
            idx = [key.get(tuple(r)) for r in np.sort(tri, axis=1).tolist()]
            if any(i is None for i in idx):
                raise MeshError(f"boundary {name!r} has triangles that are not tet facets")
            bnd[name] = np.asarray(idx, dtype=np.int64)
        return mesh.with_boundaries(bnd)


# ------------------------------------------------------------------------------ construction
def _add_curve(occ, e, t_start: int, t_end: int, aux: list[int]) -> int:
    """Add the curve of section edge ``e`` between vertices ``t_start``, ``t_end``; the tags of
    the auxiliary points (interpolation / control points) are appended to ``aux``."""
    if e.straight:
        return occ.addLine(t_start, t_end)
    if len(e.points) == 2 and e.t0 is not None and e.t1 is not None:
        # root blend: the cubic Hermite curve with tangents scaled to the chord ℓ, given
        # explicitly as a Bézier (addSpline would rescale the tangents in its own way)
        p0, p1 = e.points
        ell = float(np.linalg.norm(p1 - p0))
        c0 = occ.addPoint(*(p0 + ell / 3 * e.t0))
        c1 = occ.addPoint(*(p1 - ell / 3 * e.t1))
        aux += [c0, c1]
        return occ.addBSpline([t_start, c0, c1, t_end], degree=3)
    mids = [occ.addPoint(*p) for p in e.points[1:-1]]
    aux += mids
    tang: list[float] = []
    if e.t0 is not None and e.t1 is not None:
        tang = [*map(float, e.t0), *map(float, e.t1)]
    return occ.addSpline([t_start, *mids, t_end], tangents=tang)


def _label_clouds(fr: SectorFrame, n_teeth: int, n_sections: int = 25):
    """Labelled sample points of ``n_sections`` section wires spread over the loft span."""
    Ls = np.linspace(*fr.L_range, n_sections)
    pts, labs, ll = [], [], []
    same = fr.family == "involute" and fr.n_sections == 2  # spur: sections are translates
    allx = sections_edges(fr, n_teeth, Ls[:1] if same else Ls, nu=11)
    for i, L in enumerate(Ls):
        edges = allx[0 if same else i]
        for e in edges:
            q = hermite_points(e)
            if same:
                q = q + (L - Ls[0]) * fr.e_L
            pts.append(q)
            labs += [e.label] * len(q)
            ll += [L] * len(q)
    return np.vstack(pts), np.array(labs), np.array(ll), Ls


def _classify(gmsh, fr: SectorFrame, faces: list[int], n_teeth: int) -> dict[str, list[int]]:
    """Name the faces of the trimmed solid geometrically.

    Envelope faces by their cone coordinates (``L = L_start``, ``L = L_end``, ``h = bottom``);
    loft faces by a majority vote of a 5 × 5 parametric sample: each sample point, moved along
    the meridian to the nearest labelled section (same ``h`` and polar angle), takes the label
    of the nearest section sample point.
    """
    P, labs, ll, Ls = _label_clouds(fr, n_teeth)
    tol = 1e-4 * max(1.0, fr.module)
    groups: dict[str, list[int]] = {}
    for tag in faces:
        lo, hi = gmsh.model.getParametrizationBounds(2, tag)
        s = np.linspace(0.1, 0.9, 5)
        uv = np.array(
            [[lo[0] + a * (hi[0] - lo[0]), lo[1] + b * (hi[1] - lo[1])] for a in s for b in s]
        )
        x = np.reshape(gmsh.model.getValue(2, tag, uv.ravel()), (-1, 3))
        L, h = fr.lh(x)
        if np.all(np.abs(L - fr.L_start) < tol):
            name = "face_start"
        elif np.all(np.abs(L - fr.L_end) < tol):
            name = "face_end"
        elif np.all(np.abs(h - fr.bottom(L)) < tol):
            name = fr.bottom_name
        else:
            votes: dict[str, int] = {}
            phi = np.arctan2(x[:, 1], x[:, 0])
            for Li, hi_, pi in zip(L, h, phi, strict=True):
                Ln = Ls[np.argmin(np.abs(Ls - Li))]
                sel = ll == Ln
                q = fr.point(Ln, hi_, pi)
                i = np.argmin(np.sum((P[sel] - q) ** 2, axis=1))
                lab = labs[sel][i]
                votes[lab] = votes.get(lab, 0) + 1
            name = max(votes, key=votes.get)
            if votes[name] < 0.6 * len(x):
                log.warning("face %d classified %s with weak majority %s", tag, name, votes)
        groups.setdefault(name, []).append(tag)
    return groups


def _zone_points(fr: SectorFrame, zone: Sequence[FlankZone], spacing: float, n_teeth: int) -> Array:
    """Points on the flanks covering the zone boxes at about ``spacing`` (the seeds of the fine
    mesh-size field).

    The flank of tooth 0 is evaluated exactly on a 25 × 25 grid over the ``(u, v)`` bounding box
    of all boxes of a side, and the box grids are interpolated from it (bicubic splines per
    coordinate) and rotated to their teeth. A face-gear flank point is an iterative envelope
    solve of ~1 ms: evaluating every box exactly took 3.3-6.2 s of the seed face gear's 8 s
    sector mesh (44 boxes, 3096 points); the splines take 0.2 s, are within 0.0005 mm of the
    exact points there, far below any element size, and only place the size field.
    """
    from scipy.interpolate import RectBivariateSpline

    zone = list(zone)
    out: list[Array] = [np.zeros((0, 3))] * len(zone)
    for side in sorted({z.side for z in zone}):
        idx = [i for i, z in enumerate(zone) if z.side == side]
        ug = np.linspace(min(zone[i].u[0] for i in idx), max(zone[i].u[1] for i in idx), 25)
        vg = np.linspace(min(zone[i].v[0] for i in idx), max(zone[i].v[1] for i in idx), 25)
        if np.ptp(ug) <= 0.0 or np.ptp(vg) <= 0.0:
            raise InputError("mesh.zone", "a box of zero extent", "boxes with u0 < u1, v0 < v1")
        G = fr.flank_points(side, ug[:, None], vg[None, :])  # (25, 25, 3)
        splines = [RectBivariateSpline(ug, vg, G[..., c]) for c in range(3)]

        def at(u: Array, v: Array) -> Array:
            return np.stack([s(u, v) for s in splines], axis=-1)  # noqa: B023 (used at once)

        for i in idx:
            z = zone[i]
            P = at(np.linspace(*z.u, 9), np.linspace(*z.v, 9))
            lu = np.max(np.sum(np.linalg.norm(np.diff(P, axis=0), axis=-1), axis=0))
            lv = np.max(np.sum(np.linalg.norm(np.diff(P, axis=1), axis=-1), axis=1))
            nu, nv = max(2, math.ceil(lu / spacing) + 1), max(2, math.ceil(lv / spacing) + 1)
            pts = at(np.linspace(*z.u, nu), np.linspace(*z.v, nv)).reshape(-1, 3)
            out[i] = fr.on_tooth(pts, z.tooth - n_teeth // 2)
    return np.vstack(out) if out else np.zeros((0, 3))


def _build(
    fr: SectorFrame,
    n_teeth: int,
    level: int,
    zone: Sequence[FlankZone],
    algorithm: int,
    min_sicn: float,
    path: Path,
    fillet_mm: float | None = None,
    refine: tuple = ((), None),
) -> dict[str, object]:
    """Build and mesh the sector, writing ``path``; returns the diagnostics.

    Attempts (2-D algorithm, 3-D algorithm), each in a fresh gmsh session (gmsh is not reliably
    reusable after a failed ``generate``): Frontal-Delaunay surfaces and ``algorithm`` first;
    on a failure or slivers (min SICN < ``min_sicn``) MeshAdapt surfaces, then the Delaunay
    volume mesher.
    """
    attempts = list(dict.fromkeys([(6, algorithm), (1, algorithm), (6, 1), (1, 1)]))
    failures = []
    t0 = time.perf_counter()
    for alg2, alg3 in attempts:
        try:
            diag = _attempt(fr, n_teeth, level, zone, alg2, alg3, path, fillet_mm, refine)
        except _AttemptFailed as exc:
            log.warning("sector mesh: %s", exc)
            failures.append(str(exc))
            continue
        if diag["min_sicn"] >= min_sicn:
            diag["attempts"] = len(failures) + 1
            diag["total_s"] = time.perf_counter() - t0
            return diag
        msg = f"2D/3D algorithms {alg2}/{alg3}: min SICN {diag['min_sicn']:.3f} < {min_sicn}"
        log.warning("sector mesh: %s", msg)
        failures.append(msg)
    raise MeshError(f"sector mesh quality: no acceptable mesh ({'; '.join(failures)})")


class _AttemptFailed(Exception):
    """gmsh failed to mesh with one pair of algorithms."""


def _attempt(
    fr: SectorFrame,
    n_teeth: int,
    level: int,
    zone: Sequence[FlankZone],
    alg2: int,
    alg3: int,
    path: Path,
    fillet_mm: float | None = None,
    refine: tuple = ((), None),
) -> dict[str, object]:
    import gmsh

    h_fine, h_coarse = mesh_sizes(fr.module, level)
    diag: dict[str, object] = {"h_fine_mm": h_fine, "h_coarse_mm": h_coarse}
    t0 = time.perf_counter()
    initialize_gmsh()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 2)
        gmsh.option.setNumber("General.NumThreads", 1)  # deterministic meshes (HXT)
        gmsh.model.add("sector")
        occ = gmsh.model.occ
        wires: list[int] = []
        aux: list[int] = []
        section_curves: list[int] = []
        for edges in sections_edges(fr, n_teeth, np.linspace(*fr.L_range, fr.n_sections)):
            starts = [occ.addPoint(*e.points[0]) for e in edges]
            curves = [
                _add_curve(occ, e, starts[i], starts[(i + 1) % len(edges)], aux)
                for i, e in enumerate(edges)
            ]
            wires.append(occ.addWire(curves))
            aux += starts
            section_curves += curves
        loft = occ.addThruSections(wires, makeSolid=True, makeRuled=fr.n_sections == 2)
        loft_vol = [dt for dt in loft if dt[0] == 3]
        # the section curves and their points are not part of the solid: left in the model,
        # removeAllDuplicates would embed those touching it (split faces, slivers)
        occ.remove([(1, c) for c in section_curves] + [(0, t) for t in aux], recursive=True)
        # envelope: revolved quadrilateral (L, h) -> (rho, z)
        hi = max(float(fr.tip(fr.L_start)), float(fr.tip(fr.L_end))) + 3 * fr.module
        corners = [
            (fr.L_start, float(fr.bottom(fr.L_start))),
            (fr.L_end, float(fr.bottom(fr.L_end))),
            (fr.L_end, hi),
            (fr.L_start, hi),
        ]
        pts = []
        for L, h in corners:
            r, z = fr.rho_z(L, h)
            # quadrilateral in the half-plane φ = π: the seam of the revolved envelope then lies
            # opposite the sector (a seam through the teeth splits faces into slivers)
            pts.append(occ.addPoint(-float(r), 0.0, float(z)))
        lines = [occ.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
        quad = occ.addPlaneSurface([occ.addCurveLoop(lines)])
        rev = occ.revolve([(2, quad)], 0, 0, 0, 0, 0, 1, 2 * math.pi)
        env = [dt for dt in rev if dt[0] == 3]
        out, _ = occ.intersect(loft_vol, env)
        occ.synchronize()
        log.debug("entities after trimming: %s", [len(gmsh.model.getEntities(d)) for d in range(4)])
        occ.removeAllDuplicates()
        occ.synchronize()
        vols = gmsh.model.getEntities(3)
        if len(vols) != 1:
            raise MeshError(f"sector solid has {len(vols)} volumes after trimming (expected 1)")
        vol = vols[0][1]
        # drop what is not part of the solid (the envelope's generating quadrilateral)
        bf = gmsh.model.getBoundary([(3, vol)], oriented=False)
        bc = gmsh.model.getBoundary(bf, combined=False, oriented=False)
        bp = gmsh.model.getBoundary(bc, combined=False, oriented=False)
        keep = {(3, vol), *bf, *bc, *bp}
        stray = [dt for d in (2, 1, 0) for dt in gmsh.model.getEntities(d) if dt not in keep]
        if stray:
            occ.remove(stray)
            occ.synchronize()
        diag["cad_volume_mm3"] = occ.getMass(3, vol)
        faces = [t for _, t in gmsh.model.getBoundary([(3, vol)], oriented=False)]
        groups = _classify(gmsh, fr, faces, n_teeth)
        expected = {"cut_left", "cut_right", fr.bottom_name, "face_start", "face_end"}
        for j in range(n_teeth):
            expected |= {f"flank_drive_{j}", f"flank_coast_{j}", f"fillet_{j}", f"top_{j}"}
        if set(groups) != expected:
            raise MeshError(
                f"face classification: missing {sorted(expected - set(groups))}, "
                f"unexpected {sorted(set(groups) - expected)}"
            )
        for name, tags in sorted(groups.items()):
            gmsh.model.addPhysicalGroup(2, tags, name=name)
        gmsh.model.addPhysicalGroup(3, [vol], name="volume")
        diag["flank_cad_deviation_mm"] = _cad_deviation(gmsh, fr, groups, n_teeth)
        diag["construction_s"] = time.perf_counter() - t0

        # size fields
        zp = _zone_points(fr, zone, 0.5 * h_fine, n_teeth)
        ptags = [occ.addPoint(*p) for p in zp]
        occ.synchronize()
        fd = gmsh.model.mesh.field
        f1 = fd.add("Distance")
        fd.setNumbers(f1, "PointsList", ptags)
        t1 = fd.add("Threshold")
        fd.setNumber(t1, "InField", f1)
        fd.setNumber(t1, "SizeMin", h_fine)
        fd.setNumber(t1, "SizeMax", h_coarse)
        fd.setNumber(t1, "DistMin", 0.5 * h_fine)
        fd.setNumber(t1, "DistMax", 0.5 * h_fine + 2.5 * (h_coarse - h_fine))
        fillets = sorted({t for z in zone for t in groups[f"fillet_{z.tooth}"]})
        h_fil, d_fil, sampling = 1.25 * h_fine, 0.5 * h_fine, 40
        if fillet_mm is not None:
            # samples about one fillet size apart on the largest fillet face, a fine layer two
            # elements deep (the stress decays over the fillet radius), the same 0.4 slope
            span = max(
                float(np.linalg.norm(np.subtract(*np.reshape(
                    gmsh.model.getBoundingBox(2, t), (2, 3)))))
                for t in fillets
            )  # fmt: skip
            # the budget: at most FILLET_TRIANGLES equilateral triangles (area √3/4 h²) on the
            # refined fillets, else a coarser size (the sector's memory grows with it)
            area = sum(occ.getMass(2, t) for t in fillets)
            h_fil = max(fillet_mm, math.sqrt(area / (0.25 * math.sqrt(3.0) * FILLET_TRIANGLES)))
            d_fil = 2.0 * h_fil
            sampling = max(40, math.ceil(span / h_fil))
            diag.update(fillet_mm=h_fil, fillet_mm_asked=fillet_mm, fillet_area_mm2=area)
        f2 = fd.add("Distance")
        fd.setNumbers(f2, "SurfacesList", fillets)
        fd.setNumber(f2, "Sampling", sampling)
        t2 = fd.add("Threshold")
        fd.setNumber(t2, "InField", f2)
        fd.setNumber(t2, "SizeMin", h_fil)
        fd.setNumber(t2, "SizeMax", h_coarse)
        fd.setNumber(t2, "DistMin", d_fil)
        fd.setNumber(t2, "DistMax", d_fil + 2.5 * (h_coarse - h_fil))
        fields = [t1, t2]
        boxes, h_ref = refine
        if boxes:  # the boxes of a chosen size (sector_mesh's refine, refine_mm)
            rp = _zone_points(fr, boxes, 0.5 * h_ref, n_teeth)
            rtags = [occ.addPoint(*p) for p in rp]
            occ.synchronize()
            f3 = fd.add("Distance")
            fd.setNumbers(f3, "PointsList", rtags)
            t3 = fd.add("Threshold")
            fd.setNumber(t3, "InField", f3)
            fd.setNumber(t3, "SizeMin", h_ref)
            fd.setNumber(t3, "SizeMax", h_coarse)
            fd.setNumber(t3, "DistMin", 0.5 * h_ref)
            fd.setNumber(t3, "DistMax", 0.5 * h_ref + 2.5 * (h_coarse - h_ref))
            fields.append(t3)
            diag.update(refine_points=len(rp), refine_mm=h_ref)
        fmin = fd.add("Min")
        fd.setNumbers(fmin, "FieldsList", fields)
        fd.setAsBackgroundMesh(fmin)
        for k, v in {
            "Mesh.MeshSizeExtendFromBoundary": 0,
            "Mesh.MeshSizeFromPoints": 0,
            "Mesh.MeshSizeFromCurvature": 0,
            "Mesh.MeshSizeMax": h_coarse,
            "Mesh.MeshSizeMin": min(0.5 * h_fine, h_fil, 0.5 * (refine[1] or h_fine)),
            "Mesh.ElementOrder": 1,
            "Mesh.Optimize": 1,
        }.items():
            gmsh.option.setNumber(k, v)
        diag["zone_points"] = len(zp)
        tm = time.perf_counter()
        gmsh.option.setNumber("Mesh.Algorithm", alg2)
        gmsh.option.setNumber("Mesh.Algorithm3D", alg3)
        try:
            with native_output_to_log(log):
                gmsh.model.mesh.generate(2)
                diag["flat_triangles_fixed"] = _fix_flat_triangles(gmsh, groups, h_fine)
                gmsh.model.mesh.generate(3)
        except Exception as exc:  # gmsh raises a bare Exception
            raise _AttemptFailed(f"2D/3D algorithms {alg2}/{alg3}: {exc}") from exc
        tags, _ = gmsh.model.mesh.getElementsByType(4)
        if len(tags) == 0:
            raise _AttemptFailed(f"2D/3D algorithms {alg2}/{alg3}: no tetrahedra")
        q = gmsh.model.mesh.getElementQualities(tags, "minSICN")
        diag.update(
            algorithm2d=alg2,
            algorithm3d=alg3,
            min_sicn=float(q.min()),
            sicn_p01=float(np.quantile(q, 0.01)),
            n_tets=len(tags),
        )
        diag["mesh_s"] = time.perf_counter() - tm
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.SaveAll", 0)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    diag["total_s"] = time.perf_counter() - t0
    return diag


def _fix_flat_triangles(gmsh, groups: dict[str, list[int]], h_fine: float) -> int:
    """Re-mesh the surfaces if the surface mesh has a flat triangle; returns how many there were.

    gmsh puts at least two segments on every curve (``Mesh.MinimumCurveNodes`` = 3), also on the
    short edges where a narrow top land meets a face end (the face gear's top land is 0.8 mm wide
    at its outer end), and the surface mesher has been seen to close the face end there with a
    triangle on the three collinear nodes of that edge: HXT then stops on "two exactly
    self-intersecting facets" and the sector needed a second, slower attempt (13-15.6 s instead
    of 6.7 s for the face-gear sector). Such edges (top ∩ face end, shorter than ``h_fine``) get
    one segment and the surfaces are meshed again. Meshes without a flat triangle are untouched.
    """
    tags, _ = gmsh.model.mesh.getElementsByType(2)
    if len(tags) == 0:
        return 0
    flat = int(np.sum(np.asarray(gmsh.model.mesh.getElementQualities(tags, "minSICN")) < 1e-3))
    if flat == 0:
        return 0

    def curves(prefix: str) -> set[int]:
        faces = [(2, t) for name, ts in groups.items() if name.startswith(prefix) for t in ts]
        return {c for _, c in gmsh.model.getBoundary(faces, combined=False, oriented=False)}

    short = [
        c
        for c in sorted((curves("face_start") | curves("face_end")) & curves("top_"))
        if gmsh.model.occ.getMass(1, c) < h_fine
    ]
    log.info(
        "sector mesh: %d flat surface triangles; one segment on %d short edges", flat, len(short)
    )
    gmsh.model.mesh.clear()
    for c in short:
        gmsh.model.mesh.setTransfiniteCurve(c, 2)
    gmsh.model.mesh.generate(2)
    return flat


def _cad_deviation(gmsh, fr: SectorFrame, groups: dict[str, list[int]], n_teeth: int) -> float:
    """Max distance of a 6 × 6 parametric sample of every CAD flank face to the analytic flank."""
    worst = 0.0
    for side in ("drive", "coast"):
        xs, ks = [], []
        for j in range(n_teeth):
            for tag in groups[f"flank_{side}_{j}"]:
                lo, hi = gmsh.model.getParametrizationBounds(2, tag)
                s = np.linspace(0.0, 1.0, 6)
                uv = [
                    [lo[0] + a * (hi[0] - lo[0]), lo[1] + b * (hi[1] - lo[1])] for a in s for b in s
                ]
                xs.append(np.reshape(gmsh.model.getValue(2, tag, np.ravel(uv)), (-1, 3)))
                ks.append(np.full(len(xs[-1]), j - n_teeth // 2))
        d, _ = flank_distance(fr, side, np.concatenate(ks), np.vstack(xs))
        worst = max(worst, float(d.max()))
    return worst


# ------------------------------------------------------------------------------ public API
def sector_mesh(
    member: GeneratedMember,
    n_teeth: int = 3,
    level: int = 0,
    zone: Sequence[FlankZone] | None = None,
    rim_modules: float = 3.0,
    algorithm: int = 10,
    min_sicn: float = 0.03,
    fillet_mm: float | None = None,
    side: Side = "drive",
    refine: Sequence[FlankZone] = (),
    refine_mm: float | None = None,
) -> SectorMesh:
    """Mesh (or load from the cache) a sector of ``n_teeth`` teeth of ``member``.

    Parameters
    ----------
    member
        An ``InvoluteMember``, ``FaceGearMember`` or ``SpiralBevelMember``.
    n_teeth
        Teeth in the sector (the loaded analysis passes contact ratio + one neighbour each side).
    level
        Size knob 0 (coarse) … 4 (fine), see :data:`FINE`, :data:`COARSE`.
    zone
        Potential contact zone as flank boxes; default :func:`default_zone` (the whole working
        ``side`` flank of the centre teeth: what the loaded analysis meshes, so that a sector
        depends only on the member, the tooth count, the level and the side, never on where the
        mate sits). Fillets of the zone teeth are refined too.
    rim_modules
        Rim thickness below the root in modules (involute, spiral bevel).
    algorithm
        gmsh 3-D algorithm (10 HXT; 1 Delaunay is the automatic fallback).
    min_sicn
        Minimum acceptable element quality (signed inverse condition number).
    fillet_mm
        Element size (mm) on the fillets of the zone teeth, made coarser where their area would
        take more than :data:`FILLET_TRIANGLES` triangles (the size used is
        ``diagnostics["fillet_mm"]``); None: ``1.25 h_fine``. The root
        stress is read there (:mod:`fegear.fem.stress`; its convergence under this size:
        ``benchmarks/results/root_stress_refinement.md``).
    side
        Working flank side of the default zone (``"drive"`` or ``"coast"``).
    refine, refine_mm
        Flank boxes meshed at ``refine_mm`` (mm) besides the zone, the size growing away from
        them with the same slope (the full-FE decks of :mod:`fegear.export`: elements of a
        chosen size around the contact patches of one position); both enter the cache key
        only when given.

    Raises
    ------
    MeshError
        If the solid cannot be built, named, or meshed with acceptable quality.
    """
    if not isinstance(n_teeth, int) or not 1 <= n_teeth <= member.n_teeth // 2:
        raise InputError("mesh.n_teeth", n_teeth, f"an integer in 1..{member.n_teeth // 2}")
    mesh_sizes(1.0, level)
    # a member with flank modifications of some µm is meshed as its unmodified solid (optional
    # capability ``mesh_member()``, fegear.geometry.cylindrical): the same mesh and compliance
    # operator serve every modification; the gaps come from the exact modified surfaces
    if hasattr(member, "mesh_member"):
        member = member.mesh_member()
    fr = sector_frame(member, rim_modules)
    zone = tuple(default_zone(fr, n_teeth, side) if zone is None else zone)
    for z in zone:
        if not 0 <= z.tooth < n_teeth:
            raise InputError("mesh.zone.tooth", z.tooth, f"in 0..{n_teeth - 1}")
    params = {
        "member": repr(member),
        "family": fr.family,
        "n_teeth": n_teeth,
        "level": level,
        "zone": [[z.tooth, z.side, list(z.u), list(z.v)] for z in zone],
        "rim_modules": rim_modules,
        "algorithm": algorithm,
        "min_sicn": min_sicn,
    }
    if fillet_mm is not None:  # only when given: the contact meshes keep their cache keys
        if not (np.isfinite(fillet_mm) and fillet_mm > 0.0):
            raise InputError("mesh.fillet_mm", fillet_mm, "a finite size > 0 (mm)")
        params["fillet_mm"] = float(fillet_mm)
        params["fillet_triangles"] = FILLET_TRIANGLES
    refine = tuple(refine)
    if refine:
        if refine_mm is None or not (np.isfinite(refine_mm) and refine_mm > 0.0):
            raise InputError("refine_mm", refine_mm, "a finite size > 0 (mm) with refine boxes")
        for z in refine:
            if not 0 <= z.tooth < n_teeth:
                raise InputError("mesh.refine.tooth", z.tooth, f"in 0..{n_teeth - 1}")
        params["refine"] = [[z.tooth, z.side, list(z.u), list(z.v)] for z in refine]
        params["refine_mm"] = float(refine_mm)

    # the entry (fegear.store.cache.cached_record): the .msh, then the JSON of the diagnostics
    # that makes it valid; the key holds the code of fegear.mesh and fegear.geometry and gmsh's
    # version (fegear.store.cache.PRODUCERS["mesh"])
    def build(entry: Entry) -> dict[str, object]:
        diag: dict[str, object] = {}

        def write(tmp: Path) -> None:
            diag.update(
                _build(
                    fr,
                    n_teeth,
                    level,
                    zone,
                    algorithm,
                    min_sicn,
                    tmp,
                    fillet_mm,
                    (refine, refine_mm),
                )  # fmt: skip
            )

        entry.write(".msh", write)
        return diag

    entry, record, hit = cached_record("mesh", params, build)
    path = entry.path(".msh")
    diag = dict(record)
    diag["cache_hit"] = hit
    public = {k: v for k, v in params.items() if k != "member"}
    public["member_name"] = getattr(member, "name", "")
    public["h_fine_mm"], public["h_coarse_mm"] = mesh_sizes(fr.module, level)
    return load_sector_mesh(path, member=getattr(member, "name", ""), family=fr.family,
                            parameters=public, diagnostics=diag)  # fmt: skip


def _sector_from_fields(member, family, points, tets, boundaries, parameters, diagnostics, path):
    """The :class:`SectorMesh` of its pickled fields (:meth:`SectorMesh.__reduce__`)."""
    ro = MappingProxyType
    return SectorMesh(member, family, points, tets, ro(boundaries), ro(parameters),
                      ro(diagnostics), path)  # fmt: skip


def _msh_arrays(path: Path) -> tuple[Array, NDArray[np.int64], dict[str, NDArray[np.int64]]]:
    """Nodes, tets and named boundary triangles of a sector ``.msh`` (volume nodes only).

    Parsing the ASCII ``.msh`` (meshio) takes 0.2 s for a 40 000-node sector, most of it in the
    ``$Entities`` section; the arrays are kept next to it in ``<name>.arrays.npz`` (10 ms to read;
    written atomically, re-made if older than the ``.msh``).
    """
    side = path.with_name(path.stem + ".arrays.npz")
    if side.exists() and side.stat().st_mtime >= path.stat().st_mtime:
        with np.load(side) as z:
            bnd = {k[2:]: z[k] for k in z.files if k.startswith("b:")}
            return z["points"], z["tets"], bnd
    import meshio

    m = meshio.read(path, file_format="gmsh")  # no format guessing (meshio prints its misses)
    tets = np.asarray(m.cells_dict["tetra"], dtype=np.int64)
    names = {int(v[0]): k for k, v in m.field_data.items() if int(v[1]) == 2}
    tri = np.asarray(m.cells_dict.get("triangle", np.zeros((0, 3))), dtype=np.int64)
    phys = np.asarray(m.cell_data_dict["gmsh:physical"].get("triangle", []), dtype=np.int64)
    used = np.unique(tets)
    remap = -np.ones(len(m.points), dtype=np.int64)
    remap[used] = np.arange(len(used))
    bnd = {}
    for tag, name in names.items():
        t = remap[tri[phys == tag]]
        if np.any(t < 0):
            raise MeshError(f"boundary {name!r} references nodes outside the volume mesh")
        bnd[name] = t
    points = np.asarray(m.points[used], dtype=float)
    tets = remap[tets]

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez(fh, points=points, tets=tets, **{f"b:{k}": v for k, v in bnd.items()})

    try:
        atomic_write(side, write)
    except OSError as exc:  # a read-only cache still works, only slower
        log.debug("mesh arrays not cached (%s)", exc)
    return points, tets, bnd


def load_sector_mesh(
    path: Path | str,
    member: str = "",
    family: str = "",
    parameters: Mapping[str, object] | None = None,
    diagnostics: Mapping[str, object] | None = None,
) -> SectorMesh:
    """Read a sector ``.msh`` (linear tets + named triangle groups) into a :class:`SectorMesh`."""
    points, tets, bnd = _msh_arrays(Path(path))
    params = dict(parameters or {})
    params.setdefault("n_teeth", sum(1 for k in bnd if k.startswith("top_")))
    return SectorMesh(
        member=member,
        family=family,
        points=points,
        tets=tets,
        boundaries=MappingProxyType(bnd),
        parameters=MappingProxyType(params),
        diagnostics=MappingProxyType(dict(diagnostics or {})),
        path=Path(path),
    )
