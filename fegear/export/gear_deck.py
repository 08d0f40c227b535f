"""A gear pair at one mesh position as a CalculiX/Abaqus deck (``docs/calculix.md``).

The same problem as fegear's loaded analysis at that position:

- **Bodies.** Both members' sectors of the loaded analysis (:func:`fegear.mesh.sector.sector_mesh`:
  the tooth count of the cycle's contact zone, the case's mesh level on the whole working flank
  of the loaded teeth), with boxes around the pairs that can touch at this position
  (:func:`fegear.ltca.zone.contact_zone` of this position within ``reach_mm``) meshed at
  ``element_mm``; as C3D10 elements (:mod:`fegear.export.inp`).
- **Frame.** The gear's axis frame at the position: the gear axis is the deck's ``z`` axis through
  the origin, the pinion placed by the assembly (installation errors included) at the TCA's
  closed position (the first pair touching, the others open by their separations).
- **Supports.** The pinion's bore (face gear: blank base) and both sector cuts fixed, as fegear
  clamps them (the pinion held); the gear's bore/base and cuts made one rigid body
  (``*RIGID BODY``) with the reference node ``RP_GEAR`` on the axis, held, and the rotation
  node ``ROT_GEAR`` (CalculiX: its translations are the body's rotations), free only in ``z``:
  fegear's rigid rotation ``θ`` of member 2. (CalculiX 2.20's ``*KINEMATIC`` coupling carries
  translations only, DOFs 1-3.)
- **Load.** The resisting torque ``T2`` on ``ROT_GEAR`` against the gear's driving sense, in the
  two steps of :mod:`fegear.export.deck` (a small prescribed lag that closes the first pair by
  about a micrometre, then the torque).
- **Contact.** One ``*CONTACT PAIR`` per tooth pair that can touch (a valid pair whose
  separation at this position is below ``reach_mm``): the pinion's working flank (slave)
  against the gear's (master), penalty, frictionless.
- **Output.** The contact force and moment per pair (``*CONTACT PRINT``; the deck's frame puts
  the moment about ``z`` equal to the pair's torque on the gear axis), the displacement of
  ``ROT_GEAR`` (the rotation ``θ``), the displacements (``*NODE FILE``) and the contact
  pressures (``*CONTACT FILE``). :mod:`fegear.export.ccx_results` reads them.

Pairs whose separation exceeds ``reach_mm`` are not in contact pairs: the deck's record keeps
their angular separations, and the reader flags a solved lag that would have closed one.
"""

from __future__ import annotations

import io
import logging
import math

import numpy as np

from fegear.errors import InputError
from fegear.export.deck import (
    DEFAULT_PENALTY_E,
    IP_PRINT,
    Deck,
    boundary_lines,
    contact_cards,
    element_sides,
    material_cards,
    nset_lines,
)
from fegear.export.flank_projection import flank_projection
from fegear.export.inp import Tet10Body, tet10_body, write_body
from fegear.geometry.transforms import inverse
from fegear.ltca import LTCAOptions
from fegear.ltca.analysis import cycle_zone
from fegear.ltca.cycle import cycle_tca
from fegear.ltca.zone import contact_zone
from fegear.mesh.sector import FlankZone, sector_mesh
from fegear.mesh.sector_geometry import sector_frame
from fegear.pipeline.pair import build_pair
from fegear.tca.results import ARCSEC

__all__ = ["gear_deck", "patch_boxes", "DEFAULT_REACH_MM", "DEFAULT_PATCH_GAP_MM"]

log = logging.getLogger(__name__)

#: Separation (mm) below which a pair is given a contact pair and refined elements.
DEFAULT_REACH_MM = 0.03
#: Separation (mm) that bounds the patch strips of a locally refined deck (:func:`patch_boxes`).
DEFAULT_PATCH_GAP_MM = 0.01
#: Lag of the first step: closes the first pair by this much (mm) at its contact point.
PRELOAD_MM = 0.001


