"""Case files (TOML): schema and validation.

A case names its units in its keys (``force_N``, ``radii_mm``, ``E_MPa``). Unknown keys are
refused (with the closest known key suggested, which catches a wrong unit suffix), missing required
keys are refused, and every error names the field, the value and the allowed range
(:class:`~fegear.errors.InputError`), so the command line can print it as one line.

Hertz scene (``kind = "hertz_scene"``)::

    [case]    kind = "hertz_scene", name = "..."
    [load]    force_N                                   (required, > 0)
    [roller]  radii_mm = [Rx, Ry] (required), half_length_mm, E_MPa, nu
    [block]   half_size_mm, height_mm, E_MPa, nu
    [mesh]    level (0..5), symmetry ("quarter" | "none"), grid_margin
    [solver]  backend ("auto" | "pardiso" | "superlu"), fidelity ("fe" | "hybrid"), fe_level
    [study]   levels = [0, 1, 2, ...]   (optional: a mesh-convergence study)

Gear pairs (``kind = "face_gear" | "spur" | "spiral_bevel"``): see :mod:`fegear.io.gear_case`
(:func:`load_case` returns a :class:`~fegear.io.gear_case.GearCase` for them).
"""

from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fegear.errors import InputError
from fegear.io.gear_case import GearCase
from fegear.scenes.hertz_scene import CELLS_ACROSS_MINOR, HertzScene

__all__ = ["HertzCase", "GearCase", "load_case", "parse_case", "parse_hertz_case"]

_NUM = (int, float)

# section -> key -> (type, required)
_SCHEMA: dict[str, dict[str, tuple[type | tuple[type, ...], bool]]] = {
    "case": {"kind": (str, True), "name": (str, False), "description": (str, False)},
    "load": {"force_N": (_NUM, True)},
    "roller": {
        "radii_mm": (list, True),
        "half_length_mm": (_NUM, False),
        "E_MPa": (_NUM, False),
        "nu": (_NUM, False),
    },
    "block": {
        "half_size_mm": (_NUM, False),
        "height_mm": (_NUM, False),
        "E_MPa": (_NUM, False),
        "nu": (_NUM, False),
    },
    "mesh": {"level": (int, False), "symmetry": (str, False), "grid_margin": (_NUM, False)},
    "solver": {"backend": (str, False), "fidelity": (str, False), "fe_level": (int, False)},
    "study": {"levels": (list, False)},
}
_REQUIRED_SECTIONS = ("case", "load", "roller")
# HertzScene field -> the case-file key that sets it (errors name what the user wrote)
_SCENE_KEYS = {
    "force_N": "load.force_N",
    "roller_half_length_mm": "roller.half_length_mm",
    "block_half_size_mm": "block.half_size_mm",
    "block_height_mm": "block.height_mm",
    "E_roller_MPa": "roller.E_MPa",
    "nu_roller": "roller.nu",
    "E_block_MPa": "block.E_MPa",
    "nu_block": "block.nu",
    "mesh.symmetry": "mesh.symmetry",
}


@dataclass(frozen=True)
class HertzCase:
    """A validated Hertz-scene case."""

    name: str
    scene: HertzScene
    level: int
    backend: str
    fidelity: str
    fe_level: int
    study_levels: tuple[int, ...]
    source: str

    def to_document(self) -> dict[str, Any]:
        """The case as a case-file document (the TOML tables as dicts): :func:`parse_case` of
        it gives this case back."""
        s = self.scene
        return {
            "case": {"kind": "hertz_scene", "name": self.name},
            "load": {"force_N": s.force_N},
            "roller": {
                "radii_mm": list(s.roller_radii_mm),
                "half_length_mm": s.roller_half_length_mm,
                "E_MPa": s.E_roller_MPa,
                "nu": s.nu_roller,
            },
            "block": {
                "half_size_mm": s.block_half_size_mm,
                "height_mm": s.block_height_mm,
                "E_MPa": s.E_block_MPa,
                "nu": s.nu_block,
            },
            "mesh": {"level": self.level, "symmetry": s.symmetry, "grid_margin": s.grid_margin},
            "solver": {
                "backend": self.backend,
                "fidelity": self.fidelity,
                "fe_level": self.fe_level,
            },
            "study": {"levels": list(self.study_levels)},
        }

    def replace(self, **changes: Any) -> HertzCase:
        """A new, validated case with some fields changed (the case itself is frozen).

        Parameters
        ----------
        **changes
            Case-file keys as ``section_key``-free names: ``name``, ``level``, ``backend``,
            ``fidelity``, ``fe_level``, ``study_levels``, ``force_N`` (N), ``roller_radii_mm``
            (``(Rx, Ry)``, mm), ``roller_half_length_mm``, ``block_half_size_mm``,
            ``block_height_mm`` (mm), ``E_roller_MPa``, ``E_block_MPa`` (MPa), ``nu_roller``,
            ``nu_block``, ``symmetry``, ``grid_margin``, and ``source``.

        Raises
        ------
        InputError
            An unknown field, or a value the case file would refuse, named as in the case file.
        """
        from fegear.io.gear_case import _plain

        doc = self.to_document()
        source = self.source
        for key, value in changes.items():
            value = _plain(value)
            if key == "source":
                source = str(value)
                continue
            if key not in _HERTZ_FIELDS:
                known = sorted([*_HERTZ_FIELDS, "source"])
                close = difflib.get_close_matches(key, known, n=1, cutoff=0.5)
                raise InputError(
                    key,
                    value,
                    f"one of the fields {known}",
                    f"did you mean {close[0]!r}?" if close else "",
                )
            section, name = _HERTZ_FIELDS[key]
            doc[section][name] = value
        return parse_hertz_case(doc, source=source)


