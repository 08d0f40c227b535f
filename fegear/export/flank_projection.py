"""Closest points on a member's exact working flank: where a deck puts the mid-edge nodes of its
flank faces (:func:`fegear.export.inp.tet10_body`, ``project``).

A C3D10 face with its mid-edge nodes at the chord midpoints lies inside a convex flank by up to
``h² / (8 R)`` (``h`` the element size, ``R`` the flank's radius of curvature): 2.5 µm for
``h`` = 0.5 mm on the 12 mm profile radius of the FZG pinion at its pitch point, a quarter of the
elastic approach there, and as much as the separation that decides whether a second pair carries
load. On the exact surface the quadratic face follows it to ``O(h³)``.

The closest points are those of :func:`fegear.mesh.sector_geometry.flank_distance` (Gauss-Newton
on the exact flank from the nearest of a sample grid) on the member itself: a member with flank
modifications (crowning, reliefs) is meshed as its unmodified solid
(:func:`fegear.mesh.sector.sector_mesh`), and its flank nodes moved onto the modified flank put
the modification, some µm, into the deck.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from fegear.mesh.sector_geometry import flank_distance, sector_frame

__all__ = ["flank_projection"]

Array = NDArray[np.float64]
#: points per closest-point batch (the nearest-sample search holds batch × n_grid² distances)
_BATCH = 2000


def flank_projection(
    member, side: str, tooth: int, rim_modules: float = 3.0
) -> Callable[[Array], Array]:
    """``f(points (q, 3)) -> (q, 3)``: closest points on the working ``side`` flank (with its
    modifications) of member tooth ``tooth`` (member frame, mm)."""
    fr = sector_frame(member, rim_modules)

    def project(x: Array) -> Array:
        x = np.asarray(x, dtype=float)
        out = np.empty_like(x)
        for s in range(0, len(x), _BATCH):
            _, ab = flank_distance(fr, side, tooth, x[s : s + _BATCH])
            out[s : s + _BATCH] = fr.tooth_points(side, tooth, ab[:, 0], ab[:, 1])
        return out

    return project
