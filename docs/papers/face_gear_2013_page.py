"""The text and figures of ``face_gear_2013.md``, from the parts in ``face_gear_2013.json``.

:func:`render` is pure (the page's text from the JSON: ``tests/test_papers.py`` compares it with
the page); :func:`figures` draws the PNGs into ``docs/papers/face_gear_2013/``.
"""

from __future__ import annotations

import math

import numpy as np
from _parts import HERE, num, plt, reflow, save, seconds_text, table
from face_gear_2013_runs import (
    LOADS,
    PINION_TORQUE_NM,
    TABLE3_AB,
    TABLE3_ROWS,
)

ORDER = ("case", "path", "shapers", "errors_path", "loads", "dgamma", "dgamma_shaper",
         "dgamma_placed")  # fmt: skip
FIG = HERE / "face_gear_2013"
CMD = "python docs/papers/make_face_gear_2013.py"


def _cmd(part: str) -> str:
    return f"`{CMD} {part}`"


def _d(doc: dict, part: str) -> dict:
    return doc["parts"][part]["data"]


# --------------------------------------------------------------------------------------------
# derived numbers (each from the parts' data)
# --------------------------------------------------------------------------------------------


def best_shaper(shapers: list[dict], key: str = "geometric_ratio") -> dict:
    """The shaper whose a/b at Table 3's rows is nearest the paper's (least squares in log a/b),
    with the fractional N_s of the fit ``a/b ∝ (N_s − N1)^(−1/2)`` per row."""
    paper = np.array([a / b for a, b in TABLE3_AB])
    errs = []
    for s in shapers:
        r = np.array(s[key])
        errs.append(float(np.sqrt(np.mean(np.log(r / paper) ** 2))))
    i = int(np.argmin(errs))
    s0 = shapers[i]
    n1 = 25
    per_row = n1 + (s0["n_shaper"] - n1) * (np.array(s0[key]) / paper) ** 2
    return {
        "n_shaper": s0["n_shaper"],
        "rms_log": errs[i],
        "errors": errs,
        "per_row": per_row.tolist(),
    }


def delta_crossing(shapers: list[dict]) -> float | None:
    """The shaper (fractional) at which one δ gives both the paper's a and b: the mean δ implied
    by a (∝ k_a, grows with N_s) equals the mean δ implied by b (∝ k_b, nearly constant)."""
    ns = np.array([s["n_shaper"] for s in shapers], float)
    d = np.array([np.mean(s["delta_from_a_mm"]) - np.mean(s["delta_from_b_mm"]) for s in shapers])
    k = np.flatnonzero(np.sign(d[:-1]) != np.sign(d[1:]))
    if k.size == 0:
        return None
    i = int(k[0])
    return float(ns[i] - d[i] * (ns[i + 1] - ns[i]) / (d[i + 1] - d[i]))


def te_pp(run: dict) -> tuple[float | None, bool]:
    """``(TE p-p, reported)``: the run's headline loaded TE p-p, or, where the headline is null
    (the positions miss a handover), the p-p over its positions: a lower bound (False)."""
    if run["te_pp_loaded_arcsec"] is not None:
        return run["te_pp_loaded_arcsec"], True
    te = [x for x in run["te_loaded"] if x is not None]
    return (max(te) - min(te) if te else None), False


def doubling(runs: list[dict]) -> dict:
    """From a Δγ sweep: the aligned TE p-p, and per side the smallest |Δγ| at which the loaded
    TE p-p is twice it (linear interpolation over the reported values), the largest reported
    ratio, the largest lower bound where the headline is null, the first Δγ with a loaded pair
    on a face end, and the first Δγ whose TE p-p is not reported (and why)."""
    ok = [r for r in runs if "error" not in r]
    base = next(r for r in ok if r["dgamma_deg"] == 0.0)
    te0 = base["te_pp_loaded_arcsec"]
    out = {"te0": te0}
    for side, sgn in (("plus", 1.0), ("minus", -1.0)):
        seq = sorted(
            (r for r in ok if sgn * r["dgamma_deg"] >= 0), key=lambda r: abs(r["dgamma_deg"])
        )
        rep = [r for r in seq if te_pp(r)[1] and r["dgamma_deg"] != 0.0]
        ratio = [te_pp(r)[0] / te0 for r in rep]
        g = [r["dgamma_deg"] for r in rep]
        ratio, g = [1.0] + ratio, [0.0] + g  # from the aligned run
        at = None
        for i in range(1, len(ratio)):
            if ratio[i] >= 2.0 > ratio[i - 1]:
                at = g[i - 1] + (2.0 - ratio[i - 1]) * (g[i] - g[i - 1]) / (ratio[i] - ratio[i - 1])
                break
        unrep = [r for r in seq if not te_pp(r)[1]]
        lower = [te_pp(r)[0] / te0 for r in unrep if te_pp(r)[0] is not None]
        out[side] = {
            "double_at": at,
            "max_ratio": max(ratio[1:], default=None),
            "max_at": g[1 + int(np.argmax(ratio[1:]))] if len(ratio) > 1 else None,
            "lower_bound": max(lower) if lower else None,
            "unreported_from": unrep[0]["dgamma_deg"] if unrep else None,
            "lower_bound_at": unrep[int(np.argmax(lower))]["dgamma_deg"] if lower else None,
            "face_end_from": next((r["dgamma_deg"] for r in seq if _face_end(r)), None),
            "range": [seq[0]["dgamma_deg"], seq[-1]["dgamma_deg"]],
        }
    out["failed"] = [(r["dgamma_deg"], r["error"]) for r in runs if "error" in r]
    return out


def _face_end(run: dict) -> bool:
    """A loaded pair touches an end of the face: the face gear's inner or outer radius, or an
    end of the pinion's face."""
    return any(("inner end" in e or "outer end" in e or "face end" in e)
               for e in run.get("edges_seen", {}))  # fmt: skip


