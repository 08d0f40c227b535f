"""Measured flanks of cylindrical gears as profile and lead traces (docs/measured_flanks.md).

A gear measuring machine reports a cylindrical gear's flank as traces (ISO 1328-1, VDI/VDE
2607/2612): a **profile trace** ``δ_P(d)``, the normal deviation along the profile against the
diameter ``d`` (or the roll length ``L = √(d²/4 − r_b²)``, the abscissa of a profile chart),
measured in one transverse plane ``z = z_P``; a **lead trace** (helix trace)
``δ_L(z)``, the deviation along the face against the axial position ``z`` (mm from the member's
face centre), measured on one diameter ``d = d_L``. ``[topography]`` takes them per member and
side as ``<member>_<side>_profile`` and ``<member>_<side>_lead``, each a two-column file
(comma-separated; blank lines and lines starting with ``#`` are comments)::

    # pinion drive flank, lead trace          <- comments, anywhere
    at_diameter_mm, 77.5                      <- optional: where the trace was measured
    z_mm, removed_um                          <- coordinate, sign convention
    -7.0, 9.69
    0.0,  0.0
    7.0,  9.71

- the optional **position line** before the header: ``at_z_mm, z_P`` in a profile trace,
  ``at_diameter_mm, d_L`` (or ``at_roll_mm, L_L``) in a lead trace;
- the **header**: the coordinate (``diameter_mm`` or ``roll_mm`` of a profile trace, ``z_mm``
  of a lead trace) and the sign: ``removed_um`` (fegear's convention: + = material removed, the
  flank under its design) or ``added_um`` (the measuring machines' "plus material" convention:
  negated on reading);
- at least 2 rows of a coordinate and a deviation (µm along the flank normal), finite, the
  coordinates strictly monotone (increasing or decreasing; read in increasing order).

**The surface.** Each trace is interpolated like a grid direction (:mod:`fegear.tca.deviation`:
the not-a-knot B-spline through its points, cubic from 4 points, else of degree ``n − 1``); call
the interpolants ``S_P`` and ``S_L``. The flank's deviation is the separable surface

    δ(d, z) = S_P(d) + S_L(z) − δ_c,    δ_c = (S_P(d_L) + S_L(z_P)) / 2,

the two traces' crossing point ``(d_L, z_P)`` on both (``d`` stands for the profile trace's
coordinate, a diameter or a roll length; a lead trace's position is given in the same).
``z_P`` defaults to 0 (mid-face), ``d_L`` to the middle of the profile trace's span
``(d_first + d_last)/2`` (the profile trace spans the measured working depth; give the position
line for the true position). The crossing must lie on both traces' spans. Where the traces agree
there, ``δ_c`` is their common value and ``δ`` reproduces each trace along its own line; where
they disagree by ``m = S_P(d_L) − S_L(z_P)``, each trace is reproduced shifted by ``∓m/2`` (a
constant: the flank's thickness, not its shape) and a :class:`TraceMismatchWarning` names ``m``
when ``|m|`` exceeds :data:`MISMATCH_WARN_UM`. A profile trace alone gives ``δ = S_P(d)`` over
the whole face, a lead trace alone ``δ = S_L(z)`` over the whole profile. A profile modification
is a function of the roll length (ISO 21771), steep in ``d`` near the form circle (``L ∝
√(d − d_b)`` at the base circle): a trace of few points interpolates it far better in
``roll_mm`` (11 points of an 8 µm profile crowning: 1e-13 mm against 9e-5 mm in
``diameter_mm``).

**The grid.** The surface becomes a :class:`TraceGrid`, a
:class:`~fegear.io.topography.TopographyGrid` in ``diameter_mm`` (or ``roll_mm``) coordinates on
the traces' own points: rows the profile trace's ``d_i``, columns the lead trace's ``z_j``,
``G_ij = S_P(d_i) + S_L(z_j) − δ_c``. Its tensor-product spline is the surface exactly: the
cardinal splines of each direction sum to 1 (a spline reproduces constants), so
``Σ_ij G_ij B_i(d) ℓ_j(z) = S_P(d) + S_L(z) − δ_c``. A missing trace is one row (``d_L``) or
one column (``z_P``): a degree-0 direction, constant. So a trace takes the grids' path
unchanged: the deviated flank map, the check against the working flank (naming the trace's file
and line), the cache keys (the grid's hash), the ``summary.json`` echo. A lead trace alone
without a position line sits on the member's mid working depth, placed by :func:`placed` when
the member is known (the row's position does not change ``δ``, so not the hash either).
"""

