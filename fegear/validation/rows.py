r"""The validation rows: run fegear on each case and set it against its independent reference.

Each ``*_rows`` function runs the cases (cached meshes and operators are reused) and returns
:class:`~fegear.validation.Row` objects for ``docs/validation.md``; the measurement helpers
(:func:`pitch_point_run`, :func:`bevel_te_parabola`, :func:`load_trend`) are what the tests call.

How each quantity is measured
-----------------------------
*FZG at the pitch point.* The pinion angle :math:`\varphi_C` at which one pair touches at the pitch
point C comes from the rigid TCA (:func:`pitch_point_phi1`); fegear's loaded analysis runs at that
single position (:func:`fegear.ltca.run_ltca`), where one pair carries the whole torque. Its
elastic lag :math:`\Delta\varphi_2 = TE_{loaded} - TE_{unloaded}` (rad) is the deflection
:math:`\delta = r_{b2}|\Delta\varphi_2|` of the pair along the line of action, under the normal
load :math:`F_{bn} = T_2/r_{b2}`, so the single-pair stiffness per unit face width is

.. math:: c' = \frac{F_{bn}}{b\,\delta} = \frac{T_2}{r_{b2}^2\, b\, |\Delta\varphi_2|}
          \quad [\text{N/(mm·µm)} \text{ after } 10^{-3}].

The mid-face peak pressure is the largest cell pressure of each row of cells across the line,
averaged over the rows in the middle half of the face width (:math:`|z| < b/4`): line Hertz (an
infinitely long contact) has the same peak in every section; an uncrowned line contact's
pressure rises towards the face ends, which it does not model. At ``hertz`` fidelity (no cells)
it is the pair's closed-form Hertz pressure.

*Spiral bevel.* The synthesis (:mod:`fegear.geometry.bevel.synthesis`) designs the unloaded
TE as the parabola :math:`\Delta\varphi_2 = -\Delta (N_1/\pi)^2 \varphi_1^2` of amplitude
:math:`\Delta` (``te_amplitude_arcsec``) over the cycle :math:`\varphi_1 \in [-\pi/N_1, \pi/N_1]`.
The rigid TCA's TE over the cycle gives the peak-to-peak, and a least-squares parabola through it
the curvature, compared with the design's :math:`-2\Delta(N_1/\pi)^2` (arcsec/rad²).

*Load trend (seed face gear).* At the seed's light, moderate and heavy torques: the loaded TE
peak-to-peak, the mean elastic lag :math:`|\overline{TE}_{loaded}|`, the loaded contact ratio and
the largest patch length :math:`2a` of a pair away from the flank edges over the cycle.
"""

from __future__ import annotations

import importlib
import logging
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fegear.api import load_case, run
from fegear.errors import FegearError, InputError
from fegear.ltca import LTCAOptions, run_ltca
from fegear.pipeline.pair import build_pair
from fegear.tca import TCA, TCAOptions, reference_phase
from fegear.validation import Row, Value, as_row
from fegear.validation.iso6336 import pitch_point_line_hertz, single_stiffness

__all__ = [
    "CASES",
    "PitchPointRun",
    "BevelParabola",
    "TrendPoint",
    "ROOT_STRESS_MODULE",
    "ROOT_STRESS_FUNCTION",
    "bevel_te_parabola",
    "bevel_rows",
    "fzg_reference",
    "fzg_rows",
    "hertz_scene_rows",
    "load_trend",
    "load_trend_rows",
    "trend_point",
    "pitch_point_phi1",
    "pitch_point_run",
    "root_stress_rows",
]

log = logging.getLogger(__name__)
ARCSEC = math.pi / (180.0 * 3600.0)
CASES = Path(__file__).resolve().parents[2] / "cases"
#: The page's generator (the command of every row).
COMMAND = "python docs/make_validation.py"
TESTS = "tests/test_validation.py"


def _case(name: str):
    return load_case(CASES / name)


# --------------------------------------------------------------------------------------------
# Hertz scene
# --------------------------------------------------------------------------------------------


