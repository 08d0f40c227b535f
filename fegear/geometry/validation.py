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
    if inv_radius(ra) <= 0:
        lo, hi = rb, ra  # bisection for the pointed radius
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if inv_radius(mid) > 0 else (lo, mid)
        raise DesignError(
            "tip_radius_mm", ra, f"< {lo:.4f} mm (pointed-tooth radius)",
            f"pointed tooth: tip radius exceeds the pointed radius by {ra - lo:.4f} mm",
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
