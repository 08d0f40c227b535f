r"""Validation rows of helical pairs: contact ratios, mesh stiffness, line Hertz, KHβ.

Each row sets a fegear result against a number computed without the solver
(``python docs/make_validation.py cylindrical``):

*Contact ratios* — measured on the members' flanks (:func:`fegear.tca.contact_lines.
contact_ratios`, the first to the last contact of a pair by bisection) against ISO 21771's
closed forms (:func:`fegear.tca.contact_lines.iso_contact_ratios`).

*Mesh and single stiffness* — from a loaded cycle (:mod:`fegear.ltca.line_load`): the mean
secant mesh stiffness ``c_γ`` over the cycle and the largest single stiffness ``c'`` of a pair
whose contact line spans the face, against ISO 6336-1 Method B: ``c'_{th}`` of the virtual
spur gears times ``C_B \cos β``, the solid-gear value of ISO's ``c' = c'_{th} C_M C_R C_B
\cos β`` that an ideal FE model of the gears should match: ``C_B = [1 + 0.5 (1.2 − h_{fP}/
m_n)] [1 − 0.02 (20° − α_{Pn})]`` the basic rack factor (0.975 for the 1.25 m_n dedendum of the
pairs' racks), ``C_R = 1`` (solid blanks), and ``C_M = 0.8`` left out: it is ISO's empirical
step from the theoretical value to measured gears (deviations, running-in, the test rigs'
compliance), which a model of exact flanks on a clamped sector does not have. And
``c_{γα} = c' (0.75 ε_α + 0.25)``.

*Line Hertz at the pitch point of a helical pair* — at the pinion angle where pair 0's contact
line crosses the pitch cylinder in the middle of the face, the largest cell pressure within
``b/8`` of the middle against line Hertz of the local load per unit length of the line
``w = q_0(0) \cos β_b`` (its face-width load in the middle bins, :mod:`fegear.ltca.line_load`)
with the normal-section radii ``ρ_i = r_{bi} \tan α_{wt} / \cos β_b`` (the helicoids'
curvature across the contact line; ISO 6336-2's ``Z_H`` has the same ``\cos β_b``):
``p_H = \sqrt{w E^* / (π R)}``, ``1/R = 1/ρ_1 + 1/ρ_2``. The load comes from the solve (the
share of a helical pair's line is not a closed form); the reference is the pressure Hertz
gives for it.

*Root stress* — the largest maximum principal stress in a tension fillet over a loaded cycle
(the stress sectors with refined fillets) against ISO 6336-3 method B's σF0 of the virtual spur
gears with the helix factor Yβ (:func:`iso_root_stress`).

*Face load factor of a misaligned pair* — the unmodified helical pair under an out-of-plane axis
deviation ``f_Σβ`` whose mesh misalignment along the line of action is
``F_βx = f_Σβ \cos α_{wt}`` over the face, beside ISO 6336-1:2006 §7.6 (method C):
``K_{Hβ} = 1 + c_{γβ} F_{βy} / (2 F_m / b)`` (``≤ 2``, else ``\sqrt{2 c_{γβ} F_{βy} b/F_m}``)
with ``F_{βy} = F_{βx}`` (no running-in), ``F_m = F_t`` (``K_A = K_v = 1``), and
``c_{γβ} = 0.85 c_{γα}`` of ISO's stiffness (``C_M = 0.8``, ``C_B`` of the 1.25 m dedendum).
The estimate assumes a linear gap across the face on an elastic foundation of constant
stiffness per unit face width (no coupling along the face, stiff shafts and blanks, a tooth
equally stiff at the face ends and in the middle); it is a design estimate, set beside the
LTCA's value, not a pass/fail reference. The same formula with fegear's measured ``c_γ`` is in
the notes.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fegear.api import run
from fegear.io.gear_case import parse_gear_case
from fegear.ltca import LTCAOptions, run_ltca
from fegear.ltca.line_load import load_distribution
from fegear.mechanics.hertz_closed_form import effective_modulus, hertz_line
from fegear.pipeline.pair import build_pair
from fegear.tca.contact_lines import (
    contact_ratios,
    iso_contact_ratios,
    plane_of_action,
    section_contact,
)
from fegear.validation import Row, Value
from fegear.validation.iso6336 import single_stiffness, theoretical_single_stiffness
from fegear.validation.iso6336_root import nominal_root_stress, root_factors

__all__ = [
    "PAIRS",
    "basic_rack_factor",
    "HertzRun",
    "KHBetaRun",
    "RootRun",
    "StiffnessRun",
    "contact_ratio_rows",
    "helical_hertz_run",
    "hertz_rows",
    "iso_root_stress",
    "khb_rows",
    "khb_run",
    "pair_case",
    "root_rows",
    "root_run",
    "stiffness_rows",
    "stiffness_run",
]

COMMAND = "python docs/make_validation.py cylindrical"
TESTS = "tests/test_validation_cylindrical.py"

_FZG = {"teeth": [16, 24], "module_mm": 4.5, "pressure_angle_deg": 20.0,
        "profile_shift": [0.1817, 0.1715], "face_width_mm": 14.0}  # fmt: skip
#: The pairs of the rows: name → (``[pair]`` table, torque on the gear N·m, words).
PAIRS = {
    "fzg_type_c": ({**_FZG, "tip_diameter_mm": [82.46, 118.36]}, 200.0,
                   "FZG type C (spur, real tips)"),
    "helical_15": ({**_FZG, "helix_angle_deg": 15.0}, 200.0,
                   "FZG-size helical, β 15° (cases/helical_crowned.toml without crowning)"),
    "helical_25": ({"teeth": [19, 37], "module_mm": 4.0, "pressure_angle_deg": 20.0,
                    "helix_angle_deg": 25.0, "hand": "left", "profile_shift": [0.3, 0.1],
                    "face_width_mm": 20.0}, 400.0,
                   "helical z 19/37, m_n 4, β 25° left, x 0.3/0.1, b 20 mm"),
    "iso_tr_ex1": ({"teeth": [17, 103], "module_mm": 8.0, "pressure_angle_deg": 20.0,
                    "helix_angle_deg": 15.8, "profile_shift": [0.145, 0.0],
                    "face_width_mm": 100.0}, 21408.85,
                   "ISO/TR 6336-30 example 1 (cases/iso_tr6336_30_ex1.toml: m_n 8, z 17/103, "
                   "β 15.8°, b 100 mm, F_t/b 500 N/mm)"),
}  # fmt: skip
#: ISO 6336-1 basic rack factor of the rows' racks (dedendum 1.25 m_n, α_Pn 20°): C_B.
RACK_DEDENDUM, RACK_ANGLE_DEG = 1.25, 20.0


def basic_rack_factor(h_fp: float = RACK_DEDENDUM, alpha_pn_deg: float = RACK_ANGLE_DEG) -> float:
    """ISO 6336-1:2006 §9.3.2 ``C_B = [1 + 0.5 (1.2 − h_fP/m_n)] [1 − 0.02 (20° − α_Pn)]``."""
    return (1.0 + 0.5 * (1.2 - h_fp)) * (1.0 - 0.02 * (20.0 - alpha_pn_deg))


def pair_case(name: str, n_positions: int = 12, **errors: float):
    """The :class:`~fegear.io.gear_case.GearCase` of :data:`PAIRS` ``[name]`` (hybrid level 0)."""
    pair, torque, _ = PAIRS[name]
    case = parse_gear_case(
        {
            "case": {"kind": "cylindrical", "name": name},
            "pair": dict(pair),
            "load": {"torque2_Nm": torque},
            "analysis": {"fidelity": "hybrid", "level": 0, "n_positions": n_positions},
        }
    )
    return case.with_errors(**errors) if errors else case


def _members(case):
    p = build_pair(case)
    return p.pinion, p.gear, p.assembly


# --------------------------------------------------------------------------- contact ratios
def contact_ratio_rows(names=("fzg_type_c", "helical_15", "helical_25")) -> list[Row]:
    """εα, εβ, εγ measured on the flanks against ISO 21771's closed forms (no solver)."""
    rows = []
    for name in names:
        t0 = time.perf_counter()
        p, g, asm = _members(pair_case(name))
        cr = contact_ratios(p, g, asm)
        dt = time.perf_counter() - t0
        iso = iso_contact_ratios(p, g, asm)
        for i, (sym, val) in enumerate((("ε_α", cr.eps_alpha), ("ε_β", cr.eps_beta),
                                        ("ε_γ", cr.eps_gamma))):  # fmt: skip
            rows.append(Row(
                key=f"{name}_eps_{'abg'[i]}",
                check=f"{PAIRS[name][2]}: contact ratio {sym}",
                quantity=f"{sym} (first to last contact of a pair, measured on the flanks)",
                reference=float(iso[i]),
                reference_text="ISO 21771:2007 §5.4 closed form (ε_α from the tip radii, "
                "ε_β = b sin β/(π m_n), ε_γ = ε_α + ε_β); path bounded by "
                f"{cr.start_limit} and {cr.end_limit}",
                values=(Value("tca", None, float(val), seconds=dt,
                              note="contact lines of the unmodified flanks"),),
                tolerance="1e-6 (bisection to 1e-14 rad)",
                command=COMMAND,
                test=f"{TESTS}::test_contact_ratio_rows_are_the_closed_forms",
            ))  # fmt: skip
    return rows


