"""Unloaded TCA of the reference spiral bevel pair (docs/reference_pairs.md, docs/tca/README.md):
12/36 teeth, 35°, 22.5°, predesigned parabolic TE of 8 arcsec, path angle −8° (drive) on the gear
flank."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fegear.geometry.bevel import SpiralBevelPair
from fegear.geometry.pair_placement import InstallationErrors, spiral_bevel_assembly
from fegear.tca import TCAOptions, flank_map, run_tca
from fegear.tca.bevel import cycle_angles, error_effects, path_angle_on_gear, te_parabola

SIDE = "drive"
DL = 0.05  # mm, ΔE / ΔP / ΔG of the error study
DG = 0.02  # deg, Δγ of the error study


@pytest.fixture(scope="module")
def pair(spiral_bevel_pair) -> SpiralBevelPair:
    return spiral_bevel_pair  # the session's (tests/conftest.py)


@pytest.fixture(scope="module")
def nominal(pair):
    """Error-free pair over 1.25 mesh cycles (both transfer points inside the range)."""
    phi = cycle_angles(pair.blank.n1, 21, margin=0.25)
    return run_tca(pair.pinion, pair.gear, spiral_bevel_assembly(pair, SIDE), TCAOptions(),
                   phi1=phi)  # fmt: skip


@pytest.fixture(scope="module")
def effects(pair):
    cases = {}
    for sg in (1, -1):
        cases[("dE", sg)] = InstallationErrors(dE_mm=sg * DL)
        cases[("dP", sg)] = InstallationErrors(dA1_mm=sg * DL)
        cases[("dG", sg)] = InstallationErrors(dA2_mm=sg * DL)
        cases[("dgamma", sg)] = InstallationErrors(dgamma_deg=sg * DG)
    return error_effects(pair, cases, SIDE, n_positions=13)


def test_native_flank_is_the_engine_surface(pair):
    for m in (pair.pinion, pair.gear):
        for side in ("drive", "coast"):
            fm = flank_map(m, side)
            b = fm.bounds
            u, v = np.meshgrid(np.linspace(0, 1, 5), np.linspace(b.v_start, b.v_end, 5))
            s, th = fm.native(u, v)
            p, n = fm.evaluate(s, th)
            p0, n0 = m.point_normal(side, u, v)
            # both exact (engine point solve to 1e-11 mm, meshing Newton to 1e-14 rad):
            # agreement to round-off of ~100 mm coordinates, far below the 1 µm TCA floor
            assert np.abs(p - p0).max() < 1e-9, (m.name, side)
            assert np.abs(n - n0).max() < 1e-11, (m.name, side)
            uu, vv = fm.flank(s, th, p)
            assert np.abs(uu - u).max() < 1e-10 and np.abs(vv - v).max() < 1e-9
            # equation of meshing holds (sine of the angle between n and v)
            assert m.native_flank(side).meshing_residual(s, th).max() < 1e-10
            # the map's tangents (the table's derivatives) vs central differences (FD truncation
            # + round-off ~1e-8)
            rs, rt = fm.jacobian(s, th, fm.evaluate(s + 0.0, th)[0])
            h = 1e-5
            fs = (fm.evaluate(s + h, th)[0] - fm.evaluate(s - h, th)[0]) / (2 * h)
            ft = (fm.evaluate(s, th + h)[0] - fm.evaluate(s, th - h)[0]) / (2 * h)
            assert np.abs(rs - fs).max() < 1e-6 and np.abs(rt - ft).max() < 1e-6
            # native_point hands over the inversion's last evaluation: the same numbers, exactly
            s2, th2, p2, n2 = fm.native_point(u, v)
            for x, y in ((s2, s), (th2, th), (p2, p), (n2, n)):
                assert x.shape == y.shape and np.array_equal(x, y), (m.name, side)


def test_te_parabola_with_designed_amplitude_and_transfer_points(pair, nominal):
    r, n1 = nominal, pair.blank.n1
    assert r.has_contact.all()
    amp_target = pair.targets.te_amplitude_arcsec
    xv, tv, amp, rms = te_parabola(r, n1)
    # the tolerance: amplitude within 10 % of the 8 arcsec design
    assert abs(amp - amp_target) < 0.1 * amp_target, amp
    # a parabola: the quadratic fit of the mean pair's curve leaves < 1 % of the amplitude
    assert rms < 0.01 * amp_target, rms
    # vertex at the mean position (calibrated TE 0 at φ1 = 0; third-order roll tuned symmetric)
    assert abs(math.degrees(xv)) < 0.2 and abs(tv) < 0.05, (xv, tv)
    cyc = np.abs(r.phi1) <= math.pi / n1 + 1e-9  # one cycle, both transfer positions included
    pp = np.ptp(r.te_arcsec[cyc])
    assert abs(pp - amp_target) < 0.1 * amp_target, pp
    # transfer points: the TE curves of consecutive pairs intersect at ±π/N1 (±15°)
    tp = r.transfer_points
    assert tp.shape == (2, 2), tp
    ang = np.degrees(tp[:, 0])
    # positions 1.875° apart, linear interpolation of two parabolas: ~0.01° on the angle
    assert np.allclose(ang, [-180 / n1, 180 / n1], atol=0.05), ang
    # the TE there is −amplitude (the designed parabola meets its neighbour at its ends)
    assert np.allclose(tp[:, 1], -amp, atol=0.05 * amp_target), tp
    # every pair's curve is a parabola of the same shape shifted by one pitch
    k0 = int(np.nonzero((r.pairs == 0).all(1))[0][0])
    for k in (k0 - 1, k0 + 1):
        m = r.pair_valid[:, k] & (r.pair_te_arcsec[:, k] > -3 * amp_target)
        dk = (k - k0) * 2 * math.pi / n1 * float(np.sign(np.diff(r.phi1)[0]))
        ref = np.interp(r.phi1[m] - dk, r.phi1, r.pair_te_arcsec[:, k0])
        inside = np.abs(r.phi1[m] - dk) <= r.phi1.max()
        assert np.abs(r.pair_te_arcsec[m, k][inside] - ref[inside]).max() < 0.3


def test_contact_path_direction_as_designed(pair):
    eta, target = path_angle_on_gear(pair, SIDE)
    # local synthesis is exact to first order at M; the chord at ±0.02 rad is O(dphi²): 0.5°
    assert abs(eta - target) < 0.5, (eta, target)


def test_nominal_contact_inside_the_flank_and_pattern(pair, nominal):
    r = nominal
    assert not r.edge.any()
    b = pair.gear.boundaries()
    assert np.all((r.gear_uv[:, 0] > 0) & (r.gear_uv[:, 0] < 1))
    assert np.all((r.gear_uv[:, 1] > b.v_start) & (r.gear_uv[:, 1] < b.v_end))
    # longitudinal path: ~11 mm along the 25.4 mm face per cycle, toe → heel
    cyc = np.abs(r.phi1) < math.pi / pair.blank.n1
    L = r.gear_uv[cyc, 1]
    assert np.all(np.diff(L) > 0) and 8.0 < np.ptp(L) < 20.0
    assert r.pattern_pinion.any()
    for p in r.positions:
        for g in p.grids:
            assert np.all(np.isfinite(g.separation)) and np.all(g.separation[g.valid] > -1e-8)
    # Litvin's paint ellipse at every position (point contact, localized)
    assert np.all(r.paint_axes_mm[:, 0] > 0) and np.all(r.paint_axes_mm[:, 0] < 10.0)


def test_errors_te_shift_is_first_order_theory(effects):
    _, eff, _ = effects
    for key, e in eff.items():
        assert e.has_contact, key
        # envelope theorem: ΔTE(0) = −(δr·n)/h to first order; the second-order remainder
        # (contact shift ~2.5 mm on a 1e-3/mm relative curvature) is < 1 % here
        assert abs(e.te0_arcsec - e.te0_first_order_arcsec) < 0.01 * abs(
            e.te0_first_order_arcsec
        ), (key, e)


def test_errors_move_the_pattern_as_theory_says(effects):
    ref, eff, _ = effects
    for name in ("dE", "dP", "dG", "dgamma"):
        p, m = eff[(name, 1)], eff[(name, -1)]
        # small errors act linearly: opposite errors, opposite shifts (10 % + 0.01 mm)
        assert abs(p.dL_mm + m.dL_mm) < 0.1 * abs(p.dL_mm) + 0.01, name
        assert abs(p.dh_mm + m.dh_mm) < 0.1 * abs(p.dh_mm) + 0.01, name
        assert abs(p.te0_arcsec + m.te0_arcsec) < 0.05 * abs(p.te0_arcsec), name
        # Litvin's predesigned parabola absorbs the (linear) TE of the misalignment: the TE
        # stays a parabola of about the designed amplitude (±15 %), no jump at the transfer
        for e in (p, m):
            assert abs(e.amplitude_arcsec - 8.0) < 1.2, (name, e.amplitude_arcsec)
            assert abs(e.te_pp_arcsec - 8.0) < 1.6, (name, e.te_pp_arcsec)
    # the offset ΔE is the strong lengthwise mover (Gleason's V setting) — a shift of several
    # mm toward the toe for +0.05 mm — and moves the parabola the most (the vertex follows
    # the path); ΔG moves the pattern toward the heel, ΔP and Δγ move it little
    dL = {n: eff[(n, 1)].dL_mm for n in ("dE", "dP", "dG", "dgamma")}
    assert dL["dE"] < -1.0 and dL["dG"] > 0.5, dL
    assert abs(dL["dE"]) > 2 * max(abs(dL["dP"]), abs(dL["dG"]), abs(dL["dgamma"])), dL
    assert eff[("dE", 1)].vertex_deg < -3.0 and eff[("dE", -1)].vertex_deg > 3.0
    # all four move the pattern far more along the face than across the profile
    for n in dL:
        assert abs(eff[(n, 1)].dh_mm) < 0.3 * abs(dL[n]) + 0.01, n


def test_no_contact_is_a_flag_not_a_crash(pair):
    # the gear pulled 15 mm away from the apex (more than the whole depth, 9.4 mm): the circles
    # of the pinion points about the gear axis no longer meet the gear flank
    asm = spiral_bevel_assembly(pair, SIDE, InstallationErrors(dA2_mm=15.0))
    r = run_tca(pair.pinion, pair.gear, asm, TCAOptions(n_positions=3))
    assert not r.has_contact.any()
    assert r.te_peak_to_peak_arcsec == 0.0
    for a in (r.te_arcsec, r.pair_te_arcsec, r.gear_uv, r.pinion_uv, r.backlash_mm):
        assert np.all(np.isfinite(a)) and not np.any(a)
    assert all(p.ellipse is None and p.contact_pair == -1 for p in r.positions)


@pytest.fixture(scope="module")
def nominal_path(pair):
    """Pair 0's unloaded contact interval (tca.path) from 13 positions of the error-free pair."""
    from fegear.tca import TCA, reference_phase
    from fegear.tca.path import contact_path

    opt = TCAOptions(separation_grid=None)
    asm = spiral_bevel_assembly(pair, SIDE)
    asm = asm.with_phase2(reference_phase(pair.pinion, pair.gear, asm, opt))
    tca = TCA(pair.pinion, pair.gear, asm, opt)
    pos = tca.positions(cycle_angles(pair.blank.n1, 13), with_grids=False)
    return tca, pos, contact_path(tca, pos)


