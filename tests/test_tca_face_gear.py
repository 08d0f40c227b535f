"""TCA of the seed face gear (docs/reference_pairs.md): localized contact, Δγ = −0.02°, 0, +0.02°,
Hertz."""

from __future__ import annotations

import numpy as np
import pytest

from fegear.geometry import FaceGearDesign, FaceGearMember, InvoluteDesign, InvoluteMember
from fegear.geometry.pair_placement import InstallationErrors, face_gear_assembly
from fegear.tca import TCAOptions, flank_map, run_tca

FG = FaceGearMember(FaceGearDesign())
# FaceGearMember.pinion() uses the default rack tip radius 0.38 m, which the involute validation
# refuses at α = 25° (max 0.318): the pinion is built here with 0.25 m (it only shapes the fillet)
PINION = InvoluteMember(
    InvoluteDesign(25, 6.35, 25.0, rack_tip_radius_coeff=0.25, face_width_mm=90.0), "pinion"
)


@pytest.fixture(scope="module")
def cycles():
    out = {}
    for dg in (-0.02, 0.0, 0.02):
        asm = face_gear_assembly(FG, InstallationErrors(dgamma_deg=dg), PINION)
        out[dg] = run_tca(PINION, FG, asm, TCAOptions(n_positions=25, pinion_torque_Nm=350.14))
    return out


def test_closed_form_face_gear_matches_generated_surface():
    for side in ("drive", "coast"):
        fm = flank_map(FG, side)
        bd = fm.bounds
        u = np.linspace(bd.u_fillet, bd.u_tip, 5)
        v = np.linspace(bd.v_start, bd.v_end, 5)
        p, n = fm.evaluate(*fm.native(u, v))
        p0, n0 = FG.point_normal(side, u, v)
        # both exact (engine inversion to 1e-12 mm): agreement to round-off of 500 mm coordinates
        assert np.abs(p - p0).max() < 1e-9
        assert np.abs(n - n0).max() < 1e-12


def test_point_jacobian_is_evaluate_and_jacobian_bit_for_bit():
    """The Newton solves' one-call point and Jacobian (the forward-difference points sharing the
    roll or the turn of the point; the pinion's stacked in one evaluation) are the numbers of
    ``evaluate`` then ``jacobian``, whatever the batch."""
    rng = np.random.default_rng(7)
    pin = flank_map(PINION, "drive")
    for fm in (flank_map(FG, "drive"), flank_map(FG, "coast"), pin):
        lo, hi = fm.native_box()
        a = rng.uniform(lo[0], hi[0], 37)
        b = rng.uniform(lo[1], hi[1], 37)
        p, n, ra, rb = fm.point_jacobian(a, b)
        p0, n0 = fm.evaluate(a, b)
        ra0, rb0 = fm.jacobian(a, b, p0)
        for x, y in ((p, p0), (n, n0), (ra, ra0), (rb, rb0)):
            assert x.tobytes() == y.tobytes()
        for k in (0, 5, 36):  # one point alone
            q, m, qa, qb = fm.point_jacobian(a[k], b[k])
            for x, y in ((q, p0[k]), (m, n0[k]), (qa, ra0[k]), (qb, rb0[k])):
                assert x.tobytes() == y.tobytes()


def test_localized_contact(cycles):
    r = cycles[0.0]
    assert r.has_contact.all()
    a, b = r.paint_axes_mm[:, 0], r.paint_axes_mm[:, 1]
    m = a > 0
    # point contact: finite ellipses, much shorter than the 89 mm face, elongated along the face
    assert m.sum() >= 20
    assert np.all(a[m] < 0.5 * 89.0) and np.all(b[m] < a[m])
    # the conjugate path runs at a nearly constant radius (inside the face) across the profile
    L = r.gear_uv[:, 1]
    assert np.all((L > 471.0) & (L < 560.0))
    z = FG.height(r.gear_uv[:, 0], r.gear_uv[:, 1])
    assert np.ptp(z) > 5.0, z  # from near the root to near the tip (mm of height)


def test_shaft_angle_error_moves_the_path_not_the_te_shape(cycles):
    Lm = {dg: float(np.median(r.gear_uv[:, 1])) for dg, r in cycles.items()}
    # Δγ < 0 moves the bearing contact toward the inner end, Δγ > 0 toward the outer end
    assert Lm[-0.02] < Lm[0.0] - 5.0 and Lm[0.02] > Lm[0.0] + 5.0, Lm
    for dg, r in cycles.items():
        # face gear + involute pinion: the TE is constant (Litvin), a shaft-angle error only
        # offsets it; on the whole generated flank no position runs onto a flank bottom (the
        # flank cut at one height made edge contacts that dipped by ~0.5 arcsec): every position
        # agrees to 1e-3 arcsec
        assert np.ptp(r.te_arcsec) < 1e-3, (dg, r.te_arcsec)
    assert abs(np.median(cycles[0.0].te_arcsec)) < 1e-3


