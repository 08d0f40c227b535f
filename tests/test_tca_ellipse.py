"""Contact ellipses of the unloaded TCA (:mod:`fegear.tca.ellipse`): the curvatures against the
involute's closed form, the ellipses against closed-form Hertz of the same curvatures, Litvin's
ellipse against the exact separation of the flanks, and the face gear's shaper sweep."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import fegear
from fegear.geometry import InvoluteMember
from fegear.geometry.pair_placement import involute_assembly
from fegear.geometry.transforms import apply_points, apply_vectors
from fegear.mechanics.hertz_closed_form import hertz_point_radii
from fegear.pipeline.pair import build_pair
from fegear.tca import TCA, TCAOptions, reference_phase
from fegear.tca.ellipse import cycle_record, ellipses, outline, record
from fegear.tca.solve import line_hit
from fegear.validation import rows as V

OPT = TCAOptions(separation_grid=None)


def _positions(pinion, gear, asm, phi1):
    asm = asm.with_phase2(reference_phase(pinion, gear, asm, OPT))
    tca = TCA(pinion, gear, asm, OPT)
    return tca, tca.positions(np.atleast_1d(phi1), with_grids=False)


CASES = Path(__file__).resolve().parents[1] / "cases"


@pytest.fixture(scope="module")
def fzg():
    """The FZG case, its pair, the pinion angle of the pitch point and the closed-form radii."""
    case = fegear.load_case(CASES / "fzg_spur.toml")
    pair = build_pair(case)
    return case, pair, V.pitch_point_phi1(pair), V.fzg_reference(case)[0]


def test_fzg_principal_curvatures_are_the_involute_radii_at_the_pitch_point(fzg):
    """The case's pair is unmodified (no crowning, no relief): line contact along the face;
    across the profile the relative curvature is 1/ρ1 + 1/ρ2, ρ_i = r_bi tan α_w."""
    case, pair, phi_c, ref = fzg
    for m in (pair.pinion, pair.gear):  # what "exact" rests on: the case has no crowning
        d = m.design
        assert d.lead_crowning_mm == d.profile_crowning_mm == d.tip_relief_mm == 0.0
    tca, (p,) = _positions(pair.pinion, pair.gear, pair.assembly, phi_c)
    (e,) = ellipses([p], tca.asm.axis1(), case.torque2_Nmm / case.ratio / 1000.0)
    c = e.curvature
    k_ref = 1.0 / ref.rho1_mm + 1.0 / ref.rho2_mm
    # central differences of the exact involute (steps 5e-6 in tan α_y): measured 4.8e-7 for
    # the sum, +7e-6 and −1.1e-5 for the flanks (their errors of 5e-7/mm cancel in the sum)
    assert c.k[1] == pytest.approx(k_ref, rel=1e-5)
    assert c.pinion_k[0] == pytest.approx(1.0 / ref.rho1_mm, rel=3e-5)
    assert c.gear_k[0] == pytest.approx(1.0 / ref.rho2_mm, rel=3e-5)
    # along the face both flanks are straight: k_a = 0 up to round-off of the differences
    assert abs(c.k[0]) < 1e-9 * c.k[1] and abs(c.pinion_k[1]) < 1e-9 and abs(c.gear_k[1]) < 1e-9
    assert e.line_contact and e.paint_a_mm is None and e.hertz is None and e.hertz_reason
    # the zero curvature runs along the axes (z), the other one across the profile
    assert abs(c.major_axis[2]) == pytest.approx(1.0, abs=1e-12)
    assert abs(c.minor_axis[2]) < 1e-12
    assert e.paint_b_mm == pytest.approx(math.sqrt(2 * e.delta_mm / k_ref), rel=1e-5)
    row = record(e)
    assert row["paint"]["a_mm"] is None and row["hertz"] is None and row["line_contact"]


def test_crowned_fzg_ellipses_are_closed_form_hertz_of_the_same_curvatures(fzg):
    """Lead crowning C_β (2z/b)² of the pinion bends its flank along the face by 8 C_β/b²: at
    mid-face (the pitch point, no errors) the pair has the radii (b²/8C_β, ρ1) on (∞, ρ2), a
    closed-form Hertz contact. The TCA's ellipses are that contact's."""
    case, pair, phi_c, ref = fzg
    C = 0.01
    d1 = dataclasses.replace(pair.pinion.design, lead_crowning_mm=C)
    pinion = InvoluteMember(d1, pair.pinion.name)
    asm = involute_assembly(pinion, pair.gear)
    T1 = case.torque2_Nmm / case.ratio / 1000.0
    tca, (p,) = _positions(pinion, pair.gear, asm, phi_c)
    (e,) = ellipses([p], tca.asm.axis1(), T1, E_MPa=case.E_MPa, nu=case.nu)
    b = d1.face_width_mm
    R_crown = b * b / (8 * C)
    # 1e-4: finite differences through the generation engine (measured 1.7e-6 for k_a)
    assert e.curvature.k[0] == pytest.approx(1.0 / R_crown, rel=1e-4)
    assert e.curvature.k[1] == pytest.approx(1.0 / ref.rho1_mm + 1.0 / ref.rho2_mm, rel=1e-4)
    assert abs(e.point[2]) < 1e-6  # mid-face
    # one pair carries the whole torque on the base circle: F = T1 / r_b1 (a spur pair's arm)
    assert e.force_N == pytest.approx(1e3 * T1 / pair.pinion.r_b, rel=1e-12)
    h = hertz_point_radii(e.force_N, (R_crown, ref.rho1_mm), (None, ref.rho2_mm),
                          case.E_MPa, case.nu, case.E_MPa, case.nu)  # fmt: skip
    # the same Hertz solution of curvatures equal to 1e-4 (measured 7e-7 in a, b and p0)
    for got, want in ((e.hertz.a_mm, h.a_mm), (e.hertz.b_mm, h.b_mm),
                      (e.hertz.p0_MPa, h.p0_MPa)):  # fmt: skip
        assert got == pytest.approx(want, rel=1e-4)
    # Litvin's ellipse a = sqrt(2δ/k_a) = b sqrt(δ/4C), b = sqrt(2δ/k_b)
    assert e.paint_a_mm == pytest.approx(b * math.sqrt(e.delta_mm / (4 * C)), rel=1e-4)
    assert e.major_to_face_deg == {"pinion": pytest.approx(0.0, abs=1e-6),
                                   "gear": pytest.approx(0.0, abs=1e-6)}  # fmt: skip
    # the outline on each flank: the tangent-plane ellipse, a along z (the face), b across
    for member in ("pinion", "gear"):
        uv = outline(e, member, "paint", n=5)  # t = 0, 90°, 180°, 270°, 360°
        assert abs(uv[0, 1] - e.point[2]) == pytest.approx(e.paint_a_mm, rel=1e-6)
    row, cyc = record(e), cycle_record([e, None], e.delta_mm, T1)
    assert row["hertz"]["p0_MPa"] == e.hertz.p0_MPa and cyc["positions_with_ellipse"] == [0]
    assert cyc["paint_axis_ratio"] == [e.paint_axis_ratio, e.paint_axis_ratio]


# --------------------------------------------------------------------------------------------
# the seed face gear
# --------------------------------------------------------------------------------------------

#: shapers of the sweep (N1 = 25): the case's 27 and the paper's ellipses' neighbourhood
SHAPERS = (26, 27, 29, 32)


@pytest.fixture(scope="module")
def face_gear_sweep():
    case = fegear.load_case(CASES / "face_gear_nominal.toml")
    T1 = case.torque2_Nmm / case.ratio / 1000.0
    out = {}
    for ns in SHAPERS:
        pair = build_pair(case.replace(pair={**case.pair, "n_shaper": ns}))
        tca, ps = _positions(pair.pinion, pair.gear, pair.assembly, 0.0)
        out[ns] = (tca, ps[0], ellipses(ps, tca.asm.axis1(), T1)[0])
    return out


def test_n_shaper_sweep_is_monotone_in_the_axis_ratio(face_gear_sweep):
    """A larger shaper (N_s − N1 the mismatch) bends the face-gear flank away from the pinion
    along the face: k_a grows ∝ N_s − N1 and the ellipse shortens, a/b = sqrt(k_b/k_a) falls."""
    ns = np.array(SHAPERS, dtype=float)
    ratio = np.array([face_gear_sweep[n][2].paint_axis_ratio for n in SHAPERS])
    ka = np.array([face_gear_sweep[n][2].curvature.k[0] for n in SHAPERS])
    kb = np.array([face_gear_sweep[n][2].curvature.k[1] for n in SHAPERS])
    assert np.all(np.diff(ratio) < 0), ratio
    # proportional to the mismatch (measured 2.373e-5 per tooth within 0.1 %): 1 %
    per_tooth = ka / (ns - 25)
    assert np.ptp(per_tooth) < 0.01 * per_tooth.mean(), per_tooth
    # across the profile the pinion's involute dominates: k_b within 0.5 % of the shapers
    # (measured 0.2 %, the finite differences' noise)
    assert np.ptp(kb) < 0.005 * kb.mean(), kb
    # the point of the reference contact does not move with the shaper (design point, 508 mm)
    pts = np.array([face_gear_sweep[n][2].point for n in SHAPERS])
    assert np.abs(pts - pts[0]).max() < 1e-4, pts
    assert pts[0][0] == pytest.approx(508.0, abs=1e-4)


def _separation_on_outline(tca, p, e, n: int = 8) -> np.ndarray:
    """The exact separation along the pinion normal at the pinion points of the instantaneous
    ellipse's outline (``n`` points), in units of δ."""
    cp = p.contact_pair
    T = tca._tooth_frames(np.array([p.phi1]), np.array([-p.te_rad]))[0][cp]
    uv = outline(e, "pinion", "paint", n=n + 1)[:-1]
    P, N = tca.fm1.evaluate(*tca.fm1.native(uv[:, 0], uv[:, 1]))
    Q, NQ = apply_points(T, P), apply_vectors(T, N)
    a2, b2 = tca.gear_start(np.hypot(Q[:, 0], Q[:, 1]), Q[:, 2])
    *_, s, _, _, ok = line_hit(tca.fm2, a2, b2, Q, NQ)
    assert ok.all()
    return s / e.delta_mm