# --------------------------------------------------------------------------------------------
# page
# --------------------------------------------------------------------------------------------


def render(doc: dict) -> str:
    parts = [_head(doc), _table1(doc), _table2(doc), _table3(doc), _loads(doc), _dgamma(doc),
             _summary(doc)]  # fmt: skip
    return reflow("\n\n".join(p.rstrip() for p in parts if p)) + "\n"


def _head(doc: dict) -> str:
    return f"""# The face-gear paper, number by number

Wang, Niu and Zhang, *Study of Orthogonal Face Gear's Contact Spots and Transmission Errors*
(Sensors & Transducers, IFSA, 2013) study a face gear of 160 teeth driven by a spur pinion of 25:
the unloaded contact path (its Table 2), the contact ellipses along it at 350.14 N·m (Table 3),
the transmission error (TE) at three loads, and a shaft-angle error Δγ = ±0.02°, which they find
raises the TE amplitude 2.0-2.3 times. This page sets each of those numbers beside fegear's on the
seed case `cases/face_gear_nominal.toml` and its load cases, with the ratio fegear / paper where
both are numbers, and says where fegear disagrees and why that is most likely.

The page is generated: `{CMD}` runs every part below and rewrites it
({seconds_text(doc, ORDER)} of wall time on 2 shared cores, each part as last run, with the
artefact cache as it found it). Each table names the part that measured it; `{CMD} PART` reruns
one part and `{CMD} render` rewrites the page from `docs/papers/face_gear_2013.json`. The
measurements are in `docs/papers/face_gear_2013_runs.py`, this text in
`docs/papers/face_gear_2013_page.py`; the contact ellipses come from `fegear/tca/ellipse.py`.
Units: mm, N·m, arcsec (″), degrees."""


def _table1(doc: dict) -> str:
    c = _d(doc, "case")
    p = {k: (f"{v:g}" if isinstance(v, float) else v) for k, v in c["pair"].items()}
    width = c["pair"]["outer_radius_mm"] - c["pair"]["inner_radius_mm"]
    T_paper = 1100e3 / (2 * math.pi * 300 / 60)  # the paper's eqs. 6-7: P / ω, N·m
    rows = [
        ("face-gear teeth N2", "160", p["n_face_gear"], ""),
        ("pinion teeth N1", "25", p["n_pinion"], ""),
        ("module (mm)", "6.35", p["module_mm"], ""),
        ("pressure angle (°)", "25", p["pressure_angle_deg"], ""),
        ("shaft angle (°)", "90", p["shaft_angle_deg"], ""),
        ("face-gear 'inner diameter' (mm)", "471", p["inner_radius_mm"],
         "a radius: the pitch radius N2 m/2 = "
         f"{num(c['pitch_radius_mm'])} mm lies between 471 and 560"),
        ("face-gear 'external diameter' (mm)", "560", p["outer_radius_mm"], "a radius, as above"),
        ("face-gear width (mm)", "89", f"{width:g}", "560 − 471: the radial width of the teeth"),
        ("pinion width (mm)", "90", p["pinion_face_width_mm"], ""),
        ("blank thickness (mm)", "40", p["blank_thickness_mm"], ""),
        ("shaper teeth N_s", "not given", c["n_shaper"],
         "fegear's default N1 + 2; §3 finds what the paper's ellipses imply"),
        ("material", "structural steel", f"E {c['E_MPa']:g} MPa, ν {c['nu']:g}", ""),
        ("pinion torque of Table 3 (N·m)", "350.14", f"{c['pinion_torque_Nm']:g}",
         f"the paper's T = P/ω with 1100 kW at 300 rpm is {T_paper:.1f} N·m; 350.14 N·m is "
         f"{350.14 * 2 * math.pi * 300 / 60 / 1e3:.2f} kW"),
    ]  # fmt: skip
    return f"""## 1. Table 1: the case

The paper's Table 1 is `cases/face_gear_nominal.toml` (part `case`: {_cmd("case")}). The
analysis runs at fidelity `{c["fidelity"]}` level {c["level"]}, {c["n_positions"]} positions per
mesh cycle. Derived: pinion pitch radius {num(c["pinion_pitch_radius_mm"])} mm, base radius
{num(c["pinion_base_radius_mm"])} mm, base pitch {num(c["base_pitch_mm"])} mm. The model is
quasi-static: the paper's speeds (100, 200, 400 rpm) do not enter, as the paper itself finds
(its Fig. 14: speed has almost no effect on the TE).

{table(("quantity", "paper (Table 1)", "fegear case", "note"), rows)}"""


