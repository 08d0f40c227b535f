"""The measurements of ``face_gear_2013.md`` (each a *part* of ``make_face_gear_2013.py``).

The paper: Wang, Niu, Zhang, "Study of Orthogonal Face Gear's Contact Spots and Transmission
Errors", Sensors & Transducers (IFSA), 2013: a face gear 160/25 driven by a spur pinion. Its
tables are transcribed here (:data:`TABLE2`, :data:`TABLE3`) and set beside fegear's numbers on
the seed case ``cases/face_gear_nominal.toml`` and its load cases ``cases/face_gear_load_*.toml``.
Every function returns plain data (mm, N·m, arcsec, deg).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from _parts import CASES

#: Table 2 of the paper: contact trajectory coordinates (x, y, z) in mm, its rows in order.
TABLE2 = (
    (9.7622, -497.8976, -85.649), (8.8386, -497.7834, -83.6832), (7.9181, -497.7032, -81.7174),
    (7.3056, -497.6686, -80.4069), (6.0825, -497.6447, -77.7858), (4.8604, -497.6813, -75.1647),
    (3.6374, -497.7784, -72.5437), (2.4116, -497.9359, -69.9226), (1.1811, -498.1538, -67.3015),
    (0.254, -498.3568, -65.3357), (-0.3665, -498.5109, -64.0252), (-0.9893, -498.68, -62.7147),
    (-1.6146, -498.8641, -61.4041), (-2.2425, -499.0632, -60.0936),
)  # fmt: skip
#: Table 3: rows 4-10 of Table 2 with the long and short semi-axes a, b (mm) at 350.14 N·m.
TABLE3_ROWS = (3, 4, 5, 6, 7, 8, 9)
TABLE3_AB = ((6.6208, 0.5917), (6.6140, 0.4881), (6.6059, 0.4573), (6.5923, 0.4150),
             (6.5892, 0.4031), (6.5567, 0.3717), (6.5446, 0.3452))  # fmt: skip
#: the paper's pinion torque of Table 3 (N·m) and loads of its TE study (face-gear torque, N·mm)
PINION_TORQUE_NM = 350.14
LOADS = (("light", 5e5), ("moderate", 3e6), ("heavy", 6e6))
#: shapers of the sweep (the paper gives none; fegear's default is N1 + 2 = 27)
SHAPERS = (26, 27, 28, 29, 30, 31, 32, 33, 34)
#: shaft-angle errors of the loaded sweep at the moderate load (deg), seed shaper
DGAMMAS = (-0.05, -0.04, -0.03, -0.02, -0.01, 0.0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06)
#: the shaper the paper's ellipses imply: one δ gives both its a and b there (part ``shapers``:
#: the δ that a implies equals the δ that b implies at N_s = 31.0); it moves the bearing about
#: a third as far per degree as N_s = 27, so its sweep spans three times the range
PAPER_SHAPER = 31
DGAMMAS_PAPER_SHAPER = (-0.15, -0.12, -0.09, -0.06, -0.02, 0.0, 0.02, 0.06, 0.09, 0.12, 0.15,
                        0.18)  # fmt: skip


def _case(name: str = "face_gear_nominal"):
    import fegear

    return fegear.load_case(CASES / f"{name}.toml")


def _with_shaper(case, ns: int | None):
    return case if ns is None else case.replace(pair={**case.pair, "n_shaper": ns})


def paper_path() -> dict:
    """Table 2's own numbers: polyline and chord length, direction, location."""
    P = np.array(TABLE2)
    d = P[-1] - P[0]
    return {
        "polyline_mm": float(np.linalg.norm(np.diff(P, axis=0), axis=1).sum()),
        "chord_mm": float(np.linalg.norm(d)),
        # angle between the path and the plane normal to x (the paper's x: along the face-gear
        # axis, see the frame mapping)
        "angle_to_pitch_plane_deg": math.degrees(math.atan2(abs(d[0]), math.hypot(d[1], d[2]))),
        "y_min": float(P[:, 1].min()),
        "y_max": float(P[:, 1].max()),
        "y_mean": float(P[:, 1].mean()),
        "x_range": [float(P[:, 0].min()), float(P[:, 0].max())],
    }


