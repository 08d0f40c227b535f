"""CalculiX results of an exported deck turned back into fegear's quantities (``docs/calculix.md``).

What is read:

- ``<job>.dat``: per contact pair the ``*CONTACT PRINT`` statistics of the last time (the total
  force and moment on the slave surface about the origin, the area and the normal force); the
  contact values at every active integration point of the slave faces (``*CONTACT PRINT`` with
  ``CSTR, CDIS, CELS``: slave element, face, pressure, overclosure, spring energy); and the
  ``*NODE PRINT`` displacements of the reference node (the Hertz scene's axle ``u_z``; a gear
  pair's ``ROT_GEAR``, whose translations are the rotations of the gear's rigid rim);
- ``<job>.frd``: the node coordinates and the nodal contact stresses (``CONTACT`` block:
  ``CPRESS`` at the slave nodes) of the last increment;
- ``<job>.json``: the deck's record (:class:`fegear.export.deck.Deck`): pairs, slave faces (as
  six-node faces and as element + face), reference nodes, load, penalty, sign conventions.

**The contact pressure.** CalculiX's face-to-face penalty contact (``TYPE=SURFACE TO
SURFACE``; CalculiX manual §6.7 "Boundary conditions", "Face-to-Face Penalty Contact") defines the
traction at integration points of the slave faces: slave and master faces are overlaid, their
common polygons triangulated, and each triangle integrated with a 7-point rule; a point is
active (gets a contact spring element) when it penetrates the master (``gencontelem_f2f.f``:
static steps create elements only where the clearance is negative). Its pressure is
``p = K δ`` (linear pressure-overclosure, ``δ`` the overclosure) and its area ``A = |x_ξ × x_η|
w`` (``w`` its weight); the pair's force ``*CONTACT PRINT CF`` is ``Σ p A n`` over the active
points (``printoutcontact.f``), and its printed area ``Σ A``. The points' positions are not
written, but each point's area is: the spring stores the energy ``E = A p² / (2 K)``
(``springforc_f2f.f``), so ``A = 2 K E / p²`` from the printed ``CSTR`` and ``CELS``
(:class:`ContactPoints`), and ``Σ p A`` is the pressure integral, equal to the contact force.

The nodal ``CPRESS`` of the ``.frd`` is not that field interpolated: ``extrapolatecontact.f``
fits, per slave face, the face's *active* points only (one point: its value at all three
corners; two: their mean; three: the plane through them; more: a least-squares plane, clipped
to the points' range), puts the mid-edge nodes at the mean of their corners, and averages the
faces at each node. A face partly in contact thus carries the pressure of its contact part over
its whole area: integrated with the face's shape functions (:func:`face_integral`: the
six-node triangle's ``N_i``, the geometry quadratic, Dunavant's 7-point rule), CalculiX's nodal
pressures exceed the force by about the ratio of the touched faces' area to the contact area
(1.31 on the Hertz scene at 0.45 mm, 1.08 at 0.24 mm; more where the patch is narrower than an
element). The reader therefore takes the force of each slave face from its points (``Σ p A``
over the face) and spreads it to the face's six nodes in proportion to the nodal ``CPRESS``
times the nodes' lumped areas (:func:`_spread`): nodal forces that sum to the contact force and
lie where CalculiX's pressure does. A node's **pressure** is its force / its tributary area (a
third of each of the four straight sub-triangles of a six-node face around it).

Quantities (the same definitions as fegear's, so that the two compare):

- **Load share** of a pair = its torque on the gear axis / ``T2``. The deck's frame has the gear
  axis as ``z`` through the origin, so a pair's torque is ``−s₂ M_z`` of the force on its slave
  (pinion) flank (``s₂`` the gear's driving sense about ``z``; the force on the gear is the
  opposite one).
- **Pressure integral** ``Σ p A`` of the active points (``ip_force_N``) against ``CF``'s normal
  force; the contact area ``Σ A``; the largest point pressure; CalculiX's nodal ``CPRESS``
  integrated (``nodal_force_N``) and its largest value, for the record.
- **p_max**: the largest nodal pressure of a pair, and the recovered peak of
  :func:`fegear.mechanics.patch.measure_patch` on the nodal forces; **patch semi-axes**:
  ``sqrt(5 λ)`` of the second moments of those nodal forces in the patch's tangent plane
  (:mod:`fegear.mechanics.patch`: exact for a Hertz distribution). For the Hertz quarter model
  the patch is mirrored about both symmetry planes first. A deck written without the points'
  print is read from the nodal ``CPRESS`` as CalculiX writes it.
- **Loaded TE** = unloaded TE (the TCA's, in the deck's record) − ``θ``, ``θ = −s₂ u_z`` of
  ``ROT_GEAR`` (the lag of the gear, rad; arcsec in the result): fegear's definition (the lag
  of member 2 is positive when the driven member falls behind, and a lag makes the TE more
  negative).
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from fegear.errors import FegearError, InputError
from fegear.mechanics.patch import measure_patch

__all__ = [
    "CcxPair",
    "CcxResult",
    "ContactPoints",
    "face_integral",
    "read_results",
    "read_frd_contact",
    "read_dat",
    "read_dat_points",
]

Array = NDArray[np.float64]
IntArr = NDArray[np.int64]
#: one arcsecond in rad
_ARCSEC = math.pi / (180.0 * 3600.0)


class CcxResultError(FegearError):
    """CalculiX results that are missing, incomplete or not those of the deck."""


@dataclass(frozen=True)
class CcxPair:
    """One contact pair's result (N, N·mm, MPa, mm).

    Attributes
    ----------
    k, j
        Pinion and gear tooth (gear pairs; 0, 0 for the Hertz scene).
    normal_force_N
        Contact normal force (CalculiX's ``*CONTACT PRINT`` statistics, compressive positive).
    torque_Nmm
        Torque of the pair on the gear axis (gear pairs; 0 for the Hertz scene).
    load_share
        ``torque_Nmm / T2`` (gear pairs), 1 for the Hertz scene.
    p_max_MPa
        Largest nodal contact pressure (nodal force / tributary area; the module's docstring).
    p_peak_MPa
        Recovered peak pressure (:func:`fegear.mechanics.patch.measure_patch`).
    semi_major_mm, semi_minor_mm
        Equivalent-ellipse semi-axes of the patch (0 without contact).
    n_active
        Slave nodes with a positive pressure.
    nodal_force_N
        CalculiX's nodal ``CPRESS`` integrated over the slave faces with their shape functions
        (:func:`face_integral`): above the force where faces are partly in contact.
    edge_contact
        The patch reaches a border of either working flank (tip, fillet limit, face end).
    p_interior_MPa
        Largest nodal pressure away from the flank borders (fegear's rule,
        :mod:`fegear.ltca.edges`: farther than ``max(3 b, 2 h)`` from every loaded node on a
        border, ``b`` the patch's semi-minor axis, ``h`` the deck's contact element size);
        None when no loaded node is that far, or its pressure is below the pair's mean
        pressure (the tail of a patch sitting on the edge).
    ip_force_N
        The pressure integral ``Σ p A`` over the active integration points (None for a deck
        without their print): the contact force.
    contact_area_mm2
        ``Σ A`` of the active integration points.
    p_max_points_MPa
        Largest pressure at an integration point.
    p_max_nodal_MPa
        Largest nodal ``CPRESS`` as CalculiX writes it.
    n_points
        Active integration points of the pair.
    """

    k: int
    j: int
    normal_force_N: float
    torque_Nmm: float
    load_share: float
    p_max_MPa: float
    p_peak_MPa: float
    semi_major_mm: float
    semi_minor_mm: float
    n_active: int
    nodal_force_N: float
    edge_contact: bool = False
    p_interior_MPa: float | None = None
    ip_force_N: float | None = None
    contact_area_mm2: float | None = None
    p_max_points_MPa: float | None = None
    p_max_nodal_MPa: float = 0.0
    n_points: int = 0


@dataclass(frozen=True)
class CcxResult:
    """A deck's CalculiX result.

    Attributes
    ----------
    kind
        ``"hertz_scene"`` or ``"gear_pair"``.
    pairs
        Per contact pair.
    applied
        The load the deck applies on the modelled part: force (N, Hertz scene) or ``T2`` (N·mm).
    balance
        Hertz scene: ``Σ normal forces / applied force``; gear pair: ``Σ torques / T2``.
    approach_mm
        Hertz scene: the axle's approach to the table (mm), else None.
    theta_rad, te_unloaded_arcsec, te_loaded_arcsec
        Gear pair: the gear's lag and the TE (None for the Hertz scene).
    warnings
        What changes the meaning of the numbers: a pair left out of the deck that the lag
        closes, a lag that closes separations beyond the deck's reach.
    """

    kind: str
    pairs: tuple[CcxPair, ...]
    applied: float
    balance: float
    approach_mm: float | None = None
    theta_rad: float | None = None
    te_unloaded_arcsec: float | None = None
    te_loaded_arcsec: float | None = None
    warnings: tuple[str, ...] = ()

    @property
    def p_max_MPa(self) -> float:
        """Largest nodal contact pressure over the pairs."""
        return max((p.p_max_MPa for p in self.pairs), default=0.0)

    def to_dict(self) -> dict:
        """JSON-able form."""
        return {
            "kind": self.kind,
            "applied": self.applied,
            "balance": self.balance,
            "approach_mm": self.approach_mm,
            "theta_rad": self.theta_rad,
            "te_unloaded_arcsec": self.te_unloaded_arcsec,
            "te_loaded_arcsec": self.te_loaded_arcsec,
            "p_max_MPa": self.p_max_MPa,
            "pairs": [p.__dict__.copy() for p in self.pairs],
            "warnings": list(self.warnings),
        }


_FLOAT = r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?"
#: A number of a contact statistics block: CalculiX 2.20 writes ``NaN`` for the centre, normal
#: and normal force of a pair out of contact (zero force, zero area).
_STAT = rf"(?:{_FLOAT}|NaN)"


def read_dat(path: str | Path) -> tuple[dict[tuple[str, str], dict[str, Array]], dict]:
    """The last-time blocks of a ``.dat``: ``({(slave, master): {"force", "moment", "area",
    "normal"}}, {set: {node: (3,) displacement}})`` (names upper case, as CalculiX writes them).
    A pair out of contact (zero area: CalculiX writes ``NaN`` for its normal force) reads as a
    normal force of 0."""
    text = Path(path).read_text(encoding="ascii", errors="replace")
    stats: dict[tuple[str, str], dict[str, Array]] = {}
    pat = re.compile(
        r"statistics for slave set (\S+), master set (\S+) and time\s+(\S+)\s+"
        r"total surface force \(fx,fy,fz\) and moment about the origin\s*\(mx,my,mz\)\s+"
        rf"((?:{_STAT}\s+){{6}})"
        # within this block only (a block of a pair out of contact must not reach the next)
        r"(?:(?!statistics for slave set).)*?"
        r"area,\s+normal force \(\+ = tension\) and shear force \(size\)\s+"
        rf"((?:{_STAT}\s+){{3}})",
        re.S,
    )
    for m in pat.finditer(text):
        v = np.array(m.group(4).split(), dtype=float)
        a = np.array(m.group(5).split(), dtype=float)
        if a[0] == 0.0:  # out of contact: no area, NaN normal force
            a = np.where(np.isfinite(a), a, 0.0)
        stats[(m.group(1), m.group(2))] = {
            "time": float(m.group(3)),
            "force": v[:3],
            "moment": v[3:],
            "area": a[0],
            "normal": a[1],
        }
    disp: dict[str, dict[int, Array]] = {}
    for m in re.finditer(
        r"displacements \(vx,vy,vz\) for set (\S+) and time\s+\S+\s*\n\s*\n((?:\s*\d+(?:\s+"
        + _FLOAT
        + r"){3}\s*\n)+)",
        text,
    ):
        rows = {}
        for line in m.group(2).strip().splitlines():
            f = line.split()
            rows[int(f[0])] = np.array(f[1:4], dtype=float)
        disp[m.group(1)] = rows  # the last time wins
    return stats, disp


def _frd_rows(lines: list[str], start: int) -> tuple[dict[int, list[float]], int]:
    """The ``-1`` rows of an ``.frd`` block from ``start`` to its ``-3``: {node: values}."""
    out: dict[int, list[float]] = {}
    i = start
    while i < len(lines) and not lines[i].startswith(" -3"):
        s = lines[i]
        if s.startswith(" -1"):
            node = int(s[3:13])
            body = s[13:].rstrip()
            out[node] = [float(body[c : c + 12]) for c in range(0, len(body), 12)]
        i += 1
    return out, i


def read_frd_contact(path: str | Path) -> tuple[dict[int, Array], dict[int, float]]:
    """Node coordinates and the last ``CONTACT`` block's ``CPRESS`` (MPa) of an ``.frd``."""
    lines = Path(path).read_text(encoding="ascii", errors="replace").splitlines()
    coords: dict[int, Array] = {}
    press: dict[int, float] = {}
    i = 0
    while i < len(lines):
        s = lines[i]
        if s.startswith("    2C"):
            rows, i = _frd_rows(lines, i + 1)
            coords = {n: np.array(v[:3]) for n, v in rows.items()}
        elif s.startswith(" -4  CONTACT"):
            names = []
            j = i + 1
            while lines[j].startswith(" -5"):
                names.append(lines[j].split()[1])
                j += 1
            rows, i = _frd_rows(lines, j)
            col = names.index("CPRESS")
            press = {n: v[col] for n, v in rows.items()}  # the last block wins
        i += 1
    if not coords:
        raise CcxResultError(f"{path}: no node block (2C)")
    return coords, press


#: Dunavant's degree-5 rule on the triangle (7 points): area coordinates and weights (sum 1)
_G7_A, _G7_B = 0.059715871789770, 0.470142064105115
_G7_C, _G7_D = 0.797426985353087, 0.101286507323456
_G7_L = np.array(
    [[1 / 3, 1 / 3, 1 / 3]]
    + [[_G7_A, _G7_B, _G7_B], [_G7_B, _G7_A, _G7_B], [_G7_B, _G7_B, _G7_A]]
    + [[_G7_C, _G7_D, _G7_D], [_G7_D, _G7_C, _G7_D], [_G7_D, _G7_D, _G7_C]]
)
_G7_W = np.array([0.225] + [0.132394152788506] * 3 + [0.125939180544827] * 3)


def _tri6(L: Array) -> tuple[Array, Array, Array]:
    """Six-node triangle at area coordinates ``L`` (3,): shape functions ``N`` (6,) and their
    derivatives along ``ξ = L2``, ``η = L3`` (``L1 = 1 − ξ − η``); nodes: corners 1, 2, 3, then
    mid-edges 1-2, 2-3, 3-1."""
    l1, l2, l3 = L
    N = np.array([l1 * (2 * l1 - 1), l2 * (2 * l2 - 1), l3 * (2 * l3 - 1),
                  4 * l1 * l2, 4 * l2 * l3, 4 * l3 * l1])  # fmt: skip
    dxi = np.array([1 - 4 * l1, 4 * l2 - 1, 0.0, 4 * (l1 - l2), 4 * l3, -4 * l3])
    deta = np.array([1 - 4 * l1, 0.0, 4 * l3 - 1, -4 * l2, 4 * l2, 4 * (l1 - l3)])
    return N, dxi, deta


def face_integral(faces: Array, xyz: Array, values: Array) -> Array:
    """``∫ v dA`` over each six-node face, ``v`` and the geometry interpolated with the face's
    quadratic shape functions (isoparametric), Dunavant's 7-point degree-5 rule.

    Parameters
    ----------
    faces
        ``(f, 6)`` rows into ``xyz``/``values``: corners, then mid-edges 1-2, 2-3, 3-1.
    xyz
        ``(n, 3)`` node coordinates.
    values
        ``(n,)`` nodal values (the field interpolated as ``v = Σ N_i v_i``).

    Returns
    -------
    ``(f,)`` integrals. Exact for a quadratic ``v`` on a flat face (then the corners' weights
    ``∫ N_i dA`` are 0 and the mid-edges' ``A / 3``: a field's integral comes from its mid-edge
    values alone).
    """
    f = np.asarray(faces, dtype=np.int64)
    X = np.asarray(xyz, dtype=float)[f]  # (f, 6, 3)
    V = np.asarray(values, dtype=float)[f]  # (f, 6)
    out = np.zeros(len(f))
    for L, w in zip(_G7_L, _G7_W, strict=True):
        N, dxi, deta = _tri6(L)
        t1 = np.einsum("i,fij->fj", dxi, X)
        t2 = np.einsum("i,fij->fj", deta, X)
        J = np.linalg.norm(np.cross(t1, t2), axis=1)  # |x_ξ × x_η|: dA = J dξ dη
        out += 0.5 * w * J * (V @ N)  # the reference triangle's area is 1/2
    return out


@dataclass(frozen=True)
class ContactPoints:
    """CalculiX's face-to-face contact values at the active integration points of the slave
    faces (``*CONTACT PRINT`` with ``CSTR, CDIS, CELS``), one entry per contact element.

    Attributes
    ----------
    time
        Total time of the block.
    element, face
        Slave element (1-based) and face (1-4) the point lies in.
    pressure
        Contact pressure (MPa, ``CSTR`` normal component: penalty × overclosure).
    overclosure
        Normal overclosure (mm, ``CDIS``'s normal component, as printed).
    energy
        Spring energy of the contact element (N·mm, ``CELS``).
    """

    time: float
    element: NDArray[np.int64]
    face: NDArray[np.int64]
    pressure: Array
    overclosure: Array
    energy: Array

    def areas(self, penalty: float) -> Array:
        """The slave area each point stands for (mm²): CalculiX's linear spring of slope
        ``penalty`` (MPa/mm) over the point's area ``A`` stores ``E = A p² / (2 K)``
        (``springforc_f2f.f``), hence ``A = 2 K E / p²``; 0 where ``p = 0``."""
        p = self.pressure
        with np.errstate(divide="ignore", invalid="ignore"):
            a = 2.0 * penalty * self.energy / (p * p)
        return np.where(p > 0.0, a, 0.0)


def read_dat_points(path: str | Path) -> ContactPoints | None:
    """The last ``CSTR``/``CDIS``/``CELS`` blocks of face-to-face contact in a ``.dat`` (rows
    ``slave element, face, values`` for all contact elements); None when the ``.dat`` has none.
    The three blocks list the same contact elements in the same order (checked)."""
    text = Path(path).read_text(encoding="ascii", errors="replace")
    heads = {
        "press": r"contact stress \(slave element\+face,press,tang1,tang2\)",
        "disp": r"relative contact displacement \(slave element\+face,normal,tang1,tang2\)",
        # CalculiX 2.20 writes "contact print energy (...)for all", later versions "spring"
        "energy": r"contact (?:spring|print) energy \(slave element\+face,energy\)",
    }
    last: dict[str, tuple[float, Array]] = {}
    for key, head in heads.items():
        pat = re.compile(
            head + r"\s*for all contact elements and time\s*(\S+)\s*\n\s*\n"
            r"((?:[ \t]*\d+[ \t]+\d+(?:[ \t]+" + _STAT + r")+[ \t]*\n)*)"
        )
        for m in pat.finditer(text):
            body = m.group(2).split("\n")
            rows = [r.split() for r in body if r.strip()]
            ncol = 5 if key != "energy" else 3
            arr = np.array([r[:ncol] for r in rows], dtype=float).reshape(-1, ncol)
            last[key] = (float(m.group(1)), arr)  # the last time wins
    if set(last) != set(heads):
        return None
    (tp, P), (td, D), (te, E) = last["press"], last["disp"], last["energy"]
    if not (tp == td == te) or not (len(P) == len(D) == len(E)):
        raise CcxResultError(f"{path}: contact point blocks of different times or lengths")
    ids = P[:, :2].astype(np.int64)
    if not (np.array_equal(ids, D[:, :2]) and np.array_equal(ids, E[:, :2])):
        raise CcxResultError(f"{path}: contact point blocks list different contact elements")
    return ContactPoints(
        time=tp, element=ids[:, 0], face=ids[:, 1], pressure=P[:, 2],
        overclosure=D[:, 2], energy=E[:, 2],
    )  # fmt: skip


def _tributary(faces: Array, xyz: dict[int, Array]) -> dict[int, float]:
    """Nodal areas of six-node faces ``(f, 6)`` (corners, mid-edges 1-2, 2-3, 3-1): a third of
    each of the four straight sub-triangles to each of its nodes."""
    w: dict[int, float] = {}
    for c0, c1, c2, m01, m12, m20 in faces.tolist():
        for tri in ((c0, m01, m20), (c1, m12, m01), (c2, m20, m12), (m01, m12, m20)):
            p = [xyz[n] for n in tri]
            a = 0.5 * float(np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0])))
            for n in tri:
                w[n] = w.get(n, 0.0) + a / 3.0
    return w