from __future__ import annotations

import hashlib
import math
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import make_interp_spline

from fegear.errors import InputError
from fegear.io.topography import FLANKS, TopographyGrid, _number, read_text

__all__ = [
    "MISMATCH_WARN_UM",
    "TRACE_KEYS",
    "Trace",
    "TraceGrid",
    "TraceMismatchWarning",
    "parse_trace",
    "placed",
    "read_flank_traces",
    "read_trace",
    "trace_grid",
]

Array = NDArray[np.float64]

#: The ``[topography]`` trace keys: ``<member>_<side>_profile`` and ``<member>_<side>_lead``.
TRACE_KEYS = tuple(f"{f}_{t}" for f in FLANKS for t in ("profile", "lead"))
#: Per trace kind: its coordinate headers and its position lines' names.
_COORDS = {"profile": ("diameter_mm", "roll_mm"), "lead": ("z_mm",)}
_AT = {"profile": ("at_z_mm",), "lead": ("at_diameter_mm", "at_roll_mm")}
#: The sign headers and their factor to fegear's convention (+ = material removed).
_SIGNS = {"removed_um": 1.0, "added_um": -1.0}
#: Mismatch (µm) of the two traces at their crossing above which a warning names it: the
#: resolution a measuring machine prints its traces at.
MISMATCH_WARN_UM = 0.1


class TraceMismatchWarning(UserWarning):
    """A flank's profile and lead traces disagree at their crossing point."""


@dataclass(frozen=True)
class Trace:
    """One trace as read.

    Attributes
    ----------
    key
        The ``[topography]`` key (``"pinion_drive_lead"``).
    path
        The file.
    kind
        ``"profile"`` or ``"lead"``.
    coordinate
        ``(n,)`` diameters or roll lengths (profile) or axial positions ``z`` (lead), mm,
        increasing.
    removed_um
        ``(n,)`` normal deviations, µm, + = material removed (an ``added_um`` file negated).
    lines
        ``(n,)`` the file line of each point (1-based, comments counted).
    at, at_line
        The position line's value (mm: ``z_P`` of a profile trace, ``d_L`` of a lead trace) and
        its line; None and 0 where the file has none.
    coordinate_name, at_name
        The header's coordinate (``"diameter_mm"``, ``"roll_mm"``, ``"z_mm"``) and the position
        line's name (``"at_z_mm"``, ``"at_diameter_mm"``, ``"at_roll_mm"``; "" without one).
    """

    key: str
    path: Path
    kind: str
    coordinate: Array = field(repr=False)
    removed_um: Array = field(repr=False)
    lines: tuple[int, ...] = field(repr=False)
    at: float | None = None
    at_line: int = 0
    coordinate_name: str = ""
    at_name: str = ""

    @property
    def flank(self) -> str:
        """``"pinion_drive"`` ..."""
        return self.key.rsplit("_", 1)[0]

    def where(self, line: int | None = None, cell: int | None = None) -> str:
        """The error field naming this trace's file and a place in it."""
        at = [f"row {line}" if line else "", f"column {cell}" if cell else ""]
        place = ", ".join(a for a in at if a)
        return f"topography.{self.key} ({self.path.name}" + (f": {place})" if place else ")")

    def value(self, x: float) -> float:
        """The trace's interpolant at ``x`` (mm, inside its span), µm."""
        k = min(3, self.coordinate.size - 1)
        return float(make_interp_spline(self.coordinate, self.removed_um, k=k)(x))


