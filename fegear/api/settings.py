"""The machine settings of a bevel case, as the ``[machine]`` tables of a case file."""

from __future__ import annotations

from fegear import __version__
from fegear.errors import InputError
from fegear.geometry.bevel.sheet import FLANKS, FlankTable, flank_table
from fegear.io.gear_case import BEVEL_KINDS, GearCase
from fegear.io.machine_table import format_machine
from fegear.pipeline.pair import build_pair

__all__ = ["machine_tables", "machine_sheet"]


def machine_tables(case: GearCase) -> dict[str, FlankTable]:
    """The machine settings that cut the flanks of a bevel ``case`` (synthesized, or the
    case's ``[machine]`` tables), one :class:`~fegear.geometry.bevel.sheet.FlankTable` per
    flank (mm, deg; the blade tips in the cradle plane).

    Raises :class:`~fegear.errors.InputError` for a case of another kind."""
    if getattr(case, "kind", None) not in BEVEL_KINDS:
        raise InputError("case.kind", getattr(case, "kind", None), f"one of {BEVEL_KINDS}")
    pair = build_pair(case).spiral_bevel
    member = {"pinion": 1, "gear": 2}
    return {
        f: flank_table(pair.blank, member[f.split("_")[0]], pair.settings.get(*f.split("_")))
        for f in FLANKS
    }


def machine_sheet(case: GearCase, units: str = "mm") -> str:
    """:func:`machine_tables` as the ``[machine.<flank>]`` TOML of a case file, in ``units``
    ``"mm"`` (mm, decimal degrees) or ``"in"`` (inches, degrees-minutes)."""
    how = "as given in the case" if case.machine is not None else "synthesized by fegear"
    title = f"machine settings of {case.name!r} ({case.source}), {how}; fegear {__version__}"
    return format_machine(machine_tables(case), units, title)