# --------------------------------------------------------------------------------------------
# one pair's unloaded contact path with its ellipses
# --------------------------------------------------------------------------------------------


def pair_path(case, n: int = 41, outlines: bool = False) -> dict:
    """Pair 0's unloaded contact path over its whole contact interval (:mod:`fegear.tca.path`)
    and, at ``n`` pinion angles evenly spread over it, its contact ellipses
    (:mod:`fegear.tca.ellipse`: Litvin's for 6.32 µm, Hertz of one pair at the paper's
    350.14 N·m)."""
    from fegear.pipeline.pair import build_pair
    from fegear.tca import TCA, TCAOptions
    from fegear.tca.cached import cached_tca
    from fegear.tca.ellipse import ellipses, outline
    from fegear.tca.path import contact_path

    pair = build_pair(case)
    opt = TCAOptions(n_positions=case.n_positions, separation_grid=None)
    n1 = pair.assembly.n1
    phi1 = -np.pi / n1 + 2 * np.pi / n1 * np.arange(case.n_positions) / case.n_positions
    tca, pos, _ = cached_tca(pair.pinion, pair.gear, pair.assembly, opt, phi1)
    cp = contact_path(tca, pos)
    if cp is None:
        return {"contact": False}
    one = TCA(pair.pinion, pair.gear, tca.asm, replace(opt, pair_offsets=(0,)))
    psi = np.linspace(cp.phi_start, cp.phi_end, n)
    ps = one.positions(psi, with_grids=False)
    es = ellipses(ps, tca.asm.axis1(), PINION_TORQUE_NM, E_MPa=case.E_MPa, nu=case.nu)
    bd = tca.fm2.bounds
    X = np.array([e.point for e in es])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(X, axis=0), axis=1))])
    guv = np.array([e.gear_uv for e in es])
    out = {
        "contact": True,
        "contact_ratio": cp.contact_ratio,
        "length_flank_mm": cp.length_mm,
        "length_space_mm": float(np.linalg.norm(np.diff(cp.fixed_points, axis=0), axis=1).sum()),
        "ends": [cp.start_limit, cp.end_limit],
        "phi_deg": np.degrees(psi).tolist(),
        "points": X.tolist(),
        "arc_mm": s.tolist(),
        "gear_radius_mm": guv[:, 1].tolist(),
        "gear_height_mm": bd.profile(guv[:, 0], guv[:, 1]).tolist(),
        "ka": [e.curvature.k[0] for e in es],
        "kb": [e.curvature.k[1] for e in es],
        "paint_a": [e.paint_a_mm for e in es],
        "paint_b": [e.paint_b_mm for e in es],
        "hertz_a": [e.hertz.a_mm for e in es],
        "hertz_b": [e.hertz.b_mm for e in es],
        "hertz_p0": [e.hertz.p0_MPa for e in es],
        "hertz_approach": [e.hertz.approach_mm for e in es],
        "force_N": [e.force_N for e in es],
        "major_to_face_gear_deg": [e.major_to_face_deg["gear"] for e in es],
        "x_mean": float(X[:, 0].mean()),
        "x_range": [float(X[:, 0].min()), float(X[:, 0].max())],
    }
    if outlines:

        def on_gear(uv):
            return np.stack([uv[:, 1], bd.profile(uv[:, 0], uv[:, 1])], -1).round(4).tolist()

        out["outline_paint"] = [on_gear(outline(e, "gear", "paint", 49)) for e in es]
        out["outline_hertz"] = [on_gear(outline(e, "gear", "hertz", 49)) for e in es]
        # the paper's Table 3 ellipses, drawn along fegear's principal directions at the path
        # sample nearest each row (rows matched by arc length, :func:`_matched`)
        sf = (1.0 - _row_fractions()) * s[-1]
        near = [int(np.argmin(np.abs(s - x))) for x in sf[list(TABLE3_ROWS)]]
        out["outline_paper"] = [
            on_gear(outline(es[k], "gear", n=49, axes=ab))
            for k, ab in zip(near, TABLE3_AB, strict=True)
        ]
        out["gear_bounds"] = {
            "v": np.linspace(bd.v_start, bd.v_end, 61).tolist(),
            "fillet": bd.fillet_curve(np.linspace(bd.v_start, bd.v_end, 61)).tolist(),
            "tip": bd.tip_curve(np.linspace(bd.v_start, bd.v_end, 61)).tolist(),
        }
    return out


