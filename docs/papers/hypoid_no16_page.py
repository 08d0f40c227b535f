"""The text and figure of ``hypoid_no16.md``, from ``hypoid_no16.json``.

:func:`render` is pure (the page's text from the JSON: ``tests/test_paper_hypoid.py`` compares
it with the page); :func:`figures` draws ``docs/papers/hypoid_no16/sections.png``.
"""

from __future__ import annotations

import math

from _parts import HERE, plt, reflow, save, seconds_text, table
from hypoid_no16_runs import SHEET, dm

ORDER = ("blank", "gear_settings", "synthesis")
FIG = HERE / "hypoid_no16"
CMD = "python docs/papers/make_hypoid_no16.py"
URL = "http://www.meshingwithgears.com/cpchyp16.html"


def _dm(x: float) -> str:
    """Degrees as the sheet prints them: ``74°49'``, to the tenth of a minute."""
    s = "-" if x < 0 else ""
    x = abs(x)
    d = int(x)
    m = round((x - d) * 60.0, 1)
    if m >= 60.0:
        d, m = d + 1, 0.0
    return f"{s}{d}°{m:04.1f}'"


def _sheet_dm(a: tuple[int, int]) -> str:
    return f"{a[0]}°{a[1]:02d}'"


def _dd(fe: float, sheet: float, unit: str = "°") -> str:
    d = fe - sheet
    if unit == "°":
        return f"{d:+.3f}° ({d * 60:+.1f}')"
    return f"{d:+.4f} in ({100 * d / sheet:+.1f} %)"


def blank_rows(doc: dict) -> list[list[str]]:
    """Quantity, sheet, fegear, fegear − sheet, what it tests."""
    b = doc["parts"]["blank"]["data"]
    p, g = b["members"]["pinion"], b["members"]["gear"]
    s = SHEET
    cone = "the pitch cones"
    prop = "the proportions"
    rows = []

    def ang(name, sheet_a, fe, what):
        rows.append([name, _sheet_dm(sheet_a), _dm(fe), _dd(fe, dm(sheet_a)), what])

    def ln(name, sheet_v, fe, what):
        rows.append([name, f"{sheet_v:.4g} in", f"{fe:.4f} in", _dd(fe, sheet_v, "in"), what])

    ang("gear pitch angle γ2", s["gear_pitch_angle"], g["pitch_angle"], cone)
    ang("gear mean spiral angle β2", s["spiral_angle"]["gear"], g["spiral_angle"], cone)
    ang("pinion mean spiral angle β1", s["spiral_angle"]["pinion"], p["spiral_angle"], "input")
    eps = (dm(s["spiral_angle"]["pinion"]) - dm(s["spiral_angle"]["gear"]),)
    rows.append(["offset angle ε' = β1 − β2", _dm(eps[0]) + " (from the two)",
                 _dm(b["offset_angle_pitch_plane"]),
                 _dd(b["offset_angle_pitch_plane"], eps[0]), cone])  # fmt: skip
    ln("cone distance (heading) / gear A0", s["cone_distance_in"], g["outer_cone_distance_in"],
       cone)  # fmt: skip
    ln("gear addendum (heel)", s["gear_addendum_in"], g["addendum_in"], prop)
    ln("working depth (heel)", s["working_depth_in"], b["working_depth_in"], prop)
    ln("whole depth (heel)", s["whole_depth_in"], b["whole_depth_in"], prop)
    ang("gear dedendum angle", s["gear_dedendum_angle"], g["dedendum_angle"], "taper")
    for who, m in (("gear", g), ("pinion", p)):
        ang(f"{who} face angle", s["face_angle"][who], m["face_angle"], "taper, proportions")
    for who, m in (("gear", g), ("pinion", p)):
        ang(f"{who} root angle", s["root_angle"][who], m["root_angle"], "taper")
    for who, m in (("gear", g), ("pinion", p)):
        ln(f"{who} outside diameter", s["outside_diameter_in"][who],
           m["outside_diameter_in"], "cones, proportions, pinion face")  # fmt: skip
    for who, m in (("gear", g), ("pinion", p)):
        ln(f"{who} crown to crossing point", s["crown_to_crossing_in"][who],
           m["crown_to_crossing_in"], "cones, proportions, pinion face")  # fmt: skip
    for who, m in (("gear", g), ("pinion", p)):
        ln(f"{who} root apex beyond crossing point", s["root_apex_beyond_crossing_in"][who],
           m["root_apex_beyond_crossing_in"], "cones, taper")  # fmt: skip
    ln("gear whole depth at mid face", s["gear_mean_whole_depth_in"], g["mean_whole_depth_in"],
       prop)  # fmt: skip
    ln("gear normal thickness at mid face", s["gear_mean_normal_chordal_thickness_in"],
       g["mean_normal_thickness_in"], "thickness, backlash")  # fmt: skip
    ang("drive flank pressure angle (gear concave)", s["gear_pa_concave"],
        b["pressure_angle"]["drive"], "input (f_αlim)")  # fmt: skip
    ang("coast flank pressure angle (gear convex)", s["gear_pa_convex"],
        b["pressure_angle"]["coast"], "input (f_αlim)")  # fmt: skip
    return rows


