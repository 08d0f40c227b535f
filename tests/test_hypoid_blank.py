"""The hypoid blank (``fegear.geometry.bevel.hypoid``, ``.hypoid_cones``): pitch cones tangent
at P, the tooth trace along the relative velocity, the limit condition checked by brute force,
the spiral bevel at E = 0 and as E → 0, ISO 23509:2016's Annex F samples, and the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fegear.errors import DesignError, InputError
from fegear.geometry.bevel.blank import SpiralBevelBlank
from fegear.geometry.bevel.hypoid import HypoidBlank
from fegear.geometry.bevel.hypoid_cones import iso23509_method1_gear_mean_radius, pitch_cones
from fegear.geometry.bevel.mesh_frame import mean_point
from fegear.geometry.transforms import apply_points, apply_vectors, rot_axis, translation

EZ = np.array([0.0, 0.0, 1.0])
#: designs the geometric invariants are checked on (the default: 10/41, E 25 mm, β1 45°)
DESIGNS = {
    "default": {},
    "large offset": {"offset_mm": 60.0},
    "shaft 70": {"shaft_angle_deg": 70.0, "offset_mm": 20.0},
    "shaft 110": {"shaft_angle_deg": 110.0, "offset_mm": 20.0},
    "left hand": {"hand": "left"},
    "ratio near 1": {"n1": 20, "n2": 21, "offset_mm": 20.0, "spiral_angle_deg": 40.0},
    "small cutter": {"cutter_radius_mm": 40.0},
}
#: the spiral bevel reference pair of docs/reference_pairs.md
REFERENCE = dict(n1=12, n2=36, module_mm=25.4 / 5.14, spiral_angle_deg=35.0,
                 pressure_angle_deg=22.5, face_width_mm=25.4)  # fmt: skip


@pytest.fixture(scope="module", params=sorted(DESIGNS))
def blank(request) -> HypoidBlank:
    return HypoidBlank(**DESIGNS[request.param])


def _unit(v):
    return v / np.linalg.norm(v)


def _line_distance(p, u, q, v) -> float:
    """Shortest distance between the lines ``p + λ u`` and ``q + μ v``."""
    c = np.cross(u, v)
    return abs(float((q - p) @ c)) / float(np.linalg.norm(c))


def _gear_speed(b: HypoidBlank):
    """``(ω1, ω2, v12(r))`` of the mesh: pinion ω1 = e_z, gear ω2 = −(N1/N2) e2 about A2."""
    A2, e2 = b.gear_axis()
    w2 = -b.m21 * e2
    return EZ, w2, lambda r: np.cross(EZ, r) - np.cross(w2, r - A2)


def _frame(b: HypoidBlank):
    """``(P, n_p, t, w)`` with w the in-plane normal to the trace on the apex side."""
    P, n, t = b.pitch_point(), b.pitch_normal(), b.tooth_trace()
    w = np.cross(n, t)
    return P, n, t, (w if w @ P < 0 else -w)


# --------------------------------------------------------------------------------------------
# the pitch cones
# --------------------------------------------------------------------------------------------
def test_both_cones_contain_p_and_their_normals_there_are_opposite(blank):
    """P lies at L = Rm_i on both pitch cones; the cones' outward normals at P are n_p and −n_p
    (1e-12 relative: rounding of mm-sized coordinates)."""
    P, n = blank.pitch_point(), blank.pitch_normal()
    A2, e2 = blank.gear_axis()
    for apex, axis, i, sign in ((np.zeros(3), EZ, 1, 1.0), (A2, e2, 2, -1.0)):
        g, rm = blank.pitch_angle(i), blank.mean_cone_distance(i)
        r = P - apex
        assert np.linalg.norm(r) == pytest.approx(rm, rel=1e-12)
        assert r @ axis == pytest.approx(rm * math.cos(g), rel=1e-12, abs=1e-12 * rm)
        radial = _unit(r - (r @ axis) * axis)
        outward = math.cos(g) * radial - math.sin(g) * axis
        np.testing.assert_allclose(outward, sign * n, atol=1e-12)
    assert P[1] == 0.0 and P[0] > 0.0  # P in the xz plane at +x
    assert blank.mean_cone_distance(1) * np.array(
        [math.sin(blank.pitch_angle(1)), 0, math.cos(blank.pitch_angle(1))]
    ) == pytest.approx(P, abs=1e-12)


def test_the_normal_line_at_p_meets_both_axes(blank):
    """The common normal at P meets the pinion and the gear axis (1e-10 mm: rounding)."""
    P, n = blank.pitch_point(), blank.pitch_normal()
    A2, e2 = blank.gear_axis()
    assert _line_distance(P, n, np.zeros(3), EZ) < 1e-10
    assert _line_distance(P, n, A2, e2) < 1e-10


def test_the_axes_cross_at_the_shaft_angle_and_pass_at_the_offset(blank):
    """Shortest distance between the axes = E and their angle = Σ (1e-10 mm, 1e-12 rad); the
    crossing point is the pinion axis' point nearest the gear axis; the hand decides the side."""
    A2, e2 = blank.gear_axis()
    assert abs(e2 @ EZ - math.cos(math.radians(blank.shaft_angle_deg))) < 1e-12
    if blank.offset_mm > 0:
        assert _line_distance(np.zeros(3), EZ, A2, e2) == pytest.approx(blank.offset_mm, abs=1e-10)
    C = blank.crossing_point()
    assert C[:2] == pytest.approx([0.0, 0.0], abs=0)
    # C is nearest: the common perpendicular from C meets the gear axis at right angles
    foot = A2 + ((C - A2) @ e2) * e2
    assert (foot - C) @ EZ == pytest.approx(0.0, abs=1e-10)
    # the common perpendicular C -> foot has the length E; a right-hand gear's axis passes on
    # the +y side of the pinion axis, a left-hand one's on the -y side (its mirror image)
    assert np.linalg.norm(foot - C) == pytest.approx(blank.offset_mm, abs=1e-10)
    side = 1.0 if blank.hand == "right" else -1.0
    assert side * (foot - C)[1] > 0.9 * blank.offset_mm


