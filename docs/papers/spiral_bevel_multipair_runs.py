"""The measurements of ``spiral_bevel_multipair.md`` (parts of ``make_spiral_bevel_multipair.py``).

The paper: "Mathematical model and algorithm for contact stress analysis of gears with multi-pair
contact" (spiral bevel gear with a predesigned parabolic TE and localized contact; the seed text
of this project). Its claims are checked on fegear's reference spiral bevel
``cases/spiral_bevel_nominal.toml`` (12/36, predesigned parabolic TE of 8 arcsec) over a range
of pinion torques at the case's fidelity (``hybrid`` level 0). Every function returns plain data
(mm, N·m, arcsec, MPa, µm).
"""

from __future__ import annotations

import numpy as np
from _parts import CASES

#: pinion torques of the load range (N·m); the case's own is 100 N·m
TORQUES = (10.0, 25.0, 50.0, 100.0, 200.0, 400.0)


def _case():
    import fegear

    return fegear.load_case(CASES / "spiral_bevel_nominal.toml")


def part_tca() -> dict:
    """The unloaded TCA of the case's positions: the TE parabola, every candidate pair's
    separation (the paper's "backlashes" δ_i), the contact path, the contact ellipses."""
    from fegear.ltca import LTCAOptions
    from fegear.ltca.cycle import cycle_tca
    from fegear.pipeline.pair import build_pair
    from fegear.tca.ellipse import ellipses
    from fegear.tca.path import contact_path

    case = _case()
    pair = build_pair(case)
    opt = LTCAOptions(n_positions=case.n_positions, **case.contact.as_dict())
    tca, pos, _ = cycle_tca(pair.pinion, pair.gear, pair.assembly, opt)
    T1 = case.torque2_Nmm / case.ratio / 1000.0
    es = ellipses(pos, tca.asm.axis1(), T1, E_MPa=case.E_MPa, nu=case.nu)
    cp = contact_path(tca, pos)
    return {
        "pinion_torque_Nm": T1,
        "phi_deg": [float(np.degrees(p.phi1)) for p in pos],
        "te_arcsec": [p.te_arcsec for p in pos],
        "pairs": [[int(k), int(j)] for k, j in pos[0].pairs],
        "backlash_um": [[1e3 * float(b) for b in p.backlash_mm] for p in pos],
        "pair_valid": [[bool(v) for v in p.pair_valid] for p in pos],
        "contact_pair": [int(p.contact_pair) for p in pos],
        "contact_ratio_unloaded": None if cp is None else cp.contact_ratio,
        "paint_a": [e.paint_a_mm for e in es],
        "paint_b": [e.paint_b_mm for e in es],
        "hertz_a": [e.hertz.a_mm for e in es],
        "hertz_b": [e.hertz.b_mm for e in es],
        "hertz_p0": [e.hertz.p0_MPa for e in es],
        "ka": [e.curvature.k[0] for e in es],
        "kb": [e.curvature.k[1] for e in es],
    }


def _loaded(T1: float) -> dict:
    import fegear

    case = _case()
    case = case.replace(pinion_torque_Nm=T1)
    r = fegear.run(case)
    s = r.summary
    c = s["cycle"]
    rows = []
    for p in s["positions"]:
        loaded = [q for q in p["pairs"] if q["in_contact"]]
        rows.append(
            {
                "phi_deg": p["pinion_angle_deg"],
                "te_loaded": p["te_loaded_arcsec"],
                "te_unloaded": p["te_unloaded_arcsec"],
                "lag": p["elastic_lag_arcsec"],
                "n_pairs": p["n_pairs_in_contact"],
                "status": p["status"],
                "pairs": [
                    {
                        "pinion_tooth": q["pinion_tooth"],
                        "gear_tooth": q["gear_tooth"],
                        "load_share": q["load_share"],
                        "force_N": q["force_N"],
                        "semi_major_mm": q.get("semi_major_mm"),
                        "semi_minor_mm": q.get("semi_minor_mm"),
                        "p_max_MPa": q["p_max_MPa"],
                        "edges": q.get("edges", []),
                    }
                    for q in loaded
                ],
            }
        )
    return {
        "pinion_torque_Nm": T1,
        "torque2_Nm": c["torque2_Nm"],
        "te_pp_loaded_arcsec": c["te_pp_loaded_arcsec"],
        "te_pp_loaded_reason": c["te_pp_loaded_reason"],
        "te_pp_unloaded_arcsec": c["te_pp_unloaded_arcsec"],
        "positions_used": c["te_pp_loaded_positions_used"],
        "excluded": c["excluded_positions"],
        "contact_ratio_loaded": c["contact_ratio_loaded"],
        "max_pairs_in_contact": c["max_pairs_in_contact"],
        "p_max_MPa": c["p_max_MPa"],
        "p_max_edge_MPa": c["p_max_edge_MPa"],
        "edge_positions": c["positions_with_edge_contact"],
        "pattern": s["pattern"],
        "contact_zone": c.get("contact_zone"),
        "positions": rows,
        "warnings": s["warnings"],
    }


def part_loads() -> dict:
    """The loaded cycle at each pinion torque of :data:`TORQUES`."""
    return {"runs": [_loaded(T) for T in TORQUES]}


PARTS = {"tca": part_tca, "loads": part_loads}
