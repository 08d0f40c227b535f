"""The validity range of the loaded model, and the checks that say when a result leaves it.

The loaded tooth contact analysis is linear elastic, small-deformation and frictionless
(docs/ltca/validity.md): the gaps, normals and moment arms are those of the unloaded flanks,
the compliance is that of the undeformed bodies, and the material never yields. A result is
still computed outside that range (the equations have a solution at any load), but it no
longer describes the gears. Each check compares one number of the result with its limit:

``approach_over_module``
    The largest elastic approach of a loaded pair, ``θ h`` (the lag of member 2 times the
    moment arm of the pair's normal: the normal displacement the deformation takes up at the
    contact), as a fraction of the module. Limit :data:`APPROACH_LIMIT` = 2 %: the contact
    normals and moment arms are the unloaded ones, and the deformed tooth turns by about its
    deflection over its height (about 2.25 modules), so at 2 % of the module the normals have
    turned by about 0.5° and the moment arms, separations and load shares are in error by about
    1 %, the order of the model's own discretisation error.
``p_max_over_steel_limit``
    The cycle's p_max away from the edges (the headline). Limit :data:`P_ELASTIC_LIMIT_MPA` =
    4000 MPa: the largest Hertz pressure that hardened bearing steel (58-64 HRC) carries with a
    permanent deformation of 1e-4 of the rolling element's diameter, the basis of the static
    load rating of roller bearings (ISO 76; 4200 MPa for ball bearings). A case-hardened gear
    flank has about that hardness; beyond it the flank deforms plastically and the elastic
    pressures are not the gears'. The edge values are left out: the pressure at a sharp flank
    edge is singular in a linear model, beyond any limit at any load (and grid-dependent), so
    it says nothing about the load; nor is the mean pressure of an edge patch a measure (a
    corner contact one cell wide reads 12 GPa on FZG at 800 N·m, the cell's, not the contact's).
``patch_spans_flank``
    The positions where a loaded patch runs over the whole active profile (its cells reach the
    boundary at the pinion's tip or the gear's root and the one at the pinion's root or the
    gear's tip), or, on the face gear and the spiral bevel (localized contact by design), over
    the whole face width (both face ends of one member). Limit 0 positions: the contact
    solution assumes a patch small against the tooth (the half-space near field of ``hybrid``,
    the Hertz laws of ``hertz``); a patch as large as the flank is a conformal, tooth-sized
    contact, and the load has left the flank it was designed for.

A check that cannot be evaluated (no p_max away from the edges; no contact cells at
``hertz``) has ``value`` None and is not exceeded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fegear.errors import InputError
from fegear.ltca.results import LoadedCycle

__all__ = [
    "APPROACH_LIMIT",
    "P_ELASTIC_LIMIT_MPA",
    "ValidityCheck",
    "validity_checks",
]

#: Largest elastic approach at a contact, as a fraction of the module (module docstring).
APPROACH_LIMIT = 0.02
#: Largest contact pressure hardened steel carries elastically, MPa (ISO 76: module docstring).
P_ELASTIC_LIMIT_MPA = 4000.0
#: Gear kinds whose contact is localized by design (a patch over the whole face width is out of
#: range for them; a spur pair's line contact runs over the face width by design).
LOCALIZED = ("face_gear", "spiral_bevel", "hypoid")

# EDGE_TAGS bits (fegear.ltca.grid): the two ends of the active profile on the pinion's flank,
# and the face ends of each member.
_PROFILE_TOP = (1 << 1) | (1 << 4)  # pinion tip, gear root
_PROFILE_BOTTOM = (1 << 0) | (1 << 5)  # pinion root, gear tip
_FACE_ENDS = ((1 << 2) | (1 << 3), (1 << 6) | (1 << 7))  # pinion, gear


@dataclass(frozen=True)
class ValidityCheck:
    """One check of the validity range (module docstring).

    Attributes
    ----------
    name
        ``"approach_over_module"``, ``"p_max_over_steel_limit"`` or ``"patch_spans_flank"``.
    value, limit, unit
        The number and its limit (``value`` None: not evaluated, ``reason`` why).
    exceeded
        ``value > limit``.
    positions
        The positions where the limit is exceeded.
    text
        One line for the terminal, "" when not exceeded.
    reason
        Why the value is None ("" otherwise).
    """

    name: str
    value: float | None
    limit: float
    unit: str
    exceeded: bool
    positions: tuple[int, ...] = ()
    text: str = ""
    reason: str = ""

    def as_dict(self) -> dict[str, Any]:
        """The ``summary.json`` record (``validity.checks[i]``)."""
        return {
            "name": self.name,
            "value": self.value,
            "limit": self.limit,
            "unit": self.unit,
            "exceeded": self.exceeded,
            "positions": list(self.positions),
            "reason": self.reason,
        }


def _approach(cycle: LoadedCycle, module_mm: float) -> ValidityCheck:
    """``max θ h / m`` over the loaded pairs (``h = torque / force`` of the pair)."""
    ratio = np.zeros(len(cycle.positions))
    for i, p in enumerate(cycle.positions):
        for q in p.pairs:
            if q.in_contact:
                ratio[i] = max(ratio[i], p.theta * q.torque_Nmm / q.force_N / module_mm)
    value = float(ratio.max()) if ratio.size else 0.0
    over = tuple(int(i) for i in np.flatnonzero(ratio > APPROACH_LIMIT))
    text = ""
    if over:
        i = int(np.argmax(ratio))
        text = (
            f"outside the model's validity range: the elastic approach at the contact is "
            f"{100 * value:.3g} % of the module ({value * module_mm:.4g} mm at position {i}; "
            f"limit {100 * APPROACH_LIMIT:g} %) at {len(over)} of {ratio.size} positions: the "
            "small-deformation model (unloaded normals and moment arms) does not hold "
            "(summary.json: validity)"
        )
    return ValidityCheck(
        "approach_over_module", value, APPROACH_LIMIT, "module", bool(over), over, text
    )


def _pressure(cycle: LoadedCycle, p_max_MPa: float | None, where: int | None) -> ValidityCheck:
    """The headline p_max against the elastic limit of hardened steel."""
    lim = P_ELASTIC_LIMIT_MPA
    if p_max_MPa is None:
        why = "no p_max away from the edges (the edge values are singular: not a measure)"
        return ValidityCheck("p_max_over_steel_limit", None, lim, "MPa", False, reason=why)
    over = tuple(
        i
        for i, p in enumerate(cycle.positions)
        if p.status == "ok"
        and any(q.p_interior_MPa is not None and q.p_interior_MPa > lim for q in p.pairs)
    )
    text = ""
    if p_max_MPa > lim:
        text = (
            f"outside the model's validity range: p_max {p_max_MPa:.4g} MPa (position {where}) "
            f"is beyond the {lim:.0f} MPa hardened steel carries elastically (ISO 76), at "
            f"{len(over)} of {len(cycle.positions)} positions: the flanks deform plastically, "
            "the linear elastic pressures are not the gears' (summary.json: validity)"
        )
    return ValidityCheck(
        "p_max_over_steel_limit", float(p_max_MPa), lim, "MPa", p_max_MPa > lim, over, text
    )


def _spans(mask: int, localized: bool) -> bool:
    if mask & _PROFILE_TOP and mask & _PROFILE_BOTTOM:
        return True
    return localized and any(mask & ends == ends for ends in _FACE_ENDS)


def _patch(cycle: LoadedCycle, localized: bool) -> ValidityCheck:
    """The positions where a loaded patch spans the active profile (or the face width)."""
    if not any(p.cells for p in cycle.positions):
        return ValidityCheck(
            "patch_spans_flank",
            None,
            0.0,
            "positions",
            False,
            reason="no contact cells at this fidelity",
        )
    over = []
    for i, p in enumerate(cycle.positions):
        for c, pr in zip(p.cells, p.pressure, strict=True):
            if c.boundary_edges is None or not np.any(pr > 0.0):
                continue
            mask = int(np.bitwise_or.reduce(c.boundary_edges[pr > 0.0]))
            if _spans(mask, localized):
                over.append(i)
                break
    text = ""
    if over:
        what = "the whole active profile" + (" or face width" if localized else "")
        text = (
            f"outside the model's validity range: a loaded patch runs over {what} at "
            f"{len(over)} of {len(cycle.positions)} positions (limit 0): the contact is no "
            "longer small against the tooth (summary.json: validity)"
        )
    return ValidityCheck(
        "patch_spans_flank", float(len(over)), 0.0, "positions", bool(over), tuple(over), text
    )


def validity_checks(
    cycle: LoadedCycle,
    module_mm: float,
    kind: str,
    p_max_MPa: float | None,
    p_max_position: int | None = None,
) -> tuple[ValidityCheck, ...]:
    """The checks of the validity range (module docstring) of a loaded ``cycle``.

    Parameters
    ----------
    cycle
        The loaded cycle.
    module_mm
        The pair's module (mm; the case's ``module_mm``).
    kind
        The gear kind (``"spur"``, ``"face_gear"``, ``"spiral_bevel"``): localized contact by
        design or not (:data:`LOCALIZED`).
    p_max_MPa, p_max_position
        The cycle's headline p_max away from the edges (None if not reported) and where.
    """
    if not (math.isfinite(module_mm) and module_mm > 0.0):
        raise InputError("module_mm", module_mm, "a finite number > 0")
    return (
        _approach(cycle, module_mm),
        _pressure(cycle, p_max_MPa, p_max_position),
        _patch(cycle, kind in LOCALIZED),
    )
