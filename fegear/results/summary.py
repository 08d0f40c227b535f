"""``summary.json``: the result model of a gear run as a JSON document, and back.

:func:`summary_document` writes the model (:class:`~fegear.results.model.GearRunResult`) as
the document; :func:`load_result` reads a saved ``summary.json`` back into the same model (the
round trip is exact: ``load_result`` of what :func:`summary_document` wrote equals the model).
The keys are the model's field names, in the layout of the document: the headlines in
``cycle``, the engagement checks beside them in ``cycle``, the positions with their pairs in
``positions``. The keys, their units and their meaning: ``docs/cli/README.md``.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from fegear.errors import InputError
from fegear.ltca.results import Excluded
from fegear.results.model import (
    TCA_LOST,
    Checks,
    Cycle,
    GearRunResult,
    PairLoad,
    PatternCentre,
    Position,
)

__all__ = ["UNITS", "load_result", "result_from_summary", "summary_document"]

UNITS = {
    "length": "mm",
    "angle": "deg",
    "te": "arcsec",
    "force": "N",
    "torque": "N·m (torque2_Nmm: N·mm)",
    "pressure": "MPa",
    "displacement (VTK)": "mm",
}

CONVENTIONS = {
    "te": "TE = (phi2 - phi2_0) - (N1/N2)(phi1 - phi1_0) on member 2; negative: lag",
    "frame": "fixed frame of fegear.geometry.pair_placement (contact points, VTK)",
    "speed": "quasi-static model: speed does not enter",
}


def _list(x) -> list | None:
    return None if x is None else list(x)


def _tuple(x) -> tuple | None:
    return None if x is None else tuple(x)


# --------------------------------------------------------------------------------------------
# Model → document
# --------------------------------------------------------------------------------------------


def _pair_doc(q: PairLoad, loaded: bool) -> dict[str, Any]:
    if not loaded:
        return {
            "index": q.index,
            "pinion_tooth": q.pinion_tooth,
            "gear_tooth": q.gear_tooth,
            "in_contact": q.in_contact,
            "backlash_mm": q.backlash_mm,
            "load_share": None,
            "p_max_MPa": None,
            "edge_contact": q.edge_contact,
            "edge": ",".join(q.edges),
            "contact_point_mm": _list(q.contact_point_mm),
        }
    return {
        "index": q.index,
        "pinion_tooth": q.pinion_tooth,
        "gear_tooth": q.gear_tooth,
        "force_N": q.force_N,
        "torque_Nm": q.torque_Nm,
        "load_share": q.load_share,
        "p_max_MPa": q.p_max_MPa,
        "p_peak_MPa": q.p_peak_MPa,
        "semi_major_mm": q.semi_major_mm,
        "semi_minor_mm": q.semi_minor_mm,
        "n_active_cells": q.n_active_cells,
        "edge_contact": q.edge_contact,
        "edges": list(q.edges),
        "p_interior_MPa": q.p_interior_MPa,
        "p_edge_MPa": q.p_edge_MPa,
        "pressure_reason": q.pressure_reason,
        "cells_across_patch": q.cells_across_patch,
        "resolved": q.resolved,
        "in_contact": q.in_contact,
        "contact_point_mm": _list(q.contact_point_mm),
    }


def _position_doc(p: Position, loaded: bool) -> dict[str, Any]:
    pairs = [_pair_doc(q, loaded) for q in p.pairs]
    if not loaded:
        return {
            "index": p.index,
            "pinion_angle_deg": p.pinion_angle_deg,
            "gear_angle_deg": p.gear_angle_deg,
            "te_unloaded_arcsec": p.te_unloaded_arcsec,
            "te_loaded_arcsec": None,
            "has_contact": p.unloaded_contact,
            "pairs": pairs,
            "contact_ellipse": p.contact_ellipse,
        }
    return {
        "index": p.index,
        "pinion_angle_deg": p.pinion_angle_deg,
        "gear_angle_deg": p.gear_angle_deg,
        "te_unloaded_arcsec": p.te_unloaded_arcsec,
        "te_loaded_arcsec": p.te_loaded_arcsec,
        "te_loaded_urad": p.te_loaded_urad,
        "elastic_lag_arcsec": p.elastic_lag_arcsec,
        "n_pairs_in_contact": p.n_pairs_in_contact,
        "status": p.status,
        "status_reason": p.status_reason,
        "unloaded_contact": p.unloaded_contact,
        "total_force_N": p.total_force_N,
        "p_max_MPa": p.p_max_MPa,
        "pairs": pairs,
        "solver": p.solver,
        "warnings": list(p.warnings),
        "members": list(p.members),
        "contact_ellipse": p.contact_ellipse,
    }


def _checks_doc(ch: Checks | None) -> dict[str, Any]:
    if ch is None:
        return {}
    tip = None
    if ch.pinion_tip_clearance_mm is not None or ch.gear_tip_clearance_mm is not None:
        tip = {"pinion_tip": ch.pinion_tip_clearance_mm, "gear_tip": ch.gear_tip_clearance_mm}
    doc: dict[str, Any] = {
        "tip_clearance_mm": tip,
        "unloaded_interior_contact_fraction": ch.unloaded_interior_contact_fraction,
        "contact_ratio_unloaded_below_1": ch.contact_ratio_unloaded_below_1,
        "handover_missed_by_positions": ch.handover_missed_by_positions,
        "positions_without_unloaded_contact": list(ch.positions_without_unloaded_contact),
        "contact_ratio_unloaded": ch.contact_ratio_unloaded,
        "path_length_mm": ch.path_length_mm,
        "path_length_in_space_mm": ch.path_length_in_space_mm,
        "path_ends": _list(ch.path_ends),
    }
    if ch.path_reason:
        doc["path_reason"] = ch.path_reason
    else:
        doc["path_pinion_angles_deg"] = _list(ch.path_pinion_angles_deg)
    return doc


def _excluded_doc(e: Excluded) -> dict[str, Any]:
    return {
        "index": e.index,
        "pinion_angle_deg": e.pinion_angle_deg,
        "status": e.status,
        "reason": e.reason,
    }


def _cycle_doc(r: GearRunResult) -> dict[str, Any]:
    c = r.cycle
    head = {
        "n_positions": c.n_positions,
        "torque2_Nm": c.torque2_Nm,
        "te_pp_unloaded_arcsec": c.te_pp_unloaded_arcsec,
        "te_pp_unloaded_reason": c.te_pp_unloaded_reason,
        "te_pp_loaded_arcsec": c.te_pp_loaded_arcsec,
        "te_pp_loaded_reason": c.te_pp_loaded_reason,
    }
    if not r.loaded:
        return {
            **head,
            "contact_ratio_loaded": None,
            "p_max_MPa": None,
            "p_max_reason": c.p_max_reason,
            "hertz_p0_max_MPa": c.hertz_p0_max_MPa,
            "positions_without_contact": c.positions_without_contact,
            "paint_thickness_mm": c.paint_thickness_mm,
            **_checks_doc(r.checks),
            "contact_ellipses": c.contact_ellipses,
        }
    doc = {
        **head,
        "te_pp_loaded_positions_used": c.te_pp_loaded_positions_used,
        "excluded_positions": [_excluded_doc(e) for e in c.excluded_positions],
        "contact_ratio_loaded": c.contact_ratio_loaded,
        "contact_ratio_reason": c.contact_ratio_reason,
        "p_max_MPa": c.p_max_MPa,
        "p_max_reason": c.p_max_reason,
        "p_max_at": None
        if c.p_max_MPa is None
        else {"position": c.p_max_position, "pair": list(c.p_max_pair)},
        "p_max_edge_MPa": c.p_max_edge_MPa,
        "p_max_edge_at": None
        if c.p_max_edge_MPa is None
        else {
            "position": c.p_max_edge_position,
            "pair": list(c.p_max_edge_pair),
            "edges": list(c.p_max_edge_edges),
        },
        "positions_with_edge_contact": list(c.positions_with_edge_contact),
        "max_pairs_in_contact": c.max_pairs_in_contact,
        "positions_without_contact": c.positions_without_contact,
        "max_equilibrium_residual": c.max_equilibrium_residual,
        "max_complementarity_residual": c.max_complementarity_residual,
        "max_penetration_mm": c.max_penetration_mm,
        "root_stress_max_MPa": c.root_stress_max_MPa,
        "root_stress_reason": c.root_stress_reason,
        "root_stress_fillet_mm": c.root_stress_fillet_mm,
        "root_stress_notes": list(c.root_stress_notes),
        "root_stress_max_equilibrium_residual": c.root_stress_max_equilibrium_residual,
        **_checks_doc(r.checks),
        "contact_ellipses": c.contact_ellipses,
        "te_harmonics": c.te_harmonics,
    }
    if c.contact_zone is not None:
        doc["contact_zone"] = c.contact_zone
    return doc


def summary_warnings(r: GearRunResult) -> list[str]:
    """``summary.json``'s ``warnings``: the run's warnings, then the solver's notes of the
    positions (each once, sorted)."""
    notes = sorted({w for p in r.positions for w in p.warnings})
    return list(r.warnings) + notes


def summary_document(r: GearRunResult, files: list[str] | None = None) -> dict[str, Any]:
    """The ``summary.json`` document of a result (``files``: the files written beside it)."""
    doc: dict[str, Any] = {
        "case": r.case_name,
        "kind": r.kind,
        "fidelity": r.fidelity,
        "level": r.level,
        "units": UNITS,
        "conventions": CONVENTIONS,
        "inputs": r.inputs,
        "cycle": _cycle_doc(r),
        "positions": [_position_doc(p, r.loaded) for p in r.positions],
    }
    if r.loaded:
        doc["mesh"] = r.mesh
    doc["timings_s"] = dict(r.seconds)
    if r.loaded:
        doc["validity"] = r.validity
    if r.cylindrical is not None:
        doc["cylindrical"] = r.cylindrical
    if r.ease_off is not None:
        doc["ease_off"] = r.ease_off
    doc["pattern"] = (
        {m: pc.as_dict() for m, pc in r.pattern.items()} if r.pattern is not None else None
    )
    doc["cache"] = r.cache
    doc["warnings"] = summary_warnings(r)
    doc["files"] = files or []
    doc["versions"] = dict(r.versions)
    return doc


# --------------------------------------------------------------------------------------------
# Document → model
# --------------------------------------------------------------------------------------------


def _opt_float(x: Any) -> float | None:
    return None if x is None else float(x)


def _pair(q: Mapping[str, Any], loaded: bool) -> PairLoad:
    if not loaded:
        return PairLoad(
            index=int(q["index"]),
            pinion_tooth=int(q["pinion_tooth"]),
            gear_tooth=int(q["gear_tooth"]),
            in_contact=bool(q["in_contact"]),
            backlash_mm=_opt_float(q.get("backlash_mm")),
            force_N=None,
            torque_Nm=None,
            load_share=None,
            p_max_MPa=None,
            p_interior_MPa=None,
            p_edge_MPa=None,
            semi_major_mm=None,
            semi_minor_mm=None,
            edge_contact=bool(q["edge_contact"]),
            edges=tuple(e for e in str(q.get("edge", "")).split(",") if e),
            contact_point_mm=_tuple(q.get("contact_point_mm")),
        )
    return PairLoad(
        index=int(q["index"]),
        pinion_tooth=int(q["pinion_tooth"]),
        gear_tooth=int(q["gear_tooth"]),
        force_N=q["force_N"],
        torque_Nm=q["torque_Nm"],
        load_share=q["load_share"],
        p_max_MPa=q["p_max_MPa"],
        p_peak_MPa=q["p_peak_MPa"],
        semi_major_mm=q["semi_major_mm"],
        semi_minor_mm=q["semi_minor_mm"],
        n_active_cells=q["n_active_cells"],
        edge_contact=bool(q["edge_contact"]),
        edges=tuple(q["edges"]),
        p_interior_MPa=q["p_interior_MPa"],
        p_edge_MPa=q["p_edge_MPa"],
        pressure_reason=str(q["pressure_reason"]),
        cells_across_patch=q["cells_across_patch"],
        resolved=q["resolved"],
        in_contact=bool(q["in_contact"]),
        contact_point_mm=_tuple(q["contact_point_mm"]),
    )


def _position(p: Mapping[str, Any], loaded: bool) -> Position:
    pairs = tuple(_pair(q, loaded) for q in p["pairs"])
    if not loaded:
        has = bool(p["has_contact"])
        return Position(
            index=int(p["index"]),
            pinion_angle_deg=p["pinion_angle_deg"],
            gear_angle_deg=p["gear_angle_deg"],
            te_unloaded_arcsec=p["te_unloaded_arcsec"],
            te_loaded_arcsec=None,
            n_pairs_in_contact=sum(q.in_contact for q in pairs),
            status="ok" if has else "lost",
            status_reason="" if has else TCA_LOST,
            p_max_MPa=None,
            pairs=pairs,
            unloaded_contact=has,
            contact_ellipse=p.get("contact_ellipse"),
        )
    return Position(
        index=int(p["index"]),
        pinion_angle_deg=p["pinion_angle_deg"],
        gear_angle_deg=p["gear_angle_deg"],
        te_unloaded_arcsec=p["te_unloaded_arcsec"],
        te_loaded_arcsec=p["te_loaded_arcsec"],
        te_loaded_urad=p["te_loaded_urad"],
        elastic_lag_arcsec=p["elastic_lag_arcsec"],
        n_pairs_in_contact=int(p["n_pairs_in_contact"]),
        status=str(p["status"]),
        status_reason=str(p["status_reason"]),
        unloaded_contact=bool(p["unloaded_contact"]),
        total_force_N=p["total_force_N"],
        p_max_MPa=p["p_max_MPa"],
        pairs=pairs,
        solver=p["solver"],
        warnings=tuple(p["warnings"]),
        members=tuple(p["members"]),
        contact_ellipse=p.get("contact_ellipse"),
    )


def _checks(c: Mapping[str, Any]) -> Checks | None:
    if "unloaded_interior_contact_fraction" not in c:
        return None
    tip = c.get("tip_clearance_mm") or {}
    return Checks(
        pinion_tip_clearance_mm=_opt_float(tip.get("pinion_tip")),
        gear_tip_clearance_mm=_opt_float(tip.get("gear_tip")),
        unloaded_interior_contact_fraction=_opt_float(c["unloaded_interior_contact_fraction"]),
        contact_ratio_unloaded_below_1=_opt_float(c["contact_ratio_unloaded_below_1"]),
        handover_missed_by_positions=bool(c["handover_missed_by_positions"]),
        positions_without_unloaded_contact=tuple(c["positions_without_unloaded_contact"]),
        contact_ratio_unloaded=_opt_float(c["contact_ratio_unloaded"]),
        path_length_mm=_opt_float(c["path_length_mm"]),
        path_length_in_space_mm=_opt_float(c["path_length_in_space_mm"]),
        path_ends=_tuple(c["path_ends"]),
        path_reason=str(c.get("path_reason", "")),
        path_pinion_angles_deg=_tuple(c.get("path_pinion_angles_deg")),
    )


def _cycle(c: Mapping[str, Any], loaded: bool) -> Cycle:
    if not loaded:
        return Cycle(
            n_positions=int(c["n_positions"]),
            torque2_Nm=c["torque2_Nm"],
            te_pp_unloaded_arcsec=c["te_pp_unloaded_arcsec"],
            te_pp_unloaded_reason=c["te_pp_unloaded_reason"],
            te_pp_loaded_arcsec=None,
            te_pp_loaded_reason=c["te_pp_loaded_reason"],
            te_pp_loaded_positions_used=None,
            excluded_positions=(),
            contact_ratio_loaded=None,
            contact_ratio_reason=c["te_pp_loaded_reason"],  # the same: no loaded analysis
            p_max_MPa=None,
            p_max_reason=c["p_max_reason"],
            p_max_position=None,
            p_max_pair=None,
            p_max_edge_MPa=None,
            p_max_edge_position=None,
            p_max_edge_pair=None,
            p_max_edge_edges=(),
            positions_with_edge_contact=(),
            max_equilibrium_residual=None,
            hertz_p0_max_MPa=c["hertz_p0_max_MPa"],
            positions_without_contact=int(c["positions_without_contact"]),
            paint_thickness_mm=c["paint_thickness_mm"],
            contact_ellipses=c["contact_ellipses"],
        )
    at = c["p_max_at"] or {}
    edge = c["p_max_edge_at"] or {}
    return Cycle(
        n_positions=int(c["n_positions"]),
        torque2_Nm=c["torque2_Nm"],
        te_pp_unloaded_arcsec=c["te_pp_unloaded_arcsec"],
        te_pp_unloaded_reason=c["te_pp_unloaded_reason"],
        te_pp_loaded_arcsec=c["te_pp_loaded_arcsec"],
        te_pp_loaded_reason=c["te_pp_loaded_reason"],
        te_pp_loaded_positions_used=c["te_pp_loaded_positions_used"],
        excluded_positions=tuple(
            Excluded(int(e["index"]), e["pinion_angle_deg"], e["status"], e["reason"])
            for e in c["excluded_positions"]
        ),
        contact_ratio_loaded=c["contact_ratio_loaded"],
        contact_ratio_reason=c["contact_ratio_reason"],
        p_max_MPa=c["p_max_MPa"],
        p_max_reason=c["p_max_reason"],
        p_max_position=at.get("position"),
        p_max_pair=_tuple(at.get("pair")),
        p_max_edge_MPa=c["p_max_edge_MPa"],
        p_max_edge_position=edge.get("position"),
        p_max_edge_pair=_tuple(edge.get("pair")),
        p_max_edge_edges=tuple(edge.get("edges", ())),
        positions_with_edge_contact=tuple(c["positions_with_edge_contact"]),
        max_pairs_in_contact=c["max_pairs_in_contact"],
        positions_without_contact=int(c["positions_without_contact"]),
        max_equilibrium_residual=c["max_equilibrium_residual"],
        max_complementarity_residual=c["max_complementarity_residual"],
        max_penetration_mm=c["max_penetration_mm"],
        root_stress_max_MPa=c["root_stress_max_MPa"],
        root_stress_reason=c["root_stress_reason"],
        root_stress_fillet_mm=c["root_stress_fillet_mm"],
        root_stress_notes=tuple(c["root_stress_notes"]),
        root_stress_max_equilibrium_residual=c["root_stress_max_equilibrium_residual"],
        contact_ellipses=c["contact_ellipses"],
        te_harmonics=c["te_harmonics"],
        contact_zone=c.get("contact_zone"),
    )


def _pattern(doc: Mapping[str, Any] | None) -> dict[str, PatternCentre] | None:
    if doc is None:
        return None
    return {
        m: PatternCentre(
            member=m,
            face_mm=d["face_mm"],
            profile_mm=d["profile_mm"],
            face_range_mm=_tuple(d["face_range_mm"]),
            profile_range_mm=_tuple(d["profile_range_mm"]),
            face_name=d["face"],
            profile_name=d["profile"],
            weighting=d["weighting"],
            reason=d["reason"],
        )
        for m, d in doc.items()
    }


def result_from_summary(doc: Mapping[str, Any]) -> GearRunResult:
    """The result model of a ``summary.json`` document (the inverse of
    :func:`summary_document`; the ``files`` list is not part of the model)."""
    loaded = doc["fidelity"] != "tca"
    positions = tuple(_position(p, loaded) for p in doc["positions"])
    notes = sorted({w for p in positions for w in p.warnings})
    warnings = list(doc["warnings"])
    if notes:  # summary_warnings: the run's warnings, then the positions' notes
        warnings = warnings[: len(warnings) - len(notes)]
    return GearRunResult(
        case_name=doc["case"],
        kind=doc["kind"],
        fidelity=doc["fidelity"],
        level=doc["level"],
        inputs=doc["inputs"],
        cycle=_cycle(doc["cycle"], loaded),
        checks=_checks(doc["cycle"]),
        positions=positions,
        pattern=_pattern(doc.get("pattern")),
        warnings=tuple(warnings),
        seconds=doc["timings_s"],
        mesh=doc.get("mesh"),
        validity=doc.get("validity"),
        cylindrical=doc.get("cylindrical"),
        ease_off=doc.get("ease_off"),
        cache=doc.get("cache"),
        versions=doc["versions"],
    )


def load_result(path: str | Path) -> GearRunResult:
    """Read a saved gear run's ``summary.json`` (or the folder holding it) into its result
    model.

    Raises
    ------
    InputError
        No such file, or not the summary of a gear run.
    """
    p = Path(path)
    if p.is_dir():
        p = p / "summary.json"
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError("summary", str(p), "a readable summary.json of a gear run") from exc
    if not isinstance(doc, dict) or "positions" not in doc or "cycle" not in doc:
        raise InputError("summary", str(p), "the summary.json of a gear run (not a Hertz scene)")
    try:
        return result_from_summary(doc)
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError("summary", str(p), f"a complete gear-run summary ({exc!r})") from exc
