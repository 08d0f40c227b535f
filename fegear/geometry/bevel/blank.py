"""Bevel blank data: pitch cones, Gleason proportions and the flank coordinates ``(L, h)``.

Face-milled spiral bevel gears (Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed.,
2004, ch. 21). A blank tells the members where their flanks are: per member ``i`` (1 pinion, 2
gear) its pitch cone, the cone distances of toe, mean point and heel, the root and face cones
in the member's own ``(L, h)`` coordinates, and the tooth thickness; and, for the pair, where the
mean pitch point and the gear axis lie in the mesh frame (:mod:`.mesh_frame`).

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
:meth:`~fegear.geometry.bevel.member.SpiralBevelMember.fillet_height`) and on to the face cone
``h_a(L) = a_i − (A0 − L) tan δ_fj``. The mate's face cone reaches down to the working depth
``h_w(L) = −a_j + (A0 − L) tan δ_fi`` (the clearance ``c`` above the root cone): the lowest point
that can be in contact in the nominal mesh (:meth:`SpiralBevelBlank.flank_heights`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ...errors import DesignError, InputError

__all__ = ["ARCSEC", "BevelBlank", "EDGE_RADIUS_MODULES", "SpiralBevelBlank"]

Array = NDArray[np.float64]
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
        Mean spiral angle β, in [0, 50].
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
        :meth:`~fegear.geometry.bevel.pair.SpiralBevelPair.design` as ``0.25 m`` (the tip
        radius of the ISO 53 basic rack profile C, ``ρ_fP = 0.25 m``) where the tooth spaces of
        both members carry it with at least 20 % of their point width left as root land, else
        80 % of the largest radius they carry. The reference pair's gear tooth spaces are
        narrowest at the heel (point width 1.74 mm) and carry at most 1.01 mm, so 0.25 m =
        1.235 mm does not fit: 0.81 mm (0.164 m) it is. A radius whose fillets do not fit in a
        tooth space (more than the blade points can carry) is refused
        (:meth:`~fegear.geometry.bevel.member.SpiralBevelMember.check_fillets`).
    hand
        Hand of the gear's spiral, ``"right"`` (default: the tooth trace turns towards +θ going
        toe → heel, clockwise seen from the front) or ``"left"``; the pinion has the other hand.
        A left-hand pair is the mirror image of the right-hand one
        (:meth:`~fegear.geometry.bevel.pair.SpiralBevelPair.mirrored`).
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
    hand: str = "right"
    #: prefix of the field names in this blank's errors
    field_prefix: ClassVar[str] = "spiral_bevel"

    def __post_init__(self) -> None:
        if self.hand not in ("right", "left"):
            raise InputError(f"{self.field_prefix}.hand", self.hand, "'right' or 'left'")
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
        A0 = self.outer_cone_distance(2)
        if self.face_width_mm > A0 / 2.5:
            raise DesignError(
                "spiral_bevel.face_width_mm",
                self.face_width_mm,
                f"<= A0/2.5 = {A0 / 2.5:.3f} mm",
                "Gleason limits the face width to about a third of the outer cone distance",
            )
        if self.whole_depth >= A0 - self.face_width_mm:
            raise DesignError("spiral_bevel.module_mm", self.module_mm, "smaller", "teeth too deep")
        rc, rm, b = self.cutter_radius_mm, self.mean_cone_distance(2), math.radians(self.beta_deg)
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
    def offset_mm(self) -> float:
        """Shortest distance E between the axes: 0 (intersecting axes; a hypoid has E > 0)."""
        return 0.0

    @property
    def edge_radius(self) -> float:
        """Blade edge radius ``ρ_f`` (mm) the synthesis puts on the cutters: ``edge_radius_mm``,
        or the ``0.25 m`` that :meth:`~fegear.geometry.bevel.pair.SpiralBevelPair.design`
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
        A0 = self.outer_cone_distance(2)
        return math.atan(b1 / A0), math.atan(b2 / A0)

    # --- per member i (1 pinion, 2 gear): the bevel-blank protocol of the members ---
    def pitch_angle(self, i: int) -> float:
        """Pitch cone angle γ_i (rad)."""
        return self.pitch_angles[i - 1]

    def pitch_apex(self, i: int) -> float:
        """Distance (mm) from the crossing point of the axes to member i's pitch apex along its
        axis, positive beyond the crossing point (away from the member's blank): 0, the cones
        share their apex."""
        return 0.0

    def outer_cone_distance(self, i: int) -> float:
        """Outer (heel) cone distance ``A0`` (mm), the same for both members."""
        return self.module_mm * self.n2 / (2.0 * math.sin(self.pitch_angles[1]))

    def mean_cone_distance(self, i: int) -> float:
        """Mean cone distance ``Rm = A0 − F/2`` (mm): the mean point of both members."""
        return self.outer_cone_distance(i) - 0.5 * self.face_width_mm

    def face_width(self, i: int) -> float:
        """Face width ``F`` along the pitch generatrix (mm), toe ``A0 − F`` → heel ``A0``."""
        return self.face_width_mm

    def spiral_angle(self, i: int) -> float:
        """Mean spiral angle β_i (rad): the same on both members."""
        return math.radians(self.spiral_angle_deg)

    def pressure_angle(self, side: str) -> float:
        """Normal pressure angle (rad) of the gear's ``side`` flank at its mean point: the same
        on both sides."""
        return math.radians(self.pressure_angle_deg)

    def addendum(self, i: int) -> float:
        return self.addenda[i - 1]

    def dedendum(self, i: int) -> float:
        return self.dedenda[i - 1]

    def dedendum_angle(self, i: int) -> float:
        return self.dedendum_angles[i - 1]

    def thickness_heel(self, i: int) -> float:
        """Heel transverse circular thickness of member i, zero backlash, mm:
        ``t2 = p/2 − (a1 − a2) tan α / cos β``, ``t1 = p − t2``."""
        p = math.pi * self.module_mm
        a1, a2 = self.addenda
        al, be = math.radians(self.pressure_angle_deg), math.radians(self.spiral_angle_deg)
        t2 = 0.5 * p - (a1 - a2) * math.tan(al) / math.cos(be)
        return p - t2 if i == 1 else t2

    def root_cone_line(self, i: int) -> tuple[float, float]:
        """``(a, b)`` of member i's root cone ``h_R(L) = a + b L`` in its ``(L, h)`` plane:
        ``a = −b_i + A0 tan δ_fi``, ``b = −tan δ_fi`` (through the apex)."""
        td = math.tan(self.dedendum_angles[i - 1])
        return -self.dedenda[i - 1] + self.outer_cone_distance(i) * td, -td

    def face_cone_line(self, i: int) -> tuple[float, float]:
        """``(a, b)`` of member i's face cone ``h_a(L) = a + b L``: ``a = a_i − A0 tan δ_fj``,
        ``b = tan δ_fj`` (parallel to the mate's root cone: parallel clearance)."""
        tj = math.tan(self.dedendum_angles[1 if i == 1 else 0])
        return self.addenda[i - 1] - self.outer_cone_distance(i) * tj, tj

    def root_height(self, i: int, L: Array | float) -> Array:
        """Height ``h_R(L) = −b_i + (A0 − L) tan δ_fi`` of the root cone of member i (mm)."""
        A0 = self.outer_cone_distance(i)
        L = np.asarray(L, dtype=float)
        return -self.dedenda[i - 1] + (A0 - L) * math.tan(self.dedendum_angles[i - 1])

    def half_tooth_angle(self, i: int) -> float:
        """Half the transverse tooth-thickness angle of member i (1|2) at the mean point, rad."""
        rm, A0 = self.mean_cone_distance(i), self.outer_cone_distance(i)
        t = self.thickness_heel(i) * rm / A0
        return 0.5 * t / (rm * math.sin(self.pitch_angles[i - 1]))

    def flank_heights(self, i: int, L: Array | float) -> tuple[Array, Array]:
        """Working depth ``h_w(L)`` (the mate's face cone, nominal mesh: the clearance above the
        root cone) and face-cone height ``h_a(L)`` of member i (mm). The flank itself reaches
        down to the fillet limit, below ``h_w`` (:mod:`fegear.geometry.bevel.member`)."""
        A0 = self.outer_cone_distance(i)
        a = self.addenda
        d = self.dedendum_angles
        j = 2 if i == 1 else 1
        L = np.asarray(L, dtype=float)
        h_f = -a[j - 1] + (A0 - L) * math.tan(d[i - 1])
        h_a = a[i - 1] - (A0 - L) * math.tan(d[j - 1])
        return h_f, h_a

    # --- the pair in the mesh frame (:mod:`.mesh_frame`) ---
    def pitch_point(self) -> Array:
        """Mean pitch point ``P = Rm (sin γ1, 0, cos γ1)`` (mm), mesh frame."""
        g1 = self.pitch_angles[0]
        return self.mean_cone_distance(1) * np.array([math.sin(g1), 0.0, math.cos(g1)])

    def gear_axis(self) -> tuple[Array, Array]:
        """Gear pitch apex (the origin) and unit axis ``e2 = (sin Σ, 0, cos Σ)`` from the apex
        toward the gear blank, mesh frame."""
        s = math.radians(self.shaft_angle_deg)
        return np.zeros(3), np.array([math.sin(s), 0.0, math.cos(s)])

    def crossing_point(self) -> Array:
        """The point of the pinion axis nearest the gear axis: the common apex (origin)."""
        return np.zeros(3)


#: A blank of either bevel kind: :class:`SpiralBevelBlank` or
#: :class:`~.hypoid.HypoidBlank` (the same per-member protocol).
BevelBlank = Any
