"""Case-file schema: one declarative description of every section and key, one validator.

A case file is a TOML document of tables (sections). Each section is a :class:`Section` of
:class:`Key` declarations: the key's type, whether it is required, its default, its allowed range
or choices, its unit (in the key's name, ``docs/conventions.md``) and one line of meaning. The same
declarations

- validate a document (:func:`check_document`, :func:`check_table`): unknown sections and keys
  are refused with the closest known name suggested (a wrong unit suffix, ``module_in`` →
  ``module_mm``), a missing required key is refused, and a value of the wrong type or out of
  range is refused with an :class:`~fegear.errors.InputError` naming the field, the value and
  what is allowed (``analysis.level = 7 is not allowed: must be an integer in [0, 4]``);
- fill the defaults (:meth:`Section.value`);
- write the case-file reference (:func:`reference_markdown`, ``docs/case_files.md``).

Rules between keys (an outer radius above the inner one, exactly one torque) stay in the
parsers of the case kinds (:mod:`fegear.io.gear_case`, :mod:`fegear.scenes.hertz_case`).
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from typing import Any

from fegear.errors import InputError

__all__ = [
    "BOOLEAN",
    "INTEGER",
    "INT_LIST",
    "INT_PAIR",
    "NUMBER",
    "NUMBER_OR_PAIR",
    "NUMBER_PAIR",
    "STRING",
    "Key",
    "Range",
    "Section",
    "check_document",
    "check_table",
    "reference_markdown",
]

#: Value types of a key.
NUMBER = "number"
INTEGER = "integer"
STRING = "string"
BOOLEAN = "boolean"
INT_PAIR = "int-pair"  # [pinion, gear] integers
NUMBER_PAIR = "number-pair"  # two numbers
NUMBER_OR_PAIR = "number-or-pair"  # a number for both members or [pinion, gear]
INT_LIST = "int-list"  # a list of integers
_TYPES = (NUMBER, INTEGER, STRING, BOOLEAN, INT_PAIR, NUMBER_PAIR, NUMBER_OR_PAIR, INT_LIST)


@dataclass(frozen=True)
class Range:
    """An interval ``lo ≤ v ≤ hi`` (either end open or absent) of a number or integer."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    unit: str = ""

    def contains(self, v: float) -> bool:
        """Whether ``v`` is in the interval."""
        if self.lo is not None and (v <= self.lo if self.lo_open else v < self.lo):
            return False
        return not (self.hi is not None and (v >= self.hi if self.hi_open else v > self.hi))

    def text(self, integer: bool = False) -> str:
        """What is allowed, as the error message says it: ``"> 0"``, ``"in [10, 35] deg"``,
        ``"an integer in [0, 4]"``, ``"an integer >= 5"``."""
        unit = f" {self.unit}" if self.unit else ""
        if self.lo is not None and self.hi is not None:
            left, right = "(["[not self.lo_open], ")]"[not self.hi_open]
            s = f"in {left}{self.lo:g}, {self.hi:g}{right}{unit}"
        elif self.lo is not None:
            s = f"{'>' if self.lo_open else '>='} {self.lo:g}{unit}"
        elif self.hi is not None:
            s = f"{'<' if self.hi_open else '<='} {self.hi:g}{unit}"
        else:
            s = "any value"
        return f"an integer {s}" if integer else s


@dataclass(frozen=True)
class Key:
    """One case-file key.

    Attributes
    ----------
    name
        The key as written in the file (units in the name: ``module_mm``).
    type
        One of :data:`NUMBER`, :data:`INTEGER`, :data:`STRING`, :data:`BOOLEAN`, :data:`INT_PAIR`,
        :data:`NUMBER_PAIR`, :data:`NUMBER_OR_PAIR`, :data:`INT_LIST`.
    doc
        One line of meaning (for the reference).
    required
        The key must be present.
    default
        The value when absent (None: no default, or decided by the program: ``doc`` says how).
    range
        Allowed interval of a number, an integer or of every element of a pair or list.
    choices
        Allowed strings.
    allowed
        The message's "must be …" for a value out of range or not a choice (default: from
        ``range`` or ``choices``).
    hint
        Extra text of that message.
    labels
        Names of the two elements of a pair (``("pinion", "gear")``).
    """

    name: str
    type: str
    doc: str = ""
    required: bool = False
    default: Any = None
    range: Range | None = None
    choices: tuple[str, ...] = ()
    allowed: str = ""
    hint: str = ""
    labels: tuple[str, str] = ("pinion", "gear")

    def __post_init__(self) -> None:
        if self.type not in _TYPES:
            raise ValueError(f"unknown key type {self.type!r} of {self.name!r}")

    def check(self, fld: str, value: Any) -> None:
        """Check the type and the range of ``value`` given for field ``fld``.

        Raises
        ------
        InputError
            Naming ``fld``, the value and what is allowed.
        """
        t = self.type
        if t == BOOLEAN:
            if not isinstance(value, bool):
                raise InputError(fld, value, "true or false")
            return
        if t == STRING:
            if not isinstance(value, str):
                raise InputError(fld, value, "a string")
            if self.choices and value not in self.choices:
                raise InputError(fld, value, self.allowed or _either(self.choices), self.hint)
            return
        if t in (NUMBER, INTEGER) or (t == NUMBER_OR_PAIR and _is_num(value)):
            self._scalar(fld, value, t == INTEGER)
            return
        if t == INT_LIST:
            if not isinstance(value, list):
                raise InputError(fld, value, "a list of integers")
            for i, v in enumerate(value):
                self._scalar(f"{fld}[{i}]", v, True)
            return
        what = {
            INT_PAIR: "a list of two integers",
            NUMBER_PAIR: "a list of two numbers",
            NUMBER_OR_PAIR: "a number or a list of two numbers",
        }[t] + f" [{', '.join(self.labels)}]"
        if not isinstance(value, list) or len(value) != 2:
            raise InputError(fld, value, what)
        for i, v in enumerate(value):
            self._scalar(f"{fld}[{i}]", v, t == INT_PAIR)

    def _scalar(self, fld: str, value: Any, integer: bool) -> None:
        if integer:
            if not _is_int(value):
                raise InputError(fld, value, "an integer")
        else:
            if not _is_num(value):
                raise InputError(fld, value, "a number")
            if not math.isfinite(value):
                raise InputError(fld, value, "a finite number")
        if self.range is not None and not self.range.contains(value):
            raise InputError(fld, value, self.allowed or self.range.text(integer), self.hint)

    def type_text(self) -> str:
        """The type for the reference."""
        return {
            NUMBER: "number",
            INTEGER: "integer",
            STRING: "string",
            BOOLEAN: "boolean",
            INT_PAIR: f"[{', '.join(self.labels)}] integers",
            NUMBER_PAIR: f"[{', '.join(self.labels)}] numbers",
            NUMBER_OR_PAIR: f"number or [{', '.join(self.labels)}]",
            INT_LIST: "list of integers",
        }[self.type]

    def allowed_text(self) -> str:
        """The allowed values for the reference."""
        if self.choices:
            return ", ".join(f'"{c}"' for c in self.choices)
        if self.range is not None:
            return self.allowed or self.range.text()
        return self.allowed