def settings_rows(doc: dict) -> list[list[str]]:
    """Setting, sheet (both gear flanks), fegear drive, fegear coast."""
    gs = doc["parts"]["gear_settings"]["data"]
    d, c = gs["drive"], gs["coast"]
    s = SHEET["gear"]
    r0, w = 0.5 * s["cutter_diameter_in"], s["point_width_in"]
    roll = s["nc_over_75"] * 75.0 / SHEET["n_gear"]
    test = dm(s["work_test_roll"]) / s["cradle_test_roll_deg"]

    def inch(x):
        return f"{x:.4f}"

    return [
        ["cutting method", "spread blade: both flanks in one setup",
         "own setup, outside blade", "own setup, inside blade"],
        ["cutter radius (nominal)", f"{r0:.4f} (9.000 dia)",
         f"{inch(d['blade_radius_at_mean_point_in'])} at the mean point",
         f"{inch(c['blade_radius_at_mean_point_in'])} at the mean point"],
        ["blade point radius", f"OB {r0 + w / 2:.4f} / IB {r0 - w / 2:.4f} (point width 0.0900)",
         inch(d["point_radius_in"]), inch(c["point_radius_in"])],
        ["blade angle", f"OB {_sheet_dm(s['blade_angle_outside'])} / "
         f"IB {_sheet_dm(s['blade_angle_inside'])}",
         _dm(d["blade_angle"]), _dm(c["blade_angle"])],
        ["edge radius", f"{s['edge_radius_in']:.3f}", f"{d['edge_radius_in']:.3f} (input)",
         f"{c['edge_radius_in']:.3f} (input)"],
        ["radial", f"{s['radial_in']:.3f}", inch(d["radial_in"]), inch(c["radial_in"])],
        ["cradle angle", _sheet_dm(s["cradle_angle"]), _dm(d["cradle_angle"]),
         _dm(c["cradle_angle"])],
        ["machine root angle", _sheet_dm(s["machine_root_angle"]),
         _dm(d["machine_root_angle"]), _dm(c["machine_root_angle"])],
        ["ratio of roll ω_work/ω_cradle", f"{roll:.5f} (Nc/75 0.545665 × 75/41; test roll "
         f"29°57'/30° = {test:.5f})", f"{d['ratio_of_roll']:.5f}", f"{c['ratio_of_roll']:.5f}"],
        ["blank offset", f"{s['blank_offset_in']:.3f} DN", inch(d["blank_offset_in"]),
         inch(c["blank_offset_in"])],
        ["sliding base", f"{s['sliding_base_in']:.3f} WITH", inch(d["sliding_base_in"]),
         inch(c["sliding_base_in"])],
        ["machine centre to back / to apex", "MD −0.240 (to back)",
         f"{inch(d['machine_center_to_apex_in'])} (to apex)",
         f"{inch(c['machine_center_to_apex_in'])} (to apex)"],
        ["tilt", "0", "— (not modelled)", "— (not modelled)"],
    ]  # fmt: skip


