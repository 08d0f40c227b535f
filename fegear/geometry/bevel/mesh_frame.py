"""The mesh frame of a bevel or hypoid pair: where the members sit and how they turn.

Mesh frame (fixed): the pinion pitch apex at the origin, the pinion axis ``+z`` (the pinion
blank on ``+z`` of its apex), the mean pitch point ``P`` of the blank in the ``xz`` plane at
``+x`` (:meth:`~.blank.SpiralBevelBlank.pitch_point`). The gear axis passes through the gear's
pitch apex ``A2`` along ``e2`` (:meth:`~.blank.SpiralBevelBlank.gear_axis`): for intersecting
axes ``A2 = 0`` and ``e2 = (sin Σ, 0, cos Σ)`` (``+x`` for Σ = 90°); a hypoid's gear axis is
offset from the pinion axis by ``E``. The pitch cones touch at ``P``.

A member frame has its axis ``z`` and its pitch apex at the origin, the blank on ``+z``
(:mod:`.member`). The gear frame is placed by :func:`gear_frame`: its ``z`` axis on ``e2``
through ``A2`` and its ``xz`` plane through ``P``, so that a gear point at polar angle 0 and
cone distance ``Rm2`` on the pitch cone is ``P``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..surface import unit
from ..transforms import compose, rot_axis, rot_z, translation

__all__ = ["mean_point", "gear_flank_design", "gear_frame", "mesh_transforms"]

Array = NDArray[np.float64]


def mean_point(blank, i: int, theta: float) -> tuple[Array, Array, Array]:
    """Mean pitch point of member i at polar angle θ (member frame): point, generatrix
    ``e_g``, pitch normal ``e_p`` (outward of the pitch cone)."""
    g = blank.pitch_angle(i)
    rm = blank.mean_cone_distance(i)
    c, s = math.cos(theta), math.sin(theta)
    e_g = np.array([math.sin(g) * c, math.sin(g) * s, math.cos(g)])
    e_p = np.array([math.cos(g) * c, math.cos(g) * s, -math.sin(g)])
    return rm * e_g, e_g, e_p


def gear_flank_design(blank, side: str) -> tuple[Array, Array, Array, float]:
    """Gear mean point, designed outward normal, tooth trace, polar angle θ_M of one flank
    (gear member frame).

    Trace ``t = cos β2 e_g + sin β2 e_θ`` (right-hand gear); ``w = −sin β2 e_g + cos β2 e_θ``;
    normal ``n = ±cos α w + sin α e_p`` with the side's pressure angle α. The +θ flank is
    concave (the standard cutter centre, the one nearer the apex, lies on the +w side), so
    drive = +θ side, coast = −θ side.
    """
    al, be = blank.pressure_angle(side), blank.spiral_angle(2)
    sgn = 1.0 if side == "drive" else -1.0
    th = sgn * blank.half_tooth_angle(2)
    M, e_g, e_p = mean_point(blank, 2, th)
    e_th = np.array([-math.sin(th), math.cos(th), 0.0])
    t = math.cos(be) * e_g + math.sin(be) * e_th
    w = -math.sin(be) * e_g + math.cos(be) * e_th
    n = sgn * math.cos(al) * w + math.sin(al) * e_p
    return M, n, t, th


def gear_frame(blank) -> Array:
    """``(4, 4)``: gear member frame → mesh frame at ``φ2 = 0`` with the gear's polar angle 0
    in the plane of ``e2`` and ``P``: columns ``e_x = (g2 − (g2·e2) e2)/|·|`` with the gear
    generatrix ``g2 = (P − A2)/|P − A2|``, ``e_y = e2 × e_x``, ``e_z = e2``; origin ``A2``.

    For intersecting axes this is ``rot_y(Σ) rot_z(π)`` (to round-off): the gear's ``+x`` goes
    to ``(−cos Σ, 0, sin Σ)``, its ``+y`` to ``−y``.
    """
    A2, e2 = blank.gear_axis()
    g2 = unit(blank.pitch_point() - A2)
    ex = unit(g2 - np.dot(g2, e2) * e2)
    M = np.eye(4)
    M[:3, 0], M[:3, 1], M[:3, 2], M[:3, 3] = ex, np.cross(e2, ex), e2, A2
    return M


def mesh_transforms(blank, side: str, theta_gear: float, delta_pinion: float, sigma: float):
    """Functions ``φ -> 4×4`` placing pinion and gear in the mesh frame (driving-sense angles),
    and the gear axis ``e2``.

    At ``φ1 = φ2 = 0`` the mean contact point of ``side`` is at ``P``: the gear flank's mean
    point (polar angle ``theta_gear`` in the gear frame) turned to polar angle 0, the pinion
    flank's (``delta_pinion``) likewise. The pinion turns about ``σ e_z``, the gear about
    ``−σ e2`` through ``A2`` (so that the pitch cones roll).
    """
    A2, e2 = blank.gear_axis()
    G0 = compose(gear_frame(blank), rot_z(-theta_gear))
    P0 = rot_z(-delta_pinion)
    to_apex, from_apex = translation(A2), translation(-A2)

    def pinion(phi1: float | Array) -> Array:
        return compose(rot_z(sigma * np.asarray(phi1)), P0)

    def gear(phi2: float | Array) -> Array:
        return compose(to_apex, rot_axis(-sigma * e2, np.asarray(phi2)), from_apex, G0)

    return pinion, gear, e2
