"""gmsh meshes of the Hertz scene: a crowned roller pressed on a block.

Geometry (mm, fixed frame; the contact point at the origin, ``z`` the common normal, pointing
from the block into the roller):

- **Block**: the box ``[-L, L] × [-L, L] × [-H, 0]``; its top face ``z = 0`` is the contact face
  (physical group ``contact``), the bottom ``z = -H`` rests on a rigid table (``bottom``, clamped),
  the four sides are free.
- **Roller**: a barrel of axis ``(0, y, Rx)``: in the plane ``y = 0`` its section is the circle of
  radius ``Rx`` about the axis; its meridian (the profile in the plane ``x = 0``) is a circle of
  radius ``Ry`` through the origin with centre ``(0, 0, Ry)``, so the principal radii at the contact
  point are ``Rx`` (about ``y``) and ``Ry`` (about ``x``). Only the lower half (``z <= Rx``) is
  modelled: the axial plane ``z = Rx`` (``axle``) is clamped to a rigid axle that carries the load,
  as in a roller test rig; the barrel surface is ``contact``, the end faces ``y = ±l`` are free.

With ``symmetry = "quarter"`` only ``x >= 0, y >= 0`` of both bodies is meshed, and the planes
``x = 0`` (``sym_x``, ``u_x = 0``) and ``y = 0`` (``sym_y``, ``u_y = 0``) carry symmetry conditions;
the contact is symmetric about both, so this is exact and four times cheaper.

Size field: a gmsh ``Distance`` field from points sampled along the major axis of the expected
contact ellipse (on the contact face of each body), through a ``Threshold`` field: element size
``h_fine`` within ``r_fine`` of that segment, growing linearly to ``h_coarse`` over a transition of
``(h_coarse - h_fine) / growth``. Linear tetrahedra (gmsh order 1) are written: scikit-fem uses them
with ``ElementTetP2`` and keeps the named boundaries.
"""

from __future__ import annotations

import logging
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import skfem
from skfem.io.meshio import from_meshio

from fegear.errors import InputError, MeshError
from fegear.mesh.gmsh_session import initialize as initialize_gmsh
from fegear.store.cache import cached_file

__all__ = ["BodyMeshSpec", "mesh_block", "mesh_roller", "read_tet_mesh", "roller_height"]

log = logging.getLogger(__name__)

MESH_VERSION = "hertz_bodies_v2"


@dataclass(frozen=True)
class BodyMeshSpec:
    """Size and refinement parameters of one body's mesh (mm).

    Attributes
    ----------
    h_fine
        Element size in the refined zone.
    h_coarse
        Element size far from the contact.
    r_fine
        Radius of the refined zone around the refinement segment.
    segment_length
        Length of the refinement segment along ``y`` from the contact point (the major axis).
    growth
        Size growth per unit distance in the transition (dimensionless, e.g. 0.3).
    symmetry
        ``"quarter"`` or ``"none"``.
    """

    h_fine: float
    h_coarse: float
    r_fine: float
    segment_length: float
    growth: float = 0.3
    symmetry: str = "quarter"


def roller_height(x: np.ndarray, y: np.ndarray, Rx: float, Ry: float) -> np.ndarray:
    """Height ``z`` (mm) of the roller's barrel surface above the point ``(x, y)``.

    The meridian ``z_m(y) = Ry - sqrt(Ry² - y²)`` sets the section radius ``r(y) = Rx - z_m(y)``
    about the axis ``z = Rx``; then ``z = Rx - sqrt(r(y)² - x²)``. Exact, not the paraboloid.
    """
    zm = Ry - np.sqrt(Ry * Ry - y * y)
    r = Rx - zm
    return Rx - np.sqrt(r * r - x * x)


def _init(name: str) -> None:
    import gmsh

    initialize_gmsh()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)  # deterministic meshes (HXT is parallel)
    gmsh.model.add(name)