def _patch(nodes, xyz, press, weights, mirror: bool) -> tuple[float, float, float, float, int]:
    """``(p_max, p_peak, semi_major, semi_minor, n_active)`` of the nodes' pressures."""
    ids = [n for n in nodes if press.get(n, 0.0) > 0.0 and weights.get(n, 0.0) > 0.0]
    if not ids:
        return 0.0, 0.0, 0.0, 0.0, 0
    P = np.array([xyz[n] for n in ids])
    p = np.array([press[n] for n in ids])
    w = np.array([weights[n] for n in ids])
    if mirror:  # the Hertz quarter model: both symmetry planes x = 0, y = 0
        sx = np.array([1.0, -1.0, 1.0, -1.0])
        sy = np.array([1.0, 1.0, -1.0, -1.0])
        P = np.vstack([P * np.array([a, b, 1.0]) for a, b in zip(sx, sy, strict=True)])
        p, w = np.tile(p, 4), np.tile(w, 4)
    d = P - (w * p) @ P / np.sum(w * p)
    _, _, vt = np.linalg.svd(d * np.sqrt(w * p)[:, None], full_matrices=False)
    uv = d @ vt[:2].T  # the patch's tangent plane
    pm = measure_patch(uv, p * w, w)
    return float(p.max()), pm.p_peak, pm.semi_major, pm.semi_minor, len(ids)


