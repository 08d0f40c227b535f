"""The CalculiX cross-check as tables: ``benchmarks/results/calculix.json`` into markdown.

``benchmarks/calculix_crosscheck.py`` runs CalculiX along a ladder of contact element sizes and
fegear beside it, and writes the measured rows into ``calculix.json``; this module turns them into
the benchmark's page (:func:`markdown`) and into the section of ``docs/validation.md``
(:func:`validation_section`, written by ``docs/make_validation.py``). Nothing here runs a solver:
every number comes from the JSON.

Comparisons (``docs/calculix.md``):

- CalculiX's own convergence: the change of each quantity between its two finest sizes (load
  shares: the largest difference over the pairs; lag and interior p_max: relative).
- fegear against CalculiX's finest size: load shares (largest difference, a pair missing from
  one side counting as share 0), interior p_max per pair (relative; fegear's edge rule on both
  sides, ``fegear.ltca.edges``), loaded TE (relative).
- Time at equal accuracy: the coarsest CalculiX size from which on every finer size agrees with
  the finest as closely as fegear does (load shares and lag), its time over fegear's cold time.
- With three or more CalculiX sizes converging monotonically, the loaded TE is also extrapolated
  to zero element size (:func:`richardson`) and fegear is checked against that value, with its
  grid convergence index as CalculiX's remaining uncertainty.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import NamedTuple

__all__ = [
    "GEAR_SECTIONS",
    "Extrapolation",
    "ccx_movement",
    "criteria",
    "equal_accuracy",
    "gear_comparison",
    "markdown",
    "richardson",
    "validation_section",
]

#: Gear sections of ``calculix.json``: key -> title.
GEAR_SECTIONS = {
    "fzg": "FZG type C, 200 N·m on the gear",
    "face_gear": "Seed face gear 160/25, 350.14 N·m on the pinion",
    "spiral_bevel": "Spiral bevel 12/36, 100 N·m on the pinion",
}
#: The acceptance bounds of the cross-check against CalculiX: load shares (absolute), interior
#: p_max and loaded TE (relative).
SHARE_TOL, P_TOL, TE_TOL = 0.03, 0.05, 0.05


def _pct(x: float | None) -> str:
    return "—" if x is None else f"{100 * x:+.2f}%"


def _f(x: float | None, fmt: str) -> str:
    return "—" if x is None else format(x, fmt)


def _ab(a: float, b: float) -> str:
    """Semi-axes ``a × b`` (— where the patch is not resolved: no width)."""
    return "—" if not b else f"{a:.2f} × {b:.3f}"


def _timing(r: Mapping) -> str:
    """A note on how a run's time was taken, when not by the benchmark itself."""
    return f" ({r['timing']})" if r.get("timing") else ""


def _load(r: Mapping) -> str:
    return _f(r.get("load_before"), ".2f")


def positions(section: Mapping) -> list[tuple[str, dict]]:
    """The positions of a gear section: ``(label, rows)`` (the entries that are dicts)."""
    return [(k, v) for k, v in section.items() if isinstance(v, dict) and "ccx" in v]


def _ccx_ok(rows: Mapping) -> list[dict]:
    """CalculiX rows that finished, coarse to fine."""
    return sorted((r for r in rows["ccx"] if "result" in r), key=lambda r: -r["element_mm"])


def _ccx_shares(r: Mapping) -> dict:
    return {(p["k"], p["j"]): p["load_share"] for p in r["result"]["pairs"]}


def _fe_shares(r: Mapping) -> dict:
    return {(p["k"], p["j"]): p["share"] for p in r["pairs"]}


def _dev(a: Mapping, b: Mapping) -> float:
    """Largest difference of two sets of load shares (a pair missing from one: share 0)."""
    return max(abs(a.get(k, 0.0) - b.get(k, 0.0)) for k in set(a) | set(b))


def _rel(x: float | None, ref: float | None) -> float | None:
    return None if x is None or not ref else x / ref - 1.0


def _ccx_interior(r: Mapping) -> dict:
    return {(p["k"], p["j"]): p["p_interior_MPa"] for p in r["result"]["pairs"]}


