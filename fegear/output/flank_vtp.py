"""The flank views as VTK PolyData files: ``vtk/flank_<member>_<i>.vtp`` (written by
:func:`write_flank_vtp`, read back by :func:`read_flank_vtp`, with pyvista when it is installed,
else by the XML reader here): the loaded cells of one member at one position in its flank
coordinates (:mod:`fegear.output.flank_view`)."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fegear.output.flank_view import TIME_UNIT, FlankFrame, FlankPatch
from fegear.store.files import atomic_write

__all__ = ["read_flank_vtp", "write_flank_vtp"]

log = logging.getLogger(__name__)

Array = NDArray[np.float64]


def write_flank_vtp(path: Path, frame: FlankFrame, patch: FlankPatch, time_deg: float) -> Path:
    """One member's flank at one position as a ``.vtp`` (module docstring), atomically.

    Written as VTK XML PolyData in ASCII (:func:`_vtp_xml`, no VTK needed; values to full
    float64 precision), the cells ordered as VTK orders them: the outline (a line) first, then
    the loaded quads."""
    m = patch.quads.shape[0]
    k = frame.outline.shape[0]
    pts = np.zeros((k + 4 * m, 3))
    pts[:k, :2] = frame.outline
    pts[k:, :2] = patch.quads.reshape(-1, 2)
    cells = {
        "pressure_MPa": np.r_[0.0, patch.pressure_MPa],
        "force_N": np.r_[0.0, patch.force_N],
        "tooth": np.r_[-1, patch.tooth].astype(np.int32),
        "pair": np.r_[-1, patch.pair].astype(np.int32),
        "edge": np.r_[0, patch.edge.astype(np.int32)].astype(np.int32),
        "outline": np.r_[1, np.zeros(m, np.int32)].astype(np.int32),
    }
    fields = {
        "pinion_angle_deg": np.array([time_deg], dtype=np.float64),
        "time_unit": [TIME_UNIT],
        "member": [frame.member],
        "x_axis": [f"face: {frame.face_name}"],
        "y_axis": [f"profile: {frame.profile_name}"],
        "face_ends": list(frame.face_ends),
    }
    text = _vtp_xml(pts, np.arange(k), np.arange(k, k + 4 * m).reshape(m, 4), cells, fields)
    return atomic_write(path, lambda q: q.write_text(text, encoding="utf-8"))


def read_flank_vtp(path: Path) -> tuple[FlankFrame, FlankPatch, float]:
    """Read back :func:`write_flank_vtp`: ``(frame, patch, pinion angle deg)`` (the frame
    without its ``bounds``). Files of earlier versions (binary, written by pyvista) are read
    with pyvista (extra ``view``)."""
    points, lines, polys, cd, fd = _read_vtp(Path(path))
    member = str(fd["member"][0])
    outline = points[lines[0], :2]
    sel = np.asarray(cd["outline"]) == 0
    if polys.size == 0:
        patch = FlankPatch.empty(member)
    else:
        quads = points[polys][:, :, :2]
        patch = FlankPatch(
            member,
            quads,
            quads.mean(axis=1),
            np.asarray(cd["pressure_MPa"])[sel],
            np.asarray(cd["force_N"])[sel],
            np.asarray(cd["tooth"])[sel].astype(np.int64),
            np.asarray(cd["pair"])[sel].astype(np.int64),
            np.asarray(cd["edge"])[sel] != 0,
        )
    ends = tuple(str(x) for x in fd["face_ends"]) if "face_ends" in fd else ("", "")
    frame = FlankFrame(
        member,
        str(fd["x_axis"][0]).removeprefix("face: "),
        str(fd["y_axis"][0]).removeprefix("profile: "),
        outline,
        (ends + ("", ""))[:2],
    )
    return frame, patch, float(fd["pinion_angle_deg"][0])


#: VTK XML type names of the arrays written (VTK File Formats, "XML File Formats").
_VTK_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.int32): "Int32"}
_NUMPY_TYPES = {
    "Float64": np.float64,
    "Float32": np.float32,
    "Int32": np.int32,
    "Int64": np.int64,
    "UInt8": np.uint8,
}


def _ascii(values: np.ndarray) -> str:
    """Numbers as text: integers as they are, floats as Python's shortest round-trip repr."""
    return " ".join(map(repr, np.asarray(values).ravel().tolist()))