def test_the_pitch_apexes_beyond_the_crossing_points(blank):
    """``pitch_apex(i) = (C_i − A_i)·e_i`` with C_i on axis i nearest the other axis (1e-10 mm)."""
    A2, e2 = blank.gear_axis()
    assert blank.pitch_apex(1) == pytest.approx(blank.crossing_point()[2], abs=1e-12)
    C2 = A2 + ((blank.crossing_point() - A2) @ e2) * e2  # nearest to axis 1: foot of C1
    assert blank.pitch_apex(2) == pytest.approx((C2 - A2) @ e2, abs=1e-10)


def test_the_tooth_trace_is_along_the_relative_velocity_at_the_design_spiral_angle(blank):
    """t ∥ v12 and t ⟂ n_p (1e-12: rounding); β1 = the design value, β2 = ∠(g2, t), and
    β1 − β2 = ε' = ∠(g1, g2) (1e-12 rad); the pinion is the larger one (ε' > 0)."""
    P, n, t, _ = _frame(blank)
    A2, e2 = blank.gear_axis()
    _, _, v12 = _gear_speed(blank)
    v = v12(P)
    assert np.linalg.norm(t) == pytest.approx(1.0, abs=1e-15)
    assert abs(t @ n) < 1e-15
    assert np.linalg.norm(np.cross(t, v)) < 1e-12 * np.linalg.norm(v)
    assert abs(v @ n) < 1e-12 * np.linalg.norm(v)  # v12 lies in the pitch plane
    g1, g2 = _unit(P), _unit(P - A2)
    assert t @ g1 > 0 and t @ g2 > 0  # toe → heel on both
    angle = lambda a, b: math.atan2(np.linalg.norm(np.cross(a, b)), a @ b)  # noqa: E731
    assert angle(g1, t) == pytest.approx(math.radians(blank.spiral_angle_deg), abs=1e-12)
    assert angle(g2, t) == pytest.approx(blank.spiral_angle(2), abs=1e-12)
    eps = blank.offset_angle_pitch_plane
    assert eps == pytest.approx(angle(g1, g2), abs=1e-12)
    assert blank.spiral_angle(1) - blank.spiral_angle(2) == pytest.approx(eps, abs=1e-12)
    assert eps > 0
    # the ratio relation: equal normal pitches N1 / (r1 cos β1) = N2 / (r2 cos β2)
    r1 = np.linalg.norm(P - (P @ EZ) * EZ)
    r2 = np.linalg.norm((P - A2) - ((P - A2) @ e2) * e2)
    assert r1 * math.cos(blank.spiral_angle(1)) / blank.n1 == pytest.approx(
        r2 * math.cos(blank.spiral_angle(2)) / blank.n2, rel=1e-12
    )