def _pair_toml(kw: dict) -> str:
    lines = [
        "    [case]",
        '    kind = "hypoid"',
        "    [pair]",
        f"    n_pinion = {kw['n1']}",
        f"    n_gear = {kw['n2']}",
        f"    module_mm = {kw['module_mm']:.6f}            # 25.4 / 4.97",
        f"    offset_mm = {kw['offset_mm']:.1f}                 # 1.500 in",
        f"    spiral_angle_deg = {kw['spiral_angle_deg']:.6f}    # 50°29', pinion",
        f"    pressure_angle_deg = {kw['pressure_angle_deg']:.2f}       # (24°30' + 18°00') / 2",
        f"    limit_pressure_angle_factor = {kw['limit_pressure_angle_factor']:.6f}",
        f"    face_width_mm = {kw['face_width_mm']:.2f}            # 1.250 in",
        f"    cutter_radius_mm = {kw['cutter_radius_mm']:.1f}          # 9.000 in diameter",
        f"    edge_radius_mm = {kw['edge_radius_mm']:.3f}           # 0.040 in",
        f'    hand = "{kw["hand"]}"',
    ]
    return "\n".join(lines)


def summary(doc: dict) -> str:
    """The closing table: sheet, fegear, verdict."""
    b = doc["parts"]["blank"]["data"]
    gs = doc["parts"]["gear_settings"]["data"]
    refused = doc["parts"]["synthesis"]["data"]["error"] is not None
    g, s = b["members"]["gear"], SHEET
    dg = (g["pitch_angle"] - dm(s["gear_pitch_angle"])) * 60
    db = (g["spiral_angle"] - dm(s["spiral_angle"]["gear"])) * 60
    da0 = g["outer_cone_distance_in"] - s["cone_distance_in"]
    dq = (abs(gs["coast"]["cradle_angle"]) - dm(s["gear"]["cradle_angle"])) * 60
    sheet_cones = ", ".join(
        _sheet_dm(a) for a in (s["gear_pitch_angle"], s["spiral_angle"]["gear"])
    )
    fe_cones = ", ".join(_dm(x) for x in (g["pitch_angle"], g["spiral_angle"]))
    rows = [
        ["gear pitch angle, spiral angle, cone distance", f"{sheet_cones}, 4.274 in",
         f"{fe_cones}, {g['outer_cone_distance_in']:.4f} in",
         f"agree ({dg:+.1f}', {db:+.1f}', {da0:+.4f} in)"],
        ["depths, taper, root and face angles", "tilted root, working depth 0.375 in",
         f"standard taper, {b['working_depth_in']:.3f} in", "differ: another proportion rule"],
        ["gear machine settings", "spread blade, one setup", "a setup per flank",
         f"differ in kind; cradle angle of the convex flank within {abs(dq):.1f}'"],
        ["pinion machine settings", "not in the copy read",
         "synthesis refused" if refused else "synthesized", "—"],
        ["TCA, LTCA", "none given", "none (no pinion)" if refused else "not run",
         "nothing to compare"],
    ]  # fmt: skip
    return table(["", "sheet", "fegear", ""], rows)


