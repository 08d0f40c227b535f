"""The ``[machine]`` section of a bevel case: machine settings per member and flank.

A bevel or hypoid case may give the machine settings that cut its flanks instead of having them
synthesized: four tables ``[machine.gear_drive]``, ``[machine.gear_coast]``,
``[machine.pinion_drive]``, ``[machine.pinion_coast]``, each the settings of one flank as a
summary sheet prints them (:class:`~fegear.geometry.bevel.sheet.FlankTable`, whose docstring
and module give the conventions). The unit is in each key, as everywhere in a case file, in
either of the two systems sheets are printed in:

* lengths ``<key>_mm`` or ``<key>_in`` (inches, 25.4 mm);
* angles ``<key>_deg`` (decimal degrees) or ``<key>_degmin`` (degrees and minutes: a string
  ``"58 36.5"``, ``"58°36.5'"``, ``"-2 05"``, or a pair ``[58, 36.5]``);
* a blade parabola ``parabola_per_mm`` or ``parabola_per_in`` (1/mm, 1/in);
* ``ratio_of_roll``, ``modified_roll_2C`` (1/rad), ``modified_roll_6D`` (1/rad²) and
  ``blade`` (``"outside"`` | ``"inside"``) without a unit.

A key given in both units, a unit that is neither (``radial_cm``: the closest keys are
suggested), a missing required setting, a value out of its range, a tilt, swivel or helical
motion other than 0 (fegear's machine has the cutter axis parallel to the cradle axis and no
helical motion) are refused with an :class:`~fegear.errors.InputError` naming
``machine.<flank>.<key>``.
"""

from __future__ import annotations

import difflib
import math
import re
from typing import Any

from fegear.errors import InputError
from fegear.geometry.bevel.sheet import FLANKS, FlankTable

__all__ = ["MACHINE_KEYS", "parse_machine", "reference_markdown"]

INCH = 25.4
_LEN = {"mm": 1.0, "in": INCH}
_INV = {"per_mm": 1.0, "per_in": 1.0 / INCH}

#: ``name: (kind, required, doc, allowed range (lo, hi, open ends) in mm/deg, or None)``
MACHINE_KEYS: dict[str, tuple[str, bool, str, tuple | None]] = {
    "blade": ("choice", True, "blade: 'outside' (cuts a concave flank) or 'inside' (convex)", None),
    "blade_angle": ("angle", True, "blade angle to the cutter axis", (0.0, 60.0, True)),
    "blade_radius": ("length", True, "blade radius at blade_height above the blade tip "
                     "(at the tip: the point radius)", (0.0, None, True)),
    "blade_height": ("length", False, "height above the blade tip of blade_radius and of the "
                     "parabola's vertex (default 0)", (0.0, None, False)),
    "parabola": ("inverse", False, "blade parabola coefficient (profile crowning, default 0)",
                 (0.0, None, False)),
    "edge_radius": ("length", True, "blade edge (tip) radius", (0.0, None, True)),
    "radial": ("length", True, "radial setting (cutter centre to cradle axis)", (0.0, None, True)),
    "cradle_angle": ("angle", True, "cradle angle of the cutter centre", (-180.0, 180.0, False)),
    "machine_root_angle": ("angle", True, "machine root angle", (-90.0, 90.0, True)),
    "blank_offset": ("length", False, "blank offset (default 0)", None),
    "sliding_base": ("length", False, "sliding base (default 0)", None),
    "machine_center_to_apex": ("length", False, "machine centre to the member's pitch apex "
                               "along the work axis (default 0)", None),
    "ratio_of_roll": ("number", True, "ratio of roll ω_work/ω_cradle", (0.0, None, True)),
    "modified_roll_2C": ("number", False, "modified roll 2C, 1/rad (default 0)", None),
    "modified_roll_6D": ("number", False, "modified roll 6D, 1/rad² (default 0)", None),
    "tilt": ("angle", False, "cutter tilt: only 0 (not modelled)", (0.0, 0.0, False)),
    "swivel": ("angle", False, "cutter swivel: only 0 (not modelled)", (0.0, 0.0, False)),
    "helical_motion": ("number", False, "helical motion: only 0 (not modelled)", (0.0, 0.0, False)),
}  # fmt: skip
_SUFFIXES = {"length": ("_mm", "_in"), "angle": ("_deg", "_degmin"), "inverse": ("_per_mm",
             "_per_in"), "number": ("",), "choice": ("",)}  # fmt: skip