def _row_fractions() -> np.ndarray:
    """Arc-length fraction of each Table 2 row along the paper's polyline (first row 0)."""
    P = np.array(TABLE2)
    sp = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    return sp / sp[-1]


def _matched(path: dict) -> dict:
    """fegear's path at the arc-length fractions of the paper's Table 2 rows, the paper's first
    row at fegear's pinion-tip end (the b-trend of Table 3 and the mirror mapping: see
    :func:`frame_mapping`). Returns the interpolated points and ellipse values at the Table 3
    rows."""
    f = _row_fractions()
    s = np.asarray(path["arc_mm"])
    sf = (1.0 - f) * s[-1]  # fegear runs gear tip -> pinion tip
    out = {"fraction": f.tolist()}
    for key in ("points",):
        A = np.asarray(path[key])
        out[key] = np.stack([np.interp(sf, s, A[:, i]) for i in range(3)], -1).tolist()
    for key in ("ka", "kb", "paint_a", "paint_b", "hertz_a", "hertz_b", "hertz_approach",
                "gear_radius_mm", "gear_height_mm"):  # fmt: skip
        out[key] = np.interp(sf, s, np.asarray(path[key])).tolist()
    return out


def frame_mapping(path: dict) -> dict:
    """Table 2 in fegear's fixed frame.

    fegear: face-gear axis +z, pitch plane z = 0, pinion axis along +x at height r_p1, the
    path in the plane x = 508 mm. The paper's x runs along the face-gear axis (its span is the
    path's height span), y along the pinion axis (≈ −498: the distance from the face-gear
    axis), z across both (the 25° slope of the plane of action is x against z). Table 3's b
    falls from row 4 to row 10, so the rows run from the pinion-tip end (where the pinion's
    profile curvature is smallest) to the face-gear tip: with the rows matched by arc-length
    fraction, ``x_p = c_x − z``, ``y_p = c_y − x``, ``z_p = c_z − y`` (a mirror image: the paper
    drives the other flank, or turns the other way), the offsets ``c`` by least squares. The
    residuals say how well the two paths coincide once placed.
    """
    P = np.array(TABLE2)
    m = _matched(path)
    F = np.asarray(m["points"])
    mapped = np.stack([-F[:, 2], -F[:, 0], -F[:, 1]], -1)
    c = (P - mapped).mean(0)
    res = P - (mapped + c)
    return {
        "offsets_mm": c.tolist(),
        "rms_mm": np.sqrt((res**2).mean(0)).tolist(),
        "max_abs_mm": np.abs(res).max(0).tolist(),
        "matched_points": F.tolist(),
    }


def table3_compare(path: dict) -> dict:
    """The paper's Table 3 beside fegear's ellipses at the same rows (matched by arc length)."""
    m = _matched(path)
    rows = []
    for k, (a_p, b_p) in zip(TABLE3_ROWS, TABLE3_AB, strict=True):
        ka, kb = m["ka"][k], m["kb"][k]
        rows.append(
            {
                "row": k + 1,
                "paper_a": a_p,
                "paper_b": b_p,
                "paper_ratio": a_p / b_p,
                "geometric_ratio": math.sqrt(kb / ka),
                "hertz_ratio": m["hertz_a"][k] / m["hertz_b"][k],
                "paint_a": m["paint_a"][k],
                "paint_b": m["paint_b"][k],
                "hertz_a": m["hertz_a"][k],
                "hertz_b": m["hertz_b"][k],
                "hertz_approach_mm": m["hertz_approach"][k],
                # δ of Litvin's a = sqrt(2δ/k): what the paper's a and b each imply
                "delta_from_a_mm": ka * a_p**2 / 2,
                "delta_from_b_mm": kb * b_p**2 / 2,
                "height_mm": m["gear_height_mm"][k],
            }
        )
    return {"rows": rows}


# --------------------------------------------------------------------------------------------
# parts
# --------------------------------------------------------------------------------------------