def _table2(doc: dict) -> str:
    d = _d(doc, "path")
    pp, p, fr = d["paper"], d["path"], d["frame"]
    X = np.asarray(p["points"])
    dX = X[-1] - X[0]
    ang = math.degrees(math.atan2(abs(dX[2]), math.hypot(dX[0], dX[1])))
    loc_p = -pp["y_mean"]
    rows = [
        ("path length in space (mm)", f"{num(pp['polyline_mm'])} (polyline); "
         f"{num(pp['chord_mm'])} (chord)", p["length_space_mm"],
         f"{p['length_space_mm'] / pp['polyline_mm']:.4f}"),
        ("path on the face-gear flank (mm)", "—", p["length_flank_mm"], "—"),
        ("slope against the pitch plane (°)", pp["angle_to_pitch_plane_deg"], ang,
         f"{ang / pp['angle_to_pitch_plane_deg']:.4f}"),
        ("distance from the face-gear axis (mm)", f"{num(-pp['y_max'])} … {num(-pp['y_min'])} "
         f"(mean {num(loc_p)})", p["x_mean"], f"{p['x_mean'] / loc_p:.4f}"),
        ("spread of that distance along the path (mm)", pp["y_max"] - pp["y_min"],
         p["x_range"][1] - p["x_range"][0], "—"),
        ("contact ratio (one pair's interval / angular pitch)", "—", p["contact_ratio"], "—"),
        ("what ends the path", "the face-gear tooth height", " → ".join(p["ends"]), "—"),
    ]  # fmt: skip
    e = _d(doc, "errors_path")
    label = {"dgamma_deg": "Δγ (°)", "dA2_mm": "Δq = ΔA2 (mm)", "dE_mm": "ΔE (mm)"}
    erows = [
        (label[name], f"{v['value']:+g}", v["x_mean"], v["x_mean"] - p["x_mean"],
         v["x_spread_mm"], v["contact_ratio"])
        for name, v in e.items()
    ]  # fmt: skip
    spread = max(v["x_spread_mm"] for v in e.values())
    c = fr["offsets_mm"]
    return f"""## 2. Table 2: the contact path

fegear traces one pair's unloaded contact over its whole contact interval (`fegear.tca.path`;
part `path`: {_cmd("path")}). Table 2 lists 14 points of the paper's path (mm):

{table(("quantity", "paper (Table 2)", "fegear", "ratio"), rows)}

**The frame mapping.** fegear's fixed frame: the face-gear axis is +z, the pitch plane z = 0, the
pinion axis runs along +x at the height of its pitch radius, so x is the distance from the
face-gear axis along the pinion axis. Table 2's x spans the path's height (12.0 mm against
fegear's {num(float(np.ptp(X[:, 2])))}), its y is near −498 (a distance from the face-gear axis),
its z spans the path's run across both axes; the slope of x against z is the 25° of the plane of
action. Table 3's short semi-axis b falls from row 4 to row 10, so the rows run from the
pinion-tip end of the path (where the pinion's involute is least curved and the ellipse widest)
to the face-gear tip. With the rows matched to fegear's path by arc length,

    x_paper = {c[0]:.2f} − z,   y_paper = {c[1]:.2f} − x,   z_paper = {c[2]:.2f} − y   (mm)

fits Table 2 with residuals of {num(fr["rms_mm"][0], 2)} / {num(fr["rms_mm"][1], 2)} /
{num(fr["rms_mm"][2], 2)} mm rms (largest {num(fr["max_abs_mm"][0], 2)} /
{num(fr["max_abs_mm"][1], 2)} / {num(fr["max_abs_mm"][2], 2)} mm) in x / y / z. The mapping is a
mirror image (its determinant is −1): the paper's pinion drives the other flank, or its frame is
left-handed. In x and z the paths agree to a few hundredths of a millimetre: the same straight
segment of the plane of action, the same length. The y residual is Table 2's own curvature: its
distance from the face-gear axis wanders by {num(pp["y_max"] - pp["y_min"], 3)} mm along the
path, fegear's by {num(p["x_range"][1] - p["x_range"][0], 2)} mm.

**The location: fegear disagrees by {num(p["x_mean"] - loc_p, 3)} mm.** fegear's path lies in the
plane x = {num(p["x_mean"], 6)} mm, the paper's at about {num(loc_p)} mm
(ratio {p["x_mean"] / loc_p:.4f}), {num(p["x_mean"] - loc_p, 3)} mm nearer the inner end in the
paper. Why fegear's path lies there: the pinion and the shaper that cut the face gear are spur
gears whose pitch cylinders touch the face gear's pitch plane along the same line, so they share
one plane of action; the pinion touches the face gear where the shaper's contact line with the
face gear crosses that plane, and it does so only where the shaper rolls on the face gear without
sliding, at the radius N2 m / 2 = 508 mm — for any number of shaper teeth (Litvin & Fuentes,
*Gear Geometry and Applied Theory*, 2004, the chapter on face-gear drives; part `shapers` below
measures {num(min(s["x_mean"] for s in _d(doc, "shapers")["shapers"]), 6)} …
{num(max(s["x_mean"] for s in _d(doc, "shapers")["shapers"]), 6)} mm for N_s = 26 … 34).
The paper does not define its frame's origin, so 498 mm may be an
offset of the origin alone; if it is a real location, an installation offset puts it there
(part `errors_path`: {_cmd("errors_path")}; one error at a time on the unloaded pair):

{
        table(
            (
                "error",
                "value",
                "path x mean (mm)",
                "shift (mm)",
                "x spread along the path (mm)",
                "contact ratio",
            ),
            erows,
        )
    }

The most likely reasons, in order: the origin of the paper's frame (the paper does not state
it), then a slight misassembly of its CAD model (an axial shift Δq of the face gear of
{_dq_text(doc)} mm puts fegear's path at the paper's radius, part `dgamma_placed`). Every one of
these errors keeps fegear's path in a plane (spread at most {num(spread, 2)} mm), so the
paper's {num(pp["y_max"] - pp["y_min"], 3)} mm wander of y along its path comes from its own
solution or frame, not from an installation error."""


def _dq_text(doc: dict) -> str:
    if "dgamma_placed" not in doc["parts"]:
        return "—"
    return f"{_d(doc, 'dgamma_placed')['dA2_mm']:+.3f}"


