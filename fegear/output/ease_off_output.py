"""The ease-off files of a gear run (:mod:`fegear.tca.ease_off`, ``docs/ease_off.md``):
``ease_off.png``, ``ease_off.vts`` and ``ease_off.json``, written by every gear run that writes
outputs, every fidelity.

- ``ease_off.png``: the ease-off ``ε`` (µm, relative to its minimum over the active flank) as a
  filled contour map over the pinion flank (face × profile, the flank coordinates of
  ``bearing_pattern.png``), the TCA's contact points of the run's positions on it and the
  minimum marked; blank where a point has no contact position on the gear's working flank.
- ``ease_off.vts``: the grid as a VTK structured grid on the pinion flank (pinion member frame,
  mm), point data ``ease_off_um``, ``ease_off_rad``, ``contact_position_deg``, ``arm_mm``
  (NaN where undefined), and for a measured pair ``design_ease_off_um``,
  ``measured_minus_design_um``.
- ``ease_off.json``: the grid's flank coordinates, ``eps_um`` (rows: profile, null where
  undefined), ``theta_arcsec``, the minimum's flank coordinates and level; for a measured pair
  (:class:`~fegear.tca.deviation.MeasuredMember`) the design pair's ``design_eps_um`` on the same
  grid and assembly and ``measured_minus_design_um`` (``ε`` of both, each less the design's
  minimum). ``summary.json`` holds the numbers that describe it (``ease_off``:
  :mod:`fegear.results.ease_off`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fegear.output.figure import pyplot as _plt
from fegear.output.figure import save_png as _save
from fegear.pipeline.run import GearRun
from fegear.results.ease_off import FILE
from fegear.store.files import atomic_write, write_json
from fegear.tca.ease_off_pair import PairEaseOff, pair_ease_off
from fegear.tca.plots import axis_label
from fegear.tca.results import ARCSEC

__all__ = ["RunEaseOff", "run_ease_off", "write_ease_off"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class RunEaseOff(PairEaseOff):
    """The ease-off of a run (:class:`~fegear.tca.ease_off_pair.PairEaseOff`) and where the
    run's positions touch it.

    Attributes
    ----------
    path_uv
        ``(n, 2)`` the TCA's contact points of the run's positions (pinion flank coordinates).
    """

    path_uv: np.ndarray


def run_ease_off(run: GearRun) -> RunEaseOff:
    """The :class:`RunEaseOff` of ``run`` (its pair in the assembly the analysis phased: the
    run's own, else made, :func:`fegear.tca.ease_off_pair.pair_ease_off`)."""
    p = run.pair
    pe = run.ease_off or pair_ease_off(p.pinion, p.gear, run.assembly)
    uv = np.array([x.pinion_uv for x in run.ellipses if x is not None]).reshape(-1, 2)
    return RunEaseOff(pe.ease_off, pe.design, uv)


def _json_grid(a: np.ndarray, scale: float = 1.0, digits: int = 4) -> list:
    return [[None if not np.isfinite(x) else round(float(x) * scale, digits) for x in row]
            for row in a]  # fmt: skip


def _document(r: RunEaseOff, bounds) -> dict:
    e = r.ease_off
    doc = {
        "definition": "eps = theta_e * h: the gap of each pinion point in its contact position "
        "(min over the pinion angle of the TCA's angular gap) along the pinion normal, "
        "relative to its minimum; null where the point has no contact position on the gear's "
        "working flank (docs/ease_off.md)",
        "units": {
            "u": "pinion profile coordinate",
            "v": "pinion face coordinate",
            "eps_um": "µm",
            "theta_arcsec": "arcsec",
        },  # fmt: skip
        "u_name": getattr(bounds, "u_name", "u"),
        "v_name": getattr(bounds, "v_name", "v"),
        "u": [float(x) for x in e.u],
        "v": [float(x) for x in e.v],
        "eps_um": _json_grid(e.eps_um),
        "theta_arcsec": _json_grid(e.theta_rad, 1 / ARCSEC),
        "eps_max_um": _finite(np.nanmax(e.eps_um) if np.isfinite(e.eps_um).any() else None),
        "minimum": {
            "u": _finite(e.min_uv[0]),
            "v": _finite(e.min_uv[1]),
            "eps_mm": _finite(e.eps_min_mm),
        },  # fmt: skip
        "defined_fraction": round(float(np.isfinite(e.eps_um).mean()), 4),
    }
    if r.design is not None:
        doc["design_eps_um"] = _json_grid(r.design.eps_um)
        doc["measured_minus_design_um"] = _json_grid(r.difference_um)
    return doc


def _finite(x) -> float | None:
    return None if x is None or not np.isfinite(x) else float(x)


def _plot(path: Path, run: GearRun, r: RunEaseOff, bounds) -> Path:
    plt = _plt()
    e = r.ease_off
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    if np.isfinite(e.eps_um).any():
        top = float(np.nanmax(e.eps_um))
        # levels spaced quadratically: ε grows with the square of the distance from the valley
        # (the bearing), so the levels are about equally spaced on the flank and the valley,
        # where the contact is, gets as many of them as the flanks beside it
        levels = (top if top > 0 else 1e-3) * np.linspace(0.0, 1.0, 21) ** 2
        cs = ax.contourf(e.v, e.u, e.eps_um, levels=levels, cmap="viridis")
        lines = ax.contour(e.v, e.u, e.eps_um, levels=levels[1::2], colors="k", linewidths=0.3)
        ax.clabel(lines, levels[3:10:2], fmt="%.3g", fontsize=6)
        bar = fig.colorbar(cs, ax=ax, label="ease-off ε (µm, from its minimum)")
        bar.set_ticks(levels[::4])
        bar.set_ticklabels([f"{x:.3g}" for x in levels[::4]])
        ax.plot(e.min_uv[1], e.min_uv[0], "x", color="w", ms=8, mew=1.5, label="minimum")
    if r.path_uv.size:
        o = np.argsort(r.path_uv[:, 1])
        ax.plot(r.path_uv[o, 1], r.path_uv[o, 0], "o-", color="tab:red", ms=3, lw=1,
                label="TCA contact points")  # fmt: skip
    ax.set_xlim(e.v[0], e.v[-1])
    ax.set_ylim(e.u[0], e.u[-1])
    ax.set_xlabel(axis_label(getattr(bounds, "v_name", "v")))
    ax.set_ylabel(axis_label(getattr(bounds, "u_name", "u")))
    kind = "measured flanks" if r.design is not None else "design"
    ax.set_title(f"{run.case.name}: ease-off on the pinion flank ({kind})\n"
                 "gap in the contact position along the normal; blank: no contact position "
                 "on the gear flank", fontsize=9)  # fmt: skip
    ax.legend(fontsize=7, loc="upper right")
    return _save(fig, path)


def _vts_text(r: RunEaseOff) -> str:
    """A VTK XML StructuredGrid (ASCII) of the grid: ``i`` along the face, ``j`` the profile."""
    e = r.ease_off
    nu, nv = e.u.size, e.v.size
    order = lambda a: np.asarray(a).reshape(nu, nv, *np.shape(a)[2:]).swapaxes(0, 1)  # noqa: E731
    data = {
        "ease_off_um": e.eps_um,
        "ease_off_rad": e.theta_rad,
        "contact_position_deg": np.degrees(e.phi1_rad),
        "arm_mm": e.h_mm,
    }
    if r.design is not None:
        data["design_ease_off_um"] = r.design.eps_um
        data["measured_minus_design_um"] = r.difference_um

    def arr(name: str, a: np.ndarray, comps: int = 1) -> str:
        vals = " ".join(repr(float(x)) for x in order(a).ravel())
        c = f' NumberOfComponents="{comps}"' if comps > 1 else ""
        return f'<DataArray type="Float64" Name="{name}"{c} format="ascii">\n{vals}\n</DataArray>\n'

    ext = f"0 {nv - 1} 0 {nu - 1} 0 0"
    return (
        '<?xml version="1.0"?>\n<VTKFile type="StructuredGrid" version="0.1" '
        'byte_order="LittleEndian">\n'
        f'<StructuredGrid WholeExtent="{ext}">\n<Piece Extent="{ext}">\n<PointData>\n'
        + "".join(arr(k, v) for k, v in data.items())
        + "</PointData>\n<Points>\n"
        + arr("points_mm", e.points, 3)
        + "</Points>\n</Piece>\n</StructuredGrid>\n</VTKFile>\n"
    )


def write_ease_off(out: Path, run: GearRun) -> list[Path]:
    """Write ``ease_off.png``, ``ease_off.vts`` and ``ease_off.json`` of ``run`` into ``out``
    (each atomically); returns their paths."""
    out = Path(out)
    r = run_ease_off(run)
    m, side = run.pair.pinion, run.assembly.side1
    try:
        bounds = m.boundaries(side)
    except TypeError:
        bounds = m.boundaries()
    text = _vts_text(r)
    return [
        _plot(out / "ease_off.png", run, r, bounds),
        atomic_write(out / "ease_off.vts", lambda q: q.write_text(text, encoding="utf-8")),
        write_json(out / FILE, _document(r, bounds)),
    ]
