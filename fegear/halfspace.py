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
solver (a Hertz contact on a half-space has a known answer).
"""

from __future__ import annotations

import numpy as np

__all__ = ["rectangle_integral", "halfspace_influence"]


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
