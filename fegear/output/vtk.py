"""The VTK files of a loaded gear run: the sectors, the contact cells and the flank views per
position, and ``cycle.pvd``, the collection ParaView plays (the files and their fields:
:mod:`fegear.output.gear_output`)."""

from __future__ import annotations

import base64
import math
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from fegear.geometry.transforms import apply_points, apply_vectors
from fegear.output.flank_view import TIME_UNIT
from fegear.output.flank_vtp import write_flank_vtp
from fegear.pipeline.run import GearRun
from fegear.store.files import atomic_write

__all__ = ["write_gear_vtk", "write_pvd"]


#: VTK XML type names of the arrays written (VTK File Formats, "XML File Formats").
_VTU_TYPES = {
    np.dtype(np.float64): "Float64",
    np.dtype(np.int32): "Int32",
    np.dtype(np.int64): "Int64",
}
#: VTK cell type numbers of the cells written.
_VTK_CELLS = {"tetra": 10, "quad": 9}


def _binary_array(name: str, values: np.ndarray) -> str:
    """One ``DataArray`` in VTK's inline ``binary`` format: base64 of a UInt32 byte count (the
    default ``header_type``) followed by the raw little-endian values, as meshio writes it."""
    a = np.ascontiguousarray(values)
    a = a.astype(a.dtype.newbyteorder("<"), copy=False)
    raw = a.tobytes()
    comps = f' NumberOfComponents="{a.shape[1]}"' if a.ndim == 2 else ""
    code = base64.b64encode(np.uint32(len(raw)).tobytes() + raw).decode("ascii")
    return (
        f'<DataArray type="{_VTU_TYPES[a.dtype]}" Name="{name}"{comps} format="binary">\n'
        f"{code}\n</DataArray>\n"
    )