def _refine(spec: BodyMeshSpec, seg_points: np.ndarray) -> None:
    """Distance + Threshold size field around a polyline of sample points."""
    import gmsh

    occ = gmsh.model.occ
    tags = [occ.addPoint(*p) for p in seg_points]
    occ.synchronize()
    dist = gmsh.model.mesh.field.add("Distance")
    gmsh.model.mesh.field.setNumbers(dist, "PointsList", tags)
    thr = gmsh.model.mesh.field.add("Threshold")
    gmsh.model.mesh.field.setNumber(thr, "InField", dist)
    gmsh.model.mesh.field.setNumber(thr, "SizeMin", spec.h_fine)
    gmsh.model.mesh.field.setNumber(thr, "SizeMax", spec.h_coarse)
    gmsh.model.mesh.field.setNumber(thr, "DistMin", spec.r_fine)
    gmsh.model.mesh.field.setNumber(
        thr, "DistMax", spec.r_fine + (spec.h_coarse - spec.h_fine) / spec.growth
    )
    gmsh.model.mesh.field.setAsBackgroundMesh(thr)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", spec.h_coarse)


def _name_faces(groups: dict[str, list[int]], volume: int, vol_name: str) -> None:
    import gmsh

    for name, tags in groups.items():
        if not tags:
            raise MeshError(f"no face found for physical group {name!r}")
        gmsh.model.addPhysicalGroup(2, tags, name=name)
    gmsh.model.addPhysicalGroup(3, [volume], name=vol_name)


def _generate(path: Path) -> None:
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 10)  # HXT: several times faster than Delaunay
    gmsh.option.setNumber("Mesh.ElementOrder", 1)
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.model.mesh.generate(3)
    _, _, ntags = gmsh.model.mesh.getElements(3)
    if not ntags or len(ntags[0]) == 0:
        raise MeshError("gmsh produced no tetrahedra")
    gmsh.write(str(path))


def _classify(bounds: dict[str, tuple[str, float]], tol: float) -> dict[str, list[int]]:
    """Select boundary faces by the plane their bounding box lies in (geometric selection)."""
    import gmsh

    out: dict[str, list[int]] = {name: [] for name in bounds}
    out["other"] = []
    axis = {"x": (0, 3), "y": (1, 4), "z": (2, 5)}
    for dim, tag in gmsh.model.getEntities(2):
        bb = gmsh.model.getBoundingBox(dim, tag)
        for name, (ax, val) in bounds.items():
            lo, hi = axis[ax]
            if abs(bb[lo] - val) < tol and abs(bb[hi] - val) < tol:
                out[name].append(tag)
                break
        else:
            out["other"].append(tag)
    return out


def mesh_block(size: tuple[float, float], spec: BodyMeshSpec, path: Path) -> None:
    """Mesh the block ``[-L, L]² × [-H, 0]`` (or its quarter) into ``path`` (.msh)."""
    import gmsh

    L, H = size
    _init("block")
    try:
        occ = gmsh.model.occ
        if spec.symmetry == "quarter":
            vol = occ.addBox(0, 0, -H, L, L, H)
        else:
            vol = occ.addBox(-L, -L, -H, 2 * L, 2 * L, H)
        occ.synchronize()
        tol = 1e-6 * L
        planes = {"contact": ("z", 0.0), "bottom": ("z", -H)}
        if spec.symmetry == "quarter":
            planes |= {"sym_x": ("x", 0.0), "sym_y": ("y", 0.0)}
        faces = _classify(planes, tol)
        faces["free"] = faces.pop("other")
        _name_faces(faces, vol, "block")
        y0 = 0.0 if spec.symmetry == "quarter" else -spec.segment_length
        ys = np.linspace(
            y0,
            spec.segment_length,
            max(2, int(math.ceil((spec.segment_length - y0) / (0.5 * spec.h_fine))) + 1),
        )
        _refine(spec, np.column_stack([0 * ys, ys, 0 * ys]))
        _generate(path)
    finally:
        gmsh.finalize()