def _interior(nodes, xyz, press, weights, border, b: float, h: float):
    """``(edge_contact, p_interior)`` of a pair (:class:`CcxPair`) from its nodal pressures:
    loaded nodes within ``h / 2`` of a border node are on the edge; the interior is farther than
    ``max(3 b, 2 h)`` from them."""
    ids = [n for n in nodes if press.get(n, 0.0) > 0.0 and weights.get(n, 0.0) > 0.0]
    if not ids:
        return False, None
    P = np.array([xyz[n] for n in ids])
    p = np.array([press[n] for n in ids])
    w = np.array([weights[n] for n in ids])
    return _interior_points(P, p, w, border, xyz, b, h)


def _interior_points(P, p, w, border, xyz, b: float, h: float):
    """``(edge_contact, p_interior)`` of loaded points ``P`` (pressures ``p``, areas ``w``):
    points within ``h / 2`` of a border node are on the edge; the interior is farther than
    ``max(3 b, 2 h)`` from them; None when no point is that far or its pressure is below the
    mean pressure."""
    from scipy.spatial import cKDTree

    if len(p) == 0:
        return False, None
    on_edge = np.zeros(len(p), dtype=bool)
    if len(border):
        B = np.array([xyz[n] for n in border if n in xyz])
        on_edge = cKDTree(B).query(P)[0] <= 0.5 * h
    if not on_edge.any():
        return False, float(p.max())
    far = cKDTree(P[on_edge]).query(P)[0] > max(3.0 * b, 2.0 * h)
    mean = float(np.sum(p * w) / np.sum(w))
    if not far.any() or p[far].max() < mean:
        return True, None
    return True, float(p[far].max())