def _pressure_integral(r: Mapping) -> dict:
    """Per pair of a CalculiX row: the integral of the pressure it was read with over its
    contact force; absent where not read. Rows read from the integration points
    (``ip_force_N``, :mod:`fegear.export.ccx_results`) integrate their points' pressure
    (1 within the print's digits); older rows the nodal ``CPRESS`` over tributary areas
    (``nodal_force_N``: above 1 where faces are partly in contact)."""
    out = {}
    for p in r["result"]["pairs"]:
        f = p.get("ip_force_N") or p.get("nodal_force_N")
        if f and p.get("normal_force_N"):
            out[(p["k"], p["j"])] = f / p["normal_force_N"]
    return out


def _loaded(shares: Mapping, floor: float = 0.05) -> int:
    """Pairs carrying more than ``floor`` of the torque."""
    return sum(1 for s in shares.values() if s > floor)


def not_run(section: Mapping, label: str) -> str:
    """Why a position has no CalculiX row: the cost of the case's runs at its other positions."""
    runs = [f"{r['element_mm']} mm at {lab}: {r['ccx_s']:.0f} s, {_f(r['peak_MB'], '.0f')} MB"
            for lab, rows in positions(section) if lab != label for r in _ccx_ok(rows)]  # fmt: skip
    return "CalculiX not run here (the time it takes: " + ("; ".join(runs) or "—") + ")"


def ccx_movement(rows: Mapping) -> dict | None:
    """CalculiX's change between its two finest sizes: ``{"from_mm", "to_mm", "shares",
    "lag", "te", "p_interior": {(k, j): rel}}`` (None with fewer than two sizes)."""
    ok = _ccx_ok(rows)
    if len(ok) < 2:
        return None
    a, b = ok[-2], ok[-1]
    pa, pb = _ccx_interior(a), _ccx_interior(b)
    return {
        "from_mm": a["element_mm"],
        "to_mm": b["element_mm"],
        "shares": _dev(_ccx_shares(a), _ccx_shares(b)),
        "lag": _rel(b["result"]["theta_rad"], a["result"]["theta_rad"]),
        "te": _rel(b["result"]["te_loaded_arcsec"], a["result"]["te_loaded_arcsec"]),
        "p_interior": {k: _rel(pb.get(k), pa.get(k)) for k in pb},
    }


class Extrapolation(NamedTuple):
    """A quantity extrapolated to zero element size from the three finest sizes."""

    value: float
    """the extrapolated value"""
    order: float
    """the observed order of convergence p"""
    gci: float
    """grid convergence index of the finest size (relative, safety factor 1.25): the band
    around the extrapolated value the converged one is expected in"""
    sizes: tuple[float, float, float]
    """element sizes used, coarse to fine (mm)"""


def richardson(sizes: Sequence[float], values: Sequence[float]) -> Extrapolation | None:
    """Richardson extrapolation of ``values`` measured at element ``sizes`` (any order; the
    three finest are used), or None when it does not apply.

    With ``h1 < h2 < h3`` and ``φ1, φ2, φ3``, ``ε21 = φ2 − φ1``, ``ε32 = φ3 − φ2``,
    ``r21 = h2/h1``, ``r32 = h3/h2``, the observed order ``p`` solves (fixed point)

        p = (ln(ε32/ε21) + ln((r21^p − 1)/(r32^p − 1))) / ln r21,

    then ``φ_ext = (r21^p φ1 − φ2)/(r21^p − 1)`` and the grid convergence index of the finest
    size ``GCI = 1.25 |(φ1 − φ2)/φ1| / (r21^p − 1)`` (Celik et al. 2008, "Procedure for
    estimation and reporting of uncertainty due to discretization in CFD applications",
    J. Fluids Eng. 130, 078001, eqs. 1-6, monotone case, without their absolute value, so that a
    diverging sequence gives a negative order; Roache 1998). None: fewer than three sizes,
    oscillating or stalled values (``ε32/ε21 <= 0``), or an order outside ``[0.5, 6]`` (the
    sizes are not in the asymptotic range: no extrapolation is trusted).
    """
    pts = sorted(zip(sizes, values, strict=True))[:3]
    if len(pts) < 3:
        return None
    (h1, f1), (h2, f2), (h3, f3) = pts
    e21, e32 = f2 - f1, f3 - f2
    if e21 == 0.0 or e32 / e21 <= 0.0 or not h1 < h2 < h3:
        return None
    r21, r32 = h2 / h1, h3 / h2
    p = math.log(e32 / e21) / math.log(r21)
    for _ in range(200):
        if p <= 0.0:  # diverging (the finer step moves more): no order
            return None
        q = math.log((r21**p - 1.0) / (r32**p - 1.0))
        p_new = (math.log(e32 / e21) + q) / math.log(r21)
        if abs(p_new - p) < 1e-10:
            p = p_new
            break
        p = p_new
    else:
        return None
    if not 0.5 <= p <= 6.0:
        return None
    k = r21**p
    value = (k * f1 - f2) / (k - 1.0)
    gci = 1.25 * abs((f1 - f2) / f1) / (k - 1.0)
    return Extrapolation(value, p, gci, (h3, h2, h1))