_DEGMIN = re.compile(r"^\s*([+-]?)\s*(\d+(?:\.\d*)?)\s*(?:°|d|\s|-)\s*(\d+(?:\.\d*)?)\s*'?\s*$")


def _names() -> dict[str, tuple[str, str]]:
    """Every accepted key ``name+suffix`` -> ``(name, suffix)``."""
    out = {}
    for name, (kind, *_rest) in MACHINE_KEYS.items():
        for suf in _SUFFIXES[kind]:
            out[name + suf] = (name, suf)
    return out


def degmin(field: str, value: Any) -> float:
    """Degrees of a degrees-and-minutes value: ``"58 36.5"``, ``"58°36.5'"``, ``"-2 05"``,
    ``[58, 36.5]`` (minutes in [0, 60); the sign of the whole angle in front)."""
    if isinstance(value, list) and len(value) == 2 and all(_is_number(v) for v in value):
        d, m = float(value[0]), float(value[1])
        sign, d = (-1.0 if d < 0 or (d == 0 and math.copysign(1, d) < 0) else 1.0), abs(d)
    elif isinstance(value, str) and (hit := _DEGMIN.match(value)):
        sign = -1.0 if hit.group(1) == "-" else 1.0
        d, m = float(hit.group(2)), float(hit.group(3))
    else:
        raise InputError(field, value, "degrees and minutes: \"58 36.5\", \"58°36.5'\" or "
                         "[58, 36.5]")  # fmt: skip
    if not 0.0 <= m < 60.0:
        raise InputError(field, value, "minutes in [0, 60)")
    return sign * (d + m / 60.0)


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _value(field: str, kind: str, suffix: str, value: Any) -> Any:
    """The value in mm / deg / 1/mm of a key given with ``suffix``."""
    if kind == "choice":
        if value not in ("outside", "inside"):
            raise InputError(field, value, "'outside' or 'inside'")
        return value
    if suffix == "_degmin":
        return degmin(field, value)
    if not _is_number(value):
        raise InputError(field, value, "a finite number")
    if kind == "length":
        return float(value) * _LEN[suffix[1:]]
    if kind == "inverse":
        return float(value) * _INV[suffix[1:]]
    return float(value)


def _check_range(field: str, v: float, rng: tuple | None, unit: str) -> None:
    if rng is None:
        return
    lo, hi, open_ = rng
    if lo == hi:
        if v != lo:
            raise InputError(field, v, f"{lo:g} {unit}".strip(), "not modelled: fegear's machine "
                             "has the cutter axis parallel to the cradle axis and no helical "
                             "motion")  # fmt: skip
        return
    bad = (v <= lo if open_ else v < lo) or (hi is not None and (v >= hi if open_ else v > hi))
    if bad:
        lo_b, hi_b = ("(" if open_ else "["), (")" if open_ else "]")
        top = "inf" if hi is None else f"{hi:g}"
        raise InputError(field, v, f"in {lo_b}{lo:g}, {top}{hi_b} {unit}".strip())


def parse_flank(flank: str, table: Any) -> FlankTable:
    """One ``[machine.<flank>]`` table as a :class:`FlankTable` (mm, deg)."""
    where = f"machine.{flank}"
    if not isinstance(table, dict):
        raise InputError(where, table, f"a TOML table [{where}]")
    names = _names()
    got: dict[str, tuple[str, float]] = {}
    for key, value in table.items():
        if key not in names:
            close = difflib.get_close_matches(key, list(names), n=2, cutoff=0.5)
            hint = "did you mean " + " or ".join(repr(c) for c in close) + "?" if close else ""
            raise InputError(f"{where}.{key}", value, "a key of the machine settings "
                             "(docs/case_files.md#machine)", hint)  # fmt: skip
        name, suf = names[key]
        if name in got:
            raise InputError(f"{where}.{key}", value, f"one unit only: {got[name][0]!r} is given")
        kind, _, _, rng = MACHINE_KEYS[name]
        v = _value(f"{where}.{key}", kind, suf, value)
        if kind != "choice":
            unit = {"length": "mm", "angle": "deg", "inverse": "1/mm"}.get(kind, "")
            _check_range(f"{where}.{key}", v, rng, unit)
        got[name] = (key, v)
    for name, (kind, required, _, _) in MACHINE_KEYS.items():
        if required and name not in got:
            keys = " or ".join(name + s for s in _SUFFIXES[kind])
            raise InputError(f"{where}.{name}", "missing", f"present ({keys}; required)")
    kw = {}
    for name, (_, v) in got.items():
        if name in ("tilt", "swivel", "helical_motion"):
            continue
        kw[{"parabola": "parabola_per_mm"}.get(name, _field(name))] = v
    return FlankTable(**kw)


