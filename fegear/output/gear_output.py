"""Outputs of a gear-case run (DESIGN §10): ``summary.json``, VTK time series, PNGs.

Files written to the output folder (each one atomically: complete or absent):

- ``summary.json`` — inputs, per position (pinion angle, unloaded/loaded TE, status, pairs with
  force, load share, p_max, patch axes, contact point in the fixed frame, edge flag and edges),
  cycle values, solver residuals, timings, versions, units. Headlines mean what they say
  (:func:`fegear.pipeline.run.report`): ``cycle.te_pp_loaded_arcsec`` over the usable positions
  only (``te_pp_loaded_positions_used``; ``excluded_positions`` with their reasons: contact
  lost, or degenerate: a loaded patch the cells do not resolve), ``cycle.p_max_MPa`` the largest
  pressure away from the flank edges, ``cycle.p_max_edge_MPa`` the edge value beside it
  (``p_max_edge_at``: position, pair, edges named), and ``null`` with a ``*_reason`` where
  nothing physical can be reported, never 0. ``pattern`` (per member: the bearing pattern's
  centre and extent on its flank, :class:`fegear.output.flank_view.PatternCentre`) and ``cache``
  (the cache folder, the artefacts read from it and those built). The engagement checks made
  before the analysis:
  ``cycle.tip_clearance_mm``, ``cycle.unloaded_interior_contact_fraction`` (the contact ratio
  when below 1), ``cycle.positions_without_unloaded_contact``; one pair's unloaded contact over
  its whole contact interval (:func:`fegear.tca.path.contact_path`):
  ``cycle.contact_ratio_unloaded`` (the interval over the angular pitch),
  ``cycle.path_length_mm`` (on the gear flank), ``cycle.path_length_in_space_mm``,
  ``cycle.path_ends`` (what ends it: ``"gear:tip"``, ``"pinion:tip"``, ``"transfer"``, …),
  ``cycle.path_pinion_angles_deg``. The unloaded contact ellipses (every fidelity,
  :mod:`fegear.tca.ellipse`): ``positions[i].contact_ellipse`` (the TCA's pair in contact: its
  principal relative curvatures and directions, Litvin's ellipse for the paint thickness, the
  Hertz ellipse of that pair carrying the whole load; null without contact) and
  ``cycle.contact_ellipses`` (their ranges over the cycle). Keys other tools rely on:
  ``cycle.te_pp_unloaded_arcsec``, ``cycle.te_pp_loaded_arcsec``,
  ``cycle.contact_ratio_loaded``, ``cycle.p_max_MPa``, ``positions[i].pinion_angle_deg``,
  ``positions[i].te_loaded_arcsec``, ``positions[i].pairs[j].load_share``,
  ``positions[i].pairs[j].p_max_MPa``, ``positions[i].pairs[j].contact_point_mm``,
  ``positions[i].pairs[j].edge_contact``, ``cycle.contact_zone`` (``sector_teeth``, ``pairs``,
  ``gap_mm``: what the sectors modelled). (Fidelity ``tca``: the loaded values are ``null``.)
  Root stress (fidelities ``fe`` and ``hybrid``, from the stress sectors under the cell forces,
  :mod:`fegear.fem.stress`): ``positions[i].members[k]`` (``name``, ``root_stress_MPa``: per
  tooth that can touch ``tooth``, ``loaded``, ``tension_max_principal`` (largest σ1 in the
  fillet on the loaded-flank side), ``compression_min_principal`` (smallest σ3 on the other
  side), ``von_mises_max``, each with ``*_at``: ``point_mm`` in the member frame,
  ``radius_mm``, ``axial_mm``; ``stress_equilibrium``: reaction against load, relative);
  ``cycle.root_stress_max_MPa`` (per member the extremes over the loaded teeth and positions,
  where), ``cycle.root_stress_fillet_mm`` (``cycle.root_stress_notes``: why coarser than
  0.1 m), ``cycle.root_stress_max_equilibrium_residual``
  (``null`` with ``cycle.root_stress_reason`` at ``hertz``).
- ``vtk/pinion_<i>.vtu``, ``vtk/gear_<i>.vtu`` (fidelity ``fe``) — the sector of each member
  in its assembled position at position ``i`` (fixed frame, mm; the gear at its unloaded
  TCA-closed angle ``ratio·φ1 + TE_unloaded``, the elastic lag is not added), linear tets, with
  point data ``displacement_mm`` (fixed-frame components of ``u = K⁻¹ P F``; *Warp By Vector*),
  ``pressure_MPa`` (the pressure of the contact cell over each working-flank vertex, raised to
  that of the loaded cells whose nearest vertex it is, else 0: a display of the patch on the
  element mesh; the exact field is in the contact cells) and
  ``in_contact`` (1 on loaded flank vertices), ``max_principal_stress_MPa``,
  ``min_principal_stress_MPa``, ``von_mises_MPa`` (the recovered vertex stresses; the sectors
  are the stress sectors, fillets refined).
- ``vtk/contact_cells_<i>.vtu`` — the contact cells of all pairs as quads on the pinion flank
  (fixed frame) with cell data ``force_N``, ``pressure_MPa``, ``area_mm2`` (so that
  ``Σ pressure·area = Σ force``), ``gap_mm``, ``active``, ``edge``, ``pair``,
  ``pinion_tooth``, ``gear_tooth``: the exact solver output. A position without contact has an
  empty file (VTK/ParaView/pyvista read it; meshio 5.3 cannot read an empty VTU).
- ``vtk/flank_pinion_<i>.vtp``, ``vtk/flank_gear_<i>.vtp`` (fidelities ``fe`` and ``hybrid``)
  — the flank views (:mod:`fegear.output.flank_view`): the loaded contact cells of each member on
  its own working flank in flank coordinates, ``x`` the face coordinate and ``y`` the profile
  coordinate (mm; for the face gear the radius and the height above the pitch plane), cell data
  ``pressure_MPa``, ``force_N``, ``tooth``, ``pair``, ``edge``, with the working-surface
  outline (a line, ``outline`` = 1). All teeth share the flank; the bearing pattern of one
  position is what the flank shows, the cycle plays the patch across it.
- ``cycle.pvd`` — the collection: **time = pinion angle φ1 in degrees** (said in a comment of
  the file and in the field data ``pinion_angle_deg`` of every file of the series, the
  ``.vtp`` also in ``time_unit``); parts 0 pinion, 1 gear, 2 contact cells, 3 pinion flank view,
  4 gear flank view; open it in ParaView and press play.
- PNGs: ``te.png`` (unloaded and loaded TE), ``load_share.png``, ``p_max.png``,
  ``bearing_pattern.png`` (union of the loaded cells on the pinion flank, coloured by the largest
  pressure seen over the cycle), ``root_stress.png`` (per member, the root stress of one tooth
  over its passage through the mesh). Fidelity ``tca``: ``te.png`` and ``bearing_pattern.png``
  (unloaded, paint thickness).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from fegear.geometry.transforms import apply_points, apply_vectors
from fegear.output.cylindrical_output import (
    cylindrical_section,
    is_cylindrical,
    plot_line_load,
    te_harmonics,
)
from fegear.output.flank_view import (
    TIME_UNIT,
    FlankFrame,
    FlankPatch,
    PatternCentre,
    flank_frames,
    flank_patches,
    pattern_centre,
    write_flank_vtp,
)
from fegear.output.pattern_plot import plot_loaded_pattern, plot_unloaded_pattern
from fegear.output.records import solver_record, versions
from fegear.pipeline.run import GearRun, report
from fegear.store.files import atomic_write, write_json

__all__ = ["FlankViews", "flank_views", "write_gear_outputs", "gear_summary", "write_pvd"]


@dataclass(frozen=True)
class FlankViews:
    """The flank views of a run (:mod:`fegear.output.flank_view`), computed once for the files,
    the summary and the pictures.

    Attributes
    ----------
    frames
        ``{member: FlankFrame}``.
    patches
        Per position ``{member: FlankPatch}`` (empty for the fidelities without contact cells).
    pattern
        ``{member: PatternCentre}``.
    """

    frames: dict[str, FlankFrame]
    patches: tuple[dict[str, FlankPatch], ...]
    pattern: dict[str, PatternCentre]


def flank_views(run: GearRun) -> FlankViews:
    """The :class:`FlankViews` of a run."""
    frames = flank_frames(run)
    patches = tuple(flank_patches(run, frames=frames)) if run.cycle is not None else ()
    return FlankViews(frames, patches, pattern_centre(run, frames, list(patches)))


ARCSEC_PER_RAD = 180.0 * 3600.0 / math.pi


def _f(x: float) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def _f_or_none(x: float | None) -> float | None:
    return None if x is None else _f(x)


def _num(x: float | None, fmt: str) -> str:
    return "not reported" if x is None else format(x, fmt)


UNITS = {
    "length": "mm",
    "angle": "deg",
    "te": "arcsec",
    "force": "N",
    "torque": "N·m (torque2_Nmm: N·mm)",
    "pressure": "MPa",
    "displacement (VTK)": "mm",
}


def _pair_row(q, k: int) -> dict[str, Any]:
    loaded = q.force_N > 0.0
    return {
        "index": k,
        "pinion_tooth": q.k,
        "gear_tooth": q.j,
        "force_N": q.force_N,
        "torque_Nm": q.torque_Nmm / 1000.0,
        "load_share": q.load_share,
        "p_max_MPa": _f(q.p_max_MPa),  # None where the fidelity gives no pressure (reason)
        "p_peak_MPa": _f(q.p_peak_MPa),
        "semi_major_mm": q.semi_major_mm,
        "semi_minor_mm": q.semi_minor_mm,
        "n_active_cells": q.n_active,
        "edge_contact": q.edge_contact,
        "edges": list(q.edges),
        "p_interior_MPa": _f_or_none(q.p_interior_MPa),
        "p_edge_MPa": _f_or_none(q.p_edge_MPa),
        "pressure_reason": q.pressure_reason,
        "cells_across_patch": _f_or_none(q.cells_across),
        "resolved": bool(q.resolved),
        "in_contact": loaded,
        "contact_point_mm": [float(x) for x in q.contact_point] if loaded else None,
    }


def _path_keys(cp) -> dict[str, object]:
    """``cycle`` keys of one pair's unloaded contact over its whole contact interval
    (:class:`fegear.tca.path.ContactPath`), null with a reason where no pair has interior
    contact."""
    if cp is None:
        why = "no pair is in contact inside both working surfaces at any position"
        return {
            "contact_ratio_unloaded": None,
            "path_length_mm": None,
            "path_length_in_space_mm": None,
            "path_ends": None,
            "path_reason": why,
        }
    space = float(np.linalg.norm(np.diff(cp.fixed_points, axis=0), axis=1).sum())
    return {
        "contact_ratio_unloaded": _f(cp.contact_ratio),
        "path_length_mm": _f(cp.length_mm),
        "path_length_in_space_mm": _f(space),
        "path_ends": [cp.start_limit, cp.end_limit],
        "path_pinion_angles_deg": [math.degrees(cp.phi_start), math.degrees(cp.phi_end)],
    }


def _fe_positions(run: GearRun) -> list[dict[str, Any]]:
    rows = []
    for i, p in enumerate(run.cycle.positions):
        s = p.solution
        rows.append(
            {
                "index": i,
                "pinion_angle_deg": math.degrees(p.phi1),
                "gear_angle_deg": math.degrees(run.phi2[i]),
                "te_unloaded_arcsec": p.te_unloaded_arcsec,
                "te_loaded_arcsec": p.te_loaded_arcsec,
                "te_loaded_urad": p.te_loaded_arcsec / ARCSEC_PER_RAD * 1e6,
                "elastic_lag_arcsec": p.theta * ARCSEC_PER_RAD,
                "n_pairs_in_contact": p.n_pairs_in_contact,
                "status": p.status,
                "status_reason": p.status_reason,
                "unloaded_contact": bool(p.unloaded_contact),
                "total_force_N": float(s.force.sum()) if s.force.size else 0.0,
                "p_max_MPa": p.p_max_MPa,
                "pairs": [_pair_row(q, k) for k, q in enumerate(p.pairs)],
                "solver": {
                    **solver_record(s),
                    "n_cells": int(s.force.size),
                    "g_max_mm": p.g_max_mm,
                },
                "warnings": list(p.warnings),
                "members": [_member_stress_row(mf, i) for mf in run.members],
                "contact_ellipse": _ellipse_row(run, i),
            }
        )
    return rows


def _point_row(x: tuple[float, float, float]) -> dict[str, Any]:
    return {
        "point_mm": [float(v) for v in x],
        "radius_mm": float(math.hypot(x[0], x[1])),
        "axial_mm": float(x[2]),
    }


def _member_stress_row(mf, i: int) -> dict[str, Any]:
    """``positions[i].members[k]``: the root stress of every tooth of member ``mf`` that can
    touch (:class:`fegear.fem.stress.ToothRootStress`) and the equilibrium of its stress solve."""
    eq = mf.equilibrium[i] if i < len(mf.equilibrium) else None
    return {
        "name": mf.name,
        "root_stress_MPa": [
            {
                "tooth": r.tooth,
                "loaded": r.loaded,
                "tension_max_principal": r.tension_MPa,
                "compression_min_principal": r.compression_MPa,
                "von_mises_max": r.von_mises_MPa,
                "tension_at": _point_row(r.tension_point),
                "compression_at": _point_row(r.compression_point),
                "von_mises_at": _point_row(r.von_mises_point),
            }
            for r in (mf.root[i] if i < len(mf.root) else ())
        ],
        "stress_equilibrium": None
        if eq is None
        else {
            "force_residual": eq.force_residual,
            "moment_residual": eq.moment_residual,
            "applied_N": [float(v) for v in eq.applied_N],
        },
    }


def _root_stress_cycle(run: GearRun) -> dict[str, Any]:
    """``cycle.root_stress_max_MPa`` (per member: the largest tension, the most compressive
    compression and the largest von Mises stress of the loaded teeth over the positions, where),
    ``cycle.root_stress_fillet_mm``, ``cycle.root_stress_max_equilibrium_residual``; null with
    ``cycle.root_stress_reason`` where the fidelity has no cell loads."""
    if not run.members or not any(mf.root for mf in run.members):
        if run.kind is not None and not run.kind.cells:
            why = f"the {run.fidelity} fidelity has no contact cells: no loads on the sector FE"
        elif not run.case.root_stress:
            why = (
                "not computed: [analysis] root_stress = false (the default; --root-stress, "
                "or root_stress=True in fegear.run, computes it)"
            )
        else:
            why = "no loaded position"
        return {
            "root_stress_max_MPa": None,
            "root_stress_reason": why,
            "root_stress_fillet_mm": None,
            "root_stress_notes": [],
            "root_stress_max_equilibrium_residual": None,
        }
    out: dict[str, Any] = {}
    for mf in run.members:
        rows = [(i, r) for i, row in enumerate(mf.root) for r in row if r.loaded]
        if not rows:
            out[mf.name] = None
            continue
        it, t = max(rows, key=lambda x: x[1].tension_MPa)
        ic, c = min(rows, key=lambda x: x[1].compression_MPa)
        iv, v = max(rows, key=lambda x: x[1].von_mises_MPa)
        out[mf.name] = {
            "tension_max_principal": t.tension_MPa,
            "tension_at": {"position": it, "tooth": t.tooth, **_point_row(t.tension_point)},
            "compression_min_principal": c.compression_MPa,
            "compression_at": {
                "position": ic,
                "tooth": c.tooth,
                **_point_row(c.compression_point),
            },  # fmt: skip
            "von_mises_max": v.von_mises_MPa,
            "von_mises_at": {"position": iv, "tooth": v.tooth, **_point_row(v.von_mises_point)},
        }
    eqs = [e for mf in run.members for e in mf.equilibrium if e is not None]
    return {
        "root_stress_max_MPa": out,
        "root_stress_reason": "",
        "root_stress_fillet_mm": {mf.name: mf.fillet_mm for mf in run.members},
        "root_stress_notes": [mf.fillet_note for mf in run.members if mf.fillet_note],
        "root_stress_max_equilibrium_residual": max(
            (max(e.force_residual, e.moment_residual) for e in eqs), default=None
        ),
    }


def _tca_positions(run: GearRun) -> list[dict[str, Any]]:
    rows = []
    for i, p in enumerate(run.tca.positions):
        pairs = []
        for k in range(p.pairs.shape[0]):
            if not p.pair_valid[k]:
                continue
            contact = k == p.contact_pair
            pairs.append(
                {
                    "index": k,
                    "pinion_tooth": int(p.pairs[k, 0]),
                    "gear_tooth": int(p.pairs[k, 1]),
                    "in_contact": bool(contact),
                    "backlash_mm": float(p.backlash_mm[k]),
                    "load_share": None,
                    "p_max_MPa": None,
                    "edge_contact": bool(contact and p.edge[k] != ""),
                    "edge": p.edge[k],
                    "contact_point_mm": [float(x) for x in p.points[k]] if contact else None,
                }
            )
        rows.append(
            {
                "index": i,
                "pinion_angle_deg": math.degrees(p.phi1),
                "gear_angle_deg": math.degrees(p.phi2),
                "te_unloaded_arcsec": p.te_arcsec,
                "te_loaded_arcsec": None,
                "has_contact": bool(p.has_contact),
                "pairs": pairs,
                "contact_ellipse": _ellipse_row(run, i),
            }
        )
    return rows


def _ellipse_row(run: GearRun, i: int) -> dict[str, Any] | None:
    from fegear.tca.ellipse import record

    return record(run.ellipses[i]) if i < len(run.ellipses) else None


def _ellipse_cycle(run: GearRun) -> dict[str, Any]:
    from fegear.tca import TCAOptions
    from fegear.tca.ellipse import cycle_record

    delta = next((e.delta_mm for e in run.ellipses if e is not None), TCAOptions().paint_mm)
    doc = cycle_record(run.ellipses, delta, run.case.torque2_Nmm / run.case.ratio / 1000.0)
    if not run.ellipses:
        doc["reason"] = "not computed for this run"
    return doc


def gear_summary(
    run: GearRun, files: list[str] | None = None, views: FlankViews | None = None
) -> dict[str, Any]:
    """The ``summary.json`` document of a gear run (``views``: its flank views, which give
    ``pattern``; without them ``pattern`` is null — :func:`write_gear_outputs` passes them)."""
    case = run.case
    doc: dict[str, Any] = {
        "case": case.name,
        "kind": case.kind,
        "fidelity": case.fidelity,
        "level": None if case.fidelity == "tca" else case.level,  # the FE level of fe/hybrid/hertz
        "units": UNITS,
        "conventions": {
            "te": "TE = (phi2 - phi2_0) - (N1/N2)(phi1 - phi1_0) on member 2; negative: lag",
            "frame": "fixed frame of fegear.assembly (contact points, VTK)",
            "speed": "quasi-static model: speed does not enter",
        },
        "inputs": case.to_dict(),
    }
    rep = report(run)
    eng = run.engagement
    checks = {}
    if eng is not None:
        cl = eng.clearance
        checks = {
            "tip_clearance_mm": None
            if cl is None
            else {"pinion_tip": _f(cl.pinion_tip_mm), "gear_tip": _f(cl.gear_tip_mm)},
            "unloaded_interior_contact_fraction": _f(eng.handover.interior_fraction),
            "contact_ratio_unloaded_below_1": _f_or_none(eng.contact_ratio_below_one),
            "handover_missed_by_positions": bool(eng.missed_handover),
            "positions_without_unloaded_contact": list(eng.lost),
            **_path_keys(eng.path),
        }
    if run.cycle is not None:
        c = run.cycle
        sols = [p.solution for p in c.positions]
        doc["cycle"] = {
            "n_positions": len(c.positions),
            "torque2_Nm": c.torque2_Nmm / 1000.0,
            "te_pp_unloaded_arcsec": _f_or_none(rep.te_pp_unloaded_arcsec),
            "te_pp_unloaded_reason": rep.te_pp_unloaded_reason,
            "te_pp_loaded_arcsec": _f_or_none(rep.te_pp_loaded_arcsec),
            "te_pp_loaded_reason": rep.te_pp_loaded_reason,
            "te_pp_loaded_positions_used": rep.positions_used,
            "excluded_positions": [
                {
                    "index": e.index,
                    "pinion_angle_deg": math.degrees(e.phi1),
                    "status": e.status,
                    "reason": e.reason,
                }
                for e in rep.excluded
            ],
            "contact_ratio_loaded": _f_or_none(rep.contact_ratio_loaded),
            "contact_ratio_reason": rep.contact_ratio_reason,
            "p_max_MPa": _f_or_none(rep.p_max_MPa),
            "p_max_reason": rep.p_max_reason,
            "p_max_at": None
            if rep.p_max_MPa is None
            else {"position": rep.p_max_position, "pair": list(rep.p_max_pair)},
            "p_max_edge_MPa": _f_or_none(rep.p_max_edge_MPa),
            "p_max_edge_at": None
            if rep.p_max_edge_MPa is None
            else {
                "position": rep.p_max_edge_position,
                "pair": list(rep.p_max_edge_pair),
                "edges": list(rep.p_max_edge_edges),
            },
            "positions_with_edge_contact": list(rep.edge_positions),
            "max_pairs_in_contact": int(c.n_in_contact.max()) if c.n_in_contact.size else 0,
            "positions_without_contact": int(np.sum(c.n_in_contact == 0)),
            "max_equilibrium_residual": max((s.equilibrium_residual for s in sols), default=0),
            "max_complementarity_residual": max(
                (s.complementarity_residual for s in sols), default=0.0
            ),
            "max_penetration_mm": max((s.max_penetration for s in sols), default=0.0),
            **_root_stress_cycle(run),
            **checks,
            "contact_ellipses": _ellipse_cycle(run),
            "te_harmonics": te_harmonics(c),
        }
        if c.zone is not None:
            # What the sectors modelled: their teeth, the pairs with a fine zone and the
            # separation bound of that zone (larger than the case's g_max when the load grew it).
            doc["cycle"]["contact_zone"] = {
                "sector_teeth": int(c.zone.n_teeth),
                "pairs": [[int(k), int(j)] for k, j in np.asarray(c.zone.pairs).tolist()],
                "gap_mm": float(c.zone.gap_mm),
            }
        doc["positions"] = _fe_positions(run)
        doc["mesh"] = {
            mf.name: {
                "vertices": int(mf.points.shape[0]),
                "tets": int(mf.tets.shape[0]),
                "displacement_solver": mf.solver,
            }
            for mf in run.members
        }
        doc["timings_s"] = {**run.seconds, **{f"ltca.{k}": v for k, v in c.seconds.items()}}
        warnings = list(rep.warnings) + sorted({w for p in c.positions for w in p.warnings})
        doc["validity"] = {  # fegear.ltca.validity: the model's range, and where a result leaves it
            "in_range": not any(v.exceeded for v in rep.validity),
            "checks": [v.as_dict() for v in rep.validity],
        }
    else:
        r = run.tca
        doc["cycle"] = {
            "n_positions": int(r.phi1.size),
            "torque2_Nm": case.torque2_Nmm / 1000.0,
            "te_pp_unloaded_arcsec": _f_or_none(rep.te_pp_unloaded_arcsec),
            "te_pp_unloaded_reason": rep.te_pp_unloaded_reason,
            "te_pp_loaded_arcsec": None,
            "te_pp_loaded_reason": rep.te_pp_loaded_reason,
            "contact_ratio_loaded": None,
            "p_max_MPa": None,
            "p_max_reason": rep.p_max_reason,
            "hertz_p0_max_MPa": _f(r.hertz_p0_MPa.max()) if r.hertz_p0_MPa.size else None,
            "positions_without_contact": int(np.sum(~r.has_contact)),
            "paint_thickness_mm": r.paint_mm,
            **checks,
            "contact_ellipses": _ellipse_cycle(run),
        }
        doc["positions"] = _tca_positions(run)
        doc["timings_s"] = dict(run.seconds)
        warnings = list(rep.warnings)
    if is_cylindrical(run):
        doc["cylindrical"] = cylindrical_section(run)
    doc["pattern"] = (
        {m: pc.as_dict() for m, pc in views.pattern.items()} if views is not None else None
    )
    doc["cache"] = run.cache.as_dict() if run.cache is not None else None
    doc["warnings"] = warnings
    doc["files"] = files or []
    doc["versions"] = versions()
    return doc


# --------------------------------------------------------------------------------------------
# VTK
# --------------------------------------------------------------------------------------------


def _write_vtu(path: Path, mesh, time_deg: float | None = None) -> Path:
    """meshio's VTU, with the field data ``pinion_angle_deg`` (the time of the series) when
    ``time_deg`` is given (meshio writes no field data: the block goes in before the piece;
    numbers only, which meshio reads back)."""
    import meshio

    def write(q: Path) -> None:
        # binary, uncompressed: zlib took 45 of the 55 ms of a seed face-gear sector file
        # (25 positions, two members: 2 s of a warm run) for files 3 times smaller
        meshio.write(q, mesh, file_format="vtu", compression=None)
        if time_deg is None:
            return
        text = q.read_text(encoding="utf-8")
        block = (
            "<FieldData>\n"
            '<DataArray type="Float64" Name="pinion_angle_deg" NumberOfTuples="1" '
            f'format="ascii">\n{time_deg!r}\n</DataArray>\n'
            "</FieldData>\n"
        )
        head = "<UnstructuredGrid>\n"
        if head not in text:  # pragma: no cover  (meshio's layout)
            raise RuntimeError("unexpected VTU layout from meshio: no <UnstructuredGrid>")
        q.write_text(text.replace(head, head + block, 1), encoding="utf-8")

    return atomic_write(path, write)


def _cell_quads(cells) -> np.ndarray:
    """``(n, 4, 3)`` corners of the cells from their 2 × 2 Gauss points (bilinear
    extrapolation from the Gauss points at ``±1/√3`` to the corners at ``±1``)."""
    q = cells.quad_points.reshape(-1, 2, 2, 3)
    c = q.mean(axis=(1, 2))
    order = [(0, 0), (1, 0), (1, 1), (0, 1)]
    return np.stack([c + math.sqrt(3.0) * (q[:, a, b] - c) for a, b in order], axis=1)


def _contact_mesh(pos):
    import meshio

    if not pos.cells:
        return meshio.Mesh(np.zeros((0, 3)), [("quad", np.zeros((0, 4), dtype=np.int64))])
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
    return meshio.Mesh(
        corners.reshape(-1, 3),
        [("quad", np.arange(4 * n).reshape(n, 4))],
        cell_data={k: [np.asarray(v)] for k, v in data.items()},
    )


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


def _member_mesh(mf, i: int, pos):
    import meshio

    M = mf.placements[i]
    X = apply_points(M, mf.points)
    u = apply_vectors(M, mf.displacement[i])
    p = _node_pressure(mf, i, pos, X)
    data = {"displacement_mm": u, "pressure_MPa": p, "in_contact": (p > 0).astype(np.int32)}
    if mf.max_principal is not None:
        data["max_principal_stress_MPa"] = mf.max_principal[i]
        data["min_principal_stress_MPa"] = mf.min_principal[i]
        data["von_mises_MPa"] = mf.von_mises[i]
    return meshio.Mesh(X, [("tetra", mf.tets)], point_data=data)


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


def _write_vtk(out: Path, run: GearRun, views: FlankViews) -> list[Path]:
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


# --------------------------------------------------------------------------------------------
# PNG
# --------------------------------------------------------------------------------------------


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> Path:
    plt = _plt()
    fig.tight_layout()
    p = atomic_write(path, lambda q: fig.savefig(q, format="png", dpi=110))
    plt.close(fig)
    return p


def _title(run: GearRun) -> str:
    c = run.case
    return f"{c.name}: T2 {c.torque2_Nmm / 1000:.0f} N·m, {c.fidelity} level {c.level}"


def _plot_te(out: Path, run: GearRun) -> Path:
    plt = _plt()
    c = run.cycle
    deg = np.degrees(c.phi1)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.plot(deg, c.te_unloaded_arcsec, "o-", ms=3, label="unloaded")
    ax.plot(deg, c.te_loaded_arcsec, "s-", ms=3, label="loaded")
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("TE (arcsec)")
    rep = report(run)
    ax.set_title(
        f"{_title(run)}\nTE p-p unloaded {_num(rep.te_pp_unloaded_arcsec, '.2f')}, loaded "
        f"{_num(rep.te_pp_loaded_arcsec, '.2f')} arcsec "
        f"(over {rep.positions_used} of {rep.n_positions} positions)",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, out / "te.png")


def _per_pair(run: GearRun, attr: str) -> dict[int, np.ndarray]:
    """``{pinion tooth: (n,) values}`` (NaN where the pair is not modelled or not loaded)."""
    c = run.cycle
    teeth = sorted({q.k for p in c.positions for q in p.pairs})
    out = {k: np.full(len(c.positions), np.nan) for k in teeth}
    for i, p in enumerate(c.positions):
        for q in p.pairs:
            if q.force_N > 0:
                out[q.k][i] = getattr(q, attr)
    return out


def _plot_load_share(out: Path, run: GearRun) -> Path:
    plt = _plt()
    deg = np.degrees(run.cycle.phi1)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for k, v in _per_pair(run, "load_share").items():
        ax.plot(deg, np.nan_to_num(v), "o-", ms=3, label=f"pinion tooth {k:+d}")
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("load share (torque fraction)")
    ax.set_ylim(-0.05, 1.05)
    cr = report(run).contact_ratio_loaded
    ax.set_title(f"{_title(run)}\nloaded contact ratio {_num(cr, '.2f')}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, out / "load_share.png")


def _plot_p_max(out: Path, run: GearRun) -> Path:
    """``p_max.png`` (:mod:`fegear.output.p_max_plot`: the values away from the edges as lines,
    the singular edge values marked apart)."""
    from fegear.output.p_max_plot import save_p_max

    rep = report(run)
    edge = (
        f"; at the edges {rep.p_max_edge_MPa:.0f} MPa (singular)"
        if rep.p_max_edge_MPa is not None
        else ""
    )
    title = f"{_title(run)}\ncycle p_max away from the edges {_num(rep.p_max_MPa, '.0f')} MPa{edge}"
    return save_p_max(out / "p_max.png", run.cycle, title, _save)


def _one_tooth(mf, phi1_deg: np.ndarray, pitch_deg: float):
    """The root stress of one tooth over its whole passage through the mesh, pieced together
    from the teeth of the cycle: tooth ``t`` at ``φ1`` is tooth 0 at ``φ1 − σ t p`` (``p`` the
    pinion's angular pitch; ``σ = ±1``, the sense that makes the loaded stretches of the teeth
    one: the smaller spread). Returns ``(x_deg, tension, compression)`` sorted by ``x``."""
    teeth = mf.root_teeth
    best = None
    for sigma in (1.0, -1.0):
        xs = [phi1_deg - sigma * t * pitch_deg for t in teeth]
        loaded = [
            x[[any(r.tooth == t and r.loaded for r in row) for row in mf.root]]
            for t, x in zip(teeth, xs, strict=True)
        ]
        centres = [float(np.mean(v)) for v in loaded if v.size]
        spread = float(np.ptp(centres)) if centres else 0.0
        if best is None or spread < best[0]:
            best = (spread, xs)
    x = np.concatenate(best[1])
    ten = np.concatenate([mf.root_series(t) for t in teeth])
    com = np.concatenate([mf.root_series(t, "compression_MPa") for t in teeth])
    o = np.argsort(x)
    return x[o], ten[o], com[o]


def _plot_root_stress(out: Path, run: GearRun) -> Path:
    """``root_stress.png``: per member, the tension-fillet maximum principal stress and the
    compression-fillet minimum principal stress of one tooth over its passage through the mesh
    (:func:`_one_tooth`), against the pinion angle of the cycle."""
    plt = _plt()
    c = run.cycle
    deg = np.degrees(c.phi1)
    pitch = 360.0 / run.assembly.n1
    fig, axes = plt.subplots(1, len(run.members), figsize=(11, 4), squeeze=False)
    for ax, mf in zip(axes[0], run.members, strict=True):
        if not mf.root_teeth:
            ax.set_title(f"{mf.name}: no loaded position", fontsize=9)
            continue
        x, ten, com = _one_tooth(mf, deg, pitch)
        ax.plot(x, ten, "o-", ms=3, color="tab:red", label="tension fillet, max principal")
        ax.plot(x, com, "s--", ms=3, color="tab:blue", label="compression fillet, min principal")
        ax.axhline(0.0, color="gray", lw=0.5)
        ax.set_xlabel("pinion angle of the tooth's passage φ1 (deg)")
        ax.set_ylabel("root stress (MPa)")
        top = float(np.nanmax(ten))
        ax.set_title(
            f"{mf.name}: one tooth through the mesh; max {top:.0f} MPa "
            f"(fillet elements {mf.fillet_mm:.3g} mm)",
            fontsize=9,
        )
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(_title(run), fontsize=9)
    return _save(fig, out / "root_stress.png")


def _tca_plots(out: Path, run: GearRun) -> list[Path]:
    from fegear.tca.plots import plot_te

    r, name = run.tca, run.case.name
    paths = [atomic_write(out / "te.png", lambda q: plot_te({name: r}, q,
                          title=f"{name}: unloaded TE (TCA)"))]  # fmt: skip
    paths.append(plot_unloaded_pattern(out, run))
    return paths


def write_gear_outputs(out: Path, run: GearRun, views: FlankViews | None = None) -> list[Path]:
    """Write every output of a gear run into ``out`` (atomically); returns the paths.

    ``views``: the run's flank views (:func:`flank_views`), computed if not given.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    views = views if views is not None else flank_views(run)
    paths: list[Path] = []
    if run.cycle is not None:
        paths += _write_vtk(out, run, views)
        paths += [_plot_te(out, run), _plot_load_share(out, run), _plot_p_max(out, run),
                  plot_loaded_pattern(out, run)]  # fmt: skip
        if run.members and any(mf.root for mf in run.members):
            paths.append(_plot_root_stress(out, run))
        if is_cylindrical(run):
            paths.append(plot_line_load(out, run))
    else:
        paths += _tca_plots(out, run)
    files = [str(p.relative_to(out)) for p in paths] + ["summary.json"]
    # the summary last: its presence says the run is complete
    paths.append(write_json(out / "summary.json", gear_summary(run, files, views)))
    return paths
