"""The Hertz scene's case file (``kind = "hertz_scene"``): its sections, their validation and
the :class:`HertzCase` they make.

A case names its units in its keys (``force_N``, ``radii_mm``, ``E_MPa``). Unknown keys are
refused (with the closest known key suggested, which catches a wrong unit suffix), missing required
keys are refused, and every error names the field, the value and the allowed range
(:class:`~fegear.errors.InputError`), so the command line can print it as one line::

    [case]    kind = "hertz_scene", name = "..."
    [load]    force_N                                   (required, > 0)
    [roller]  radii_mm = [Rx, Ry] (required), half_length_mm, E_MPa, nu
    [block]   half_size_mm, height_mm, E_MPa, nu
    [mesh]    level (0..5), symmetry ("quarter" | "none"), grid_margin
    [solver]  backend ("auto" | "pardiso" | "superlu"), fidelity ("fe" | "hybrid"), fe_level
    [study]   levels = [0, 1, 2, ...]   (optional: a mesh-convergence study)

A case file of any kind is read by :func:`fegear.case_files.load_case`; gear pairs are
:mod:`fegear.io.gear_case`.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fegear.errors import InputError
from fegear.io.gear_case import ANALYSIS, _plain
from fegear.io.schema import (
    INT_LIST,
    INTEGER,
    NUMBER,
    NUMBER_PAIR,
    STRING,
    Key,
    Range,
    Section,
    check_document,
    check_table,
)
from fegear.scenes.hertz_scene import CELLS_ACROSS_MINOR, HertzScene

__all__ = ["SECTIONS", "HertzCase", "parse_hertz_case"]

_D = HertzScene()
_LEVEL = Range(0, len(CELLS_ACROSS_MINOR) - 1)
_POS = Range(0, None, lo_open=True)

#: The Hertz scene's sections (the engine: :mod:`fegear.io.schema`; the scene checks the
#: ranges of its own fields, :class:`~fegear.scenes.hertz_scene.HertzScene`).
SECTIONS: tuple[Section, ...] = (
    Section(
        "case",
        (
            Key("kind", STRING, '"hertz_scene"', True),
            Key("name", STRING, "case name (default: the file name)"),
            Key("description", STRING, "free text", default=""),
        ),
        required=True,
    ),
    Section("load", (Key("force_N", NUMBER, "normal force, N", True),), required=True),
    Section(
        "roller",
        (
            Key(
                "radii_mm",
                NUMBER_PAIR,
                "principal radii of curvature, mm",
                True,
                labels=("Rx", "Ry"),
            ),
            Key(
                "half_length_mm",
                NUMBER,
                "half length of the roller body, mm",
                default=_D.roller_half_length_mm,
            ),
            Key("E_MPa", NUMBER, "Young's modulus, MPa", default=_D.E_roller_MPa),
            Key("nu", NUMBER, "Poisson's ratio", default=_D.nu_roller),
        ),
        required=True,
    ),
    Section(
        "block",
        (
            Key(
                "half_size_mm", NUMBER, "half size of the block, mm", default=_D.block_half_size_mm
            ),
            Key("height_mm", NUMBER, "block height, mm", default=_D.block_height_mm),
            Key("E_MPa", NUMBER, "Young's modulus, MPa", default=_D.E_block_MPa),
            Key("nu", NUMBER, "Poisson's ratio", default=_D.nu_block),
        ),
    ),
    Section(
        "mesh",
        (
            Key(
                "level",
                INTEGER,
                "mesh level (cells across the minor semi-axis: "
                f"{', '.join(map(str, CELLS_ACROSS_MINOR))})",
                default=3,
                range=_LEVEL,
            ),
            Key("symmetry", STRING, '"quarter" or "none"', default=_D.symmetry),
            Key("grid_margin", NUMBER, "contact grid size / Hertz ellipse", default=_D.grid_margin),
        ),
    ),
    Section(
        "solver",
        (
            ANALYSIS.key("backend"),  # the same key as the gear cases
            Key("fidelity", STRING, "contact compliance", default="fe", choices=("fe", "hybrid")),
            Key("fe_level", INTEGER, "hybrid: the FE mesh level", default=0, range=_LEVEL),
        ),
    ),
    Section(
        "study",
        (
            Key(
                "levels",
                INT_LIST,
                "a mesh-convergence study over these levels",
                default=[],
                range=_LEVEL,
            ),
        ),  # fmt: skip
    ),
)
_SECTION = {s.name: s for s in SECTIONS}

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


def parse_hertz_case(data: dict[str, Any], source: str = "<memory>") -> HertzCase:
    """Validate a parsed Hertz-scene TOML document and build the case."""
    check_document(data, SECTIONS)
    sections = {name: check_table(sec, data.get(name, {})) for name, sec in _SECTION.items()}
    kind = sections["case"]["kind"]
    if kind != "hertz_scene":
        raise InputError("case.kind", kind, "'hertz_scene' (gear cases come with the gear issues)")
    roller, block, mesh = sections["roller"], sections["block"], sections["mesh"]
    radii = roller["radii_mm"]
    r, b, m = _SECTION["roller"], _SECTION["block"], _SECTION["mesh"]
    try:
        scene = HertzScene(
            force_N=float(sections["load"]["force_N"]),
            roller_radii_mm=(float(radii[0]), float(radii[1])),
            roller_half_length_mm=float(r.value(roller, "half_length_mm")),
            block_half_size_mm=float(b.value(block, "half_size_mm")),
            block_height_mm=float(b.value(block, "height_mm")),
            E_roller_MPa=float(r.value(roller, "E_MPa")),
            nu_roller=float(r.value(roller, "nu")),
            E_block_MPa=float(b.value(block, "E_MPa")),
            nu_block=float(b.value(block, "nu")),
            symmetry=str(m.value(mesh, "symmetry")),
            grid_margin=float(m.value(mesh, "grid_margin")),
        )
    except InputError as exc:
        if exc.field not in _SCENE_KEYS:
            raise
        raise InputError(_SCENE_KEYS[exc.field], exc.value, exc.allowed) from exc
    solver, study = _SECTION["solver"], _SECTION["study"]
    level = m.value(mesh, "level")
    backend = solver.value(sections["solver"], "backend")
    fidelity = solver.value(sections["solver"], "fidelity")
    fe_level = solver.value(sections["solver"], "fe_level")
    levels = study.value(sections["study"], "levels")
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