def _sector_body(
    name: str, member, sector, side: str, boxes, element_mm: float, project: bool
) -> Tet10Body:
    """The C3D10 body of a sector (member frame): surfaces ``flank_<t>`` (the working flank of
    each sector tooth ``t`` with a box in ``boxes``), ``zone_<t>`` (its faces within
    ``2 element_mm`` of the boxes: the contact surfaces) and ``support`` (bore or base plus both
    sector cuts)."""
    from scipy.spatial import cKDTree

    b = sector.boundaries
    c = sector.centre_tooth
    teeth = sorted({z.tooth for z in boxes})
    support = "base" if "base" in b else "bore"
    bnd = {f"flank_{t}": b[f"flank_{side}_{t}"] for t in teeth}
    bnd["support"] = np.vstack([b[support], b["cut_left"], b["cut_right"]])
    proj = None
    if project:
        proj = {f"flank_{t}": flank_projection(member, side, t - c) for t in teeth}
    body = tet10_body(name, sector.points, sector.tets, bnd, proj)
    fr = sector_frame(member.mesh_member() if hasattr(member, "mesh_member") else member)
    for t in teeth:
        pts = []
        for z in boxes:
            if z.tooth == t:
                U, V = np.meshgrid(np.linspace(*z.u, 25), np.linspace(*z.v, 25), indexing="ij")
                pts.append(fr.tooth_points(side, t - c, U, V).reshape(-1, 3))
        P = np.vstack(pts)
        spacing = float(np.max(cKDTree(P).query(P, k=2)[0][:, 1]))
        cen = body.nodes[body.face_triangles(f"flank_{t}")[:, :3]].mean(axis=1)
        near = cKDTree(P).query(cen)[0] <= spacing + 2.0 * element_mm
        body = body.with_surface(f"zone_{t}", f"flank_{t}", near)
    return body