def te_extrapolation(rows: Mapping) -> Extrapolation | None:
    """CalculiX's loaded TE extrapolated to zero element size (:func:`richardson`)."""
    ok = _ccx_ok(rows)
    return richardson([r["element_mm"] for r in ok],
                      [r["result"]["te_loaded_arcsec"] for r in ok])  # fmt: skip


def gear_comparison(rows: Mapping, fe: Mapping) -> dict:
    """fegear row ``fe`` against CalculiX's finest size: ``{"shares", "lag", "te",
    "p_interior": {(k, j): rel or None}}``."""
    fin = _ccx_ok(rows)[-1]
    res = fin["result"]
    pin = _ccx_interior(fin)
    return {
        "shares": _dev(_ccx_shares(fin), _fe_shares(fe)),
        "lag": _rel(fe["theta"], res["theta_rad"]),
        "te": _rel(fe["te_loaded"], res["te_loaded_arcsec"]),
        "p_interior": {
            (p["k"], p["j"]): _rel(p["p_interior"], pin.get((p["k"], p["j"]))) for p in fe["pairs"]
        },
    }


def equal_accuracy(rows: Mapping, fe: Mapping) -> dict:
    """The coarsest CalculiX size from which on every finer one agrees with the finest within
    fegear's own difference from it (load shares and lag); its time over fegear's cold time."""
    ok = _ccx_ok(rows)
    cmp = gear_comparison(rows, fe)
    fin = ok[-1]
    tol_s, tol_l = cmp["shares"], abs(cmp["lag"])
    pick = fin
    for i, r in enumerate(ok):
        if all(
            _dev(_ccx_shares(q), _ccx_shares(fin)) <= tol_s
            and abs(_rel(q["result"]["theta_rad"], fin["result"]["theta_rad"])) <= tol_l
            for q in ok[i:]
        ):
            pick = r
            break
    cold = fe.get("cold_s")
    return {"ccx": pick, "ratio": None if not cold else pick["ccx_s"] / cold, "cold_s": cold}


