"""Spiral bevel generation, synthesis and a small TCA of the mean tooth pair (reference design).

Reference pair (docs/reference_pairs.md): 12/36 teeth, outer module 4.94 mm, β 35°, α 22.5°, F 25.4
mm, Σ 90°, predesigned parabolic TE 8 arcsec. Mesh frame: apex at the origin, pinion axis +z, gear
axis +x.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from fegear.errors import DesignError, InputError
from fegear.geometry.bevel import (
    SpiralBevelBlank,
    SpiralBevelPair,
    SynthesisTargets,
)
from fegear.geometry.surface import GeneratedMember, finite_difference_curvatures, unit
from fegear.geometry.transforms import apply_points, apply_vectors

ARCSEC = math.pi / (180 * 3600)
SIDES = ("drive", "coast")


@pytest.fixture(scope="module")
def pair(spiral_bevel_pair) -> SpiralBevelPair:
    return spiral_bevel_pair  # the session's (tests/conftest.py)


def members(pair):
    return (pair.pinion, pair.gear)


def test_protocol(pair):
    for m in members(pair):
        assert isinstance(m, GeneratedMember)
        assert m.tooth_angle == pytest.approx(2 * math.pi / m.n_teeth)


def test_meshing_equation_holds_everywhere(pair):
    for m in members(pair):
        for side in SIDES:
            fl = m.flank(side, 21, 11)
            res = float(fl.meshing_residual.max())
            # Newton on n·v stops at |n·v|/|v| < 1e-15 or a 1e-15 rad bracket; 1e-11 leaves room
            # for points near the pitch line where |v| is small
            assert res < 1e-11, f"{m.name} {side}: max |n·v|/|v| = {res:.2e}"
            assert np.all(np.isfinite(fl.points)) and np.all(np.isfinite(fl.kappa))


def _angles_at_mean(m, side):
    """Pressure and spiral angle (deg) at the mean point from an FD normal of the surface."""
    um, vm = m.mean_parameters(side)  # u of the pitch cone depends on the side's fillet limit
    f = lambda a, b: m.point_normal(side, a, b)[0]  # noqa: E731
    h = 1e-4
    ru = (f(um + h, vm) - f(um - h, vm)) / (2 * h)
    rv = (f(um, vm + 1e-3) - f(um, vm - 1e-3)) / 2e-3
    p, n_exact = m.point_normal(side, um, vm)
    n = unit(np.cross(ru, rv))
    n *= np.sign(n @ n_exact)
    g = m.pitch_angle
    th = math.atan2(p[1], p[0])
    e_g = unit(p)
    e_p = np.array([math.cos(g) * math.cos(th), math.cos(g) * math.sin(th), -math.sin(g)])
    alpha = math.degrees(math.asin(n @ e_p))
    t = unit(np.cross(e_p, n))  # tooth trace: tangent to flank and pitch cone
    beta = math.degrees(math.acos(abs(t @ e_g)))
    return alpha, beta, p @ e_g, p @ e_p


def test_mean_point_spiral_and_pressure_angle(pair):
    b = pair.blank
    for m in members(pair):
        for side in SIDES:
            alpha, beta, L, h = _angles_at_mean(m, side)
            # design requirement 0.05°; FD normal (h = 1e-4) is accurate to ~1e-6°
            assert abs(alpha - b.pressure_angle_deg) < 0.05, f"{m.name} {side}: α = {alpha}"
            assert abs(beta - b.spiral_angle_deg) < 0.05, f"{m.name} {side}: β = {beta}"
            # the mean point is on the pitch cone at the mean cone distance (solver tol 1e-11)
            assert L == pytest.approx(b.mean_cone_distance(m.index), abs=1e-9)
            assert abs(h) < 1e-9


def test_face_width_toe_to_heel(pair):
    b = pair.blank
    for m in members(pair):
        bd = m.boundaries()
        assert bd.v_end - bd.v_start == pytest.approx(b.face_width_mm, abs=1e-12)
        for side in SIDES:
            fl = m.flank(side, 5, 3)
            g = m.pitch_angle
            rho = np.hypot(fl.points[..., 0], fl.points[..., 1])
            L = fl.points[..., 2] * math.cos(g) + rho * math.sin(g)
            # toe and heel columns lie on the front / back cones (point solve tol 1e-11 mm)
            assert np.allclose(L[:, 0], b.outer_cone_distance(m.index) - b.face_width_mm, atol=1e-9)
            assert np.allclose(L[:, -1], b.outer_cone_distance(m.index), atol=1e-9)
            span = float(np.max(L[:, -1] - L[:, 0]))
            assert span == pytest.approx(25.4, abs=1e-9), f"{m.name} {side}: span {span}"


def test_teeth_not_pointed(pair):
    for m in members(pair):
        b = m.boundaries()
        v = np.linspace(b.v_start, b.v_end, 7)
        a, _ = m.point_normal("drive", 1.0, v)
        c, _ = m.point_normal("coast", 1.0, v)
        land = (np.arctan2(a[:, 1], a[:, 0]) - np.arctan2(c[:, 1], c[:, 0])) * np.hypot(
            a[:, 0], a[:, 1]
        )
        # top land (arc between the flanks at the face cone) must stay positive toe to heel;
        # 0.5 mm is a practical minimum for hardened teeth (the reference pair has > 1 mm)
        assert land.min() > 0.5, f"{m.name}: top land {land.round(3)} mm"


def test_curvatures_match_finite_differences(pair):
    for m in members(pair):
        for side in SIDES:
            fl = m.flank(side, 9, 7)
            # not the bottom row: a central difference there straddles the fillet limit, where
            # the fillet (another surface, G1 only) begins
            U, V = np.meshgrid(fl.u[1:], fl.v, indexing="ij")
            k_fd, _ = finite_difference_curvatures(
                lambda a, b, m=m, side=side: m.point_normal(side, a, b)[0],
                U,
                V,
                (1e-3, 1e-2),
                normals=fl.normals[1:],
            )
            err = float(np.abs(k_fd - fl.kappa[1:]).max())
            # central differences: O(h²) truncation with h ≈ 0.007 mm (profile) / 0.01 mm
            # (face) plus point-solve noise 1e-11/h²; the observed error is < 1e-5 1/mm on
            # curvatures up to 0.25 1/mm
            assert err < 3e-5, f"{m.name} {side}: max |κ − κ_FD| = {err:.2e} 1/mm"


def test_conjugacy_at_mean_point_and_synthesis_target(pair):
    delta = pair.targets.paint_thickness_mm
    for side in SIDES:
        pin, gear = pair.mesh_placement(side)
        e1 = pair.pinion.evaluate(side, *pair.pinion.mean_parameters(side))
        e2 = pair.gear.evaluate(side, *pair.gear.mean_parameters(side))
        P1, P2 = apply_points(pin(0.0), e1.points), apply_points(gear(0.0), e2.points)
        N1, N2 = apply_vectors(pin(0.0), e1.normals), apply_vectors(gear(0.0), e2.normals)
        # same point, opposite outward normals (both from 1e-11 mm point solves)
        assert np.linalg.norm(P1 - P2) < 1e-9, f"{side}: |P1 − P2| = {np.linalg.norm(P1 - P2)}"
        assert np.linalg.norm(N1 + N2) < 1e-9, f"{side}: |N1 + N2| = {np.linalg.norm(N1 + N2)}"
        rep = pair.reports[side]
        t = rep.path_direction
        D1 = apply_vectors(pin(0.0), e1.directions)
        D2 = apply_vectors(gear(0.0), e2.directions)
        kn = float(np.sum(e1.kappa * (D1 @ t) ** 2) + np.sum(e2.kappa * (D2 @ t) ** 2))
        target = rep.relative_curvature[0, 0]
        # independent path (principal curvatures of both generated surfaces vs the synthesis
        # matrix); both come from the engine's IFT curvatures, exact to ~1e-10
        assert kn == pytest.approx(target, rel=1e-6), f"{side}: κ_rel(t) {kn} vs {target}"
        # full relative curvature tensor -> contact-ellipse major axis at the paint thickness
        K = sum(k * np.outer(d, d) for k, d in zip(e1.kappa, D1, strict=True))
        K = K + sum(k * np.outer(d, d) for k, d in zip(e2.kappa, D2, strict=True))
        q = np.cross(N2, t)
        B = np.stack([t, q])
        lam = np.linalg.eigvalsh(B @ K @ B.T)
        major = 2 * math.sqrt(2 * delta / lam[0])
        assert major == pytest.approx(pair.targets.ellipse_major_axis_mm, rel=1e-6)


def _tca(pair, side, phis):
    """Unloaded TCA of tooth 0 of both members: contact point and φ2 for each φ1 (rad).

    Unknowns ``(u1, v1, u2, v2, φ2)``; equations ``P(φ1) r1 = G(φ2) r2`` and
    ``P n1 + G n2 = 0`` (6 equations of rank 5, Gauss-Newton with a forward-difference
    Jacobian). Continuation from the mean contact position.
    """
    pin, gear = pair.mesh_placement(side)
    steps = np.array([1e-6, 1e-5, 1e-6, 1e-5, 1e-9])

    def F(x, phi1):
        X = x[None, :] + np.vstack([np.zeros(5), np.diag(steps)])
        p1, n1 = pair.pinion.point_normal(side, X[:, 0], X[:, 1])
        p2, n2 = pair.gear.point_normal(side, X[:, 2], X[:, 3])
        P, Gm = pin(phi1), gear(X[:, 4])
        r = np.concatenate(
            [
                apply_points(P, p1) - apply_points(Gm, p2),
                apply_vectors(P, n1) + apply_vectors(Gm, n2),
            ],
            -1,
        )
        return r[0], ((r[1:] - r[0]) / steps[:, None]).T

    u1, v1 = pair.pinion.mean_parameters(side)
    u2, v2 = pair.gear.mean_parameters(side)
    x_mean = np.array([u1, v1, u2, v2, 0.0])
    out = {}
    for branch in (phis[phis >= 0], phis[phis < 0][::-1]):
        x = x_mean.copy()
        for phi1 in branch:
            x[4] = pair.blank.m21 * phi1 if phi1 == 0 else x[4]
            for _ in range(30):
                r, J = F(x, phi1)
                dx = np.linalg.lstsq(J, -r, rcond=None)[0]
                x = x + dx
                if np.max(np.abs(dx[[1, 3]])) < 1e-9 and abs(dx[4]) < 1e-13:
                    break
            out[float(phi1)] = (x.copy(), float(np.max(np.abs(F(x, phi1)[0]))))
    keys = sorted(out)
    return np.array(keys), np.array([out[k][0] for k in keys]), np.array([out[k][1] for k in keys])


@pytest.mark.parametrize("side", SIDES)
def test_tca_parabolic_transmission_error(pair, side):
    n1 = pair.blank.n1
    phis = np.linspace(-math.pi / n1, math.pi / n1, 7)
    phi1, X, res = _tca(pair, side, phis)
    # contact conditions solved to ~1e-10 (mm and unit normals)
    assert res.max() < 1e-8, f"{side}: TCA residual {res.max():.1e}"
    te = (X[:, 4] - pair.blank.m21 * phi1) / ARCSEC
    c = np.polyfit(phi1, te, 2)
    amp = -c[0] * (math.pi / n1) ** 2
    target = pair.targets.te_amplitude_arcsec
    # local synthesis fixes only the second derivative at the mean point; 10 % allowed for the
    # higher-order terms over the cycle
    assert amp == pytest.approx(target, rel=0.10), f"{side}: TE {te.round(3)} arcsec, amp {amp}"
    # a predesigned parabola: symmetric, no linear term
    assert abs(c[1]) * math.pi / n1 < 0.1 * target, f"{side}: linear TE term {c[1]}"
    # the contact point stays inside the face width over the cycle
    b = pair.gear.boundaries()
    assert np.all((X[:, 3] > b.v_start) & (X[:, 3] < b.v_end)), f"{side}: path L {X[:, 3]}"


def test_override_single_setting(pair):
    s = pair.settings
    new = dataclasses.replace(
        s, pinion_drive=dataclasses.replace(s.pinion_drive, modified_roll=0.0)
    )
    p2 = SpiralBevelPair.design(pair.blank, pair.targets, settings=new)  # only the roll differs
    assert p2.pinion.drive.modified_roll == 0.0
    a, _ = p2.pinion.point_normal("drive", 0.5, 85.0)
    b, _ = pair.pinion.point_normal("drive", 0.5, 85.0)
    assert np.linalg.norm(a - b) > 1e-6  # the override changes the surface


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"n1": 3}, "spiral_bevel.n1"),
        ({"n1": 40}, "spiral_bevel.n1"),
        ({"n2": 12.5}, "spiral_bevel.n2"),
        ({"module_mm": -1.0}, "spiral_bevel.module_mm"),
        ({"face_width_mm": 0.0}, "spiral_bevel.face_width_mm"),
        ({"face_width_mm": 60.0}, "spiral_bevel.face_width_mm"),
        ({"pressure_angle_deg": 35.0}, "spiral_bevel.pressure_angle_deg"),
        ({"spiral_angle_deg": 60.0}, "spiral_bevel.spiral_angle_deg"),
        ({"shaft_angle_deg": 180.0}, "spiral_bevel.shaft_angle_deg"),
        ({"cutter_radius_mm": 10.0}, "spiral_bevel.cutter_radius_mm"),
        ({"edge_radius_mm": -0.5}, "spiral_bevel.edge_radius_mm"),
    ],
)
def test_validation(kwargs, field):
    with pytest.raises(InputError) as e:
        SpiralBevelBlank(**kwargs)
    assert e.value.field == field
    assert "must be" in str(e.value)


def test_validation_targets():
    with pytest.raises(InputError, match="te_amplitude_arcsec"):
        SynthesisTargets(te_amplitude_arcsec=-1.0)
    with pytest.raises(DesignError, match="path_angle_drive_deg"):
        # near the direction where the relative curvature along the path vanishes
        SpiralBevelPair.design(targets=SynthesisTargets(path_angle_drive_deg=15.5))


# ------------------------------------------------------------------ fillet limit and fillet
def _members_sides():
    return [(m, s) for m in ("pinion", "gear") for s in SIDES]


def _edge_envelope_at(m, side, L, w):
    """The edge-radius envelope at arc angle ``w`` and cone distance ``L``: the engine's root of
    the equation of meshing on the torus, θ by a bracketed scalar root on ``L(θ) = L`` (no
    Newton, no tables: an independent path to the point)."""
    from scipy.optimize import brentq

    from fegear.geometry.generation import generate

    tool, mot = m.edge_tool(side), m._tools(side)[1]
    g = m.pitch_angle
    th0 = float(m._limit_table(side)[1](L))
    psi0 = float(m._limit_table(side)[2](L))

    def point(th):
        return generate(tool, mot, w, th, psi0, half_width=0.3).points

    def f(th):
        p = point(th)
        return p[2] * math.cos(g) + math.hypot(p[0], p[1]) * math.sin(g) - L

    return point(brentq(f, th0 - 0.05, th0 + 0.05, xtol=1e-15))


@pytest.mark.parametrize(("name", "side"), _members_sides())
def test_fillet_limit_lies_on_the_blade_and_on_the_edge_radius_envelopes(pair, name, side):
    """At 25 cone distances toe → heel the bottom of the working surface (``u = 0``, the curve
    every consumer uses: spline height + blade inversion) is where the blade's envelope meets the
    envelope of its edge radius: the line generated by the blade's end ``s_b``."""
    m = getattr(pair, name)
    b = m.boundaries()
    L = np.linspace(b.v_start, b.v_end, 25)
    p = m.point_normal(side, np.zeros_like(L), L)[0]
    # 1) on the blade envelope at the blade's end (Newton on θ at s = s_b, engine)
    d_blade = np.linalg.norm(p - m.fillet_limit(side, L).points, axis=-1)
    # 2) on the edge-radius envelope at ϑ_b (bracketed root, engine)
    wb = m.edge_tool(side).theta_blade
    q = np.array([_edge_envelope_at(m, side, Li, wb) for Li in L])
    d_edge = np.linalg.norm(p - q, axis=-1)
    msg = (
        f"max distance to the blade-end line {d_blade.max():.1e} mm, edge radius {d_edge.max():.1e}"
    )
    # the issue asks for 1e-6 mm: the curve is a spline of the exact limit (measured ~1e-11)
    assert d_blade.max() < 1e-6 and d_edge.max() < 1e-6, msg
    # the working flank starts at the blade's end on both sides: s = s_b there (Newton 1e-11 mm
    # in (L, h) on a blade of slope ~1: 1e-9 in s)
    ev = m.evaluate(side, np.zeros_like(L), L)
    assert np.abs(ev.tool_s - m.edge_tool(side).s_blade).max() < 1e-8
    # a curve over the face, not a constant: it follows the root cone (standard taper) down
    # toward the heel, 0.6-0.9 mm (pinion) / 2 mm (gear) over the face
    h = m.fillet_height(L, side)
    assert np.all(np.diff(h) < 0) and h[0] - h[-1] > 0.5, h.round(4)