def parse_trace(text: str, key: str, path: Path) -> Trace:
    """The trace of a trace file's ``text`` (layout: the module docstring).

    Raises
    ------
    InputError
        An unknown key, header or position line, a row of other than 2 cells, a cell that is
        not a finite number, fewer than 2 points, coordinates that are not strictly monotone:
        the field names ``topography.<key>``, the file, the row (its line) and the column.
    """
    if key not in TRACE_KEYS:
        raise InputError(f"topography.{key}", path.name, f"a key of {TRACE_KEYS}")
    kind = key.rsplit("_", 1)[1]
    t = Trace(key, path, kind, np.zeros(0), np.zeros(0), ())
    rows = [(i + 1, [c.strip() for c in ln.split(",")])
            for i, ln in enumerate(ln.strip() for ln in text.splitlines())
            if ln and not ln.startswith("#")]  # fmt: skip
    at, at_line, at_name = None, 0, ""
    if rows and rows[0][1][0].lower() in _AT[kind]:
        at_line, cells = rows.pop(0)
        at_name = cells[0].lower()
        if len(cells) != 2:
            raise InputError(t.where(at_line, min(len(cells) + 1, 3)), f"{len(cells)} cells",
                             f"2 cells: {at_name} and its value in mm")  # fmt: skip
        at = _number(cells[1], key, path, at_line, 2, f"{at_name}, the trace's position")
    if not rows:
        raise InputError(t.where(), "no header", f"a header '{_COORDS[kind][0]}, removed_um' "
                         "(or added_um) and at least 2 points")  # fmt: skip
    head_line, head = rows[0]
    other = "lead" if kind == "profile" else "profile"
    coord_name = head[0].lower()
    if coord_name not in _COORDS[kind]:
        hint = ""
        if coord_name in _COORDS[other]:
            hint = f"a {other} trace: give it as topography.{t.flank}_{other}"
        elif coord_name in _AT[other]:
            hint = f"the position line of a {kind} trace is one of {_AT[kind]}"
        raise InputError(t.where(head_line, 1), head[0], f"one of {_COORDS[kind]} (the "
                         f"coordinate of a {kind} trace)", hint)  # fmt: skip
    if len(head) != 2 or head[1].lower() not in _SIGNS:
        raise InputError(t.where(head_line, 2), ", ".join(head[1:]) or "nothing",
                         f"one of {tuple(_SIGNS)} (+ = material removed, or + = material "
                         "added), the only cell after the coordinate")  # fmt: skip
    sign = _SIGNS[head[1].lower()]
    xs, ds, lines = [], [], []
    for r, cells in rows[1:]:
        if len(cells) != 2:
            raise InputError(t.where(r, 3 if len(cells) > 2 else 2), f"{len(cells)} cells",
                             f"2 cells: {coord_name} and the deviation in µm")  # fmt: skip
        xs.append(_number(cells[0], key, path, r, 1, coord_name))
        ds.append(_number(cells[1], key, path, r, 2, "a deviation in µm"))
        lines.append(r)
    if len(xs) < 2:
        raise InputError(t.where(head_line), f"{len(xs)} points",
                         "at least 2 points after the header")  # fmt: skip
    x = np.array(xs)
    up = x[1] > x[0]
    for i in range(1, x.size):
        if not (x[i] > x[i - 1] if up else x[i] < x[i - 1]):
            order = "increasing" if up else "decreasing"
            raise InputError(t.where(lines[i], 1), float(x[i]),
                             f"{'>' if up else '<'} {x[i - 1]:g} ({coord_name} strictly "
                             f"{order}, as from the first two points)")  # fmt: skip
    order = slice(None) if up else slice(None, None, -1)
    return Trace(key, path, kind, x[order].copy(), sign * np.array(ds)[order],
                 tuple(lines[order]), at, at_line, coord_name, at_name)  # fmt: skip


def read_trace(key: str, name: str, folder: Path) -> Trace:
    """Read the trace file ``name`` of ``[topography] key`` (relative to ``folder``).

    Raises
    ------
    InputError
        A file that cannot be read, or a bad trace (:func:`parse_trace`).
    """
    path, text = read_text(key, name, folder, "trace")
    return parse_trace(text, key, path)


