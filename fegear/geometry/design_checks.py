"""Design-data validation for the gear families.

Every check raises :class:`~fegear.errors.InputError` (a value outside its plain range) or
:class:`~fegear.errors.DesignError` (data that cannot make a valid tooth: undercut, pointed tooth,
impossible ratio), naming the field, the value and the allowed range.

Stated ranges (a design outside them is refused, not extrapolated):

- tooth counts: integers, ``n_teeth >= 4``; face gear ``N2 > N_s > N1`` (localized contact needs
  ``N_s > N1``; a face gear needs more teeth than its shaper);
- pressure angle 10°–35° (normal section); helix angle ``|β| <= 45°``;
- profile shift ``-1 <= x <= 2`` before the undercut/pointing checks;
- lengths (module, face width, radii, coefficients of addendum/dedendum/rack tip radius) ``> 0``;
  modifications ``>= 0``.

Geometric limits, each refused naming the field that crosses it, with the computed limit:

- involute member: undercut (``profile_shift >= x_min``), pointed tip (``profile_shift <= x_max``
  where the transverse tooth thickness vanishes at the tip circle; ``tip_radius_mm`` when the tip
  radius is given);
- involute pair (:func:`validate_involute_pair`): tip clearance at the zero-backlash working
  centre distance, ``c = a_w − r_a1 − r_f2 >= 0`` (and the same for the gear tip); a shift sum
  beyond the limit pushes the tips into the roots (``pair.profile_shift``: ``x1 + x2 <= X``);
- face gear: the undercut and pointing radii of the generated tooth
  (:meth:`fegear.geometry.face_gear.FaceGearMember.check_limits`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..errors import DesignError, InputError

if TYPE_CHECKING:
    from .face_gear import FaceGearDesign
    from .involute import InvoluteDesign

__all__ = [
    "check_positive",
    "check_nonnegative",
    "check_range",
    "check_teeth",
    "validate_involute",
    "validate_face_gear",
    "validate_involute_pair",
    "PRESSURE_ANGLE_RANGE_DEG",
]

PRESSURE_ANGLE_RANGE_DEG = (10.0, 35.0)


def check_positive(field: str, value: float) -> None:
    """``value > 0`` and finite, else InputError."""
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise InputError(field, value, "> 0 (finite)")


def check_nonnegative(field: str, value: float) -> None:
    """``value >= 0`` and finite, else InputError."""
    if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
        raise InputError(field, value, ">= 0 (finite)")


def check_range(field: str, value: float, lo: float, hi: float, unit: str = "") -> None:
    """``lo <= value <= hi``, else InputError."""
    if not (isinstance(value, int | float) and math.isfinite(value) and lo <= value <= hi):
        raise InputError(field, value, f"in [{lo:g}, {hi:g}]{unit}")


def check_teeth(field: str, value: int, minimum: int = 4) -> None:
    """An integer tooth count ``>= minimum``."""
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise InputError(field, value, f"an integer >= {minimum}")


def validate_involute(d: InvoluteDesign) -> None:
    """Plain ranges, then undercut (rack straight flank below the interference point) and a
    pointed tip (zero transverse tooth thickness at or below the tip radius)."""
    check_teeth("n_teeth", d.n_teeth)
    check_positive("module_mm", d.module_mm)
    check_range("pressure_angle_deg", d.pressure_angle_deg, *PRESSURE_ANGLE_RANGE_DEG, " deg")
    check_range("helix_angle_deg", d.helix_angle_deg, -45.0, 45.0, " deg")
    check_range("profile_shift", d.profile_shift, -1.0, 2.0)
    for f in ("addendum_coeff", "dedendum_coeff", "rack_tip_radius_coeff", "face_width_mm"):
        check_positive(f, getattr(d, f))
    for f in ("profile_crowning_mm", "lead_crowning_mm", "tip_relief_mm"):
        check_nonnegative(f, getattr(d, f))
    m, an = d.module_mm, math.radians(d.pressure_angle_deg)
    rho = d.rack_tip_radius_coeff * m
    # the rack tip arc must fit in half the rack tooth (centre at or left of the tooth centreline)
    hc = -d.dedendum_coeff * m + rho
    sc = math.pi * m / 4 - (hc - rho * math.sin(an)) * math.tan(an) + rho * math.cos(an)
    if sc > math.pi * m / 2:
        rho_max = _max_rack_tip_radius(d)
        raise DesignError(
            "rack_tip_radius_coeff", d.rack_tip_radius_coeff, f"<= {rho_max / m:.4f}",
            "the rack tip arcs of the two flanks overlap",
        )  # fmt: skip
    beta = math.radians(d.helix_angle_deg)
    at = math.atan(math.tan(an) / math.cos(beta))
    r = m * d.n_teeth / (2 * math.cos(beta))
    rb = r * math.cos(at)
    # undercut: lowest straight-flank point of the rack below the interference point
    h_low = hc - rho * math.sin(an)
    x_min = (-r * math.sin(at) ** 2 - h_low) / m
    if d.profile_shift < x_min - 1e-12:
        raise DesignError(
            "profile_shift", d.profile_shift, f">= {x_min:.4f}",
            f"undercut: rack flank reaches {(x_min - d.profile_shift) * m:.4f} mm "
            "below the interference point",
        )  # fmt: skip
    ra = (
        d.tip_radius_mm
        if d.tip_radius_mm is not None
        else r + m * (d.addendum_coeff + d.profile_shift)
    )
    check_positive("tip_radius_mm", ra)
    # half tooth angle at the base circle: s_t/(2r) + inv α_t, s_t = m_n (π/2 + 2x tan α_n)/cos β
    half = (math.pi / 2 + 2 * d.profile_shift * math.tan(an)) / d.n_teeth + (math.tan(at) - at)

    def inv_radius(rr: float) -> float:
        ay = math.acos(min(1.0, rb / rr))
        return half - (math.tan(ay) - ay)

    if ra <= rb:
        raise DesignError("tip_radius_mm", ra, f"> base radius {rb:.4f} mm")
    if inv_radius(ra) <= 0 and d.tip_radius_mm is None:
        # the tip radius follows from the shift: the limit is the shift of a pointed tip
        x_max = _pointed_shift(d)
        raise DesignError(
            "profile_shift", d.profile_shift, f"<= {x_max:.4f} (pointed tip beyond)",
            "pointed tooth: the transverse tooth thickness vanishes below the tip circle "
            f"r_a = {ra:.4f} mm",
        )  # fmt: skip
    if inv_radius(ra) <= 0:
        lo, hi = rb, ra  # bisection for the pointed radius
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if inv_radius(mid) > 0 else (lo, mid)
        raise DesignError(
            "tip_radius_mm", ra, f"< {lo:.4f} mm (pointed-tooth radius)",
            f"pointed tooth: tip radius exceeds the pointed radius by {ra - lo:.4f} mm",
        )  # fmt: skip


def _tip_half_angle(d: InvoluteDesign, x: float) -> float:
    """Half the transverse tooth angle at the tip circle of ``d`` with profile shift ``x`` (rad;
    ``<= 0``: pointed): ``ψ_a = (π/2 + 2x tan α_n)/z + inv α_t − inv α_a``, ``r_a = r + m(h_a
    + x)``."""
    m, an = d.module_mm, math.radians(d.pressure_angle_deg)
    beta = math.radians(d.helix_angle_deg)
    at = math.atan(math.tan(an) / math.cos(beta))
    r = m * d.n_teeth / (2 * math.cos(beta))
    rb = r * math.cos(at)
    ra = r + m * (d.addendum_coeff + x)
    aa = math.acos(min(1.0, rb / ra))
    return (
        (math.pi / 2 + 2 * x * math.tan(an)) / d.n_teeth + (math.tan(at) - at) - (math.tan(aa) - aa)
    )


def _pointed_shift(d: InvoluteDesign) -> float:
    """The profile shift at which the tip of ``d`` becomes pointed (bisection to 1e-12: the
    tip half angle decreases with the shift, which moves the tip circle out faster than it
    thickens the tooth)."""
    lo, hi = -1.0, max(2.0, d.profile_shift)  # the allowed range of the shift
    if _tip_half_angle(d, lo) <= 0 or _tip_half_angle(d, hi) > 0:
        return lo if _tip_half_angle(d, lo) <= 0 else hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _tip_half_angle(d, mid) > 0 else (lo, mid)
        if hi - lo < 1e-12:
            break
    return lo


def working_pressure_angle(x_sum: float, z_sum: int, an: float, at: float) -> float:
    """Transverse working pressure angle of zero backlash (rad): ``inv α_w = inv α_t +
    2 tan α_n (x1 + x2)/(z1 + z2)`` (ISO 21771), Newton on ``tan α − α``."""
    y = math.tan(at) - at + 2 * math.tan(an) * x_sum / z_sum
    a = (3.0 * y) ** (1.0 / 3.0) if y > 0 else 1e-3
    for _ in range(60):
        f = math.tan(a) - a - y
        a -= f / math.tan(a) ** 2
        if abs(f) < 1e-16:
            break
    return a


def validate_involute_pair(d1: InvoluteDesign, d2: InvoluteDesign) -> None:
    """Tip clearance of an external involute pair at its zero-backlash working centre distance
    ``a_w = (r1 + r2) cos α_t / cos α_w``: ``c_1 = a_w − r_a1 − r_f2 >= 0`` (pinion tip over the
    gear root) and ``c_2 = a_w − r_a2 − r_f1 >= 0``. With ``r_a = r + m(h_a + x)`` and
    ``r_f = r − m(h_f − x)`` both are ``m (y − (x1 + x2) + h_f − h_a)``, ``y = (a_w − a)/m``:
    a positive shift sum moves the axes apart by less than it lengthens the teeth (ISO 21771's
    tip shortening ``k``). A negative clearance is refused naming ``profile_shift`` with the
    largest shift sum that clears (or the addendum coefficient when no shift sum would)."""
    if d1.tip_radius_mm is not None or d2.tip_radius_mm is not None:
        return  # given tip radii: the assembly's own clearance check names them
    m, an = d1.module_mm, math.radians(d1.pressure_angle_deg)
    beta = math.radians(d1.helix_angle_deg)
    at = math.atan(math.tan(an) / math.cos(beta))
    zs = d1.n_teeth + d2.n_teeth
    a = m * zs / (2 * math.cos(beta))
    spare = min(d2.dedendum_coeff - d1.addendum_coeff, d1.dedendum_coeff - d2.addendum_coeff)

    def clearance(xs: float) -> float:  # mm, the smaller of the two
        aw = a * math.cos(at) / math.cos(working_pressure_angle(xs, zs, an, at))
        return (aw - a) - m * xs + m * spare

    xs = d1.profile_shift + d2.profile_shift
    c = clearance(xs)
    if c >= 0.0:
        return
    if clearance(0.0) < 0.0 or xs <= 0.0:
        raise DesignError(
            "addendum_coeff", [d1.addendum_coeff, d2.addendum_coeff],
            "an addendum that leaves a tip clearance",
            f"tip/root interference: the tips run {-c:.4f} mm into the mate's root at the "
            "working centre distance",
        )  # fmt: skip
    lo, hi = 0.0, xs  # clearance(lo) >= 0 > clearance(hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if clearance(mid) >= 0.0 else (lo, mid)
        if hi - lo < 1e-12:
            break
    raise DesignError(
        "profile_shift", [d1.profile_shift, d2.profile_shift], f"a sum x1 + x2 <= {lo:.4f}",
        f"tip/root interference: with x1 + x2 = {xs:g} the tips run {-c:.4f} mm into the mate's "
        f"root at the zero-backlash centre distance {a + (clearance(xs) - m * spare + m * xs):.4f}"
        " mm (a larger shift sum needs shorter tips)",
    )  # fmt: skip


def _max_rack_tip_radius(d: InvoluteDesign) -> float:
    """Largest rack tip radius whose arc centre stays on the rack tooth centreline side."""
    m, an = d.module_mm, math.radians(d.pressure_angle_deg)
    # sc(ρ) = πm/4 + h_f m tanα + ρ (cos α − (1 − sin α) tan α) = πm/2
    k = math.cos(an) - (1 - math.sin(an)) * math.tan(an)
    return (math.pi * m / 4 - d.dedendum_coeff * m * math.tan(an)) / k


def validate_face_gear(d: FaceGearDesign) -> None:
    """Plain ranges of a face-gear design (the undercut/pointing limits are checked by the
    member, which needs the generated surface)."""
    check_teeth("n_face_gear", d.n_face_gear)
    check_teeth("n_pinion", d.n_pinion)
    ns = d.n_shaper
    check_teeth("n_shaper", ns)
    if ns <= d.n_pinion:
        raise DesignError(
            "n_shaper", ns, f"> n_pinion = {d.n_pinion} (typically n_pinion + 1…3)",
            "a shaper with no more teeth than the pinion gives line contact or interference",
        )  # fmt: skip
    if d.n_face_gear <= ns:
        raise DesignError("n_face_gear", d.n_face_gear, f"> n_shaper = {ns}")
    check_positive("module_mm", d.module_mm)
    check_range("pressure_angle_deg", d.pressure_angle_deg, *PRESSURE_ANGLE_RANGE_DEG, " deg")
    check_range("shaft_angle_deg", d.shaft_angle_deg, 45.0, 135.0, " deg")
    for f in ("inner_radius_mm", "outer_radius_mm", "pinion_face_width_mm", "blank_thickness_mm"):
        check_positive(f, getattr(d, f))
    for f in ("addendum_coeff", "dedendum_coeff"):
        check_positive(f, getattr(d, f))
    if d.outer_radius_mm <= d.inner_radius_mm:
        raise InputError(
            "outer_radius_mm", d.outer_radius_mm, f"> inner_radius_mm = {d.inner_radius_mm}"
        )