@pytest.mark.parametrize(("name", "side"), _members_sides())
def test_fillet_meets_the_flank_tangentially_and_the_root_cone_at_its_bottom(pair, name, side):
    m = getattr(pair, name)
    b = m.boundaries()
    L = np.linspace(b.v_start, b.v_end, 21)
    # u = 0: fillet and flank meet with a common point and tangent plane (G1): blade and edge
    # radius share the circle s = s_b of the tool and its normal, so their envelopes share the
    # line it generates and the normal along it (measured <= 6e-11 mm, 2e-11; each side solved
    # to 1e-11/1e-12 mm in L/h)
    pf, nf = m.point_normal(side, np.full_like(L, -1e-12), L)
    pw, nw = m.point_normal(side, np.zeros_like(L), L)
    assert np.linalg.norm(pf - pw, axis=-1).max() < 1e-9
    assert np.linalg.norm(nf - nw, axis=-1).max() < 1e-9
    # u = −1: on the root cone, tangent to it (the point plane's own envelope is the root cone)
    bottom, nb = m.point_normal(side, -np.ones_like(L), L)
    g = m.pitch_angle
    rho = np.hypot(bottom[:, 0], bottom[:, 1])
    h = rho * math.cos(g) - bottom[:, 2] * math.sin(g)
    # round-off of 100 mm coordinates (measured 1e-14)
    np.testing.assert_allclose(h, pair.blank.root_height(m.index, L), atol=1e-9)
    gR = g - pair.blank.dedendum_angles[m.index - 1]  # root angle
    e_r = bottom / rho[:, None] * [1, 1, 0]
    n_root = math.cos(gR) * e_r - math.sin(gR) * np.array([0.0, 0.0, 1.0])
    # the unit normals agree to the Newton tolerance of the point solve
    assert np.linalg.norm(nb - n_root, axis=-1).max() < 1e-9
    # heights rise monotonically from the root cone up the fillet to the limit
    u = np.linspace(-1.0, 0.0, 21)
    hh = m.height(u[:, None], L[None, :], side)
    assert np.all(np.diff(hh, axis=0) > 0)