# ------------------------------------------------------------------------------ the page
def _hertz_md(h: Mapping) -> list[str]:
    ref = h["hertz"]
    L = ["## Hertz scene (quarter model, 2000 N)", "",
         f"Hertz: p0 {ref['p0_MPa']:.1f} MPa, a {ref['a_mm']:.4f} mm, b {ref['b_mm']:.4f} mm. "
         "CalculiX: p0 is the largest nodal `CPRESS` (and the peak recovered from the nodal "
         "forces, `fegear.mechanics.patch.measure_patch`), a and b the semi-axes of the nodal "
         "forces' second moments; fegear `hybrid` (FE of level 0): the recovered peak and the "
         "same second moments on its cells.", "",
         "| solver | contact elements (mm) | elements across 2b | DOFs | p0 err | p0 err "
         "(recovered) | a err | b err | force balance | Newton iterations | time s | peak MB | "
         "load avg |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in h["ccx"]:
        if "result" not in r:
            L.append(f"| CalculiX | {r['element_mm']} | | {r['dofs']} | failed (exit "
                     f"{r['returncode']}) | | | | | | {r['ccx_s']:.0f} | | "
                     f"{_load(r)} |")  # fmt: skip
            continue
        L.append(
            f"| CalculiX | {r['element_mm']} | {r['elements_across_2b']:.1f} | {r['dofs']} | "
            f"{_pct(r['e_p0'])} | {_pct(r['e_p0_recovered'])} | {_pct(r['e_a'])} | "
            f"{_pct(r['e_b'])} | {r['result']['balance']:.6f} | {r.get('iterations', '')} | "
            f"{r['ccx_s']:.1f} | {_f(r['peak_MB'], '.0f')} | {_load(r)} |"
        )
    for r in h["fegear"]:
        L.append(
            f"| fegear hybrid level {r['level']} | | | {r['dofs']} | {_pct(r['e_p0'])} | | "
            f"{_pct(r['e_a'])} | {_pct(r['e_b'])} | | | {r['cold_s']:.1f} cold, "
            f"{r['warm_s']:.1f} warm | {_f(r['peak_MB'], '.0f')} | {_load(r)} |"
        )
    return L + [""]


def _time(r: Mapping, unit: str = "") -> str:
    cold = "" if r.get("cold_s") is None else f"{r['cold_s']:.1f}{unit} cold, "
    shared = r.get("cold_at")
    return cold + f"{r['warm_s']:.1f}{unit} warm" + (f" (cold at {shared})" if shared else "")


def _gear_table(rows: Mapping) -> list[str]:
    L = ["| solver | contact elements (mm) | DOFs | load shares (k, j): share | "
         "p_max interior (overall) MPa | semi-axes a × b mm | lag µrad | loaded TE arcsec | "
         "time s | peak MB | load avg |",
         "|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows["ccx"]:
        if "result" not in r:
            L.append(f"| CalculiX | {r['element_mm']} | {r['dofs']} | failed (exit "
                     f"{r['returncode']}) | | | | | {r['ccx_s']:.0f} | | {_load(r)} |")  # fmt: skip
            continue
        res, prs = r["result"], r["result"]["pairs"]
        shares = ", ".join(f"({p['k']}, {p['j']}): {p['load_share'] + 0.0:.4f}" for p in prs)
        pm = ", ".join(f"{_f(p['p_interior_MPa'], '.0f')} ({p['p_max_MPa']:.0f})" for p in prs)
        ab = ", ".join(_ab(p["semi_major_mm"], p["semi_minor_mm"]) for p in prs)
        L.append(
            f"| CalculiX | {r['element_mm']} | {r['dofs']} | {shares} | {pm} | {ab} | "
            f"{1e6 * res['theta_rad']:.2f} | {res['te_loaded_arcsec']:.3f} | "
            f"{r['ccx_s']:.1f} (+{_f(r['export_s'], '.0f')} export){_timing(r)} | "
            f"{_f(r['peak_MB'], '.0f')} | {_load(r)} |"
        )
    for r in rows["fegear"]:
        prs = r["pairs"]
        shares = ", ".join(f"({p['k']}, {p['j']}): {p['share']:.4f}" for p in prs)
        pm = ", ".join(f"{_f(p['p_interior'], '.0f')} ({p['p_max']:.0f})" for p in prs)
        ab = ", ".join(_ab(p["a"], p["b"]) for p in prs)
        L.append(
            f"| fegear {r['fidelity']} level {r['level']} | | | {shares} | {pm} | {ab} | "
            f"{1e6 * r['theta']:.2f} | {r['te_loaded']:.3f} | {_time(r)} | {r['peak_MB']:.0f} | "
            f"{_load(r)} |"
        )
    return L + [""]


def _gear_md(key: str, sec: Mapping) -> list[str]:
    L = [f"## {GEAR_SECTIONS[key]}", ""]
    if sec.get("command"):
        L += [f"`{sec['command']}`", ""]
    if "line_hertz_p0_MPa" in sec:
        L += [f"ISO 6336-2 line Hertz at the pitch point: p_H {sec['line_hertz_p0_MPa']:.0f} MPa.",
              ""]  # fmt: skip
    for label, rows in positions(sec):
        where = f"φ1 = {rows['phi1_deg']}°"
        if rows.get("position") is not None:
            where += f", position {rows['position']} of the case's cycle"
        L += [f"### {label} ({where})", ""] + _gear_table(rows)
    return L


def markdown(doc: Mapping) -> str:
    """The benchmark's page (``benchmarks/results/calculix.md``)."""
    L = ["# CalculiX cross-check", "", f"`{doc['command']}`", "",
         f"CalculiX {doc['ccx_version']} (`{doc['ccx']}`), {doc['threads']} thread(s); fegear "
         "in one process (`FEGEAR_WORKERS=1`). Cold: an empty cache (meshes and compliance "
         "operators built); warm: the same run again (a position after the first of a case: "
         "warm only, on the cache its first position built). Peak memory: max RSS of the "
         "process. The machine (2 cores) was shared with other work: load avg = its 1-minute "
         "load average before the run (— not recorded).", "",
         "Load share: the pair's torque on the gear axis over T2. p_max: the largest pressure "
         "away from the flank borders (fegear's rule, `fegear.ltca.edges`; — where none is "
         "reported), in brackets the largest overall. Semi-axes: `sqrt(5 λ)` of the second "
         "moments of the nodal (cell) forces. Lag θ: the gear's elastic rotation; loaded TE = "
         "unloaded TE − θ.", ""]  # fmt: skip
    if "hertz_scene" in doc:
        L += _hertz_md(doc["hertz_scene"])
    for key in GEAR_SECTIONS:
        if key in doc:
            L += _gear_md(key, doc[key])
    L += ["## At equal accuracy and the acceptance bounds", ""] + summary(doc) + [""]
    return "\n".join(L) + "\n"


def _settled(rows: Sequence[Mapping], keys, tol: float) -> Mapping | None:
    """The first of ``rows`` (coarse to fine) from which on every row is within ``tol`` in
    every ``keys``."""
    for i, r in enumerate(rows):
        if all(abs(q[k]) <= tol for q in rows[i:] for k in keys):
            return r
    return None


def _hertz_summary(h: Mapping) -> list[str]:
    L = []
    ok = [r for r in h["ccx"] if "result" in r]
    for what, keys, tol in (
        ("p0 within 1 % from this size on", ("e_p0",), 0.01),
        ("p0, a and b within 2 % from this size on", ("e_p0", "e_a", "e_b"), 0.02),
    ):
        cc = _settled(sorted(ok, key=lambda r: -r["element_mm"]), keys, tol)
        ff = _settled(sorted(h["fegear"], key=lambda r: r["level"]), keys, tol)
        if cc and ff:
            L.append(f"- Hertz scene, {what}: CalculiX {cc['element_mm']} mm in "
                     f"{cc['ccx_s']:.0f} s and {_f(cc['peak_MB'], '.0f')} MB; fegear hybrid level "
                     f"{ff['level']} in {ff['cold_s']:.1f} s cold ({ff['warm_s']:.1f} s warm) "
                     f"and {ff['peak_MB']:.0f} MB: {cc['ccx_s'] / ff['cold_s']:.0f}x the cold "
                     "time.")  # fmt: skip
        elif ff and ok:
            fin = min(ok, key=lambda r: r["element_mm"])
            errs = ", ".join(f"{k[2:]} {_pct(fin[k])}" for k in keys)
            L.append(f"- Hertz scene, {what}: not reached by CalculiX within its ladder (at "
                     f"{fin['element_mm']} mm, {fin['ccx_s']:.0f} s: {errs}); fegear hybrid "
                     f"level {ff['level']}: {ff['cold_s']:.1f} s cold.")  # fmt: skip
    return L


def _pairs_text(d: Mapping) -> str:
    return ", ".join(f"({k[0]}, {k[1]}) {_pct(v)}" for k, v in d.items())


def summary(doc: Mapping) -> list[str]:
    """Per row: CalculiX's own convergence, fegear against its finest size, the time ratio."""
    L = _hertz_summary(doc["hertz_scene"]) if "hertz_scene" in doc else []
    for key, title in GEAR_SECTIONS.items():
        for label, rows in positions(doc.get(key, {})):
            ok = _ccx_ok(rows)
            if not ok:
                L.append(f"- {title}, {label}: {not_run(doc[key], label)}.")
                continue
            fin = ok[-1]
            mv = ccx_movement(rows)
            own = (
                "one size only"
                if mv is None
                else f"{mv['from_mm']} → {mv['to_mm']} mm: shares move {mv['shares']:.4f}, lag "
                f"{_pct(mv['lag'])}, interior p_max {_pairs_text(mv['p_interior'])}"
            )
            ext = te_extrapolation(rows)
            if ext is not None:
                own += (f"; loaded TE extrapolated to zero size {ext.value:.3f}″ (order "
                        f"{ext.order:.2f}, GCI ±{100 * ext.gci:.2f}%)")  # fmt: skip
            L.append(f"- {title}, {label}: CalculiX {own}; finest {fin['element_mm']} mm: lag "
                     f"{1e6 * fin['result']['theta_rad']:.2f} µrad, {fin['ccx_s']:.0f} s, "
                     f"{_f(fin['peak_MB'], '.0f')} MB.")  # fmt: skip
            for r in rows["fegear"]:
                c = gear_comparison(rows, r)
                eq = equal_accuracy(rows, r)
                ratio = (
                    "" if eq["ratio"] is None else
                    f"; CalculiX as close ({eq['ccx']['element_mm']} mm): {eq['ccx']['ccx_s']:.0f}"
                    f" s, {eq['ratio']:.0f}x fegear's cold time"
                )  # fmt: skip
                L.append(f"  fegear {r['fidelity']} level {r['level']}: shares within "
                         f"{c['shares']:.4f}, lag {_pct(c['lag'])}, loaded TE {_pct(c['te'])}, "
                         f"interior p_max {_pairs_text(c['p_interior'])}{ratio}.")  # fmt: skip
    return L


# ------------------------------------------------------------------ the acceptance bounds
def criteria(doc: Mapping) -> list[dict]:
    """Each gear position's acceptance checks against CalculiX's finest size (fegear
    ``hybrid`` level 0): ``{"row", "check", "value", "bound", "holds", "ccx_moves"}`` (the
    loaded TE's also ``"extrapolation"``, :class:`Extrapolation`, when CalculiX's ladder gives
    one: then ``value`` is against the extrapolated TE and ``ccx_moves`` is its GCI; else
    ``"not_extrapolated"``: True when three sizes or more did not give one: not decided; the
    p_max checks' ``"pressure_integral"``: CalculiX's pressures integrated over the pair's
    contact force (:func:`_pressure_integral`), not decided when it is off 1 by more than the
    bound);
    ``holds`` is None where the quantity is not defined (p_max with no interior peak on one
    side)."""
    out = []
    for key, title in GEAR_SECTIONS.items():
        for label, rows in positions(doc.get(key, {})):
            ok = _ccx_ok(rows)
            hyb = [r for r in rows["fegear"] if r["fidelity"] == "hybrid" and r["level"] == 0]
            if not ok or not hyb:
                continue
            c, mv = gear_comparison(rows, hyb[0]), ccx_movement(rows)
            row = f"{title}, {label}"
            if _loaded(_ccx_shares(ok[-1])) >= 2:
                out.append({"row": row, "check": "load shares within 0.03",
                            "value": c["shares"], "bound": SHARE_TOL,
                            "holds": c["shares"] <= SHARE_TOL,
                            "ccx_moves": None if mv is None else mv["shares"]})  # fmt: skip
            integral = _pressure_integral(ok[-1])
            for k, v in c["p_interior"].items():
                out.append({"row": row, "check": f"interior p_max of pair {k} within 5 %",
                            "value": v, "bound": P_TOL,
                            "holds": None if v is None else abs(v) <= P_TOL,
                            "ccx_moves": None if mv is None else
                            mv["p_interior"].get(k),
                            "pressure_integral": integral.get(k)})  # fmt: skip
            ext = te_extrapolation(rows)
            if ext is None:
                out.append({"row": row, "check": "loaded TE within 5 %", "value": c["te"],
                            "bound": TE_TOL, "holds": abs(c["te"]) <= TE_TOL,
                            "ccx_moves": None if mv is None else mv["te"],
                            "not_extrapolated": len(ok) >= 3})  # fmt: skip
            else:  # against the extrapolated value; its GCI is what CalculiX leaves open
                te = _rel(hyb[0]["te_loaded"], ext.value)
                out.append({"row": row, "check": "loaded TE within 5 %", "value": te,
                            "bound": TE_TOL, "holds": abs(te) <= TE_TOL, "ccx_moves": ext.gci,
                            "extrapolation": ext})  # fmt: skip
    return out


def _ccx_line(row: str, fin: Mapping, mv: Mapping | None) -> str:
    """The validation table's line of CalculiX's finest size (its last step's change)."""
    prs = fin["result"]["pairs"]
    moved = (lambda x: "") if mv is None else (lambda x: f" ({_pct(x)})")
    sh = ", ".join(f"({p['k']}, {p['j']}) {p['load_share'] + 0.0:.4f}" for p in prs)
    if mv is not None:
        sh += f" (±{mv['shares']:.4f})"
    pm = ", ".join(
        _f(p["p_interior_MPa"], ".0f")
        + ("" if mv is None else moved(mv["p_interior"].get((p["k"], p["j"]))))
        for p in prs
    )  # fmt: skip
    ab = ", ".join(_ab(p["semi_major_mm"], p["semi_minor_mm"]) for p in prs)
    te = f"{fin['result']['te_loaded_arcsec']:.3f}" + ("" if mv is None else moved(mv["te"]))
    return (f"| {row} | CalculiX {fin['element_mm']} mm | {sh} | {pm} | {ab} | {te} | "
            f"{fin['ccx_s']:.0f} s | {_f(fin['peak_MB'], '.0f')} |")  # fmt: skip


def _against(c: Mapping) -> str:
    """What a check's value is measured against: CalculiX's last change, or its extrapolation."""
    ext = c.get("extrapolation")
    if ext is not None:
        sizes = ", ".join(f"{h:g}" for h in ext.sizes)
        return (
            f"against CalculiX extrapolated to zero element size ({ext.value:.3f}″ from "
            f"{sizes} mm, observed order {ext.order:.2f}, GCI ±{100 * ext.gci:.2f}%)"
        )
    mv = c["ccx_moves"]
    mvs = "—" if mv is None else (f"{mv:.4f}" if "shares" in c["check"] else _pct(mv))
    return f"(CalculiX moves {mvs})"


def _verdict(c: Mapping) -> str:
    """A check of :func:`criteria` decided, or why not (the rules of ``docs/calculix.md``)."""
    mv, integral = c["ccx_moves"], c.get("pressure_integral")
    if c["holds"] is None:
        return "not compared (no interior peak on one side)"
    if integral is not None and abs(integral - 1.0) > c["bound"]:
        return (f"not decided: CalculiX's pressures integrate to {integral:.2f} times the "
                "pair's contact force (its pressure is not resolved)")  # fmt: skip
    if c.get("extrapolation") is not None and mv > c["bound"]:
        return "not decided: CalculiX's uncertainty exceeds the bound"
    if mv is None:
        return "not decided: one CalculiX size only"
    if c.get("not_extrapolated"):
        return (
            "not decided: CalculiX's three finest sizes do not converge at an order of at "
            "least 0.5 (no extrapolation), so its finest value is not bounded by its ladder"
        )
    if abs(mv) > c["bound"]:
        return "not decided: CalculiX is not converged on it"
    return "holds" if c["holds"] else "does NOT hold"


def validation_section(doc: Mapping) -> str:
    """The section of ``docs/validation.md``: per row, CalculiX's finest size beside fegear
    ``hybrid`` and ``fe`` level 0, and the acceptance checks with CalculiX's own movement."""
    L = ["## Against a full FE contact model (CalculiX)", "",
         "The same bodies, supports and load as a CalculiX model (`fegear export-ccx`, "
         "[calculix.md](calculix.md)): C3D10 sectors refined around the contact, penalty "
         "surface-to-surface contact, 2 threads. Generated from "
         "`benchmarks/results/calculix.json` (`python benchmarks/calculix_crosscheck.py`, its "
         "ladders of contact element sizes in "
         "[calculix.md](../benchmarks/results/calculix.md)). Each row: CalculiX at its finest "
         "size (the change over its last refinement step in brackets) beside fegear. Times: "
         "CalculiX's solve (the export apart), fegear cold (an empty cache) and warm.",
         ""]  # fmt: skip
    if "hertz_scene" in doc:
        h = doc["hertz_scene"]
        ok = sorted((r for r in h["ccx"] if "result" in r), key=lambda r: -r["element_mm"])
        L += ["| row | solver | p0 err | a err | b err | time | peak MB |",
              "|---|---|---|---|---|---|---|"]  # fmt: skip
        for r in ok:
            L.append(f"| Hertz scene | CalculiX {r['element_mm']} mm | {_pct(r['e_p0'])} | "
                     f"{_pct(r['e_a'])} | {_pct(r['e_b'])} | {r['ccx_s']:.0f} s | "
                     f"{_f(r['peak_MB'], '.0f')} |")  # fmt: skip
        for r in h["fegear"]:
            L.append(f"| Hertz scene | fegear hybrid {r['level']} | {_pct(r['e_p0'])} | "
                     f"{_pct(r['e_a'])} | {_pct(r['e_b'])} | {r['cold_s']:.1f} s cold, "
                     f"{r['warm_s']:.1f} s warm | {_f(r['peak_MB'], '.0f')} |")  # fmt: skip
        L += [""] + _hertz_summary(h) + [""]
    L += ["| row | solver | load shares (k, j) | interior p_max MPa | semi-axes a × b mm | "
          "loaded TE arcsec | time | peak MB |",
          "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for key, title in GEAR_SECTIONS.items():
        for label, rows in positions(doc.get(key, {})):
            ok = _ccx_ok(rows)
            row = f"{title}, {label} (φ1 = {rows['phi1_deg']}°)"
            if not ok:
                L.append(f"| {row} | {not_run(doc[key], label)} | | | | | | |")
            else:
                L.append(_ccx_line(row, ok[-1], ccx_movement(rows)))
            for r in rows["fegear"]:
                fp = r["pairs"]
                eq = equal_accuracy(rows, r) if ok else {"ratio": None}
                ratio = "" if eq["ratio"] is None else f"; CalculiX {eq['ratio']:.0f}x"
                L.append(
                    f"| | fegear {r['fidelity']} {r['level']} | "
                    + ", ".join(f"({p['k']}, {p['j']}) {p['share']:.4f}" for p in fp)
                    + " | " + ", ".join(_f(p["p_interior"], ".0f") for p in fp)
                    + " | " + ", ".join(_ab(p['a'], p['b']) for p in fp)
                    + f" | {r['te_loaded']:.3f} | {_time(r, ' s')}{ratio} | {r['peak_MB']:.0f} |"
                )  # fmt: skip
    L += ["", "Time ratio: CalculiX's time at the coarsest size from which on its load shares "
          "and lag agree with its finest as closely as fegear's do, over fegear's cold time.", "",
          "**Acceptance bounds** (fegear `hybrid` level 0 against CalculiX's finest size; "
          "CalculiX's own change over its last refinement step in brackets: a bound checked "
          "against a CalculiX value that still moves by more than the bound is not decided by "
          "this ladder; the loaded TE against CalculiX extrapolated to zero element size where "
          "three sizes allow it, decided when the extrapolation's GCI is within the bound, "
          "[calculix.md](calculix.md#calculix-extrapolated-to-zero-element-size)):",
          ""]  # fmt: skip
    for c in criteria(doc):
        val = f"{c['value']:.4f}" if "shares" in c["check"] else _pct(c["value"])
        L.append(f"- {c['row']}: {c['check']}: {val} {_against(c)}: {_verdict(c)}.")
    fzg = doc.get("fzg", {})
    pitch = fzg.get("pitch point")
    if pitch and "line_hertz_p0_MPa" in fzg:
        ref = fzg["line_hertz_p0_MPa"]
        for r in pitch["fegear"]:
            if r["fidelity"] == "hybrid" and r["level"] == 0 and r["pairs"][0]["p_interior"]:
                p = r["pairs"][0]["p_interior"]
                L.append(f"- FZG pitch point, interior p_max against ISO 6336-2's line Hertz "
                         f"{ref:.0f} MPa instead: fegear hybrid 0 {p:.0f} MPa "
                         f"({_pct(p / ref - 1)}).")  # fmt: skip
    return "\n".join(L) + "\n"
