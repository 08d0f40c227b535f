"""Tests of the closed-form half-space influence (fegear.mechanics.halfspace).

References, all independent of Love's closed form:

- ``scipy.integrate.dblquad`` of 1/r over the rectangle, split at the field point so that the
  integrable 1/r singularity sits on sub-rectangle corners (where ``quad`` sees only a log);
- Boussinesq's point force ``u = P / (π E* r)``, with the quadrupole correction of a square cell
  derived here: the second moments of a uniform square of side w are ``w²/12`` in every direction,
  so ``⟨1/|r − ρ|⟩ = (1/r)(1 + w²/(24 r²) + O((w/r)⁴))``;
- superposition and scaling: the centre of a square of side 2s is the corner of four squares of
  side s, and ``∬ dA / r`` is homogeneous of degree 1 in length, so the corner of a uniformly loaded
  square settles exactly half as much as its centre; the centre value
  ``8 ln(1 + √2) / π ≈ 2.24 p c / E*`` (half-side c) is Timoshenko & Goodier's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import dblquad

from fegear.mechanics import halfspace
from fegear.mechanics.halfspace import (
    halfspace_influence,
    layout_influence,
    layout_influences,
    rectangle_integral,
    subsurface_influence,
    tangent_layout,
)

E_STAR = 113186.8131868132  # steel on steel, 206000 / (2 (1 - 0.3²)) MPa


def _quad_integral(x: float, y: float, x1: float, x2: float, y1: float, y2: float) -> float:
    """∬ dξ dη / r by dblquad, the rectangle split at (x, y) so 1/r is singular only at corners."""
    xs = sorted({x1, x2, *([x] if x1 < x < x2 else [])})
    ys = sorted({y1, y2, *([y] if y1 < y < y2 else [])})
    total = 0.0
    for xa, xb in zip(xs[:-1], xs[1:], strict=True):
        for ya, yb in zip(ys[:-1], ys[1:], strict=True):
            val, _ = dblquad(
                lambda eta, xi: 1.0 / math.hypot(x - xi, y - eta),
                xa,
                xb,
                ya,
                yb,
                epsabs=0.0,
                epsrel=1e-12,
            )
            total += val
    return total


RECT = (-0.3, 0.5, -0.2, 0.1)  # x1, x2, y1, y2 in mm: a non-square cell off the origin


@pytest.mark.parametrize(
    ("x", "y"),
    [
        pytest.param(0.1, -0.05, id="inside-centre"),
        pytest.param(-0.25, 0.08, id="inside-near-corner"),
        pytest.param(0.5, -0.07, id="on-edge"),
        pytest.param(0.2, 0.1, id="on-other-edge"),
        pytest.param(-0.3, -0.2, id="on-corner"),
        pytest.param(0.6, 0.15, id="outside-near"),
        pytest.param(-7.0, 12.0, id="far"),
    ],
)
def test_rectangle_integral_matches_dblquad(x: float, y: float) -> None:
    exact = float(rectangle_integral(np.array(x), np.array(y), *map(np.array, RECT)))
    ref = _quad_integral(x, y, *RECT)
    # quadrature asked for 1e-12 per piece; log singularities at the corners cost a few digits
    assert exact == pytest.approx(ref, rel=1e-9), f"closed form {exact!r} vs dblquad {ref!r}"


def test_rectangle_integral_broadcasts_over_points() -> None:
    pts = np.array([[0.1, -0.05], [0.5, -0.07], [-7.0, 12.0]])
    vec = rectangle_integral(pts[:, 0], pts[:, 1], *map(np.array, RECT))
    one = [float(rectangle_integral(np.array(px), np.array(py), *RECT)) for px, py in pts]
    # same formula element by element: identical floating-point operations
    np.testing.assert_array_equal(vec, one)


def test_uniform_square_corner_settles_half_the_centre() -> None:
    """Superposition + scaling: corner(side 2s) = 2 corner(s) and centre(2s) = 4 corner(s)."""
    s = 1.7  # mm, side of the square [0, s]^2
    zero, side = np.array(0.0), np.array(s)
    centre = float(rectangle_integral(np.array(s / 2), np.array(s / 2), zero, side, zero, side))
    corner = float(rectangle_integral(zero, zero, zero, side, zero, side))
    # two evaluations of the closed form: round-off only
    assert corner / centre == pytest.approx(0.5, rel=1e-14)
    # Timoshenko & Goodier: centre displacement 8 ln(1+√2)/π · p c/E* ≈ 2.24 p c/E* (c = s/2)
    u_centre = centre / (math.pi * E_STAR)  # per unit pressure
    assert u_centre == pytest.approx(8.0 * math.log1p(math.sqrt(2.0)) / math.pi * (s / 2) / E_STAR)
    assert 8.0 * math.log1p(math.sqrt(2.0)) / math.pi == pytest.approx(2.24, abs=0.005)


def test_uniform_pressure_on_grid_is_the_whole_square() -> None:
    """Summing the cell columns of C is the closed form of the whole square (additivity)."""
    m, w = 15, 0.2  # 15 × 15 equal cells of side w
    k = (np.arange(m) - (m - 1) / 2) * w
    X, Y = np.meshgrid(k, k, indexing="ij")
    centres = np.column_stack([X.ravel(), Y.ravel()])
    C = halfspace_influence(centres, np.full_like(centres, w / 2), E_STAR)
    p = 3.0  # MPa, uniform
    u = (C @ np.full(m * m, p * w * w)).reshape(m, m)
    c = m * w / 2
    lo, hi = np.array(-c), np.array(c)
    u_ref = p * rectangle_integral(X, Y, lo, hi, lo, hi) / (math.pi * E_STAR)
    # 225 closed forms summed vs one: cancellation in the asinh differences, round-off only
    np.testing.assert_allclose(u, u_ref, rtol=1e-12)
    # physics: maximum at the centre, decreasing towards the corner cell
    # (the four symmetric corners agree to round-off, so compare values, not positions)
    assert u[m // 2, m // 2] == pytest.approx(u.max(), rel=1e-12)
    assert u[0, 0] == pytest.approx(u.min(), rel=1e-12)


def test_influence_is_symmetric_for_equal_cells() -> None:
    rng = np.random.default_rng(7)
    centres = rng.uniform(-2.0, 2.0, size=(60, 2))
    C = halfspace_influence(centres, np.full_like(centres, 0.05), E_STAR)
    # f(-X, -Y) = f(X, Y): C_ij and C_ji are the same formula on negated differences; only the
    # rounding of the coordinates (eps |x| ~ 4e-16 mm) differs, amplified by the cancellation of
    # the four asinh terms (~ r/w ≤ 40 here): measured 7e-13 relative
    np.testing.assert_allclose(C, C.T, rtol=1e-11, atol=0.0)


def test_influence_of_regular_grid_is_positive_definite() -> None:
    """What the contact solver needs: a Cholesky factor of every principal block."""
    w = 0.1
    k = np.arange(-8, 9) * w
    X, Y = np.meshgrid(k, k, indexing="ij")
    centres = np.column_stack([X.ravel(), Y.ravel()])
    C = halfspace_influence(centres, np.tile([w / 2, 0.3 * w], (centres.shape[0], 1)), E_STAR)
    eig = np.linalg.eigvalsh(0.5 * (C + C.T))
    assert eig.min() > 0.0, f"min eigenvalue {eig.min():.3e}"
    # diagonal is the largest entry of its row: a cell settles most under its own load
    assert np.all(np.argmax(C, axis=1) == np.arange(C.shape[0]))


# off-axis: the square's second moment w²/12 is isotropic, so the direction does not matter
DIRECTION = np.array([math.cos(0.7), math.sin(0.7)])


@pytest.mark.parametrize("ratio", [5.0, 10.0, 30.0, 100.0])
def test_far_field_is_a_point_force_plus_quadrupole(ratio: float) -> None:
    """u → 1/(π E* r) with the square-cell correction w²/(24 r²)."""
    w = 0.04
    r = ratio * w
    centres = np.array([[0.013, -0.021], [0.013, -0.021] + r * DIRECTION])
    C = halfspace_influence(centres, np.full((2, 2), w / 2), E_STAR)
    rel = C[1, 0] * math.pi * E_STAR * r - 1.0
    # the next multipole term is O((w/r)^4), i.e. O((w/r)^2) relative to the quadrupole
    assert rel == pytest.approx(1.0 / (24.0 * ratio**2), rel=2.0 / ratio**2)


@pytest.mark.parametrize("ratio", [1e3, 1e4])
def test_far_field_equals_point_force(ratio: float) -> None:
    """Far away the cell is a Boussinesq point force, to round-off."""
    w = 1e-3
    r = ratio * w
    centres = np.array([[0.013, -0.021], [0.013, -0.021] + r * DIRECTION])
    C = halfspace_influence(centres, np.full((2, 2), w / 2), E_STAR)
    # quadrupole 1/(24 ratio²) ≤ 4e-8; the asinh differences lose ~eps (r/w)² off-axis (measured
    # 5e-12 at 1e3, 1e-8 at 1e4): far beyond any contact grid (r/w ≤ ~100), so no tighter claim
    assert C[1, 0] * math.pi * E_STAR * r == pytest.approx(1.0, rel=1e-7)


@pytest.mark.parametrize("depth", [0.0, 0.4])
@pytest.mark.parametrize("aspect", [1.0, 20.0])
def test_gauss_far_field_matches_the_closed_form_entry_by_entry(
    monkeypatch: pytest.MonkeyPatch, depth: float, aspect: float
) -> None:
    """Away from a cell :func:`layout_influence` integrates by Gauss points instead of the
    closed form; every entry of a grid of cells (square, and long thin ones as on gear flanks),
    seen from field points scattered over and around it, stays within 1e-3 of the closed form
    (the two-point rule's bound at 3 half-widths is (8/45)(1/3)⁴ = 2e-3 of the entry; measured
    ≤ 5e-4 here and on the gear grids), and the response to a smooth load within 1e-4
    (measured 4e-5)."""
    hx, hy = 0.02, 0.02 * aspect
    i, j = np.meshgrid(np.arange(-12, 13), np.arange(-6, 7), indexing="ij")
    centres = np.stack([2 * hx * i.ravel(), 2 * hy * j.ravel(), np.zeros(i.size)], -1)
    m = centres.shape[0]
    normals = np.tile([0.0, 0.0, 1.0], (m, 1))
    edges = np.tile(np.array([[2 * hx, 0.0, 0.0], [0.0, 2 * hy, 0.0]]), (m, 1, 1))
    rng = np.random.default_rng(7)
    points = np.c_[rng.uniform(-1.5, 1.5, (400, 2)) * [30 * hx, 10 * hy], np.zeros(400)]
    lay = tangent_layout(points, centres, normals, edges)
    fast = layout_influence(lay, depth, 206000.0, 0.3)
    monkeypatch.setattr(halfspace, "_FAR_1D", math.inf)
    monkeypatch.setattr(halfspace, "_FAR_2D", math.inf)
    exact = layout_influence(lay, depth, 206000.0, 0.3)
    assert not np.array_equal(fast, exact)  # the far field took the Gauss points
    assert np.max(np.abs(fast / exact - 1.0)) < 1e-3
    load = np.exp(-((centres[:, 0] / (8 * hx)) ** 2) - (centres[:, 1] / (4 * hy)) ** 2)
    assert np.max(np.abs((fast - exact) @ load)) < 1e-4 * np.max(np.abs(exact @ load))


def test_tangent_layout_of_a_flat_grid_is_the_flat_layout() -> None:
    """On a plane the tangent layout is the plain one: offsets along the cell sides, the long
    side as ``y`` (here ``x`` is long: the frame turns), half-widths from the edges."""
    centres = np.array([[0.0, 0.0, 0.0], [0.3, 0.1, 0.0]])
    normals = np.tile([0.0, 0.0, 1.0], (2, 1))
    edges = np.tile(np.array([[0.5, 0.0, 0.0], [0.0, 0.1, 0.0]]), (2, 1, 1))
    lay = tangent_layout(centres, centres, normals, edges)
    np.testing.assert_allclose(lay.half_widths, [[0.05, 0.25], [0.05, 0.25]])
    # cell 0 seen from point 1: 0.3 along the long side (x), 0.1 across it (the frame's
    # e_S = n × e_L = ŷ)
    assert lay.y[1, 0] == pytest.approx(0.3) and lay.x[1, 0] == pytest.approx(0.1)
    assert lay.x[0, 0] == 0.0 and lay.y[0, 0] == 0.0
    flat = subsurface_influence(
        np.array([[0.0, 0.0], [0.1, 0.3]]),
        0.2,
        np.array([[0.0, 0.0], [0.1, 0.3]]),
        np.array([[0.05, 0.25]] * 2),
        206000.0,
        0.3,
    )
    np.testing.assert_allclose(layout_influence(lay, 0.2, 206000.0, 0.3), flat, rtol=1e-12)


def test_influences_at_several_depths_are_the_single_depth_ones() -> None:
    """:func:`layout_influences` shares what does not depend on the depth and nothing else: at
    each depth its entries are those of :func:`layout_influence`, bit for bit (a layout large
    enough for the row-block threads, and a small one)."""
    rng = np.random.default_rng(3)
    for m, n in ((40, 30), (150, 200)):
        centres = np.c_[rng.uniform(-2.0, 2.0, (m, 2)), np.zeros(m)]
        normals = np.tile([0.0, 0.0, 1.0], (m, 1))
        edges = np.tile(np.array([[0.1, 0.0, 0.0], [0.0, 0.6, 0.0]]), (m, 1, 1))
        points = np.c_[rng.uniform(-2.5, 2.5, (n, 2)), np.zeros(n)]
        lay = tangent_layout(points, centres, normals, edges)
        depths = [0.0, 0.35, 0.175]
        for d, got in zip(depths, layout_influences(lay, depths, 206000.0, 0.3), strict=True):
            want = layout_influence(lay, d, 206000.0, 0.3)
            np.testing.assert_array_equal(got.view(np.int64), want.view(np.int64))
