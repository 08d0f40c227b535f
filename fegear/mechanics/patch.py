"""Measures of a computed contact patch: peak pressure and semi-axes.

Both work on any field of cell forces on a planar grid of cells (the Hertz scene, or a gear flank
in its local tangent coordinates), so they know nothing about gears.

**Semi-axes from second moments.** For the Hertz distribution ``p0 sqrt(1 - x²/a² - y²/b²)`` the
force-weighted second moments are ``<x²> = a²/5`` and ``<y²> = b²/5`` (integrate in elliptic
polar coordinates: ``∫ r³ sqrt(1-r²) dr / ∫ r sqrt(1-r²) dr = (2/15)/(1/3)`` and the angular factor
1/2). So the semi-axes of the equivalent ellipse are ``sqrt(5 λ)`` of the eigenvalues ``λ`` of the
second-moment tensor about the force centroid. Unlike the extent of the active cells, this does
not jump by whole cells, so it converges with the grid.

**Peak pressure by recovery.** Piecewise-constant cell pressures computed with an FE compliance
carry noise at the element scale (a cell sees a stiffer or softer spot depending on where it sits
relative to the P2 nodes), so the raw maximum of the cells over-estimates the peak by a few percent
and does not converge at a fixed element/cell ratio. The recovered peak fits, by least squares,
the quadratic ``p² = c0 + c1 x + c2 y + c3 x² + c4 xy + c5 y²`` to the cells carrying at least
``threshold`` of the raw maximum and returns ``sqrt`` of the fitted maximum. ``p²`` of a Hertz
distribution is exactly such a quadratic, and the square of any smooth peak is quadratic near its
maximum; the fit averages the element-scale noise out, in the spirit of the patch recovery of
Zienkiewicz & Zhu (1992, IJNME 33, 1331). Both values are reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fegear.errors import InputError

__all__ = ["PatchMeasures", "measure_patch"]


@dataclass(frozen=True)
class PatchMeasures:
    """Measures of one contact patch (mm, MPa).

    Attributes
    ----------
    p_max_cell
        Largest cell pressure.
    p_peak
        Recovered peak pressure (least-squares quadratic of ``p²``); equals ``p_max_cell`` when
        too few cells carry load for a fit.
    semi_major, semi_minor
        Equivalent-ellipse semi-axes from the second moments.
    major_direction
        (2,) unit direction of the major axis in the grid coordinates.
    centroid
        (2,) force centroid.
    n_fit
        Cells used in the fit (0 if none).
    """

    p_max_cell: float
    p_peak: float
    semi_major: float
    semi_minor: float
    major_direction: np.ndarray
    centroid: np.ndarray
    n_fit: int


def measure_patch(
    centers: np.ndarray, force: np.ndarray, area: np.ndarray | float, threshold: float = 0.3
) -> PatchMeasures:
    """Measure a patch from cell centres (n, 2) mm, cell forces (n,) N and areas (mm²)."""
    c = np.asarray(centers, dtype=float)
    F = np.asarray(force, dtype=float)
    A = np.broadcast_to(np.asarray(area, dtype=float), F.shape)
    if c.shape != (F.size, 2):
        raise InputError("centers", c.shape, f"shape ({F.size}, 2)")
    total = F.sum()
    if not total > 0:
        raise InputError("force", total, "a positive total force")
    p = F / A
    m = c.T @ F / total
    d = c - m
    M = (d * F[:, None]).T @ d / total
    lam, vec = np.linalg.eigh(M)
    semi_major = math.sqrt(5.0 * max(lam[1], 0.0))
    semi_minor = math.sqrt(5.0 * max(lam[0], 0.0))
    pmax = float(p.max())
    sel = p >= threshold * pmax
    x, y = d[sel, 0], d[sel, 1]
    p_peak, n_fit = pmax, 0
    if sel.sum() >= 12:
        V = np.column_stack([np.ones_like(x), x, y, x * x, x * y, y * y])
        coef, *_ = np.linalg.lstsq(V, p[sel] ** 2, rcond=None)
        H = np.array([[2 * coef[3], coef[4]], [coef[4], 2 * coef[5]]])
        if np.all(np.linalg.eigvalsh(H) < 0):  # a proper maximum
            xm = np.linalg.solve(H, -coef[1:3])
            vmax = coef[0] + coef[1:3] @ xm + 0.5 * xm @ H @ xm
            if vmax > 0:
                p_peak, n_fit = math.sqrt(vmax), int(sel.sum())
    return PatchMeasures(
        p_max_cell=pmax,
        p_peak=float(p_peak),
        semi_major=semi_major,
        semi_minor=semi_minor,
        major_direction=vec[:, 1].copy(),
        centroid=m,
        n_fit=n_fit,
    )