# --------------------------------------------------------------------------- stiffness
@dataclass(frozen=True)
class StiffnessRun:
    """A loaded cycle's mesh and single stiffness (N/(mm·µm)) and what they are set against."""

    name: str
    n_positions: int
    c_gamma: float | None
    c_prime: float | None
    c_gamma_min: float | None
    c_gamma_max: float | None
    eps_alpha: float
    c_th: float
    cos_beta: float
    seconds: float
    eps_beta: float = 0.0


def stiffness_run(name: str, n_positions: int = 12) -> StiffnessRun:
    """Run :data:`PAIRS` ``[name]`` at ``hybrid`` level 0 over a cycle (module docstring)."""
    t0 = time.perf_counter()
    case = pair_case(name, n_positions)
    r = run(case)
    dt = time.perf_counter() - t0
    gr = r.run
    ld = load_distribution(gr.pair.pinion, gr.pair.gear, gr.assembly, gr.cycle)
    cs = [p.mesh_stiffness for p in ld.positions if p.usable and p.mesh_stiffness is not None]
    pr = case.pair
    beta = float(pr.get("helix_angle_deg", 0.0))
    cth = theoretical_single_stiffness(*pr["teeth"], *pr["profile_shift"], beta,
                                       pr["pressure_angle_deg"])  # fmt: skip
    ea, eb, _ = iso_contact_ratios(gr.pair.pinion, gr.pair.gear, gr.assembly)
    return StiffnessRun(
        name=name, n_positions=n_positions, c_gamma=ld.c_gamma, c_prime=ld.c_prime,
        c_gamma_min=min(cs) if cs else None, c_gamma_max=max(cs) if cs else None,
        eps_alpha=float(ea), c_th=float(cth), cos_beta=math.cos(math.radians(beta)),
        seconds=dt, eps_beta=float(eb),
    )  # fmt: skip