def render(doc: dict) -> str:
    parts = doc["parts"]
    b = parts["blank"]["data"]
    gs = parts["gear_settings"]["data"]
    sy = parts["synthesis"]["data"]
    g = b["members"]["gear"]
    p = b["members"]["pinion"]
    s = SHEET
    kw = b["kw"]
    dg = g["pitch_angle"] - dm(s["gear_pitch_angle"])
    db = g["spiral_angle"] - dm(s["spiral_angle"]["gear"])
    da0 = g["outer_cone_distance_in"] - s["cone_distance_in"]
    err = sy["error"]["text"].replace("\n", "") if sy["error"] else "none"
    err = " ".join(err.split())
    refused = sy["error"] is not None
    out = f"""# A 10/41 hypoid from a Gleason-style No. 16 summary sheet, on fegear

The source is the sample summary sheet "Hypoid Bevel Data Set No. 74782608" (dated 05/15/11) of a
10 × 41 hypoid with a 1.500 in offset, printed by a bevel-gear design program as its sample output
and published at {URL} (read from a stored copy of that page). It is a Gleason-style "No. 16"
sheet: the blank dimensions of both members and, per member, the machine settings of a Gleason
No. 16 hypoid generator. It is the one public hypoid source found with printed machine settings:
the NASA and university reports with tables of settings and TCA results (Litvin et al. on
face-milled formate hypoids, Zhang, Litvin and Handschuh on spiral bevels, Kolivand and
Kahraman's hypoid LTCA) were available here only by their opening pages, and none of the public
repositories searched ships such a table.

This page compares fegear's hypoid, built from the sheet's design data, with the sheet number by
number: the blank (§2), the gear's machine settings (§3), and what fegear's synthesis of the
pinion does with these data (§4). The page is generated: `{CMD}` runs the parts and rewrites it
({seconds_text(doc, ORDER)} of wall time, as last run); `{CMD} PART` reruns one, `{CMD} render`
rewrites the text from `docs/papers/hypoid_no16.json`. The measurements are in
`docs/papers/hypoid_no16_runs.py`, where the sheet's numbers are transcribed (`SHEET`).

## 1. What the sheet gives and what it leaves out

Given (page 1 of the sheet, and the heading of its page 2):

- the pair: 10 × 41 teeth, diametral pitch 4.97 (gear outer pitch diameter 41/4.97 = 8.249 in),
  pinion offset 1.500 in below centre, face width 1.250 in, shaft angle 90°, cone distance 4.274
  in, mean spiral angles 26°57' (gear, right hand) and 50°29' (pinion, left hand), pressure angles
  gear concave 24°30' / convex 18°00' (pinion concave 18°00' / convex 24°30');
- the gear's blank: addendum 0.064, working depth 0.375, whole depth 0.422 in, pitch angle 74°49',
  face angle 75°59', root angle 69°07', dedendum angle 5°42', tilted-root taper; both members'
  outside diameters, crown to crossing point, root apex beyond the crossing point, face and root
  angles; the gear tooth at mid face (normal chordal addendum 0.0511, normal chordal thickness
  0.1889 rough / 0.1589 finish, whole depth 0.3476, at the heel 0.4221 in); backlash 0.006–0.008;
- the gear's finishing on a No. 16: a spread-blade cutter of 9.000 in diameter, point width
  0.0900 (rough 0.0600), blade angles OB 24°30' / IB 18°00', edge radius 0.040; machine root angle
  69°07', machine centre to back "MD −0.240", sliding base 0.070 "WITH", blank offset 0.225 "DN",
  radial 4.108, cradle angle 67°11', tilt 0, cradle test roll 30° against work test roll 29°57',
  the Nc/75 ratio 0.545665, the index gears.

Left out, or not in the copy read here:

- **the pinion's machine settings**: the sheet announces its page 2 (No. 16 pinion finishing,
  "Fixed" setting: a cutter and a setup per flank), page 3 and 4 (roughing) and the bias
  corrections; the stored copy ends at the heading of page 2. Without them the pair cannot be cut
  from the sheet: fegear's `[machine]` takes the four flank tables together;
- the pinion's pitch angle, face width, addendum, mounting distances; the gear's mounting
  distance, which the "MD −0.240" of the machine centre to back refers to;
- **any tooth contact analysis**: no contact pattern, path, transmission error, contact ratio,
  load or stress. There is nothing in the source to compare a TCA or an LTCA with.

## 2. The blank (part `blank`: `{CMD} blank`)

fegear's hypoid blank (`HypoidBlank`, ISO 23509 method 1 with the gear cutter radius as the limit
radius: [../geometry/hypoid.md](../geometry/hypoid.md)) from the sheet's design data. The nominal
pressure angle is the mean of the gear's two and `limit_pressure_angle_factor` puts fegear's
drive flank (the gear's concave one) at the sheet's 24°30' and the coast flank at 18°00' (α_lim =
{b["limit_pressure_angle"]:.4f}° for these cones, f_αlim = {kw["limit_pressure_angle_factor"]:.6f}).
Note the names: the sheet's (Gleason's, ISO's) drive side is the gear's convex flank, fegear's
`coast`. The data as a case file's `[pair]`:

{_pair_toml(kw)}

{table(["quantity", "sheet", "fegear", "fegear − sheet", "what it tests"], blank_rows(doc))}

What agrees: the pitch cones. The gear's pitch angle is within {dg * 60:+.1f}', its spiral angle
within {db * 60:+.1f}' and the cone distance within {da0:+.4f} in of the sheet's, from the
pinion's spiral angle, the offset, the gear diameter and face width and the cutter radius alone:
ISO 23509 method 1 is Gleason's own hypoid method. The rest, 5–10', is more than the sheet's
rounding to the minute (0.5'); it is of the size that the choice of the mean point moves (fegear
puts it at mid face of the gear; the sheet does not say where Gleason's iteration puts it), and
the sheet prints no pinion pitch angle or mean cone distance to tell.

What does not: the proportions and the taper. fegear uses the Gleason spiral-bevel proportions
(working depth 1.700 m = {b["working_depth_in"]:.4f} in, the gear addendum from the tooth ratio)
with standard taper (each member's root through its own pitch apex); the sheet is a hypoid of
deeper teeth (working depth 0.375 in = 1.864 / P, whole depth 0.422) with a tilted root (gear
dedendum angle 5°42' against fegear's {_dm(g["dedendum_angle"])}, root apex −0.16 in beyond the
crossing point against the pitch apex at {g["pitch_apex_beyond_crossing_in"]:+.3f} in). The root
and face angles, the diameters and the crown positions differ by what follows from these two
choices, and the pinion's also by its face: fegear's pinion face just covers the gear's
({p["face_width_in"]:.3f} in along its pitch line), the sheet's pinion is larger (outside
diameter 3.386 against {p["outside_diameter_in"]:.3f} in). fegear has no input for another depth
or taper: `[pair]` carries the design data, not a blank drawing (`docs/geometry/hypoid.md`, "Not
done"). The normal thickness at mid face is the sheet's chordal thickness of the finished gear
(thinned for 0.006–0.008 in of backlash), fegear's the arc thickness at zero backlash on its
shallower proportions.

![axial sections](hypoid_no16/sections.png)

`hypoid_no16/sections.png`: each member's face cone (solid) and root cone (dashed) across
fegear's face, as heights above fegear's pitch cone in the member's axial section: the sheet's
cones (red, through its crown and its root apex) against fegear's (blue). The gear's face cones
nearly coincide; the sheet's gear root falls faster towards the heel (the tilted root) and its
pinion's face stands higher (the larger pinion).

## 3. The gear's machine settings (part `gear_settings`: `{CMD} gear_settings`)

The settings fegear's synthesis fits to the gear of this blank (each flank through its mean point
with the designed normal, fegear's nominal roll), as `fegear settings` prints them, against the
sheet's gear finishing settings (inches, degrees-minutes; the sheet's point radii assume the
nominal diameter at the middle of the point width):

{
        table(
            [
                "setting",
                "sheet (gear, both flanks)",
                "fegear drive (gear concave)",
                "fegear coast (gear convex)",
            ],
            settings_rows(doc),
        )
    }

They are two ways of cutting the gear and agree only in kind. The sheet cuts both flanks in one
setup with a spread-blade cutter; fegear cuts each in its own, with the blade radius
{gs["drive"]["blade_radius_at_mean_point_in"]:.4f} in at the mean point on both, so its radials
and cradle angles differ per flank and its point radii are not the sheet's. The cradle angles
agree within {abs(abs(gs["coast"]["cradle_angle"]) - dm(s["gear"]["cradle_angle"])) * 60:.1f}'
on the convex flank (fegear's sign is negative for a right-hand gear; the sheet prints no sign),
the radials within {100 * (gs["drive"]["radial_in"] / s["gear"]["radial_in"] - 1):+.1f} % and
{100 * (gs["coast"]["radial_in"] / s["gear"]["radial_in"] - 1):+.1f} %. fegear generates its gear
with the machine root angle at its root angle ({_dm(gs["drive"]["machine_root_angle"])}: the
standard taper of §2) and the nominal roll cos δ_f / sin γ = {gs["drive"]["ratio_of_roll"]:.5f},
without blank offset or sliding base; the sheet's gear has its tilted root (69°07'), a roll of
0.99817 and a blank offset and sliding base of 0.225 and 0.070 in. The blade angles differ by
{gs["drive"]["blade_angle"] - dm(s["gear"]["blade_angle_outside"]):+.2f}° and
{gs["coast"]["blade_angle"] - dm(s["gear"]["blade_angle_inside"]):+.2f}°: fegear's follow from
the designed flank normal at the mean point in its own machine frame (root angle, roll, no blank
offset); the sheet's equal the pressure angles it prints, and its other settings differ with
them. The sheet's gear settings could be entered as fegear
`[machine.gear_*]` tables (`sliding_base`, `blank_offset` and `ratio_of_roll` are taken; the
machine centre to back needs the gear's mounting distance, which the copy does not give), but not
alone: the pinion's tables are required with them and are not in the copy.

## 4. The pinion, and the TCA (part `synthesis`: `{CMD} synthesis`)

Without the sheet's pinion settings, fegear would synthesize them (`fegear run` of the `[pair]`
above without `[machine]`: the local synthesis of Litvin and Zhang for a predesigned parabolic TE
of 8″, fegear's default targets). For these data it {"refuses" if refused else "accepts"} the
pair: {"`fegear run` exits with 2 and" if refused else ""} the message

    {err}

The drive side's equations have a root (residual 1e-12) at a pinion blank offset of metres and a
ratio of roll over a hundred: the generating motion has run off to infinity, a solution of the
equations and not a machine setup, and fegear refuses it, naming the settings and their bounds
(`fegear/geometry/bevel/synthesis.py`, `REACH_FACTOR`); the coast side has no solution from
fegear's starting point at all. fegear's pinion synthesis varies four settings (cutter radius,
ratio of roll, modified roll 2C, blank offset) with the machine root angle fixed at the pinion's
root angle and no tilt; the sheet's pinion, with 50°29' of spiral angle on a 1.500 in offset, is
cut with a cutter and setup of its own per flank on the No. 16, whose settings are on the page of
the sheet the copy does not hold.

So there is no TCA and no loaded analysis on this page: the source has none to compare with, its
pinion's settings are not available, and fegear's synthesis cannot find a pinion for the sheet's
blank data.

## Summary

{summary(doc)}
"""
    return reflow(out) + "\n"


