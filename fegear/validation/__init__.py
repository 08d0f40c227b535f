"""Validation against references computed without the solver: closed forms and the standards.

Each row of ``docs/validation.md`` is a :class:`Row`: a reference number with its source, the
fegear value at each fidelity and level (:class:`Value`), the ratio, the tolerance of the test that
checks it and the command that reproduces it. ``python docs/make_validation.py`` runs the cases
and writes the page; the rows are tests in ``tests/test_validation.py``.

- :mod:`fegear.validation.iso6336`: the references for cylindrical pairs (line Hertz at the pitch
  point, ISO 6336-2 σH0, ISO 6336-1 single stiffness c'th and c').
- :mod:`fegear.validation.rows`: runs fegear for each row (Hertz scene, FZG at the pitch point,
  spiral bevel TE parabola, face-gear load trend) and the hook of the ISO 6336-3 root-stress
  rows (:func:`fegear.validation.rows.root_stress_rows`).

A module that contributes rows (the root-stress rows of ``fegear.validation.iso6336_root``)
returns a sequence of :class:`Row` (or of mappings with the same field names) from a function
``rows()`` that takes no required argument.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from fegear.errors import InputError

__all__ = ["Row", "Value", "as_row"]


@dataclass(frozen=True)
class Value:
    """One fegear measurement of a row.

    Attributes
    ----------
    fidelity
        ``"hybrid"``, ``"fe"``, ``"hertz"``, ``"tca"``.
    level
        Mesh level (None where there is none, e.g. ``tca``).
    value
        The measured quantity in the row's unit; None with ``note`` saying why.
    series
        A trend row: the quantity at each of the row's loads (``value`` is then the last one).
    seconds
        Wall time of the run (s), None if not measured.
    note
        Anything that changes how to read the number.
    """

    fidelity: str
    level: int | None
    value: float | None
    series: tuple[float | None, ...] = ()
    seconds: float | None = None
    note: str = ""


@dataclass(frozen=True)
class Row:
    """One validation row: a reference computed without the solver and fegear's values.

    Attributes
    ----------
    key
        Short identifier (``"fzg_line_hertz"``).
    check
        What is compared, in words.
    quantity
        The compared quantity with its unit.
    reference
        The reference number (None for a trend row, whose reference is ``reference_text``).
    reference_text
        How the reference is computed and where it comes from.
    values
        fegear's measurements, one per fidelity and level.
    tolerance
        The test's tolerance and its reason.
    command
        The command that reproduces the fegear values.
    test
        The test that checks the row (``tests/test_validation.py::...``).
    loads
        A trend row: labels of its loads, in order.
    pending
        Why the row has no values yet ("" when measured).
    """

    key: str
    check: str
    quantity: str
    reference: float | None
    reference_text: str
    values: tuple[Value, ...]
    tolerance: str
    command: str
    test: str
    loads: tuple[str, ...] = ()
    pending: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict, compare=False)

    def ratio(self, v: Value) -> float | None:
        """``v.value / reference`` (None without a number on either side)."""
        if v.value is None or self.reference is None or self.reference == 0.0:
            return None
        r = v.value / self.reference
        return r if math.isfinite(r) else None

    def increasing(self, v: Value) -> bool | None:
        """A trend row: the series rises strictly with the load (None if a number is missing)."""
        s = v.series
        if len(s) < 2 or any(x is None for x in s):
            return None
        return all(b > a for a, b in zip(s, s[1:], strict=False))  # type: ignore[operator]


def as_row(r: Row | Mapping[str, Any]) -> Row:
    """A :class:`Row` from a row or from a mapping with its field names (``values`` items may be
    :class:`Value` or mappings with its field names).

    Raises
    ------
    InputError
        A mapping without the fields of a row.
    """
    if isinstance(r, Row):
        return r
    if not isinstance(r, Mapping):
        raise InputError("row", type(r).__name__, "a fegear.validation.Row or a mapping")
    d = dict(r)
    try:
        vals = tuple(v if isinstance(v, Value) else Value(**dict(v)) for v in d.pop("values"))
        return Row(values=vals, **d)
    except (KeyError, TypeError) as e:
        raise InputError("row", sorted(r), f"the fields of fegear.validation.Row ({e})") from None
