"""Tests of the closed-form Hertz contact (fegear.mechanics.hertz_closed_form).

The references are independent of the module's Carlson-form evaluation:

- textbook sphere formulas (A = B);
- Johnson's K(e), E(e) relations (Contact Mechanics 1985, eq. 4.39) with scipy's ``ellipkm1`` and
  ``ellipe``;
- Johnson's defining displacement integrals L, M, N of the ellipsoidal pressure (ch. 3 and §4.2),
  integrated with ``scipy.integrate.quad``;
- the Boussinesq integral u(x, y) = 1/(π E*) ∬ p / r dA of the computed pressure field, which must
  give u = δ − A x² − B y² inside the contact (the defining Hertz condition);
- the line-contact limit and the Hamrock–Brewe curve fits.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import ellipe, ellipkm1

from fegear.errors import InputError
from fegear.mechanics.hertz_closed_form import (
    HertzPoint,
    effective_modulus,
    hertz_ellipse_for_approach,
    hertz_force_for_approach,
    hertz_law,
    hertz_line,
    hertz_point,
    hertz_point_radii,
    hertz_pressure,
    paint_ellipse,
    relative_curvature,
)

E_STEEL = 206000.0
NU_STEEL = 0.3
E_STAR = E_STEEL / (2.0 * (1.0 - NU_STEEL**2))


# ----------------------------------------------------------------------------------------------
# independent references
# ----------------------------------------------------------------------------------------------


def _johnson_integrals(q: float) -> tuple[float, float, float]:
    """I_L, I_M, I_N for a = 1, b = q: ∫0^∞ {1, 1/(a²+w), 1/(b²+w)} dw / sqrt(w(a²+w)(b²+w)).

    With w = t² the 1/sqrt(w) singularity goes away; the range is split at b and a so quad sees
    the two length scales of an elongated ellipse.
    """

    def integrand(t: float, kind: int) -> float:
        a2, b2 = 1.0 + t * t, q * q + t * t
        base = 2.0 / math.sqrt(a2 * b2)
        return base if kind == 0 else base / (a2 if kind == 1 else b2)

    out = []
    for kind in range(3):
        total = 0.0
        for lo, hi in ((0.0, q), (q, 1.0), (1.0, np.inf)):
            val, _ = quad(integrand, lo, hi, args=(kind,), epsabs=0.0, epsrel=1e-13, limit=200)
            total += val
        out.append(total)
    return out[0], out[1], out[2]


def _johnson_reference(force: float, A: float, B: float, e_star: float) -> dict[str, float]:
    """Hertz point contact from Johnson's displacement integrals, solved with brentq.

    Surface displacement of p = p0 sqrt(1 − x²/a² − y²/b²) (sum of both bodies):
    u = (L − M x² − N y²)/(π E*), with {L, M, N} = (π p0 a b / 2) {I_L, I_M, I_N}. Matching
    u + h = δ gives A = M/(πE*), B = N/(πE*), δ = L/(πE*); with P = (2/3) π a b p0:
    A = 3 P I_M(a, b)/(4π E*), I_M(a, b) = I_M(1, b/a)/a³ (and likewise for I_N, I_L with a⁻³, a⁻¹).
    """
    A, B = min(A, B), max(A, B)
    r = B / A

    def g(log_q: float) -> float:
        _, i_m, i_n = _johnson_integrals(math.exp(log_q))
        return math.log(i_n / i_m) - math.log(r)

    q = 1.0 if r == 1.0 else math.exp(brentq(g, math.log(1e-6), 0.0, xtol=1e-14))
    i_l, i_m, _ = _johnson_integrals(q)
    a = (3.0 * force * i_m / (4.0 * math.pi * e_star * A)) ** (1.0 / 3.0)
    b = q * a
    return {
        "a": a,
        "b": b,
        "p0": 1.5 * force / (math.pi * a * b),
        "approach": 3.0 * force * i_l / (4.0 * math.pi * e_star * a),
    }


def _boussinesq_displacement(x0: float, y0: float, hp: HertzPoint) -> float:
    """u(x0, y0) = 1/(π E*) ∬ p / r dA of the Hertz pressure field of ``hp`` (inside point).

    Polar coordinates about (x0, y0): along the ray (cos θ, sin θ), p²/p0² = α + β ρ − γ ρ², and
    ∫0^ρ+ sqrt(α + βρ − γρ²) dρ = sqrt(γ) h² [π/4 − φ0/2 − sin(2 φ0)/4] with centre c = β/(2γ),
    half-length h, sin φ0 = −c/h. The remaining θ integral is done with quad.
    """
    a, b = hp.a_mm, hp.b_mm
    alpha = 1.0 - (x0 / a) ** 2 - (y0 / b) ** 2

    def ray(theta: float) -> float:
        c, s = math.cos(theta), math.sin(theta)
        beta = -2.0 * (x0 * c / a**2 + y0 * s / b**2)
        gamma = (c / a) ** 2 + (s / b) ** 2
        centre = beta / (2.0 * gamma)
        half = math.sqrt(beta * beta + 4.0 * alpha * gamma) / (2.0 * gamma)
        phi0 = math.asin(max(-1.0, min(1.0, -centre / half)))
        return math.sqrt(gamma) * half**2 * (math.pi / 4 - phi0 / 2 - math.sin(2 * phi0) / 4)

    val, _ = quad(ray, 0.0, 2.0 * math.pi, epsabs=0.0, epsrel=1e-13, limit=400)
    return hp.p0_MPa * val / (math.pi * hp.E_star_MPa)


def _rel(x: float, y: float) -> float:
    return abs(x / y - 1.0)


# ----------------------------------------------------------------------------------------------
# material and sphere limit
# ----------------------------------------------------------------------------------------------


def test_effective_modulus_steel() -> None:
    # exact arithmetic up to a few ulp
    assert _rel(effective_modulus(E_STEEL, NU_STEEL, E_STEEL, NU_STEEL), E_STAR) < 1e-15
    # a rigid-like body 2 leaves body 1's plane-strain modulus (1e-12: E2 = 1e15 contributes 1e-11)
    assert _rel(effective_modulus(E_STEEL, 0.3, 1e15, 0.3), E_STEEL / 0.91) < 1e-9


@pytest.mark.parametrize("force", [1e-6, 1.0, 2000.0, 1e7])
@pytest.mark.parametrize("radius", [0.5, 50.0, 1e4])
def test_sphere_limit_exact(force: float, radius: float) -> None:
    A = 1.0 / (2.0 * radius)  # sphere of radius R on a flat: h = r²/(2R), so 1/R = A + B
    hp = hertz_point(force, A, A, E_STAR)
    a = (3.0 * force * radius / (4.0 * E_STAR)) ** (1.0 / 3.0)
    # same closed form evaluated in a different order: a few ulp of rounding
    tol = 1e-12
    assert _rel(hp.a_mm, a) < tol and _rel(hp.b_mm, a) < tol
    assert _rel(hp.p0_MPa, 3.0 * force / (2.0 * math.pi * a * a)) < tol
    assert _rel(hp.approach_mm, a * a / radius) < tol
    assert hp.axis_ratio == 1.0


def test_near_sphere_is_continuous() -> None:
    R, force = 50.0, 2000.0
    A = 1.0 / (2.0 * R)
    sphere = hertz_point(force, A, A, E_STAR)
    near = hertz_point(force, A, A * (1.0 + 1e-9), E_STAR)
    # a perturbation of 1e-9 in B/A moves every quantity by O(1e-9), never by a jump
    for f in ("a_mm", "b_mm", "p0_MPa", "approach_mm"):
        assert _rel(getattr(near, f), getattr(sphere, f)) < 1e-9, f
    assert near.b_mm <= sphere.a_mm <= near.a_mm
    # Linearisation (K, E series in e²): B/A − 1 ≈ 3e²/4 and 1 − b/a ≈ e²/2, so
    # (1 − b/a)/(B/A − 1) → 2/3. Holding down to B/A − 1 = 1e-12 shows a smooth approach to the
    # sphere; tolerance 1e-3 covers the O(B/A − 1) next term at 1e-4 and 1e-4 relative rounding
    # of (1 − b/a) ≈ 7e-13 at the smallest step.
    for eps in (1e-4, 1e-6, 1e-8, 1e-10, 1e-12):
        k = hertz_point(force, A, A * (1.0 + eps), E_STAR).axis_ratio
        assert abs((1.0 - k) / eps - 2.0 / 3.0) < 1e-3, (eps, (1.0 - k) / eps)


# ----------------------------------------------------------------------------------------------
# formulas against independent evaluations
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("ratio", [1.01, 1.5, 5.0, 37.0, 1e3, 1e6])
def test_johnson_k_e_relations(ratio: float) -> None:
    """Johnson eq. 4.39 in K(e), E(e) (scipy ellipkm1/ellipe on m = e²) holds at the solution."""
    A, force = 0.01, 500.0
    hp = hertz_point(force, A, A * ratio, E_STAR)
    a, b, p0 = hp.a_mm, hp.b_mm, hp.p0_MPa
    k2 = (b / a) ** 2
    e2 = 1.0 - k2
    K, E = ellipkm1(k2), ellipe(e2)  # ellipkm1 takes the complementary parameter 1 − m = (b/a)²
    A_j = p0 / E_STAR * b / (e2 * a * a) * (K - E)
    B_j = p0 / E_STAR * b / (a * a) * ((a * a / (b * b)) * E - K) / e2
    d_j = p0 / E_STAR * b * K
    # K − E loses ~log10(1/e²) digits near the sphere (e² ≈ 0.013 at B/A = 1.01): 1e-12 is ample
    tol = 1e-12
    assert _rel(A_j, hp.A) < tol and _rel(B_j, hp.B) < tol and _rel(d_j, hp.approach_mm) < tol


@pytest.mark.parametrize("ratio", [1.0, 1.5, 5.0, 100.0, 1e4])
def test_against_johnson_integrals(ratio: float) -> None:
    A, force = 0.02, 1234.0
    hp = hertz_point(force, A, A * ratio, E_STAR)
    ref = _johnson_reference(force, A, A * ratio, E_STAR)
    # quad at epsrel 1e-13 and brentq at xtol 1e-14 on ln(b/a): 1e-9 leaves a wide margin
    tol = 1e-9
    assert _rel(hp.a_mm, ref["a"]) < tol
    assert _rel(hp.b_mm, ref["b"]) < tol
    assert _rel(hp.p0_MPa, ref["p0"]) < tol
    assert _rel(hp.approach_mm, ref["approach"]) < tol


@pytest.mark.parametrize("ratio", [1.0, 3.0, 25.0])
def test_boussinesq_displacement_matches_gap(ratio: float) -> None:
    """The Hertz condition from first principles: u(x, y) + A x² + B y² = δ inside the contact."""
    hp = hertz_point(800.0, 0.004, 0.004 * ratio, E_STAR)
    a, b = hp.a_mm, hp.b_mm
    for fx, fy in ((0.0, 0.0), (0.5, 0.0), (0.0, 0.7), (0.4, -0.5), (-0.9, 0.1)):
        x, y = fx * a, fy * b
        u = _boussinesq_displacement(x, y, hp)
        # quad at 1e-13 on a smooth periodic ray integral; 1e-9 of δ
        assert abs(u + hp.A * x * x + hp.B * y * y - hp.approach_mm) < 1e-9 * hp.approach_mm


def test_total_force_from_pressure_field() -> None:
    hp = hertz_point(2000.0, 0.005, 0.025, E_STAR)
    a, b = hp.a_mm, hp.b_mm
    # Exact quadrature: x = a r cos t, y = b r sin t, r = sin s removes the sqrt(1 − r²) endpoint
    # singularity, so Gauss–Legendre in s (40 nodes) and the trapezoid rule in the periodic t
    # (64 nodes) are both spectrally accurate.
    s, ws = np.polynomial.legendre.leggauss(40)
    s = 0.25 * np.pi * (s + 1.0)
    ws = 0.25 * np.pi * ws
    t = np.linspace(0.0, 2.0 * np.pi, 64, endpoint=False)
    r = np.sin(s)[:, None]
    p = hertz_pressure(a * r * np.cos(t), b * r * np.sin(t), hp.p0_MPa, a, b)
    jac = a * b * r * np.cos(s)[:, None]  # dA = a b r dr dt, dr = cos s ds
    total = float(np.sum(p * jac * ws[:, None]) * (2.0 * np.pi / t.size))
    # spectral quadrature: error at rounding level, 1e-12
    assert _rel(total, hp.force_N) < 1e-12
    # Plain midpoint sum on a Cartesian box larger than the ellipse (tests the clipping to 0
    # outside): the sqrt edge gives an O(h^1.5) error, ~2e-5 here with 1200² cells, so 2e-4.
    n = 1200
    xs = (np.arange(n) + 0.5) / n * 2.4 * a - 1.2 * a
    ys = (np.arange(n) + 0.5) / n * 2.4 * b - 1.2 * b
    pg = hertz_pressure(xs[:, None], ys[None, :], hp.p0_MPa, a, b)
    assert pg.min() == 0.0 and pg.max() <= hp.p0_MPa
    total_grid = float(pg.sum()) * (2.4 * a / n) * (2.4 * b / n)
    assert _rel(total_grid, hp.force_N) < 2e-4
    # the method on the result is the same field
    assert np.array_equal(hp.pressure(xs[:5], ys[:5]), pg[np.arange(5), np.arange(5)])


# ----------------------------------------------------------------------------------------------
# the roller scene
# ----------------------------------------------------------------------------------------------


def test_roller_scene_numbers() -> None:
    """Crowned roller Rx 20, Ry 100 mm on a flat block, 2000 N, steel/steel."""
    hp = hertz_point_radii(2000.0, (20.0, 100.0), None, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    ref = _johnson_reference(2000.0, 1.0 / 40.0, 1.0 / 200.0, E_STAR)
    msg = (
        f"scene: p0 = {hp.p0_MPa:.6f} MPa, a = {hp.a_mm:.9f} mm, b = {hp.b_mm:.9f} mm, "
        f"approach = {1e3 * hp.approach_mm:.6f} um; Johnson-integral reference: "
        f"p0 = {ref['p0']:.6f}, a = {ref['a']:.9f}, b = {ref['b']:.9f}, "
        f"approach = {1e3 * ref['approach']:.6f} um"
    )
    # independent quad/brentq reference: 1e-9 (see test_against_johnson_integrals)
    assert _rel(hp.p0_MPa, ref["p0"]) < 1e-9, msg
    assert _rel(hp.a_mm, ref["a"]) < 1e-9, msg
    assert _rel(hp.b_mm, ref["b"]) < 1e-9, msg
    assert _rel(hp.approach_mm, ref["approach"]) < 1e-9, msg
    # known-good values (printed by the message above, computed with this reference)
    assert _rel(hp.p0_MPa, 1447.7064) < 1e-7, msg
    assert _rel(hp.a_mm, 1.3807275) < 1e-7, msg
    assert _rel(hp.b_mm, 0.47773044) < 1e-7, msg
    assert _rel(hp.approach_mm, 0.015237701) < 1e-7, msg
    # the roller is more curved along x (R 20): the major axis runs along y
    assert hp.major_axis_rad == pytest.approx(math.pi / 2, abs=1e-15)
    assert (hp.A, hp.B) == (1.0 / 200.0, 1.0 / 40.0)


@pytest.mark.parametrize("alpha", [2.0, 5.0, 10.0, 20.0, 40.0])
def test_hamrock_brewe_curve_fits(alpha: float) -> None:
    """Hamrock & Brewe (1983) fits, alpha = Ry/Rx = B/A, E' = 2E*, 1/R = 1/Rx + 1/Ry:
    k = a/b ≈ 1.0339 alpha^0.6360, E ≈ 1.0003 + 0.5968/alpha, K ≈ 1.5277 + 0.6023 ln(alpha),
    2a = 2 (6 k² E P R/(π E'))^(1/3), 2b = 2 (6 E P R/(π k E'))^(1/3),
    δ = K (9/(2 E R) (P/(π k E'))²)^(1/3).
    """
    force, A = 2000.0, 0.005
    hp = hertz_point(force, A, alpha * A, E_STAR)
    R = 1.0 / (2.0 * A + 2.0 * alpha * A)
    ep = 2.0 * E_STAR
    k = 1.0339 * alpha**0.6360
    e = 1.0003 + 0.5968 / alpha
    kk = 1.5277 + 0.6023 * math.log(alpha)
    a = (6.0 * k * k * e * force * R / (math.pi * ep)) ** (1.0 / 3.0)
    b = (6.0 * e * force * R / (math.pi * k * ep)) ** (1.0 / 3.0)
    d = kk * (9.0 / (2.0 * e * R) * (force / (math.pi * k * ep)) ** 2) ** (1.0 / 3.0)
    # The fits are quoted as good to a few percent for 1 <= k <= 10 (coefficients as recalled from
    # Hamrock's texts, not re-checked against the paper here). Measured on this range: <= 1.3 %;
    # 3 % is the few-percent claim, and the fits reach 3.0-3.3 % at alpha = 1 and 50.
    tol = 0.03
    assert _rel(hp.a_mm / hp.b_mm, k) < tol
    assert _rel(hp.a_mm, a) < tol and _rel(hp.b_mm, b) < tol
    assert _rel(hp.approach_mm, d) < tol
    assert _rel(hp.p0_MPa, 1.5 * force / (math.pi * a * b)) < tol


# ----------------------------------------------------------------------------------------------
# very elongated contact
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("ratio", [1e4, 1e6, 1e8, 1e12, 1e50])
def test_elongated_tends_to_line_contact(ratio: float) -> None:
    """Fixed B (across the contact) and growing B/A: the central section becomes 2D Hertz.

    Johnson eq. 4.39b gives B = (p0/(E* b)) (E − k²K)/(1 − k²), k = b/a, while 2D Hertz with the
    central line load w0 = π p0 b/2 and R = 1/(2B) gives B = p0/(E* b). The small-k expansions
    of K, E make the half-width ratio b_line/b − 1 ≈ (k²/4)(ln(4/k) − 3/2).
    """
    B = 0.05
    hp = hertz_point(3000.0, B / ratio, B, E_STAR)
    assert all(
        math.isfinite(v) and v > 0
        for v in (hp.p0_MPa, hp.a_mm, hp.b_mm, hp.approach_mm, hp.axis_ratio)
    )
    k = hp.axis_ratio
    w0 = 0.5 * math.pi * hp.p0_MPa * hp.b_mm
    line = hertz_line(w0, 1.0 / (2.0 * B), E_STAR)
    # bound: the leading asymptotic term above, doubled, plus rounding
    bound = 0.5 * k * k * math.log(4.0 / k) + 1e-13
    assert abs(line.b_mm / hp.b_mm - 1.0) < bound, (k, line.b_mm / hp.b_mm - 1.0)
    assert abs(line.p0_MPa / hp.p0_MPa - 1.0) < bound


def test_elongation_is_monotone() -> None:
    ratios = np.logspace(0.0, 14.0, 57)
    hps = [hertz_point(100.0, 1.0 / r, 1.0, E_STAR) for r in ratios]
    k = np.array([h.axis_ratio for h in hps])
    a = np.array([h.a_mm for h in hps])
    assert np.all(np.diff(k) < 0.0)  # rounder for smaller B/A, strictly
    assert np.all(np.diff(a) > 0.0)  # fixed B, falling A: the contact grows along its major axis


# ----------------------------------------------------------------------------------------------
# inverse, law, approach ellipses
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("ratio", [1.0, 1.0 + 1e-9, 3.7, 1e5])
@pytest.mark.parametrize("force", [1e-3, 2000.0, 1e6])
def test_force_for_approach_inverts(ratio: float, force: float) -> None:
    A = 0.01
    d = hertz_point(force, A, A * ratio, E_STAR).approach_mm
    # δ = c F^(2/3) and F = (δ/c)^(3/2) with the same c: a few ulp
    assert _rel(hertz_force_for_approach(d, A, A * ratio, E_STAR), force) < 1e-12
    again = hertz_ellipse_for_approach(d, A, A * ratio, E_STAR)
    assert _rel(again.force_N, force) < 1e-12 and _rel(again.approach_mm, d) < 1e-12


def test_law_vectorised_and_stiffness() -> None:
    law = hertz_law(0.005, 0.025, E_STAR)
    d = np.array([-1e-3, 0.0, 1e-3, 1e-2])
    f = law.force(d)
    assert f[0] == 0.0 and f[1] == 0.0 and np.all(f[2:] > 0.0)
    # derivative by central differences (step 1e-7 relative): truncation ~1e-14, rounding ~1e-9
    h = 1e-10
    fd = (law.force(1e-3 + h) - law.force(1e-3 - h)) / (2 * h)
    assert _rel(law.stiffness(1e-3), fd) < 1e-6
    # F ∝ δ^(3/2): exact power law up to rounding
    assert _rel(float(law.force(4e-3)) / float(law.force(1e-3)), 8.0) < 1e-13
    assert law.approach(law.force(2.5e-3)) == pytest.approx(2.5e-3, rel=1e-14)


def test_paint_ellipse_conventions() -> None:
    paint = 6.32e-3  # mm
    A = B = 0.01
    geo = paint_ellipse(paint, A, B)
    el = hertz_ellipse_for_approach(paint, A, B, E_STAR)
    # Litvin: the level curve A x² = δ; Hertz sphere: δ = a²/R = 2 A a², i.e. sqrt(2) smaller
    assert geo.a_mm == pytest.approx(math.sqrt(paint / A), rel=1e-15)
    assert geo.a_mm / el.a_mm == pytest.approx(math.sqrt(2.0), rel=1e-12)
    # elongated: a = sqrt(δ/A) along the direction of the smaller coefficient, given in any order
    geo2 = paint_ellipse(paint, 0.04, 0.01, x_axis_rad=0.3)
    assert geo2.a_mm == pytest.approx(math.sqrt(paint / 0.01), rel=1e-15)
    assert geo2.b_mm == pytest.approx(math.sqrt(paint / 0.04), rel=1e-15)
    assert geo2.major_axis_rad == pytest.approx(0.3 + math.pi / 2 - math.pi, abs=1e-15)


def test_hertz_line_formulas() -> None:
    w, R = 100.0, 15.0
    ln = hertz_line(w, R, E_STAR)
    # Johnson §4.3: b² = 4 w R/(π E*), p0 = sqrt(w E*/(π R)); equal up to rounding
    assert ln.b_mm == pytest.approx(math.sqrt(4 * w * R / (math.pi * E_STAR)), rel=1e-15)
    assert ln.p0_MPa == pytest.approx(math.sqrt(w * E_STAR / (math.pi * R)), rel=1e-14)
    y = np.linspace(-ln.b_mm, ln.b_mm, 20001)
    # trapezoid on the sqrt profile: O(h^1.5) edge error ~1e-6 with 2e4 intervals, so 1e-5
    assert _rel(float(np.trapezoid(ln.pressure(y), y)), w) < 1e-5


# ----------------------------------------------------------------------------------------------
# relative curvature
# ----------------------------------------------------------------------------------------------


def test_relative_curvature_aligned_sums() -> None:
    k1, k2 = (0.05, 0.01), (0.02, 0.004)
    rc = relative_curvature(k1, k2, 0.0)
    # omega = 0: the gap is ½(k1I + k2I) x² + ½(k1II + k2II) y², exactly
    assert rc.B == pytest.approx(0.5 * (0.05 + 0.02), rel=1e-15)
    assert rc.A == pytest.approx(0.5 * (0.01 + 0.004), rel=1e-15)
    assert rc.major_axis_rad == pytest.approx(math.pi / 2, abs=1e-15)  # along the II direction
    # the scene geometry through the curvature API (flat block: zero curvatures)
    sc = relative_curvature((1 / 20, 1 / 100), (0.0, 0.0), 0.0)
    assert (sc.A, sc.B) == pytest.approx((1 / 200, 1 / 40), rel=1e-15)


def _eig_reference(k1, k2, omega):
    """Eigen-decomposition of ½(K1 + K2), K2 rotated by omega: an independent path."""

    def tensor(kI, kII, phi):
        R = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
        return R @ np.diag([kI, kII]) @ R.T

    Q = 0.5 * (tensor(*k1, 0.0) + tensor(*k2, omega))
    vals, vecs = np.linalg.eigh(Q)
    return vals[0], vals[1], vecs[:, 0]


def test_relative_curvature_general() -> None:
    rng = np.random.default_rng(7)
    for _ in range(200):
        k1 = tuple(rng.uniform(0.0, 0.2, 2))
        k2 = tuple(rng.uniform(-0.02, 0.2, 2))
        omega = rng.uniform(-math.pi, math.pi)
        A_ref, B_ref, v = _eig_reference(k1, k2, omega)
        if A_ref <= 1e-6:
            continue
        rc = relative_curvature(k1, k2, omega)
        # two different float evaluations of the same 2×2 eigenproblem: 1e-12 relative to B
        assert abs(rc.A - A_ref) < 1e-12 * B_ref and abs(rc.B - B_ref) < 1e-12 * B_ref
        direction = np.array([math.cos(rc.major_axis_rad), math.sin(rc.major_axis_rad)])
        # eigenvector angle error ~ eps·B/(B − A); skip nearly round cases
        if B_ref - A_ref > 1e-3 * B_ref:
            assert abs(abs(direction @ v) - 1.0) < 1e-10
        # swapping the bodies: same A, B; the angle is then measured from body 2's direction
        sw = relative_curvature(k2, k1, -omega)
        assert sw.A == pytest.approx(rc.A, rel=1e-12) and sw.B == pytest.approx(rc.B, rel=1e-12)
        if B_ref - A_ref > 1e-3 * B_ref:
            diff = math.remainder(sw.major_axis_rad - (rc.major_axis_rad - omega), math.pi)
            assert abs(diff) < 1e-9


def test_concave_body_reduces_A() -> None:
    k1 = (0.1, 0.05)
    flat = relative_curvature(k1, (0.0, 0.0), 0.4)
    concave = relative_curvature(k1, (-0.02, -0.01), 0.4)
    assert concave.A < flat.A and concave.B < flat.B
    # fully conformal in one direction: not Hertzian point contact
    with pytest.raises(InputError, match="^A = "):
        relative_curvature(k1, (-0.05, -0.05), 0.0)


def test_relative_curvature_round_contact_angle() -> None:
    rc = relative_curvature((0.02, 0.02), (0.01, 0.01), 0.7)
    assert rc.A == rc.B == pytest.approx(0.015, rel=1e-15)
    assert rc.major_axis_rad == 0.0  # undefined for a circle: documented as 0


# ----------------------------------------------------------------------------------------------
# input errors
# ----------------------------------------------------------------------------------------------

_BAD = [float("nan"), float("inf"), -1.0, 0.0]


@pytest.mark.parametrize("value", _BAD + ["x", None])
def test_bad_force(value) -> None:
    with pytest.raises(InputError, match="^force_N = ") as info:
        hertz_point(value, 0.01, 0.02, E_STAR)
    assert "> 0" in str(info.value)


@pytest.mark.parametrize("field", ["A", "B", "E_star"])
@pytest.mark.parametrize("value", _BAD)
def test_bad_coefficients(field: str, value: float) -> None:
    args = {"A": 0.01, "B": 0.02, "E_star": E_STAR}
    args[field] = value
    with pytest.raises(InputError, match=f"^{re.escape(field)} = "):
        hertz_point(10.0, **args)
    with pytest.raises(InputError, match=f"^{re.escape(field)} = "):
        hertz_law(**args)


@pytest.mark.parametrize("value", _BAD)
def test_bad_approach(value: float) -> None:
    with pytest.raises(InputError, match="^approach_mm = "):
        hertz_force_for_approach(value, 0.01, 0.02, E_STAR)
    with pytest.raises(InputError, match="^approach_mm = "):
        hertz_ellipse_for_approach(value, 0.01, 0.02, E_STAR)
    with pytest.raises(InputError, match="^approach_mm = "):
        paint_ellipse(value, 0.01, 0.02)


@pytest.mark.parametrize("field", ["E1", "E2"])
@pytest.mark.parametrize("value", _BAD)
def test_bad_modulus(field: str, value: float) -> None:
    args = {"E1": E_STEEL, "nu1": 0.3, "E2": E_STEEL, "nu2": 0.3}
    args[field] = value
    with pytest.raises(InputError, match=f"^{re.escape(field)} = "):
        effective_modulus(**args)


@pytest.mark.parametrize("field", ["nu1", "nu2"])
@pytest.mark.parametrize("value", [-1.0, 0.5, 0.7, float("nan")])
def test_bad_poisson(field: str, value: float) -> None:
    args = {"E1": E_STEEL, "nu1": 0.3, "E2": E_STEEL, "nu2": 0.3}
    args[field] = value
    with pytest.raises(InputError, match=f"^{re.escape(field)} = ") as info:
        effective_modulus(**args)
    assert "(-1, 0.5)" in str(info.value)


@pytest.mark.parametrize(
    ("radii1", "radii2", "field"),
    [
        ((0.0, 100.0), None, "radii1.Rx"),
        ((20.0, -5.0), None, "radii1.Ry"),
        ((20.0, 100.0), (float("nan"), None), "radii2.Rx"),
        ((20.0, 100.0), (None, 0.0), "radii2.Ry"),
        ((20.0, None), None, "B"),  # flat in y on both bodies: line contact
    ],
)
def test_bad_radii(radii1, radii2, field: str) -> None:
    with pytest.raises(InputError, match=f"^{re.escape(field)} = "):
        hertz_point_radii(100.0, radii1, radii2, E_STEEL, 0.3, E_STEEL, 0.3)


def test_bad_curvature_and_pressure_inputs() -> None:
    with pytest.raises(InputError, match="^omega = "):
        relative_curvature((0.1, 0.1), (0.1, 0.1), float("nan"))
    with pytest.raises(InputError, match=r"^k2\[1\] = "):
        relative_curvature((0.1, 0.1), (0.1, float("inf")), 0.0)
    with pytest.raises(InputError, match="^b = "):
        hertz_pressure(0.0, 0.0, 100.0, 1.0, 0.0)
    with pytest.raises(InputError, match="^p0 = "):
        hertz_pressure(0.0, 0.0, -1.0, 1.0, 1.0)
    with pytest.raises(InputError, match="^load_N_per_mm = "):
        hertz_line(0.0, 10.0, E_STAR)