def hertz_scene_rows(
    fe_levels: Sequence[int] = (0, 1, 2, 3, 4, 5), hybrid_levels: Sequence[int] = (0, 1, 2, 3, 4, 5)
) -> list[Row]:
    """Hertz scene (``cases/hertz_scene.toml``): p0, a, b at each fidelity and level against the
    closed-form Hertz point contact (:func:`fegear.scenes.hertz_scene.hertz_reference`, from
    :mod:`fegear.mechanics.hertz_closed_form`). Three rows: p0 (MPa), a (mm), b (mm)."""
    case = _case("hertz_scene.toml")
    vals: dict[str, list[Value]] = {"p0": [], "a": [], "b": []}
    ref = None
    for fid, levels in (("fe", fe_levels), ("hybrid", hybrid_levels)):
        for lv in levels:
            t0 = time.perf_counter()
            r = run(case, fidelity=fid, level=lv, study=())
            dt = time.perf_counter() - t0
            ref = (r.hertz_p0_MPa, r.hertz_a_mm, r.hertz_b_mm)
            note = "" if fid == "fe" else f"FE level {case.fe_level} + half-space"
            for key, v in (("p0", r.p0_MPa), ("a", r.a_mm), ("b", r.b_mm)):
                vals[key].append(Value(fid, lv, float(v), seconds=dt, note=note))
    if ref is None:
        raise InputError("levels", (fe_levels, hybrid_levels), "at least one level")
    s = case.scene
    src = (
        "Hertz point contact, closed form (Johnson 1985 §4.2; "
        f"`fegear/mechanics/hertz_closed_form.py`): roller "
        f"R {s.roller_radii_mm[0]:g}/{s.roller_radii_mm[1]:g} mm on a flat, {s.force_N:g} N, "
        f"E {s.E_roller_MPa:g} MPa, ν {s.nu_roller:g}"
    )
    tol = (
        "`hybrid` level 3: 1 % on p0 and a, b (the recovered peak of a 16-cells-across grid; "
        "the scene's half-space is 20 mm deep, not infinite)"
    )
    test = f"{TESTS}::test_hertz_scene_hybrid_matches_closed_form_hertz"
    names = {"p0": ("peak pressure p0 (MPa)", 0), "a": ("semi-major axis a (mm)", 1),
             "b": ("semi-minor axis b (mm)", 2)}  # fmt: skip
    return [
        Row(
            key=f"hertz_scene_{k}",
            check="Hertz scene: crowned roller on a block",
            quantity=q,
            reference=float(ref[i]),
            reference_text=src,
            values=tuple(vals[k]),
            tolerance=tol,
            command=f"{COMMAND} hertz",
            test=test,
        )
        for k, (q, i) in names.items()
    ]


# --------------------------------------------------------------------------------------------
# FZG at the pitch point
# --------------------------------------------------------------------------------------------


def fzg_reference(case=None):
    """The FZG references from the case's design data: ``(PitchPointHertz, SingleStiffness)``
    (:mod:`fegear.validation.iso6336`; basic rack dedendum 1.25 m, fegear's rack cutter)."""
    case = case or _case("fzg_spur.toml")
    p = case.pair
    z1, z2 = p["teeth"]
    x1, x2 = p["profile_shift"]
    b = p["face_width_mm"]
    b = min(b) if isinstance(b, (list, tuple)) else b
    h = pitch_point_line_hertz(z1, z2, p["module_mm"], p["pressure_angle_deg"], x1, x2, b,
                               case.torque2_Nmm, case.E_MPa, case.nu)  # fmt: skip
    c = single_stiffness(z1, z2, x1, x2, alpha_n_deg=p["pressure_angle_deg"], hfP_mn=1.25)
    return h, c


