"""TCA of the FZG type C spur pair (docs/reference_pairs.md): conjugacy, line of action, contact
ratio, axis-parallelism errors, loss of contact, the separation grid."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fegear.geometry import InvoluteDesign, InvoluteMember
from fegear.geometry.pair_placement import InstallationErrors, involute_assembly
from fegear.tca import (
    ARCSEC,
    TCA,
    TCAOptions,
    contact_interval,
    flank_map,
    reference_phase,
    run_tca,
)

PINION = InvoluteMember(
    InvoluteDesign(16, 4.5, 20, profile_shift=0.1817, face_width_mm=14), "pinion"
)
GEAR = InvoluteMember(InvoluteDesign(24, 4.5, 20, profile_shift=0.1715, face_width_mm=14), "gear")


@pytest.fixture(scope="module")
def conjugate():
    asm = involute_assembly(PINION, GEAR)
    return asm, run_tca(PINION, GEAR, asm, TCAOptions(n_positions=25))


def _alpha_w(asm) -> float:
    a = asm.axes_distance()
    return math.acos((PINION.r_b + GEAR.r_b) / a)


def test_closed_form_involute_matches_generated_surface():
    for m in (PINION, GEAR):
        for side in ("drive", "coast"):
            fm = flank_map(m, side)
            bd = fm.bounds
            u = np.linspace(bd.u_fillet, bd.u_tip, 9)
            v = np.linspace(bd.v_start, bd.v_end, 9)
            p, n = fm.evaluate(*fm.native(u, v))
            p0, n0 = m.point_normal(side, u, v)
            # the envelope engine solves to 1e-15 rad; both are exact to round-off (~1e-13 mm)
            assert np.abs(p - p0).max() < 1e-9
            assert np.abs(n - n0).max() < 1e-12


def test_conjugate_pair_has_zero_te(conjugate):
    _, r = conjugate
    assert r.has_contact.all()
    # conjugate involutes: the TE is identically 0; 1e-3 arcsec is the brief's tolerance
    assert np.abs(r.te_arcsec).max() < 1e-3, np.abs(r.te_arcsec).max()
    assert not np.isnan(r.pair_te_arcsec).any()


def test_contact_on_line_of_action(conjugate):
    asm, r = conjugate
    X = np.array([p.points[p.contact_pair] for p in r.positions])
    aw = _alpha_w(asm)
    # line of action: tangent to both base circles, through the pitch point, inclined by α_w
    d = np.array([math.sin(aw), math.cos(aw), 0.0])
    rw1 = asm.axes_distance() * PINION.r_b / (PINION.r_b + GEAR.r_b)
    rel = X - np.array([rw1, 0.0, 0.0])
    dist = np.linalg.norm(rel - np.outer(rel @ d, d) - np.outer(rel[:, 2], [0, 0, 1]), axis=1)
    # the contact point is the minimiser of a quadratic (θ ~ c Δu²) computed to ~1e-16 rad, so
    # it is located to ~sqrt(1e-16 / c) ~ 1e-7..1e-6 mm (measured 6e-7): 1e-5 mm is sub-µm
    assert dist.max() < 1e-5, dist.max()


def test_contact_ratio_equals_transverse_contact_ratio(conjugate):
    asm, _ = conjugate
    asm = asm.with_phase2(reference_phase(PINION, GEAR, asm))
    a0, a1 = contact_interval(PINION, GEAR, asm)
    eps = (a1 - a0) * asm.n1 / (2 * math.pi)
    aw = _alpha_w(asm)
    pb = math.pi * 4.5 * math.cos(math.radians(20))
    analytic = (
        math.sqrt(PINION.r_a**2 - PINION.r_b**2)
        + math.sqrt(GEAR.r_a**2 - GEAR.r_b**2)
        - asm.axes_distance() * math.sin(aw)
    ) / pb
    # bisection to ~1e-9 rad on both ends: 1e-3 is the brief's tolerance (measured ~1e-8)
    assert abs(eps - analytic) < 1e-3, (eps, analytic)


def test_contact_path_of_one_pair_gives_the_transverse_contact_ratio(conjugate):
    """:func:`fegear.tca.path.contact_path` (pair 0 over its whole interval, from the cycle's
    three pairs, ends bisected) against the closed-form ε_α; the pair enters at the gear tip and
    leaves at the pinion tip; in space the path is the line of action, ε_α p_b long."""
    from fegear.tca import TCA
    from fegear.tca.path import contact_path

    asm, _ = conjugate
    opt = TCAOptions(n_positions=25, separation_grid=None)
    asm = asm.with_phase2(reference_phase(PINION, GEAR, asm, opt))
    tca = TCA(PINION, GEAR, asm, opt)
    phi1 = -np.pi / 16 + 2 * np.pi / 16 * np.arange(25) / 25
    cp = contact_path(tca, tca.positions(phi1, with_grids=False))
    aw = _alpha_w(asm)
    pb = math.pi * 4.5 * math.cos(math.radians(20))
    analytic = (
        math.sqrt(PINION.r_a**2 - PINION.r_b**2)
        + math.sqrt(GEAR.r_a**2 - GEAR.r_b**2)
        - asm.axes_distance() * math.sin(aw)
    ) / pb
    # both ends bisected by 4 rounds of 9 points from a 1/25 cycle step: ~1.5e-6 rad at each
    # end of a 0.39 rad pitch (measured 7.5e-6 in ε)
    assert abs(cp.contact_ratio - analytic) < 2e-5, (cp.contact_ratio, analytic)
    assert cp.start_limit.startswith("gear:tip") and cp.end_limit.startswith("pinion:tip"), cp
    space = np.linalg.norm(cp.fixed_points[-1] - cp.fixed_points[0])
    # the path of a line contact is its mid-face section's (fegear.tca.line_path), on the line
    # of action, its ends at the flank limits through the affine roll maps: ε_α p_b long (the
    # bisected interval's ends are 1e-4 mm coarser; these measured 6e-7 mm from the closed form)
    assert abs(space - analytic * pb) < 1e-5, (space, analytic * pb)
    assert abs(space - PINION.r_b * (cp.phi[-1] - cp.phi[0])) < 1e-9  # unrolled by the base circle


@pytest.mark.parametrize("kind", ["delta", "beta"])
def test_axis_parallelism_error(kind):
    f = 0.02  # mm over the 14 mm face: a coarse ISO 1328 class
    err = (
        InstallationErrors(f_sigma_delta_mm=f)
        if kind == "delta"
        else InstallationErrors(f_sigma_beta_mm=f)
    )
    asm = involute_assembly(PINION, GEAR, err)
    r = run_tca(PINION, GEAR, asm, TCAOptions(n_positions=13, separation_grid=None))
    assert r.has_contact.all()
    # contact runs at one face end: v = -b/2 (in-plane: the smaller centre distance) for +f
    assert r.edge.all()
    # (on the pinion face end, or on the gear face end where the tilted gear is the shorter one)
    v_end = np.where(np.abs(r.pinion_uv[:, 1]) > np.abs(r.gear_uv[:, 1]), r.pinion_uv[:, 1],
                     r.gear_uv[:, 1])  # fmt: skip
    assert np.all(np.abs(np.abs(v_end) - 7.0) < 1e-6), (r.pinion_uv, r.gear_uv)
    aw = _alpha_w(asm.without_errors())
    rw2 = asm.without_errors().axes_distance() * GEAR.r_b / (PINION.r_b + GEAR.r_b)
    # theory (first order, each transverse slice a conjugate involute pair): constant TE,
    # in-plane  +(f/2) tan α_w / r_w2  (end slice at centre distance a − f/2),
    # out-of-plane +(f/2) / r_w2       (end slice shifted f/2 across the centre line)
    expect = (0.5 * f * (math.tan(aw) if kind == "delta" else 1.0) / rw2) / ARCSEC
    # peak-to-peak: zero to first order; what remains is of the order of the tilt (1.4e-3 rad)
    # times the TE (measured 0.007 / 0.022 arcsec = 5e-4 / 6e-4 of it)
    assert r.te_peak_to_peak_arcsec < 1.5e-3 * abs(expect), r.te_peak_to_peak_arcsec
    # the contact sits on the gear's own (tilted) face end, whose slice is ~r f/b inside the
    # nominal end: first-order theory within ~1 % (measured 0.6 % in-plane, 0.03 % out-of-plane)
    assert abs(r.te_arcsec.mean() - expect) < 0.01 * abs(expect), (r.te_arcsec.mean(), expect)
    if kind == "delta":
        assert np.all(v_end < 0)


def test_no_contact_is_a_result_not_a_crash():
    asm = involute_assembly(PINION, GEAR, InstallationErrors(da_mm=30.0))
    r = run_tca(PINION, GEAR, asm, TCAOptions(n_positions=3, separation_grid=None))
    assert not r.has_contact.any()
    assert np.all(np.isfinite(r.te_arcsec)) and np.all(r.contact_pair == -1)


def test_separation_grid_is_a_contact_grid(conjugate):
    asm, r = conjugate
    p = r.positions[3]
    g = p.grids[int(np.nonzero(p.pairs[:, 0] == 0)[0][0])]
    pts, nrm, gap, h, area = g.contact_cells()
    assert len(gap) > 10 and np.all(np.isfinite(gap))
    # the gap is a distance to the mate after closing: >= 0 up to the 1e-10 mm solve tolerance
    assert gap.min() > -1e-9
    # cell areas: positive, summing to the working flank area (face width × involute arc)
    assert area.min() > 0
    # g − θ h is the gap after a further rigid lag θ of the gear: re-solve the separations
    tca = TCA(PINION, GEAR, asm.with_phase2(reference_phase(PINION, GEAR, asm)), TCAOptions())
    dth = 1e-6
    ts = -p.te_rad
    g0 = tca._grids(p.phi1, ts, p.pair_valid)
    g1 = tca._grids(p.phi1, ts + dth, p.pair_valid)
    i = [q.k for q in g0].index(0)
    m = g0[i].valid & g1[i].valid
    fd = (g0[i].separation - g1[i].separation)[m] / dth
    # forward difference of a smooth field: O(θ) = 1e-6 relative, plus 1e-10 mm / 1e-6 solve noise
    assert np.allclose(fd, g0[i].h[m], rtol=1e-5, atol=1e-3), np.abs(fd - g0[i].h[m]).max()
    # near the contact line the normals are nearly collinear and h -> the gear base radius
    # (involute); cells within 1 µm of contact still differ by O(angle²) ~ 1e-4
    near = g0[i].separation[m] < 1e-3
    assert np.allclose(g0[i].h[m][near], GEAR.r_b, rtol=1e-3)


def test_line_hit_from_the_interpolated_start_finds_the_same_flank_points():
    """``TCA.gear_start`` (the start of every Newton solve on the gear flank) interpolates the
    gear's 21 × 21 flank samples over ``(ρ, z)``: it returns the samples themselves at their own
    points and the nearest sample outside them; ``line_hit`` from it (each line iterating only
    until it has converged) meets the gear flank where it does from the nearest sample."""
    from fegear.tca.solve import TOL_MM, line_hit

    asm = involute_assembly(PINION, GEAR)
    tca = TCA(PINION, GEAR, asm, TCAOptions())
    g = tca.fm2.evaluate(tca.ga, tca.gb)[0]
    a, b = tca.gear_start(np.hypot(g[:, 0], g[:, 1]), g[:, 2])
    np.testing.assert_allclose(a, tca.ga, rtol=0, atol=1e-9)  # the nodes, to round-off
    np.testing.assert_allclose(b, tca.gb, rtol=0, atol=1e-9)
    idx = tca.gtree.query([[1e4, 1e4]])[1]  # outside the samples: the nearest one
    assert tca.gear_start(np.array([1e4]), np.array([1e4]))[0] == pytest.approx(tca.ga[idx])
    # lines through points 0.01 mm off the gear flank, along its normal
    rng = np.random.default_rng(1)
    k = rng.choice(tca.ga.size, 40, replace=False)
    p0, n0 = tca.fm2.evaluate(tca.ga[k] + 1e-3, tca.gb[k] + 1e-3)
    Q, N = p0 + 0.01 * n0, -n0
    hit = line_hit(tca.fm2, *tca.gear_start(np.hypot(Q[:, 0], Q[:, 1]), Q[:, 2]), Q, N)
    idx = tca.gtree.query(np.stack([np.hypot(Q[:, 0], Q[:, 1]), Q[:, 2]], -1))[1]
    ref = line_hit(tca.fm2, tca.ga[idx], tca.gb[idx], Q, N)
    assert hit[5].all() and ref[5].all()
    np.testing.assert_allclose(hit[2], 0.01, atol=10 * TOL_MM)  # the separation put in
    np.testing.assert_allclose(hit[3], ref[3], atol=10 * TOL_MM)  # the same flank points


def test_contact_path_of_a_line_contact_does_not_depend_on_the_sampling(conjugate):
    """A line contact's TCA point lies anywhere along the line; the path is its mid-face
    section's, from flank limit to flank limit (fegear.tca.line_path), so its length is the
    same from 9 or 25 positions and, in space, ε_α p_b."""
    from fegear.tca import TCA
    from fegear.tca.path import contact_path

    asm, _ = conjugate
    out = []
    for n in (9, 25):
        opt = TCAOptions(n_positions=n, separation_grid=None)
        a = asm.with_phase2(reference_phase(PINION, GEAR, asm, opt))
        tca = TCA(PINION, GEAR, a, opt)
        phi1 = -np.pi / 16 + 2 * np.pi / 16 * np.arange(n) / n
        out.append(contact_path(tca, tca.positions(phi1, with_grids=False)))
    aw = _alpha_w(asm)
    g_alpha = (
        math.sqrt(PINION.r_a**2 - PINION.r_b**2)
        + math.sqrt(GEAR.r_a**2 - GEAR.r_b**2)
        - asm.axes_distance() * math.sin(aw)
    )
    for cp in out:
        space = np.linalg.norm(np.diff(cp.fixed_points, axis=0), axis=1).sum()
        # the samples on the straight line of action, the ends at the flank limits (the affine
        # fits of the samples' roll parameters: measured 6e-7 mm)
        assert space == pytest.approx(g_alpha, abs=1e-5), space
    # the arc length of the gear flank between the same ends (4001 points: chord error < 1e-9
    # mm); the ends move by the fits' round-off only (measured 1.4e-7 mm of 8.0 mm)
    assert out[0].length_mm == pytest.approx(out[1].length_mm, rel=1e-6)
