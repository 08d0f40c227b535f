"""The bearing-pattern picture of a gear run, ``bearing_pattern.png`` (pinion flank).

Loaded fidelities (:func:`plot_loaded_pattern`): the union of the loaded contact cells coloured
by the largest pressure over the cycle on a scale that ends at the largest pressure away from
the flank edges (:func:`colour_scale`; the singular, grid-dependent edge values never set it:
the cells on a flank edge are hatched, their largest value is in the legend, the colours above
the scale are clipped and the colour bar says so), the force centroids, and the unloaded TCA
path with the Hertz ellipse of one pair carrying the whole load at each contact point. Fidelity
``tca`` (:func:`plot_unloaded_pattern`): the cells within the paint thickness, the path, and at
each contact point Litvin's instantaneous ellipse for the paint thickness and the Hertz ellipse
(:func:`fegear.tca.plots.plot_pattern`). The ellipses are those of ``summary.json``
(``positions[i].contact_ellipse``, :mod:`fegear.tca.ellipse`); an ellipse the flank cannot hold
(longer than the flank: a spur or helical pair without crowning) is a line contact, drawn as its
contact line clipped to the flank (:func:`fegear.tca.plots.contact_kind`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from fegear.output.figure import pyplot as _plt
from fegear.output.figure import run_title as _title
from fegear.output.figure import save_png as _save
from fegear.pipeline.run import GearRun
from fegear.store.files import atomic_write
from fegear.tca.plots import axis_label, draw_ellipses, legend_entries, plot_pattern

__all__ = ["ColourScale", "colour_scale", "plot_loaded_pattern", "plot_unloaded_pattern"]

Array = NDArray[np.float64]
log = logging.getLogger(__name__)
#: the hatch and outline of the cells on a flank edge
EDGE_COLOUR = "lime"


def _unloaded_path(ax, run: GearRun, which: tuple[str, ...], color: str) -> None:
    """The TCA contact points of the run's positions and their Hertz ellipses (pinion flank);
    a line contact (an ellipse longer than the flank, :func:`fegear.tca.plots.contact_kind`) is
    drawn as its contact line clipped to the flank, not as an ellipse."""
    es = [e for e in run.ellipses if e is not None]
    if not es:
        return
    uv = np.array([e.pinion_uv for e in es])
    ax.plot(uv[:, 1], uv[:, 0], "+", color=color, ms=5, mew=0.8, label="unloaded contact points")
    d = draw_ellipses(ax, es, "pinion", which, color=color, lw=0.5, bounds=_flank_bounds(run))
    T1 = es[0].pinion_torque_Nm
    legend_entries(ax, d, which[0], color, f"Hertz ellipses, one pair at T1 = {T1:.4g} N·m", 0.5)


def plot_unloaded_pattern(out: Path, run: GearRun) -> Path:
    """``bearing_pattern.png`` of fidelity ``tca`` (:func:`fegear.tca.plots.plot_pattern` with
    the run's ellipses)."""
    name = run.case.name
    return atomic_write(
        out / "bearing_pattern.png",
        lambda q: plot_pattern(
            run.tca,
            q,
            _flank_bounds(run),
            title=f"{name}: unloaded bearing pattern on the pinion flank",
            ellipses=run.ellipses or None,
        ),
    )


def _flank_bounds(run: GearRun):
    m, side = run.pair.pinion, run.assembly.side1
    try:
        return m.boundaries(side)
    except TypeError:
        return m.boundaries()


@dataclass(frozen=True)
class ColourScale:
    """The colour scale of the loaded bearing pattern.

    Attributes
    ----------
    vmax
        MPa, the top of the scale: the largest pressure away from the flank edges (None: no
        such value, matplotlib's own scale).
    edge_max
        MPa, the largest pressure of a loaded cell on a flank boundary (None: none).
    cell_max
        MPa, the largest pressure of any loaded cell (None: none).
    """

    vmax: float | None
    edge_max: float | None
    cell_max: float | None = None


def colour_scale(positions) -> ColourScale:
    """The :class:`ColourScale` of the loaded positions ``positions``
    (:class:`~fegear.ltca.results.LoadedPosition`): the top is the largest pair value away from
    the edges (:attr:`~fegear.ltca.results.PairContact.p_interior_MPa`) over the usable
    positions (all of them when none is usable), else the largest pressure of a loaded cell
    not on a flank boundary; edge values (singular, grid-dependent) never set it."""
    usable = [p for p in positions if p.status == "ok"] or list(positions)
    inner = [q.p_interior_MPa for p in usable for q in p.pairs
             if q.in_contact and q.p_interior_MPa is not None]  # fmt: skip
    cells = [(c, pr) for p in positions for c, pr in zip(p.cells, p.pressure, strict=True)]
    off = [float(pr[~c.boundary].max()) for c, pr in cells if (pr[~c.boundary] > 0).any()]
    on = [float(pr[c.boundary].max()) for c, pr in cells if (pr[c.boundary] > 0).any()]
    top = max(inner) if inner else max(off) if off else None
    top = top if top is not None and top > 0 else None
    return ColourScale(top, max(on) if on else None, max(on + off) if on + off else None)


def _painted(run: GearRun, us: Array, vs: Array) -> tuple[Array, Array, list]:
    """``(P_inner, P_edge, centroids)``: the largest pressure each pixel saw over the cycle
    from the loaded cells away from the flank boundaries and from those on them, and the force
    centroids ``(u, v)`` of the loaded pairs."""
    P_in = np.zeros((us.size, vs.size))
    P_edge = np.zeros_like(P_in)
    path = []
    for pos in run.cycle.positions:
        if not pos.cells:  # the hertz fidelity has no contact grid
            continue
        for c, p, q in zip(pos.cells, pos.pressure, pos.pairs, strict=True):
            if q.force_N <= 0:
                continue
            _paint_cells(P_in, us, vs, c, np.where(c.boundary, 0.0, p))
            _paint_cells(P_edge, us, vs, c, np.where(c.boundary, p, 0.0))
            w = p * c.area
            path.append((w @ c.uv) / w.sum())
    return P_in, P_edge, path


def _mark_edges(ax, vs: Array, us: Array, on_edge: NDArray[np.bool_], edge_max: float) -> None:
    """Hatch and outline the pixels whose pressure is that of a cell on a flank boundary."""
    if not on_edge.any():
        return
    m = on_edge.astype(float)
    cs = ax.contourf(vs, us, m, levels=[0.5, 1.5], colors="none", hatches=["////"])
    cs.set_hatchcolor(EDGE_COLOUR)
    cs.set_hatch_linewidth(0.6)
    ax.contour(vs, us, m, levels=[0.5], colors=EDGE_COLOUR, linewidths=0.5)
    ax.add_patch(_plt().Rectangle((0, 0), 0, 0, fill=False, hatch="////", ec=EDGE_COLOUR, lw=0.5,
                 label=f"cells on a flank edge (singular), up to {edge_max:.0f} MPa"))  # fmt: skip


def plot_loaded_pattern(out: Path, run: GearRun) -> Path:
    """``bearing_pattern.png`` of a loaded run: the union of the loaded cells on the pinion flank
    (tooth-local ``(u, v)``), coloured by the largest pressure each point saw over the cycle on
    a scale that ends at the largest pressure away from the flank edges (:func:`colour_scale`;
    higher values are clipped to the top colour, and the colour bar says so); the cells on a
    flank edge (singular, grid-dependent pressures) hatched and outlined, their largest value in
    the legend; dots: force centroids (the loaded path); over it the unloaded TCA path with, at
    each of its contact points, the Hertz ellipse of one pair carrying the whole load (dashed,
    :mod:`fegear.tca.ellipse`), or, for a line contact, the contact line (dotted): where the
    loaded patches are shorter than the ellipses, the load is shared or the patch runs into a
    flank edge."""
    plt = _plt()
    b = _flank_bounds(run)
    us = np.linspace(b.u_fillet, b.u_tip, 240)
    vs = np.linspace(b.v_start, b.v_end, 240)
    P_in, P_edge, path = _painted(run, us, vs)
    P = np.maximum(P_in, P_edge)
    scale = colour_scale(run.cycle.positions)
    log.debug("bearing pattern: colour scale to %s MPa, edge cells up to %s MPa",
              scale.vmax, scale.edge_max)  # fmt: skip
    fig, ax = plt.subplots(figsize=(7.5, 4.6))
    im = ax.pcolormesh(vs, us, np.ma.masked_where(P <= 0, P), cmap="inferno", shading="nearest",
                       vmin=0.0, vmax=scale.vmax)  # fmt: skip
    _mark_edges(ax, vs, us, (P_edge > P_in) & (P_edge > 0), scale.edge_max or 0.0)
    if path:
        pa = np.array(path)
        ax.plot(pa[:, 1], pa[:, 0], "c.", ms=4, label="force centroids")
    _unloaded_path(ax, run, ("hertz",), "deepskyblue")
    ax.add_patch(plt.Rectangle((b.v_start, b.u_fillet), b.v_end - b.v_start,
                               b.u_tip - b.u_fillet, fill=False, ec="gray", lw=1))  # fmt: skip
    ax.set_xlim(b.v_start, b.v_end)
    ax.set_ylim(b.u_fillet, b.u_tip)
    ax.set_xlabel(axis_label(getattr(b, "v_name", "v")))
    ax.set_ylabel(axis_label(getattr(b, "u_name", "u")))
    ax.set_title(f"{_title(run)}\nloaded bearing pattern on the pinion flank", fontsize=9)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(0.0, -0.16), ncol=2,
                  frameon=False)  # fmt: skip
    clipped = scale.vmax is not None and (scale.cell_max or 0.0) > scale.vmax
    label = "max pressure over the cycle (MPa)"
    if clipped:
        label += (
            f"\ntop colour: {scale.vmax:.0f} (away from the edges);\n"
            f"above it, up to {scale.cell_max:.0f}: clipped"
        )
    fig.colorbar(im, ax=ax, label=label, extend="max" if clipped else "neither")
    return _save(fig, out / "bearing_pattern.png")