def pitch_point_phi1(pair, n_samples: int = 17) -> float:
    """Pinion angle φ1 (rad) at which a pair of a spur ``pair`` (:class:`~fegear.io.gear_case.
    GearPair`) touches at the pitch point C, from the rigid TCA.

    The contact point of an involute pair runs along the line of action at ``r_b1`` per radian
    of the pinion, so its signed distance ``s`` from C along the line is linear in φ1: sampled
    over one cycle, the pair whose ``s`` changes sign gives φ_C by linear interpolation, checked
    against a TCA at φ_C (within 1e-4 mm of C).

    Raises
    ------
    FegearError
        No pair passes through the pitch point (not a conjugate spur pair).
    """
    asm = pair.assembly
    opt = TCAOptions()
    asm = asm.with_phase2(reference_phase(pair.pinion, pair.gear, asm, opt))
    tca = TCA(pair.pinion, pair.gear, asm, opt)
    rb1, rb2 = pair.pinion.r_b, pair.gear.r_b
    C = np.array([asm.axes_distance() * rb1 / (rb1 + rb2), 0.0])
    n1 = asm.n1
    phi = -np.pi / n1 + 2 * np.pi / n1 * np.arange(n_samples + 1) / n_samples
    pts: dict[int, list[tuple[float, np.ndarray]]] = {}
    for p in tca.positions(phi, with_grids=False):
        for j in np.flatnonzero(p.pair_valid & (p.backlash_mm < 1e-6)):
            pts.setdefault(int(j), []).append((float(p.phi1), np.asarray(p.points[j][:2])))
    for track in pts.values():
        if len(track) < 2:
            continue
        d = track[-1][1] - track[0][1]
        d = d / np.linalg.norm(d)
        s = [float((x - C) @ d) for _, x in track]
        for (pa, _), (pb, _), sa, sb in zip(track, track[1:], s, s[1:], strict=False):
            if sa <= 0.0 <= sb or sb <= 0.0 <= sa:
                phi_c = pa - sa * (pb - pa) / (sb - sa)
                chk = tca.positions(np.array([phi_c]), with_grids=False)[0]
                j = int(np.argmin(np.linalg.norm(chk.points[:, :2] - C, axis=1)))
                miss = float(np.linalg.norm(chk.points[j, :2] - C))
                if miss < 1e-4:
                    return float(phi_c)
                raise FegearError(f"pitch point missed by {miss:.2e} mm at φ1 = {phi_c:.6f} rad")
    raise FegearError("no pair passes through the pitch point over the cycle")


@dataclass(frozen=True)
class PitchPointRun:
    """fegear's loaded FZG pair at the pitch point.

    Attributes
    ----------
    fidelity, level
        How it ran.
    phi1_deg
        Pinion angle of the pitch point (deg).
    n_pairs
        Pairs carrying load (1: the single-pair zone).
    te_elastic_arcsec
        Loaded minus unloaded TE (arcsec; negative: the gear lags).
    c_prime
        Single-pair stiffness per unit face width (N/(mm·µm)).
    p_mid_MPa, p_mid_range_MPa
        Peak pressure at mid-face (MPa; :func:`_mid_face_peak`) and the range of the row peaks
        it averages.
    p_max_MPa
        Largest pressure of the pair anywhere (MPa; the face ends included).
    cells_across
        Contact cells across the patch (inf at ``hertz``).
    seconds
        Wall time (s): meshes and operators (cached after the first run) and the solve.
    """

    fidelity: str
    level: int
    phi1_deg: float
    n_pairs: int
    te_elastic_arcsec: float
    c_prime: float
    p_mid_MPa: float
    p_mid_range_MPa: tuple[float, float]
    p_max_MPa: float
    cells_across: float
    seconds: float


def _mid_face_peak(z: np.ndarray, p: np.ndarray, b: float) -> tuple[float, float, float]:
    """Peak pressure of a line contact at mid-face: the largest cell pressure of each row of
    cells across the line (cells at one face position ``z``, mm), averaged over the rows in the
    middle half of the face width ``b`` (a row: centres within 0.01 mm of each other along the
    face; line Hertz gives the same peak in every such section;
    the average takes out the cell-to-cell scatter of the discrete solution). Returns
    ``(mean, min, max)`` of those row peaks (MPa)."""
    order = np.argsort(z)
    row = np.empty(z.size, dtype=int)
    row[order] = np.concatenate([[0], np.cumsum(np.diff(z[order]) > 0.01)])  # rows 0.01 mm apart
    centre = 0.5 * (z.max() + z.min())
    peaks = [
        float(p[row == k].max())
        for k in range(row.max() + 1)
        if abs(z[row == k].mean() - centre) < 0.25 * b
    ]
    if not peaks:
        raise FegearError("no contact cells in the middle half of the face")
    return float(np.mean(peaks)), min(peaks), max(peaks)


