"""The head cutter of a face-milling machine: blade surfaces of revolution and edge radii.

A face-milling head cutter carries blades on a circle; each blade sweeps, as the cutter turns, a
surface of revolution about the cutter axis (Litvin & Fuentes, *Gear Geometry and Applied
Theory*, 2nd ed., 2004, §21.2): a cone for a straight blade, a parabolic profile for a
profile-crowned pinion blade (§21.5), and at its end the torus of the edge radius that cuts the
fillet. The tool frame has its axis ``z_t`` along the cutter axis; where it sits on the cradle
is the machine's business (:mod:`.machine`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import DesignError
from ..generation import ToolSample, tool_sample

__all__ = ["HeadCutter", "EdgeRadius", "blade_tip"]

Array = NDArray[np.float64]


def _revolution_sample(prof: tuple[Array, ...], theta: Array, sg: float) -> ToolSample:
    """Tool sample of the surface of revolution ``(ρ(w) cos θ, ρ(w) sin θ, z(w))`` from its
    profile ``prof = (ρ, z, ρ', z', ρ'', z'')`` (w-derivatives); normal ``sg (r_w × r_θ)/|·|``."""
    rho, z, rho1, z1, rho2, z2 = prof
    c, si = np.cos(theta), np.sin(theta)
    zero = np.zeros_like(rho)
    r = np.stack([rho * c, rho * si, z], -1)
    r_s = np.stack([rho1 * c, rho1 * si, z1], -1)
    r_t = np.stack([-rho * si, rho * c, zero], -1)
    r_ss = np.stack([rho2 * c, rho2 * si, z2], -1)
    r_st = np.stack([-rho1 * si, rho1 * c, zero], -1)
    r_tt = np.stack([-rho * c, -rho * si, zero], -1)
    return tool_sample(r, r_s, r_t, r_ss, r_st, r_tt, sg)


@dataclass(frozen=True)
class HeadCutter:
    """Blade surface of revolution of a head cutter, tool frame (axis z_t, origin at z_ref).

    Profile in the axial half-plane (ρ, z): ``P(s) = (r_c, 0) + s d − a_c s² n`` with the unit
    blade direction ``d = (±sin α, cos α)`` (+ outside blade) and the unit normal
    ``n = (∓cos α, sin α)`` pointing into the blade (out of the cut tooth); s (mm) runs from the
    mean-point height towards the cutter head (towards the tooth tip). Surface
    ``r_t(s, θ) = (ρ cos θ, ρ sin θ, z)`` (Litvin & Fuentes 2004 §21.2; parabolic blade §21.5).
    The blade ends at its edge radius (:class:`EdgeRadius`, :func:`blade_tip`); this surface is
    the blade only, continued past that end (the envelope engine needs no limits).
    """

    radius: float
    blade_angle: float
    outside: bool
    parabola: float = 0.0

    @property
    def sign(self) -> float:
        """+1 outside blade, −1 inside blade."""
        return 1.0 if self.outside else -1.0

    def profile(self, s: Array) -> tuple[Array, ...]:
        """``(ρ, z, ρ', z', ρ'', z'')`` of the blade profile at ``s`` (mm; derivatives in s)."""
        s = np.asarray(s, float)
        sa, ca = math.sin(self.blade_angle), math.cos(self.blade_angle)
        sg = self.sign
        d_r, d_z = sg * sa, ca
        n_r, n_z = -sg * ca, sa
        a = self.parabola
        rho = self.radius + s * d_r - a * s**2 * n_r
        z = s * d_z - a * s**2 * n_z
        rho1 = d_r - 2 * a * s * n_r
        z1 = d_z - 2 * a * s * n_z
        rho2 = np.full_like(s, -2 * a * n_r)
        z2 = np.full_like(s, -2 * a * n_z)
        return rho, z, rho1, z1, rho2, z2

    def evaluate(self, u: Array, theta: Array) -> ToolSample:
        s, th = np.broadcast_arrays(np.asarray(u, float), np.asarray(theta, float))
        return _revolution_sample(self.profile(s), th, self.sign)


@dataclass(frozen=True)
class EdgeRadius:
    """The edge radius (tip radius) of a head-cutter blade: a torus, tool frame.

    Profile in the axial half-plane: the arc of radius ``ρ_f`` about the centre ``(ρ_c, z_c)``,

    .. math::  P(\\vartheta) = (\\rho_c + \\sigma \\rho_f \\sin\\vartheta,\\;
               z_c - \\rho_f \\cos\\vartheta), \\qquad 0 \\le \\vartheta \\le \\vartheta_b,

    ``σ = +1`` outside blade, ``−1`` inside; unit normal into the tool (out of the cut tooth)
    ``N(ϑ) = (−σ sin ϑ, cos ϑ)``, pointing at the centre. At ``ϑ = 0`` the arc touches the
    cutter's *point plane* ``z = z_c − ρ_f`` (normal along the cutter axis: it cuts the root
    cone); at ``ϑ_b`` it touches the blade at ``s_b`` with the blade's normal (for a straight
    blade ``ϑ_b = 90° − α``): the tool is G1 across both joins (Litvin & Fuentes 2004 §21.2,
    "blade with a fillet"; Litvin & Zhang, NASA CR-4342, 1991, §2; Gleason's edge radius).
    Surface ``r_t(ϑ, θ) = (ρ cos θ, ρ sin θ, z)``; the envelope of it under the blade's
    generating motion is the fillet of the flank the blade cuts.
    """

    centre_radius: float
    centre_z: float
    edge_radius: float
    outside: bool
    theta_blade: float
    s_blade: float

    @property
    def sign(self) -> float:
        return 1.0 if self.outside else -1.0

    @property
    def point_z(self) -> float:
        """``z_t`` of the point plane (the lowest point of the blade), mm."""
        return self.centre_z - self.edge_radius

    def profile(self, w: Array) -> tuple[Array, ...]:
        """``(ρ, z, ρ', z', ρ'', z'')`` of the arc at ``ϑ = w`` (rad; derivatives in ϑ)."""
        w = np.asarray(w, float)
        sg, rf = self.sign, self.edge_radius
        sw, cw = np.sin(w), np.cos(w)
        return (
            self.centre_radius + sg * rf * sw,
            self.centre_z - rf * cw,
            sg * rf * cw,
            rf * sw,
            -sg * rf * sw,
            rf * cw,
        )

    def evaluate(self, u: Array, theta: Array) -> ToolSample:
        w, th = np.broadcast_arrays(np.asarray(u, float), np.asarray(theta, float))
        return _revolution_sample(self.profile(w), th, self.sign)


def blade_tip(cutter: HeadCutter, edge_radius: float, point_z: float) -> EdgeRadius:
    """The edge radius ``ρ_f`` of ``cutter``'s blade that touches the point plane ``z = point_z``.

    The centre of the arc lies ``ρ_f`` inside the blade along its unit profile normal
    ``N(s) = σ(−z', ρ')/|(ρ', z')|`` and ``ρ_f`` above the point plane:
    ``z(s_b) + ρ_f N_z(s_b) = point_z + ρ_f``. For a straight blade
    ``s_b = (point_z + ρ_f (1 − sin α)) / cos α``; for a parabolic blade Newton from there
    (``d/ds (z + ρ_f N_z)`` by the curvature of the profile). ``ϑ_b`` from
    ``N(ϑ_b) = N(s_b)``: ``sin ϑ_b = z'/|·|``, ``cos ϑ_b = σ ρ'/|·|``.

    Raises :class:`~fegear.errors.DesignError` if the blade does not descend to the point plane
    (a blade that turns over before it reaches it).
    """
    sa, ca = math.sin(cutter.blade_angle), math.cos(cutter.blade_angle)
    sg, rf = cutter.sign, float(edge_radius)
    s = (point_z + rf * (1.0 - sa)) / ca

    def centre(s: float) -> tuple[float, float, float, float]:
        rho, z, rho1, z1, _, _ = (float(x) for x in cutter.profile(np.array(s)))
        wn = math.hypot(rho1, z1)
        return rho + rf * (-sg * z1 / wn), z + rf * (sg * rho1 / wn), rho1 / wn, z1 / wn

    for _ in range(50):
        f = centre(s)[1] - (point_z + rf)
        h = 1e-6
        fp = (centre(s + h)[1] - centre(s - h)[1]) / (2 * h)
        if not fp > 0:
            raise DesignError(
                "spiral_bevel.edge_radius_mm", rf, "an edge radius the blade can carry",
                "the blade does not descend to the point plane",
            )  # fmt: skip
        ds = f / fp
        s -= ds
        if abs(ds) < 1e-14 * max(1.0, abs(s)):
            break
    rc, zc, t_r, t_z = centre(s)
    theta_b = math.atan2(t_z, sg * t_r)
    if not 0.0 < theta_b < math.pi:
        raise DesignError(
            "spiral_bevel.edge_radius_mm", rf, "an edge radius the blade can carry",
            f"blade direction at its tip turns away from the point plane (ϑ_b {theta_b:.3f})",
        )  # fmt: skip
    return EdgeRadius(rc, zc, rf, cutter.outside, float(theta_b), float(s))
