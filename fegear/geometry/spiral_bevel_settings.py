"""Spiral bevel blank data, head-cutter / cradle machine settings, and their local synthesis.

Face-milled spiral bevel gears (Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed.,
2004, ch. 21; Litvin & Zhang, NASA CR-4342, 1991; Argyris, Fuentes & Litvin, CMAME 191 (2002)
1057–1095). Nobody types machine settings: :func:`synthesize` computes them from the blank
(:class:`SpiralBevelBlank`) and the design targets (:class:`SynthesisTargets`).

Blank (Gleason standard proportions, AGMA 2005 / Gleason spiral bevel system, standard taper)
-------------------------------------------------------------------------------------------
With outer transverse module ``m``, ``N1 < N2``, shaft angle Σ::

    tan γ1 = sin Σ / (N2/N1 + cos Σ),  γ2 = Σ − γ1          pitch cone angles
    A0 = m N2 / (2 sin γ2),  Rm = A0 − F/2                  outer / mean cone distance
    h_k = 1.700 m,  c = 0.125 h_k + 0.051 mm,  h_t = h_k + c  working / whole depth, clearance
    a2 = h_k (0.210 + 0.290 (N1/N2)²),  a1 = h_k − a2       addenda at the heel
    b_i = h_t − a_i,  δ_fi = atan(b_i / A0)                  dedenda, dedendum angles
    γ_Ri = γ_i − δ_fi,  γ_ai = γ_i + δ_fj                    root / face angles (parallel clearance)
    t2 = p/2 − (a1 − a2) tan α / cos β,  t1 = p − t2         heel circular thicknesses, p = π m

Flank coordinates of a point ``p`` of member ``i`` (axial plane, pitch angle γ)::

    L = z cos γ + ρ sin γ      cone distance (projection on the pitch generatrix), ρ = √(x²+y²)
    h = ρ cos γ − z sin γ      height above the pitch cone (normal to the generatrix)

The flank runs from the toe ``L = A0 − F`` to the heel ``L = A0`` (back/front cones normal to the
pitch cone) and from the root cone ``h_R(L) = −b_i + (A0 − L) tan δ_fi`` (through the apex) up the
generated fillet to the fillet limit (where the blade meets its edge radius, a curve over the face:
:meth:`~fegear.geometry.spiral_bevel.SpiralBevelMember.fillet_height`) and on to the face cone
``h_a(L) = a_i − (A0 − L) tan δ_fj``. The mate's face cone reaches down to the working depth
``h_w(L) = −a_j + (A0 − L) tan δ_fi`` (the clearance ``c`` above the root cone): the lowest point
that can be in contact in the nominal mesh (:meth:`SpiralBevelBlank.flank_heights`).

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

Local synthesis of the pinion (Litvin & Zhang 1991; Litvin & Fuentes 2004 §9.6, §21.6)
------------------------------------------------------------------------------------
At the mean contact point M (on the common pitch generatrix, so the relative velocity
``v^(12) = 0``) with common unit normal ``n`` (out of the gear tooth), pinion ``ω1 = σ e1``
(|ω1| = 1), gear ``ω2 = σ m21 e2``, ``m21 = N1/N2``, ``ṁ21 = m'21`` (per rad of pinion), the
shape operators ``S_i`` of both surfaces w.r.t. ``n`` (``dn = S_i dr`` on surface i) satisfy
(differentiating the contact conditions along the path, Litvin 2004 eqs. 9.4.x rewritten)::

    (S2 − S1) v_r2 = ω12 × n                                    (tangency of the normals)
    n · (ω12 × v_r2) = −[n · (ω̇12 × M) + n · (ω12 × (ω2 × M))]    (meshing, differentiated)

with ``ω12 = ω1 − ω2`` and ``ω̇12 = −m'21 σ e2``. Choosing the path direction ``t`` on the gear
(angle η from the tooth trace towards the tip) gives ``v_r2 = λ t`` from the second equation; the
first gives ``A t = (ω12 × n)/λ`` for the relative curvature ``A = S2 − S1`` (the separation is
``½ xᵀ A x``); the third entry of ``A`` follows from the contact ellipse: its major semi-axis
``a`` at elastic approach (paint thickness) δ needs ``λ_min(A) = 2δ/a²``. Predesigned parabolic TE
``Δφ2 = ½ m'21 φ1²``: amplitude Δ over the cycle ``φ1 ∈ [−π/N1, π/N1]`` gives
``m'21 = −2Δ (N1/π)²`` (gear lags at the transfer points).

The pinion settings are then found numerically (instead of Litvin's closed-form curvature
relations, which are error-prone to transcribe): with the cutter refitted through M with normal
``−n`` (which fixes blade angle, radial setting, cradle angle), solve
``[f(M) = 0, S_pinion(M) = A − S2]`` (4 equations) for the pinion cutter radius ``r_c1``
(lengthwise crowning), ratio of roll ``m_c1``, modified-roll coefficient ``C`` and blank offset
``E_m1``; the pinion curvatures come from the generation engine (implicit-function theorem).
Because the cutter is refitted through M, a sliding base X_B (a shift along the cradle axis)
would move blank and cutter together and change nothing; the blank offset E_m1 is the placement
setting that moves the instantaneous axis off M, so it is the one solved for (X_B = X_D = 0).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import fsolve

from ..errors import DesignError, InputError, SolverError
from .generation import Fixed, Motion, Rotation, ToolSample, generate, tool_sample
from .surface import unit
from .transforms import apply_points, apply_vectors, compose, rot_axis, rot_y, rot_z, translation

__all__ = [
    "SpiralBevelBlank",
    "SynthesisTargets",
    "MachineSettings",
    "SpiralBevelSettings",
    "SynthesisReport",
    "HeadCutter",
    "EdgeRadius",
    "blade_tip",
    "point_plane",
    "machine_motion",
    "synthesize",
    "mean_point",
    "mesh_transforms",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]
Side = Literal["drive", "coast"]
ARCSEC = math.pi / (180.0 * 3600.0)
#: default blade edge radius in modules: the ISO 53 basic rack profile C tip radius 0.25 m
EDGE_RADIUS_MODULES = 0.25


# --------------------------------------------------------------------------------------------
# blank
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SpiralBevelBlank:
    """Blank data of a spiral bevel pair and derived Gleason proportions (see module doc).

    Parameters
    ----------
    n1, n2
        Tooth numbers of pinion (member 1) and gear (member 2), ``5 <= n1 <= n2``.
    module_mm
        Outer (heel) transverse module (mm); 4.94 mm = 5.14 diametral pitch.
    spiral_angle_deg
        Mean spiral angle β, in [0, 50]. The gear is right-hand (trace turns towards +θ going
        toe → heel, i.e. clockwise seen from the front), the pinion left-hand.
    pressure_angle_deg
        Normal pressure angle α at the mean point, both flanks, in [10, 30].
    face_width_mm
        Face width F along the pitch generatrix, ``0 < F <= A0/2.5`` (Gleason: F ≤ A0/3; a
        little slack is allowed).
    shaft_angle_deg
        Shaft angle Σ in (0, 180).
    cutter_radius_mm
        Nominal gear head-cutter radius (mean radius of the blade at the mean point). Default
        76.2 mm: the standard 6-inch-diameter Gleason cutter for this size (Gleason's tables
        recommend a cutter radius close to the mean cone distance for spiral angles ~35°).
    edge_radius_mm
        Edge (tip) radius ``ρ_f`` of every blade, mm (> 0): the blade profile ends in an arc
        tangent to the blade and to the cutter's point plane (:class:`EdgeRadius`); it generates
        the fillet. The arc rises ``ρ_f (1 − sin α)`` above the point plane along the cutter
        axis. None (default): chosen by
        :meth:`~fegear.geometry.spiral_bevel.SpiralBevelPair.design` as ``0.25 m`` (the tip
        radius of the ISO 53 basic rack profile C, ``ρ_fP = 0.25 m``) where the tooth spaces of
        both members carry it with at least 20 % of their point width left as root land, else
        80 % of the largest radius they carry. The reference pair's gear tooth spaces are
        narrowest at the heel (point width 1.74 mm) and carry at most 1.01 mm, so 0.25 m =
        1.235 mm does not fit: 0.81 mm (0.164 m) it is. A radius whose fillets do not fit in a
        tooth space (more than the blade points can carry) is refused
        (:meth:`~fegear.geometry.spiral_bevel.SpiralBevelMember.check_fillets`).
    """

    n1: int = 12
    n2: int = 36
    module_mm: float = 25.4 / 5.14
    spiral_angle_deg: float = 35.0
    pressure_angle_deg: float = 22.5
    face_width_mm: float = 25.4
    shaft_angle_deg: float = 90.0
    cutter_radius_mm: float = 76.2
    edge_radius_mm: float | None = None

    def __post_init__(self) -> None:
        for name in ("n1", "n2"):
            v = getattr(self, name)
            if not isinstance(v, int | np.integer) or v < 5:
                raise InputError(f"spiral_bevel.{name}", v, "an integer >= 5")
        if self.n1 > self.n2:
            raise InputError(
                "spiral_bevel.n1", self.n1, f"<= n2 = {self.n2}", "member 1 is the pinion"
            )
        for name in ("module_mm", "face_width_mm", "cutter_radius_mm"):
            v = getattr(self, name)
            if not np.isfinite(v) or v <= 0:
                raise InputError(f"spiral_bevel.{name}", v, "> 0")
        if self.edge_radius_mm is not None and not (
            np.isfinite(self.edge_radius_mm) and self.edge_radius_mm > 0
        ):
            raise InputError("spiral_bevel.edge_radius_mm", self.edge_radius_mm, "> 0 (or unset)")
        if not 0.0 < self.shaft_angle_deg < 180.0:
            raise InputError("spiral_bevel.shaft_angle_deg", self.shaft_angle_deg, "in (0, 180)")
        if not 0.0 <= self.spiral_angle_deg <= 50.0:
            raise InputError("spiral_bevel.spiral_angle_deg", self.spiral_angle_deg, "in [0, 50]")
        if not 10.0 <= self.pressure_angle_deg <= 30.0:
            raise InputError(
                "spiral_bevel.pressure_angle_deg", self.pressure_angle_deg, "in [10, 30]"
            )
        if self.face_width_mm > self.outer_cone_distance / 2.5:
            raise DesignError(
                "spiral_bevel.face_width_mm",
                self.face_width_mm,
                f"<= A0/2.5 = {self.outer_cone_distance / 2.5:.3f} mm",
                "Gleason limits the face width to about a third of the outer cone distance",
            )
        if self.whole_depth >= self.outer_cone_distance - self.face_width_mm:
            raise DesignError("spiral_bevel.module_mm", self.module_mm, "smaller", "teeth too deep")
        rc, rm, b = self.cutter_radius_mm, self.mean_cone_distance, math.radians(self.beta_deg)
        if rc <= 0.3 * rm or rc > 3.0 * rm:
            raise DesignError(
                "spiral_bevel.cutter_radius_mm",
                rc,
                f"in (0.3 Rm, 3 Rm] = ({0.3 * rm:.1f}, {3 * rm:.1f}] mm",
            )
        if rm**2 + rc**2 - 2 * rm * rc * math.sin(b) <= 0:
            raise DesignError("spiral_bevel.cutter_radius_mm", rc, "a reachable cutter position")

    # --- derived quantities (mm, rad) ---
    @property
    def beta_deg(self) -> float:
        return self.spiral_angle_deg

    @property
    def edge_radius(self) -> float:
        """Blade edge radius ``ρ_f`` (mm) the synthesis puts on the cutters: ``edge_radius_mm``,
        or the ``0.25 m`` that :meth:`~fegear.geometry.spiral_bevel.SpiralBevelPair.design`
        then reduces if the tooth spaces do not carry it (see ``edge_radius_mm``)."""
        if self.edge_radius_mm is None:
            return EDGE_RADIUS_MODULES * self.module_mm
        return float(self.edge_radius_mm)

    @property
    def m21(self) -> float:
        """Nominal gear ratio ω2/ω1 = N1/N2."""
        return self.n1 / self.n2

    @property
    def pitch_angles(self) -> tuple[float, float]:
        """Pitch cone angles (γ1, γ2), rad."""
        s = math.radians(self.shaft_angle_deg)
        g1 = math.atan2(math.sin(s), self.n2 / self.n1 + math.cos(s))
        return g1, s - g1

    @property
    def outer_cone_distance(self) -> float:
        return self.module_mm * self.n2 / (2.0 * math.sin(self.pitch_angles[1]))

    @property
    def mean_cone_distance(self) -> float:
        return self.outer_cone_distance - 0.5 * self.face_width_mm

    @property
    def working_depth(self) -> float:
        return 1.700 * self.module_mm

    @property
    def clearance(self) -> float:
        return 0.125 * self.working_depth + 0.051

    @property
    def whole_depth(self) -> float:
        return self.working_depth + self.clearance

    @property
    def addenda(self) -> tuple[float, float]:
        """Heel addenda (a1, a2), mm."""
        a2 = self.working_depth * (0.210 + 0.290 * (self.n1 / self.n2) ** 2)
        return self.working_depth - a2, a2

    @property
    def dedenda(self) -> tuple[float, float]:
        a1, a2 = self.addenda
        return self.whole_depth - a1, self.whole_depth - a2

    @property
    def dedendum_angles(self) -> tuple[float, float]:
        b1, b2 = self.dedenda
        return math.atan(b1 / self.outer_cone_distance), math.atan(b2 / self.outer_cone_distance)

    @property
    def thickness_heel(self) -> tuple[float, float]:
        """Heel transverse circular thicknesses (t1, t2), zero backlash, mm."""
        p = math.pi * self.module_mm
        a1, a2 = self.addenda
        al, be = math.radians(self.pressure_angle_deg), math.radians(self.spiral_angle_deg)
        t2 = 0.5 * p - (a1 - a2) * math.tan(al) / math.cos(be)
        return p - t2, t2

    def root_height(self, i: int, L: Array | float) -> Array:
        """Height ``h_R(L) = −b_i + (A0 − L) tan δ_fi`` of the root cone of member i (mm)."""
        A0 = self.outer_cone_distance
        L = np.asarray(L, dtype=float)
        return -self.dedenda[i - 1] + (A0 - L) * math.tan(self.dedendum_angles[i - 1])

    def half_tooth_angle(self, i: int) -> float:
        """Half the transverse tooth-thickness angle of member i (1|2) at the mean point, rad."""
        t = self.thickness_heel[i - 1] * self.mean_cone_distance / self.outer_cone_distance
        return 0.5 * t / (self.mean_cone_distance * math.sin(self.pitch_angles[i - 1]))

    def flank_heights(self, i: int, L: Array | float) -> tuple[Array, Array]:
        """Working depth ``h_w(L)`` (the mate's face cone, nominal mesh: the clearance above the
        root cone) and face-cone height ``h_a(L)`` of member i (mm). The flank itself reaches
        down to the fillet limit, below ``h_w`` (:mod:`fegear.geometry.spiral_bevel`)."""
        A0 = self.outer_cone_distance
        a = self.addenda
        d = self.dedendum_angles
        j = 2 if i == 1 else 1
        L = np.asarray(L, dtype=float)
        h_f = -a[j - 1] + (A0 - L) * math.tan(d[i - 1])
        h_a = a[i - 1] - (A0 - L) * math.tan(d[j - 1])
        return h_f, h_a


@dataclass(frozen=True)
class SynthesisTargets:
    """Design targets of the local synthesis (Litvin & Zhang 1991).

    Parameters
    ----------
    te_amplitude_arcsec
        Predesigned parabolic TE amplitude over one mesh cycle (> 0, ≤ 60).
    path_angle_drive_deg, path_angle_coast_deg
        Direction η of the contact path on the gear flank at its mean point, measured from the
        tooth trace (toe → heel) towards the tip, in (−90, 90). The relative curvature along the
        path is ``((ω12 × n)·t)²/c`` (see :func:`_relative_curvature`), which vanishes for one
        direction (η ≈ +15° drive, −15° coast for the reference pair, where the path speed
        λ → ∞); the defaults −8° / +8° give a longitudinal path travelling ≈ 16 mm per mesh
        cycle on the 25.4 mm face (Argyris et al. 2002 prefer longitudinal paths with a
        predesigned parabolic TE).
    ellipse_major_axis_mm
        Major axis 2a of the instantaneous contact ellipse at the paint thickness (> 0).
        Default 6.0 mm (about 0.8 of the mean working depth measured along the flank, so that
        the ellipse, whose major axis runs across the profile for a longitudinal path, fits).
    paint_thickness_mm
        Elastic approach / marking-compound thickness δ, default 0.00632 mm.
    pinion_parabola_per_mm
        Parabolic blade coefficient ``a_c`` of the pinion blade (profile crowning), ≥ 0:
        the blade deviates by ``a_c s²`` (mm) from the straight blade at distance s from the
        mean-point height. Default 0.002 1/mm (order of magnitude of Argyris et al. 2002).
    symmetric_te
        Tune the third-order roll coefficient D of each pinion side by a rigid TCA of the mean
        tooth pair so that TE(−π/N1) = TE(+π/N1): local synthesis fixes the TE only to second
        order at the mean point, and the third-order term otherwise tilts the parabola (about
        ±3 arcsec for the reference pair). Costs ~10 s.
    """

    te_amplitude_arcsec: float = 8.0
    path_angle_drive_deg: float = -8.0
    path_angle_coast_deg: float = 8.0
    ellipse_major_axis_mm: float = 6.0
    paint_thickness_mm: float = 0.00632
    pinion_parabola_per_mm: float = 0.002
    symmetric_te: bool = True

    def __post_init__(self) -> None:
        if not 0.0 < self.te_amplitude_arcsec <= 60.0:
            raise InputError(
                "spiral_bevel.te_amplitude_arcsec", self.te_amplitude_arcsec, "in (0, 60]"
            )
        for name in ("path_angle_drive_deg", "path_angle_coast_deg"):
            v = getattr(self, name)
            if not -90.0 < v < 90.0:
                raise InputError(f"spiral_bevel.{name}", v, "in (-90, 90)")
        for name in ("ellipse_major_axis_mm", "paint_thickness_mm"):
            v = getattr(self, name)
            if not np.isfinite(v) or v <= 0:
                raise InputError(f"spiral_bevel.{name}", v, "> 0")
        if not 0.0 <= self.pinion_parabola_per_mm <= 0.05:
            raise InputError(
                "spiral_bevel.pinion_parabola_per_mm", self.pinion_parabola_per_mm, "in [0, 0.05]"
            )


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
        over the cycle (:meth:`~fegear.geometry.spiral_bevel.SpiralBevelPair.design`).
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


def head_cutter(ms: MachineSettings) -> HeadCutter:
    return HeadCutter(
        radius=ms.cutter_radius_mm,
        blade_angle=math.radians(ms.blade_angle_deg),
        outside=ms.blade == "outside",
        parabola=ms.parabola_per_mm,
    )


def point_plane(blank: SpiralBevelBlank, i: int, ms: MachineSettings) -> float:
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
    g = blank.pitch_angles[i - 1]
    L = blank.mean_cone_distance
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


# --------------------------------------------------------------------------------------------
# mean points and mesh placement
# --------------------------------------------------------------------------------------------
def mean_point(blank: SpiralBevelBlank, i: int, theta: float) -> tuple[Array, Array, Array]:
    """Mean pitch point of member i at polar angle θ: point, generatrix e_g, pitch normal e_p."""
    g = blank.pitch_angles[i - 1]
    rm = blank.mean_cone_distance
    c, s = math.cos(theta), math.sin(theta)
    e_g = np.array([math.sin(g) * c, math.sin(g) * s, math.cos(g)])
    e_p = np.array([math.cos(g) * c, math.cos(g) * s, -math.sin(g)])
    return rm * e_g, e_g, e_p


def gear_flank_design(blank: SpiralBevelBlank, side: str) -> tuple[Array, Array, Array, float]:
    """Gear mean point, designed outward normal, tooth trace, polar angle θ_M of one flank.

    Trace ``t = cos β e_g + sin β e_θ`` (right-hand gear); ``w = −sin β e_g + cos β e_θ``;
    normal ``n = ±cos α w + sin α e_p``. The +θ flank is concave (the standard cutter centre,
    the one nearer the apex, lies on the +w side), so drive = +θ side, coast = −θ side.
    """
    al, be = math.radians(blank.pressure_angle_deg), math.radians(blank.spiral_angle_deg)
    sgn = 1.0 if side == "drive" else -1.0
    th = sgn * blank.half_tooth_angle(2)
    M, e_g, e_p = mean_point(blank, 2, th)
    e_th = np.array([-math.sin(th), math.cos(th), 0.0])
    t = math.cos(be) * e_g + math.sin(be) * e_th
    w = -math.sin(be) * e_g + math.cos(be) * e_th
    n = sgn * math.cos(al) * w + math.sin(al) * e_p
    return M, n, t, th


def mesh_transforms(
    blank: SpiralBevelBlank, side: str, theta_gear: float, delta_pinion: float, sigma: float
):
    """Functions ``φ -> 4×4`` placing pinion and gear in the mesh frame (driving-sense angles).

    Mesh frame: apex at the origin, pinion axis +z_f, gear axis +x_f (Σ = 90°; in general the gear
    axis is ``rot_y(Σ) e_z``), common pitch generatrix in the x_f z_f plane. At ``φ1 = φ2 = 0`` the
    mean contact point of ``side`` is on the pitch generatrix. The pinion turns about ``σ e_z``,
    the gear about ``−σ e_gear`` (so that the pitch cones roll).
    """
    S = math.radians(blank.shaft_angle_deg)
    e2 = np.array([math.sin(S), 0.0, math.cos(S)])
    G0 = compose(rot_y(S), rot_z(math.pi), rot_z(-theta_gear))
    P0 = rot_z(-delta_pinion)

    def pinion(phi1: float | Array) -> Array:
        return compose(rot_z(sigma * np.asarray(phi1)), P0)

    def gear(phi2: float | Array) -> Array:
        return compose(rot_axis(-sigma * e2, np.asarray(phi2)), G0)

    return pinion, gear, e2


# --------------------------------------------------------------------------------------------
# local synthesis
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SynthesisReport:
    """What the local synthesis aimed at and reached for one side (mesh frame, mean position).

    Attributes
    ----------
    side
        ``"drive"`` or ``"coast"``.
    sigma
        Sense of pinion rotation (+1: about +z_f) for this side to drive.
    m21_prime
        dm21/dφ1 giving the predesigned parabolic TE.
    point, normal
        Mean contact point (mm) and common normal (out of the gear tooth), mesh frame.
    path_direction
        Unit tangent t of the designed path on the gear at M.
    path_speed_mm_per_rad
        λ: speed of the contact point along t per rad of pinion rotation.
    relative_curvature
        ``A = S2 − S1`` (1/mm) in the tangent basis ``(t, n × t)``.
    target_pinion_shape, achieved_pinion_shape
        Pinion shape operator w.r.t. its outward normal, basis ``(t, n × t)`` (1/mm).
    gear_flank_angle, pinion_flank_angle
        Polar angles (rad) of the mean points of this side's gear and pinion flanks in their
        member frames (half tooth-thickness angles with the flank's sign).
    residual
        Final residuals of the settings equations (scaled meshing, curvature × Rm).
    """

    side: str
    sigma: float
    m21_prime: float
    point: Array
    normal: Array
    path_direction: Array
    path_speed_mm_per_rad: float
    relative_curvature: Array
    target_pinion_shape: Array
    achieved_pinion_shape: Array
    gear_flank_angle: float
    pinion_flank_angle: float
    residual: Array = field(repr=False)


def _shape_operator(env, basis: Array) -> Array:
    """Shape operator ``dn = S dr`` of an envelope point in the orthonormal tangent ``basis``."""
    R = np.stack([env.r_u, env.r_t], -1)  # (3, 2)
    N = np.stack([env.n_u, env.n_t], -1)
    S3 = N @ np.linalg.pinv(R)
    S = basis @ S3 @ basis.T
    return 0.5 * (S + S.T)


def _relative_curvature(
    blank: SpiralBevelBlank, targets: SynthesisTargets, M: Array, n: Array, t_gear: Array,
    sigma: float, e2: Array, sigma_side: str,
) -> tuple[Array, Array, float, float]:  # fmt: skip
    """Litvin's local synthesis: path tangent t, relative curvature A (basis t, n×t), λ, m'21."""
    N1 = blank.n1
    mp = -2.0 * targets.te_amplitude_arcsec * ARCSEC * (N1 / math.pi) ** 2
    m21 = blank.m21
    w1 = sigma * np.array([0.0, 0.0, 1.0])
    w2 = -sigma * m21 * e2
    w12 = w1 - w2
    dw12 = sigma * mp * e2  # −d(ω2)/dt
    field_name = "path_angle_drive_deg" if sigma_side == "drive" else "path_angle_coast_deg"
    eta_deg = getattr(targets, field_name)
    eta = math.radians(eta_deg)
    e_tr = unit(t_gear - n * np.dot(t_gear, n))
    e_pr = np.cross(n, e_tr)
    if np.dot(e_pr, _pitch_normal_mesh(M, e2)) < 0:
        e_pr = -e_pr
    t = math.cos(eta) * e_tr + math.sin(eta) * e_pr
    q = np.cross(n, t)
    c = np.dot(n, np.cross(dw12, M)) + np.dot(n, np.cross(w12, np.cross(w2, M)))
    den = np.dot(n, np.cross(w12, t))
    if abs(den) < 1e-12:
        raise DesignError(f"spiral_bevel.{field_name}", eta_deg, "another value")
    lam = -c / den
    b = np.cross(w12, n) / lam
    p, r = np.dot(b, t), np.dot(b, q)
    a = 0.5 * targets.ellipse_major_axis_mm
    k = 2.0 * targets.paint_thickness_mm / a**2
    if p <= k:
        raise DesignError(
            f"spiral_bevel.{field_name}",
            eta_deg,
            "a path direction with a positive relative curvature along it",
            f"relative normal curvature along the path {p:.3e} 1/mm <= {k:.3e} needed by the "
            f"ellipse; change the path angle or the TE amplitude",
        )
    mu = k + r**2 / (p - k)
    A = np.array([[p, r], [r, mu]])
    return np.stack([t, q]), A, float(lam), mp


def _pitch_normal_mesh(M: Array, e2: Array) -> Array:
    """Outward normal of the gear pitch cone at M (mesh frame): away from the gear axis."""
    radial = M - e2 * np.dot(M, e2)
    return unit(radial - M * np.dot(radial, M) / np.dot(M, M))


def synthesize(
    blank: SpiralBevelBlank, targets: SynthesisTargets
) -> tuple[SpiralBevelSettings, dict[str, SynthesisReport]]:
    """Compute all machine settings from the blank and the targets (module doc).

    Returns the settings and, per side, the :class:`SynthesisReport`.
    Raises :class:`DesignError` if the synthesis has no solution.
    """
    g1, g2 = blank.pitch_angles
    d1, d2 = blank.dedendum_angles
    gm1, gm2 = g1 - d1, g2 - d2
    mc1, mc2 = math.cos(d1) / math.sin(g1), math.cos(d2) / math.sin(g2)
    out: dict[str, MachineSettings] = {}
    reports: dict[str, SynthesisReport] = {}
    for side in ("drive", "coast"):
        # ---- gear flank: design normal at its mean point, cutter fitted, nominal roll
        M2, n2, t2, th2 = gear_flank_design(blank, side)
        blade2 = "outside" if side == "drive" else "inside"
        gs = fit_cutter("gear", side, blade2, M2, n2, blank.cutter_radius_mm, 0.0, gm2,
                        math.pi - th2, mc2, edge_radius=blank.edge_radius)  # fmt: skip
        out[f"gear_{side}"] = gs
        env2 = generate(head_cutter(gs), machine_motion(gs), 0.0, 0.0, 0.0, half_width=0.2)
        # ---- into the mesh frame
        # the placement at φ = 0 does not depend on the rotation sense (1.0 here)
        _, gear_f, e2 = mesh_transforms(blank, side, th2, 0.0, 1.0)
        G = gear_f(0.0)
        M = apply_points(G, M2)
        n = apply_vectors(G, n2)
        t_g = apply_vectors(G, t2)
        if not np.allclose(apply_points(G, env2.points), M, atol=1e-8):
            raise SolverError(f"spiral bevel gear {side}: the mean point is not generated")
        # driving sense: the pinion pushes the gear along -n; gear must turn with its torque
        sigma = float(np.sign(np.dot(np.cross(M, n), e2)))
        if np.dot(np.cross(M, n), [0, 0, 1]) * sigma >= 0:
            log.warning("spiral bevel %s: pinion and gear torque senses disagree", side)
        basis, A, lam, mp = _relative_curvature(blank, targets, M, n, t_g, sigma, e2, side)
        Rg = G[:3, :3]
        env2_f = _rotate_env(env2, Rg)
        S2 = _shape_operator(env2_f, basis)
        S_p_target = A - S2  # pinion, w.r.t. its outward normal −n
        # ---- pinion flank: pinion frame = mesh frame at φ1 = 0 (M at polar angle 0)
        blade1 = "inside" if side == "drive" else "outside"
        bpin = basis  # pinion frame == mesh frame here

        def settings1(x, side=side, blade1=blade1, M=M, n=n):
            rc, m, C, E = x
            return fit_cutter("pinion", side, blade1, M, -n, rc, targets.pinion_parabola_per_mm,
                              gm1, math.pi, m, C, E, edge_radius=blank.edge_radius)  # fmt: skip

        def residual(x, M=M, bpin=bpin, S_p_target=S_p_target, settings1=settings1):
            ms = settings1(x)
            mot = machine_motion(ms)
            tool = head_cutter(ms)
            ts = tool.evaluate(np.zeros(()), np.zeros(()))
            Mm, M1m, _ = mot.matrices(np.zeros(()))
            v = M1m[:3, :3] @ ts.r + M1m[:3, 3]
            nn = Mm[:3, :3] @ ts.n
            f = float(np.dot(nn, v)) / np.linalg.norm(M)
            env = generate(tool, mot, 0.0, 0.0, 0.0, half_width=0.1)
            S = _shape_operator(env, bpin)
            d = (S - S_p_target) * blank.mean_cone_distance
            return np.array([f * 10.0, d[0, 0], d[0, 1], d[1, 1]])

        x0 = np.array([blank.cutter_radius_mm, mc1, 0.0, 0.0])
        x, info, ier, msg = fsolve(residual, x0, full_output=True, xtol=1e-12)
        res = residual(x)
        if ier != 1 or np.max(np.abs(res)) > 1e-7:
            raise DesignError(
                "spiral_bevel.synthesis_targets",
                targets,
                "targets the pinion settings can reach",
                f"local synthesis of the {side} side did not converge ({msg.strip()}); "
                f"residual {np.max(np.abs(res)):.2e}",
            )
        ps = settings1(x)
        env1 = generate(head_cutter(ps), machine_motion(ps), 0.0, 0.0, 0.0, half_width=0.1)
        S_ach = _shape_operator(env1, bpin)
        # place the pinion flank at its half tooth angle (flank faces +θ or −θ)
        e_th = np.array([0.0, 1.0, 0.0])
        s_face = float(np.sign(np.dot(-n, e_th)))
        delta = s_face * blank.half_tooth_angle(1)
        ps = replace(ps, blank_phase_deg=ps.blank_phase_deg - math.degrees(delta))
        out[f"pinion_{side}"] = ps
        reports[side] = SynthesisReport(
            side=side,
            sigma=sigma,
            m21_prime=mp,
            point=M,
            normal=n,
            path_direction=basis[0],
            path_speed_mm_per_rad=lam,
            relative_curvature=A,
            target_pinion_shape=S_p_target,
            achieved_pinion_shape=S_ach,
            gear_flank_angle=th2,
            pinion_flank_angle=delta,
            residual=res,
        )
        log.info(
            "spiral bevel %s: r_c1 = %.3f mm, m_c1 = %.6f, C = %.5f, E_m1 = %.4f mm, "
            "lambda = %.2f mm/rad, residual %.1e",
            side, x[0], x[1], x[2], x[3], lam, np.max(np.abs(res)),
        )  # fmt: skip
    return SpiralBevelSettings(**out), reports


@dataclass(frozen=True)
class _Env:
    points: Array
    normals: Array
    r_u: Array
    r_t: Array
    n_u: Array
    n_t: Array


def _rotate_env(env, R: Array) -> _Env:
    return _Env(*(a @ R.T for a in (env.points, env.normals, env.r_u, env.r_t, env.n_u, env.n_t)))