def pitch_point_run(fidelity: str = "hybrid", level: int = 0, case=None) -> PitchPointRun:
    """Run the FZG case (default ``cases/fzg_spur.toml``) at its pitch point (module docstring).

    Parameters
    ----------
    fidelity
        ``"hybrid"``, ``"fe"`` or ``"hertz"``.
    level
        Mesh level.
    case
        A spur :class:`~fegear.io.gear_case.GearCase` (its torque, material and backend).
    """
    case = case or _case("fzg_spur.toml")
    t0 = time.perf_counter()
    pair = build_pair(case)
    phi_c = pitch_point_phi1(pair)
    opt = LTCAOptions(level=level, fidelity=fidelity, n_teeth=case.n_teeth, E_MPa=case.E_MPa,
                      nu=case.nu, backend=case.backend, workers=1)  # fmt: skip
    cyc = run_ltca(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, opt,
                   phi1=np.array([phi_c]))  # fmt: skip
    dt = time.perf_counter() - t0
    pos = cyc.positions[0]
    loaded = [i for i, q in enumerate(pos.pairs) if q.in_contact]
    b = case.pair["face_width_mm"]
    b = float(min(b) if isinstance(b, (list, tuple)) else b)
    rb2 = float(pair.gear.r_b)
    dte = (pos.te_loaded_arcsec - pos.te_unloaded_arcsec) * ARCSEC
    c_prime = case.torque2_Nmm / (rb2**2 * b * abs(dte)) * 1e-3
    ip = max(loaded, key=lambda i: pos.pairs[i].force_N)
    q = pos.pairs[ip]
    if fidelity == "hertz" or not pos.cells:
        p_mid = p_lo = p_hi = p_all = float(q.p_max_MPa)
    else:
        p_mid, p_lo, p_hi = _mid_face_peak(pos.cells[ip].centers[:, 2], pos.pressure[ip], b)
        p_all = float(pos.pressure[ip].max())
    return PitchPointRun(
        fidelity=fidelity,
        level=level,
        phi1_deg=math.degrees(phi_c),
        n_pairs=len(loaded),
        te_elastic_arcsec=dte / ARCSEC,
        c_prime=float(c_prime),
        p_mid_MPa=p_mid,
        p_mid_range_MPa=(p_lo, p_hi),
        p_max_MPa=p_all,
        cells_across=float(q.cells_across),
        seconds=dt,
    )


def fzg_rows(runs: Sequence[PitchPointRun], case=None) -> list[Row]:
    """The FZG rows (line Hertz p_max at mid-face, ISO 6336-1 c'th) from pitch-point runs."""
    case = case or _case("fzg_spur.toml")
    h, c = fzg_reference(case)
    T = case.torque2_Nm
    where = f"FZG type C, {T:g} N·m on the gear, at the pitch point (φ1 = {runs[0].phi1_deg:.3f}°)"

    def note(r: PitchPointRun) -> str:
        s = f"{r.n_pairs} pair{'s' if r.n_pairs > 1 else ''} loaded"
        if math.isfinite(r.cells_across):
            s += f", {r.cells_across:.1f} cells across"
        return s

    p_vals = tuple(
        Value(
            r.fidelity,
            r.level,
            r.p_mid_MPa,
            seconds=r.seconds,
            note=note(r) + f"; row peaks {r.p_mid_range_MPa[0]:.0f}-"
            f"{r.p_mid_range_MPa[1]:.0f}, face ends {r.p_max_MPa:.0f} MPa",
        )  # fmt: skip
        for r in runs
    )
    c_vals = tuple(
        Value(
            r.fidelity,
            r.level,
            r.c_prime,
            seconds=r.seconds,
            note=note(r) + f"; elastic lag {r.te_elastic_arcsec:.2f}″",
        )  # fmt: skip
        for r in runs
    )
    return [
        Row(
            key="fzg_line_hertz",
            check=f"{where}: line Hertz",
            quantity="peak pressure at mid-face (MPa)",
            reference=h.p_H_MPa,
            reference_text=(
                f"line Hertz at the pitch point (Johnson 1985 §4.3; = ISO 6336-2 σH0 with Zε = 1): "
                f"ρ1 {h.rho1_mm:.3f}, ρ2 {h.rho2_mm:.3f} mm at "
                f"α_w {math.degrees(h.alpha_w_rad):.3f}°, "
                f"w = T2/(r_b2 b) = {h.load_N_per_mm:.1f} N/mm, E* {h.E_star_MPa:.0f} MPa; "
                f"contact half-width {h.half_width_mm:.3f} mm"
            ),
            values=p_vals,
            tolerance=(
                "`hybrid` level 0: 3 % (cells 1/10 of the contact width; the mid-face of a 14 mm "
                "line contact is in plane strain as line Hertz assumes)"
            ),
            command=f"{COMMAND} fzg",
            test=f"{TESTS}::test_fzg_pitch_point_hybrid_matches_line_hertz_and_iso_stiffness",
        ),
        Row(
            key="fzg_single_stiffness",
            check=f"{where}: ISO 6336-1 single stiffness",
            quantity="c' = T2 / (r_b2² b |Δφ2|) (N/(mm·µm))",
            reference=c.c_th,
            reference_text=(
                f"ISO 6336-1:2006 Method B theoretical single stiffness c'th = 1/q' (series "
                f"C1…C9, solid disc gears) = {c.c_th:.2f}; compared with c'th itself. ISO's "
                f"c' = c'th·CM·CR·CB·cos β = {c.c_th:.2f}·{c.CM:g}·{c.CR:g}·{c.CB:.3f}·"
                f"{c.cos_beta:g} = {c.c_prime:.2f} adds CM = 0.8 (theory to measured gears: "
                f"shafts, bearings, deviations, none of which the sector models) and CB for "
                f"fegear's 1.25 m rack dedendum"
            ),
            values=c_vals,
            tolerance=(
                "`hybrid` level 0: 10 % (c'th is a fit to solid-disc deflections for a 1.2 m "
                "dedendum, CB −2.5 % for fegear's 1.25 m; the sector's fixed bore and clamped "
                "cuts are not a disc on a shaft)"
            ),
            command=f"{COMMAND} fzg",
            test=f"{TESTS}::test_fzg_pitch_point_hybrid_matches_line_hertz_and_iso_stiffness",
        ),
    ]