@pytest.mark.parametrize(("name", "side"), _members_sides())
def test_fillet_is_an_envelope_and_the_fast_evaluator_is_the_engine(pair, name, side):
    m = getattr(pair, name)
    b = m.boundaries()
    # the fillet: u from −1 (root cone) to just below 0 (u = 0 is the blade's envelope)
    U, V = np.meshgrid(np.linspace(-1, -1e-3, 7), np.linspace(b.v_start, b.v_end, 9), indexing="ij")
    ev = m.evaluate(side, U, V)
    # equation of meshing of the torus: |n·v|/|v| (Newton to 1e-15; 1e-11 leaves room for the
    # cancellation in n·v)
    assert ev.meshing_residual.max() < 1e-11, ev.meshing_residual.max()
    assert np.all(np.isfinite(ev.kappa))
    # the fillet is the edge radius's envelope at ϑ = (1 + u) ϑ_b (exact mapping)
    np.testing.assert_allclose(ev.tool_s, (1 + U) * m.edge_tool(side).theta_blade, atol=1e-15)
    # the fast native evaluator (the meshes use it) is the same surface: round-off of ~100 mm
    # coordinates after two independent Newton solves (1e-11 mm)
    p, n = m.flank_points(side, U, V)
    assert np.abs(p - ev.points).max() < 1e-9 and np.abs(n - ev.normals).max() < 1e-9
    nf = m.native_fillet(side)
    assert nf.meshing_residual(*nf.native(U, V)).max() < 1e-10
    # working flank too, through one entry point
    p, _ = m.flank_points(side, U + 1.001, V)
    assert np.abs(p - m.point_normal(side, U + 1.001, V)[0]).max() < 1e-9


