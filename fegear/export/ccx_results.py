"""CalculiX results of an exported deck turned back into fegear's quantities (``docs/calculix.md``).

What is read:

- ``<job>.dat``: per contact pair the ``*CONTACT PRINT`` statistics of the last time (the total
  force and moment on the slave surface about the origin, the area and the normal force), and
  the ``*NODE PRINT`` displacements of the reference node (the Hertz scene's axle ``u_z``; a gear
  pair's ``ROT_GEAR``, whose translations are the rotations of the gear's rigid rim);
- ``<job>.frd``: the node coordinates and the contact stresses (``CONTACT`` block: ``CPRESS`` at
  the slave nodes) of the last increment;
- ``<job>.json``: the deck's record (:class:`fegear.export.deck.Deck`): pairs, slave faces,
  reference nodes, load, sign conventions.

Quantities (the same definitions as fegear's, so that the two compare):

- **Load share** of a pair = its torque on the gear axis / ``T2``. The deck's frame has the gear
  axis as ``z`` through the origin, so a pair's torque is ``−s₂ M_z`` of the force on its slave
  (pinion) flank (``s₂`` the gear's driving sense about ``z``; the force on the gear is the
  opposite one).
- **p_max**: the largest nodal ``CPRESS`` of a pair, and the recovered peak of
  :func:`fegear.mechanics.patch.measure_patch` on the nodal forces (``CPRESS`` times the node's
  tributary
  area on its slave faces: a third of each of the four straight sub-triangles of a six-node
  face); **patch semi-axes**: ``sqrt(5 λ)`` of the second moments of those nodal forces in the
  patch's tangent plane (:mod:`fegear.mechanics.patch`: exact for a Hertz distribution). For the
  Hertz quarter model the patch is mirrored about both symmetry planes first.
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

__all__ = ["CcxPair", "CcxResult", "read_results", "read_frd_contact", "read_dat"]

Array = NDArray[np.float64]
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
        Largest nodal contact pressure.
    p_peak_MPa
        Recovered peak pressure (:func:`fegear.mechanics.patch.measure_patch`).
    semi_major_mm, semi_minor_mm
        Equivalent-ellipse semi-axes of the patch (0 without contact).
    n_active
        Slave nodes with a positive pressure.
    nodal_force_N
        ``Σ CPRESS × tributary area``: the normal force again, from the pressures.
    edge_contact
        The patch reaches a border of either working flank (tip, fillet limit, face end).
    p_interior_MPa
        Largest nodal pressure away from the flank borders (fegear's rule,
        :mod:`fegear.ltca.edges`: farther than ``max(3 b, 2 h)`` from every loaded node on a
        border, ``b`` the patch's semi-minor axis, ``h`` the deck's contact element size);
        None when no loaded node is that far, or its pressure is below the pair's mean
        pressure (the tail of a patch sitting on the edge).
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
    """``(edge_contact, p_interior)`` of a pair (:class:`CcxPair`): loaded nodes within ``h / 2``
    of a border node are on the edge; the interior is farther than ``max(3 b, 2 h)`` from them.
    """
    from scipy.spatial import cKDTree

    ids = [n for n in nodes if press.get(n, 0.0) > 0.0 and weights.get(n, 0.0) > 0.0]
    if not ids:
        return False, None
    P = np.array([xyz[n] for n in ids])
    p = np.array([press[n] for n in ids])
    w = np.array([weights[n] for n in ids])
    on_edge = np.zeros(len(ids), dtype=bool)
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
        w = _tributary(faces[p["slave"]], xyz)
        nodes = np.unique(faces[p["slave"]])
        pmax, ppeak, sa, sb, nact = _patch(nodes, xyz, press, w, hertz and
                                           rec["modelled_fraction"] < 1.0)  # fmt: skip
        nodal = float(sum(press.get(n, 0.0) * w[n] for n in nodes if n in w))
        border = rec.get("edge_nodes", {}).get(p["slave"], [])
        edge, p_int = _interior(nodes, xyz, press, w, border, sb, float(rec["element_mm"]))
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