def _table3(doc: dict) -> str:
    t3 = _d(doc, "path")["table3"]["rows"]
    rows = [
        (r["row"], r["height_mm"], r["paper_a"], r["paper_b"], r["paper_ratio"],
         r["geometric_ratio"], r["paint_a"], r["paint_b"], r["hertz_a"], r["hertz_b"],
         1e3 * r["delta_from_a_mm"], 1e3 * r["delta_from_b_mm"])
        for r in t3
    ]  # fmt: skip
    sh = _d(doc, "shapers")["shapers"]
    best = best_shaper(sh)
    best_h = best_shaper(sh, "hertz_ratio")
    cross = delta_crossing(sh)
    paper = [a / b for a, b in TABLE3_AB]
    srows = [
        (s["n_shaper"], " → ".join(num(x, 3) for x in (s["geometric_ratio"][0],
                                                         s["geometric_ratio"][-1])),
         f"{best['errors'][i]:.3f}", 1e3 * float(np.mean(s["delta_from_a_mm"])),
         1e3 * float(np.mean(s["delta_from_b_mm"])),
         " → ".join(num(x, 3) for x in (s["hertz_ratio"][0], s["hertz_ratio"][-1])),
         s["x_mean"], s["contact_ratio"], s["mm_per_deg"] / 100.0,
         f"{s['dgamma_paint_at_inner_deg']:+.4f} / {s['dgamma_paint_at_outer_deg']:+.4f}")
        for i, s in enumerate(sh)
    ]  # fmt: skip
    s27 = next(s for s in sh if s["n_shaper"] == 27)
    return f"""## 3. Table 3: the ellipses along the path, and the shaper they imply

At every position of the unloaded TCA fegear now reports the contact ellipse
(`fegear/tca/ellipse.py`; `summary.json`: `positions[i].contact_ellipse`,
`cycle.contact_ellipses`): the principal relative curvatures k_a ≤ k_b of the two flanks,
Litvin's instantaneous ellipse for an approach δ,

    a = sqrt(2δ / k_a),   b = sqrt(2δ / k_b),   a / b = sqrt(k_b / k_a)

(the paper's eq. 5; Litvin & Fuentes 2004, the chapter "Mating Surfaces: Curvature Relations,
Contact Ellipse": the boundary of the region where the separation of the flanks, ½(k_a ξ² +
k_b η²) in the principal axes, is below δ), and the Hertz ellipse of one pair carrying the
whole load (Johnson 1985 §4.2). The axis ratio a/b does not depend on δ: it is the shape the
curvatures give. fegear's rows are its path at the arc-length fraction of each Table 3 row (part
`path`; heights above the pitch plane; δ = 6.32 µm, the customary paint thickness; Hertz at
{PINION_TORQUE_NM} N·m; the last two columns: the δ that the paper's a, and its b, each imply
through a = sqrt(2δ/k_a) on fegear's curvatures):

{
        table(
            (
                "row",
                "height (mm)",
                "paper a",
                "paper b",
                "paper a/b",
                "fegear a/b = √(k_b/k_a)",
                "Litvin a (6.32 µm)",
                "Litvin b",
                "Hertz a",
                "Hertz b",
                "δ from paper a (µm)",
                "δ from paper b (µm)",
            ),
            rows,
        )
    }

**fegear disagrees with the shape: a/b {num(t3[0]["geometric_ratio"], 3)} → {
        num(t3[-1]["geometric_ratio"], 3)
    } against the paper's {num(paper[0], 3)} → {num(paper[-1], 3)}
(ratio {t3[0]["geometric_ratio"] / paper[0]:.2f} → {t3[-1]["geometric_ratio"] / paper[-1]:.2f}).**
Both grow along the path the same way (the pinion's involute curves less toward its tip), but the
paper's ellipses are about half as long for their width. The Hertz ellipse of the load is even
longer (a/b {num(t3[0]["hertz_ratio"], 3)} → {num(t3[-1]["hertz_ratio"], 3)}), so Table 3 is not
a Hertz ellipse of fegear's curvatures either. The most likely reason is the shaper, which the
paper does not give. Across the profile the curvature is the pinion's involute (k_b does not
depend on N_s); along the face the face gear is bent away from the pinion by the shaper's
excess teeth, k_a ∝ N_s − N1 (tested: `tests/test_tca_ellipse.py`), so a/b ∝ (N_s − N1)^(−1/2).
The sweep (part `shapers`: {_cmd("shapers")}; per shaper: a/b at rows 4 and 10, the rms of
log(fegear/paper) over the 7 rows, the mean δ each of the paper's a and b implies, the Hertz
a/b, where the unloaded path lies, the contact ratio, how far it moves per 0.01° of Δγ, and the
Δγ at which the 6.32 µm ellipse's end reaches the inner / outer end of the face):

{
        table(
            (
                "N_s",
                "a/b rows 4 → 10",
                "rms log error",
                "δ from a (µm)",
                "δ from b (µm)",
                "Hertz a/b rows 4 → 10",
                "path x (mm)",
                "contact ratio",
                "mm per 0.01° Δγ",
                "Δγ to the inner / outer end (°)",
            ),
            srows,
        )
    }

The paper's shapes point to **N_s = {best["n_shaper"]}** (rms log error {best["rms_log"]:.3f};
row by row the fit a/b ∝ (N_s − 25)^(−1/2) gives N_s = {num(min(best["per_row"]), 3)} …
{num(max(best["per_row"]), 3)}: the paper's a/b grows faster along the path than an involute
pinion's curvature allows on any shaper). Read as Hertz ellipses they would need N_s =
{best_h["n_shaper"]} or more (rms {best_h["rms_log"]:.3f} at the end of the sweep). One δ gives
both of the paper's a and b where the two δ columns cross, at N_s ≈ {num(cross, 3)}
(δ ≈ {
        num(
            1e3
            * float(
                np.mean(next(s for s in sh if s["n_shaper"] == best["n_shaper"])["delta_from_b_mm"])
            ),
            2,
        )
    } µm): Table 3 is consistent with Litvin's instantaneous ellipse on a
shaper of about {round(cross) if cross else best["n_shaper"]} teeth with δ of a few micrometres,
not with 6.32 µm or with the Hertz approach of the load ({
        num(1e3 * t3[0]["hertz_approach_mm"], 3)
    } µm at N_s = 27). The path stays at {num(s27["x_mean"], 5)} mm for every shaper; a larger
shaper moves the bearing less per Δγ (section 5). `face_gear_2013/ellipses.png` draws the path on
the face-gear flank with both ellipses at every tenth sample and the paper's ellipses at its rows
(the paper's Fig. 6); `face_gear_2013/shapers.png` the a/b sweep.

![path and ellipses](face_gear_2013/ellipses.png)

![shaper sweep](face_gear_2013/shapers.png)"""