def test_the_right_hand_trace_turns_to_minus_y_and_the_left_hand_is_its_mirror():
    """Right-hand gear: t_y < 0 at P (the spiral bevel's gear); left: the mirror image in xz,
    every scalar the same (exact: the same solve)."""
    r, left = HypoidBlank(), HypoidBlank(hand="left")
    assert r.tooth_trace()[1] < 0
    m = np.array([1.0, -1.0, 1.0])
    for f in ("pitch_point", "pitch_normal", "tooth_trace", "crossing_point"):
        np.testing.assert_array_equal(getattr(left, f)(), m * getattr(r, f)())
    for a, b in zip(left.gear_axis(), r.gear_axis(), strict=True):
        np.testing.assert_array_equal(a, m * b)
    for i in (1, 2):
        for f in ("pitch_angle", "pitch_apex", "outer_cone_distance", "thickness_heel"):
            assert getattr(left, f)(i) == getattr(r, f)(i)
    assert left.limit_pressure_angle == r.limit_pressure_angle


# --------------------------------------------------------------------------------------------
# the limit condition, checked by brute force (no K, no ISO formula)
# --------------------------------------------------------------------------------------------
def _meshing_rate(b: HypoidBlank, alpha: float, h: float = 1e-5) -> float:
    """d/dτ (n·v12) for the gear's material point at P with the normal n(α) = cos α w +
    sin α n_p, moving with the gear (the gear turned about its own offset axis by rotation
    matrices; central difference, step h rad of the pinion)."""
    P, n_p, _, w = _frame(b)
    n = math.cos(alpha) * w + math.sin(alpha) * n_p
    A2, e2 = b.gear_axis()
    _, w2, v12 = _gear_speed(b)
    f = []
    for tau in (-h, h):
        M = translation(A2) @ rot_axis(w2, np.linalg.norm(w2) * tau) @ translation(-A2)
        f.append(apply_vectors(M, n) @ v12(apply_points(M, P)))
    return (f[1] - f[0]) / (2 * h)


def _contact_line_slope(b: HypoidBlank, alpha: float, rho: float, tau: float, k: float) -> float:
    """∂f/∂u / |∇f| of the meshing function f = N·v12 at the instant, on the surface
    ``P + u t + v b + ½ (u²/ρ + 2τ uv + k v²) n`` (normal n(α) at P, normal curvature 1/ρ along
    t towards n, torsion τ, profile curvature k): 0 iff the contact line at P runs along t."""
    P, n_p, t, w = _frame(b)
    n = math.cos(alpha) * w + math.sin(alpha) * n_p
    bb = np.cross(n, t)
    _, _, v12 = _gear_speed(b)

    def f(u, v):
        ru = t + (u / rho + tau * v) * n
        rv = bb + (tau * u + k * v) * n
        r = P + u * t + v * bb + 0.5 * (u * u / rho + 2 * tau * u * v + k * v * v) * n
        N = _unit(np.cross(ru, rv))
        return (N if N @ n > 0 else -N) @ v12(r)

    h = 1e-3
    fu = (f(h, 0) - f(-h, 0)) / (2 * h)
    fv = (f(0, h) - f(0, -h)) / (2 * h)
    return fu / math.hypot(fu, fv)


@pytest.mark.parametrize("name", ["default", "large offset", "shaft 110", "small cutter"])
def test_the_limit_normal_makes_the_meshing_stationary_at_a_material_point(name):
    """At α_lim the meshing function of a material point at P does not change to first order as
    the gears turn (the generated flank's singular point with the contact line along t): the
    rate is < 1e-6 of its value 2° away (the central difference's error is ~1e-9 of it)."""
    b = HypoidBlank(**DESIGNS[name])
    a = b.limit_pressure_angle
    at, off = _meshing_rate(b, a), min(abs(_meshing_rate(b, a + d)) for d in (-0.035, 0.035))
    assert abs(at) < 1e-6 * off, (at, off)