def patch_boxes(pos, pairs, bounds1, bounds2, side1: str, side2: str, c: int, gap_mm: float,
                margin_mm: float):  # fmt: skip
    """Flank boxes ``(pinion, gear)`` around the unloaded contact patch of each pair of
    ``pairs``: fegear's TCA separation ``s`` on the pair's grid (pinion cells ``u × v``), per
    ``v`` column a parabola ``s = s₀ + κ (u − u*)²`` through the column's smallest valid
    sample and its two neighbours, the strip ``|u − u*| ≤ sqrt((gap − s₀) / κ)`` (where
    ``s₀ < gap``) widened by ``margin_mm`` on each side; on the gear the same strip's points
    (the grid's ``gear_uv``, interpolated along ``u``). The flank parameters need not be
    lengths (a spiral bevel's ``u`` is a fraction of the working height): the margin is turned
    into each parameter's units with the grid's cell points (mm per unit of ``u`` and ``v``
    there). The loaded patch lies within the separations that the elastic approach closes
    (5-15 µm on these gears): a gap of 10 µm holds it with the Hertz line's half-width about
    twice over (FZG's pitch point: ±0.36 mm against fegear's semi-minor axis 0.19 mm)."""

    def clip(t, side, u, v, b):
        u = (max(u[0], b.u_fillet), min(u[1], b.u_tip))
        v = (max(v[0], b.v_start), min(v[1], b.v_end))
        u, v = (float(u[0]), float(u[1])), (float(v[0]), float(v[1]))
        return FlankZone(t, side, u, v) if u[1] > u[0] and v[1] > v[0] else None

    z1, z2 = [], []
    for g in pos.grids:
        if not any((g.k, g.j) == tuple(int(x) for x in q) for q in pairs):
            continue
        k, j = int(g.k), int(g.j)
        u, v = np.asarray(g.u, dtype=float), np.asarray(g.v, dtype=float)
        P, G = np.asarray(g.points, dtype=float), np.asarray(g.gear_uv, dtype=float)
        du = (u[-1] - u[0]) / max(len(u) - 1, 1)
        dv = (v[-1] - v[0]) / max(len(v) - 1, 1)

        def scales(i0, i1, col, g=g, u=u, v=v, P=P, G=G):
            """Margins' units at rows i0 < i1 of column col: ``(pinion u, pinion v, gear u,
            gear v)`` per mm (the flank's length along each parameter, from the cell points)."""
            lu = float(np.linalg.norm(P[i1, col] - P[i0, col]))
            out = [abs(u[i1] - u[i0]) / lu, None, abs(G[i1, col, 0] - G[i0, col, 0]) / lu, None]
            i = (i0 + i1) // 2
            cc = [x for x in (col - 1, col, col + 1) if 0 <= x < len(v) and g.valid[i, x]]
            if len(cc) >= 2:
                lv = float(np.linalg.norm(P[i, cc[-1]] - P[i, cc[0]]))
                out[1] = abs(v[cc[-1]] - v[cc[0]]) / lv
                out[3] = abs(G[i, cc[-1], 1] - G[i, cc[0], 1]) / lv
            else:  # a lone column: v taken as the same scale as u
                out[1], out[3] = out[0], out[2]
            return out

        strips = []  # (column, u_lo, u_hi, margins in u, v, gear u, gear v)
        for col in range(len(v)):
            ok = np.flatnonzero(g.valid[:, col])
            if len(ok) < 3:
                continue
            s = g.separation[ok, col]
            i = int(np.clip(np.argmin(s), 1, len(ok) - 2))
            uu, ss = u[ok[i - 1 : i + 2]], s[i - 1 : i + 2]
            kappa, b, s0 = np.polyfit(uu - uu[1], ss, 2)
            if kappa <= 0.0:
                continue
            ustar = uu[1] - b / (2.0 * kappa)
            smin = s0 - b * b / (4.0 * kappa)
            if smin >= gap_mm or not (u[ok[0]] - du <= ustar <= u[ok[-1]] + du):
                continue
            w = math.sqrt((gap_mm - smin) / kappa)
            m = [margin_mm * f for f in scales(ok[i - 1], ok[i + 1], col)]
            strips.append((col, ustar - w, ustar + w, *m))

        def gear_at(cc, us, g=g, u=u):  # the gear's (u, v) of pinion column cc at u values us
            ok = np.flatnonzero(g.valid[:, cc])
            return (np.interp(us, u[ok], g.gear_uv[ok, cc, 0]),
                    np.interp(us, u[ok], g.gear_uv[ok, cc, 1]))  # fmt: skip

        for col, lo, hi, mu, mv, gmu, gmv in strips:
            vc = (v[col] - 0.5 * dv - mv, v[col] + 0.5 * dv + mv)
            z = clip(k + c, side1, (lo - mu, hi + mu), vc, bounds1)
            if z is not None:
                z1.append(z)
            mid = 0.5 * (lo + hi)
            gu, gv = gear_at(col, np.array([lo, mid, hi]))
            # the column's gear extent in v: to half way to its neighbours'
            near = [cc for cc in (col - 1, col + 1)
                    if 0 <= cc < len(v) and np.sum(g.valid[:, cc]) >= 2]  # fmt: skip
            step = max((abs(float(gear_at(cc, np.array([mid]))[1][0]) - float(gv[1]))
                        for cc in near), default=abs(dv))  # fmt: skip
            z = clip(j + c, side2, (gu.min() - gmu, gu.max() + gmu),
                     (gv.min() - 0.5 * step - gmv, gv.max() + 0.5 * step + gmv),
                     bounds2)  # fmt: skip
            if z is not None:
                z2.append(z)
    return tuple(z1), tuple(z2)