def _loads(doc: dict) -> str:
    L = _d(doc, "loads")
    rows = []
    for name, t2 in LOADS:
        r = L[name]
        rows.append((name, f"{t2:.0e}", r["te_pp_loaded_arcsec"], r["te_pp_unloaded_arcsec"],
                     r["lag_mean_arcsec"], r["contact_ratio_loaded"], r["max_pairs_in_contact"],
                     r["p_max_MPa"], r["semi_major_max_mm"], r["semi_minor_max_mm"]))  # fmt: skip
    te = [L[n]["te_pp_loaded_arcsec"] for n, _ in LOADS]
    grows = all(b > a for a, b in zip(te, te[1:], strict=False))
    light = L["light"]
    paper_rad = (9.6e-5, 9.9e-5)
    paper_as = [x * 180 / math.pi * 3600 for x in paper_rad]
    return f"""## 4. TE and contact ratio at the three loads

The paper applies 5e5, 3e6 and 6e6 N·mm to the face gear (light, moderate, heavy:
`cases/face_gear_load_light.toml`, `_moderate`, `_heavy`) and finds that "the fluctuation range
of the error curves becomes larger as the load is high" (its Fig. 13, no numbers). fegear at the
cases' fidelity (part `loads`: {_cmd("loads")}; TE p-p over the usable positions; the mean
elastic lag of the face gear; the largest equivalent-ellipse semi-axes of a loaded patch):

{
        table(
            (
                "load",
                "T2 (N·mm)",
                "TE p-p loaded (″)",
                "TE p-p unloaded (″)",
                "mean lag (″)",
                "contact ratio loaded",
                "max pairs",
                "p_max (MPa)",
                "largest patch a (mm)",
                "largest patch b (mm)",
            ),
            rows,
        )
    }

**The trend agrees:** the loaded TE p-p {"grows" if grows else "does NOT grow"} with the load
({" → ".join(num(x, 3) for x in te)}″, ×{te[-1] / te[0]:.2f} from light to heavy), with the loaded
contact ratio and the patch: a heavier load closes the second pair earlier and longer (the
unloaded pair is conjugate, its TE zero to round-off, so every arcsecond of TE here is elastic).

**The size disagrees.** The paper's only TE number is from its speed study at the light load:
"the absolute differences of adjacent peaks ... are all between 9.6E-5 rad and 9.9E-5 rad", that
is {num(paper_as[0], 3)}-{num(paper_as[1], 3)}″, against fegear's loaded TE p-p of
{num(light["te_pp_loaded_arcsec"], 3)}″ there (ratio
{light["te_pp_loaded_arcsec"] / paper_as[0]:.3f}) and a mean elastic lag of only
{num(light["lag_mean_arcsec"], 3)}″. A quasi-static elastic pair of this size cannot vary by
{num(paper_as[0], 2)}″ ({num(paper_as[0] / 206264.8 * 508.0, 2)} mm at the 508 mm pitch
radius) at a light load when its whole elastic deflection is a few arcseconds. The paper's
figure comes from a dynamic ABAQUS run driven at a speed with a loading ramp (its Fig. 3) in
which the driven face gear is free to turn: its "peaks" most likely hold the rigid-body
oscillation of the face gear under the ramp and the meshing impacts, not the static TE. fegear's
model is quasi-static by design (speed does not enter); it reproduces the trend, not that
amplitude. `face_gear_2013/te_loads.png`: the loaded TE curves.

![TE at three loads](face_gear_2013/te_loads.png)"""


def _sweep_rows(runs: list[dict], te0: float) -> list[tuple]:
    rows = []
    for r in runs:
        if "error" in r:
            rows.append((f"{r['dgamma_deg']:+.2f}", r["error"][:170], "", "", "", "", "", ""))
            continue
        pg = r["pattern_gear"]
        edges = ", ".join(f"{k} ×{v}" for k, v in sorted(r["edges_seen"].items())) or "none"
        te, rep = te_pp(r)
        te_text = num(te) if rep else f"not reported; ≥ {num(te)} over the positions"
        rows.append((f"{r['dgamma_deg']:+.2f}", te_text,
                     f"{te / te0:.2f}" + ("" if rep else " (≥)"), r["contact_ratio_loaded"],
                     r["contact_ratio_unloaded"], pg["face_mm"], r["te_pp_unloaded_arcsec"],
                     edges))  # fmt: skip
    return rows