def _heights(m: dict, z0: float, r0: float, ang: float, L: list[float]) -> list[float]:
    """Heights above fegear's pitch cone of member ``m`` (along its normal in the axial section)
    of the cone line through ``(z0, r0)`` at ``ang`` (deg), at cone distances ``L`` (in); z from
    the crossing point along the member's axis towards its back."""
    g = math.radians(m["pitch_angle"])
    tz = m["pitch_apex_beyond_crossing_in"]
    t = math.tan(math.radians(ang))
    k = math.cos(g) + math.sin(g) * t
    return [(r0 + (-tz + x * math.cos(g) - z0) * t - x * math.sin(g)) / k for x in L]


def _sections(ax, who: str, m: dict) -> None:
    """One member's face and root cones across its face, as heights above fegear's pitch cone
    against the cone distance: the sheet's (through its crown and its root apex) and fegear's."""
    s = SHEET
    a0, fw = m["outer_cone_distance_in"], m["face_width_in"]
    L = [a0 - fw, a0]
    ax.axhline(0.0, color="0.6", lw=0.8, ls=":")
    ax.axvline(m["mean_cone_distance_in"], color="0.6", lw=0.8, ls=":")
    for src, col, zc, rc, fa, ra, rz in (
        ("fegear", "C0", m["crown_to_crossing_in"], 0.5 * m["outside_diameter_in"],
         m["face_angle"], m["root_angle"], m["root_apex_beyond_crossing_in"]),
        ("sheet", "C3", s["crown_to_crossing_in"][who], 0.5 * s["outside_diameter_in"][who],
         dm(s["face_angle"][who]), dm(s["root_angle"][who]),
         s["root_apex_beyond_crossing_in"][who]),
    ):  # fmt: skip
        ax.plot(L, _heights(m, zc, rc, fa, L), color=col, lw=1.5, label=f"{src} face cone")
        ax.plot(L, _heights(m, -rz, 0.0, ra, L), color=col, lw=1.5, ls="--",
                label=f"{src} root cone")  # fmt: skip
    ax.set_xlabel(f"{who} cone distance (in): toe to heel of fegear's face")
    ax.set_ylabel("height above fegear's pitch cone (in)")
    ax.set_title(who)
    ax.grid(alpha=0.3)


def figures(doc: dict) -> None:
    b = doc["parts"]["blank"]["data"]
    pyplot = plt()
    fig, axs = pyplot.subplots(1, 2, figsize=(10, 4.2))
    _sections(axs[0], "gear", b["members"]["gear"])
    _sections(axs[1], "pinion", b["members"]["pinion"])
    axs[1].legend(fontsize=7, loc="upper left")
    save(fig, FIG / "sections.png")