def _vtu_text(
    points: np.ndarray,
    kind: str,
    cells: np.ndarray,
    point_data: dict[str, np.ndarray],
    cell_data: dict[str, np.ndarray],
    time_deg: float | None,
) -> str:
    """A VTK XML UnstructuredGrid (binary, uncompressed) of one block of ``cells`` (``(m, k)``
    vertex indices of the VTK cell ``kind``) on ``points``, with ``point_data`` and
    ``cell_data``, and the field data ``pinion_angle_deg`` when ``time_deg`` is given (ASCII,
    before the piece). The layout of meshio 5.3's VTU writer (which wrote these files before;
    readers see the same bytes in every array), built as one string and written once: meshio's
    writer, the read-back and the rewrite for the field data were a third of the VTK time."""
    conn = np.asarray(cells)
    m, k = conn.shape
    parts = [
        '<?xml version="1.0"?>\n'
        '<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
        "<!--This file was written by fegear-->\n<UnstructuredGrid>\n"
    ]
    if time_deg is not None:
        parts.append(
            "<FieldData>\n"
            '<DataArray type="Float64" Name="pinion_angle_deg" NumberOfTuples="1" '
            f'format="ascii">\n{time_deg!r}\n</DataArray>\n'
            "</FieldData>\n"
        )
    parts += [
        f'<Piece NumberOfPoints="{len(points)}" NumberOfCells="{m}">\n<Points>\n',
        _binary_array("Points", points),
        "</Points>\n<Cells>\n",
        _binary_array("connectivity", conn.ravel()),
        _binary_array("offsets", k * np.arange(1, m + 1, dtype=conn.dtype)),
        _binary_array("types", np.full(m, _VTK_CELLS[kind], dtype=np.int64)),
        "</Cells>\n",
    ]
    for tag, data in (("PointData", point_data), ("CellData", cell_data)):
        if data:
            parts += [f"<{tag}>\n", *(_binary_array(n, v) for n, v in data.items()), f"</{tag}>\n"]
    parts.append("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    return "".join(parts)


def _write_vtu(path: Path, mesh: tuple, time_deg: float | None = None) -> Path:
    """Write ``mesh`` (the arguments of :func:`_vtu_text` but the time) as a VTU file,
    atomically, with the field data ``pinion_angle_deg`` (the time of the series) when
    ``time_deg`` is given. Binary, uncompressed: zlib took 45 of the 55 ms of a seed face-gear
    sector file (25 positions, two members: 2 s of a warm run) for files 3 times smaller."""
    text = _vtu_text(*mesh, time_deg)
    return atomic_write(path, lambda q: q.write_text(text, encoding="ascii"))


def _cell_quads(cells) -> np.ndarray:
    """``(n, 4, 3)`` corners of the cells from their 2 × 2 Gauss points (bilinear
    extrapolation from the Gauss points at ``±1/√3`` to the corners at ``±1``)."""
    q = cells.quad_points.reshape(-1, 2, 2, 3)
    c = q.mean(axis=(1, 2))
    order = [(0, 0), (1, 0), (1, 1), (0, 1)]
    return np.stack([c + math.sqrt(3.0) * (q[:, a, b] - c) for a, b in order], axis=1)


def _contact_mesh(pos) -> tuple:
    """The contact cells of a position as the quads of :func:`_vtu_text` (none without
    contact) with their cell data."""
    if not pos.cells:
        return np.zeros((0, 3)), "quad", np.zeros((0, 4), dtype=np.int64), {}, {}
    corners = np.concatenate([_cell_quads(c) for c in pos.cells])
    n = corners.shape[0]
    data = {
        "force_N": pos.solution.force,
        "pressure_MPa": np.concatenate(pos.pressure),
        "area_mm2": np.concatenate([c.area for c in pos.cells]),
        "gap_mm": np.concatenate([c.gap for c in pos.cells]),
        "active": pos.solution.active.astype(np.int32),
        "edge": np.concatenate([c.boundary for c in pos.cells]).astype(np.int32),
        "pair": np.concatenate([np.full(c.n, i, np.int32) for i, c in enumerate(pos.cells)]),
        "pinion_tooth": np.concatenate([np.full(c.n, c.k, np.int32) for c in pos.cells]),
        "gear_tooth": np.concatenate([np.full(c.n, c.j, np.int32) for c in pos.cells]),
    }
    cells = np.arange(4 * n).reshape(n, 4)
    return corners.reshape(-1, 3), "quad", cells, {}, {k: np.asarray(v) for k, v in data.items()}


def _node_pressure(mf, i: int, pos, X: np.ndarray) -> np.ndarray:
    """Pressure of the contact cell over each working-flank vertex (fixed-frame points ``X``)."""
    from scipy.spatial import cKDTree

    p = np.zeros(X.shape[0])
    if not pos.cells:
        return p
    gear = mf.name == "gear"
    centers = np.concatenate(
        [c.centers + (c.gap[:, None] * c.normals if gear else 0.0) for c in pos.cells]
    )
    half = np.concatenate([np.full(c.n, 0.5 * float(np.hypot(*c.cell_mm))) for c in pos.cells])
    pres = np.concatenate(pos.pressure)
    d, j = cKDTree(centers).query(X[mf.flank_nodes])
    ok = d <= 1.05 * half[j]
    p[mf.flank_nodes[ok]] = pres[j[ok]]
    # Cells much smaller than the elements (hybrid: 0.03 mm across a patch between vertices
    # 2 mm apart) lie over no vertex: each loaded cell also raises its nearest flank vertex to
    # its pressure, so the patch shows on the sector mesh (the exact field is in the cells).
    loaded = pres > 0
    if loaded.any():
        _, v = cKDTree(X[mf.flank_nodes]).query(centers[loaded])
        np.maximum.at(p, mf.flank_nodes[v], pres[loaded])
    return p


def _member_mesh(mf, i: int, pos) -> tuple:
    """One member's sector at position ``i`` as the tets of :func:`_vtu_text` with their point
    data (fixed frame)."""
    M = mf.placements[i]
    X = apply_points(M, mf.points)
    u = apply_vectors(M, mf.displacement[i])
    p = _node_pressure(mf, i, pos, X)
    data = {"displacement_mm": u, "pressure_MPa": p, "in_contact": (p > 0).astype(np.int32)}
    if mf.max_principal is not None:
        data["max_principal_stress_MPa"] = mf.max_principal[i]
        data["min_principal_stress_MPa"] = mf.min_principal[i]
        data["von_mises_MPa"] = mf.von_mises[i]
    return X, "tetra", mf.tets, data, {}


def write_pvd(path: Path, entries: list[tuple[float, int, str]], parts: str = "") -> Path:
    """A ParaView collection: ``entries`` of ``(time, part, relative file)``; the time is the
    pinion angle in degrees (said in a comment, with ``parts``, the names of the parts)."""
    lines = [
        '<?xml version="1.0"?>',
        f"<!-- fegear: timestep = {TIME_UNIT}" + (f"; {parts}" if parts else "") + " -->",
        '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
        "  <Collection>",
    ]
    for t, part, f in entries:
        lines.append(
            f'    <DataSet timestep="{t:.12g}" group="" part="{part}" file={quoteattr(f)}/>'
        )
    lines += ["  </Collection>", "</VTKFile>", ""]
    text = "\n".join(lines)
    return atomic_write(path, lambda q: q.write_text(text, encoding="utf-8"))


def write_gear_vtk(out: Path, run: GearRun, views) -> list[Path]:
    """Write the VTK series of a loaded run into ``out/vtk`` and ``out/cycle.pvd``; ``views``:
    its flank views (:class:`fegear.output.gear_output.FlankViews`). Returns the paths."""
    vtk = out / "vtk"
    paths, entries = [], []
    names = [mf.name for mf in run.members] + ["contact cells"]
    flanks = bool(views.patches) and bool(run.members)  # the fidelities with contact cells
    if flanks:
        names += [f"{m} flank view" for m in views.frames]
    for i, pos in enumerate(run.cycle.positions):
        t = math.degrees(pos.phi1)
        for part, mf in enumerate(run.members):
            name = f"{mf.name}_{i:03d}.vtu"
            paths.append(_write_vtu(vtk / name, _member_mesh(mf, i, pos), t))
            entries.append((t, part, f"vtk/{name}"))
        name = f"contact_cells_{i:03d}.vtu"
        empty = not pos.cells  # meshio cannot read an empty VTU back: no field data there
        paths.append(_write_vtu(vtk / name, _contact_mesh(pos), None if empty else t))
        entries.append((t, len(run.members), f"vtk/{name}"))
        if flanks:
            for k, (member, frame) in enumerate(views.frames.items()):
                name = f"flank_{member}_{i:03d}.vtp"
                paths.append(write_flank_vtp(vtk / name, frame, views.patches[i][member], t))
                entries.append((t, len(run.members) + 1 + k, f"vtk/{name}"))
    parts = "parts: " + ", ".join(f"{k} {n}" for k, n in enumerate(names))
    paths.append(write_pvd(out / "cycle.pvd", entries, parts))
    return paths