def part_case() -> dict:
    """Table 1 and the case: design values of ``cases/face_gear_nominal.toml`` and what follows
    from them."""
    from fegear.pipeline.pair import build_pair

    case = _case()
    pair = build_pair(case)
    d = pair.gear.design
    return {
        "pair": {k: v for k, v in case.pair.items()},
        "torque2_Nm": case.torque2_Nmm / 1000.0,
        "pinion_torque_Nm": case.torque2_Nmm / case.ratio / 1000.0,
        "E_MPa": case.E_MPa,
        "nu": case.nu,
        "fidelity": case.fidelity,
        "level": case.level,
        "n_positions": case.n_positions,
        "n_shaper": d.n_shaper,
        "pitch_radius_mm": 0.5 * d.n_face_gear * d.module_mm,
        "pinion_pitch_radius_mm": float(pair.pinion.r_p),
        "pinion_base_radius_mm": float(pair.pinion.r_b),
        "base_pitch_mm": math.pi * d.module_mm * math.cos(math.radians(d.pressure_angle_deg)),
    }


def part_path() -> dict:
    """Table 2 and Table 3 on the seed case (N_s = 27): the path, the frame, the ellipses."""
    path = pair_path(_case(), outlines=True)
    return {
        "paper": paper_path(),
        "path": path,
        "frame": frame_mapping(path),
        "table3": table3_compare(path),
    }


def _location_shift(case, dgamma: float) -> float:
    p = pair_path(case.with_errors(dgamma_deg=dgamma), n=9)
    return p["x_mean"] if p["contact"] else float("nan")


def part_shapers() -> dict:
    """The n_shaper sweep: a/b at Table 3's rows, the path's location and its Δγ sensitivity."""
    base = _case()
    inner, outer = base.pair["inner_radius_mm"], base.pair["outer_radius_mm"]
    out = []
    for ns in SHAPERS:
        case = _with_shaper(base, ns)
        path = pair_path(case)
        t3 = table3_compare(path)["rows"]
        xp, xm = _location_shift(case, 0.01), _location_shift(case, -0.01)
        slope = (xp - xm) / 0.02  # mm per degree
        a = max(path["paint_a"])
        out.append(
            {
                "n_shaper": ns,
                "contact_ratio": path["contact_ratio"],
                "length_space_mm": path["length_space_mm"],
                "x_mean": path["x_mean"],
                "geometric_ratio": [r["geometric_ratio"] for r in t3],
                "hertz_ratio": [r["hertz_ratio"] for r in t3],
                "paint_a_max": a,
                "hertz_a": [r["hertz_a"] for r in t3],
                "delta_from_a_mm": [r["delta_from_a_mm"] for r in t3],
                "delta_from_b_mm": [r["delta_from_b_mm"] for r in t3],
                "hertz_approach_mm": [r["hertz_approach_mm"] for r in t3],
                "x_at_dgamma": {"+0.01": xp, "-0.01": xm},
                "mm_per_deg": slope,
                "asymmetry_mm": (xp - path["x_mean"]) + (xm - path["x_mean"]),
                # the paint ellipse's end reaches a face end (linear in Δγ)
                "dgamma_paint_at_outer_deg": (outer - a - path["x_mean"]) / slope,
                "dgamma_paint_at_inner_deg": (inner + a - path["x_mean"]) / slope,
            }
        )
    return {"shapers": out}


