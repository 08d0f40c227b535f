"""The measurements of ``hypoid_no16.md`` (parts of ``make_hypoid_no16.py``).

The source: the sample "No. 16" summary sheet of a 10/41 hypoid with a 1.500 in offset,
"Hypoid Bevel Data Set No. 74782608" (dated 05/15/11), published as the sample output of a
bevel-gear design program at http://www.meshingwithgears.com/cpchyp16.html. :data:`SHEET` holds
its numbers as printed (inches, degrees-minutes as ``(deg, min)``); the stored copy read for this
page holds the sheet's page 1 (the general dimensions and the gear's finishing settings) and the
heading of page 2 (the pinion's pressure angles); the pinion's settings, the roughing sheets and
the bias corrections the page announces are not in it. The sheet gives no tooth contact analysis.

Every part returns plain data (inches and degrees, as the sheet prints them).
"""

from __future__ import annotations

import logging
import math

IN = 25.4

#: the sheet's numbers, as printed; angles (deg, min), lengths in inches
SHEET = {
    "n_pinion": 10,
    "n_gear": 41,
    "diametral_pitch": 4.97,
    "offset_in": 1.500,  # "Pinion Offset 1.500 BC" (below centre)
    "face_width_in": 1.250,
    "shaft_angle_deg": 90.0,
    "gear_pa_concave": (24, 30),
    "gear_pa_convex": (18, 0),
    "pinion_pa_concave": (18, 0),
    "pinion_pa_convex": (24, 30),
    "cone_distance_in": 4.274,  # "Cone Dist." in the heading
    "spiral_angle": {"gear": (26, 57), "pinion": (50, 29)},
    "hand": {"gear": "right", "pinion": "left"},
    "cutting_method": {"gear": "spread", "pinion": "fixed"},
    "tooth_taper": "tilted root",
    "gear_addendum_in": 0.064,
    "working_depth_in": 0.375,
    "whole_depth_in": 0.422,
    "gear_pitch_angle": (74, 49),
    "face_angle": {"gear": (75, 59), "pinion": (19, 17)},
    "root_angle": {"gear": (69, 7), "pinion": (12, 52)},
    "gear_dedendum_angle": (5, 42),
    "outside_diameter_in": {"gear": 8.283, "pinion": 3.386},
    "crown_to_crossing_in": {"gear": 1.293, "pinion": 3.907},
    "root_apex_beyond_crossing_in": {"gear": -0.16, "pinion": 1.56},
    "backlash_in": (0.006, 0.008),
    # the gear tooth at mid face (finish)
    "gear_mean_chordal_addendum_in": 0.0511,
    "gear_mean_normal_chordal_thickness_in": 0.1589,
    "gear_mean_whole_depth_in": 0.3476,
    "gear_heel_whole_depth_in": 0.4221,
    # No. 16 gear finishing settings and cutter
    "gear": {
        "cutter_diameter_in": 9.000,
        "edge_radius_in": 0.040,
        "point_width_in": 0.0900,
        "blade_angle_outside": (24, 30),
        "blade_angle_inside": (18, 0),
        "machine_root_angle": (69, 7),
        "machine_center_to_back_in": -0.240,  # printed "MD -0.240"
        "sliding_base_in": 0.070,  # "WITH"
        "blank_offset_in": 0.225,  # "DN"
        "radial_in": 4.108,
        "cradle_angle": (67, 11),
        "tilt_deg": 0.0,
        "cradle_test_roll_deg": 30.0,
        "work_test_roll": (29, 57),
        "nc_over_75": 0.545665,
    },
}


def dm(a: tuple[int, int]) -> float:
    """Degrees of a printed ``(deg, min)``."""
    return a[0] + a[1] / 60.0


def blank_kw() -> dict:
    """The sheet's design data in :class:`~fegear.geometry.bevel.hypoid.HypoidBlank`'s form:
    the nominal pressure angle is the mean of the gear's two, and ``f_αlim`` puts the drive
    flank (fegear: the gear's concave one) at the sheet's concave angle."""
    from fegear.geometry.bevel.hypoid import HypoidBlank

    s = SHEET
    cc, cv = dm(s["gear_pa_concave"]), dm(s["gear_pa_convex"])
    kw = dict(
        n1=s["n_pinion"], n2=s["n_gear"], module_mm=IN / s["diametral_pitch"],
        offset_mm=s["offset_in"] * IN, spiral_angle_deg=dm(s["spiral_angle"]["pinion"]),
        pressure_angle_deg=0.5 * (cc + cv), face_width_mm=s["face_width_in"] * IN,
        shaft_angle_deg=s["shaft_angle_deg"],
        cutter_radius_mm=0.5 * s["gear"]["cutter_diameter_in"] * IN,
        edge_radius_mm=s["gear"]["edge_radius_in"] * IN, hand=s["hand"]["gear"],
    )  # fmt: skip
    alim = abs(math.degrees(HypoidBlank(**kw).limit_pressure_angle))
    kw["limit_pressure_angle_factor"] = 0.5 * (cc - cv) / alim
    return kw


def _blank():
    from fegear.geometry.bevel.hypoid import HypoidBlank

    return HypoidBlank(**blank_kw())