def _field(name: str) -> str:
    """The :class:`FlankTable` field of a key name."""
    kind = MACHINE_KEYS[name][0]
    return name + {"length": "_mm", "angle": "_deg"}.get(kind, "")


def parse_machine(section: Any) -> dict[str, FlankTable]:
    """The ``[machine]`` section: the four flank tables (module doc)."""
    if not isinstance(section, dict):
        raise InputError("machine", section, "a TOML table [machine]")
    for key in section:
        if key not in FLANKS:
            close = difflib.get_close_matches(key, FLANKS, n=1, cutoff=0.5)
            raise InputError(f"machine.{key}", f"[machine.{key}]", f"one of {list(FLANKS)}",
                             f"did you mean [machine.{close[0]}]?" if close else "")  # fmt: skip
    for flank in FLANKS:
        if flank not in section:
            raise InputError(f"machine.{flank}", "missing", "all four flank tables")
    return {flank: parse_flank(flank, section[flank]) for flank in FLANKS}


def reference_markdown() -> str:
    """The case-file reference of ``[machine.<flank>]`` (Markdown)."""
    out = ["#### `[machine.gear_drive]`, `[machine.gear_coast]`, `[machine.pinion_drive]`, "
           "`[machine.pinion_coast]` (bevel kinds, optional: all four or none)", "",
           "The machine settings of each flank as a summary sheet prints them; without them "
           "they are synthesized. Units in the keys: lengths `_mm` or `_in`, angles `_deg` or "
           "`_degmin` (`\"58 36.5\"`, `[58, 36.5]`).", "",
           "| key | units | required | meaning |", "|---|---|---|---|"]  # fmt: skip
    for name, (kind, req, doc, _) in MACHINE_KEYS.items():
        units = ", ".join(f"`{name}{s}`" for s in _SUFFIXES[kind])
        out.append(f"| `{name}` | {units} | {'yes' if req else ''} | {doc} |")
    return "\n".join(out) + "\n"


def _degmin_text(deg: float) -> str:
    """``"D MM.MMMMMMMM"`` of an angle in degrees (the sign in front)."""
    sign = "-" if deg < 0 else ""
    d = abs(deg)
    whole = math.floor(d)
    minutes = (d - whole) * 60.0
    if round(minutes, 8) >= 60.0:
        whole, minutes = whole + 1, 0.0
    return f"{sign}{whole:d} {minutes:011.8f}"


def format_machine(tables: dict[str, FlankTable], units: str = "mm", title: str = "") -> str:
    """The ``[machine.<flank>]`` tables of ``tables`` as case-file TOML, in ``units``:
    ``"mm"`` (lengths mm, angles decimal degrees, every digit of the floats) or ``"in"``
    (lengths in inches to 1e-9 in, angles in degrees and minutes to 1e-8′: the flanks move by
    less than 1e-7 mm). :func:`parse_machine` of it gives the tables back (exactly in mm)."""
    if units not in ("mm", "in"):
        raise InputError("--units", units, "'mm' or 'in'")
    out = [f"# {title}"] if title else []
    for flank in FLANKS:
        t = tables[flank]
        out += ["", f"[machine.{flank}]"]
        for name, (kind, required, _, _) in MACHINE_KEYS.items():
            if name in ("tilt", "swivel", "helical_motion"):
                continue
            v = getattr(t, "parabola_per_mm" if name == "parabola" else _field(name))
            if not required and v == 0.0:
                continue
            if kind == "choice":
                out.append(f'{name} = "{v}"')
            elif kind == "number":
                out.append(f"{name} = {v!r}")
            elif units == "mm":
                suf = {"length": "_mm", "angle": "_deg", "inverse": "_per_mm"}[kind]
                out.append(f"{name}{suf} = {v!r}")
            elif kind == "length":
                out.append(f"{name}_in = {v / INCH:.9f}")
            elif kind == "inverse":
                out.append(f"{name}_per_in = {v * INCH:.9f}")
            else:
                out.append(f'{name}_degmin = "{_degmin_text(v)}"')
    return "\n".join(out) + "\n"