@dataclass(frozen=True)
class Section:
    """One table of a case file: ``[name]`` with its keys."""

    name: str
    keys: tuple[Key, ...]
    doc: str = ""
    required: bool = False

    @property
    def names(self) -> tuple[str, ...]:
        """The key names, in declaration order."""
        return tuple(k.name for k in self.keys)

    def key(self, name: str) -> Key:
        """The declaration of key ``name``."""
        for k in self.keys:
            if k.name == name:
                return k
        raise KeyError(name)

    def value(self, table: dict[str, Any], name: str) -> Any:
        """The key's value in a checked ``table``, else its default."""
        return table.get(name, self.key(name).default)


def check_table(section: Section, table: Any, what: str = "") -> dict[str, Any]:
    """Check one table against its section: unknown keys, types, ranges, required keys.

    Parameters
    ----------
    section
        The declaration.
    table
        The parsed TOML table.
    what
        Appended to the "one of the keys" message (``" for kind 'spur'"``).

    Returns
    -------
    dict
        A copy of the table (the defaults are not filled in: :meth:`Section.value` does).

    Raises
    ------
    InputError
        The first problem, naming ``section.key``.
    """
    name = section.name
    if not isinstance(table, dict):
        raise InputError(name, table, f"a TOML table [{name}]")
    names = section.names
    for key, value in table.items():
        if key not in names:
            close = difflib.get_close_matches(key, list(names), n=1, cutoff=0.5)
            hint = f"did you mean {close[0]!r}?" if close else ""
            raise InputError(f"{name}.{key}", value, f"one of the keys {sorted(names)}{what}", hint)
        section.key(key).check(f"{name}.{key}", value)
    for k in section.keys:
        if k.required and k.name not in table:
            raise InputError(f"{name}.{k.name}", "missing", f"present (required{what})")
    return dict(table)


def check_document(data: dict[str, Any], sections: tuple[Section, ...]) -> None:
    """Check the sections of a document: no unknown section, every required one present.

    Raises
    ------
    InputError
        An unknown section (with the closest known one suggested) or a missing required one.
    """
    names = [s.name for s in sections]
    for key in data:
        if key not in names:
            close = difflib.get_close_matches(key, names, n=1, cutoff=0.5)
            raise InputError(
                key,
                "[" + key + "]",
                f"one of the sections {sorted(names)}",
                f"did you mean [{close[0]}]?" if close else "",
            )
    for s in sections:
        if s.required and s.name not in data:
            raise InputError(s.name, "missing", f"a [{s.name}] section (required)")


def reference_markdown(sections: tuple[Section, ...], title: str = "") -> str:
    """The case-file reference of ``sections`` as a Markdown table per section.

    Columns: key (``*`` = required), type, allowed values, default, meaning.
    """
    out = [f"### {title}", ""] if title else []
    for s in sections:
        head = f"`[{s.name}]`" + (" (required)" if s.required else "")
        out += [f"#### {head}", ""]
        if s.doc:
            out += [s.doc, ""]
        out += ["| key | type | allowed | default | meaning |", "|---|---|---|---|---|"]
        for k in s.keys:
            default = "" if k.default is None else f"`{_toml(k.default)}`"
            star = "*" if k.required else ""
            out.append(
                f"| `{k.name}`{star} | {k.type_text()} | {k.allowed_text()} | {default} | {k.doc} |"
            )
        out.append("")
    return "\n".join(out)


def _toml(v: Any) -> str:
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    return f"{v:g}" if isinstance(v, float) else str(v)


def _either(choices: tuple[str, ...]) -> str:
    """``'a', 'b' or 'c'``."""
    quoted = [repr(c) for c in choices]
    return quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]


def _is_num(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)
