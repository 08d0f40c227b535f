"""Machine settings as a summary sheet gives them, and the settings of fegear's machine.

A bevel-gear summary sheet lists, per member and flank, the cutter (blade angle, blade point
radius, edge radius, blade curvature) and the machine settings (radial, cradle angle, machine
root angle, blank offset, sliding base, machine centre to back, ratio of roll and its
modifications). :class:`FlankTable` holds one flank's in mm and degrees
(:mod:`fegear.io.machine_table` reads them from a case file in mm/deg or inch/deg-min);
:func:`settings_from_tables` turns four of them into the :class:`~.machine.MachineSettings` of
fegear's machine (:mod:`.machine`), :func:`flank_table` is the way back.

Conventions of the sheet here (fegear's machine, :mod:`.machine`):

* the blade tips (the point plane, which the edge radius touches) lie in the cradle plane
  ``z_m = 0``; the blade has radius ``blade_radius_mm`` at ``blade_height_mm`` above its tip
  (0: the point radius), blade angle ``blade_angle_deg`` to the cutter axis there and the
  parabolic deviation ``parabola_per_mm · s²`` at a distance ``s`` along the blade from there;
* ``radial_mm``, ``cradle_angle_deg``: the cutter centre on the cradle, polar, at ψ = 0;
  ``machine_root_angle_deg``, ``blank_offset_mm``, ``sliding_base_mm`` and
  ``machine_center_to_apex_mm`` (X_D: from the machine centre to the member's pitch apex along
  the work axis: a sheet's machine centre to back less the member's pitch apex to back)
  place the work; ``ratio_of_roll`` is ω_work/ω_cradle; ``modified_roll_2C`` and
  ``modified_roll_6D`` are the coefficients of ``φ(ψ) = −m (ψ − 2C ψ²/2 − 6D ψ³/6)``
  (:class:`~.machine.MachineSettings` ``modified_roll``, ``modified_roll_third``);
* the angular position of each flank on its member (which a sheet does not give: it is set
  when the flanks are cut) puts its mean point at half the design tooth thickness from the
  tooth centre, as for synthesized settings (:func:`settings_from_tables`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

from ...errors import InputError
from ..generation import generate
from .machine import MachineSettings, SpiralBevelSettings, point_plane
from .member import SpiralBevelMember

__all__ = ["FLANKS", "FlankTable", "flank_table", "settings_from_tables"]

#: The four flank tables of a pair: ``member_side``.
FLANKS = ("gear_drive", "gear_coast", "pinion_drive", "pinion_coast")


@dataclass(frozen=True)
class FlankTable:
    """One flank's cutter and machine settings as a summary sheet gives them (mm, deg; module
    doc). ``blade`` is ``"outside"`` (cuts a concave flank) or ``"inside"`` (convex)."""

    blade: str
    blade_angle_deg: float
    blade_radius_mm: float
    edge_radius_mm: float
    radial_mm: float
    cradle_angle_deg: float
    machine_root_angle_deg: float
    ratio_of_roll: float
    blade_height_mm: float = 0.0
    parabola_per_mm: float = 0.0
    blank_offset_mm: float = 0.0
    sliding_base_mm: float = 0.0
    machine_center_to_apex_mm: float = 0.0
    modified_roll_2C: float = 0.0
    modified_roll_6D: float = 0.0

    def machine_settings(self, flank: str) -> MachineSettings:
        """The :class:`~.machine.MachineSettings` of this flank (``flank`` = ``member_side``),
        tool and blank phases 0 (:func:`settings_from_tables` sets the blank phase).

        Raises :class:`~fegear.errors.InputError` naming ``machine.<flank>.<key>``.
        """
        member, side = flank.split("_")
        sg = 1.0 if self.blade == "outside" else -1.0
        al = math.radians(self.blade_angle_deg)
        try:
            return MachineSettings(
                member=member, side=side, blade=self.blade,
                cutter_radius_mm=self.blade_radius_mm, blade_angle_deg=self.blade_angle_deg,
                point_radius_mm=self.blade_radius_mm - sg * self.blade_height_mm * math.tan(al),
                parabola_per_mm=self.parabola_per_mm, edge_radius_mm=self.edge_radius_mm,
                radial_setting_mm=self.radial_mm, cradle_angle_deg=self.cradle_angle_deg,
                ref_height_mm=self.blade_height_mm, tool_phase_deg=0.0,
                machine_root_angle_deg=self.machine_root_angle_deg,
                blank_offset_mm=self.blank_offset_mm, sliding_base_mm=self.sliding_base_mm,
                machine_center_to_back_mm=self.machine_center_to_apex_mm, blank_phase_deg=0.0,
                ratio_of_roll=self.ratio_of_roll, modified_roll=self.modified_roll_2C,
                modified_roll_third=self.modified_roll_6D, point_plane_mm=-self.blade_height_mm,
            )  # fmt: skip
        except InputError as exc:
            key = {"cutter_radius_mm": "blade_radius_mm"}.get(exc.field.split(".")[-1])
            key = key or exc.field.split(".")[-1]
            raise InputError(f"machine.{flank}.{key}", exc.value, exc.allowed) from exc


def flank_table(blank, i: int, ms: MachineSettings) -> FlankTable:
    """The summary-sheet table of the settings ``ms`` of member ``i`` (1 pinion, 2 gear): the
    same flank, with the blade tips moved into the cradle plane (a shift of the tool along the
    cradle axis is a shift of the work the other way: the sliding base)."""
    zp = ms.point_plane_mm if ms.point_plane_mm is not None else point_plane(blank, i, ms)
    tip = ms.ref_height_mm + zp  # z_m of the blade tips
    radius, height = ms.cutter_radius_mm, -zp
    if ms.parabola_per_mm == 0.0:  # a straight blade: its radius at the tip, the point radius
        sg = 1.0 if ms.blade == "outside" else -1.0
        radius, height = radius - sg * height * math.tan(math.radians(ms.blade_angle_deg)), 0.0
    slide = ms.sliding_base_mm - tip
    return FlankTable(
        blade=ms.blade, blade_angle_deg=ms.blade_angle_deg, blade_radius_mm=radius,
        edge_radius_mm=ms.edge_radius_mm, radial_mm=ms.radial_setting_mm,
        cradle_angle_deg=ms.cradle_angle_deg, machine_root_angle_deg=ms.machine_root_angle_deg,
        ratio_of_roll=ms.ratio_of_roll, blade_height_mm=height, parabola_per_mm=ms.parabola_per_mm,
        blank_offset_mm=ms.blank_offset_mm, sliding_base_mm=0.0 if abs(slide) < 1e-9 else slide,
        machine_center_to_apex_mm=ms.machine_center_to_back_mm,
        modified_roll_2C=ms.modified_roll, modified_roll_6D=ms.modified_roll_third,
    )  # fmt: skip


def settings_from_tables(blank, tables: dict[str, FlankTable]) -> SpiralBevelSettings:
    """The four flanks' :class:`~.machine.MachineSettings` from their sheet tables.

    Each flank's blank phase is set so that its mean point (:meth:`SpiralBevelMember.reference`,
    cone distance ``Rm`` on the pitch cone) lies at the polar angle ``±ψ_t`` of half the design
    tooth thickness (:meth:`~.blank.SpiralBevelBlank.half_tooth_angle`), on the side of the
    tooth its normal faces: turning the work by ``δ`` at ψ = 0 turns the generated flank by
    ``−δ`` about the member axis.

    Raises
    ------
    InputError
        A table missing (``machine.<flank>``) or a setting out of its range.
    DesignError
        Settings whose cutter does not cut the flank through its mean point, naming the table.
    """
    for flank in FLANKS:
        if flank not in tables:
            raise InputError(f"machine.{flank}", "missing", "a table of this flank's settings")
    ms = {f: tables[f].machine_settings(f) for f in FLANKS}
    for i, name in ((1, "pinion"), (2, "gear")):
        m = SpiralBevelMember(name, i, (blank.n1, blank.n2)[i - 1], blank,
                              ms[f"{name}_drive"], ms[f"{name}_coast"])  # fmt: skip
        for side in ("drive", "coast"):
            tool, mot = m._tools(side)
            env = generate(tool, mot, *m.reference(side), half_width=0.3)
            p, n = env.points, env.normals
            phi = math.atan2(p[1], p[0])
            faces = math.copysign(1.0, -math.sin(phi) * n[0] + math.cos(phi) * n[1])
            delta = faces * blank.half_tooth_angle(i) - phi
            f = f"{name}_{side}"
            ms[f] = replace(ms[f], blank_phase_deg=ms[f].blank_phase_deg - math.degrees(delta))
    return SpiralBevelSettings(**ms)


def table_fields() -> tuple[str, ...]:
    """The field names of :class:`FlankTable` (the case-file keys without their units)."""
    return tuple(f.name for f in fields(FlankTable))
