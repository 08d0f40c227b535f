"""Abaqus/CalculiX input-deck pieces: ten-node tetrahedra from a linear mesh, element-face
surfaces, and the writer of the mesh part of a deck.

**C3D10 from linear tetrahedra.** fegear's meshes are linear tetrahedra (gmsh order 1) on which
scikit-fem puts P2 fields with straight edges. A C3D10 element is the same P2 tetrahedron; its
six mid-edge nodes are added here at the edge midpoints, in the node order of CalculiX and Abaqus
(CalculiX manual §6.2.1 "Ten-node tetrahedral element", the same as Abaqus C3D10)::

    corners 1 2 3 4, then the edges 1-2, 2-3, 3-1, 1-4, 2-4, 3-4

(gmsh and meshio number the last three 4-1, 4-3, 4-2: a tet10 read from gmsh needs nodes 9 and 10
swapped). Every element is oriented with a positive volume ``((x2 − x1) × (x3 − x1)) · (x4 − x1) >
0`` (corners 2 and 3 swapped where it is not). The nodes of chosen boundaries can be moved onto
their exact surface (``project``): on a curved contact face the quadratic element then
follows the surface to ``O(h³)`` instead of the chord's ``h² / (8 R)`` (0.9 µm for ``h`` = 0.3 mm
on ``R`` = 12 mm: as much as a gear pair's second-pair gap).

**Faces.** A surface is a list of (element, face) of the tetrahedra (manual §6.7, "Face
numbering for tetrahedral elements", the same in Abaqus): face 1 = 1-2-3, face 2 = 1-4-2,
face 3 = 2-4-3, face 4 = 3-4-1, i.e. the face opposite corner 4, 3, 1, 2.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from fegear.errors import MeshError

__all__ = ["Tet10Body", "tet10_body", "face_sides", "write_body", "fmt_float"]

Array = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: local corner pairs of the six mid-edge nodes, CalculiX/Abaqus order (nodes 5 … 10)
EDGES = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))
#: face number (1-based, CalculiX/Abaqus) of the face opposite local corner 0, 1, 2, 3
_FACE_OPPOSITE = np.array([3, 4, 2, 1])


@dataclass(frozen=True)
class Tet10Body:
    """One solid body as C3D10 elements (mm).

    Attributes
    ----------
    name
        Body name (element set ``E_<name>``, node set ``N_<name>``).
    nodes
        ``(n, 3)`` coordinates: the corners of the linear mesh first (same order), then the
        mid-edge nodes.
    elements
        ``(m, 10)`` 0-based node indices, CalculiX order, positive volume.
    faces
        ``{name: (k, 2)}`` element-face surfaces: 0-based element index and face number 1 … 4.
    n_corners
        Nodes of the linear mesh (``nodes[:n_corners]``).
    projected_mm
        ``{boundary: largest move}`` of the nodes put on their exact surface.
    """

    name: str
    nodes: Array
    elements: IntArray
    faces: Mapping[str, IntArray]
    n_corners: int
    projected_mm: Mapping[str, float] = field(default_factory=dict)

    def face_nodes(self, name: str, corners_only: bool = False) -> IntArray:
        """Sorted unique node indices of a surface (its six-node faces, or their corners)."""
        local = _FACE_LOCAL6[:, :3] if corners_only else _FACE_LOCAL6
        f = self.faces[name]
        return np.unique(self.elements[f[:, 0][:, None], local[f[:, 1] - 1]])

    def with_surface(self, name: str, of: str, mask: NDArray[np.bool_]) -> Tet10Body:
        """A copy with the surface ``name`` made of the faces of surface ``of`` where ``mask``."""
        faces = dict(self.faces)
        faces[name] = self.faces[of][np.asarray(mask, dtype=bool)]
        if len(faces[name]) == 0:
            raise MeshError(f"surface {name!r} of {self.name}: no face of {of!r} selected")
        return replace(self, faces=faces)

    def border_nodes(self, name: str) -> IntArray:
        """Sorted node indices on the border of a surface (the corners and mid-edge nodes of
        the face edges that belong to one of its faces only)."""
        t = self.face_triangles(name)
        e = np.concatenate([t[:, [0, 1, 3]], t[:, [1, 2, 4]], t[:, [2, 0, 5]]])
        key = np.sort(e[:, :2], axis=1)
        _, inv, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        return np.unique(e[count[inv.ravel()] == 1])

    def face_triangles(self, name: str) -> IntArray:
        """``(k, 6)`` node indices of a surface's faces: corners then mid-edges (outward order
        of CalculiX's face numbering)."""
        f = self.faces[name]
        return self.elements[f[:, 0][:, None], _FACE_LOCAL6[f[:, 1] - 1]]