# --------------------------------------------------------------------------------------------
# Spiral bevel: the predesigned parabolic TE
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BevelParabola:
    """The unloaded TE of the spiral bevel over one cycle against its design parabola.

    Attributes
    ----------
    design_amplitude_arcsec
        ``te_amplitude_arcsec`` of the case (the synthesis target Δ).
    te_pp_arcsec
        TCA TE peak-to-peak over the cycle.
    curvature_arcsec_per_rad2, design_curvature_arcsec_per_rad2
        Second derivative d²TE/dφ1² of the least-squares parabola through the TCA TE, and the
        design's ``−2 Δ (N1/π)²``.
    vertex_deg
        φ1 of the fitted parabola's vertex (deg; 0 = the design's, the mean point).
    fit_rms_arcsec
        RMS residual of the fit.
    n_positions, seconds
        Positions of the cycle, wall time.
    """

    design_amplitude_arcsec: float
    te_pp_arcsec: float
    curvature_arcsec_per_rad2: float
    design_curvature_arcsec_per_rad2: float
    vertex_deg: float
    fit_rms_arcsec: float
    n_positions: int
    seconds: float


def bevel_te_parabola(case=None, n_positions: int | None = None) -> BevelParabola:
    """Rigid TCA of the nominal spiral bevel (``cases/spiral_bevel_nominal.toml``) and its TE
    parabola (module docstring)."""
    case = case or _case("spiral_bevel_nominal.toml")
    if n_positions is not None:
        case = case.replace(n_positions=n_positions)
    t0 = time.perf_counter()
    r = run(case, fidelity="tca")
    dt = time.perf_counter() - t0
    ok = np.array([p.status == "ok" for p in r.positions])
    phi = np.radians(r.pinion_angle_deg[ok])
    te = r.te_unloaded_arcsec[ok]
    c2, c1, c0 = np.polyfit(phi, te, 2)
    rms = float(np.sqrt(np.mean((np.polyval([c2, c1, c0], phi) - te) ** 2)))
    n1 = int(case.pair["n_pinion"])
    amp = float(case.pair["te_amplitude_arcsec"])
    return BevelParabola(
        design_amplitude_arcsec=amp,
        te_pp_arcsec=float(r.cycle.te_pp_unloaded_arcsec),
        curvature_arcsec_per_rad2=float(2.0 * c2),
        design_curvature_arcsec_per_rad2=-2.0 * amp * (n1 / math.pi) ** 2,
        vertex_deg=math.degrees(-c1 / (2.0 * c2)),
        fit_rms_arcsec=rms,
        n_positions=int(ok.sum()),
        seconds=dt,
    )


