"""Build the result model of a gear run, once (:func:`build_result`).

The headlines are the ones a run reports: over the usable positions only, p_max away from the
flank edges, None with a reason where nothing physical can be reported
(:class:`fegear.ltca.results.CycleHeadline`), and the warnings that change the meaning of a
headline. Every writer and the Python API read the model this builds; nothing is computed
twice.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from fegear.ltca.position import CAPPED
from fegear.ltca.validity import ValidityCheck, validity_checks
from fegear.pipeline.run import GearRun
from fegear.results.cylindrical import cylindrical_section, te_harmonics
from fegear.results.ease_off import ease_off_section
from fegear.results.model import (
    TCA_LOST,
    Checks,
    Cycle,
    GearRunResult,
    PairLoad,
    PatternCentre,
    Position,
)
from fegear.results.records import solver_record, versions
from fegear.tca import TCAOptions
from fegear.tca.ellipse import cycle_record, record
from fegear.units import ARCSEC_PER_RAD, nm_from_nmm

__all__ = ["build_result"]

_MISSED = "the positions miss the handover of a contact ratio below 1 (see the warnings)"
_TCA_ONLY = "unloaded TCA only (fidelity tca)"
_FEW = "fewer than two positions in contact"


def _f(x: float) -> float | None:
    """A finite float, else None (JSON has no NaN)."""
    x = float(x)
    return x if math.isfinite(x) else None


def _f_or_none(x: float | None) -> float | None:
    return None if x is None else _f(x)


def _plain(doc: Any) -> Any:
    """A record as JSON holds it (lists, str keys, Python numbers; the values unchanged: a
    float's JSON text reads back to the same float), so that the model built from a run and the
    one read back from its ``summary.json`` are equal."""
    return None if doc is None else json.loads(json.dumps(doc, allow_nan=False))


def _angles(phi1, idx) -> str:
    return ", ".join(f"{i} (φ1 = {np.degrees(phi1[i]):.3f}°)" for i in idx)


# --------------------------------------------------------------------------------------------
# Engagement checks
# --------------------------------------------------------------------------------------------


def _checks(run: GearRun) -> Checks | None:
    eng = run.engagement
    if eng is None:
        return None
    cl, cp = eng.clearance, eng.path
    path: dict[str, Any]
    if cp is None:
        path = {"path_reason": "no pair is in contact inside both working surfaces at any position"}
    else:
        space = float(np.linalg.norm(np.diff(cp.fixed_points, axis=0), axis=1).sum())
        path = {
            "contact_ratio_unloaded": _f(cp.contact_ratio),
            "path_length_mm": _f(cp.length_mm),
            "path_length_in_space_mm": _f(space),
            "path_ends": (cp.start_limit, cp.end_limit),
            "path_pinion_angles_deg": (math.degrees(cp.phi_start), math.degrees(cp.phi_end)),
        }
        open_ends = [
            name
            for name, limit in (("start", cp.start_limit), ("end", cp.end_limit))
            if limit.startswith("unresolved")
        ]
        if open_ends:
            # the interval runs past the pairs the cycle's TCA followed: its length is the part
            # seen, not the pair's contact (a helical pair of overlap ratio near 1 and more)
            path.update(
                contact_ratio_unloaded=None,
                path_length_mm=None,
                path_length_in_space_mm=None,
                path_reason=f"the contact interval's {' and '.join(open_ends)} "
                "reaches past the pairs the TCA followed (path_ends: unresolved): the contact "
                "ratio and the path length of the part seen would understate them",
            )
    return Checks(
        pinion_tip_clearance_mm=None if cl is None else _f(cl.pinion_tip_mm),
        gear_tip_clearance_mm=None if cl is None else _f(cl.gear_tip_mm),
        unloaded_interior_contact_fraction=_f(eng.handover.interior_fraction),
        contact_ratio_unloaded_below_1=_f_or_none(eng.contact_ratio_below_one),
        handover_missed_by_positions=bool(eng.missed_handover),
        positions_without_unloaded_contact=tuple(eng.lost),
        contact_ratio_unloaded=path.get("contact_ratio_unloaded"),
        path_length_mm=path.get("path_length_mm"),
        path_length_in_space_mm=path.get("path_length_in_space_mm"),
        path_ends=path.get("path_ends"),
        path_reason=path.get("path_reason", ""),
        path_pinion_angles_deg=path.get("path_pinion_angles_deg"),
    )


# --------------------------------------------------------------------------------------------
# Headline warnings of a loaded run
# --------------------------------------------------------------------------------------------


def _loaded_warnings(run: GearRun, h, te_l, te_l_why, missed: bool) -> list[str]:
    """The warnings that change the meaning of a loaded headline, after the engagement ones."""
    eng, c = run.engagement, run.cycle
    n = h.n_positions
    warnings = list(eng.warnings) if eng is not None else []
    lost_before = set(eng.lost) if eng is not None else set()
    lost = [e for e in h.excluded_positions if e.status == "lost" and e.index not in lost_before]
    if lost:
        where = _angles(c.phi1, [e.index for e in lost])
        warnings.append(
            f"no load carried at {len(lost)} of {n} positions: {where} ({lost[0].reason}); "
            "left out of the TE peak-to-peak"
        )
    degen = [e for e in h.excluded_positions if e.status == "degenerate"]
    if run.kind is not None and run.kind.cells and not run.kind.resolves_patch:
        bad = [(q, i) for i, p in enumerate(c.positions) for q in p.pairs if q.in_contact]
        bad = [(q, i) for q, i in bad if not q.resolved]
        if bad:
            cells = sorted({float(np.min(cc.cell_mm)) for p in c.positions for cc in p.cells})
            size = f"{cells[0]:.3g}" + (f"-{cells[-1]:.3g}" if cells[-1] > cells[0] else "")
            widths = [2.0 * q.semi_minor_mm for q, _ in bad if q.semi_minor_mm > 0]
            patch = (
                f"the loaded patch (2b = {min(widths):.3g}-{max(widths):.3g} mm"
                if widths
                else "the loaded patch (narrower than one cell"
            )
            at = len({i for _, i in bad})
            warnings.append(
                f"{run.fidelity}: the contact cells ({size} mm) are wider than {patch}) at {at} "
                f"of {n} positions: the pressures and the TE there are cell averages, not the "
                "contact's; run --fidelity hybrid (it resolves the patch at every level)"
            )
    capped = [i for i, p in enumerate(c.positions) if any(w.startswith(CAPPED) for w in p.warnings)]
    if capped:
        cap = next(w for w in c.positions[capped[0]].warnings if w.startswith(CAPPED))
        warnings.append(
            f"contact cells coarser than asked at {len(capped)} of {n} positions ([contact] "
            f"max_cells caps the cells of one pair; e.g. {cap.removeprefix(CAPPED).strip()}): "
            "raise [contact] max_cells to reach them (the cells across each loaded patch: "
            "positions[i].pairs[j].cells_across_patch in summary.json)"
        )
    if degen:
        where = (
            f"all {n} positions"
            if len(degen) == n
            else f"{len(degen)} of {n} positions: {_angles(c.phi1, [e.index for e in degen])}"
        )
        warnings.append(
            f"degenerate (a loaded patch the cells do not resolve) at {where}; left out of the "
            "TE peak-to-peak and p_max (reasons in summary.json: cycle.excluded_positions)"
        )
    if h.excluded_positions and te_l is not None:
        warnings.append(
            f"loaded TE peak-to-peak over {h.te_pp_loaded_positions_used} of {n} positions (the "
            "others are left out, above)"
        )
    if te_l is None and not missed:
        warnings.append(f"loaded TE peak-to-peak not reported: {te_l_why}")
    if h.p_max_MPa is None:
        warnings.append(f"p_max not reported: {h.p_max_reason}")
    return warnings


# --------------------------------------------------------------------------------------------
# Positions
# --------------------------------------------------------------------------------------------


def _pair(q, k: int) -> PairLoad:
    loaded = q.force_N > 0.0
    return PairLoad(
        index=k,
        pinion_tooth=q.k,
        gear_tooth=q.j,
        force_N=q.force_N,
        torque_Nm=nm_from_nmm(q.torque_Nmm),
        load_share=q.load_share,
        p_max_MPa=_f(q.p_max_MPa),  # None where the fidelity gives no pressure (reason)
        p_peak_MPa=_f(q.p_peak_MPa),
        semi_major_mm=q.semi_major_mm,
        semi_minor_mm=q.semi_minor_mm,
        n_active_cells=q.n_active,
        edge_contact=q.edge_contact,
        edges=tuple(q.edges),
        p_interior_MPa=_f_or_none(q.p_interior_MPa),
        p_edge_MPa=_f_or_none(q.p_edge_MPa),
        pressure_reason=q.pressure_reason,
        cells_across_patch=_f_or_none(q.cells_across),
        resolved=bool(q.resolved),
        in_contact=loaded,
        contact_point_mm=tuple(float(x) for x in q.contact_point) if loaded else None,
    )


def _point_row(x) -> dict[str, Any]:
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


def _ellipse_row(run: GearRun, i: int) -> dict[str, Any] | None:
    return record(run.ellipses[i]) if i < len(run.ellipses) else None


def _loaded_positions(run: GearRun) -> tuple[Position, ...]:
    rows = []
    phi2 = run.phi2
    for i, p in enumerate(run.cycle.positions):
        s = p.solution
        pairs = tuple(_pair(q, k) for k, q in enumerate(p.pairs))
        rows.append(
            Position(
                index=i,
                pinion_angle_deg=math.degrees(p.phi1),
                gear_angle_deg=math.degrees(phi2[i]),
                te_unloaded_arcsec=p.te_unloaded_arcsec,
                te_loaded_arcsec=p.te_loaded_arcsec,
                te_loaded_urad=p.te_loaded_arcsec / ARCSEC_PER_RAD * 1e6,
                elastic_lag_arcsec=p.theta * ARCSEC_PER_RAD,
                n_pairs_in_contact=p.n_pairs_in_contact,
                status=p.status,
                status_reason=p.status_reason,
                unloaded_contact=bool(p.unloaded_contact),
                total_force_N=float(s.force.sum()) if s.force.size else 0.0,
                p_max_MPa=p.p_max_MPa,
                pairs=pairs,
                solver=_plain(
                    {**solver_record(s), "n_cells": int(s.force.size), "g_max_mm": p.g_max_mm}
                ),
                warnings=tuple(p.warnings),
                members=tuple(_plain(_member_stress_row(mf, i)) for mf in run.members),
                contact_ellipse=_plain(_ellipse_row(run, i)),
            )
        )
    return tuple(rows)


def _tca_positions(run: GearRun) -> tuple[Position, ...]:
    rows = []
    for i, p in enumerate(run.tca.positions):
        pairs = []
        for k in range(p.pairs.shape[0]):
            if not p.pair_valid[k]:
                continue
            contact = k == p.contact_pair
            pairs.append(
                PairLoad(
                    index=k,
                    pinion_tooth=int(p.pairs[k, 0]),
                    gear_tooth=int(p.pairs[k, 1]),
                    in_contact=bool(contact),
                    backlash_mm=float(p.backlash_mm[k]),
                    force_N=None,
                    torque_Nm=None,
                    load_share=None,
                    p_max_MPa=None,
                    p_interior_MPa=None,
                    p_edge_MPa=None,
                    semi_major_mm=None,
                    semi_minor_mm=None,
                    edge_contact=bool(contact and p.edge[k] != ""),
                    edges=tuple(e for e in p.edge[k].split(",") if e),
                    contact_point_mm=tuple(float(x) for x in p.points[k]) if contact else None,
                )
            )
        has = bool(p.has_contact)
        rows.append(
            Position(
                index=i,
                pinion_angle_deg=math.degrees(p.phi1),
                gear_angle_deg=math.degrees(p.phi2),
                te_unloaded_arcsec=p.te_arcsec,
                te_loaded_arcsec=None,
                n_pairs_in_contact=sum(q.in_contact for q in pairs),
                status="ok" if has else "lost",
                status_reason="" if has else TCA_LOST,
                p_max_MPa=None,
                pairs=tuple(pairs),
                unloaded_contact=has,
                contact_ellipse=_plain(_ellipse_row(run, i)),
            )
        )
    return tuple(rows)


# --------------------------------------------------------------------------------------------
# Cycle
# --------------------------------------------------------------------------------------------


def _root_stress(run: GearRun) -> dict[str, Any]:
    """The root-stress fields of :class:`Cycle`: per member the largest tension, the most
    compressive compression and the largest von Mises stress of the loaded teeth over the
    positions, where; the fillet sizes, notes and the largest reaction residual; None with
    ``root_stress_reason`` where there are none."""
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
        return {"root_stress_reason": why}
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
        "root_stress_notes": tuple(mf.fillet_note for mf in run.members if mf.fillet_note),
        "root_stress_max_equilibrium_residual": max(
            (max(e.force_residual, e.moment_residual) for e in eqs), default=None
        ),
    }


def _ellipse_cycle(run: GearRun) -> dict[str, Any]:
    delta = next((e.delta_mm for e in run.ellipses if e is not None), TCAOptions().paint_mm)
    doc = cycle_record(run.ellipses, delta, run.case.pinion_torque_Nm)
    if not run.ellipses:
        doc["reason"] = "not computed for this run"
    return doc


def _loaded_cycle(run: GearRun, missed: bool) -> tuple[Cycle, list[str], tuple[ValidityCheck, ...]]:
    c = run.cycle
    h = c.headline()
    te_u = h.te_pp_unloaded_arcsec
    te_u_why = "" if te_u is not None else _FEW
    te_l, te_l_why = h.te_pp_loaded_arcsec, h.te_pp_loaded_reason
    cr, cr_why = h.contact_ratio_loaded, ""
    if missed:
        te_u, te_u_why = None, _MISSED
        te_l, te_l_why = None, _MISSED
        cr, cr_why = None, _MISSED
    warnings = _loaded_warnings(run, h, te_l, te_l_why, missed)
    checks = validity_checks(
        c, float(run.case.pair["module_mm"]), run.case.kind, h.p_max_MPa, h.p_max_position
    )
    warnings += [v.text for v in checks if v.exceeded]
    sols = [p.solution for p in c.positions]
    root = _plain(_root_stress(run))
    root["root_stress_notes"] = tuple(root.get("root_stress_notes", ()))
    zone = None
    if c.zone is not None:
        # What the sectors modelled: their teeth, the pairs with a fine zone and the
        # separation bound of that zone (larger than the case's g_max when the load grew it).
        zone = {
            "sector_teeth": int(c.zone.n_teeth),
            "pairs": [[int(k), int(j)] for k, j in np.asarray(c.zone.pairs).tolist()],
            "gap_mm": float(c.zone.gap_mm),
        }
    cycle = Cycle(
        n_positions=len(c.positions),
        torque2_Nm=nm_from_nmm(c.torque2_Nmm),
        te_pp_unloaded_arcsec=_f_or_none(te_u),
        te_pp_unloaded_reason=te_u_why,
        te_pp_loaded_arcsec=_f_or_none(te_l),
        te_pp_loaded_reason=te_l_why,
        te_pp_loaded_positions_used=h.te_pp_loaded_positions_used,
        excluded_positions=h.excluded_positions,
        contact_ratio_loaded=_f_or_none(cr),
        contact_ratio_reason=cr_why,
        p_max_MPa=_f_or_none(h.p_max_MPa),
        p_max_reason=h.p_max_reason,
        p_max_position=None if h.p_max_MPa is None else h.p_max_position,
        p_max_pair=None if h.p_max_MPa is None else tuple(h.p_max_pair),
        p_max_edge_MPa=_f_or_none(h.p_max_edge_MPa),
        p_max_edge_position=None if h.p_max_edge_MPa is None else h.p_max_edge_position,
        p_max_edge_pair=None if h.p_max_edge_MPa is None else tuple(h.p_max_edge_pair),
        p_max_edge_edges=() if h.p_max_edge_MPa is None else tuple(h.p_max_edge_edges),
        positions_with_edge_contact=tuple(h.positions_with_edge_contact),
        max_pairs_in_contact=int(c.n_in_contact.max()) if c.n_in_contact.size else 0,
        positions_without_contact=int(np.sum(c.n_in_contact == 0)),
        max_equilibrium_residual=max((s.equilibrium_residual for s in sols), default=0),
        max_complementarity_residual=max((s.complementarity_residual for s in sols), default=0.0),
        max_penetration_mm=max((s.max_penetration for s in sols), default=0.0),
        **root,
        contact_ellipses=_plain(_ellipse_cycle(run)),
        te_harmonics=_plain(te_harmonics(c)),
        contact_zone=zone,
    )
    return cycle, warnings, checks


def _tca_cycle(run: GearRun, missed: bool) -> Cycle:
    r = run.tca
    seen = r.te_arcsec[r.has_contact]
    te_u = float(np.ptp(seen)) if seen.size >= 2 and not missed else None
    why = _MISSED if missed else ("" if te_u is not None else _FEW)
    return Cycle(
        n_positions=int(r.phi1.size),
        torque2_Nm=run.case.torque2_Nm,
        te_pp_unloaded_arcsec=_f_or_none(te_u),
        te_pp_unloaded_reason=why,
        te_pp_loaded_arcsec=None,
        te_pp_loaded_reason=_TCA_ONLY,
        te_pp_loaded_positions_used=None,
        excluded_positions=(),
        contact_ratio_loaded=None,
        contact_ratio_reason=_TCA_ONLY,
        p_max_MPa=None,
        p_max_reason=_TCA_ONLY,
        p_max_position=None,
        p_max_pair=None,
        p_max_edge_MPa=None,
        p_max_edge_position=None,
        p_max_edge_pair=None,
        p_max_edge_edges=(),
        positions_with_edge_contact=(),
        max_equilibrium_residual=None,
        hertz_p0_max_MPa=_f(r.hertz_p0_MPa.max()) if r.hertz_p0_MPa.size else None,
        positions_without_contact=int(np.sum(~r.has_contact)),
        paint_thickness_mm=r.paint_mm,
        contact_ellipses=_plain(_ellipse_cycle(run)),
    )


def build_result(run: GearRun, pattern: Mapping[str, PatternCentre] | None = None) -> GearRunResult:
    """The result model of a gear run.

    Parameters
    ----------
    run
        What :func:`fegear.pipeline.run.run_gear_case` returned.
    pattern
        Where the bearing pattern is on each member's flank
        (:func:`fegear.output.flank_view.pattern_centre`, computed with the flank views the
        writers draw); None: not computed (``summary.json``'s ``pattern`` is then null).
    """
    case = run.case
    eng = run.engagement
    missed = eng is not None and eng.missed_handover
    validity = None
    mesh = None
    if run.cycle is not None:
        cycle, warnings, vchecks = _loaded_cycle(run, missed)
        positions = _loaded_positions(run)
        validity = {  # fegear.ltca.validity: the model's range, and where a result leaves it
            "in_range": not any(v.exceeded for v in vchecks),
            "checks": [v.as_dict() for v in vchecks],
        }
        mesh = {
            mf.name: {
                "vertices": int(mf.points.shape[0]),
                "tets": int(mf.tets.shape[0]),
                "displacement_solver": mf.solver,
            }
            for mf in run.members
        }
        seconds = {**run.seconds, **{f"ltca.{k}": v for k, v in run.cycle.seconds.items()}}
    else:
        cycle = _tca_cycle(run, missed)
        warnings = list(eng.warnings) if eng is not None else []
        positions = _tca_positions(run)
        seconds = dict(run.seconds)
    return GearRunResult(
        case_name=case.name,
        kind=case.kind,
        fidelity=case.fidelity,
        level=None if case.fidelity == "tca" else case.level,  # the FE level of fe/hybrid/hertz
        inputs=_plain(case.to_dict()),
        cycle=cycle,
        checks=_checks(run),
        positions=positions,
        pattern=dict(pattern) if pattern is not None else None,
        warnings=tuple(warnings),
        seconds=seconds,
        mesh=mesh,
        validity=_plain(validity),
        cylindrical=_plain(cylindrical_section(run)),
        ease_off=ease_off_section(run),
        cache=_plain(run.cache.as_dict()) if run.cache is not None else None,
        versions=versions(),
    )