def test_contact_interval_is_one_pitch_between_transfer_points(pair, nominal_path):
    """The predesigned parabolic TE hands the load over where consecutive pairs' parabolas cross
    (the transfer points at ±π/N1): the interval is one angular pitch, ended by transfers at both
    ends, not by a flank edge; the path never reaches the fillet limit (on the whole generated
    flank the gear's u = 0 lies 0.07-0.36 mm below the pinion's face cone)."""
    tca, pos, cp = nominal_path
    assert cp.start_limit == "transfer" and cp.end_limit == "transfer", cp
    # 13 positions, 4 bisection rounds of 8 per end: each end to τ1/13/9⁴ = 1.2e-5 of a pitch,
    # and the two pairs tie (within tol_rad = 1e-9 rad, on a TE difference of slope ~3e-4) over
    # ~6e-6 of a pitch: 3e-5 (measured 0.999987)
    assert abs(cp.contact_ratio - 1.0) < 3e-5, cp.contact_ratio
    # measured 15.38 mm on the gear flank, toe -> heel (longitudinal path)
    assert 14.0 < cp.length_mm < 17.0, cp.length_mm
    for uv in (cp.gear_uv, cp.pinion_uv):
        assert np.all((uv[:, 0] > 0.05) & (uv[:, 0] < 0.95)), uv[:, 0]
    assert not any("root" in e for p in pos for e in p.edge)


def test_contact_on_the_pinion_tip_is_the_pinion_tip_edge(pair):
    """The pinion pulled back 2.2 mm along its axis moves the pattern down the gear flank until
    the pinion's tip runs on it: that contact is the pinion's tip edge ("pinion:tip"), on the
    gear's working surface (u > 0), never an edge at the gear's flank bottom."""
    asm = spiral_bevel_assembly(pair, SIDE, InstallationErrors(dA1_mm=-2.2))
    opt = TCAOptions(separation_grid=None)
    r = run_tca(pair.pinion, pair.gear, asm, opt, phi1=np.radians([-7.5, -5.0, -2.5, 0.0]))
    cp = [p.contact_pair for p in r.positions]
    tags = [p.edge[k] for p, k in zip(r.positions, cp, strict=True)]
    # measured: the first three positions on the pinion tip (u1 = 1), the last inside
    assert sum("pinion:tip" in t for t in tags) >= 2, tags
    assert not any("gear:root" in t for t in tags), tags
    gu = np.array([p.gear_uv[k][0] for p, k in zip(r.positions, cp, strict=True)])
    assert np.all(gu > 0.1), gu