@pytest.mark.parametrize("name", ["default", "large offset", "shaft 70", "small cutter"])
def test_with_the_limit_radius_the_contact_line_runs_along_the_tooth_trace(name):
    """The flank with the limit normal and the normal radius of curvature r_c0 along t has its
    contact line at P along t, whatever its torsion and profile curvature (slope < 1e-7:
    finite differences of step 1e-3 mm); 10 % off the radius, it does not (slope > 1e-3)."""
    b = HypoidBlank(**DESIGNS[name])
    a, rc = b.limit_pressure_angle, b.cutter_radius_mm
    assert b.limit_radius_mm == pytest.approx(rc, rel=1e-12)
    for tau, k in ((0.0, 0.0), (0.004, -0.02), (-0.01, 0.05)):
        assert abs(_contact_line_slope(b, a, rc, tau, k)) < 1e-7
        assert abs(_contact_line_slope(b, a, 1.1 * rc, tau, k)) > 1e-3


def _iso_limit(b: HypoidBlank) -> tuple[float, float]:
    """ISO 23509:2016 formulae 32 and 33 from the blank's δ_i, Rm_i, β_i and ε'."""
    d1, d2 = b.pitch_angle(1), b.pitch_angle(2)
    R1, R2 = b.mean_cone_distance(1), b.mean_cone_distance(2)
    b1, b2 = b.spiral_angle(1), b.spiral_angle(2)
    ta = (
        -math.tan(d1) * math.tan(d2) / math.cos(b.offset_angle_pitch_plane)
        * (R1 * math.sin(b1) - R2 * math.sin(b2)) / (R1 * math.tan(d1) + R2 * math.tan(d2))
    )  # fmt: skip
    den = (
        -ta * (math.tan(b1) / (R1 * math.tan(d1)) + math.tan(b2) / (R2 * math.tan(d2)))
        + 1 / (R1 * math.cos(b1)) - 1 / (R2 * math.cos(b2))
    )  # fmt: skip
    al = math.atan(ta)
    return al, (math.tan(b1) - math.tan(b2)) / (math.cos(al) * den)


@pytest.mark.parametrize("name", ["default", "large offset", "ratio near 1", "small cutter"])
def test_the_limit_angle_and_radius_are_iso_23509s_formulae_32_and_33(name):
    """The derived limit normal and radius are ISO's closed forms, sign included (1e-10:
    cancellation in tan β1 − tan β2 on ε' of some degrees)."""
    b = HypoidBlank(**DESIGNS[name])
    al, rho = _iso_limit(b)
    assert b.limit_pressure_angle == pytest.approx(al, abs=1e-10)
    assert rho == pytest.approx(b.cutter_radius_mm, rel=1e-10)


# --------------------------------------------------------------------------------------------
# E = 0 and E → 0: the spiral bevel
# --------------------------------------------------------------------------------------------
def _compare(h: HypoidBlank, s: SpiralBevelBlank, tol: float) -> None:
    L = np.linspace(s.outer_cone_distance(2) - s.face_width_mm, s.outer_cone_distance(2), 7)
    for i in (1, 2):
        k = i - 1
        pairs = [
            (h.pitch_angle(i), s.pitch_angles[k]),
            (h.outer_cone_distance(i), s.outer_cone_distance(i)),
            (h.mean_cone_distance(i), s.mean_cone_distance(i)),
            (h.face_width(i), s.face_width_mm),
            (h.spiral_angle(i), math.radians(s.spiral_angle_deg)),
            (h.addendum(i), s.addenda[k]),
            (h.dedendum(i), s.dedenda[k]),
            (h.dedendum_angle(i), s.dedendum_angles[k]),
            (h.thickness_heel(i), s.thickness_heel(i)),
            (h.half_tooth_angle(i), s.half_tooth_angle(i)),
            *zip(h.root_cone_line(i), s.root_cone_line(i), strict=True),
            *zip(h.face_cone_line(i), s.face_cone_line(i), strict=True),
        ] + [(h.pressure_angle(side), s.pressure_angle(side)) for side in ("drive", "coast")]
        for j, (a, b) in enumerate(pairs):
            assert abs(a - b) <= tol, (i, j, a, b)
        np.testing.assert_allclose(h.root_height(i, L), s.root_height(i, L), rtol=0, atol=tol)
        for a, b in zip(h.flank_heights(i, L), s.flank_heights(i, L), strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=tol)
    for a, b in ((h.working_depth, s.working_depth), (h.whole_depth, s.whole_depth)):
        assert abs(a - b) <= tol


