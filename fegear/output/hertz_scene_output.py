"""Outputs of the Hertz scene: ``summary.json``, VTK of both bodies and of the contact grid, PNGs.

Files written to the output folder:

- ``summary.json`` — inputs, the FE result, the Hertz reference, errors, solver residuals,
  timings, versions, and ``levels`` (the per-level table when a study was run).
- ``block.vtu``, ``roller.vtu`` — the modelled part of each body (linear tets) with the
  displacement (``displacement_mm``, at the vertices) and the contact pressure interpolated on the
  contact-face nodes (``pressure_MPa``); open in ParaView, colour by either, *Warp By Vector*.
- ``contact_cells.vtu`` — the contact grid as quads in the plane ``z = 0`` with the cell
  ``pressure_MPa``, ``force_N`` and ``active`` (the exact solver output; the sum of ``force_N`` is
  the modelled part of the load).
- ``pressure_map.png`` — the computed pressure (mirrored to the whole patch with symmetry) with
  the Hertz ellipse drawn over it; ``convergence.png`` with a study.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from fegear.results.hertz_scene import HertzLevel, HertzSceneResult, hertz_summary_document
from fegear.scenes.hertz_scene import HertzLevelResult
from fegear.store.files import atomic_write, write_json

__all__ = ["write_hertz_outputs", "plot_convergence"]


def _write_bodies(out: Path, r: HertzLevelResult) -> list[Path]:
    import meshio

    paths = []
    s = r.cell_size_mm
    for body in r.bodies:
        pts = body.points
        # Contact pressure at the contact-face nodes: the value of the cell under the node.
        on_face = (np.abs(pts[:, 2]) < 1e-9) if body.name == "block" else None
        p = np.zeros(pts.shape[0])
        xy = pts[:, :2]
        ix = np.floor(xy / s).astype(int)
        keys = [tuple(k) for k in np.floor(r.centers / s).astype(int)]
        lookup = dict(zip(keys, r.pressure, strict=True))
        cand = (
            np.flatnonzero(on_face)
            if on_face is not None
            else np.flatnonzero(pts[:, 2] < 0.05 * np.ptp(pts[:, 2]))
        )
        for i in cand:
            p[i] = lookup.get(tuple(ix[i]), 0.0)
        m = meshio.Mesh(
            pts,
            [("tetra", body.tets)],
            point_data={"displacement_mm": body.displacement, "pressure_MPa": p},
        )
        paths.append(
            atomic_write(
                out / f"{body.name}.vtu", lambda q, m=m: meshio.write(q, m, file_format="vtu")
            )
        )
    # The contact grid itself.
    c, h = r.centers, r.half_width
    corners = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    pts = (c[:, None, :] + corners[None]).reshape(-1, 2)
    pts3 = np.column_stack([pts, np.zeros(len(pts))])
    quads = np.arange(len(pts)).reshape(-1, 4)
    m = meshio.Mesh(
        pts3,
        [("quad", quads)],
        cell_data={
            "pressure_MPa": [r.pressure],
            "force_N": [r.force],
            "active": [r.solution.active.astype(np.int32)],
        },
    )
    paths.append(
        atomic_write(out / "contact_cells.vtu", lambda q: meshio.write(q, m, file_format="vtu"))
    )
    return paths


def _plot_pressure(out: Path, r: HertzLevelResult) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c, p, h = r.centers, r.pressure, r.half_width
    if r.symmetry == "quarter":
        c = np.concatenate([c * [sx, sy] for sx in (1, -1) for sy in (1, -1)])
        p = np.tile(p, 4)
    xs = np.unique(np.round(c[:, 0] / h).astype(int))
    ys = np.unique(np.round(c[:, 1] / h).astype(int))
    Z = np.zeros((ys.size, xs.size))
    ix = np.searchsorted(xs, np.round(c[:, 0] / h).astype(int))
    iy = np.searchsorted(ys, np.round(c[:, 1] / h).astype(int))
    Z[iy, ix] = p
    fig, ax = plt.subplots(figsize=(5.2, 6.4), dpi=110)
    ext = [xs[0] * h - h, xs[-1] * h + h, ys[0] * h - h, ys[-1] * h + h]
    im = ax.imshow(Z, origin="lower", extent=ext, cmap="inferno", aspect="equal")
    t = np.linspace(0, 2 * math.pi, 200)
    ax.plot(
        r.hertz.b_mm * np.cos(t), r.hertz.a_mm * np.sin(t), "c--", lw=1.5, label="Hertz ellipse"
    )
    ax.plot(r.b_mm * np.cos(t), r.a_mm * np.sin(t), "w:", lw=1.2, label="FE (second moments)")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(
        f"level {r.level}: p0 {r.p0_MPa:.0f} MPa (Hertz {r.hertz.p0_MPa:.0f})", fontsize=10
    )
    ax.legend(loc="upper right", fontsize=8)
    fig.colorbar(im, ax=ax, label="pressure (MPa)")
    fig.tight_layout()
    path = atomic_write(out / "pressure_map.png", lambda q: fig.savefig(q, format="png"))
    plt.close(fig)
    return path


def plot_convergence(out: Path, levels: Sequence[HertzLevel], rate: Mapping[str, float]) -> Path:
    """Errors against Hertz over the levels of a study (log-log in the cell size)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    h = np.array([row.cell_size_mm for row in levels])
    fig, ax = plt.subplots(figsize=(5.5, 4.2), dpi=110)
    for key, mark in (("p0", "o"), ("a", "s"), ("b", "^")):
        e = np.array([abs(getattr(row, f"error_{key}")) for row in levels])
        lab = f"{key}" + (f" (rate {rate[key]:.2f})" if key in rate else "")
        ax.loglog(h, np.maximum(e, 1e-6), mark + "-", label=lab)
    ax.axhline(0.01, color="gray", ls=":", lw=1)
    ax.set_xlabel("contact cell size (mm)")
    ax.set_ylabel("|relative error| vs Hertz")
    ax.invert_xaxis()
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = atomic_write(out / "convergence.png", lambda q: fig.savefig(q, format="png"))
    plt.close(fig)
    return path


def write_hertz_outputs(out: Path, result: HertzSceneResult, r: HertzLevelResult) -> list[Path]:
    """Write every output of a Hertz-scene run into ``out``: ``summary.json`` from the result
    model (:mod:`fegear.results.hertz_scene`), the VTK files and the pressure map from the fields
    of the run's level ``r``, the convergence plot from the model's study. Returns the paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = [write_json(out / "summary.json", hertz_summary_document(result))]
    if r.bodies:
        paths += _write_bodies(out, r)
    paths.append(_plot_pressure(out, r))
    if len(result.levels) >= 2:
        paths.append(plot_convergence(out, result.levels, result.convergence_rate))
    return paths