def mesh_roller(
    radii: tuple[float, float], half_length: float, spec: BodyMeshSpec, path: Path
) -> None:
    """Mesh the lower half of the barrel roller (or its quarter) into ``path`` (.msh)."""
    import gmsh

    Rx, Ry = radii
    lh = half_length
    if not lh < Ry:
        raise InputError("roller.half_length_mm", lh, f"< Ry = {Ry}")
    if not Ry - math.sqrt(Ry * Ry - lh * lh) < 0.5 * Rx:
        raise InputError("roller.half_length_mm", lh, "small enough that the crown drop < Rx/2")
    zm = Ry - math.sqrt(Ry * Ry - lh * lh)
    _init("roller")
    try:
        occ = gmsh.model.occ
        # Profile in the plane x = 0: the meridian arc, the two ends and the axis.
        p0 = occ.addPoint(0, -lh, zm)
        pc = occ.addPoint(0, 0, Ry)
        p1 = occ.addPoint(0, lh, zm)
        p2 = occ.addPoint(0, lh, Rx)
        p3 = occ.addPoint(0, -lh, Rx)
        arc = occ.addCircleArc(p0, pc, p1)
        l1 = occ.addLine(p1, p2)
        l2 = occ.addLine(p2, p3)
        l3 = occ.addLine(p3, p0)
        face = occ.addPlaneSurface([occ.addCurveLoop([arc, l1, l2, l3])])
        rev = occ.revolve([(2, face)], 0, 0, Rx, 0, 1, 0, 2 * math.pi)
        solid = [e for e in rev if e[0] == 3]
        occ.remove([(2, face)], recursive=True)  # the profile is not part of the body
        # Keep the lower half (and the quarter x, y >= 0 with symmetry).
        big = 4 * (Rx + lh)
        if spec.symmetry == "quarter":
            box = occ.addBox(0, 0, -1.0, big, big, Rx + 1.0)
        else:
            box = occ.addBox(-big / 2, -big / 2, -1.0, big, big, Rx + 1.0)
        cut, _ = occ.intersect(solid, [(3, box)])
        occ.remove([(0, pc)])
        occ.synchronize()
        vols = [t for d, t in cut if d == 3]
        if len(vols) != 1:
            raise MeshError(f"roller construction gave {len(vols)} volumes, expected 1")
        tol = 1e-6 * Rx
        planes = {"axle": ("z", Rx), "end": ("y", lh)}
        if spec.symmetry == "quarter":
            planes |= {"sym_x": ("x", 0.0), "sym_y": ("y", 0.0)}
        faces = _classify(planes, tol)
        if spec.symmetry != "quarter":
            faces["end"] += [
                t
                for t in faces["other"]
                if abs(gmsh.model.getBoundingBox(2, t)[1] + lh) < tol
                and abs(gmsh.model.getBoundingBox(2, t)[4] + lh) < tol
            ]
            faces["other"] = [t for t in faces["other"] if t not in faces["end"]]
        faces["contact"] = faces.pop("other")
        _name_faces(faces, vols[0], "roller")
        y0 = 0.0 if spec.symmetry == "quarter" else -spec.segment_length
        ys = np.linspace(
            y0,
            spec.segment_length,
            max(2, int(math.ceil((spec.segment_length - y0) / (0.5 * spec.h_fine))) + 1),
        )
        zs = roller_height(np.zeros_like(ys), ys, Rx, Ry)
        _refine(spec, np.column_stack([0 * ys, ys, zs]))
        _generate(path)
    finally:
        gmsh.finalize()


def cached_body_mesh(kind: str, geometry: dict, spec: BodyMeshSpec) -> tuple[Path, bool]:
    """Mesh a body through the content-hash cache; ``kind`` is ``"block"`` or ``"roller"``."""
    params = {"version": MESH_VERSION, "body": kind, "geometry": geometry, "spec": asdict(spec)}
    if kind == "block":
        return cached_file(
            "mesh",
            params,
            ".msh",
            lambda p: mesh_block((geometry["half_size"], geometry["height"]), spec, p),
        )
    if kind == "roller":
        return cached_file(
            "mesh",
            params,
            ".msh",
            lambda p: mesh_roller(tuple(geometry["radii"]), geometry["half_length"], spec, p),
        )
    raise InputError("kind", kind, "'block' or 'roller'")


def read_tet_mesh(path: Path) -> skfem.MeshTet:
    """Read a gmsh linear-tet mesh into scikit-fem with its named boundaries."""
    import meshio

    m = meshio.read(path, file_format="gmsh")  # no format guessing (meshio prints its misses)
    # gmsh also writes the nodes of geometric points that carry no element (the refinement
    # samples): keep only the nodes used by cells, renumbered.
    used = np.unique(np.concatenate([c.data.ravel() for c in m.cells]))
    new = np.full(m.points.shape[0], -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    m = meshio.Mesh(
        m.points[used],
        [meshio.CellBlock(c.type, new[c.data]) for c in m.cells],
        cell_data=m.cell_data,
        field_data=m.field_data,
    )
    mesh = from_meshio(m)
    if not isinstance(mesh, skfem.MeshTet) or mesh.t.shape[0] != 4:
        raise MeshError(f"{path}: expected linear tetrahedra")
    return mesh