def test_point_plane_cuts_the_root_cone_at_the_blank_dedendum(pair):
    b = pair.blank
    for m in members(pair):
        i = m.index
        bm = b.mean_cone_distance(i) * math.tan(b.dedendum_angles[i - 1])  # mean dedendum
        for side in SIDES:
            e = m.edge_tool(side)
            # the mean point (tool origin) lies the mean dedendum above the root cone; along the
            # cutter axis (normal to the root generatrix) that is b_m cos δ_f (closed form)
            assert -e.point_z == pytest.approx(bm * math.cos(b.dedendum_angles[i - 1]), abs=1e-9)
            # edge radius tangent to the point plane and to the blade at s_b (G1: same point,
            # same direction; closed-form arc, Newton on s_b to 1e-14)
            ms = m.settings(side)
            prof = m._tools(side)[0].profile(np.array(e.s_blade))
            arc = e.profile(np.array(e.theta_blade))
            assert abs(prof[0] - arc[0]) < 1e-9 and abs(prof[1] - arc[1]) < 1e-9
            t_blade = np.array([prof[2], prof[3]]) / math.hypot(prof[2], prof[3])
            t_arc = np.array([arc[2], arc[3]]) / math.hypot(arc[2], arc[3])
            assert np.abs(t_blade - t_arc).max() < 1e-9
            assert e.profile(np.array(0.0))[1] == pytest.approx(e.point_z, abs=1e-12)
            assert e.edge_radius == ms.edge_radius_mm