@dataclass(frozen=True)
class TraceGrid(TopographyGrid):
    """A :class:`~fegear.io.topography.TopographyGrid` made of a flank's traces
    (:func:`trace_grid`; the module docstring).

    ``rows`` are the profile trace's lines (a lead trace alone: its position line),
    ``cols`` the lead trace's lines (a profile trace alone: its position line),
    ``header_row`` −1: :meth:`where` names the trace file a row or a column came from.

    Attributes
    ----------
    profile_trace, lead_trace
        The traces (one may be None).
    crossing
        ``(d_L, z_P)`` mm of the crossing point (``d_L`` a diameter or a roll length, as
        ``coordinates``; None until :func:`placed` where a lead trace alone has no position
        line).
    mismatch_um
        ``S_P(d_L) − S_L(z_P)``, µm (0 with one trace).
    """

    profile_trace: Trace | None = field(default=None, repr=False, compare=False)
    lead_trace: Trace | None = field(default=None, repr=False, compare=False)
    crossing: tuple[float | None, float | None] = field(default=(None, None), compare=False)
    mismatch_um: float = field(default=0.0, compare=False)

    def where(self, row: int | None = None, col: int | None = None) -> str:
        """The field naming the trace file and line of a grid row (a diameter) or of a grid
        column (``row`` = ``header_row`` = −1: an axial position)."""
        if row == self.header_row and col is not None:  # a column: an axial position
            t, line = self.lead_trace or self.profile_trace, col
        else:
            t, line = self.profile_trace or self.lead_trace, row
        assert t is not None
        return t.where(line, (2 if line == t.at_line else 1) if line else None)

    @property
    def files(self) -> tuple[Path, ...]:
        """The trace files the flank's deviation was read from (profile, then lead)."""
        return tuple(t.path for t in (self.profile_trace, self.lead_trace) if t is not None)

    def echo(self) -> dict[str, object]:
        """What ``summary.json`` says of the traces (``inputs.topography.<flank>``)."""
        p, ld = self.profile_trace, self.lead_trace
        return {
            **super().echo(),
            "file": " + ".join(t.path.name for t in (p, ld) if t is not None),
            "profile_trace": None if p is None else p.path.name,
            "lead_trace": None if ld is None else ld.path.name,
            "crossing_profile_mm": self.crossing[0],
            "crossing_z_mm": self.crossing[1],
            "mismatch_um": self.mismatch_um,
        }


