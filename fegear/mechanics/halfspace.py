"""Closed-form elastic half-space influence of uniform pressure on rectangular cells.

The normal surface displacement of a homogeneous isotropic half-space under a normal pressure
``p`` is (Boussinesq; Johnson 1985, *Contact Mechanics*, eq. 3.20)

.. math::

    u_z(x, y) = \\frac{1-\\nu^2}{\\pi E} \\iint \\frac{p(\\xi, \\eta)}
        {\\sqrt{(x-\\xi)^2 + (y-\\eta)^2}}\\,d\\xi\\,d\\eta ,

and the normal approach of two such bodies is the same with ``(1-ν²)/E`` replaced by their sum
``1/E*``. For a uniform pressure on the rectangle ``[x1, x2] × [y1, y2]`` the integral is closed
form (Love 1929; Johnson eq. 3.25): with ``X = ξ - x``, ``Y = η - y`` and

.. math::

    f(X, Y) = X \\operatorname{asinh}\\frac{Y}{|X|} + Y \\operatorname{asinh}\\frac{X}{|Y|}
    \\qquad (f = 0 \\text{ on } X = 0 \\text{ or } Y = 0 \\text{ for the vanishing term}),

``∬ dξ dη / r = f(X2, Y2) - f(X1, Y2) - f(X2, Y1) + f(X1, Y1)``. The ``asinh`` form is the
``X ln(Y + r)`` antiderivative without its cancellation for negative ``Y``.

This is the near-field operator of the ``hybrid`` fidelity and an independent check of the contact
solver (a Hertz contact on a half-space has a known answer). On a curved flank each cell is laid
out in its own tangent plane (:func:`tangent_layout`), and away from a cell its integral is taken
by Gauss points instead of the closed form (:func:`layout_influence`: within 5e-4 of it, half the
cost on the gear grids).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

__all__ = [
    "CellLayout",
    "halfspace_influence",
    "layout_influence",
    "layout_influences",
    "rectangle_integral",
    "subsurface_influence",
    "tangent_layout",
]

#: Field points per block of the row-parallel evaluation (a block of 64 x ~500 cells stays in
#: cache: measured 25 % faster than the whole matrix at once on one thread).
_BLOCK = 64


#: Far entries (see :func:`layout_influence`): a field point whose distance to the cell (along
#: the larger of the two axes) is at least ``_FAR_2D`` times the cell's longer half-width takes
#: 2 x 2 Gauss points; one at least ``_FAR_1D`` half-widths off the cell's ``x`` side, 2 Gauss
#: points across ``x`` and the exact line integral along ``y``.
_FAR_2D = 3.0
_FAR_1D = 3.0
_GAUSS = 1.0 / math.sqrt(3.0)
#: mm², below any squared distance between two cell centres.
_TINY2 = 1e-24

_POOLS: dict[int, ThreadPoolExecutor] = {}


def _pool() -> ThreadPoolExecutor:
    """Threads for the row blocks (numpy's ufuncs release the GIL on large arrays): one pool per
    process (a forked worker does not inherit the parent's threads), ``$FEGEAR_THREADS`` threads
    (set by the loaded cycle's workers to their share of the cores), else one per core."""
    pid = os.getpid()
    if pid not in _POOLS:
        n = int(os.environ.get("FEGEAR_THREADS", "0")) or min(8, os.cpu_count() or 1)
        _POOLS[pid] = ThreadPoolExecutor(max_workers=n)
    return _POOLS[pid]


def _f(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    ax = np.abs(X)
    ay = np.abs(Y)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = np.where(ax > 0.0, X * np.arcsinh(Y / np.where(ax > 0, ax, 1.0)), 0.0)
        t2 = np.where(ay > 0.0, Y * np.arcsinh(X / np.where(ay > 0, ay, 1.0)), 0.0)
    return t1 + t2


def rectangle_integral(
    x: np.ndarray, y: np.ndarray, x1: np.ndarray, x2: np.ndarray, y1: np.ndarray, y2: np.ndarray
) -> np.ndarray:
    """``∬_{[x1,x2]×[y1,y2]} dξ dη / sqrt((x-ξ)² + (y-η)²)`` in mm, broadcast over all arguments."""
    X1, X2 = x1 - x, x2 - x
    Y1, Y2 = y1 - y, y2 - y
    return _f(X2, Y2) - _f(X1, Y2) - _f(X2, Y1) + _f(X1, Y1)


def halfspace_influence(centers: np.ndarray, half_widths: np.ndarray, E_star: float) -> np.ndarray:
    """Influence matrix of rectangular cells on two elastic half-spaces.

    Parameters
    ----------
    centers
        (n, 2) mm, cell centres in the contact plane.
    half_widths
        (n, 2) mm, half-widths of the cells along x and y.
    E_star
        MPa, effective modulus ``1/E* = (1-ν1²)/E1 + (1-ν2²)/E2``.

    Returns
    -------
    numpy.ndarray
        (n, n) mm/N: normal approach at the centre of cell ``i`` per unit force spread uniformly
        on cell ``j`` (collocation at the centres; symmetric for equal cells).
    """
    c = np.asarray(centers, dtype=float)
    hw = np.asarray(half_widths, dtype=float)
    x = c[:, 0][:, None]
    y = c[:, 1][:, None]
    x1 = (c[:, 0] - hw[:, 0])[None, :]
    x2 = (c[:, 0] + hw[:, 0])[None, :]
    y1 = (c[:, 1] - hw[:, 1])[None, :]
    y2 = (c[:, 1] + hw[:, 1])[None, :]
    area = (4.0 * hw[:, 0] * hw[:, 1])[None, :]
    return rectangle_integral(x, y, x1, x2, y1, y2) / (np.pi * E_star * area)


def _f_depth(X: np.ndarray, Y: np.ndarray, z: float) -> tuple[np.ndarray, np.ndarray]:
    """Antiderivatives at depth ``z > 0``: of ``1/ρ`` and of ``z/ρ³``, ``ρ = sqrt(X²+Y²+z²)``.

    ``∬ dX dY / ρ = X asinh(Y / sqrt(X²+z²)) + Y asinh(X / sqrt(Y²+z²)) - z atan(XY / (z ρ))``
    (the ``X ln(Y + ρ)`` form less terms in ``X`` or ``Y`` alone, which cancel in the corner sum)
    and ``∬ z dX dY / ρ³ = atan(XY / (z ρ))`` (the solid angle of the rectangle seen from depth
    ``z``; Gradshteyn & Ryzhik 2.271, 2.284).
    """
    rho = np.sqrt(X * X + Y * Y + z * z)
    i2 = np.arctan(X * Y / (z * rho))
    i1 = X * np.arcsinh(Y / np.sqrt(X * X + z * z)) + Y * np.arcsinh(X / np.sqrt(Y * Y + z * z))
    return i1 - z * i2, i2


def subsurface_influence(
    points: np.ndarray,
    depth: float,
    centers: np.ndarray,
    half_widths: np.ndarray,
    E: float,
    nu: float,
) -> np.ndarray:
    """Normal displacement of ONE half-space at depth ``z`` under uniform pressure on cells.

    Boussinesq's point-force solution (Johnson 1985, eq. 3.21a): the displacement along the
    load direction at depth ``z`` and horizontal distance ``r`` from a force ``P`` is

    .. math:: u_z = \\frac{P}{4\\pi G}\\Big[\\frac{z^2}{\\rho^3}
        + \\frac{2(1-\\nu)}{\\rho}\\Big], \\qquad \\rho^2 = r^2 + z^2,\\;
        G = \\frac{E}{2(1+\\nu)},

    integrated in closed form over each rectangle (see :func:`_f_depth`). At ``z = 0`` it reduces
    to ``(1-ν²)/(πE) ∬ p / r`` of :func:`halfspace_influence` for one body.

    Parameters
    ----------
    points
        (n, 2) mm, horizontal positions of the field points.
    depth
        mm, depth ``z >= 0`` below the surface (``0`` uses the surface formula).
    centers, half_widths
        (m, 2) mm, the loaded cells (axis-aligned rectangles in one plane).
    E, nu
        The body's Young's modulus (MPa) and Poisson's ratio.

    Returns
    -------
    numpy.ndarray
        (n, m) mm/N: displacement at point ``i`` per unit force spread on cell ``j``.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    c = np.asarray(centers, dtype=float)
    layout = CellLayout(
        pts[:, 0][:, None] - c[:, 0][None, :],
        pts[:, 1][:, None] - c[:, 1][None, :],
        np.asarray(half_widths, dtype=float),
    )
    return layout_influence(layout, depth, E, nu)


class CellLayout(NamedTuple):
    """Field points seen from loaded rectangular cells, each in its own frame.

    Attributes
    ----------
    x, y
        ``(n, m)`` mm, field point ``i`` relative to the centre of cell ``j``, along the cell's
        two sides.
    half_widths
        ``(m, 2)`` mm, half the cell's sides along ``x`` and ``y``.
    """

    x: np.ndarray
    y: np.ndarray
    half_widths: np.ndarray

    def rows(self, rows: np.ndarray) -> CellLayout:
        """The layout of the field points ``rows`` only."""
        return CellLayout(self.x[rows], self.y[rows], self.half_widths)


def tangent_layout(
    points: np.ndarray, centers: np.ndarray, normals: np.ndarray, edges: np.ndarray
) -> CellLayout:
    """Lay the cells of a curved surface out in their own tangent planes.

    Cell ``j`` (centre ``c_j``, unit normal ``n_j``, edge vectors ``a_j``, ``b_j``: a small
    parallelogram of the surface) becomes the rectangle of the same area ``A_j = |a_j × b_j|``
    whose long side is its longer edge ``L_j``: half-widths ``(A_j / (2|L_j|), |L_j| / 2)`` along
    ``e_S = n_j × e_L`` and ``e_L = L_j / |L_j|``. A field point ``p_i`` is placed at
    ``d = p_i − c_j`` projected on that plane, stretched to the chord length ``|d|`` (so the
    distance that drives ``1/r`` is the true one; the normal offset of a curved surface would
    otherwise shorten it by ``|d|³/(8R²)``).

    Why not one flat map of the surface: the cells of a grid turned to an oblique contact
    patch on a flank whose metric varies (an involute's radius of curvature changes along the
    profile) are sheared parallelograms of varying width, and a single set of "intrinsic"
    coordinates (cumulative chord lengths along the grid lines) cannot place them consistently:
    measured on the seed face gear, cells of one column differed in width by ±20 % from the
    spacing of their centres, and the loaded TE moved by up to 0.03″ (≈ 6 % of the cycle's
    peak-to-peak) between a grid turned by 7° and one aligned with the profile. In its own
    tangent plane every cell is exact to first order, and its neighbours (which dominate the
    near field) are at their true distances. For elongated cells (the thin, long patches of
    gears) the long side carries the shear: a neighbour across the cell sits at the true
    perpendicular distance ``A_j / |L_j|``.

    Parameters
    ----------
    points
        ``(n, 3)`` mm, field points on the surface.
    centers, normals
        ``(m, 3)``, cell centres (mm) and unit normals.
    edges
        ``(m, 2, 3)`` mm, the two edge vectors of each cell.

    Returns
    -------
    CellLayout
        ``(n, m)`` coordinates of the field points in the cell frames, ``(m, 2)`` half-widths.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    c = np.asarray(centers, dtype=float)
    nrm = np.asarray(normals, dtype=float)
    ed = np.asarray(edges, dtype=float)
    length = np.linalg.norm(ed, axis=-1)  # (m, 2)
    long = np.argmax(length, axis=1)
    L = ed[np.arange(c.shape[0]), long]
    L = L - np.sum(L * nrm, -1)[:, None] * nrm
    eL = L / np.linalg.norm(L, axis=-1)[:, None]
    eS = np.cross(nrm, eL)
    area = np.linalg.norm(np.cross(ed[:, 0], ed[:, 1]), axis=-1)
    hL = 0.5 * length[np.arange(c.shape[0]), long]
    hw = np.stack([area / (4.0 * hL), hL], -1)
    # d · e = p · e − c · e for the three frame vectors: one matrix product, no (n, m, 3) array
    o = c.mean(axis=0)
    frames = np.concatenate([eS, eL, nrm])  # (3m, 3)
    xyz = (p - o) @ frames.T
    xyz -= np.sum((np.concatenate([c, c, c]) - o) * frames, -1)[None, :]
    m = c.shape[0]
    x, y, z = xyz[:, :m], xyz[:, m : 2 * m], xyz[:, 2 * m :]
    # stretch (x, y) to the chord: sqrt(1 + z² / (x² + y²)); the cell itself stays at 0
    planar2 = x * x
    planar2 += y * y
    np.maximum(planar2, _TINY2, out=planar2)
    np.square(z, out=z)
    z /= planar2
    z += 1.0
    np.sqrt(z, out=z)
    x *= z
    y *= z
    return CellLayout(x, y, hw)


def _exact(X1, X2, Y1, Y2, z):
    """``(∬ 1/ρ, ∬ z/ρ³)`` over the rectangles (corner sums of :func:`_f`, :func:`_f_depth`)."""
    if z <= 0.0:
        return rectangle_integral(0.0, 0.0, X1, X2, Y1, Y2), 0.0
    i1, i2 = 0.0, 0.0
    for Xa, Ya, sgn in ((X2, Y2, 1.0), (X1, Y2, -1.0), (X2, Y1, -1.0), (X1, Y1, 1.0)):
        a1, a2 = _f_depth(Xa, Ya, z)
        i1 = i1 + sgn * a1
        i2 = i2 + sgn * a2
    return i1, i2


def _gauss_x(x, y, hx, hy, z):
    """The same by 2 Gauss points across ``x`` and the exact integral along ``y``:
    ``∫ dY/ρ = asinh(Y/q)``, ``∫ z dY/ρ³ = z Y/(q² ρ)``, ``q² = X² + z²``."""
    j1, j2 = 0.0, 0.0
    for g in (-_GAUSS, _GAUSS):
        X = g * hx - x
        q2 = X * X + z * z
        q = np.sqrt(q2)
        for Y, sgn in ((hy - y, 1.0), (-hy - y, -1.0)):
            j1 = j1 + sgn * np.arcsinh(Y / q)
            if z > 0.0:
                j2 = j2 + sgn * z * Y / (q2 * np.sqrt(q2 + Y * Y))
    return hx * j1, hx * j2


def _gauss_xy(x, y, hx, hy, z, squares=None):
    """The same by 2 x 2 Gauss points (point forces). ``squares``: ``(X², Y²)`` of the Gauss
    points, ``[(g hx − x)², …]`` and ``[(g hy − y)², …]`` (they do not depend on ``z``:
    :func:`layout_influences` makes them once for all its depths)."""
    sx, sy = squares if squares is not None else _gauss_squares(x, y, hx, hy)
    X = [s + z * z for s in sx]
    Y = sy
    j1 = np.zeros(np.broadcast(x, hx).shape)
    j2 = np.zeros_like(j1) if z > 0.0 else 0.0
    for X2 in X:
        for Y2 in Y:
            inv = X2 + Y2
            np.sqrt(inv, out=inv)
            np.reciprocal(inv, out=inv)
            j1 += inv
            if z > 0.0:
                j2 += inv * inv * inv
    return hx * hy * j1, z * hx * hy * j2


def _gauss_squares(x, y, hx, hy) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """``([(g hx − x)² for g], [(g hy − y)² for g])`` at the two Gauss points ``g = ∓1/√3``."""
    return (
        [np.square(g * hx - x) for g in (-_GAUSS, _GAUSS)],
        [np.square(g * hy - y) for g in (-_GAUSS, _GAUSS)],
    )


def layout_influence(layout: CellLayout, depth: float, E: float, nu: float) -> np.ndarray:
    """Normal displacement of ONE half-space at depth ``z`` (:func:`subsurface_influence`) at the
    field points of ``layout`` per unit force spread uniformly on each of its cells, ``(n, m)``
    mm/N:

    .. math:: w = \\frac{z\\,I_3 + 2(1-\\nu) I_1}{4\\pi G A}, \\qquad
        I_1 = \\iint \\frac{dX\\,dY}{\\rho}, \\quad I_3 = \\iint \\frac{z\\,dX\\,dY}{\\rho^3}.

    Near a cell the integrals are the closed forms (:func:`_f`, :func:`_f_depth`: eight
    ``asinh`` and four ``atan`` per entry). Away from it the integrand is smooth over the cell
    and Gauss quadrature is as good at a fraction of the cost: two points across ``x`` and the
    exact line integral along ``y`` where the field point is ``_FAR_1D`` half-widths off the
    cell's ``x`` side (the side beside a long thin cell), 2 × 2 points where it is ``_FAR_2D``
    longer half-widths off the cell. The two-point rule integrates cubics exactly; its error on
    ``1/ρ`` at a distance ``d`` from a cell of half-width ``h`` is ``~(8/45)(h/d)⁴`` of the
    entry (Abramowitz & Stegun 25.4.29), below 2e-3 at ``d = 3h`` and measured below 1e-3 on
    every entry of the gear grids (``tests/test_halfspace.py``).
    """
    return layout_influences(layout, (depth,), E, nu)[0]


def layout_influences(
    layout: CellLayout, depths: Sequence[float], E: float, nu: float
) -> list[np.ndarray]:
    """:func:`layout_influence` of the same layout at each of ``depths``, entry for entry the
    same numbers: what does not depend on the depth (the Gauss points' squared offsets
    ``(g h − x)²``, the cells' near entries and their quadrature rule) is made once for all
    depths (the ``hybrid`` fidelity reads every layout at the surface and at the matching
    depth)."""
    n = layout.x.shape[0]
    if n > _BLOCK and layout.x.size > 20_000:
        # Row blocks on all cores: 2.5x faster on 2 cores for 500 x 500 (bit-identical: the
        # entries are independent).
        blocks = [slice(i, min(i + _BLOCK, n)) for i in range(0, n, _BLOCK)]
        parts = list(
            _pool().map(lambda b: layout_influences(layout.rows(b), depths, E, nu), blocks)
        )
        return [np.vstack([p[k] for p in parts]) for k in range(len(depths))]
    hw = layout.half_widths
    hx, hy = hw[:, 0], hw[:, 1]
    x, y = layout.x, layout.y
    squares = _gauss_squares(x, y, hx, hy)
    # 2 x 2 points everywhere (most entries: no indexing), then the entries near a cell
    ox, oy = np.abs(x) - hx, np.abs(y) - hy  # distances off the cell's sides
    rows, cols = np.nonzero(np.maximum(ox, oy) < _FAR_2D * np.maximum(hx, hy))
    across = ox[rows, cols] >= _FAR_1D * hx[cols]
    near = []
    for sel, rule in ((across, _gauss_x), (~across, None)):
        r, c = rows[sel], cols[sel]
        near.append((r, c, rule, x[r, c], y[r, c], hx[c], hy[c]))
    G = E / (2.0 * (1.0 + nu))
    area = (4.0 * hw[:, 0] * hw[:, 1])[None, :]
    out = []
    for depth in depths:
        z = max(float(depth), 0.0)
        i1, i2 = _gauss_xy(x, y, hx, hy, z, squares)
        for r, c, rule, xs, ys, hxs, hys in near:
            if rule is None:
                a1, a2 = _exact(-hxs - xs, hxs - xs, -hys - ys, hys - ys, z)
            else:
                a1, a2 = rule(xs, ys, hxs, hys, z)
            i1[r, c] = a1
            if z > 0.0:
                i2[r, c] = a2
        out.append((z * i2 + 2.0 * (1.0 - nu) * i1) / (4.0 * np.pi * G * area))
    return out
