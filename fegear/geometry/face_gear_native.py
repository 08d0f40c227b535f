"""The face-gear flank in its shaper parameters: closest-point searches with exact tangents.

The generated surface is ``p(t, u_s)`` (shaper roll ``t``, shaper axial position ``u_s``; the
engine's envelope, :meth:`~fegear.geometry.face_gear.FaceGearMember.envelope`), with exact
tangents ``∂p/∂t``, ``∂p/∂u_s`` from the implicit-function theorem on the equation of meshing
(:mod:`fegear.geometry.generation`). One evaluation is one envelope; an evaluation at flank
coordinates ``(u, v)`` is a 2-D Newton of envelopes (the height ``z(u, L)`` and radius ``L``,
:meth:`~fegear.geometry.face_gear.FaceGearMember.point_normal`), and its tangents by finite
differences cost two more. A closest-point search (the distance of a meshed or CAD flank to the
exact one, :func:`fegear.mesh.sector_geometry.flank_distance`) therefore runs in ``(t, u_s)``,
where the parameters extend past the flank limits onto the generated surface itself (not onto
the fillet), as they do for the spiral bevel's :class:`~fegear.geometry.bevel.native.NativeFlank`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .surface import Side

if TYPE_CHECKING:
    from .face_gear import FaceGearMember

__all__ = ["FaceGearNativeFlank"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class FaceGearNativeFlank:
    """Exact evaluator of one face-gear flank in the shaper parameters ``(t, u_s)``
    (:class:`~fegear.geometry.surface.NativeFlankEvaluator`); build with
    :meth:`~fegear.geometry.face_gear.FaceGearMember.native_flank`."""

    member: FaceGearMember
    side: Side

    def native(self, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Shaper parameters ``(t, u_s)`` of the working-flank points at flank coordinates
        ``(u, v)`` (``u >= 0``; the 2-D Newton of ``point_normal``, to 1e-12 mm)."""
        m = self.member
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        _, t, us = m._solve(self.side, m.height(u, v, self.side), v)
        return np.asarray(t, float), np.asarray(us, float)

    def evaluate(self, a: ArrayLike, b: ArrayLike, tangents: bool = False) -> tuple[Array, ...]:
        """Points ``(..., 3)`` mm and outward unit normals at shaper parameters ``(t, u_s) =
        (a, b)``; with ``tangents`` also ``∂p/∂t`` and ``∂p/∂u_s`` (mm per unit)."""
        env = self.member.envelope(self.side, a, b)
        if tangents:
            return env.points, env.normals, env.r_u, env.r_t
        return env.points, env.normals
