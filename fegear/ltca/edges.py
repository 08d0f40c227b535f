"""Which loaded cells carry a flank edge's pressure, and which are away from it.

A contact that reaches a boundary of a working flank (a tip, a fillet limit, a face end) has a
singular pressure there: the flank ends abruptly, and the half-space pressure at a sharp edge
grows like ``r^(-1/2)`` towards it (the flat-punch edge: Johnson 1985, *Contact Mechanics*,
§5.2). Its cell values are grid-dependent (they grow as the cells shrink) and are reported as
the edge value (:attr:`fegear.ltca.results.PairContact.p_edge_MPa`), never as the headline.

**The rule** (docs/ltca/edge_reach.md). A loaded cell is *away from the edges* when it is
farther than the edge's reach from every loaded cell on a flank boundary; its reach is the
larger of

- :data:`EDGE_REACH_SEMI_WIDTHS` semi-widths ``b`` of the patch (the semi-minor axis of its
  equivalent ellipse, across the contact line): the edge's pressure concentration decays over
  a distance of the order of the contact semi-width. On a straight roller pressed on a
  half-space (``benchmarks/bench_edge_reach.py``), the pressure on the centre line at a
  distance ``y`` from the roller's end exceeds the mid-length value by 17 % at ``y = b``, 7.5 %
  at ``2 b``, 4 % at ``3 b`` and 2 % at ``4 b``; an edge parallel to the contact line (a
  tip cutting the Hertz strip) changes the pressure over the whole width of the patch, which
  lies within ``2 b`` of it: a patch on a tip or a fillet limit has no interior;
- :data:`EDGE_REACH_CELLS` cells of the patch's grid, counted along each cell axis
  (``sqrt((Δξ/s_ξ)² + (Δη/s_η)²)``): a cell average next to the edge's cell carries part of the
  singular load (the half-space roller: the cell at the end grows as ``h^(-1/2)`` when the
  cells of size ``h`` are halved, 2.76, 3.80, 5.30 times the mid-length value; two cells or
  more from the end the three grids agree within 2 %).

and, besides, such a cell is the patch's interior only if the pair has one: its largest
pressure away from the edges must reach the pair's mean pressure (force over loaded area: a
Hertz patch peaks at 1.5 times its mean, a line contact at 1.27 times); below it, the cells
away from the edge are the tail of a patch sitting on the edge (FZG with a 0.5 mm axis tilt:
94 MPa beyond the reach where the pair's mean pressure is about 3000 MPa).

The loaded cells on a boundary are the last cells before it (:func:`fegear.ltca.grid.pair_cells`
marks them), so the distance to them is the distance to the flank boundary within one cell.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from fegear.ltca.grid import PairCells, edge_names

__all__ = ["EDGE_REACH_CELLS", "EDGE_REACH_SEMI_WIDTHS", "edge_split", "near_edge"]

#: Cells (along the cell axes) within which a cell average carries the edge's load.
EDGE_REACH_CELLS = 2.0
#: Patch semi-widths within which the edge's pressure concentration is more than a few % of the
#: pressure (4 % at 3 b on the half-space roller; the module docstring).
EDGE_REACH_SEMI_WIDTHS = 3.0


def near_edge(
    local: NDArray[np.float64], cell_mm: NDArray[np.float64], on_edge: NDArray[np.bool_], b: float
) -> NDArray[np.bool_]:
    """``(n,)`` bool: the cells within the edge's reach of a cell ``on_edge``.

    Parameters
    ----------
    local
        ``(n, 2)`` mm, cell centres along the cell axes ``ξ, η``.
    cell_mm
        ``(2,)`` mm, the cell sizes ``(s_ξ, s_η)``.
    on_edge
        ``(n,)`` bool, the loaded cells on a flank boundary.
    b
        mm, the patch's semi-width (semi-minor axis).

    A cell is near when its distance to an edge cell is at most
    ``EDGE_REACH_SEMI_WIDTHS · b`` or at most ``EDGE_REACH_CELLS`` cells in the cell metric.
    """
    near = on_edge.copy()
    if not on_edge.any():
        return near
    d_mm = cKDTree(local[on_edge]).query(local)[0]
    scaled = local / np.asarray(cell_mm, dtype=float)
    d_cells = cKDTree(scaled[on_edge]).query(scaled)[0]
    return near | (d_mm <= EDGE_REACH_SEMI_WIDTHS * b) | (d_cells <= EDGE_REACH_CELLS)


def edge_split(
    c: PairCells, act: NDArray[np.bool_], p: NDArray[np.float64], semi_minor: float, b1, b2
) -> tuple[tuple[str, ...], float | None, float | None]:
    """``(edges, p_interior, p_edge)`` of one loaded pair (MPa): the boundaries its active cells
    touch (named, :func:`fegear.ltca.grid.edge_names`), the largest pressure of the active
    cells away from the edges (the module's rule; None when there is none, or when it is below
    the pair's mean pressure), and the largest within the edges' reach (None for an interior
    contact). ``act``: the active cells of ``c``, ``p`` their pressures, ``semi_minor`` the
    patch's semi-minor axis (mm), ``b1``/``b2`` the pinion's and the gear's flank bounds."""
    mask = c.boundary_edges if c.boundary_edges is not None else c.boundary.astype(np.uint8)
    on_edge = act & (mask != 0)
    if not on_edge.any():
        return (), float(p[act].max()), None
    near = act & near_edge(c.local, c.cell_mm, on_edge, semi_minor)
    far = act & ~near
    p_int = float(p[far].max()) if far.any() else None
    p_mean = float((p * c.area)[act].sum() / c.area[act].sum())
    if p_int is not None and p_int < p_mean:
        p_int = None  # the tail of an edge contact, not an interior
    return edge_names(mask[on_edge], b1, b2), p_int, float(p[near].max())