def _dgamma(doc: dict) -> str:
    D = _d(doc, "dgamma")["runs"]
    dd = doubling(D)
    te0 = dd["te0"]
    g = {r["dgamma_deg"]: r for r in D if "error" not in r}
    p2, m2 = g.get(0.02), g.get(-0.02)
    sh = _d(doc, "dgamma_shaper")
    pl = _d(doc, "dgamma_placed")
    ds, dp = doubling(sh["runs"]), doubling(pl["runs"])
    heads = ("Δγ (°)", "TE p-p loaded (″)", "ratio to Δγ = 0", "contact ratio loaded",
             "contact ratio unloaded", "pattern centre on the face gear, radius (mm)",
             "TE p-p unloaded (″)", "loaded pairs on a flank edge (pair-positions)")  # fmt: skip

    def dbl(x):
        return "not reached" if x is None else f"{x:+.3f}°"

    def centre(r):
        return None if r is None else r["pattern_gear"]["face_mm"]

    def ratio(r):
        return None if r is None else te_pp(r)[0] / te0

    sign_rows = [
        ("definition", "\"staggered shaft installation error\", γ = +0.02°, −0.02° (sign not "
         "defined)", "Δγ: the shaft angle becomes γ + Δγ, the pinion turned about the common "
         "perpendicular through the crossing point"),
        ("+0.02°", "\"the tooth contact position is moving to face gear's inner surface and the "
         "edge contact is easily happened\"", "the bearing moves toward the **outer** end "
         f"(pattern centre {num(centre(p2))} mm against {num(centre(g[0.0]))} mm)"),
        ("−0.02°", "\"the face gear contact trajectory moves from its inner diameter to outer "
         "diameter\"", f"toward the **inner** end ({num(centre(m2))} mm)"),
        ("TE amplitude at ±0.02°", "2.0-2.3 times the aligned one", f"{num(ratio(p2), 3)} "
         f"times at +0.02°, {num(ratio(m2), 3)} at −0.02° (moderate load)"),
    ]  # fmt: skip
    drows = []
    for label, d in (("N_s = 27, bearing at 508 mm (the seed case)", dd),
                     (f"N_s = {sh['n_shaper']} (the paper's ellipses), bearing at 508 mm", ds),
                     (f"N_s = 27, bearing at {num(pl['x_mean'])} mm (Δq = {pl['dA2_mm']:+.3f} "
                      "mm, the paper's Table 2)", dp)):  # fmt: skip
        drows.append((label, d["te0"], dbl(d["plus"]["double_at"]), dbl(d["minus"]["double_at"]),
                      f"{_r(d['plus'])} / {_r(d['minus'])}",
                      _unreported_text(d), _edge_text(d)))  # fmt: skip
    cr = [r["contact_ratio_loaded"] for r in D if "error" not in r and r["contact_ratio_loaded"]]
    return f"""## 5. Δγ = ±0.02°: the sign, the ratios, and what doubles the TE

**The sign conventions side by side** (the paper's words; fegear at the moderate load, part
`dgamma` below):

{table(("", "paper", "fegear (`fegear.geometry.pair_placement`, `docs/tca`)"), sign_rows)}

For the same sign the two move the bearing in opposite directions: the paper's +0.02° is fegear's
−0.02° (a shaft angle closed rather than opened, or the error taken about the other sense of the
common perpendicular; the paper does not define it). This is a convention, not a disagreement
about the physics. Read in the paper's convention fegear's ratios are {num(ratio(m2), 3)} (its
+0.02°) and {num(ratio(p2), 3)} (its −0.02°).

**The ratios disagree.** The sweep at the moderate load (part `dgamma`: {_cmd("dgamma")}; the
seed case `cases/face_gear_load_moderate.toml` with Δγ; ratio = TE p-p / TE p-p at Δγ = 0 =
{num(te0, 3)}″; where the headline is null because the positions miss a handover whose unloaded
contact ratio is below 1, the p-p over the positions is given as a lower bound):

{table(heads, _sweep_rows(D, te0))}

At ±0.02° the ratios are {num(ratio(p2), 3)} (+) and {num(ratio(m2), 3)} (−), against the
paper's 2.0-2.3. The physics, in plain words:

- A face gear driven by an **involute** pinion gets no TE from misalignment: the pinion's
  involute keeps the transmission function linear when the axes move, and only the bearing
  contact shifts (Litvin & Fuentes 2004, the chapter on face-gear drives; Litvin, Fuentes,
  Zanzi, Pontiggia, Handschuh, *Face-gear drive with spur involute pinion: geometry,
  generation by a worm, stress analysis*, Comput. Methods Appl. Mech. Engrg. 191 (2002)
  2785-2813). fegear's unloaded TE p-p column shows it: zero to round-off at every Δγ where
  the contact stays inside the flanks (unloaded contact ratio at least 1; below it a pair runs
  off an edge before the next takes over, the edge contact is no involute contact, and the
  unloaded TE shows a few 1e-4″ or is not reported where the positions miss the handover).
- What is left under load is the elastic TE, and its amplitude follows the loaded contact ratio:
  where two pairs share the load the mesh is stiffer than where one carries it alone, and the
  TE p-p is that difference. Δγ slides the bearing along the face, where the path on the face
  gear is longer (toward the inner end) or shorter (toward the outer end): the loaded contact
  ratio runs from {num(max(cr), 3)} to {num(min(cr), 3)} over the sweep and the TE p-p
  follows it, down toward the inner end, up (not steadily) toward the outer.
- Edge contact at a face end does not by itself double the TE amplitude: the patch is cut and
  its pressure rises, but the mesh stiffness changes little while the contact ratio stays high.
  The amplitude jumps where the contact ratio of the unloaded pair falls below 1:
  then a pair runs off a tip before the next takes over, and the TE has a step at the
  handover that a load must bridge.

**What it takes to double the TE amplitude.** The same sweep on the shaper the paper's ellipses
imply (part `dgamma_shaper`: {_cmd("dgamma_shaper")}) and with the seed shaper's bearing placed
where Table 2 puts it (part `dgamma_placed`: {_cmd("dgamma_placed")}; the face gear shifted
axially by Δq = {pl["dA2_mm"]:+.3f} mm so that the unloaded path lies at {num(pl["x_mean"])} mm):

{
        table(
            (
                "configuration",
                "TE p-p at Δγ = 0 (″)",
                "doubled at Δγ > 0",
                "doubled at Δγ < 0",
                "largest reported ratio (+ / −)",
                "headline not reported from (+ / −)",
                "first loaded contact on a face end (+ / −)",
            ),
            drows,
        )
    }

{_doubling_text(dd, ds, dp, sh["n_shaper"])}

`face_gear_2013/dgamma.png` draws the TE p-p ratio, the contact ratio and the pattern centre
against Δγ for the three configurations.

![TE against dgamma](face_gear_2013/dgamma.png)

The sweeps of the other two configurations:

{table(heads, _sweep_rows(sh["runs"], ds["te0"]))}

{table(heads, _sweep_rows(pl["runs"], dp["te0"]))}"""


def _r(e: dict) -> str:
    if e["max_ratio"] is None:
        return "—"
    return f"{e['max_ratio']:.2f} at {e['max_at']:+.2f}°"


def _unreported_text(d: dict) -> str:
    def t(e):
        if e["unreported_from"] is None:
            return "—"
        return (f"{e['unreported_from']:+.2f}° (ratio ≥ {e['lower_bound']:.2f} at "
                f"{e['lower_bound_at']:+.2f}°)")  # fmt: skip

    return f"{t(d['plus'])} / {t(d['minus'])}"


