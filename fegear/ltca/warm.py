"""Warm start of the contact solver from a neighbouring solution (same position on a finer grid,
or the previous mesh position).

The active-set solver (:func:`fegear.contact.solve_contact`) needs about as many factorisations
as it takes to grow the active set from one cell to the patch (measured on the seed face gear,
``hybrid`` level 0: 9 per solve). The patch of a pair moves little between two solves: on a
refined grid of the same position it stays where it was, and from one mesh position to the next
it rolls along the flank with the pair's TCA contact point. So the cells of the new grid take
the contact state of the nearest cell of the previous one, in the pinion tooth's own frame,
relative to the pair's TCA contact point (:attr:`~fegear.ltca.grid.PairCells.origin`). That is
only a guess: the solver's result does not depend on it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np
from scipy.spatial import cKDTree

from fegear.assembly import Assembly, tooth_transform
from fegear.geometry.transforms import apply_points, compose, inverse
from fegear.ltca.grid import PairCells

__all__ = ["Footprint", "footprint", "active_guess"]


class Footprint(NamedTuple):
    """Contact state of one pair's cells: ``points (n, 3)`` mm in the pinion tooth frame
    relative to the pair's TCA contact point, ``active (n,)`` bool."""

    points: np.ndarray
    active: np.ndarray


def _relative_points(asm: Assembly, phi1: float, c: PairCells) -> np.ndarray:
    Minv = inverse(compose(asm.placement1(phi1), tooth_transform(asm.n1, c.k)))
    origin = c.origin if c.origin is not None else c.centers.mean(axis=0)
    return apply_points(Minv, c.centers) - apply_points(Minv, origin)


def footprint(
    asm: Assembly, phi1: float, cells: Sequence[PairCells], active: np.ndarray
) -> dict[tuple[int, int], Footprint]:
    """Footprints of the pairs of one solution (``active``: the solver's mask over all cells)."""
    out, start = {}, 0
    for c in cells:
        out[(c.k, c.j)] = Footprint(
            _relative_points(asm, phi1, c), np.asarray(active[start : start + c.n], dtype=bool)
        )
        start += c.n
    return out


def active_guess(
    asm: Assembly,
    phi1: float,
    cells: Sequence[PairCells],
    previous: Mapping[tuple[int, int], Footprint],
) -> np.ndarray:
    """Guessed contact state ``(Σ n,)`` of ``cells`` at ``phi1``: the state of the nearest cell
    of the same pair in ``previous`` (False for a pair that had no cells or no contact)."""
    parts = []
    for c in cells:
        fp = previous.get((c.k, c.j))
        if fp is None or not fp.active.any():
            parts.append(np.zeros(c.n, dtype=bool))
            continue
        idx = cKDTree(fp.points).query(_relative_points(asm, phi1, c))[1]
        parts.append(fp.active[idx])
    return np.concatenate(parts) if parts else np.zeros(0, dtype=bool)