@pytest.mark.parametrize("shaft", [90.0, 75.0, 105.0])
def test_offset_zero_is_the_spiral_bevel_blank(shaft):
    """E = 0: every number of SpiralBevelBlank to 1e-12 (they are the same formulas), the mean
    point and pitch normal those of ``mean_point``, no offset angle, the apexes at the crossing."""
    h = HypoidBlank(**REFERENCE, offset_mm=0.0, shaft_angle_deg=shaft)
    s = SpiralBevelBlank(**REFERENCE, shaft_angle_deg=shaft)
    _compare(h, s, 1e-12)
    M, _, e_p = mean_point(s, 1, 0.0)
    np.testing.assert_allclose(h.pitch_point(), M, atol=1e-12)
    np.testing.assert_allclose(h.pitch_normal(), e_p, atol=1e-12)
    assert h.offset_angle_pitch_plane == 0.0 and h.limit_pressure_angle == 0.0
    assert h.pitch_apex(1) == h.pitch_apex(2) == 0.0
    A2, e2 = h.gear_axis()
    np.testing.assert_allclose(A2, 0.0, atol=0)
    np.testing.assert_allclose(
        e2, [math.sin(math.radians(shaft)), 0, math.cos(math.radians(shaft))]
    )


def test_as_the_offset_vanishes_the_blank_tends_to_the_spiral_bevel_linearly():
    """E = 1e-3 … 1e-6 mm: every number approaches the spiral bevel's as a E + b E²: the slopes
    (q(E) − q(0))/E at 1e-6 and 1e-3 agree to 1e-3 of the largest (the quadratic term, ~E),
    and q(1e-6) is within 1e-5 mm or rad of q(0) (a slope of order 1 per mm)."""
    s = SpiralBevelBlank(**REFERENCE)
    h0 = HypoidBlank(**REFERENCE, offset_mm=0.0)
    _compare(h0, s, 1e-12)

    def numbers(b: HypoidBlank) -> np.ndarray:
        return np.array(
            [f(i) for i in (1, 2) for f in (b.pitch_angle, b.mean_cone_distance,
             b.outer_cone_distance, b.face_width, b.spiral_angle, b.dedendum_angle,
             b.thickness_heel, b.half_tooth_angle, b.pitch_apex)]
            + [b.offset_angle_pitch_plane, b.limit_pressure_angle]
        )  # fmt: skip

    q0 = numbers(h0)
    slopes = {}
    for E in (1e-3, 1e-4, 1e-5, 1e-6):
        q = numbers(HypoidBlank(**REFERENCE, offset_mm=E))
        slopes[E] = (q - q0) / E
        assert np.max(np.abs(q - q0)) < 10 * E, E  # converges at least linearly
    big = np.max(np.abs(slopes[1e-6]))
    for E in (1e-3, 1e-4, 1e-5):
        assert np.max(np.abs(slopes[E] - slopes[1e-6])) < 1e-3 * big, E
    assert np.max(np.abs(slopes[1e-3] - slopes[1e-4])) > 0  # a quadratic term exists
    # the fit a E + b E² through 1e-3 and 1e-4 predicts 1e-5 (residual ~ E³)
    a = (slopes[1e-4] * 1e-3 - slopes[1e-3] * 1e-4) / (1e-3 - 1e-4)
    bq = (slopes[1e-3] - slopes[1e-4]) / (1e-3 - 1e-4)
    assert np.max(np.abs(a + bq * 1e-5 - slopes[1e-5])) < 1e-6 * big