def test_drive_and_coast_fillets_close_the_tooth_space_in_the_clearance(pair):
    """Coast/drive consistency: each side's u is measured from its own fillet limit; both limits
    lie below the working depth the mate's tip reaches (the mate's tip meets the working
    surface, never a fillet), and the two fillets of a tooth space leave a root land on the
    root cone from toe to heel."""
    b = pair.blank
    for m in members(pair):
        bd = m.boundaries()
        L = np.linspace(bd.v_start, bd.v_end, 11)
        h_w, h_a = b.flank_heights(m.index, L)
        for side in SIDES:
            h_fl = m.fillet_height(L, side)
            # spline vs the flank's own height function: the same curve (exact)
            np.testing.assert_array_equal(m.height(0.0, L, side), h_fl)
            np.testing.assert_allclose(m.height(1.0, L, side), h_a, atol=1e-12)
            um, vm = m.mean_parameters(side)
            assert abs(float(m.height(um, vm, side))) < 1e-12  # the mean point: pitch cone
            # below the mate's face cone (measured 0.07 … 0.36 mm with the default radius)
            assert np.all(h_fl < h_w - 0.01), (m.name, side, (h_w - h_fl).round(3))
        np.testing.assert_array_equal(bd.fillet_curve(L), m.fillet_height(L, "drive"))
        bc = m.boundaries("coast")  # the same limits in u, the coast's own curves
        assert (bc.u_root, bc.u_fillet, bc.u_tip) == (bd.u_root, bd.u_fillet, bd.u_tip)
        np.testing.assert_array_equal(bc.fillet_curve(L), m.fillet_height(L, "coast"))
        np.testing.assert_allclose(bd.tip_curve(L), h_a, atol=1e-12)
        _, land = m.root_land()
        assert land.min() > 0.05, (m.name, land.round(3))