#: :meth:`HertzCase.replace` field -> (case-file section, key)
_HERTZ_FIELDS = {
    "name": ("case", "name"),
    "force_N": ("load", "force_N"),
    "roller_radii_mm": ("roller", "radii_mm"),
    "roller_half_length_mm": ("roller", "half_length_mm"),
    "E_roller_MPa": ("roller", "E_MPa"),
    "nu_roller": ("roller", "nu"),
    "block_half_size_mm": ("block", "half_size_mm"),
    "block_height_mm": ("block", "height_mm"),
    "E_block_MPa": ("block", "E_MPa"),
    "nu_block": ("block", "nu"),
    "level": ("mesh", "level"),
    "symmetry": ("mesh", "symmetry"),
    "grid_margin": ("mesh", "grid_margin"),
    "backend": ("solver", "backend"),
    "fidelity": ("solver", "fidelity"),
    "fe_level": ("solver", "fe_level"),
    "study_levels": ("study", "levels"),
}


def _type_name(t: type | tuple[type, ...]) -> str:
    if t is _NUM:
        return "a number"
    return {str: "a string", int: "an integer", list: "a list"}.get(t, str(t))


def _check_section(name: str, table: Any) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise InputError(name, table, "a TOML table [" + name + "]")
    schema = _SCHEMA[name]
    for key, value in table.items():
        if key not in schema:
            close = difflib.get_close_matches(key, list(schema), n=1, cutoff=0.5)
            hint = f"did you mean {close[0]!r}?" if close else ""
            raise InputError(f"{name}.{key}", value, f"one of the keys {sorted(schema)}", hint)
        typ, _ = schema[key]
        ok = isinstance(value, typ) and not (typ is _NUM and isinstance(value, bool))
        if typ is int and isinstance(value, bool):
            ok = False
        if not ok:
            raise InputError(f"{name}.{key}", value, _type_name(typ))
        if typ is _NUM and not math.isfinite(value):
            raise InputError(f"{name}.{key}", value, "a finite number")
    for key, (_, required) in schema.items():
        if required and key not in table:
            raise InputError(f"{name}.{key}", "missing", "present (required)")
    return table


def parse_case(data: dict[str, Any], source: str = "<memory>") -> HertzCase | GearCase:
    """Validate a parsed TOML document and build the case (dispatch on ``[case] kind``)."""
    from fegear.io.gear_case import GEAR_KINDS, parse_gear_case

    allowed = ", ".join(repr(k) for k in ("hertz_scene", *GEAR_KINDS))
    # The kind decides the schema: without it no section list (the Hertz scene's or a gear
    # pair's) can be right, so the message asks for the kind, not for other sections.
    if "case" not in data:
        raise InputError("case", "missing", f"a [case] section with kind = one of {allowed}")
    if not isinstance(data["case"], dict):
        raise InputError("case", data["case"], "a TOML table [case]")
    kind = data["case"].get("kind")
    if kind is None:
        raise InputError("case.kind", "missing", f"one of {allowed} (required)")
    if kind in GEAR_KINDS:
        return parse_gear_case(data, source)
    if kind != "hertz_scene":
        raise InputError("case.kind", kind, f"one of {allowed}")
    return parse_hertz_case(data, source)