def _vtp_xml(
    points: Array,
    line: NDArray[np.int_],
    quads: NDArray[np.int_],
    cells: dict[str, np.ndarray],
    fields: dict[str, Any],
) -> str:
    """VTK XML PolyData (version 0.1, ``format="ascii"``) of one polyline ``line`` and the
    ``quads`` on ``points``, with per-cell ``cells`` (line first) and ``fields`` (float64 arrays
    or lists of strings; a string array in ASCII is its UTF-8 bytes as integers, each string
    ended by 0, as VTK's own writer does)."""

    def field(name: str, value: Any) -> str:
        if isinstance(value, np.ndarray):
            return (
                f'<DataArray type="{_VTK_TYPES[value.dtype]}" Name="{name}" '
                f'NumberOfTuples="{value.size}" format="ascii">{_ascii(value)}</DataArray>'
            )
        codes = [b for s in value for b in (*str(s).encode("utf-8"), 0)]
        return (
            f'<Array type="String" Name="{name}" NumberOfTuples="{len(value)}" '
            f'format="ascii">{" ".join(map(str, codes))}</Array>'
        )

    def cell_array(name: str, value: np.ndarray) -> str:
        return (
            f'<DataArray type="{_VTK_TYPES[value.dtype]}" Name="{name}" '
            f'format="ascii">{_ascii(value)}</DataArray>'
        )

    def topology(conn: np.ndarray, size: int) -> str:
        offsets = size * np.arange(1, conn.size // size + 1) if conn.size else conn
        return (
            f'<DataArray type="Int64" Name="connectivity" format="ascii">{_ascii(conn)}'
            '</DataArray>\n<DataArray type="Int64" Name="offsets" format="ascii">'
            f"{_ascii(offsets)}</DataArray>"
        )

    empty = (
        '<DataArray type="Int64" Name="connectivity" format="ascii"></DataArray>\n'
        '<DataArray type="Int64" Name="offsets" format="ascii"></DataArray>'
    )
    n_quads = quads.shape[0]
    return "\n".join(
        [
            '<?xml version="1.0"?>',
            '<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">',
            "<PolyData>",
            "<FieldData>",
            *(field(k, v) for k, v in fields.items()),
            "</FieldData>",
            f'<Piece NumberOfPoints="{points.shape[0]}" NumberOfVerts="0" NumberOfLines="1" '
            f'NumberOfStrips="0" NumberOfPolys="{n_quads}">',
            "<CellData>",
            *(cell_array(k, v) for k, v in cells.items()),
            "</CellData>",
            '<Points><DataArray type="Float64" Name="Points" NumberOfComponents="3" '
            f'format="ascii">{_ascii(points)}</DataArray></Points>',
            f"<Verts>{empty}</Verts>",
            f"<Lines>{topology(np.asarray(line), line.size)}</Lines>",
            f"<Strips>{empty}</Strips>",
            f"<Polys>{topology(np.asarray(quads).ravel(), 4)}</Polys>",
            "</Piece>",
            "</PolyData>",
            "</VTKFile>",
            "",
        ]
    )


def _read_vtp(path: Path) -> tuple[Array, NDArray[np.int_], NDArray[np.int_], dict, dict]:
    """``(points, line (one polyline's point indices, as a 1-row array), quads (q, 4), cell
    data, field data)`` of a flank ``.vtp``: the ASCII files :func:`_vtp_xml` writes, or through
    pyvista the binary ones of earlier versions."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    arrays = root.iter("DataArray")
    if root.get("type") != "PolyData" or any(a.get("format") != "ascii" for a in arrays):
        return _read_vtp_pyvista(path)

    def values(node: ET.Element) -> np.ndarray:
        return np.array((node.text or "").split(), dtype=_NUMPY_TYPES[node.get("type")])

    def strings(node: ET.Element) -> list[str]:
        codes = bytes(int(c) for c in (node.text or "").split())
        return [s.decode("utf-8") for s in codes.split(b"\0")[:-1]]

    piece = root.find("PolyData/Piece")
    fd: dict[str, Any] = {}
    for node in _children(root.find("PolyData/FieldData")):
        fd[node.get("Name")] = strings(node) if node.get("type") == "String" else values(node)
    cd = {node.get("Name"): values(node) for node in _children(piece.find("CellData"))}
    points = values(piece.find("Points/DataArray")).reshape(-1, 3)

    def cells(kind: str) -> list[np.ndarray]:
        conn = values(piece.find(f"{kind}/DataArray[@Name='connectivity']")).astype(np.int64)
        offsets = values(piece.find(f"{kind}/DataArray[@Name='offsets']")).astype(np.int64)
        return np.split(conn, offsets[:-1]) if offsets.size else []

    line = np.array(cells("Lines"))
    quads = np.array(cells("Polys"), dtype=np.int64).reshape(-1, 4)
    return points, line, quads, cd, fd


def _children(node: Any) -> list:
    """The child elements of an XML element, none for a missing one."""
    return [] if node is None else list(node)


def _read_vtp_pyvista(path: Path) -> tuple[Array, NDArray[np.int_], NDArray[np.int_], dict, dict]:
    """:func:`_read_vtp` of a binary ``.vtp`` (written by pyvista before fegear wrote ASCII)."""
    try:
        import pyvista as pv
    except ImportError as exc:
        raise ImportError(
            f"{path} is a binary VTK file of an earlier fegear version; reading it needs "
            "pyvista: pip install 'fegear[view]' (or run the case again)"
        ) from exc
    mesh = pv.read(str(path))
    k = int(mesh.lines[0])
    line = np.asarray(mesh.lines[1 : 1 + k], dtype=np.int64)[None, :]
    faces = np.asarray(mesh.faces)
    quads = faces.reshape(-1, 5)[:, 1:] if faces.size else np.zeros((0, 4), np.int64)
    fd = {name: mesh.field_data[name] for name in mesh.field_data}
    cd = {name: np.asarray(mesh.cell_data[name]) for name in mesh.cell_data}
    return np.asarray(mesh.points), line, quads, cd, fd