# --------------------------------------------------------------------------------------------
# ISO 23509:2016 Annex F
# --------------------------------------------------------------------------------------------
def test_iso_23509_annex_f2_sample_1_spiral_bevel():
    """Sample 1 (F.2: z 14/39, de2 176.893 mm, b2 25.4 mm, β 35°, method 0): the printed pitch
    data to their 3 decimals (±0.0005 rounding)."""
    b = HypoidBlank(n1=14, n2=39, module_mm=176.893 / 39, offset_mm=0.0, spiral_angle_deg=35.0,
                    pressure_angle_deg=20.0, face_width_mm=25.4,
                    cutter_radius_mm=114.3)  # fmt: skip
    printed = {
        "delta1": (math.degrees(b.pitch_angle(1)), 19.747),
        "delta2": (math.degrees(b.pitch_angle(2)), 70.253),
        "Rm": (b.mean_cone_distance(2), 81.273),
        "Re2": (b.outer_cone_distance(2), 93.973),
        "Ri2": (b.outer_cone_distance(2) - b.face_width(2), 68.573),
        "dm1": (2 * b.mean_cone_distance(1) * math.sin(b.pitch_angle(1)), 54.918),
        "dm2": (2 * b.mean_cone_distance(2) * math.sin(b.pitch_angle(2)), 152.987),
        "Re1": (b.outer_cone_distance(1), 93.973),
        "b1": (b.face_width(1), 25.400),
    }
    for name, (mine, iso) in printed.items():
        assert mine == pytest.approx(iso, abs=5e-4), name


def test_iso_23509_annex_f3_sample_2_hypoid_method_1():
    """Sample 2 (F.3: z 13/42, a 15 mm, de2 170 mm, b2 30 mm, r_c0 63.5 mm, method 1) with ISO's
    calculation point (formulae 11, 12) and its printed β_m1 = 49.998°: the printed pitch-cone
    results. Tolerances: 0.0006 = the printed 3 decimals plus the rounding of β_m1; 0.0025 for
    the values the limit iteration moves (Rm1, t_z1, t_z2, α_lim): the standard's iteration stops
    at |ρ_mβ/ρ_lim − 1| ≤ 0.01 and its printed values sit at ρ_lim = 63.496 mm, not 63.5
    (which moves Rm1 by 0.0023 mm); dm1 is printed 0.001 below 2 Rm1 sin δ1 (0.0012)."""
    r2 = iso23509_method1_gear_mean_radius(13, 42, 170.0, 30.0)
    c = pitch_cones(13, 42, offset_mm=15.0, spiral_angle_deg=49.998, cutter_radius_mm=63.5,
                    outer_diameter_mm=170.0, face_width_mm=30.0,
                    gear_mean_radius_mm=r2)  # fmt: skip
    g1, g2 = c.pitch_angles
    rm1, rm2 = c.mean_cone_distances
    re2 = 85.0 / math.sin(g2)
    toe, heel = c.pinion_face_cover(re2, 30.0)
    P, A2, e2 = (np.array(v) for v in (c.point, c.gear_apex, c.gear_axis))
    radial = _unit((P - A2) - ((P - A2) @ e2) * e2)
    zeta_m = math.degrees(math.asin(abs(np.cross(radial, EZ) @ e2)))
    tight = {
        "Rm2": (rm2, 76.337),
        "beta_m2": (math.degrees(c.spiral_angles[1]), 38.609),
        "c_be2": ((re2 - rm2) / 30.0, 0.504),
        "dm2": (2 * rm2 * math.sin(g2), 141.877),
        "zeta_m": (zeta_m, 10.603),
        "zeta_mp": (math.degrees(c.offset_angle_pitch_plane), 11.390),
        "a_p": (c.pitch_plane_offset_mm, 15.075),
        "Re2": (re2, 91.468),
        "Ri2": (re2 - 30.0, 61.468),
        "b_p1": (heel - toe, 30.626),
        "b_1A": (rm1 - toe, 15.243),
    }
    loose = {
        "Rm1": (rm1, 73.519),
        "dm1": (2 * rm1 * math.sin(g1), 53.383),
        "t_z1": (c.pitch_apexes_mm[0], -1.225),
        "t_z2": (c.pitch_apexes_mm[1], 1.576),
        "alpha_lim": (math.degrees(c.limit_pressure_angle), -2.253),
    }
    for name, (mine, iso) in tight.items():
        assert mine == pytest.approx(iso, abs=6e-4), name
    for name, (mine, iso) in loose.items():
        assert mine == pytest.approx(iso, abs=2.5e-3), name
    assert c.limit_radius_mm == pytest.approx(63.5, rel=1e-12)