def bevel_rows(b: BevelParabola) -> list[Row]:
    """The spiral bevel rows (TE peak-to-peak, TE curvature) from :func:`bevel_te_parabola`."""
    test = f"{TESTS}::test_spiral_bevel_unloaded_te_is_the_design_parabola"
    where = "spiral bevel 12/36 nominal, unloaded TCA over one cycle"
    cmd = f"{COMMAND} bevel"
    note = f"{b.n_positions} positions, vertex at φ1 = {b.vertex_deg:+.2f}°"
    return [
        Row(
            key="bevel_te_pp",
            check=f"{where}: the predesigned parabolic TE",
            quantity="TE peak-to-peak (arcsec)",
            reference=b.design_amplitude_arcsec,
            reference_text=(
                "the design amplitude Δ the pinion's machine settings are synthesized for "
                "(`te_amplitude_arcsec`; Litvin & Fuentes 2004 §9.6, §21.6: Δφ2 = ½ m'21 φ1², "
                "m'21 = −2Δ(N1/π)²)"
            ),
            values=(Value("tca", None, b.te_pp_arcsec, seconds=b.seconds, note=note),),
            tolerance=(
                "5 %: the synthesis fixes the second order at the mean point; the third-order "
                "modified roll centres the parabola, higher orders and the transfer points are "
                "the TCA's"
            ),
            command=cmd,
            test=test,
        ),
        Row(
            key="bevel_te_curvature",
            check=f"{where}: the curvature of the TE parabola",
            quantity="d²TE/dφ1² of the least-squares parabola (arcsec/rad²)",
            reference=b.design_curvature_arcsec_per_rad2,
            reference_text="the design parabola's −2Δ(N1/π)² (same source)",
            values=(
                Value(
                    "tca",
                    None,
                    b.curvature_arcsec_per_rad2,
                    seconds=b.seconds,
                    note=note + f", fit rms {b.fit_rms_arcsec:.3f}″",
                ),  # fmt: skip
            ),
            tolerance="5 %: as the peak-to-peak (the fit spans the whole cycle, not only M)",
            command=cmd,
            test=test,
        ),
    ]


# --------------------------------------------------------------------------------------------
# Seed trend: TE, contact ratio and patch size grow with the load
# --------------------------------------------------------------------------------------------

#: The seed face gear at its light, moderate and heavy loads (``docs/reference_pairs.md``).
TREND_CASES = (
    "face_gear_load_light.toml",
    "face_gear_load_moderate.toml",
    "face_gear_load_heavy.toml",
)


#: How to read a fidelity's trend (docs/ltca/te_vs_load.md).
TREND_NOTES = {
    "hybrid": "resolves the 0.5 mm wide patch at level 0",
    "hertz": (
        "one closed-form Hertz law per pair on a lumped compliance: it misses the entering "
        "pair's corner contact at the face-gear tip that shapes the hybrid TE, so its TE "
        "peak-to-peak levels off (docs/ltca/te_vs_load.md)"
    ),
}


@dataclass(frozen=True)
class TrendPoint:
    """The seed face gear's headline numbers at one load.

    Attributes
    ----------
    torque2_Nmm
        Resisting torque on the face gear (N·mm).
    te_pp_arcsec, te_mean_abs_arcsec
        Loaded TE peak-to-peak and the mean elastic lag |mean loaded TE| (arcsec).
    contact_ratio
        Loaded contact ratio.
    patch_2a_mm
        Largest patch length 2a of a pair away from the flank edges over the cycle (mm).
    seconds
        Wall time (s).
    """

    torque2_Nmm: float
    te_pp_arcsec: float | None
    te_mean_abs_arcsec: float
    contact_ratio: float | None
    patch_2a_mm: float | None
    seconds: float


def trend_point(
    name: str, fidelity: str = "hybrid", level: int = 0, workers: int = 1
) -> TrendPoint:
    """The seed face gear case ``name`` (one of :data:`TREND_CASES`) at one fidelity: its
    :class:`TrendPoint`. ``workers`` processes solve the positions (the result does not depend
    on it; each worker holds the operators: one keeps the memory low)."""
    case = _case(name)
    t0 = time.perf_counter()
    r = run(case, fidelity=fidelity, level=level, workers=workers)
    dt = time.perf_counter() - t0
    axes = [
        2.0 * q.semi_major_mm
        for p in r.positions
        if p.status == "ok"
        for q in p.pairs
        if q.in_contact and not q.edge_contact and q.semi_major_mm is not None
    ]
    return TrendPoint(
        torque2_Nmm=case.torque2_Nmm,
        te_pp_arcsec=r.cycle.te_pp_loaded_arcsec,
        te_mean_abs_arcsec=float(abs(np.nanmean(r.te_loaded_arcsec))),
        contact_ratio=r.cycle.contact_ratio_loaded,
        patch_2a_mm=max(axes) if axes else None,
        seconds=dt,
    )