def stiffness_rows(runs: list[StiffnessRun]) -> list[Row]:
    """c' and c_γα against ISO 6336-1 Method B (module docstring)."""
    rows = []
    for s in runs:
        cb = basic_rack_factor()
        cp = s.c_th * cb * s.cos_beta
        cga = cp * (0.75 * s.eps_alpha + 0.25)
        where = f"{PAIRS[s.name][2]}, {PAIRS[s.name][1]:g} N·m on the gear"
        note = (f"{s.n_positions} positions; c_γ(φ) {s.c_gamma_min:.2f}-{s.c_gamma_max:.2f}"
                if s.c_gamma_min is not None else f"{s.n_positions} positions")  # fmt: skip
        common = dict(command=COMMAND, test=f"{TESTS}::test_helical_stiffness_rows",
                      tolerance="10 % (ISO's c'th is a fit to solid-disc deflections of the "
                      "virtual spur gears; the sector's bore and cuts are clamped); c' of a "
                      "helical pair: see its note")  # fmt: skip
        span = f"; its contact line spans ε_β = {s.eps_beta:.2f} base pitches of the path"
        cp_note = (
            note
            + span
            + (
                ", where the single-pair stiffness falls off towards tip and root: the line's mean "
                "is below ISO's spur maximum at the pitch point"
                if s.eps_beta > 0.5
                else ""
            )
        )
        rows.append(Row(
            key=f"{s.name}_c_prime", check=f"{where}: single stiffness c'",
            quantity="largest c'_j of a pair spanning the face (N/(mm·µm))",
            reference=cp,
            reference_text=f"ISO 6336-1:2006 Method B c'th = {s.c_th:.2f} (virtual teeth "
            f"z/(cos²β_b cos β)) × C_B = {cb:.3f} × cos β = {s.cos_beta:.4f}: the solid-gear "
            "value (C_R = 1) an ideal FE model should match; ISO's C_M = 0.8 is the empirical "
            "step to measured gears, left out",
            values=(Value("hybrid", 0, s.c_prime, seconds=s.seconds, note=cp_note),), **common,
        ))  # fmt: skip
        rows.append(Row(
            key=f"{s.name}_c_gamma", check=f"{where}: mesh stiffness c_γα",
            quantity="mean secant mesh stiffness c_γ over the cycle (N/(mm·µm))",
            reference=cga,
            reference_text=f"ISO 6336-1 c_γα = c' (0.75 ε_α + 0.25) with c' = {cp:.2f} "
            f"(above), ε_α = {s.eps_alpha:.4f}",
            values=(Value("hybrid", 0, s.c_gamma, seconds=s.seconds, note=note),), **common,
        ))  # fmt: skip
    return rows


