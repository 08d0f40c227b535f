"""Machine settings of a cradle-type face-milling generator and the motion they make.

Generating machine (one per flank: "fixed setting" for every flank, see :class:`MachineSettings`)
-------------------------------------------------------------------------------------------------
Machine frame S_m: ``z_m`` = cradle axis, the cradle plane ``z_m = 0`` holds the machine centre.
The blank (member frame, axis z, apex at origin) is placed by::

    B(ψ) = T(0, E_m, X_B) · rot_y(π/2 + γ_m) · T(0, 0, X_D) · rot_z(φ0 + φ(ψ)),
    φ(ψ) = −m_c (ψ − C ψ²/2 − D ψ³/6)                 (modified roll, Litvin 2004 §21.4)

so that with ``E_m = X_B = X_D = 0`` the root cone touches the cradle plane along ``+x_m`` and the
pitch generatrix lies along ``(cos δ_f, 0, sin δ_f)``. The head cutter rides on the cradle::

    T_c(ψ) = rot_z(ψ) · T(S_r cos q, S_r sin q, z_ref) · rot_z(θ_0)

and the tool → blank motion of the envelope engine is ``M(ψ) = B(ψ)⁻¹ T_c(ψ)``
(:mod:`fegear.geometry.generation`). The nominal ratio of roll ``m_c = cos δ_f / sin γ`` rolls the
blank pitch cone on the generating crown gear's pitch cone (semi-angle 90° − δ_f) without slip, so
the instantaneous axis passes through the mean point: ``v = 0`` there and the equation of meshing
holds for any tool normal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ...errors import DesignError, InputError
from ..generation import Fixed, Motion, Rotation
from ..transforms import apply_points, apply_vectors, compose, rot_y, rot_z, translation
from .cutter import HeadCutter

__all__ = [
    "MachineSettings",
    "SpiralBevelSettings",
    "head_cutter",
    "point_plane",
    "blank_placement",
    "machine_motion",
    "fit_cutter",
    "mirrored",
]

Array = NDArray[np.float64]


# --------------------------------------------------------------------------------------------
# machine settings and tool
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class MachineSettings:
    """Head cutter and cradle settings that generate ONE flank (angles in degrees, lengths mm).

    Every flank has its own settings (fixed-setting method); a gear cut by a spread-blade cutter
    would share the cradle settings of both sides — here each gear side is synthesized to have
    exactly the design spiral and pressure angle at its own mean point. Override any field with
    :func:`dataclasses.replace`; the surfaces are generated from these fields only.

    Attributes
    ----------
    member, side
        ``"pinion"|"gear"`` and ``"drive"|"coast"``.
    blade
        ``"outside"`` (cuts a concave flank) or ``"inside"`` (convex flank).
    cutter_radius_mm
        Blade radius at the reference height ``z_ref`` (the mean point's height).
    blade_angle_deg
        Angle of the blade to the cutter axis (= tool pressure angle).
    point_radius_mm
        Blade radius in the cradle plane z_m = 0 (≈ at the root; derived, for reports).
    parabola_per_mm
        Parabolic blade coefficient a_c (0: straight blade).
    edge_radius_mm
        Blade edge radius ρ_f (> 0): the arc tangent to the blade and to the point plane that
        generates the fillet (:class:`EdgeRadius`; the point plane is where the cutter cuts the
        blank's root cone, :func:`point_plane`).
    radial_setting_mm, cradle_angle_deg
        Cutter centre on the cradle, polar (S_r, q) in the machine frame at ψ = 0.
    ref_height_mm
        z_m of the tool reference plane (mean-point height).
    tool_phase_deg
        Cutter angular parameter origin (θ = 0 passes through the mean point); no effect on the
        surface.
    machine_root_angle_deg
        γ_m, blank axis inclination to the cradle plane.
    blank_offset_mm, sliding_base_mm, machine_center_to_back_mm
        E_m, X_B, X_D of the blank placement (module doc).
    blank_phase_deg
        φ0, rotation of the blank about its axis at ψ = 0.
    ratio_of_roll
        m_c = ω_blank/ω_cradle.
    modified_roll, modified_roll_third
        C and D of the modified roll ``φ(ψ) = −m_c(ψ − Cψ²/2 − Dψ³/6)`` (1/rad, 1/rad²). C is
        fixed by the local synthesis (it enters the pinion curvature at the mean point); D
        (third order, no effect on the curvature at M) is tuned so the TE parabola is symmetric
        over the cycle (:meth:`~fegear.geometry.bevel.pair.SpiralBevelPair.design`).
    point_plane_mm
        ``z_t`` (tool frame) of the cutter's point plane, the plane of the blade tips that the
        edge radius touches. None (synthesized settings): where the machine plane touches the
        blank's root cone at the mean cone distance (:func:`point_plane`). A number (settings
        as a summary sheet gives them: the blade tips in the cradle plane, ``−ref_height_mm``):
        the settings decide the tooth depth, and the member's root cone is the one the point
        plane sweeps (:meth:`~fegear.geometry.bevel.member.SpiralBevelMember.root_cone_line`).
    """

    member: str
    side: str
    blade: str
    cutter_radius_mm: float
    blade_angle_deg: float
    point_radius_mm: float
    parabola_per_mm: float
    edge_radius_mm: float
    radial_setting_mm: float
    cradle_angle_deg: float
    ref_height_mm: float
    tool_phase_deg: float
    machine_root_angle_deg: float
    blank_offset_mm: float
    sliding_base_mm: float
    machine_center_to_back_mm: float
    blank_phase_deg: float
    ratio_of_roll: float
    modified_roll: float
    modified_roll_third: float = 0.0
    point_plane_mm: float | None = None

    def __post_init__(self) -> None:
        if self.blade not in ("outside", "inside"):
            raise InputError("machine_settings.blade", self.blade, "'outside' or 'inside'")
        if not self.cutter_radius_mm > 0:
            raise InputError("machine_settings.cutter_radius_mm", self.cutter_radius_mm, "> 0")
        if not 0 < self.blade_angle_deg < 60:
            raise InputError("machine_settings.blade_angle_deg", self.blade_angle_deg, "in (0, 60)")
        if not self.ratio_of_roll > 0:
            raise InputError("machine_settings.ratio_of_roll", self.ratio_of_roll, "> 0")
        if not (np.isfinite(self.edge_radius_mm) and self.edge_radius_mm > 0):
            raise InputError("machine_settings.edge_radius_mm", self.edge_radius_mm, "> 0")


@dataclass(frozen=True)
class SpiralBevelSettings:
    """The four flank settings of a pair."""

    gear_drive: MachineSettings
    gear_coast: MachineSettings
    pinion_drive: MachineSettings
    pinion_coast: MachineSettings

    def get(self, member: str, side: str) -> MachineSettings:
        return getattr(self, f"{member}_{side}")


def head_cutter(ms: MachineSettings) -> HeadCutter:
    return HeadCutter(
        radius=ms.cutter_radius_mm,
        blade_angle=math.radians(ms.blade_angle_deg),
        outside=ms.blade == "outside",
        parabola=ms.parabola_per_mm,
    )


def point_plane(blank, i: int, ms: MachineSettings) -> float:
    """``z_t`` (tool frame, mm) of the cutter's point plane for member i: the plane
    ``z_m = const`` of the machine that touches the blank's root cone at the mean cone distance.

    The point plane is normal to the cutter (and cradle) axis; under the generating motion it
    turns in itself with the cradle and sweeps, with the blank's rotation about its own axis, a
    cone coaxial with the blank whose semi-angle is the machine root angle γ_m. Touching the
    root circle at ``L = R_m`` (``h_R = −b_m``, the mean dedendum; its extreme ``z_m``,
    ``c_z + ρ_R |(a_z, b_z)|`` with centre ``c`` and in-plane axes ``a``, ``b`` of the circle in
    the machine frame at ψ = 0) this cone IS the root cone when ``γ_m = γ − δ_f`` (the
    synthesized settings: the root cone touches the cradle plane ``z_m = 0`` along a
    generatrix, so the plane is ``z_m = 0``), and it cuts the root cone depth at the mean point
    otherwise. In the tool frame (origin at ``z_ref``): ``z_t = z_m − z_ref``. The depth of the
    mean point above it along the cutter axis is ``R_m sin δ_f = b_m cos δ_f`` (tested).
    """
    g = blank.pitch_angle(i)
    L = blank.mean_cone_distance(i)
    h = float(blank.root_height(i, L))
    rho = L * math.sin(g) + h * math.cos(g)
    z = L * math.cos(g) - h * math.sin(g)
    B = blank_placement(ms)
    c = B[:3, :3] @ np.array([0.0, 0.0, z]) + B[:3, 3]
    top = c[2] + rho * math.hypot(B[2, 0], B[2, 1])
    return float(top - ms.ref_height_mm)


def blank_placement(ms: MachineSettings) -> Array:
    """Blank (member) frame → machine frame at ψ = 0 (4×4)."""
    return compose(
        translation([0.0, ms.blank_offset_mm, ms.sliding_base_mm]),
        rot_y(math.pi / 2 + math.radians(ms.machine_root_angle_deg)),
        translation([0.0, 0.0, ms.machine_center_to_back_mm]),
        rot_z(math.radians(ms.blank_phase_deg)),
    )


def machine_motion(ms: MachineSettings) -> Motion:
    """Tool → blank generating motion ``M(ψ) = B(ψ)⁻¹ T_c(ψ)`` (module doc)."""
    gm = math.radians(ms.machine_root_angle_deg)
    q = math.radians(ms.cradle_angle_deg)
    m, C, D = ms.ratio_of_roll, ms.modified_roll, ms.modified_roll_third
    phi0 = math.radians(ms.blank_phase_deg)
    return Motion(
        (
            Rotation("z", (-phi0, m, -0.5 * m * C, -m * D / 6.0)),
            Fixed(translation([0.0, 0.0, -ms.machine_center_to_back_mm])),
            Fixed(rot_y(-(math.pi / 2 + gm))),
            Fixed(translation([0.0, -ms.blank_offset_mm, -ms.sliding_base_mm])),
            Rotation("z", (0.0, 1.0)),
            Fixed(
                compose(
                    translation(
                        [
                            ms.radial_setting_mm * math.cos(q),
                            ms.radial_setting_mm * math.sin(q),
                            ms.ref_height_mm,
                        ]
                    ),
                    rot_z(math.radians(ms.tool_phase_deg)),
                )
            ),
        )
    )


def fit_cutter(
    member: str,
    side: str,
    blade: str,
    point: Array,
    normal: Array,
    cutter_radius: float,
    parabola: float,
    machine_root_angle: float,
    blank_phase: float,
    ratio_of_roll: float,
    modified_roll: float = 0.0,
    blank_offset: float = 0.0,
    *,
    edge_radius: float,
) -> MachineSettings:
    """Settings whose cutter passes through ``point`` with outward tooth normal ``normal``
    (blade edge radius ``edge_radius``, mm).

    A surface of revolution has its normals meeting its axis; the cutter axis is parallel to the
    cradle axis, so it lies on the normal line ``M + t n`` at horizontal distance r_c: the blade
    angle is ``asin(n_z)`` (machine frame), the cutter centre ``M_h ± r_c n_h/|n_h|`` (+ outside
    blade, normal pointing towards the axis).
    """
    ms0 = MachineSettings(
        member, side, blade, cutter_radius, 20.0, cutter_radius, parabola, edge_radius, 0.0, 0.0,
        0.0, 0.0, math.degrees(machine_root_angle), blank_offset, 0.0, 0.0,
        math.degrees(blank_phase), ratio_of_roll, modified_roll,
    )  # fmt: skip
    B = blank_placement(ms0)
    P = apply_points(B, point)
    n = apply_vectors(B, normal)
    nh = np.array([n[0], n[1]])
    if n[2] <= 0 or np.linalg.norm(nh) < 1e-9:
        raise DesignError(
            f"spiral_bevel.{member}.{side}", float(n[2]), "a tooth normal facing the cutter"
        )
    alpha = math.asin(min(1.0, n[2]))
    eh = nh / np.linalg.norm(nh)
    sg = 1.0 if blade == "outside" else -1.0
    centre = P[:2] + sg * cutter_radius * eh
    phase = math.atan2(P[1] - centre[1], P[0] - centre[0])
    # blade radius in the cradle plane z_m = 0 (straight part), for reports
    rp = cutter_radius - sg * P[2] * math.tan(alpha)
    return MachineSettings(
        member=member,
        side=side,
        blade=blade,
        cutter_radius_mm=float(cutter_radius),
        blade_angle_deg=math.degrees(alpha),
        point_radius_mm=float(rp),
        parabola_per_mm=float(parabola),
        edge_radius_mm=float(edge_radius),
        radial_setting_mm=float(np.hypot(*centre)),
        cradle_angle_deg=math.degrees(math.atan2(centre[1], centre[0])),
        ref_height_mm=float(P[2]),
        tool_phase_deg=math.degrees(phase),
        machine_root_angle_deg=math.degrees(machine_root_angle),
        blank_offset_mm=float(blank_offset),
        sliding_base_mm=0.0,
        machine_center_to_back_mm=0.0,
        blank_phase_deg=math.degrees(blank_phase),
        ratio_of_roll=float(ratio_of_roll),
        modified_roll=float(modified_roll),
    )


def mirrored(ms: MachineSettings) -> MachineSettings:
    """The settings that cut the mirror image (``y → −y`` in the member frame) of the flank
    ``ms`` cuts: the other hand.

    The reflection ``Y = diag(1, −1, 1)`` of the machine frame maps the cradle chain of
    :func:`machine_motion` onto itself with ``rot_z(a) → rot_z(−a)`` and ``y`` offsets negated;
    the head cutter, a surface of revolution, is its own mirror image (``θ → −θ``). With the
    cradle angle ``ψ → −ψ`` the roll ``−φ(−ψ) = −m (ψ + C ψ²/2 − D ψ³/6)``: so ``q → −q``,
    ``E_m → −E_m``, ``φ0 → −φ0``, ``θ0 → −θ0``, ``C → −C``; the rest is unchanged.
    """
    return replace(
        ms,
        cradle_angle_deg=-ms.cradle_angle_deg,
        blank_offset_mm=-ms.blank_offset_mm,
        blank_phase_deg=-ms.blank_phase_deg,
        tool_phase_deg=-ms.tool_phase_deg,
        modified_roll=-ms.modified_roll,
    )