def load_trend(fidelity: str = "hybrid", level: int = 0, workers: int = 1) -> list[TrendPoint]:
    """The seed face gear at the three seed loads (:data:`TREND_CASES`) at one fidelity."""
    return [trend_point(name, fidelity, level, workers) for name in TREND_CASES]


def load_trend_rows(trends: dict[tuple[str, int], list[TrendPoint]]) -> list[Row]:
    """The trend rows from :func:`load_trend` at several ``(fidelity, level)``."""
    first = next(iter(trends.values()))
    loads = tuple(f"{p.torque2_Nmm:.0e} N·mm".replace("e+0", "e") for p in first)
    quantities = (
        ("te_pp_arcsec", "loaded TE peak-to-peak (arcsec)"),
        ("te_mean_abs_arcsec", "mean elastic lag |mean loaded TE| (arcsec)"),
        ("contact_ratio", "loaded contact ratio"),
        ("patch_2a_mm", "largest interior patch length 2a (mm)"),
    )
    rows = []
    for attr, label in quantities:
        vals = []
        for (fid, lv), pts in trends.items():
            s = tuple(getattr(p, attr) for p in pts)
            vals.append(Value(fid, lv, s[-1], series=s, seconds=sum(p.seconds for p in pts),
                              note=TREND_NOTES.get(fid, "")))  # fmt: skip
        rows.append(
            Row(
                key=f"trend_{attr}",
                check="seed face gear 160/25: grows with the load (seed trend)",
                quantity=label,
                reference=None,
                reference_text=(
                    "rises with the torque (the seed's loaded TCA: TE, contact ratio and patch "
                    "size grow with load); Hertz: a patch grows as F^(1/3)"
                ),
                values=tuple(vals),
                tolerance="strictly increasing over the three loads at `hybrid` level 0",
                command=f"{COMMAND} trend",
                test=f"{TESTS}::test_face_gear_te_contact_ratio_and_patch_grow_with_load",
                loads=loads,
            )
        )
    return rows


# --------------------------------------------------------------------------------------------
# ISO 6336-3 root stress: rows contributed by fegear.validation.iso6336_root
# --------------------------------------------------------------------------------------------

#: The module and function that contribute the ISO 6336-3 nominal root stress rows (σF0 of the
#: FZG pair at the outer point of single contact): ``rows()`` with no required argument,
#: returning :class:`~fegear.validation.Row` objects or mappings with their field names.
ROOT_STRESS_MODULE = "fegear.validation.iso6336_root"
ROOT_STRESS_FUNCTION = "rows"
#: Shown on the page while the hook finds nothing.
ROOT_STRESS_PENDING = (
    "pending: the root stress from the sector FE is not in fegear yet; "
    f"`{ROOT_STRESS_MODULE}.{ROOT_STRESS_FUNCTION}()` will supply these rows"
)


def root_stress_rows() -> list[Row] | None:
    """The root-stress rows from ``fegear.validation.iso6336_root.rows()``, or None while that
    module (or its function) does not exist. Errors inside an existing module propagate."""
    try:
        mod = importlib.import_module(ROOT_STRESS_MODULE)
    except ModuleNotFoundError as e:
        if e.name == ROOT_STRESS_MODULE:
            return None
        raise
    fn = getattr(mod, ROOT_STRESS_FUNCTION, None)
    if not callable(fn):
        return None
    return [as_row(r) for r in fn()]


def pending_root_stress_row() -> Row:
    """The placeholder row of the page while :func:`root_stress_rows` finds nothing: no numbers,
    the reason."""
    return Row(
        key="iso6336_3_root_stress",
        check="FZG type C, 200 N·m on the gear: root stress at the outer point of single contact",
        quantity="pinion and gear σF (MPa) / ISO 6336-3 σF0",
        reference=None,
        reference_text="ISO 6336-3 method B nominal root stress σF0 = Ft/(b mn) YF YS Yβ",
        values=(),
        tolerance="±15 % (ISO's form factors are approximations)",
        command=COMMAND,
        test="tests/test_root_stress.py (the rows' own test)",
        pending=ROOT_STRESS_PENDING,
    )