def _doubling_text(dd: dict, ds: dict, dp: dict, ns: int) -> str:
    """The answer to "what doubles the TE amplitude", from the three sweeps."""
    reached = [(name, side, d[side]["double_at"]) for name, d in
               (("the seed case", dd), (f"N_s = {ns}", ds), ("the placed bearing", dp))
               for side in ("plus", "minus") if d[side]["double_at"] is not None]  # fmt: skip
    if reached:
        what = "; ".join(f"{n} at {x:+.3f}°" for n, _, x in reached)
        head = f"The reported TE amplitude doubles on {what}."
    else:
        best = max((d[s]["max_ratio"] or 0.0, n) for n, d in
                   (("the seed case", dd), (f"N_s = {ns}", ds), ("the placed bearing", dp))
                   for s in ("plus", "minus"))  # fmt: skip
        head = (
            f"No configuration doubles the reported TE amplitude within the sweeps (largest "
            f"ratio {best[0]:.2f}, {best[1]})."
        )
    cfg = (("the seed case", dd), (f"N_s = {ns}", ds), ("the placed bearing", dp))
    below = "; ".join(
        f"{n}: {d[sd]['unreported_from']:+.2f}° (≥ {d[sd]['lower_bound']:.2f} at "
        f"{d[sd]['lower_bound_at']:+.2f}°)"
        for n, d in cfg
        for sd in ("plus", "minus")
        if d[sd]["unreported_from"] is not None
    )
    return (
        f"{head} The paper's ±0.02° is far from enough on every configuration. What can double "
        "it is the handover: past the Δγ where the unloaded contact ratio falls below 1 one pair "
        "runs off a face end or a tip before the next takes over, the TE has a step there, and "
        "the p-p over the positions alone (a lower bound: 25 positions miss the step) climbs "
        f"toward twice the aligned amplitude — {below}. So, to double the TE amplitude of this "
        "pair at the moderate load, Δγ must push the bearing off the face until the contact "
        "ratio drops below 1; a bearing placed nearer that end gets there sooner, and a larger "
        "shaper needs a larger Δγ for the same shift (section 3: mm per 0.01°). The tip/root "
        "clearance bounds how far one can go (refused runs in the sweeps)."
    )


def _edge_text(d: dict) -> str:
    def t(x):
        return "none" if x is None else f"{x:+.2f}°"

    return f"{t(d['plus']['face_end_from'])} / {t(d['minus']['face_end_from'])}"


def _summary(doc: dict) -> str:
    pp, p = _d(doc, "path")["paper"], _d(doc, "path")["path"]
    t3 = _d(doc, "path")["table3"]["rows"]
    sh = _d(doc, "shapers")["shapers"]
    cross = delta_crossing(sh)
    L = _d(doc, "loads")
    light = L["light"]
    paper_as = 9.6e-5 * 180 / math.pi * 3600
    D = {r["dgamma_deg"]: r for r in _d(doc, "dgamma")["runs"] if "error" not in r}
    te0 = D[0.0]["te_pp_loaded_arcsec"]
    r2 = [D[g]["te_pp_loaded_arcsec"] / te0 for g in (0.02, -0.02) if g in D]
    dd = doubling(_d(doc, "dgamma")["runs"])
    pl = _d(doc, "dgamma_placed")
    lines = [
        f"- **Path location** (section 2): {num(p['x_mean'])} mm from the face-gear axis (any "
        f"shaper, error-free) against about {num(-pp['y_mean'])} mm; the paper's frame origin is "
        f"not defined, an axial shift of the face gear of {pl['dA2_mm']:+.3f} mm would also "
        "explain it. Length, direction and the path's straight run agree to a few hundredths of "
        "a millimetre.",
        f"- **Ellipse shape** (section 3): fegear's a/b on the seed shaper (N_s = 27) is "
        f"{min(r['geometric_ratio'] / r['paper_ratio'] for r in t3):.2f}-"
        f"{max(r['geometric_ratio'] / r['paper_ratio'] for r in t3):.2f} times the paper's; the "
        f"paper's a and b are both met with one δ on a shaper of N_s ≈ {num(cross, 3)}, a datum "
        "the paper does not give.",
        f"- **TE size** (section 4): the trend with the load agrees; the paper's "
        f"{num(paper_as, 3)}″ peak differences at the light load are "
        f"{paper_as / light['te_pp_loaded_arcsec']:.0f} times fegear's static loaded TE p-p and "
        "most likely dynamic.",
        "- **Δγ** (section 5): opposite sign conventions; no TE from misalignment in fegear "
        "(Litvin's result for an involute pinion); loaded ratios "
        + " and ".join(f"{x:.2f}" for x in r2)
        + " at ±0.02°, not 2.0-2.3. The amplitude "
        + (
            "doubles on the seed design at "
            + " / ".join(
                f"{dd[k]['double_at']:+.3f}°"
                for k in ("plus", "minus")
                if dd[k]["double_at"] is not None
            )  # fmt: skip
            if any(dd[k]["double_at"] is not None for k in ("plus", "minus"))
            else "does not double where fegear reports it (largest ratio "
            f"{max(dd[k]['max_ratio'] for k in ('plus', 'minus')):.2f}); it approaches twice "
            "only where Δγ drives the unloaded contact ratio below 1 (from "
            f"{dd['plus']['unreported_from']:+.2f}° on the seed design, lower bound "
            f"{dd['plus']['lower_bound']:.2f})"
        )
        + ".",
    ]
    return "## 6. Where fegear and the paper disagree\n\n" + "\n".join(lines)


# --------------------------------------------------------------------------------------------
# figures
# --------------------------------------------------------------------------------------------