# --------------------------------------------------------------------------- line Hertz
@dataclass(frozen=True)
class HertzRun:
    """Pressure in the middle of pair 0's contact line at the pitch point of a helical pair."""

    name: str
    phi1_deg: float
    p_mid_MPa: float
    w_N_per_mm: float
    p_hertz_MPa: float
    rho1_mm: float
    rho2_mm: float
    E_star_MPa: float
    half_width_mm: float
    cells_across: float
    seconds: float


def _pitch_phi1(p, g, asm) -> float:
    """The pinion angle at which pair 0's contact in the middle section of the face is at the
    pitch point: its roll length on the pinion is ``r_b1 tan α_wt`` (linear in the angle)."""
    pa = plane_of_action(p, g, asm)
    zm = 0.5 * sum(pa.face)
    target = p.r_b * math.tan(pa.alpha_wt)
    a, b = -0.05, 0.05
    La, Lb = (float(section_contact(p, g, pa, x, zm)[1]) for x in (a, b))
    phi = a + (target - La) * (b - a) / (Lb - La)
    for _ in range(3):  # exact for the linear relation; two more steps check it
        L = float(section_contact(p, g, pa, phi, zm)[1])
        phi += (target - L) / p.r_b
    return phi


def helical_hertz_run(name: str = "helical_15", level: int = 0) -> HertzRun:
    """The loaded pair at the pitch point (one position, ``hybrid``; module docstring)."""
    from dataclasses import replace as _replace

    t0 = time.perf_counter()
    case = pair_case(name)
    p, g, asm = _members(case)
    phi = _pitch_phi1(p, g, asm)
    opt = LTCAOptions(level=level, fidelity="hybrid", E_MPa=case.E_MPa, nu=case.nu, workers=1)
    cyc = run_ltca(p, g, asm, case.torque2_Nmm, opt, phi1=np.array([phi]))
    dt = time.perf_counter() - t0
    pos = cyc.positions[0]
    i0 = next(i for i, c in enumerate(pos.cells) if c.k == 0 and c.j == 0)
    c = pos.cells[i0]
    pa = plane_of_action(p, g, asm)
    zm = 0.5 * sum(pa.face)
    b = pa.face[1] - pa.face[0]
    mid = np.abs(c.centers[:, 2] - zm) < b / 8
    p_mid = float(pos.pressure[i0][mid].max())
    ld = load_distribution(p, g, asm, _replace(cyc, positions=(pos,)))
    q0 = next(q for q in ld.positions[0].pairs if q.k == 0)
    n = q0.q_N_per_mm.size
    w = float(np.mean(q0.w_N_per_mm[n // 2 - 1 : n // 2 + 1]))
    cb = math.cos(p.beta_b)
    rho1 = p.r_b * math.tan(pa.alpha_wt) / cb
    rho2 = g.r_b * math.tan(pa.alpha_wt) / cb
    R = 1.0 / (1.0 / rho1 + 1.0 / rho2)
    Es = effective_modulus(case.E_MPa, case.nu, case.E_MPa, case.nu)
    h = hertz_line(w, R, Es)
    return HertzRun(
        name=name, phi1_deg=math.degrees(phi), p_mid_MPa=p_mid, w_N_per_mm=w,
        p_hertz_MPa=float(h.p0_MPa), rho1_mm=rho1, rho2_mm=rho2, E_star_MPa=Es,
        half_width_mm=float(h.b_mm), cells_across=float(pos.pairs[i0].cells_across), seconds=dt,
    )  # fmt: skip


def hertz_rows(h: HertzRun) -> list[Row]:
    """The helical line-Hertz row."""
    return [Row(
        key=f"{h.name}_line_hertz",
        check=f"{PAIRS[h.name][2]}, {PAIRS[h.name][1]:g} N·m, pair 0 through the pitch point in "
        f"the middle of the face (φ1 = {h.phi1_deg:.3f}°): line Hertz",
        quantity="largest pressure within b/8 of the middle of the face (MPa)",
        reference=h.p_hertz_MPa,
        reference_text=f"line Hertz p_H = √(w E*/(π R)) of the local line load w = "
        f"{h.w_N_per_mm:.1f} N/mm (face-width load of the pair in the middle bins × cos β_b), "
        f"normal-section radii ρ = r_b tan α_wt / cos β_b = {h.rho1_mm:.3f}, {h.rho2_mm:.3f} mm, "
        f"E* {h.E_star_MPa:.0f} MPa; half-width {h.half_width_mm:.3f} mm",
        values=(Value("hybrid", 0, h.p_mid_MPa, seconds=h.seconds,
                      note=f"{h.cells_across:.1f} cells across"),),
        tolerance="3 % (as the FZG row: cells 1/8 of the contact width)",
        command=COMMAND,
        test=f"{TESTS}::test_helical_line_hertz_row",
    )]  # fmt: skip


# --------------------------------------------------------------------------- KHβ
@dataclass(frozen=True)
class KHBetaRun:
    """KHβ of the misaligned unmodified pair and ISO's estimate."""

    name: str
    f_sigma_beta_mm: float
    f_beta_x_um: float
    k_h_beta: float | None
    k_h_beta_aligned: float | None
    c_gamma: float | None
    iso: float
    iso_own_stiffness: float | None
    c_gamma_beta_iso: float
    line_load_N_per_mm: float
    seconds: float


def _iso_khb(c_gb: float, f_by_um: float, fm_b: float) -> float:
    k = 1.0 + c_gb * f_by_um / (2.0 * fm_b)
    return k if k <= 2.0 else math.sqrt(2.0 * c_gb * f_by_um / fm_b)


def khb_run(name: str = "helical_15", f_beta_x_um: float = 15.0, n_positions: int = 12):
    """The pair with and without the axis deviation of ``F_βx`` (µm) along the line of action."""
    t0 = time.perf_counter()
    case = pair_case(name, n_positions)
    p, g, asm = _members(case)
    aw = plane_of_action(p, g, asm).alpha_wt
    f = f_beta_x_um * 1e-3 / math.cos(aw)
    out = []
    for c in (case, case.with_errors(f_sigma_beta_mm=f)):
        gr = run(c).run
        out.append(load_distribution(gr.pair.pinion, gr.pair.gear, gr.assembly, gr.cycle))
    dt = time.perf_counter() - t0
    pr = case.pair
    beta = float(pr.get("helix_angle_deg", 0.0))
    s = single_stiffness(*pr["teeth"], *pr["profile_shift"], beta, pr["pressure_angle_deg"],
                         hfP_mn=1.25)  # fmt: skip
    ea = iso_contact_ratios(p, g, asm)[0]
    c_gb = 0.85 * s.c_prime * (0.75 * ea + 0.25)
    b = out[1].face_mm
    fm_b = case.torque2_Nmm / g.r_p / b  # F_t / b at the reference circle
    own = None if out[0].c_gamma is None else _iso_khb(0.85 * out[0].c_gamma, f_beta_x_um, fm_b)
    return KHBetaRun(
        name=name, f_sigma_beta_mm=f, f_beta_x_um=f_beta_x_um, k_h_beta=out[1].k_h_beta,
        k_h_beta_aligned=out[0].k_h_beta, c_gamma=out[0].c_gamma,
        iso=_iso_khb(c_gb, f_beta_x_um, fm_b), iso_own_stiffness=own, c_gamma_beta_iso=c_gb,
        line_load_N_per_mm=fm_b, seconds=dt,
    )  # fmt: skip


def khb_rows(k: KHBetaRun) -> list[Row]:
    """KHβ of the misaligned pair beside ISO's estimate."""
    own = "—" if k.iso_own_stiffness is None else f"{k.iso_own_stiffness:.3f}"
    return [Row(
        key=f"{k.name}_k_h_beta",
        check=f"{PAIRS[k.name][2]}, {PAIRS[k.name][1]:g} N·m, f_Σβ = {k.f_sigma_beta_mm:.4f} mm "
        f"(F_βx = {k.f_beta_x_um:g} µm): face load factor beside ISO 6336-1",
        quantity="KHβ of the cycle-mean face-width load",
        reference=k.iso,
        reference_text=f"ISO 6336-1:2006 §7.6 method C: 1 + c_γβ F_βy/(2 F_m/b), F_βy = F_βx "
        f"(no running-in), F_m/b = F_t/b = {k.line_load_N_per_mm:.1f} N/mm, c_γβ = 0.85 c_γα = "
        f"{k.c_gamma_beta_iso:.2f} N/(mm·µm) (C_M 0.8). It assumes a linear gap on an "
        f"elastic foundation of constant stiffness, uncoupled along the face: an estimate, "
        f"not a pass/fail reference; with fegear's c_γ it gives {own}",
        values=(Value("hybrid", 0, k.k_h_beta, seconds=k.seconds,
                      note=f"aligned: KHβ {k.k_h_beta_aligned:.3f}; c_γ {k.c_gamma:.2f}"),),
        tolerance="none: side by side (the test checks that the misalignment raises KHβ). "
        "fegear's face-width load is steeper than the uncoupled foundation's: measured 1.76 → "
        "0.20 of the mean across the face plus the end bin at 2.01, where springs of fegear's "
        "own c_γ give 1.51 → 0.49 for the same gap; the tooth, coupled along the face, resists "
        "a twist more than a bend, and the line end carries an edge peak narrower than a bin "
        "(8 bins: KHβ 1.89)",
        command=COMMAND,
        test=f"{TESTS}::test_helical_khb_row",
    )]  # fmt: skip


# --------------------------------------------------------------------------- root stress
@dataclass(frozen=True)
class RootRun:
    """Largest tooth-root tension of each member over a loaded cycle and ISO 6336-3's σF0.

    Attributes
    ----------
    fe_MPa, iso_MPa
        ``{"pinion": …, "gear": …}``: fegear's largest maximum principal stress in a tension
        fillet over the cycle, and ISO 6336-3 method B σF0 with Yβ.
    factors
        ``{member: (z_n, Y_F, Y_S)}`` of the virtual spur gears; ``y_beta`` Yβ.
    """

    name: str
    n_positions: int
    fe_MPa: dict
    iso_MPa: dict
    factors: dict
    y_beta: float
    eps_beta: float
    fillet_mm: dict
    seconds: float


def iso_root_stress(name: str) -> tuple[dict, dict, float, float]:
    r"""ISO 6336-3:2006 method B σF0 of both members of :data:`PAIRS` ``[name]``: the factors of
    the virtual spur gear in the normal section (§5: ``z_n = z/(\cos^2β_b \cos β)``,
    ``d_{an} = d_n + d_a − d``, ``ε_{αn} = ε_α/\cos^2β_b``;
    :func:`fegear.validation.iso6336_root.root_factors`), ``Y_β = 1 − ε_β β/120°`` (``ε_β``,
    ``β`` capped at 1 and 30°) and ``F_t = 2 T/d`` at the reference circle:
    ``σ_{F0} = F_t/(b m_n) Y_F Y_S Y_β``. Returns ``(σF0, (z_n, Y_F, Y_S), Y_β, ε_β)``."""
    case = pair_case(name)
    p, g, asm = _members(case)
    ea, eb, _ = iso_contact_ratios(p, g, asm)
    d = p.design
    beta = abs(math.radians(d.helix_angle_deg))
    cbb2 = math.cos(p.beta_b) ** 2
    y_beta = 1.0 - min(eb, 1.0) * min(math.degrees(beta), 30.0) / 120.0
    b = min(p.design.face_width_mm, g.design.face_width_mm)
    ft = case.torque2_Nmm / g.r_p
    sigma, factors = {}, {}
    for who, m in (("pinion", p), ("gear", g)):
        md = m.design
        zn = md.n_teeth / (cbb2 * math.cos(beta))
        dn = md.module_mm * zn
        ran = 0.5 * (dn + 2 * m.r_a - 2 * m.r_p)
        f = root_factors(zn, md.module_mm, md.pressure_angle_deg, md.profile_shift,
                         md.dedendum_coeff * md.module_mm,
                         md.rack_tip_radius_coeff * md.module_mm, ran, ea / cbb2)  # fmt: skip
        sigma[who] = nominal_root_stress(ft, b, md.module_mm, f, y_beta)
        factors[who] = (zn, f.YF, f.YS)
    return sigma, factors, y_beta, eb


def root_run(name: str = "helical_15", n_positions: int = 16) -> RootRun:
    """fegear's root stress over a cycle (``hybrid`` level 0, the stress sectors with refined
    fillets: :func:`fegear.pipeline.fields.displacements`) beside :func:`iso_root_stress`. The
    FE value is the largest over the positions and the loaded teeth: ISO's σF0 is the nominal
    stress of the most unfavourable load position, which a helical tooth meets somewhere in the
    cycle; ``n_positions`` samples it."""
    t0 = time.perf_counter()
    r = run(pair_case(name, n_positions).replace(root_stress=True))
    dt = time.perf_counter() - t0
    fe, fil = {}, {}
    for mf in r.run.members:
        vals = [np.nanmax(mf.root_series(t)) for t in mf.root_teeth]
        fe[mf.name] = float(np.nanmax(vals))
        fil[mf.name] = float(mf.fillet_mm)
    iso, factors, yb, eb = iso_root_stress(name)
    return RootRun(name, n_positions, fe, iso, factors, yb, eb, fil, dt)


def root_rows(rr: RootRun) -> list[Row]:
    """ISO 6336-3 σF0 with Yβ against fegear's largest root tension, per member."""
    rows = []
    for who in ("pinion", "gear"):
        zn, yf, ys = rr.factors[who]
        rows.append(Row(
            key=f"{rr.name}_root_stress_{who}",
            check=f"{PAIRS[rr.name][2]}, {PAIRS[rr.name][1]:g} N·m: {who} root stress",
            quantity=f"{who} σF, largest max principal stress in a tension fillet over the "
            "cycle (MPa)",
            reference=rr.iso_MPa[who],
            reference_text=f"ISO 6336-3 method B σF0 = Ft/(b m_n) YF YS Yβ of the virtual spur "
            f"gear z_n {zn:.2f}: YF {yf:.3f}, YS {ys:.3f}, Yβ = 1 − ε_β β/120° = {rr.y_beta:.4f} "
            f"(ε_β {rr.eps_beta:.3f})",
            values=(Value("hybrid", 0, rr.fe_MPa[who], seconds=rr.seconds,
                          note=f"{rr.n_positions} positions; fillet elements "
                          f"{rr.fillet_mm[who]:.3g} mm"),),
            tolerance="±15 % (ISO's form and stress-correction factors and Yβ are "
            "approximations; the FE maximum is sampled at the cycle's positions)",
            command=COMMAND,
            test=f"{TESTS}::test_helical_root_stress_rows",
        ))  # fmt: skip
    return rows