#: local node indices (0-based) of faces 1-4: three corners, then the mid-edge nodes 1-2, 2-3, 3-1
#: of the face in that order
_FACE_LOCAL6 = np.array(
    [
        [0, 1, 2, 4, 5, 6],  # 1-2-3: edges 1-2 (5), 2-3 (6), 3-1 (7)
        [0, 3, 1, 7, 8, 4],  # 1-4-2: edges 1-4 (8), 4-2 (9), 2-1 (5)
        [1, 3, 2, 8, 9, 5],  # 2-4-3: edges 2-4 (9), 4-3 (10), 3-2 (6)
        [2, 3, 0, 9, 7, 6],  # 3-4-1: edges 3-4 (10), 4-1 (8), 1-3 (7)
    ]
)


def _oriented(points: Array, tets: IntArray) -> IntArray:
    """``tets`` with corners 2 and 3 swapped where the volume is negative."""
    p = points[tets]
    vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])
    if np.any(vol == 0.0):
        raise MeshError(f"{int(np.sum(vol == 0.0))} tetrahedra of zero volume")
    out = tets.copy()
    neg = vol < 0.0
    out[neg, 1], out[neg, 2] = tets[neg, 2], tets[neg, 1]
    return out


def _key(tri: IntArray, n: int) -> NDArray[np.int64]:
    """One int64 per unordered triangle of node indices below ``n``."""
    s = np.sort(tri, axis=1).astype(np.int64)
    return (s[:, 0] * n + s[:, 1]) * n + s[:, 2]


def face_sides(tets: IntArray, triangles: IntArray) -> IntArray:
    """``(k, 2)``: the element (0-based) and face number (1 … 4) of each boundary triangle of
    the oriented tetrahedra ``tets`` (``(m, 4)``, corners only).

    Raises
    ------
    MeshError
        A triangle that is no face of any tetrahedron.
    """
    n = int(tets.max()) + 1
    if n >= 2_000_000:
        raise MeshError(f"{n} nodes: too many for the face keys (at most 2 000 000)")
    opp = np.arange(4)
    faces = np.stack([np.delete(tets, c, axis=1) for c in opp], axis=1)  # (m, 4, 3)
    keys = _key(faces.reshape(-1, 3), n)
    order = np.argsort(keys, kind="stable")
    sk = keys[order]
    want = _key(np.asarray(triangles), n)
    pos = np.searchsorted(sk, want)
    pos = np.minimum(pos, sk.size - 1)
    ok = sk[pos] == want
    if not np.all(ok):
        raise MeshError(f"{int(np.sum(~ok))} boundary triangles are not element faces")
    flat = order[pos]
    elem, corner = np.divmod(flat, 4)
    return np.column_stack([elem, _FACE_OPPOSITE[corner]]).astype(np.int64)


