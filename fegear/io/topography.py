"""Measured flank topographies: the grid files of ``[topography]`` (docs/measured_flanks.md).

A topography file holds, for one flank of one member, a grid of **normal deviations from the
nominal flank** in µm, positive where material is removed (the flank lies under its design), as
a gear measuring machine or a CMM reports them. Layout (comma-separated; blank lines and lines
starting with ``#`` are comments)::

    # pinion drive flank, measured 2024-05-02          <- comments, anywhere
    normalized,   0.0,  0.25,  0.5,  0.75,  1.0         <- corner cell, then the face coordinates
    0.0,          4.1,  1.2,   0.0,  1.1,   3.9         <- a profile coordinate, then deviations
    0.5,          3.8,  1.0,  -0.2,  1.0,   4.0
    1.0,          4.4,  1.5,   0.3,  1.6,   4.2

- the **corner cell** names the coordinates: ``normalized`` (profile 0 at the start of the
  working flank → 1 at the tip; face 0 at its start — toe, inner radius, ``−b/2`` — → 1 at its
  end) for every family, or ``diameter_mm`` (cylindrical members only: the rows are diameters in
  mm, the columns axial positions ``z`` in mm from the face centre of the member), or
  ``roll_mm`` (cylindrical: the rows are roll lengths ``L = √(r² − r_b²)`` in mm, the abscissa
  of a profile chart; the columns as ``diameter_mm``);
- the rest of the **first row** are the face coordinates, the rest of the **first column** the
  profile coordinates, both strictly increasing, at least 2 of each;
- the **body** are the deviations in µm, finite, one per face coordinate on every row.

:func:`read_topography` refuses anything else with an :class:`~fegear.errors.InputError` whose
field names the case-file key, the file, its line (row) and cell (column), both counted from 1
as an editor and a spreadsheet count them (comment lines included in the rows). Whether the grid
lies on the member's working flank is checked where the member is known
(:mod:`fegear.pipeline.pair`). This module reads files; it builds nothing.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from fegear.errors import InputError

__all__ = [
    "COORDINATES",
    "FLANKS",
    "TopographyGrid",
    "read_topography",
    "parse_topography",
]

#: The ``[topography]`` keys: member and flank side.
FLANKS = ("pinion_drive", "pinion_coast", "gear_drive", "gear_coast")
#: The corner cell of a grid file: its coordinates.
COORDINATES = ("normalized", "diameter_mm", "roll_mm")


@dataclass(frozen=True)
class TopographyGrid:
    """One flank's measured grid, as read (no member attached yet).

    Attributes
    ----------
    key
        The ``[topography]`` key (``"pinion_drive"``, ...).
    path
        The file (as resolved from the case file's folder).
    coordinates
        ``"normalized"``, ``"diameter_mm"`` or ``"roll_mm"`` (the corner cell).
    profile
        ``(n_p,)`` profile coordinates (fraction of the working profile, or diameters or roll
        lengths in mm).
    face
        ``(n_f,)`` face coordinates (fraction of the face, or axial positions in mm).
    deviation_um
        ``(n_p, n_f)`` normal deviations in µm, positive = material removed.
    rows, cols
        ``(n_p,)`` the file line of each profile coordinate, ``(n_f,)`` the cell of each face
        coordinate (1-based: what an error names); ``header_row`` the line of the header.
    sha256
        Hash of the content: the coordinates' name and the three arrays' bytes (float64), not
        of the file's text (comments and number formatting do not count). It is what the cache
        keys of the TCA and of the loaded cycle hold.
    """

    key: str
    path: Path
    coordinates: str
    profile: NDArray[np.float64] = field(repr=False, compare=False)
    face: NDArray[np.float64] = field(repr=False, compare=False)
    deviation_um: NDArray[np.float64] = field(repr=False, compare=False)
    rows: tuple[int, ...] = field(repr=False, compare=False)
    cols: tuple[int, ...] = field(repr=False, compare=False)
    header_row: int = field(default=1, repr=False, compare=False)
    sha256: str = ""

    @property
    def member(self) -> str:
        """``"pinion"`` or ``"gear"``."""
        return self.key.split("_")[0]

    @property
    def side(self) -> str:
        """``"drive"`` or ``"coast"``."""
        return self.key.split("_")[1]

    @property
    def is_zero(self) -> bool:
        """Every deviation is 0."""
        return not np.any(self.deviation_um)

    def where(self, row: int | None = None, col: int | None = None) -> str:
        """The error field naming this grid's file and a place in it."""
        at = [f"row {row}" if row is not None else "", f"column {col}" if col is not None else ""]
        place = ", ".join(a for a in at if a)
        return f"topography.{self.key} ({self.path.name}" + (f": {place})" if place else ")")

    @property
    def files(self) -> tuple[Path, ...]:
        """The files the flank's deviation was read from (one grid file)."""
        return (self.path,)

    def echo(self) -> dict[str, object]:
        """What ``summary.json`` says of the grid (``inputs.topography.<key>``)."""
        return {
            "file": self.path.name,
            "sha256": self.sha256,
            "coordinates": self.coordinates,
            "shape": [int(self.profile.size), int(self.face.size)],
            "max_um": float(self.deviation_um.max()),
            "min_um": float(self.deviation_um.min()),
        }


def _field(key: str, path: Path, row: int, col: int | None = None) -> str:
    at = f"row {row}" + (f", column {col}" if col is not None else "")
    return f"topography.{key} ({path.name}: {at})"


def _number(text: str, key: str, path: Path, row: int, col: int, what: str) -> float:
    """A cell's number; refused naming the file, row and column."""
    try:
        x = float(text)
    except ValueError:
        raise InputError(_field(key, path, row, col), text, f"a number ({what})") from None
    if not math.isfinite(x):
        raise InputError(_field(key, path, row, col), text, f"a finite number ({what})")
    return x


def parse_topography(text: str, key: str, path: Path) -> TopographyGrid:
    """The grid of a topography file's ``text`` (see the module docstring for the layout).

    Raises
    ------
    InputError
        A cell that is not a finite number, a row of another length, coordinates that do not
        increase, fewer than 2 points in a direction, an unknown corner cell, normalized
        coordinates outside ``[0, 1]``: the field names ``topography.<key>``, the file, the
        row (its line) and the column (its cell).
    """
    lines = [(i + 1, ln.strip()) for i, ln in enumerate(text.splitlines())]
    rows = [(i, [c.strip() for c in ln.split(",")]) for i, ln in lines
            if ln and not ln.startswith("#")]  # fmt: skip
    if len(rows) < 3:
        raise InputError(f"topography.{key} ({path.name})", f"{len(rows)} rows",
                         "a header row and at least 2 rows of deviations")  # fmt: skip
    head_row, head = rows[0]
    corner = head[0].lower()
    if corner not in COORDINATES:
        raise InputError(_field(key, path, head_row, 1), head[0],
                         f"one of {COORDINATES} (the grid's coordinates)")  # fmt: skip
    if len(head) < 3:
        raise InputError(_field(key, path, head_row), f"{len(head) - 1} face coordinates",
                         "at least 2 face coordinates after the corner cell")  # fmt: skip
    face = np.array([_number(c, key, path, head_row, j + 2, "a face coordinate")
                     for j, c in enumerate(head[1:])])  # fmt: skip
    n_f = face.size
    profile, dev, line_of = [], [], []
    for r, cells in rows[1:]:
        if len(cells) != n_f + 1:
            col = len(cells) + 1 if len(cells) < n_f + 1 else n_f + 2  # the first missing/extra
            raise InputError(_field(key, path, r, col), f"{len(cells)} cells",
                             f"{n_f + 1} cells: a profile coordinate and {n_f} deviations "
                             "(one per face coordinate of the header)")  # fmt: skip
        profile.append(_number(cells[0], key, path, r, 1, "a profile coordinate"))
        dev.append([_number(c, key, path, r, j + 2, "a deviation in µm")
                    for j, c in enumerate(cells[1:])])  # fmt: skip
        line_of.append(r)
    prof = np.array(profile)
    cols = tuple(range(2, n_f + 2))
    for j in range(1, n_f):
        if not face[j] > face[j - 1]:
            raise InputError(_field(key, path, head_row, cols[j]), face[j],
                             f"> {face[j - 1]:g} (face coordinates increasing)")  # fmt: skip
    for i in range(1, prof.size):
        if not prof[i] > prof[i - 1]:
            raise InputError(_field(key, path, line_of[i], 1), prof[i],
                             f"> {prof[i - 1]:g} (profile coordinates increasing)")  # fmt: skip
    if corner == "normalized":
        for j, x in enumerate(face):
            if not 0.0 <= x <= 1.0:
                raise InputError(_field(key, path, head_row, cols[j]), x,
                                 "in [0, 1] (normalized face position: the grid must lie on "
                                 "the working flank)")  # fmt: skip
        for i, x in enumerate(prof):
            if not 0.0 <= x <= 1.0:
                raise InputError(_field(key, path, line_of[i], 1), x,
                                 "in [0, 1] (normalized profile position: the grid must lie on "
                                 "the working flank)")  # fmt: skip
    deviation = np.array(dev, dtype=float)
    h = hashlib.sha256(corner.encode())
    for a in (prof, face, deviation):
        h.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
        h.update(str(a.shape).encode())
    return TopographyGrid(
        key=key, path=path, coordinates=corner, profile=prof, face=face, deviation_um=deviation,
        rows=tuple(line_of), cols=cols, header_row=head_row, sha256=h.hexdigest(),
    )  # fmt: skip


def read_topography(key: str, name: str, folder: Path) -> TopographyGrid:
    """Read the grid file ``name`` of ``[topography] key`` (relative to ``folder``, the case
    file's; an absolute path as it is).

    Raises
    ------
    InputError
        An unknown key, a file that cannot be read, or a bad grid (:func:`parse_topography`).
    """
    if key not in FLANKS:
        raise InputError(f"topography.{key}", name, f"a key of {FLANKS}")
    path, text = read_text(key, name, folder, "grid")
    return parse_topography(text, key, path)


def read_text(key: str, name: str, folder: Path, what: str) -> tuple[Path, str]:
    """``(path, text)`` of the ``[topography]`` file ``name`` (relative to ``folder``, the case
    file's); an :class:`~fegear.errors.InputError` naming ``key`` where it cannot be read."""
    path = Path(name)
    if not path.is_absolute():
        path = folder / path
    try:
        return path, path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"topography.{key}", name, f"a readable {what} file (UTF-8 text)",
                         f"{type(exc).__name__}: {exc}") from None  # fmt: skip