def trace_grid(flank: str, profile: Trace | None, lead: Trace | None) -> TraceGrid:
    """The grid of a flank's traces (the separable surface of the module docstring).

    Parameters
    ----------
    flank
        ``"pinion_drive"`` ...
    profile, lead
        The traces (at least one).

    Raises
    ------
    InputError
        A crossing point off a trace's span, naming the position line (or the file, where the
        position is the default).

    Warns
    -----
    TraceMismatchWarning
        The traces disagree at the crossing by more than :data:`MISMATCH_WARN_UM`.
    """
    if profile is None and lead is None:
        raise InputError(f"topography.{flank}", "no trace", "a profile or a lead trace")
    z_p = 0.0 if profile is None or profile.at is None else profile.at
    d_l: float | None = None if lead is None else lead.at
    if profile is not None:
        coords = profile.coordinate_name
    else:
        roll = lead.at_name == "at_roll_mm"  # type: ignore[union-attr]
        coords = "roll_mm" if roll else "diameter_mm"
    mismatch, delta_c = 0.0, 0.0
    if profile is not None and lead is not None:
        dp, zl = profile.coordinate, lead.coordinate
        if lead.at_name and lead.at_name != f"at_{coords}":
            raise InputError(lead.where(lead.at_line, 1), lead.at_name, f"'at_{coords}' (the "
                             f"profile trace {profile.path.name} is in {coords})")  # fmt: skip
        if d_l is None:
            d_l = 0.5 * (float(dp[0]) + float(dp[-1]))
        if not dp[0] <= d_l <= dp[-1]:
            raise InputError(lead.where(lead.at_line, 2), d_l,
                             f"in [{dp[0]:g}, {dp[-1]:g}] mm (the {coords} of "
                             f"{profile.path.name}: the traces must cross)")  # fmt: skip
        if not zl[0] <= z_p <= zl[-1]:
            what = "" if profile.at_line else " (the default: mid-face; give at_z_mm)"
            raise InputError(profile.where(profile.at_line or None, 2 if profile.at_line else None),
                             z_p, f"in [{zl[0]:g}, {zl[-1]:g}] mm (the axial positions of "
                             f"{lead.path.name}: the traces must cross){what}")  # fmt: skip
        a, b = profile.value(d_l), lead.value(z_p)
        mismatch, delta_c = a - b, 0.5 * (a + b)
        if abs(mismatch) > MISMATCH_WARN_UM:
            warnings.warn(
                f"topography.{flank}: the profile trace ({profile.path.name}) and the lead trace "
                f"({lead.path.name}) differ by {mismatch:+.3f} µm at their crossing "
                f"({coords} = {d_l:g}, z = {z_p:g} mm); each is used shifted by half of it "
                "(docs/measured_flanks.md)",
                TraceMismatchWarning,
                stacklevel=2,
            )
    if profile is not None:
        d, rows, p_um = profile.coordinate, profile.lines, profile.removed_um
    else:
        d = np.array([math.nan if d_l is None else d_l])
        rows, p_um = (lead.at_line,), np.zeros(1)  # type: ignore[union-attr]
    if lead is not None:
        z, cols, l_um = lead.coordinate, lead.lines, lead.removed_um
    else:
        z, cols, l_um = np.array([z_p]), (profile.at_line,), np.zeros(1)  # type: ignore[union-attr]
    dev = p_um[:, None] + l_um[None, :] - delta_c
    h = hashlib.sha256(f"traces {coords}".encode())
    for arr in (d, z, dev):
        h.update(np.ascontiguousarray(arr, dtype="<f8").tobytes())
        h.update(str(arr.shape).encode())
    return TraceGrid(
        key=flank, path=(profile or lead).path, coordinates=coords,  # type: ignore[union-attr]
        profile=d, face=z, deviation_um=dev, rows=tuple(rows), cols=tuple(cols), header_row=-1,
        sha256=h.hexdigest(), profile_trace=profile, lead_trace=lead, crossing=(d_l, z_p),
        mismatch_um=float(mismatch),
    )  # fmt: skip


def read_flank_traces(files: dict[str, Any], folder: Path, kind: str) -> dict[str, TraceGrid]:
    """The trace grids of a ``[topography]`` table (its checked ``files``), by flank key.

    Raises
    ------
    InputError
        A trace of a member that is not cylindrical, a trace and a grid for the same flank
        (naming both keys), a bad trace file.
    """
    out = {}
    for flank in FLANKS:
        given = [k for k in (f"{flank}_profile", f"{flank}_lead") if k in files]
        if not given:
            continue
        if kind != "cylindrical":
            raise InputError(f"topography.{given[0]}", files[given[0]], "absent for kind "
                             f"{kind!r}: traces are for kind 'cylindrical' (give a grid as "
                             f"topography.{flank})")  # fmt: skip
        if flank in files:
            raise InputError(f"topography.{given[0]}", files[given[0]],
                             f"absent with topography.{flank} (a flank is a grid or traces, "
                             "not both)")  # fmt: skip
        p, ld = (read_trace(k, str(files[k]), folder) if k in files else None
                 for k in (f"{flank}_profile", f"{flank}_lead"))  # fmt: skip
        out[flank] = trace_grid(flank, p, ld)
    return out


def placed(grid: TopographyGrid, member: Any) -> TopographyGrid:
    """``grid`` with a lead trace alone placed on ``member``'s mid working depth where its file
    gives no position (the diameter at the middle of the roll length from the form circle to the
    tip); any other grid as it is.

    Parameters
    ----------
    grid
        A grid of ``[topography]``.
    member
        The generated member (cylindrical: ``roll_length``, ``r_b``, ``flank_coordinates``).
    """
    if not (isinstance(grid, TraceGrid) and np.isnan(grid.profile).any()):
        return grid
    bd = member.flank_coordinates(grid.side).bounds
    L = float(member.roll_length(0.5 * (bd.u_fillet + bd.u_tip)))
    d = L if grid.coordinates == "roll_mm" else 2.0 * math.hypot(float(member.r_b), L)
    return replace(grid, profile=np.array([d]), crossing=(d, grid.crossing[1]))
