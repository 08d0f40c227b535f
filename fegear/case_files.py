"""Case files (TOML) of every kind: read one, dispatch on ``[case] kind``, and the case-file
reference (``docs/case_files.md``).

Gear pairs (``kind = "face_gear" | "spur" | "cylindrical" | "spiral_bevel" | "hypoid"``) are
validated by :mod:`fegear.io.gear_case` into a :class:`~fegear.io.gear_case.GearCase`; the
Hertz scene (``kind = "hertz_scene"``) by :mod:`fegear.scenes.hertz_case` into a
:class:`~fegear.scenes.hertz_case.HertzCase`. Every problem raises
:class:`~fegear.errors.InputError` naming the field, the value and what is allowed.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from fegear.errors import InputError
from fegear.io import gear_case
from fegear.io.gear_case import GEAR_KINDS, GearCase, parse_gear_case
from fegear.io.schema import reference_markdown
from fegear.scenes.hertz_case import SECTIONS, HertzCase, parse_hertz_case

__all__ = ["load_case", "parse_case", "reference"]


def parse_case(data: dict[str, Any], source: str = "<memory>") -> HertzCase | GearCase:
    """Validate a parsed TOML document and build the case (dispatch on ``[case] kind``)."""
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


def load_case(path: str | Path) -> HertzCase | GearCase:
    """Read and validate a case file; every problem raises :class:`InputError`."""
    p = Path(path)
    if not p.is_file():
        raise InputError("case", str(p), "an existing TOML file")
    try:
        # utf-8-sig: a byte-order mark (what Windows editors put at the start) is not TOML
        data = tomllib.loads(p.read_text(encoding="utf-8-sig"))
    except tomllib.TOMLDecodeError as exc:
        raise InputError("case", str(p), "valid TOML", str(exc)) from exc
    except UnicodeDecodeError as exc:
        raise InputError("case", str(p), "a UTF-8 text file", str(exc)) from exc
    return parse_case(data, source=str(p))


def reference() -> str:
    """The case-file reference of every kind (Markdown), from the schema declarations: the
    content of ``docs/case_files.md`` (``python -m fegear.case_files > docs/case_files.md``)."""
    return "\n".join(
        [
            "# Case files",
            "",
            "Generated from the schema declarations by `python -m fegear.case_files > "
            "docs/case_files.md` (a test keeps it equal). `*` = required. Units are in the key "
            "names. Unknown sections and keys are refused with the closest known one suggested; "
            "every error names the field, the value and what is allowed.",
            "",
            "## Gear pairs",
            "",
            gear_case.reference(),
            '## Hertz scene (`kind = "hertz_scene"`)',
            "",
            reference_markdown(SECTIONS),
        ]
    )


if __name__ == "__main__":
    print(reference(), end="")