def _paint_cells(P: np.ndarray, us: np.ndarray, vs: np.ndarray, c, p: np.ndarray) -> None:
    """Raise the pixels ``P[(us, vs)]`` that the loaded cells of ``c`` cover to their pressure.

    The cells form a grid in their own axes (turned against ``(u, v)`` by the ``hybrid``
    refinement): the affine map from the cells' intrinsic coordinates to ``(u, v)`` is fitted
    on the cell centres, every pixel is taken back to cell coordinates and coloured by the
    nearest cell when it lies within that cell (normalised distance below one half-diagonal).
    """
    from scipy.spatial import cKDTree

    load = p > 0
    if not load.any():
        return
    X = np.c_[c.local, np.ones(c.n)]
    B, _, rank, _ = np.linalg.lstsq(X, c.uv, rcond=None)  # uv ≈ [local, 1] B
    if rank < 3 or abs(np.linalg.det(B[:2])) < 1e-12 * np.abs(B[:2]).max() ** 2:
        # A single row or column of cells (grid axes along u, v): boxes from the spacings.
        du = _spacing(c.uv[:, 0], float(c.cell_mm[0]))
        dv = _spacing(c.uv[:, 1], float(c.cell_mm[1]))
        for (u, v), pv in zip(c.uv[load], p[load], strict=True):
            iu = (us >= u - du / 2) & (us <= u + du / 2)
            iv = (vs >= v - dv / 2) & (vs <= v + dv / 2)
            P[np.ix_(iu, iv)] = np.maximum(P[np.ix_(iu, iv)], pv)
        return
    box = (c.uv[load].min(0), c.uv[load].max(0))
    pad = np.abs(B[:2]).T @ c.cell_mm
    iu = np.flatnonzero((us >= box[0][0] - pad[0]) & (us <= box[1][0] + pad[0]))
    iv = np.flatnonzero((vs >= box[0][1] - pad[1]) & (vs <= box[1][1] + pad[1]))
    if iu.size == 0 or iv.size == 0:
        return
    UU, VV = np.meshgrid(us[iu], vs[iv], indexing="ij")
    uv = np.stack([UU.ravel(), VV.ravel()], -1)
    loc = np.linalg.solve(B[:2].T, (uv - B[2]).T).T  # pixel -> cell coordinates
    scale = np.asarray(c.cell_mm, dtype=float)
    d, j = cKDTree(c.local[load] / scale).query(loc / scale)
    hit = d <= 0.75
    vals = np.zeros(uv.shape[0])
    vals[hit] = p[load][j[hit]]
    blk = P[np.ix_(iu, iv)]
    P[np.ix_(iu, iv)] = np.maximum(blk, vals.reshape(UU.shape))


def _spacing(x: np.ndarray, cell_mm: float) -> float:
    """Cell size along one flank coordinate: the spacing of the cell centres, or the cell size
    in mm when the cells form a single row (the pinion flank coordinates of the involute
    family, which carries the fe fidelity, are mm)."""
    d = np.diff(np.unique(x))
    d = d[d > 1e-9 * cell_mm]
    return float(d.min()) if d.size else cell_mm