def figures(doc: dict) -> None:
    P = doc["parts"]
    if "path" in P:
        _fig_ellipses(P["path"]["data"])
    if "shapers" in P:
        _fig_shapers(P["shapers"]["data"]["shapers"])
    if "loads" in P:
        _fig_loads(P["loads"]["data"])
    if all(k in P for k in ("dgamma", "dgamma_shaper", "dgamma_placed")):
        _fig_dgamma(P)


def _fig_ellipses(d: dict) -> None:
    p = d["path"]
    pyplot = plt()
    fig, ax = pyplot.subplots(figsize=(9, 4.6))
    b = p["gear_bounds"]
    v = np.asarray(b["v"])
    ax.plot(np.r_[v, v[::-1], v[:1]], np.r_[b["fillet"], b["tip"][::-1], b["fillet"][:1]], "k-",
            lw=0.8)  # fmt: skip
    ax.plot(p["gear_radius_mm"], p["gear_height_mm"], "r-", lw=1.5, label="unloaded path")
    for k in range(0, len(p["outline_paint"]), 10):
        o = np.asarray(p["outline_paint"][k])
        h = np.asarray(p["outline_hertz"][k])
        ax.plot(o[:, 0], o[:, 1], "-", color="tab:blue", lw=0.8,
                label="Litvin, 6.32 µm" if k == 0 else None)  # fmt: skip
        ax.plot(h[:, 0], h[:, 1], "--", color="tab:green", lw=0.8,
                label=f"Hertz, {PINION_TORQUE_NM} N·m" if k == 0 else None)  # fmt: skip
    for i, o in enumerate(p["outline_paper"]):
        o = np.asarray(o)
        ax.plot(o[:, 0], o[:, 1], ":", color="tab:purple", lw=1.2,
                label="paper, Table 3 (fegear's axes)" if i == 0 else None)  # fmt: skip
    ax.set_xlabel("radius L (mm)")
    ax.set_ylabel("height above the pitch plane (mm)")
    ax.set_title("seed face gear (N_s = 27): unloaded path and contact ellipses on the face-gear "
                 "flank (every 10th sample)", fontsize=9)  # fmt: skip
    ax.legend(fontsize=7, loc="upper right")
    save(fig, FIG / "ellipses.png")


def _fig_shapers(sh: list[dict]) -> None:
    pyplot = plt()
    fig, ax = pyplot.subplots(figsize=(7, 4))
    rows = [k + 1 for k in TABLE3_ROWS]
    for s in sh:
        ax.plot(rows, s["geometric_ratio"], "-", lw=1, label=f"N_s = {s['n_shaper']}")
    ax.plot(rows, [a / b for a, b in TABLE3_AB], "ko--", lw=1.5, label="paper, Table 3")
    ax.set_xlabel("row of Table 2 / 3")
    ax.set_ylabel("a / b = sqrt(k_b / k_a)")
    ax.set_yscale("log")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title("ellipse shape along the path: the n_shaper sweep against Table 3", fontsize=9)
    save(fig, FIG / "shapers.png")


def _fig_loads(L: dict) -> None:
    pyplot = plt()
    fig, ax = pyplot.subplots(figsize=(7, 4))
    for name, t2 in LOADS:
        r = L[name]
        ax.plot(r["phi_deg"], r["te_loaded"], "o-", ms=3, label=f"{name}, {t2:.0e} N·mm")
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("loaded TE (arcsec)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("seed face gear: loaded TE over one mesh cycle at the paper's three loads",
                 fontsize=9)  # fmt: skip
    save(fig, FIG / "te_loads.png")


def _fig_dgamma(P: dict) -> None:
    pyplot = plt()
    fig, axes = pyplot.subplots(1, 3, figsize=(12, 3.8))
    ns = P["dgamma_shaper"]["data"]["n_shaper"]
    configs = (("dgamma", "N_s 27, 508 mm"), ("dgamma_shaper", f"N_s {ns}, 508 mm"),
               ("dgamma_placed", "N_s 27, at Table 2's radius"))  # fmt: skip
    for i, (key, label) in enumerate(configs):
        runs = [r for r in P[key]["data"]["runs"] if "error" not in r]
        te0 = next(r["te_pp_loaded_arcsec"] for r in runs if r["dgamma_deg"] == 0.0)
        rep = [(r["dgamma_deg"], te_pp(r)[0] / te0) for r in runs if te_pp(r)[1]]
        low = [(r["dgamma_deg"], te_pp(r)[0] / te0) for r in runs if not te_pp(r)[1]]
        c = f"C{i}"
        axes[0].plot(*zip(*rep, strict=True), "o-", ms=3, color=c, label=label)
        if low:
            axes[0].plot(*zip(*low, strict=True), "^", ms=6, mfc="none", color=c,
                         label="lower bound (handover missed)" if i == 0 else None)  # fmt: skip
        g = [r["dgamma_deg"] for r in runs]
        axes[1].plot(g, [r["contact_ratio_loaded"] or np.nan for r in runs], "o-", ms=3, color=c)
        axes[2].plot(g, [r["pattern_gear"]["face_mm"] or np.nan for r in runs], "o-", ms=3,
                     color=c)  # fmt: skip
    axes[0].axhline(2.0, color="k", lw=0.8, ls="--")
    axes[0].vlines([-0.02, 0.02], 2.0, 2.3, color="tab:red", lw=4, alpha=0.5,
                   label="paper, 2.0-2.3 at ±0.02°")  # fmt: skip
    axes[0].set_ylabel("TE p-p / TE p-p at Δγ = 0")
    axes[1].set_ylabel("loaded contact ratio")
    axes[2].set_ylabel("pattern centre on the face gear, radius (mm)")
    for ax in axes:
        ax.set_xlabel("Δγ (deg)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("moderate load (3e6 N·mm): loaded TE, contact ratio and bearing against Δγ",
                 fontsize=9)  # fmt: skip
    save(fig, FIG / "dgamma.png")


__all__ = ["render", "figures", "best_shaper", "delta_crossing", "doubling", "te_pp"]