def test_the_iso_calculation_point_moves_the_blank_only_a_little():
    """fegear's mid-face mean point against ISO method 1's (Sample 2 data, β1 = 50°): the
    pitch angles differ by < 0.05°, the face width factor is 0.5 against 0.504."""
    b = HypoidBlank(n1=13, n2=42, module_mm=170.0 / 42, offset_mm=15.0, spiral_angle_deg=50.0,
                    face_width_mm=30.0, cutter_radius_mm=63.5)  # fmt: skip
    r2 = iso23509_method1_gear_mean_radius(13, 42, 170.0, 30.0)
    c = pitch_cones(13, 42, offset_mm=15.0, spiral_angle_deg=50.0, cutter_radius_mm=63.5,
                    outer_diameter_mm=170.0, face_width_mm=30.0,
                    gear_mean_radius_mm=r2)  # fmt: skip
    a02 = b.outer_cone_distance(2)
    assert (a02 - b.mean_cone_distance(2)) / b.face_width(2) == pytest.approx(0.5, abs=1e-12)
    for i in (1, 2):
        assert abs(b.pitch_angle(i) - c.pitch_angles[i - 1]) < math.radians(0.05)


# --------------------------------------------------------------------------------------------
# proportions
# --------------------------------------------------------------------------------------------
def test_the_proportions_hold_on_each_members_own_cone(blank):
    """Root lines through each member's own pitch apex (h_R(0) = 0), the mate's face cone the
    clearance above the root, the addenda summing to the working depth, and the mean normal
    thicknesses summing to the normal pitch (zero backlash) (1e-12 mm: rounding)."""
    b = blank
    L = np.linspace(0.0, b.outer_cone_distance(1), 5)
    for i in (1, 2):
        assert b.root_height(i, 0.0) == pytest.approx(0.0, abs=1e-12)
        hw, ha = b.flank_heights(i, L)
        np.testing.assert_allclose(hw, b.root_height(i, L) + b.clearance, atol=1e-12)
        a0 = b.outer_cone_distance(i)
        assert ha[-1] if a0 == L[-1] else True
        assert b.outer_cone_distance(i) - b.face_width(i) > b.whole_depth
    assert b.addendum(1) + b.addendum(2) == pytest.approx(b.working_depth, abs=1e-12)
    assert b.dedendum(1) + b.addendum(1) == pytest.approx(b.whole_depth, abs=1e-12)
    sn = [
        b.thickness_heel(i) * b.mean_cone_distance(i) / b.outer_cone_distance(i)
        * math.cos(b.spiral_angle(i))
        for i in (1, 2)
    ]  # fmt: skip
    r2 = b.mean_cone_distance(2) * math.sin(b.pitch_angle(2))
    pn = 2 * math.pi * r2 * math.cos(b.spiral_angle(2)) / b.n2
    assert sn[0] + sn[1] == pytest.approx(pn, abs=1e-12)
    assert b.outer_cone_distance(2) == pytest.approx(
        b.module_mm * b.n2 / (2 * math.sin(b.pitch_angle(2))), rel=1e-15
    )