def test_default_edge_radius_and_its_effect():
    """The default edge radius: 0.25 m unless the tooth spaces cannot carry it with 20 % of their
    point width to spare. The reference gear's spaces are narrowest at the heel (point width
    1.74 mm, at most 1.01 mm of edge radius): 0.81 mm. A smaller radius lowers the fillet limit
    (the blade reaches further down), a larger one than fits is refused."""
    tg = SynthesisTargets(symmetric_te=False)  # the third-order roll does not enter here
    p0 = SpiralBevelPair.design(targets=tg)
    rho = {p0.settings.get(m, s).edge_radius_mm for m in ("pinion", "gear") for s in SIDES}
    assert len(rho) == 1
    (rho,) = rho
    assert 0.2 * 4.94 > rho > 0.15 * 4.94, rho  # measured 0.8102 mm
    p1 = SpiralBevelPair.design(SpiralBevelBlank(edge_radius_mm=0.5), targets=tg)
    assert p1.settings.gear_drive.edge_radius_mm == 0.5
    # the rule: 20 % of the point width W (the land of sharp blades) left as root land where the
    # spaces are narrowest; W from the lands at two radii (the land is linear in ρ: the default
    # was found from 0.25 m and 0.125 m, checked here at 0.81 mm and 0.5 mm, 1e-3 of W)
    L, l0 = p0.gear.root_land()
    l1 = p1.gear.root_land()[1]
    K = (l1 - l0) / (rho - 0.5)
    W = l0 + K * rho
    k = int(np.argmin(W / K))
    assert L[k] == L[-1], "narrowest at the heel"
    assert l0[k] / W[k] == pytest.approx(0.2, abs=1e-3), (l0[k], W[k])
    for side in SIDES:
        for a, c in ((p0.gear, p1.gear), (p0.pinion, p1.pinion)):
            assert np.all(c.fillet_height(L, side) < a.fillet_height(L, side)), (a.name, side)
    with pytest.raises(DesignError) as e:
        SpiralBevelPair.design(SpiralBevelBlank(edge_radius_mm=1.5), targets=tg)
    assert e.value.field == "spiral_bevel.edge_radius_mm"
    assert "tooth space" in str(e.value) and "overlap" in str(e.value)


def test_the_plain_data_record_rebuilds_the_same_pair(pair):
    """The synthesis is cached as JSON (no pickle): the pair rebuilt from its record has the same
    settings and the same flank points, bit for bit (floats survive JSON exactly)."""
    import json

    rebuilt = SpiralBevelPair.from_record(json.loads(json.dumps(pair.record())))
    assert rebuilt.settings == pair.settings and rebuilt.blank == pair.blank
    for name in ("pinion", "gear"):
        a, b = getattr(pair, name), getattr(rebuilt, name)
        for side in ("drive", "coast"):
            fa, fb = a.flank(side, nu=7, nv=5), b.flank(side, nu=7, nv=5)
            np.testing.assert_array_equal(fa.points, fb.points)
    np.testing.assert_array_equal(rebuilt.reports["drive"].point, pair.reports["drive"].point)