def _local(faces: Array, xyz: dict[int, Array]) -> tuple[NDArray[np.int64], IntArr, Array]:
    """``(ids, local faces (f, 6), coordinates (n, 3))`` of a surface's six-node faces."""
    ids, inv = np.unique(np.asarray(faces, dtype=np.int64), return_inverse=True)
    return ids, inv.reshape(-1, 6), np.array([xyz[int(n)] for n in ids])


def _lumped(loc: IntArr, X: Array) -> Array:
    """``(f, 6)`` lumped nodal areas of each six-node face: a third of each of its four straight
    sub-triangles to each of the sub-triangle's nodes (positive, sum = the face's area)."""
    w = np.zeros(loc.shape)
    for tri in ((0, 3, 5), (1, 4, 3), (2, 5, 4), (3, 4, 5)):
        p = X[loc[:, tri]]
        a = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
        for t in tri:
            w[:, t] += a / 3.0
    return w


def _face_points(
    pts: ContactPoints, sides: Array, penalty: float
) -> tuple[Array, Array, Array, int]:
    """Per face of a slave surface (``sides`` ``(f, 2)``: element, face): ``(force, contact
    area, largest pressure)`` of its active integration points, and the number of points."""
    key = {(int(e), int(k)): i for i, (e, k) in enumerate(np.asarray(sides).tolist())}
    idx = np.array([key.get((int(e), int(k)), -1) for e, k in zip(pts.element, pts.face,
                                                                 strict=True)])  # fmt: skip
    mine = idx >= 0
    a = pts.areas(penalty)[mine]
    p = pts.pressure[mine]
    i = idx[mine]
    n = len(sides)
    force, area, pmax = np.zeros(n), np.zeros(n), np.zeros(n)
    np.add.at(force, i, p * a)
    np.add.at(area, i, a)
    np.maximum.at(pmax, i, p)
    return force, area, pmax, int(mine.sum())