def test_hertz_along_the_path(cycles):
    r = cycles[0.0]
    m = r.hertz_axes_mm[:, 0] > 0
    assert m.sum() >= 20
    a, b, p0 = r.hertz_axes_mm[m, 0], r.hertz_axes_mm[m, 1], r.hertz_p0_MPa[m]
    assert np.all(np.isfinite(a)) and np.all(b > 0) and np.all(a > b)
    # Hertz equilibrium: F = (2/3) p0 π a b with F = T1 / (moment arm ~ r_b1)
    F = np.array([p.ellipse.force_N for p in r.positions if p.ellipse and p.ellipse.hertz])
    assert np.allclose(F, 2 / 3 * p0 * np.pi * a * b, rtol=1e-9)
    assert np.allclose(F, 350.14e3 / PINION.r_b, rtol=1e-6)  # involute: the arm is r_b1


def test_huge_error_gives_no_contact():
    asm = face_gear_assembly(FG, InstallationErrors(dE_mm=80.0), PINION)
    r = run_tca(PINION, FG, asm, TCAOptions(n_positions=2, separation_grid=None))
    assert not r.has_contact.any()
    assert np.all(np.isfinite(r.te_arcsec))


@pytest.fixture(scope="module")
def nominal_path():
    from fegear.tca import TCA, reference_phase
    from fegear.tca.path import contact_path

    out = {}
    for n in (25, 50):
        opt = TCAOptions(n_positions=n, separation_grid=None)
        asm = face_gear_assembly(FG, InstallationErrors(), PINION)
        asm = asm.with_phase2(reference_phase(PINION, FG, asm, opt))
        tca = TCA(PINION, FG, asm, opt)
        pos = tca.positions(-np.pi / 25 + 2 * np.pi / 25 * np.arange(n) / n, with_grids=False)
        out[n] = (tca, pos, contact_path(tca, pos))
    return out


def test_the_path_runs_from_the_face_gear_tip_to_the_pinion_tip(nominal_path):
    """On the whole generated flank (fillet limit a curve over the face) the seed's path is not
    cut short: the pair enters where the face-gear tip meets the pinion flank and leaves at the
    pinion tip, with a contact ratio above 1 and no contact on the face gear's flank bottom."""
    tca, pos, cp = nominal_path[25]
    assert cp.start_limit == "gear:tip" and cp.end_limit == "pinion:tip", cp
    assert not any("gear:root" in e for p in pos for e in p.edge)
    # measured 1.554 (the flank cut at one height gave < 1, the changeover an edge contact)
    assert 1.5 < cp.contact_ratio < 1.6, cp.contact_ratio
    z = FG.height(cp.gear_uv[:, 0], cp.gear_uv[:, 1])
    # enters at the tip plane: the bisection ends within ~1.5e-6 rad, the contact point moves
    # ~10 mm/rad up the flank (measured 1.7e-5 mm below the tip)
    assert abs(z[0] - FG.tip_height) < 1e-4, z[0]
    assert z[-1] < -5.0  # leaves 5.5 mm below the pitch plane, below the old cut at -0.8 mm


def test_the_path_of_contact_lies_in_the_plane_of_action(nominal_path):
    """Spur involute pinion: every contact point lies in its plane of action (tangent to the base
    cylinder) and the transverse path is r_b1 Δφ1 (invariants of the involute)."""
    tca, _, cp = nominal_path[25]
    o, e = tca.asm.axis1()
    x = cp.fixed_points - o
    xt = x - np.outer(x @ e, e)  # transverse projection
    # the plane of action: the line through the transverse points has them at distance r_b1
    # from the axis along its normal; check the straightness and the length
    d = xt[-1] - xt[0]
    length = np.linalg.norm(d)
    off = np.linalg.norm(np.cross(xt - xt[0], d / length), axis=-1)
    # straight: the TCA locates the minimum of the angular gap, a quadratic, so its position is
    # known to about the square root of the gap precision (measured 2.2e-5 mm)
    assert off.max() < 1e-4, off.max()
    dphi = cp.phi_end - cp.phi_start
    assert abs(length - PINION.r_b * dphi) < 1e-6 * length, (length, PINION.r_b * dphi)
    assert abs(dphi / (2 * np.pi / 25) - cp.contact_ratio) < 1e-12


def test_the_contact_ratio_does_not_depend_on_the_sampling(nominal_path):
    a, b = nominal_path[25][2], nominal_path[50][2]
    # the ends come from bisection to ~1e-6 rad of a 0.25 rad pitch
    assert abs(a.contact_ratio - b.contact_ratio) < 2e-5, (a.contact_ratio, b.contact_ratio)
    # the length is a polyline through the samples: chord sag O(h²κ) (measured below 0.1 %)
    assert abs(a.length_mm / b.length_mm - 1) < 1e-3, (a.length_mm, b.length_mm)