def _loaded(case, **errors) -> dict:
    """One loaded run at the case's fidelity and level: its headline numbers and curves."""
    import fegear

    if errors:
        case = case.with_errors(**errors)
    r = fegear.run(case)
    s = r.summary
    c = s["cycle"]
    pos = s["positions"]
    axes = [
        (q["semi_major_mm"], q["semi_minor_mm"])
        for p in pos
        for q in p["pairs"]
        if q["in_contact"] and q.get("semi_major_mm") is not None
    ]
    edges: dict[str, int] = {}
    for p in pos:
        for q in p["pairs"]:
            if q["in_contact"]:
                for e in q.get("edges", []):
                    edges[e] = edges.get(e, 0) + 1
    return {
        "fidelity": s["fidelity"],
        "level": s["level"],
        "torque2_Nm": c["torque2_Nm"],
        "te_pp_loaded_arcsec": c["te_pp_loaded_arcsec"],
        "te_pp_loaded_reason": c["te_pp_loaded_reason"],
        "te_pp_unloaded_arcsec": c["te_pp_unloaded_arcsec"],
        "positions_used": c["te_pp_loaded_positions_used"],
        "contact_ratio_loaded": c["contact_ratio_loaded"],
        "contact_ratio_unloaded": c.get("contact_ratio_unloaded"),
        "max_pairs_in_contact": c["max_pairs_in_contact"],
        "p_max_MPa": c["p_max_MPa"],
        "p_max_edge_MPa": c["p_max_edge_MPa"],
        "edge_positions": c["positions_with_edge_contact"],
        "edges_seen": edges,
        "pattern_gear": s["pattern"]["gear"],
        "phi_deg": [p["pinion_angle_deg"] for p in pos],
        "te_loaded": [p["te_loaded_arcsec"] for p in pos],
        "te_unloaded": [p["te_unloaded_arcsec"] for p in pos],
        "lag_mean_arcsec": float(np.mean([p["elastic_lag_arcsec"] for p in pos])),
        "n_pairs": [p["n_pairs_in_contact"] for p in pos],
        "semi_major_max_mm": max((a for a, _ in axes), default=None),
        "semi_minor_max_mm": max((b for _, b in axes), default=None),
        "warnings": s["warnings"],
        "seconds": sum(v for v in s["timings_s"].values() if isinstance(v, float)),
    }


def part_loads() -> dict:
    """TE and contact ratio at the paper's three loads (``cases/face_gear_load_*.toml``)."""
    return {name: _loaded(_case(f"face_gear_load_{name}")) for name, _ in LOADS}


def _sweep(case, dgammas, **errors) -> list[dict]:
    out = []
    for g in dgammas:
        try:
            res = _loaded(case, dgamma_deg=g, **errors)
        except Exception as exc:  # a clear "no contact": the page says so, with the message
            res = {"error": f"{type(exc).__name__}: {exc}"}
        out.append({"dgamma_deg": g, **res})
    return out


def part_dgamma() -> dict:
    """Δγ at the moderate load, the seed shaper N_s = 27, bearing at fegear's 508 mm."""
    return {"runs": _sweep(_case("face_gear_load_moderate"), DGAMMAS)}


def part_dgamma_shaper() -> dict:
    """Δγ at the moderate load with the shaper the paper's ellipses imply
    (:data:`PAPER_SHAPER`)."""
    case = _with_shaper(_case("face_gear_load_moderate"), PAPER_SHAPER)
    return {"n_shaper": PAPER_SHAPER, "runs": _sweep(case, DGAMMAS_PAPER_SHAPER)}


def part_dgamma_placed() -> dict:
    """Δγ at the moderate load with the bearing placed at the paper's radius (Table 2: 498.2 mm)
    by an axial shift Δq of the face gear, found on the unloaded path."""
    case = _case("face_gear_load_moderate")
    target = -paper_path()["y_mean"]
    x0 = pair_path(case, n=9)["x_mean"]
    x1 = pair_path(case.with_errors(dA2_mm=0.1), n=9)["x_mean"]
    dq = 0.1 * (target - x0) / (x1 - x0)
    x_dq = pair_path(case.with_errors(dA2_mm=dq), n=9)["x_mean"]
    return {
        "dA2_mm": dq,
        "x_mean": x_dq,
        "target_mm": target,
        "runs": _sweep(case, DGAMMAS, dA2_mm=dq),
    }


def part_errors_path() -> dict:
    """Which installation error puts the unloaded path where Table 2 has it, and how flat."""
    case = _case()
    out = {}
    for name, err in (("dgamma_deg", -0.01), ("dA2_mm", 0.1), ("dE_mm", 0.1)):
        p = pair_path(case.with_errors(**{name: err}), n=21)
        X = np.asarray(p["points"])
        out[name] = {
            "value": err,
            "x_mean": p["x_mean"],
            "x_range": p["x_range"],
            "contact_ratio": p["contact_ratio"],
            # the spread of the distance from the face-gear axis along the pinion axis
            "x_spread_mm": float(np.ptp(X[:, 0])),
        }
    return out


PARTS = {
    "case": part_case,
    "path": part_path,
    "shapers": part_shapers,
    "errors_path": part_errors_path,
    "loads": part_loads,
    "dgamma": part_dgamma,
    "dgamma_shaper": part_dgamma_shaper,
    "dgamma_placed": part_dgamma_placed,
}