def _spread(loc: IntArr, X: Array, p_nodes: Array, face_force: Array) -> Array:
    """Nodal forces ``(n,)`` carrying each face's force (from its integration points) to its
    six nodes in proportion to the lumped weights × the nodal pressures CalculiX extrapolated
    (the lumped weights alone where those are all zero): the forces sum to the faces'."""
    wf = _lumped(loc, X)
    g = wf * np.maximum(p_nodes[loc], 0.0)
    sg = g.sum(axis=1)
    share = np.where(sg[:, None] > 0.0, g / np.where(sg > 0.0, sg, 1.0)[:, None],
                     wf / wf.sum(axis=1)[:, None])  # fmt: skip
    out = np.zeros(len(X))
    np.add.at(out, loc.ravel(), (face_force[:, None] * share).ravel())
    return out


def read_results(job: str | Path) -> CcxResult:
    """The result of the CalculiX job ``job`` (path without extension: ``<job>.dat``,
    ``<job>.frd`` and the deck's ``<job>.json`` next to each other).

    Raises
    ------
    InputError
        No deck record.
    CcxResultError
        Missing or incomplete results (CalculiX did not finish the load step).
    """
    job = Path(job)
    if job.suffix in (".inp", ".dat", ".frd", ".json"):
        job = job.with_suffix("")

    def at(ext: str) -> Path:  # job names may hold dots (hertz_scene_0.3)
        return job.parent / (job.name + ext)

    rec_path = at(".json")
    if not rec_path.is_file():
        raise InputError("job", str(job), "a job exported by fegear (its .json record)")
    rec = json.loads(rec_path.read_text(encoding="utf-8"))
    for ext in (".dat", ".frd"):
        if not at(ext).is_file():
            raise CcxResultError(f"{at(ext)} missing: run `ccx -i {job.name}` first")
    stats, disp = read_dat(at(".dat"))
    xyz, press = read_frd_contact(at(".frd"))
    points = read_dat_points(at(".dat"))
    if points is not None and abs(points.time - 2.0) > 1e-6:
        points = None  # not the load step's
    faces = {k: np.asarray(v, dtype=np.int64) for k, v in rec["slave_faces"].items()}
    final_time = 2.0  # the load step ends at total time 2 (step 1: the preload)
    warnings: list[str] = []
    pairs = []
    hertz = rec["kind"] == "hertz_scene"
    for p in rec["pairs"]:
        key = (p["slave"].upper(), p["master"].upper())
        st = stats.get(key)
        if st is None or abs(st["time"] - final_time) > 1e-6:
            raise CcxResultError(
                f"{job}.dat: no contact statistics of {key} at the end of the load step "
                "(did CalculiX converge? see its .sta file)"
            )
        F6 = faces[p["slave"]]
        w = _tributary(F6, xyz)
        nodes = np.unique(F6)
        ids, loc, X = _local(F6, xyz)
        p_nodes = np.array([press.get(int(n), 0.0) for n in ids])
        nodal = float(face_integral(loc, X, p_nodes).sum())
        mirror = hertz and rec["modelled_fraction"] < 1.0
        border = rec.get("edge_nodes", {}).get(p["slave"], [])
        h = float(rec.get("patch_mm") or rec["element_mm"])  # the elements along the patch
        sides = rec.get("slave_sides", {}).get(p["slave"])
        pmax_nodal = float(max((press.get(int(n), 0.0) for n in nodes), default=0.0))
        if points is not None and sides is not None:
            # the pressure at CalculiX's integration points: each face's force to its nodes
            ff, fa, fp, npts = _face_points(points, sides, float(rec["penalty_MPa_per_mm"]))
            fn = _spread(loc, X, p_nodes, ff)
            eff = {int(n): f / w[int(n)] for n, f in zip(ids, fn, strict=True) if w[int(n)] > 0}
            pmax, ppeak, sa, sb, nact = _patch(nodes, xyz, eff, w, mirror)
            edge, p_int = _interior(nodes, xyz, eff, w, border, sb, h)
            ip_force, area, p_ip = float(ff.sum()), float(fa.sum()), float(fp.max(initial=0.0))
        else:  # a deck without the integration points' print: CalculiX's nodal pressures
            pmax, ppeak, sa, sb, nact = _patch(nodes, xyz, press, w, mirror)
            edge, p_int = _interior(nodes, xyz, press, w, border, sb, h)
            ip_force = area = p_ip = None
            npts = 0
        if hertz:
            torque, share = 0.0, 1.0
        else:
            torque = -rec["sense2"] * float(st["moment"][2])
            share = torque / rec["torque2_Nmm"]
        pairs.append(
            CcxPair(
                k=int(p.get("k", 0)),
                j=int(p.get("j", 0)),
                normal_force_N=-float(st["normal"]),
                torque_Nmm=torque,
                load_share=share,
                p_max_MPa=pmax,
                p_peak_MPa=ppeak,
                semi_major_mm=sa,
                semi_minor_mm=sb,
                n_active=nact,
                nodal_force_N=nodal,
                edge_contact=edge,
                p_interior_MPa=p_int,
                ip_force_N=ip_force,
                contact_area_mm2=area,
                p_max_points_MPa=p_ip,
                p_max_nodal_MPa=pmax_nodal,
                n_points=npts,
            )  # fmt: skip
        )
    if hertz:
        applied = float(rec["force_modelled_N"])
        u = disp.get("RP_AXLE", {}).get(int(rec["ref_nodes"]["RP_AXLE"]))
        if u is None:
            raise CcxResultError(f"{job}.dat: no displacement of RP_AXLE")
        return CcxResult(
            kind="hertz_scene",
            pairs=tuple(pairs),
            applied=applied,
            balance=sum(q.normal_force_N for q in pairs) / applied,
            approach_mm=-float(u[2]),
        )
    rot = disp.get("ROT_GEAR", {}).get(int(rec["ref_nodes"]["ROT_GEAR"]))
    if rot is None:
        raise CcxResultError(f"{job}.dat: no displacement of ROT_GEAR")
    theta = -rec["sense2"] * float(rot[2])
    for q in rec["left_out"]:
        if theta >= q["backlash_rad"]:
            warnings.append(
                f"pair ({q['k']}, {q['j']}) has no contact pair in the deck but the lag "
                f"{theta:.3g} rad closes its separation ({q['backlash_rad']:.3g} rad): export "
                "with a larger reach"
            )
    closes = theta * rec["lever_max_mm"]
    if closes > rec["reach_mm"]:
        warnings.append(
            f"the lag closes separations up to {1000 * closes:.1f} um, beyond the deck's reach "
            f"{1000 * rec['reach_mm']:.0f} um: the contact surfaces may cut the patches short; "
            "export with a larger reach"
        )
    te_u = float(rec["te_unloaded_arcsec"])
    return CcxResult(
        kind="gear_pair",
        pairs=tuple(pairs),
        applied=float(rec["torque2_Nmm"]),
        balance=sum(q.torque_Nmm for q in pairs) / float(rec["torque2_Nmm"]),
        theta_rad=theta,
        te_unloaded_arcsec=te_u,
        te_loaded_arcsec=te_u - theta / _ARCSEC,
        warnings=tuple(warnings),
    )
