"""``p_max.png``: the largest pressure over the cycle, away from the flank edges, with the edge
values marked as what they are.

A pressure at a flank edge is singular (it grows with every refinement of the contact grid): it
is not the contact's pressure and not a trend. The figure draws, per pair, its largest pressure
away from the edges (:attr:`fegear.ltca.results.PairContact.p_interior_MPa`) and, as the solid
"position max" line, the largest of them at each position (a gap where a position has no
interior value); the edge values (:attr:`~fegear.ltca.results.PairContact.p_edge_MPa`) are separate
markers, "singular". The y range is that of the interior values; an edge value above it is drawn
at the top edge of the plot as an upward triangle, the largest of them with their values written
under them, as many as fit without overlapping (:func:`label_picks`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

__all__ = ["PMaxSeries", "label_picks", "p_max_series", "plot_p_max", "save_p_max"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class PMaxSeries:
    """What ``p_max.png`` draws.

    Attributes
    ----------
    phi1_deg
        ``(n,)`` pinion angles of the positions (deg).
    interior
        ``{pinion tooth: (n,) MPa}``: the pair's largest pressure away from the edges (NaN where
        the pair carries no load or has no interior value).
    position_max
        ``(n,)`` MPa: the largest interior value of each position (NaN where none): the
        "position max" line.
    edge
        ``(m, 3)``: ``(φ1 deg, MPa, pinion tooth)`` of every edge value (singular).
    """

    phi1_deg: Array
    interior: dict[int, Array]
    position_max: Array
    edge: Array


def p_max_series(cycle) -> PMaxSeries:
    """The :class:`PMaxSeries` of a :class:`~fegear.ltca.results.LoadedCycle`."""
    deg = np.degrees(np.asarray(cycle.phi1, dtype=float))
    n = len(cycle.positions)
    teeth = sorted({q.k for p in cycle.positions for q in p.pairs})
    interior = {k: np.full(n, np.nan) for k in teeth}
    edge = []
    for i, p in enumerate(cycle.positions):
        for q in p.pairs:
            if not q.force_N > 0:
                continue
            if q.p_interior_MPa is not None:
                interior[q.k][i] = q.p_interior_MPa
            if q.p_edge_MPa is not None:
                edge.append((deg[i], q.p_edge_MPa, q.k))
    stack = np.array(list(interior.values())) if interior else np.full((1, n), np.nan)
    with np.errstate(all="ignore"):
        has = np.any(np.isfinite(stack), axis=0)
        pos_max = np.where(has, np.nanmax(np.where(np.isfinite(stack), stack, -np.inf), 0), np.nan)
    return PMaxSeries(deg, interior, pos_max, np.array(edge, dtype=float).reshape(-1, 3))


def plot_p_max(ax, series: PMaxSeries) -> tuple[float, float] | None:
    """Draw ``series`` on the matplotlib axes ``ax``; returns the y range set (None: matplotlib's
    own, when no interior value exists)."""
    for k, v in series.interior.items():
        ax.plot(series.phi1_deg, v, ".:", lw=1, label=f"pinion tooth {k:+d}, away from the edges")
    ax.plot(
        series.phi1_deg,
        series.position_max,
        "k-",
        lw=1.5,
        label="position max (away from the edges)",
    )
    inner = series.position_max[np.isfinite(series.position_max)]
    ylim = None
    if inner.size:
        top = float(inner.max())
        ylim = (0.0, 1.15 * top if top > 0 else 1.0)
    e = series.edge
    if e.size:
        top = np.inf if ylim is None else ylim[1]
        below, above = e[e[:, 1] <= top], e[e[:, 1] > top]
        if below.size:
            ax.plot(below[:, 0], below[:, 1], "rx", ms=6,
                    label="at a flank edge (singular, grid-dependent)")  # fmt: skip
        if above.size:
            y = 0.97 * top
            ax.plot(above[:, 0], np.full(len(above), y), "r^", ms=6,
                    label=f"at a flank edge, above the range ({len(above)}; singular): "
                    "the largest values written")  # fmt: skip
            _edge_labels(ax, above[:, 0], above[:, 1], y)
    if ylim is not None:
        ax.set_ylim(*ylim)
    return ylim


def label_picks(x: Array, values: Array, min_dx: float) -> NDArray[np.int_]:
    """Indices of the values to write beside their markers at abscissae ``x`` so that no two
    labels are closer than ``min_dx`` (their width): the largest first, then each next largest
    that keeps clear of those chosen (greedy). Sorted by ``x``."""
    chosen: list[int] = []
    for i in np.argsort(-np.asarray(values, dtype=float), kind="stable"):
        if all(abs(x[i] - x[j]) >= min_dx for j in chosen):
            chosen.append(int(i))
    return np.array(sorted(chosen, key=lambda i: x[i]), dtype=int)


def _label_width(ax, n_chars: int, fontsize: float) -> float:
    """The width of a label of ``n_chars`` digits at ``fontsize`` in the x units of ``ax``
    (about 0.6 em a digit, and an em of room between labels)."""
    fig = ax.get_figure()
    axes_pt = ax.get_position().width * fig.get_figwidth() * 72.0
    lo, hi = ax.get_xlim()
    return (0.6 * n_chars + 1.0) * fontsize / axes_pt * abs(hi - lo)


def _edge_labels(ax, x: Array, values: Array, y: float, fontsize: float = 6.0) -> None:
    """Write the edge values ``values`` above the range under their markers at ``(x, y)``, as
    many as fit side by side, the largest first (:func:`label_picks`)."""
    width = _label_width(ax, len(f"{float(np.max(values)):.0f}"), fontsize)
    for i in label_picks(x, values, width):
        ax.annotate(f"{values[i]:.0f}", (x[i], y), textcoords="offset points", xytext=(0, -11),
                    ha="center", fontsize=fontsize, color="r")  # fmt: skip


def save_p_max(path: Path, cycle, title: str, save) -> Path:
    """``p_max.png`` of ``cycle`` at ``path`` (``save(fig, path)`` writes and closes it)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    plot_p_max(ax, p_max_series(cycle))
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("largest cell pressure (MPa)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    # below the axes: inside, it hides the markers (edge values) where it stands
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, frameon=False)
    return save(fig, path)