def tet10_body(
    name: str,
    points: Array,
    tets: IntArray,
    boundaries: Mapping[str, IntArray],
    project: Mapping[str, Callable[[Array], Array]] | None = None,
) -> Tet10Body:
    """The C3D10 body of a linear tetrahedral mesh (module docstring).

    Parameters
    ----------
    name
        Body name.
    points, tets
        ``(n, 3)`` mm and ``(m, 4)`` 0-based corners.
    boundaries
        ``{name: (k, 3) triangles}`` of the linear mesh: the surfaces of the deck.
    project
        ``{boundary: f}`` with ``f((q, 3) points) -> (q, 3)`` their closest points on the exact
        surface: the corners of that boundary's triangles (the CAD surface gmsh meshed is within
        its tolerance of the exact one; a modified flank differs from the solid meshed by its
        modification), then their mid-edge nodes are moved there.
    """
    points = np.array(points, dtype=float)
    moved: dict[str, float] = {}
    for bname, f in (project or {}).items():  # the corners first: the mid-edge nodes follow
        k = np.unique(np.asarray(boundaries[bname]))
        new = np.asarray(f(points[k]), dtype=float)
        moved[bname] = float(np.max(np.linalg.norm(new - points[k], axis=1))) if len(k) else 0.0
        points[k] = new
    tets = _oriented(points, np.asarray(tets, dtype=np.int64))
    m = len(tets)
    pairs = np.stack([tets[:, list(e)] for e in EDGES], axis=1).reshape(-1, 2)
    lo, hi = np.minimum(pairs[:, 0], pairs[:, 1]), np.maximum(pairs[:, 0], pairs[:, 1])
    n = len(points)
    ekey = lo * n + hi
    uniq, inv = np.unique(ekey, return_inverse=True)
    a, b = np.divmod(uniq, n)
    mids = 0.5 * (points[a] + points[b])
    for bname, f in (project or {}).items():
        tri = np.asarray(boundaries[bname])
        e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        k = np.searchsorted(uniq, np.min(e, axis=1) * n + np.max(e, axis=1))
        k = np.unique(k)
        new = np.asarray(f(mids[k]), dtype=float)
        if len(k):
            moved[bname] = max(moved[bname], float(np.max(np.linalg.norm(new - mids[k], axis=1))))
        mids[k] = new
    elements = np.empty((m, 10), dtype=np.int64)
    elements[:, :4] = tets
    elements[:, 4:] = n + inv.reshape(m, 6)
    faces = {k: face_sides(tets, np.asarray(v)) for k, v in boundaries.items()}
    return Tet10Body(
        name=name,
        nodes=np.vstack([points, mids]),
        elements=elements,
        faces=faces,
        n_corners=n,
        projected_mm=moved,
    )


def fmt_float(x: float) -> str:
    """A float as the deck writes it: 12 significant digits (``repr`` of a short value)."""
    return f"{x:.12g}" if abs(x) >= 1e-300 or x == 0.0 else "0"


def write_body(
    out: io.TextIOBase,
    body: Tet10Body,
    node_offset: int,
    element_offset: int,
    transform: Array | None = None,
) -> None:
    """Write ``*NODE``, ``*ELEMENT`` and the ``*SURFACE`` cards of ``body``.

    Nodes are numbered ``node_offset + 1 …``, elements ``element_offset + 1 …`` (1-based in the
    deck); ``transform`` (4, 4) places the body's coordinates in the deck's frame. Surfaces are
    named ``S_<body>_<boundary>`` (upper case in the deck's eyes: CalculiX and Abaqus names are
    case-insensitive).
    """
    x = body.nodes
    if transform is not None:
        x = x @ transform[:3, :3].T + transform[:3, 3]
    out.write(f"*NODE, NSET=N_{body.name}\n")
    ids = np.arange(1, len(x) + 1) + node_offset
    pts = zip(ids, x, strict=True)
    out.write("".join(f"{i}, {a:.12g}, {b:.12g}, {c:.12g}\n" for i, (a, b, c) in pts))
    out.write(f"*ELEMENT, TYPE=C3D10, ELSET=E_{body.name}\n")
    eids = np.arange(1, len(body.elements) + 1) + element_offset
    e = body.elements + 1 + node_offset
    rows = zip(eids, e.tolist(), strict=True)
    out.write("".join(f"{i}, " + ", ".join(map(str, r)) + "\n" for i, r in rows))
    for name, f in body.faces.items():
        out.write(f"*SURFACE, NAME=S_{body.name}_{name}, TYPE=ELEMENT\n")
        sides = zip(f[:, 0] + 1 + element_offset, f[:, 1], strict=True)
        out.write("".join(f"{el}, S{k}\n" for el, k in sides))