def parse_hertz_case(data: dict[str, Any], source: str = "<memory>") -> HertzCase:
    """Validate a parsed Hertz-scene TOML document and build the case."""
    for key in data:
        if key not in _SCHEMA:
            close = difflib.get_close_matches(key, list(_SCHEMA), n=1, cutoff=0.5)
            raise InputError(
                key,
                "[" + key + "]",
                f"one of the sections {sorted(_SCHEMA)}",
                f"did you mean [{close[0]}]?" if close else "",
            )
    for sec in _REQUIRED_SECTIONS:
        if sec not in data:
            raise InputError(sec, "missing", f"a [{sec}] section (required)")
    sections = {name: _check_section(name, data.get(name, {})) for name in _SCHEMA}
    kind = sections["case"]["kind"]
    if kind != "hertz_scene":
        raise InputError("case.kind", kind, "'hertz_scene' (gear cases come with the gear issues)")
    roller, block, mesh = sections["roller"], sections["block"], sections["mesh"]
    radii = roller["radii_mm"]
    if len(radii) != 2 or not all(isinstance(r, _NUM) and not isinstance(r, bool) for r in radii):
        raise InputError("roller.radii_mm", radii, "a list of two numbers [Rx, Ry]")
    defaults = HertzScene()
    try:
        scene = HertzScene(
            force_N=float(sections["load"]["force_N"]),
            roller_radii_mm=(float(radii[0]), float(radii[1])),
            roller_half_length_mm=float(
                roller.get("half_length_mm", defaults.roller_half_length_mm)
            ),
            block_half_size_mm=float(block.get("half_size_mm", defaults.block_half_size_mm)),
            block_height_mm=float(block.get("height_mm", defaults.block_height_mm)),
            E_roller_MPa=float(roller.get("E_MPa", defaults.E_roller_MPa)),
            nu_roller=float(roller.get("nu", defaults.nu_roller)),
            E_block_MPa=float(block.get("E_MPa", defaults.E_block_MPa)),
            nu_block=float(block.get("nu", defaults.nu_block)),
            symmetry=str(mesh.get("symmetry", defaults.symmetry)),
            grid_margin=float(mesh.get("grid_margin", defaults.grid_margin)),
        )
    except InputError as exc:
        if exc.field not in _SCENE_KEYS:
            raise
        raise InputError(_SCENE_KEYS[exc.field], exc.value, exc.allowed) from exc
    nlev = len(CELLS_ACROSS_MINOR)
    level = mesh.get("level", 3)
    if not 0 <= level < nlev:
        raise InputError("mesh.level", level, f"an integer in [0, {nlev - 1}]")
    backend = sections["solver"].get("backend", "auto")
    if backend not in ("auto", "pardiso", "superlu"):
        raise InputError("solver.backend", backend, "'auto', 'pardiso' or 'superlu'")
    fidelity = sections["solver"].get("fidelity", "fe")
    if fidelity not in ("fe", "hybrid"):
        raise InputError("solver.fidelity", fidelity, "'fe' or 'hybrid'")
    fe_level = sections["solver"].get("fe_level", 0)
    if not 0 <= fe_level < nlev:
        raise InputError("solver.fe_level", fe_level, f"an integer in [0, {nlev - 1}]")
    levels = sections["study"].get("levels", [])
    for i, lv in enumerate(levels):
        if not (isinstance(lv, int) and not isinstance(lv, bool) and 0 <= lv < nlev):
            raise InputError(f"study.levels[{i}]", lv, f"an integer in [0, {nlev - 1}]")
    return HertzCase(
        name=sections["case"].get("name", Path(source).stem),
        scene=scene,
        level=int(level),
        backend=backend,
        fidelity=fidelity,
        fe_level=int(fe_level),
        study_levels=tuple(sorted(set(levels))),
        source=source,
    )


def load_case(path: str | Path) -> HertzCase | GearCase:
    """Read and validate a case file; every problem raises :class:`InputError`."""
    p = Path(path)
    if not p.is_file():
        raise InputError("case", str(p), "an existing TOML file")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise InputError("case", str(p), "valid TOML", str(exc)) from exc
    except UnicodeDecodeError as exc:
        raise InputError("case", str(p), "a UTF-8 text file", str(exc)) from exc
    return parse_case(data, source=str(p))
