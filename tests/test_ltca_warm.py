"""The warm start of the loaded analysis (fegear.ltca.warm) on synthetic cell grids.

A flat grid of cells on the plane z = 0 stands for one pair's cells; the neighbouring solution is
the same grid with a known approach field. The prediction keeps the cells whose separation minus
the neighbour's approach is within the bound, and the ring around the kept cells is their first
layer of neighbours on the grid.
"""

from __future__ import annotations

import numpy as np
import pytest

from fegear.geometry.pair_placement import involute_assembly
from fegear.ltca.grid import PairCells, take_cells
from fegear.ltca.warm import Footprint, _relative_points, likely_cells, ring_cells

CELL = (0.05, 0.4)  # mm along ξ (across the patch) and η (along it)


def _grid(n_xi: int, n_eta: int, gap: np.ndarray | None = None) -> PairCells:
    """Cells of a flat grid centred on the origin (fixed frame = pinion tooth 0 frame at φ1 = 0
    for the involute assembly below), all moment arms 1 mm/rad."""
    xi = (np.arange(n_xi) - (n_xi - 1) / 2) * CELL[0]
    eta = (np.arange(n_eta) - (n_eta - 1) / 2) * CELL[1]
    X, E = (a.ravel() for a in np.meshgrid(xi, eta, indexing="ij"))
    n = X.size
    centers = np.stack([X, E, np.zeros(n)], -1) + np.array([30.0, 0.0, 0.0])
    edges = np.broadcast_to(np.array([[CELL[0], 0, 0], [0, CELL[1], 0]]), (n, 2, 3)).copy()
    return PairCells(
        k=0,
        j=0,
        uv=np.stack([X, E], -1),
        centers=centers,
        normals=np.tile([0.0, 0.0, 1.0], (n, 1)),
        quad_points=np.repeat(centers[:, None], 4, axis=1),
        gap=np.full(n, 1e-3) if gap is None else gap,
        h=np.ones(n),
        area=np.full(n, CELL[0] * CELL[1]),
        local=np.stack([X, E], -1),
        edges=edges,
        cell_mm=np.array(CELL),
        boundary=np.zeros(n, dtype=bool),
        origin=np.array([30.0, 0.0, 0.0]),
    )


@pytest.fixture(scope="module")
def asm():
    from fegear.geometry import InvoluteDesign, InvoluteMember

    p = InvoluteMember(InvoluteDesign(20, 3.0, 20, face_width_mm=10), "pinion")
    g = InvoluteMember(InvoluteDesign(30, 3.0, 20, face_width_mm=10), "gear")
    return involute_assembly(p, g)


def test_the_ring_is_the_first_layer_of_neighbours() -> None:
    c = _grid(7, 5)
    ij = np.stack(np.meshgrid(np.arange(7), np.arange(5), indexing="ij"), -1).reshape(-1, 2)
    centre = np.flatnonzero((np.abs(ij[:, 0] - 3) <= 1) & (np.abs(ij[:, 1] - 2) <= 1))
    ring = ring_cells(c, centre)
    expect = np.flatnonzero(
        (np.abs(ij[:, 0] - 3) <= 2) & (np.abs(ij[:, 1] - 2) <= 2) & ~np.isin(np.arange(35), centre)
    )
    np.testing.assert_array_equal(ring, expect)  # 5 x 5 block less the 3 x 3 centre: 16 cells
    assert ring_cells(c, np.arange(c.n)).size == 0  # nothing left out, no ring


def test_the_kept_cells_are_those_predicted_within_the_bound(asm) -> None:
    """Separation ``g = x²/(2R)`` across the grid, approach field ``e = 2 µm`` everywhere, lag and
    arms giving ``θ h_max = 10 µm``: with ``trim = 0.3`` the cells with ``g − e ≤ 3 µm``, i.e.
    ``|x| ≤ √(2R · 5 µm)``, are kept."""
    R = 10.0
    x = (np.arange(41) - 20) * CELL[0]
    g = np.repeat(x**2 / (2 * R), 3)
    c = _grid(41, 3, gap=g)
    theta = 10e-3 / float(c.h.max())
    fp = Footprint(_relative_points(asm, 0.0, c), g < 2e-3, np.full(c.n, 2e-3), theta)
    (keep,) = likely_cells(asm, 0.0, [c], {(0, 0): fp}, 0.3)
    np.testing.assert_array_equal(keep, np.flatnonzero(g - 2e-3 <= 0.3 * 10e-3))
    assert 0 < keep.size < c.n
    kept = take_cells(c, keep)
    np.testing.assert_allclose(kept.local.mean(axis=0), 0.0, atol=1e-12)  # re-centred


def test_a_pair_without_contact_before_keeps_every_cell(asm) -> None:
    c = _grid(11, 3, gap=np.linspace(0.0, 5e-3, 33))
    idle = Footprint(_relative_points(asm, 0.0, c), np.zeros(c.n, bool), np.zeros(c.n), 1e-4)
    assert likely_cells(asm, 0.0, [c], {(0, 0): idle}, 0.3) == [None]
    assert likely_cells(asm, 0.0, [c], {}, 0.3) == [None]
    loaded = idle._replace(active=np.ones(c.n, bool))
    assert likely_cells(asm, 0.0, [c], {(0, 0): loaded}, 0.0) == [None]  # trim 0: all cells