def test_the_pinion_face_covers_the_gear_face_along_its_generatrix():
    """Default pinion face: the pinion generatrix through P, in the developed pitch plane,
    between the gear's toe and heel circles about its apex (1e-9 mm); a given F1 widens it
    equally at both ends."""
    b = HypoidBlank()
    P, A2 = b.pitch_point(), b.gear_axis()[0]
    g1 = _unit(P)
    a02, f2 = b.outer_cone_distance(2), b.face_width(2)
    heel, toe = b.outer_cone_distance(1), b.outer_cone_distance(1) - b.face_width(1)
    assert np.linalg.norm(heel * g1 - A2) == pytest.approx(a02, abs=1e-9)
    assert np.linalg.norm(toe * g1 - A2) == pytest.approx(a02 - f2, abs=1e-9)
    assert b.face_width(1) > b.face_width(2)  # cos ε' < 1: the generatrix crosses obliquely
    w = HypoidBlank(pinion_face_width_mm=b.face_width(1) + 4.0)
    assert w.outer_cone_distance(1) == pytest.approx(heel + 2.0, abs=1e-12)
    assert w.outer_cone_distance(1) - w.face_width(1) == pytest.approx(toe - 2.0, abs=1e-12)


# --------------------------------------------------------------------------------------------
# plain data and refusals
# --------------------------------------------------------------------------------------------
def test_record_round_trip():
    b = HypoidBlank(offset_mm=30.0, hand="left", pinion_face_width_mm=35.0)
    rec = b.record()
    assert all(isinstance(v, int | float | str | type(None)) for v in rec.values())
    assert HypoidBlank.from_record(rec) == b
    with pytest.raises(InputError, match="format"):
        HypoidBlank.from_record({**rec, "format": "other"})


@pytest.mark.parametrize(
    ("kw", "error", "field"),
    [
        ({"offset_mm": -1.0}, InputError, "hypoid.offset_mm"),
        ({"offset_mm": 102.5}, InputError, "hypoid.offset_mm"),  # = de2/2
        ({"offset_mm": float("nan")}, InputError, "hypoid.offset_mm"),
        ({"offset_mm": 80.0}, DesignError, "hypoid.offset_mm"),  # β2 < 0
        ({"offset_mm": 100.0, "spiral_angle_deg": 60.0}, DesignError, "hypoid.offset_mm"),
        ({"spiral_angle_deg": 61.0}, InputError, "hypoid.spiral_angle_deg"),
        ({"spiral_angle_deg": 10.0}, DesignError, "hypoid.offset_mm"),  # β2 < 0
        ({"pressure_angle_deg": 5.0}, InputError, "hypoid.pressure_angle_deg"),
        ({"n1": 4}, InputError, "hypoid.n1"),
        ({"n1": 45}, InputError, "hypoid.n1"),
        ({"n2": 12.0}, InputError, "hypoid.n2"),
        ({"module_mm": 0.0}, InputError, "hypoid.module_mm"),
        ({"face_width_mm": 50.0}, DesignError, "hypoid.face_width_mm"),
        ({"pinion_face_width_mm": -3.0}, InputError, "hypoid.pinion_face_width_mm"),
        ({"pinion_face_width_mm": 190.0}, DesignError, "hypoid.pinion_face_width_mm"),
        ({"cutter_radius_mm": 20.0}, DesignError, "hypoid.cutter_radius_mm"),
        ({"shaft_angle_deg": 180.0}, InputError, "hypoid.shaft_angle_deg"),
        ({"hand": "up"}, InputError, "hypoid.hand"),
        ({"edge_radius_mm": 0.0}, InputError, "hypoid.edge_radius_mm"),
    ],
)
def test_bad_design_data_is_refused_naming_the_field(kw, error, field):
    with pytest.raises(error) as exc:
        HypoidBlank(**kw)
    assert exc.value.field == field
    assert exc.value.allowed


def test_an_unreachable_limit_condition_says_why_with_numbers():
    """A small cutter at a large offset: no cones connected to the spiral bevel meet
    ρ_lim = r_c0; the refusal gives the offset reached and the limit radii available."""
    with pytest.raises(DesignError) as exc:
        HypoidBlank(offset_mm=60.0, spiral_angle_deg=60.0, cutter_radius_mm=30.0)
    e = exc.value
    assert e.field == "hypoid.offset_mm"
    assert "<= 13.3" in e.allowed
    assert "limit radii in [" in e.detail and "r_c0 = 30 mm" in e.detail


def test_member_index_is_checked():
    with pytest.raises(InputError) as exc:
        HypoidBlank().pitch_angle(3)
    assert exc.value.field == "hypoid.member"
