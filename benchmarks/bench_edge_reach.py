"""How far a flank edge's pressure concentration reaches into a contact (docs/ltca/edge_reach.md).

Two half-space contacts of a cylinder (radius 20 mm, line load 500 N/mm, steel: Hertz semi-width
``b`` = 0.335 mm, ``p0`` = 949 MPa), solved with fegear's own contact solver on cells carrying
uniform pressure (:func:`fegear.mechanics.halfspace.halfspace_influence`,
:func:`fegear.mechanics.contact.solve_contact`):

A. **An edge across the contact line** (a face end): a straight roller of length 16 b ending
   abruptly at ``y = 0`` and ``y = 16 b``. The peak pressure across the roller at a distance
   ``y`` from its end, over the one at mid-length, on cells of ``b/4``, ``b/8`` and ``b/16``
   along the roller (the end cell is singular: it grows as the cells shrink; beyond two cells
   the three grids agree).
B. **An edge along the contact line** (a tip or a fillet limit): the same cylinder on a flank
   that ends at ``x = x_e`` inside the Hertz strip (a strip 40 b long, its middle row read):
   the pressure at a distance from the edge against Hertz's ``p0 sqrt(1 - x²/b²)``.

Usage::

    python benchmarks/bench_edge_reach.py

Writes a Markdown table to stdout and to benchmarks/results/edge_reach.md (about 1 min).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from fegear.mechanics.contact import solve_contact
from fegear.mechanics.halfspace import halfspace_influence
from fegear.mechanics.hertz_closed_form import effective_modulus, hertz_line

E_STAR = effective_modulus(206000.0, 0.3, 206000.0, 0.3)
R_MM, W_N_PER_MM = 20.0, 500.0
HL = hertz_line(W_N_PER_MM, R_MM, E_STAR)
B, P0 = HL.b_mm, HL.p0_MPa
OUT = Path(__file__).resolve().parent / "results" / "edge_reach.md"


def _pressure(xs: np.ndarray, ys: np.ndarray, dx: float, dy: float) -> np.ndarray:
    """``(nx, ny)`` MPa: the contact of the cylinder ``g = x²/(2R)`` on the cells ``xs × ys``
    (centres, mm) carrying the line load over their length."""
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    centres = np.column_stack([X.ravel(), Y.ravel()])
    C = halfspace_influence(centres, np.tile([dx / 2, dy / 2], (centres.shape[0], 1)), E_STAR)
    s = solve_contact(C, (X**2 / (2.0 * R_MM)).ravel(), W_N_PER_MM * ys.size * dy)
    return (s.force / (dx * dy)).reshape(X.shape)


def roller_end(per_b: int, length_b: float = 16.0, nx: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """Study A on cells of ``b/per_b`` along the roller: ``(y/b, peak/mid-length peak)``."""
    dx = 2.6 * B / nx
    xs = (np.arange(nx) + 0.5) * dx - 1.3 * B
    dy = B / per_b
    ny = int(round(length_b * per_b))
    ys = (np.arange(ny) + 0.5) * dy
    peak = _pressure(xs, ys, dx, dy).max(axis=0)
    return ys / B, peak / peak[ny // 2]


def tip_cut(xe_b: float, nx: int = 24) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Study B with the flank ending at ``x = xe_b · b``: ``(x/b, p/p0, Hertz/p0)`` of the
    middle row."""
    dx = (1.3 - xe_b) * B / nx
    xs = xe_b * B + (np.arange(nx) + 0.5) * dx
    ny = 40
    row = _pressure(xs, (np.arange(ny) + 0.5) * B, dx, B)[:, ny // 2]
    hertz = np.sqrt(np.clip(1.0 - (xs / B) ** 2, 0.0, None))
    return xs / B, row / P0, hertz


def main() -> int:
    t0 = time.perf_counter()
    lines = [
        "# How far a flank edge reaches into a contact",
        "",
        "`python benchmarks/bench_edge_reach.py` (the studies: its docstring; the rule they",
        "support: docs/ltca/edge_reach.md). Cylinder R = 20 mm, 500 N/mm, steel: "
        f"b = {B:.3f} mm, p0 = {P0:.0f} MPa.",
        "",
        "## A. A roller's end (an edge across the contact line)",
        "",
        "Peak pressure across the roller at a distance y from its end, over its mid-length "
        "value (roller 16 b long):",
        "",
    ]
    grids = {n: roller_end(n) for n in (4, 8, 16)}
    at = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0)
    lines += ["| y / b | " + " | ".join(f"cells b/{n}" for n in grids) + " |"]
    lines += ["|---" * (len(grids) + 1) + "|"]
    for y in at:
        cells = []
        for y_b, ratio in grids.values():
            k = int(np.argmin(np.abs(y_b - y))) if y > 0 else 0
            cells.append(f"{ratio[k]:.3f} (at {y_b[k]:.2f})")
        label = "end cell" if y == 0 else f"{y:g}"
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "## B. A tip across the Hertz strip (an edge along the contact line)",
        "",
        "Pressure / p0 at a distance d from the edge, the flank ending at x_e (Hertz's value "
        "of the uncut strip in brackets):",
        "",
        "| x_e / b | d = 0.1 b | 0.25 b | 0.5 b | 1 b | 1.5 b | contact ends at d / b |",
        "|---|---|---|---|---|---|---|",
    ]
    for xe in (-0.8, -0.5, 0.0):
        x_b, p, hz = tip_cut(xe)
        d = x_b - xe
        row = []
        for dist in (0.1, 0.25, 0.5, 1.0, 1.5):
            k = int(np.argmin(np.abs(d - dist)))
            row.append(f"{p[k]:.3f} ({hz[k]:.3f})")
        end = float(d[p > 0].max()) if np.any(p > 0) else 0.0
        lines.append(f"| {xe:g} | " + " | ".join(row) + f" | {end:.2f} |")
    lines += ["", f"({time.perf_counter() - t0:.0f} s)", ""]
    text = "\n".join(lines)
    print(text)
    OUT.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