def gear_deck(
    case,
    phi1: float,
    element_mm: float,
    name: str | None = None,
    reach_mm: float = DEFAULT_REACH_MM,
    penalty_E: float = DEFAULT_PENALTY_E,
    level: int | None = None,
    project: bool = True,
    patch_mm: float | None = None,
    patch_gap_mm: float = DEFAULT_PATCH_GAP_MM,
) -> Deck:
    """The deck of ``case`` (a :class:`~fegear.io.gear_case.GearCase`) at the pinion angle
    ``phi1`` (rad, the convention of fegear's cycle: position ``i`` of ``n`` is
    ``−π/N1 + 2π i / (N1 n)``).

    Parameters
    ----------
    element_mm
        Element size (mm) around the pairs that can touch.
    name
        Job name (default ``<case>_phi<φ1 in millidegrees>``).
    reach_mm
        Separation (mm) below which a pair can touch under the load: it gets a contact pair and
        refined elements (the lag of the solution is checked against the pairs left out).
    penalty_E
        Penalty slope in Young's moduli per mm.
    level
        Mesh level of the sectors away from the refined boxes (default: the case's).
    project
        Move the mid-edge nodes of the working flanks onto the exact (unmodified) flank
        (:mod:`fegear.export.flank_projection`).
    patch_mm
        Element size (mm) along each pair's contact patch (:func:`patch_boxes`: the flank
        strip where the TCA separation is below ``patch_gap_mm``, two elements wider each
        side), the mesh growing from it with the sector's slope to the level's size on the
        rest of the flank: these boxes are then the refined ones, not the reach's (``element_mm``
        still sets how far around the reach's boxes the contact surfaces extend). None: the
        reach's boxes at ``element_mm``.
    patch_gap_mm
        The separation (mm) that bounds the patch strips.

    Raises
    ------
    InputError
        A bad size, or a position without contact.
    """
    if not (isinstance(element_mm, (int, float)) and math.isfinite(element_mm) and element_mm > 0):
        raise InputError("element_mm", element_mm, "a finite size > 0 (mm)")
    if not (math.isfinite(reach_mm) and reach_mm > 0):
        raise InputError("reach_mm", reach_mm, "a finite separation > 0 (mm)")
    lvl = case.level if level is None else level
    pair = build_pair(case)
    opt = LTCAOptions(
        n_positions=case.n_positions, level=lvl, n_teeth=case.n_teeth, E_MPa=case.E_MPa,
        nu=case.nu, backend=case.backend, fidelity="fe", **case.contact.as_dict(),
    )  # fmt: skip
    tca, positions, _ = cycle_tca(pair.pinion, pair.gear, pair.assembly, opt, np.array([phi1]))
    pos = positions[0]
    if not pos.has_contact:
        raise InputError("phi1", phi1, "a position where the flanks meet (no contact there)")
    asm = tca.asm
    n = cycle_zone(pair.pinion, pair.gear, pair.assembly, opt).n_teeth
    c = n // 2
    here = contact_zone([pos], tca.fm1.bounds, tca.fm2.bounds, asm.side1, asm.side2, reach_mm,
                        n_teeth=n, exact=True)  # fmt: skip
    if len(here.pairs) == 0:
        raise InputError("reach_mm", reach_mm, "a reach that holds the pair in contact")
    fine, h_fine = (here.pinion, here.gear), float(element_mm)
    if patch_mm is not None:
        if not (isinstance(patch_mm, (int, float)) and math.isfinite(patch_mm) and patch_mm > 0):
            raise InputError("patch_mm", patch_mm, "a finite size > 0 (mm)")
        fine = patch_boxes(pos, here.pairs, tca.fm1.bounds, tca.fm2.bounds, asm.side1, asm.side2,
                           c, patch_gap_mm, 2.0 * patch_mm)  # fmt: skip
        if not fine[0] or not fine[1]:
            raise InputError("patch_gap_mm", patch_gap_mm, "a gap that the pairs' patches reach")
        h_fine = float(patch_mm)
    sectors = [
        sector_mesh(m, n, lvl, side=s, refine=z, refine_mm=h_fine)
        for m, s, z in ((pair.pinion, asm.side1, fine[0]), (pair.gear, asm.side2, fine[1]))
    ]
    h = float(element_mm)
    pin = _sector_body("pinion", pair.pinion, sectors[0], asm.side1, here.pinion, h, project)
    gear = _sector_body("gear", pair.gear, sectors[1], asm.side2, here.gear, h, project)
    # the deck's frame: the gear's axis frame at this position (gear axis = z through 0)
    M1 = asm.placement1(pos.phi1)
    D2 = asm.placement2(pos.phi2) @ inverse(asm.const2)
    T1 = inverse(D2) @ M1
    T2 = asm.const2
    torque = float(case.torque2_Nmm)
    s2 = int(asm.sense2)
    # the first pair's moment arm (mm/rad) at its closest point: the preload lag
    ip = int(pos.contact_pair)
    g0 = next(g for g in pos.grids if (g.k, g.j) == tuple(int(x) for x in pos.pairs[ip]))
    i0 = np.unravel_index(np.argmin(np.where(g0.valid, g0.separation, np.inf)), g0.valid.shape)
    h0 = float(g0.h[i0])
    theta_pre = PRELOAD_MM / h0
    # the largest moment arm of the pairs' cells within the reach: a lag θ closes separations
    # up to θ · lever (the reader checks it against the reach)
    near = [g for g in pos.grids if any((g.k, g.j) == tuple(int(x) for x in q) for q in here.pairs)]
    lever = max(float(np.max(g.h[g.valid & (g.separation <= reach_mm)], initial=0.0)) for g in near)

    out = io.StringIO()
    out.write("*HEADING\n")
    out.write(
        f"fegear {case.kind} pair {case.name!r}: phi1 {math.degrees(pos.phi1):.6g} deg, "
        f"T2 {torque / 1000:g} N.m, contact elements {element_mm:g} mm"
        + ("" if patch_mm is None else f", {patch_mm:g} mm along the patches")
        + "\n"
    )
    out.write(
        "** units: mm, N, MPa. Written by fegear (fegear.export.gear_deck). Frame: the gear\n"
        "** axis frame at this position (gear axis = z through the origin).\n"
    )
    write_body(out, pin, 0, 0, T1)
    n1 = len(pin.nodes)
    write_body(out, gear, n1, len(pin.elements), T2)
    n_nodes = n1 + len(gear.nodes)
    rp = n_nodes + 1
    rot = rp + 1
    out.write(f"*NODE, NSET=RP_GEAR\n{rp}, 0, 0, 0\n")
    out.write(f"*NODE, NSET=ROT_GEAR\n{rot}, 0, 0, 0\n")
    out.write(nset_lines("PINION_HELD", pin.face_nodes("support") + 1))
    out.write(material_cards("STEEL", case.E_MPa, case.nu, ["E_pinion", "E_gear"]))
    rim = gear.face_nodes("support") + 1 + n1
    out.write(nset_lines("GEAR_RIM", rim))
    out.write(f"*RIGID BODY, NSET=GEAR_RIM, REF NODE={rp}, ROT NODE={rot}\n")
    pairs, slave_faces, slave_sides, edge_nodes = [], {}, {}, {}
    for k, j in here.pairs:
        k, j = int(k), int(j)
        s, m = f"S_pinion_zone_{k + c}", f"S_gear_zone_{j + c}"
        pairs.append({"k": k, "j": j, "slave": s, "master": m})
        slave_faces[s] = (pin.face_triangles(f"zone_{k + c}") + 1).tolist()
        slave_sides[s] = element_sides(pin, f"zone_{k + c}", 0)
        # the borders of both working flanks: a patch reaching one is an edge contact
        edge_nodes[s] = np.concatenate(
            [pin.border_nodes(f"flank_{k + c}") + 1, gear.border_nodes(f"flank_{j + c}") + 1 + n1]
        ).tolist()
    out.write(contact_cards([(p["slave"], p["master"]) for p in pairs], penalty_E * case.E_MPa))
    fixed = [("PINION_HELD", 1, 3, None), ("RP_GEAR", 1, 3, None), ("ROT_GEAR", 1, 2, None)]
    out.write("*STEP\n*STATIC\n")
    out.write(boundary_lines(fixed + [("ROT_GEAR", 3, 3, -s2 * theta_pre)], op_new=False))
    out.write(IP_PRINT)  # CalculiX: energy output (CELS) must start in the first step
    out.write("*END STEP\n")
    out.write("*STEP, INC=200\n*STATIC\n1.0, 1.0, 1e-05, 1.0\n")
    out.write(boundary_lines(fixed, op_new=True))
    out.write(f"*CLOAD\nROT_GEAR, 3, {-s2 * torque:.12g}\n")
    out.write("*NODE PRINT, NSET=ROT_GEAR\nU\n")
    out.write("*NODE FILE\nU\n")
    for p in pairs:
        out.write(f"*CONTACT PRINT, SLAVE={p['slave']}, MASTER={p['master']}\nCF\n")
    out.write(IP_PRINT)
    out.write("*CONTACT FILE\nCDIS, CSTR\n")
    out.write("*END STEP\n")
    # pairs left out of the contact pairs: their angular separation (a lag beyond it closes them)
    left = [
        {"k": int(k), "j": int(j), "backlash_rad": float(b), "modelled_teeth": bool(
            0 <= k + c < n and 0 <= j + c < n)}
        for (k, j), ok, b in zip(pos.pairs, pos.pair_valid, pos.backlash_rad, strict=True)
        if ok and not any(p["k"] == k and p["j"] == j for p in pairs)
    ]  # fmt: skip
    record = {
        "kind": "gear_pair",
        "case": case.name,
        "case_kind": case.kind,
        "phi1_rad": float(pos.phi1),
        "phi2_rad": float(pos.phi2),
        "te_unloaded_arcsec": float(pos.te_arcsec),
        "torque2_Nmm": torque,
        "sense2": s2,
        "element_mm": float(element_mm),
        "patch_mm": None if patch_mm is None else float(patch_mm),
        "patch_gap_mm": float(patch_gap_mm),
        "patch_boxes": None
        if patch_mm is None
        else {
            "pinion": [[z.tooth, *z.u, *z.v] for z in fine[0]],
            "gear": [[z.tooth, *z.u, *z.v] for z in fine[1]],
        },  # fmt: skip
        "reach_mm": float(reach_mm),
        "level": int(lvl),
        "n_teeth": int(n),
        "penalty_MPa_per_mm": penalty_E * case.E_MPa,
        "preload_rad": theta_pre,
        "pairs": pairs,
        "slave_faces": slave_faces,
        "slave_sides": slave_sides,
        "edge_nodes": edge_nodes,
        "lever_max_mm": lever,
        "left_out": left,
        "ref_nodes": {"RP_GEAR": rp, "ROT_GEAR": rot},
        "n_nodes": n_nodes,
        "n_elements": len(pin.elements) + len(gear.elements),
        "dofs": 3 * n_nodes,
        "projected_mm": {
            **{f"pinion:{k}": v for k, v in pin.projected_mm.items()},
            **{f"gear:{k}": v for k, v in gear.projected_mm.items()},
        },  # fmt: skip
        "mesh_cache_hit": all(bool(sm.diagnostics.get("cache_hit")) for sm in sectors),
        "arcsec_rad": ARCSEC,
    }
    job = name or f"{case.name}_phi{round(math.degrees(pos.phi1) * 1000):+d}"
    log.info("gear deck %s: %d nodes, %d C3D10, %d contact pairs", job, n_nodes,
             record["n_elements"], len(pairs))  # fmt: skip
    return Deck(name=job, text=out.getvalue(), record=record)
