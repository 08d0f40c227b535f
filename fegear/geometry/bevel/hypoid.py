"""Hypoid blank: the Gleason proportions of a face-milled hypoid pair on its pitch cones.

The pitch cones come from :func:`~.hypoid_cones.pitch_cones` (ISO 23509:2016 method 1, derived;
``docs/geometry/hypoid.md``). On them this blank puts the proportions of
:class:`~.blank.SpiralBevelBlank`, per member on its own cone, and gives the members the same
per-member protocol (:mod:`.member`, :mod:`.synthesis`, :mod:`.mesh_frame`). At ``E = 0`` it is
that spiral bevel blank, number for number.

Blank proportions (Gleason, as ``SpiralBevelBlank``, per member on its own pitch cone)
-------------------------------------------------------------------------------------
Module ``m = de2/N2`` (the gear's outer transverse module)::

    h_k = 1.700 m,  c = 0.125 h_k + 0.051 mm,  h_t = h_k + c
    a2 = h_k (0.210 + 0.290 (N1/N2)²),  a1 = h_k − a2,  b_i = h_t − a_i      at each heel A0_i
    δ_fi = atan(b_i / A0_i)      root line through member i's own pitch apex (standard taper)
    h_R,i(L) = −b_i + (A0_i − L) tan δ_fi,   h_a,i(L) = a_i − (A0_i − L) tan δ_fj   (parallel
    clearance applied on member i's own cone), h_w,i(L) = h_R,i(L) + c (the mate's face cone)
    t2 = π m/2 − (a1 − a2) tan α / cos β2                    gear heel transverse thickness
    s_n2 = t2 (Rm2/A0_2) cos β2,  s_n1 = p_n − s_n2,  p_n = 2π r2 cos β2 / N2  (mean normal pitch)
    t1 = s_n1 / cos β1 · A0_1 / Rm1                          pinion heel transverse thickness

(``t1 = π m − t2`` at ``E = 0``). The gear face runs from ``A0_2 − b2`` to ``A0_2``. The
**pinion face** covers the gear face along the pinion's pitch generatrix through P in the
developed pitch plane (both apices lie in it): its toe and heel are where that generatrix crosses
the gear's toe and heel circles ``|X − A2| = A0_2 − b2, A0_2``::

    L = Rm1 − Rm2 cos ε' + √(R² − a_p²),  a_p = Rm2 sin ε'  (ISO's pitch-plane offset)

which is ISO 23509's pinion face width in the pitch plane ``b_p1`` and its inner part ``b_1A``
(Annex F.3: 30.626 and 15.243 mm, tested), and ``b2`` exactly at ``E = 0``. ISO's final pinion
face width adds increments along the pinion axis that come from its own depth and face-cone
construction (formulae 161–166: 31.910 mm in F.3); give ``pinion_face_width_mm`` for such a
face: the extra width is split equally beyond both ends of the covering span.

Conventions
-----------
* ``hand`` is the gear's (the pinion has the other). A right-hand gear has its trace turning
  towards −y going toe → heel at P (as the spiral bevel's gear); its axis is displaced from the
  pinion axis by E towards +y (the common perpendicular from the pinion axis to the gear axis
  points to +y), the side that makes the pinion larger than a spiral bevel pinion
  (``β1 − β2 = ε' > 0``, the usual hypoid). A left-hand gear is the mirror image in the xz
  plane: every vector output has its y component negated; every scalar is the same.
* :meth:`HypoidBlank.pitch_apex`: Gleason's and ISO's "pitch apex beyond crossing point"
  ``t_z,i = (C_i − A_i)·e_i`` (``C_i`` the point of axis i nearest the other axis, ``A_i`` the
  pitch apex, ``e_i`` towards member i's blank): positive when the apex lies beyond the crossing
  point seen from the member's back (ISO 23509 Annex F.3: −1.225 / +1.576 mm, tested).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from ...errors import DesignError, InputError
from .blank import EDGE_RADIUS_MODULES
from .hypoid_cones import HypoidPitchCones, pitch_cones

__all__ = ["HypoidBlank"]

Array = NDArray[np.float64]
#: record format of :meth:`HypoidBlank.record`
RECORD_FORMAT = "fegear.hypoid_blank/1"


@dataclass(frozen=True)
class HypoidBlank:
    """Blank data of a face-milled hypoid pair and its derived pitch cones and Gleason
    proportions (module doc). Member 1 is the pinion, 2 the gear.

    Parameters
    ----------
    n1, n2
        Tooth numbers, ``5 <= n1 <= n2``.
    module_mm
        Outer transverse module of the gear, ``de2 = m N2`` (mm).
    offset_mm
        Hypoid offset E >= 0 (mm), below the gear's outer pitch radius ``de2/2``; the hand
        decides the side (module doc). 0: the spiral bevel blank.
    spiral_angle_deg
        Pinion mean spiral angle β1 (the design input), in [0, 60]; the gear's is
        ``β2 = β1 − ε'``, which must not be negative.
    pressure_angle_deg
        Nominal normal pressure angle α, in [10, 30]; the flanks are cut at
        ``α ∓ f_αlim α_lim`` (:meth:`pressure_angle`).
    face_width_mm
        Gear face width b2 along its pitch generatrix, ``0 < b2 <= A0_2/2.5``.
    pinion_face_width_mm
        Pinion face width F1; None: the span that covers the gear face (module doc; b2 at E = 0).
    shaft_angle_deg
        Shaft angle Σ in (0, 180).
    cutter_radius_mm
        Gear cutter radius r_c0 (mean blade radius), in (0.3 Rm, 3 Rm]; it fixes the pitch cones
        through the limit condition ``ρ_lim = r_c0``.
    edge_radius_mm
        Blade edge radius, as :class:`~.blank.SpiralBevelBlank` (None: chosen by the design).
    hand
        Hand of the gear, ``"right"`` or ``"left"`` (the pinion has the other).
    limit_pressure_angle_factor
        ISO 23509's influence factor ``f_αlim`` of the limit pressure angle on the flank
        pressure angles, in [0, 1] (1: the generated pressure angles balance the limit normal;
        0: both flanks at α).
    """

    n1: int = 10
    n2: int = 41
    module_mm: float = 5.0
    offset_mm: float = 25.0
    spiral_angle_deg: float = 45.0
    pressure_angle_deg: float = 20.0
    face_width_mm: float = 30.0
    pinion_face_width_mm: float | None = None
    shaft_angle_deg: float = 90.0
    cutter_radius_mm: float = 76.2
    edge_radius_mm: float | None = None
    hand: Literal["right", "left"] = "right"
    limit_pressure_angle_factor: float = 1.0
    #: prefix of the field names in this blank's errors
    field_prefix: ClassVar[str] = "hypoid"
    _geo: dict[str, Any] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        self._check_inputs()
        de2 = self.module_mm * self.n2
        cones = pitch_cones(
            self.n1, self.n2, offset_mm=self.offset_mm, spiral_angle_deg=self.spiral_angle_deg,
            cutter_radius_mm=self.cutter_radius_mm, outer_diameter_mm=de2,
            face_width_mm=self.face_width_mm, shaft_angle_deg=self.shaft_angle_deg,
            hand=self.hand,
        )  # fmt: skip
        if cones.spiral_angles[1] < 0.0:
            raise DesignError(
                "hypoid.offset_mm", self.offset_mm, "an offset with β2 = β1 − ε' >= 0",
                f"the gear spiral angle would be {math.degrees(cones.spiral_angles[1]):.2f}° "
                f"(ε' = {math.degrees(cones.offset_angle_pitch_plane):.2f}°): its hand "
                "reverses; raise the spiral angle or lower the offset",
            )  # fmt: skip
        object.__setattr__(self, "_geo", self._proportions(cones, de2))
        self._check_design()

    # --- validation ---
    def _check_inputs(self) -> None:
        for name in ("n1", "n2"):
            v = getattr(self, name)
            if not isinstance(v, int | np.integer) or isinstance(v, bool) or v < 5:
                raise InputError(f"hypoid.{name}", v, "an integer >= 5")
        if self.n1 > self.n2:
            raise InputError("hypoid.n1", self.n1, f"<= n2 = {self.n2}", "member 1 is the pinion")
        for name in ("module_mm", "face_width_mm", "cutter_radius_mm"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
                raise InputError(f"hypoid.{name}", v, "> 0")
        for name in ("pinion_face_width_mm", "edge_radius_mm"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
                raise InputError(f"hypoid.{name}", v, "> 0 (or unset)")
        if self.hand not in ("right", "left"):
            raise InputError("hypoid.hand", self.hand, "'right' or 'left'", "the gear's hand")
        if not 0.0 < self.shaft_angle_deg < 180.0:
            raise InputError("hypoid.shaft_angle_deg", self.shaft_angle_deg, "in (0, 180)")
        if not 0.0 <= self.spiral_angle_deg <= 60.0:
            raise InputError("hypoid.spiral_angle_deg", self.spiral_angle_deg, "in [0, 60]")
        f = self.limit_pressure_angle_factor
        if not (isinstance(f, int | float) and 0.0 <= f <= 1.0):
            raise InputError("hypoid.limit_pressure_angle_factor", f, "in [0, 1]")
        if not 10.0 <= self.pressure_angle_deg <= 30.0:
            raise InputError("hypoid.pressure_angle_deg", self.pressure_angle_deg, "in [10, 30]")
        r_e2 = 0.5 * self.module_mm * self.n2
        e = self.offset_mm
        if not (isinstance(e, int | float) and math.isfinite(e) and 0.0 <= e < r_e2):
            raise InputError(
                "hypoid.offset_mm", e, f"in [0, de2/2) = [0, {r_e2:.3f}) mm",
                "the pinion axis must pass inside the gear's pitch circle",
            )  # fmt: skip
        # the cutter against the spiral bevel's mean cone distance (the hypoid's is close)
        s = math.radians(self.shaft_angle_deg)
        g2 = s - math.atan2(math.sin(s), self.n2 / self.n1 + math.cos(s))
        rm = self.module_mm * self.n2 / (2.0 * math.sin(g2)) - 0.5 * self.face_width_mm
        rc = self.cutter_radius_mm
        if not 0.3 * rm < rc <= 3.0 * rm:
            raise DesignError(
                "hypoid.cutter_radius_mm",
                rc,
                f"in (0.3 Rm, 3 Rm] = ({0.3 * rm:.1f}, {3 * rm:.1f}] mm",
            )

    def _check_design(self) -> None:
        g = self._geo
        a02 = g["A0"][1]
        if self.face_width_mm > a02 / 2.5:
            raise DesignError(
                "hypoid.face_width_mm", self.face_width_mm, f"<= A0_2/2.5 = {a02 / 2.5:.3f} mm",
                "Gleason limits the face width to about a third of the outer cone distance",
            )  # fmt: skip
        for k, member in ((1, "gear"), (0, "pinion")):
            toe = g["A0"][k] - g["F"][k]
            if self.whole_depth >= toe:
                what = (
                    "pinion_face_width_mm" if k == 0 and self.pinion_face_width_mm else "module_mm"
                )
                raise DesignError(
                    f"hypoid.{what}", getattr(self, what), "smaller",
                    f"teeth too deep: whole depth {self.whole_depth:.3f} mm >= the {member} toe "
                    f"cone distance {toe:.3f} mm",
                )  # fmt: skip
        rm2, rc, b2 = g["Rm"][1], self.cutter_radius_mm, g["spiral"][1]
        if rm2**2 + rc**2 - 2 * rm2 * rc * math.sin(b2) <= 0:
            raise DesignError("hypoid.cutter_radius_mm", rc, "a reachable cutter position")

    # --- derived geometry, computed once ---
    def _proportions(self, c: HypoidPitchCones, de2: float) -> dict[str, Any]:
        m = self.module_mm
        g1, g2 = c.pitch_angles
        rm1, rm2 = c.mean_cone_distances
        b1s, b2s = c.spiral_angles
        a02 = de2 / (2.0 * math.sin(g2))
        toe1, heel1 = c.pinion_face_cover(a02, self.face_width_mm)
        if self.pinion_face_width_mm is None:
            f1, a01 = heel1 - toe1, heel1
        else:
            f1 = float(self.pinion_face_width_mm)
            a01 = heel1 + 0.5 * (f1 - (heel1 - toe1))
        if self.offset_mm == 0.0 and self.pinion_face_width_mm is None:
            f1, a01 = self.face_width_mm, a02  # the spiral bevel's numbers, bit for bit
        hk = 1.700 * m
        cl = 0.125 * hk + 0.051
        ht = hk + cl
        a2 = hk * (0.210 + 0.290 * (self.n1 / self.n2) ** 2)
        a1 = hk - a2
        ded = (ht - a1, ht - a2)
        A0 = (a01, a02)
        dang = (math.atan(ded[0] / A0[0]), math.atan(ded[1] / A0[1]))
        p = math.pi * m
        al = math.radians(self.pressure_angle_deg)
        t2 = 0.5 * p - (a1 - a2) * math.tan(al) / math.cos(b2s)
        if self.offset_mm == 0.0:
            t1 = p - t2
        else:
            pn = 2.0 * math.pi * rm2 * math.sin(g2) * math.cos(b2s) / self.n2
            sn1 = pn - t2 * (rm2 / a02) * math.cos(b2s)
            t1 = sn1 / math.cos(b1s) * a01 / rm1
        return {
            "cones": c, "A0": A0, "Rm": (rm1, rm2), "F": (f1, self.face_width_mm),
            "gamma": (g1, g2), "spiral": (b1s, b2s), "hk": hk, "c": cl, "ht": ht,
            "add": (a1, a2), "ded": ded, "dang": dang, "t": (t1, t2),
        }  # fmt: skip

    @staticmethod
    def _member(i: int) -> int:
        if i not in (1, 2):
            raise InputError("hypoid.member", i, "1 (pinion) or 2 (gear)")
        return i - 1

    # --- the pair ---
    @property
    def cones(self) -> HypoidPitchCones:
        """The solved pitch cones (plain data)."""
        return self._geo["cones"]

    @property
    def m21(self) -> float:
        """Nominal gear ratio ω2/ω1 = N1/N2."""
        return self.n1 / self.n2

    @property
    def offset_angle_pitch_plane(self) -> float:
        """ε' = β1 − β2, the angle between the pitch generatrices in the pitch plane (rad)."""
        return self.cones.offset_angle_pitch_plane

    @property
    def limit_pressure_angle(self) -> float:
        """α_lim (rad), ISO 23509's sign (module doc)."""
        return self.cones.limit_pressure_angle

    @property
    def limit_radius_mm(self) -> float:
        """ρ_lim (mm): equals ``cutter_radius_mm`` (the condition solved for)."""
        return self.cones.limit_radius_mm

    @property
    def edge_radius(self) -> float:
        """Blade edge radius (mm): ``edge_radius_mm`` or 0.25 m (as the spiral bevel)."""
        if self.edge_radius_mm is None:
            return EDGE_RADIUS_MODULES * self.module_mm
        return float(self.edge_radius_mm)

    @property
    def working_depth(self) -> float:
        return self._geo["hk"]

    @property
    def clearance(self) -> float:
        return self._geo["c"]

    @property
    def whole_depth(self) -> float:
        return self._geo["ht"]

    def pitch_point(self) -> Array:
        """Mean pitch point P (mm, mesh frame)."""
        return np.array(self.cones.point)

    def pitch_normal(self) -> Array:
        """Unit normal of the pitch plane at P, outward of the pinion cone."""
        return np.array(self.cones.normal)

    def tooth_trace(self) -> Array:
        """Unit tooth trace t at P, along the relative velocity, toe → heel."""
        return np.array(self.cones.trace)

    def gear_axis(self) -> tuple[Array, Array]:
        """``(A2, e2)``: the gear pitch apex and the unit gear axis towards the gear blank."""
        return np.array(self.cones.gear_apex), np.array(self.cones.gear_axis)

    def crossing_point(self) -> Array:
        """The point of the pinion axis nearest the gear axis (mm)."""
        return np.array(self.cones.crossing_point)

    # --- per member ---
    def pitch_angle(self, i: int) -> float:
        return self._geo["gamma"][self._member(i)]

    def pitch_apex(self, i: int) -> float:
        """Pitch apex beyond crossing point ``t_z,i`` (mm, Gleason/ISO sign: module doc)."""
        return self.cones.pitch_apexes_mm[self._member(i)]

    def outer_cone_distance(self, i: int) -> float:
        """A0_i: the heel's cone distance (mm)."""
        return self._geo["A0"][self._member(i)]

    def mean_cone_distance(self, i: int) -> float:
        """Rm_i: P's cone distance on member i's pitch cone (mm)."""
        return self._geo["Rm"][self._member(i)]

    def face_width(self, i: int) -> float:
        """F_i along the generatrix: the face runs from the toe ``A0_i − F_i`` to the heel."""
        return self._geo["F"][self._member(i)]

    def spiral_angle(self, i: int) -> float:
        """Mean spiral angle β_i at P (rad)."""
        return self._geo["spiral"][self._member(i)]

    def addendum(self, i: int) -> float:
        """Heel addendum a_i (mm)."""
        return self._geo["add"][self._member(i)]

    def dedendum(self, i: int) -> float:
        """Heel dedendum b_i (mm)."""
        return self._geo["ded"][self._member(i)]

    def dedendum_angle(self, i: int) -> float:
        """δ_fi = atan(b_i / A0_i) (rad)."""
        return self._geo["dang"][self._member(i)]

    def thickness_heel(self, i: int) -> float:
        """Heel transverse circular thickness of member i, zero backlash (mm)."""
        return self._geo["t"][self._member(i)]

    def pressure_angle(self, side: str) -> float:
        """Normal pressure angle (rad) of the gear's ``side`` flank at its mean point.

        ISO 23509:2016 §6.3: the generated pressure angles ``α_nD = α + f_αlim α_lim`` on the
        gear's convex flank (ISO's drive side) and ``α_nC = α − f_αlim α_lim`` on its concave
        flank, ``α_lim`` with ISO's sign (module doc of :mod:`.hypoid_cones`). fegear's drive
        flank is the gear's concave one (:mod:`.mesh_frame`): ``drive`` is ``α − f_αlim α_lim``,
        ``coast`` ``α + f_αlim α_lim``.
        """
        if side not in ("drive", "coast"):
            raise InputError("hypoid.side", side, "'drive' or 'coast'")
        shift = self.limit_pressure_angle_factor * self.limit_pressure_angle
        al = math.radians(self.pressure_angle_deg)
        return al - shift if side == "drive" else al + shift

    def root_cone_line(self, i: int) -> tuple[float, float]:
        """``(a, b)`` of member i's root cone ``h_R(L) = a + b L`` in its ``(L, h)`` plane
        (through member i's own pitch apex)."""
        k = self._member(i)
        td = math.tan(self._geo["dang"][k])
        return -self._geo["ded"][k] + self._geo["A0"][k] * td, -td

    def face_cone_line(self, i: int) -> tuple[float, float]:
        """``(a, b)`` of member i's face cone ``h_a(L) = a + b L`` (parallel clearance: the
        mate's dedendum angle)."""
        k = self._member(i)
        tj = math.tan(self._geo["dang"][1 - k])
        return self._geo["add"][k] - self._geo["A0"][k] * tj, tj

    def root_height(self, i: int, L: Array | float) -> Array:
        """Height ``h_R(L) = −b_i + (A0_i − L) tan δ_fi`` of member i's root cone (mm)."""
        k = self._member(i)
        L = np.asarray(L, dtype=float)
        return -self._geo["ded"][k] + (self._geo["A0"][k] - L) * math.tan(self._geo["dang"][k])

    def flank_heights(self, i: int, L: Array | float) -> tuple[Array, Array]:
        """``(h_w(L), h_a(L))`` of member i (mm): the mate's face cone (the clearance above the
        root cone) and member i's face cone, on member i's own cone (module doc)."""
        k = self._member(i)
        j = 1 - k
        A0 = self._geo["A0"][k]
        a, d = self._geo["add"], self._geo["dang"]
        L = np.asarray(L, dtype=float)
        return -a[j] + (A0 - L) * math.tan(d[k]), a[k] - (A0 - L) * math.tan(d[j])

    def half_tooth_angle(self, i: int) -> float:
        """Half the transverse tooth-thickness angle of member i at its mean point (rad)."""
        k = self._member(i)
        rm, a0 = self._geo["Rm"][k], self._geo["A0"][k]
        t = self._geo["t"][k] * rm / a0
        return 0.5 * t / (rm * math.sin(self._geo["gamma"][k]))

    # --- plain data ---
    def record(self) -> dict[str, Any]:
        """The blank as plain data (its input fields); :meth:`from_record` rebuilds it."""
        rec: dict[str, Any] = {"format": RECORD_FORMAT}
        rec.update({f.name: getattr(self, f.name) for f in fields(self) if f.init})
        return rec

    @classmethod
    def from_record(cls, rec: dict[str, Any]) -> HypoidBlank:
        """The blank of a :meth:`record`. Raises :class:`InputError` on another format."""
        if rec.get("format") != RECORD_FORMAT:
            raise InputError("hypoid record format", rec.get("format"), RECORD_FORMAT)
        names = {f.name for f in fields(cls) if f.init}
        return cls(**{k: v for k, v in rec.items() if k in names})
