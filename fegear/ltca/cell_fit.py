"""Contact cells fitted to the flank boundaries.

The cells of a pair lie on a regular grid of its pinion flank (:func:`fegear.ltca.grid.pair_cells`,
grid coordinates ``(ξ, η)`` in mm along the cell axes) and a cell is kept when its centre lies on
both working flanks. A boundary (a face end, the tip, the fillet limit, of either member) then
falls anywhere between the last kept centre and the next: the last cell either overhangs the
boundary by up to half a cell (load on a flank that is not there) or stops up to half a cell
short of it (a strip that carries nothing). A line contact runs to both face ends at every
position, so its effective face width changed by up to one cell from one position to the next:
FZG's 14 mm face with cells of 0.9 mm along it read a face-end load per unit width from 0.61 to
1.33 times the mid-face one at neighbouring positions; fitted, 1.03-1.05 at every position.

:func:`fit_to_boundaries` moves the outer edge of every kept cell whose neighbour along ``η``
has its centre off the flanks onto the boundary: the crossing of the cell's midline with the
boundary, found by bisection between the two centres (:data:`BISECTIONS` halvings: a crossing to
``2⁻¹²`` of a cell). Such a cell spans ``½ … 1½`` cells along ``η`` (less where both its
neighbours are off: the flank between two boundaries); its midline has the length of the part
on the flank, so its area is that of the flank part whatever the boundary's angle to the cell
(a straight boundary: the trapezoid and the rectangle of equal midline have equal areas). Cells
whose neighbours are on the flank are left as they are: the zone's limit at ``g_max`` is not a
boundary. A cell left with less than :data:`MIN_FITTED` of its length (a sliver between a tip
and a face end, where the grid crosses a corner) keeps its grid cell: fitted, its pressure
would be a force over a vanishing area (FZG with a 0.03 mm axis tilt: a 0.00016 mm cell read
989 GPa), and dropped, the corner contact it stands for is lost (the spiral bevel's third pair
entering at 400 N·m took no load).

Only along ``η``: the grid's ``η`` runs along the contact line of a line contact and along the
major axis of a patch (:func:`fegear.ltca.hybrid.refined_sizes` turns it so), where the gap
varies least, and a fitted cell's gap is read at its new centre. Across the patch (``ξ``) the
gap of a cell at the tip or the fillet limit, where a pair enters contact, changes with its
centre: fitted along ``ξ`` too, the element-sized cells of ``fe`` on FZG read the entering
pair's closest cell 131 µm from contact instead of 34 µm, and the pair never took load.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["BISECTIONS", "MIN_FITTED", "fit_to_boundaries", "neighbour_values"]

Array = NDArray[np.float64]
#: Halvings of the bisection for a boundary crossing (to ``2⁻¹²`` of a cell).
BISECTIONS = 12
#: The shortest fitted cell, in units of the grid's cell length along ``η``: a shorter one is a
#: sliver and keeps its grid cell (module docstring).
MIN_FITTED = 0.25


def neighbour_values(on: NDArray[np.bool_], axis: int, step: int, outside) -> NDArray[np.bool_]:
    """``on`` of each grid cell's neighbour along ``axis`` (``step`` ±1); a neighbour outside the
    grid takes ``outside`` (same shape as ``on``)."""
    nb = np.array(outside, dtype=bool, copy=True)
    if axis == 0 and step == 1:
        nb[:-1] = on[1:]
    elif axis == 0:
        nb[1:] = on[:-1]
    elif step == 1:
        nb[:, :-1] = on[:, 1:]
    else:
        nb[:, 1:] = on[:, :-1]
    return nb


def fit_to_boundaries(
    on_at: Callable[[Array, Array], NDArray[np.bool_]],
    xi: Array,
    eta: Array,
    on: NDArray[np.bool_],
    keep: NDArray[np.bool_],
    size: tuple[float, float],
) -> tuple[Array, Array]:
    """The edges of the kept cells along ``ξ`` and ``η``, fitted to the flank boundaries.

    Parameters
    ----------
    on_at
        ``on_at(ξ, η)`` -> bool, broadcast: grid coordinates (mm) on both working flanks.
    xi, eta
        ``(nξ, nη)`` grid coordinates of the cell centres.
    on
        ``(nξ, nη)`` the centres on both working flanks.
    keep
        ``(nξ, nη)`` the cells kept (``keep ⊆ on``).
    size
        The grid's cell sizes ``(s_ξ, s_η)`` mm.

    Returns
    -------
    lo, hi
        ``(n, 2)`` grid coordinates of each kept cell's lower and upper edge along ``ξ`` and
        ``η`` (row-major order of ``keep``): ``centre ∓ s/2`` except where a boundary is fitted
        (module docstring).
    """
    centre = np.stack([xi[keep], eta[keep]], -1)
    half = 0.5 * np.asarray(size, dtype=float)
    lo, hi = centre - half, centre + half
    for axis in (1,):  # along η only (module docstring: why not along ξ)
        for step in (1, -1):
            # a neighbour outside the grid: on the flanks unless its centre is off them
            shift = np.zeros(2)
            shift[axis] = step * size[axis]
            edge = _edge_cells(on, axis, step)
            outside = np.ones_like(on)
            if edge.any():
                outside[edge] = on_at(xi[edge] + shift[0], eta[edge] + shift[1])
            off = keep & ~neighbour_values(on, axis, step, outside)
            idx = off[keep]
            if not idx.any():
                continue
            x0 = centre[idx]
            a, b = np.zeros(idx.sum()), np.full(idx.sum(), float(size[axis]))  # on, off
            for _ in range(BISECTIONS):
                t = 0.5 * (a + b)
                p = x0.copy()
                p[:, axis] += step * t
                ok = on_at(p[:, 0], p[:, 1])
                a, b = np.where(ok, t, a), np.where(ok, b, t)
            reach = 0.5 * (a + b)
            if step == 1:
                hi[idx, axis] = x0[:, axis] + reach
            else:
                lo[idx, axis] = x0[:, axis] - reach
    return lo, hi


def _edge_cells(on: NDArray[np.bool_], axis: int, step: int) -> NDArray[np.bool_]:
    """The cells of the grid's last row/column along ``axis`` in the direction ``step``."""
    e = np.zeros(on.shape, dtype=bool)
    if axis == 0:
        e[-1 if step == 1 else 0, :] = True
    else:
        e[:, -1 if step == 1 else 0] = True
    return e