def test_instantaneous_ellipse_is_the_level_curve_of_the_exact_separation(face_gear_sweep):
    """Litvin's ellipse is the second-order (quadratic) approximation of the level curve
    ``h = δ`` of the exact separation: on its outline the exact separation is δ up to the
    cubic terms, whose share falls with the ellipse's size a ∝ δ^(1/2)."""
    tca, p, _ = face_gear_sweep[27]
    T1 = 350.14
    err = []
    for delta in (1e-4, 2.5e-5):  # a = 2.1 mm and 1.0 mm on the seed face gear
        (e,) = ellipses([p], tca.asm.axis1(), T1, delta_mm=delta)
        err.append(np.abs(_separation_on_outline(tca, p, e) - 1.0).max())
    # measured 3.3 % and 1.6 % (0.8 % at a = 0.5 mm; at 6.32 µm, a = 16 mm: +29 % and −6 % at
    # the ends of the major axis, −20 % between)
    assert err[0] < 0.06, err
    rate = math.log(err[0] / err[1]) / math.log(2.0)  # a halves: the error should halve
    assert 0.8 < rate < 1.3, (rate, err)


def test_summary_of_the_seed_face_gear_has_the_ellipses(fegear_cache):
    case = fegear.load_case(CASES / "face_gear_nominal.toml")
    s = fegear.run(case, fidelity="tca").summary
    cyc = s["cycle"]["contact_ellipses"]
    rows = [p["contact_ellipse"] for p in s["positions"]]
    assert all(r is not None and not r["line_contact"] for r in rows)
    p0 = [r["hertz"]["p0_MPa"] for r in rows]
    # the same Hertz as the TCA's own (cycle.hertz_p0_max_MPa): one code path
    assert max(p0) == s["cycle"]["hertz_p0_max_MPa"] == cyc["hertz_p0_MPa"][1]
    for r in rows:
        ka, kb = r["principal_relative_curvatures_per_mm"]
        assert r["paint"]["axis_ratio"] == pytest.approx(math.sqrt(kb / ka), rel=1e-12)
        xi, eta = np.array(r["principal_directions"])
        n = np.array(r["normal"])
        assert abs(xi @ eta) < 1e-12 and abs(xi @ n) < 1e-12 and abs(eta @ n) < 1e-12
        # an involute pinion's normal is tangent to its base circle: F = T1 / r_b1 (71.937 mm)
        assert r["hertz"]["force_N"] == pytest.approx(350.14e3 / 71.937, rel=1e-4)
    assert cyc["pinion_torque_Nm"] == pytest.approx(350.14)