def part_blank() -> dict:
    """fegear's blank of the sheet's design data, in the sheet's quantities (in, deg)."""
    b = _blank()
    d = math.degrees
    out: dict = {"kw": blank_kw(), "members": {}}
    for i, name in ((1, "pinion"), (2, "gear")):
        j = 3 - i
        g, a0, a = b.pitch_angle(i), b.outer_cone_distance(i), b.addendum(i)
        tz = b.pitch_apex(i)
        rm = b.mean_cone_distance(i)
        fa, fb = b.face_cone_line(i)
        ra, rb = b.root_cone_line(i)
        out["members"][name] = {
            "pitch_angle": d(g),
            "spiral_angle": d(b.spiral_angle(i)),
            "outer_cone_distance_in": a0 / IN,
            "mean_cone_distance_in": rm / IN,
            "face_width_in": b.face_width(i) / IN,
            "pitch_apex_beyond_crossing_in": tz / IN,
            "root_apex_beyond_crossing_in": tz / IN,  # standard taper: through its own apex
            "addendum_in": a / IN,
            "dedendum_in": b.dedendum(i) / IN,
            "dedendum_angle": d(b.dedendum_angle(i)),
            "face_angle": d(g + b.dedendum_angle(j)),
            "root_angle": d(g - b.dedendum_angle(i)),
            "outside_diameter_in": 2.0 * (a0 * math.sin(g) + a * math.cos(g)) / IN,
            "crown_to_crossing_in": (a0 * math.cos(g) - a * math.sin(g) - tz) / IN,
            "mean_whole_depth_in": ((fa + fb * rm) - (ra + rb * rm)) / IN,
            "mean_normal_thickness_in": b.thickness_heel(i) * rm / a0
            * math.cos(b.spiral_angle(i)) / IN,
        }  # fmt: skip
    out["working_depth_in"] = b.working_depth / IN
    out["whole_depth_in"] = b.whole_depth / IN
    out["offset_angle_pitch_plane"] = d(b.offset_angle_pitch_plane)
    out["limit_pressure_angle"] = d(b.limit_pressure_angle)
    out["pressure_angle"] = {s: d(b.pressure_angle(s)) for s in ("drive", "coast")}
    return out


def part_gear_settings() -> dict:
    """The gear settings fegear's synthesis fits to this blank (one per flank, as in
    :func:`fegear.geometry.bevel.synthesis.synthesize`), as sheet tables in inches/degrees."""
    from fegear.geometry.bevel.machine import fit_cutter
    from fegear.geometry.bevel.mesh_frame import gear_flank_design
    from fegear.geometry.bevel.sheet import flank_table

    b = _blank()
    g2, d2 = b.pitch_angle(2), b.dedendum_angle(2)
    out = {}
    for side in ("drive", "coast"):
        M2, n2, _, th2 = gear_flank_design(b, side)
        blade = "outside" if side == "drive" else "inside"
        ms = fit_cutter("gear", side, blade, M2, n2, b.cutter_radius_mm, 0.0, g2 - d2,
                        math.pi - th2, math.cos(d2) / math.sin(g2),
                        edge_radius=b.edge_radius)  # fmt: skip
        ft = flank_table(b, 2, ms)
        out[side] = {
            "blade": ft.blade,
            "blade_angle": ft.blade_angle_deg,
            "point_radius_in": ft.blade_radius_mm / IN,
            "blade_radius_at_mean_point_in": ms.cutter_radius_mm / IN,
            "mean_point_height_in": ms.ref_height_mm / IN,
            "edge_radius_in": ft.edge_radius_mm / IN,
            "radial_in": ft.radial_mm / IN,
            "cradle_angle": ft.cradle_angle_deg,
            "machine_root_angle": ft.machine_root_angle_deg,
            "ratio_of_roll": ft.ratio_of_roll,
            "blank_offset_in": ft.blank_offset_mm / IN,
            "sliding_base_in": ft.sliding_base_mm / IN,
            "machine_center_to_apex_in": ft.machine_center_to_apex_mm / IN,
        }
    return out


class _Keep(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.INFO)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())


def part_synthesis() -> dict:
    """fegear's design of the pair from the sheet's blank data (what ``fegear run`` of these
    data does): the local synthesis of the pinion's settings, per side, and its outcome."""
    from fegear.errors import FegearError
    from fegear.geometry.bevel.pair import SpiralBevelPair
    from fegear.geometry.bevel.synthesis import SynthesisTargets

    keep = _Keep()
    lg = logging.getLogger("fegear.geometry.bevel.synthesis")
    lg.addHandler(keep)
    lg.setLevel(logging.INFO)
    out: dict = {"targets": SynthesisTargets().__dict__}
    try:
        SpiralBevelPair.design(_blank(), SynthesisTargets())
        out["error"] = None
    except FegearError as exc:
        out["error"] = {"type": type(exc).__name__, "text": str(exc)}
    finally:
        lg.removeHandler(keep)
    out["log"] = [ln for ln in keep.lines if ln.startswith("spiral bevel")]
    return out


PARTS = {
    "blank": part_blank,
    "gear_settings": part_gear_settings,
    "synthesis": part_synthesis,
}
