"""Outputs of a sweep (:mod:`fegear.sweep`): ``sweep.json``, ``comparison.md``, ``te_overlay.png``.

Each item has its own folder ``<out>/<item>/`` with the outputs of ``fegear run``. The sweep
outputs are written into ``<out>/`` (each atomically), from the items' ``summary.json``:

- ``sweep.json`` — the items (name, base case, grid parameters, status, wall time, error) with
  their key results (``te_pp_unloaded_arcsec``, ``te_pp_loaded_arcsec``,
  ``contact_ratio_loaded``, ``p_max_MPa``, ``pattern_position_mm`` and its extent), and the
  comparison against the nominal item. Rewritten after every item, so it tells the state of an
  interrupted sweep too.
  With ``spread``: per key result its minimum, median and maximum over the finished items that
  have it and the count of those that do not (a tolerance study: the spread of the headlines
  over installation errors or measured flank grids, ``docs/measured_flanks.md``).
- ``comparison.md`` — the comparison table and the spread (Markdown).
- ``te_overlay.png`` — the TE curves of all finished items on one figure (unloaded and loaded).

Pattern position (mm), the mean of the pairs' contact points over the cycle (weighted by the pair
force when loaded; the unloaded TCA's contact points otherwise), measured along the face:

- face gear: radius from the face-gear axis (fixed ``z`` axis): larger = toward the OUTER end;
- spiral bevel: distance from the apex (the fixed-frame origin): larger = toward the outer end
  (heel);
- spur: axial position ``z`` from the face centre (no inner or outer end: toward ``+z``/``−z``).

Comparison: ``te_ratio`` = TE peak-to-peak of the item / TE peak-to-peak of the nominal item
(loaded when both are loaded, else unloaded; ``null`` when the nominal's TE is below
:data:`TE_FLOOR_ARCSEC`, which a conjugate pair's unloaded TE is); ``pattern_shift_mm`` = item
pattern position − nominal.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from fegear import __version__
from fegear.output.figure import pyplot, save_png
from fegear.results.model import GearRunResult
from fegear.results.summary import result_from_summary
from fegear.store.files import atomic_write, write_json
from fegear.sweep.marker import verified_summary

__all__ = [
    "TE_FLOOR_ARCSEC",
    "key_results",
    "comparison",
    "comparison_error",
    "reference_item",
    "write_sweep_json",
    "write_sweep_outputs",
]

#: TE peak-to-peak below which a ratio against it is not meaningful (arcsec; round-off of the
#: TCA of a conjugate pair is ~1e-3 arcsec).
TE_FLOOR_ARCSEC = 0.01
#: Pattern shifts smaller than this are reported as "none" (mm).
SHIFT_FLOOR_MM = 1e-3

_MEASURE = {
    "face_gear": ("radius from the face-gear axis", "outer end", "inner end"),
    "spiral_bevel": ("distance from the apex", "outer end (heel)", "inner end (toe)"),
    "hypoid": ("distance from the pinion apex", "outer end (heel)", "inner end (toe)"),
    "spur": ("axial position z from the face centre", "+z end", "-z end"),
}


def _finite(x: Any) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _measure(kind: str, p: np.ndarray) -> np.ndarray:
    """``(n,)`` position along the face of contact points ``p`` ``(n, 3)`` (fixed frame, mm)."""
    if kind == "face_gear":
        return np.hypot(p[:, 0], p[:, 1])
    if kind in ("spiral_bevel", "hypoid"):
        return np.linalg.norm(p, axis=1)
    return p[:, 2]


def key_results(result: GearRunResult | Mapping[str, Any]) -> dict[str, Any]:
    """Key results of one run from its result model (or its ``summary.json`` document, read
    into the model: :func:`fegear.results.result_from_summary`).

    Returns
    -------
    dict
        ``te_pp_unloaded_arcsec``, ``te_pp_loaded_arcsec``, ``contact_ratio_loaded``,
        ``p_max_MPa`` (``None`` where the fidelity has no loaded values),
        ``pattern_position_mm`` (see the module docstring), ``pattern_extent_mm``
        (``[min, max]`` of the contact points), ``pattern_measure``, ``pattern_weighting``.
    """
    r = result if isinstance(result, GearRunResult) else result_from_summary(result)
    c = r.cycle
    pts, w = [], []
    for pos in r.positions:
        for q in pos.pairs:
            if q.contact_point_mm is None:
                continue
            if q.force_N is not None and q.force_N <= 0:
                continue
            pts.append(q.contact_point_mm)
            w.append(1.0 if q.force_N is None else float(q.force_N))
    loaded = any(q.force_N is not None for p in r.positions for q in p.pairs)
    pos_mm = extent = None
    if pts:
        s = _measure(r.kind, np.asarray(pts, dtype=float))
        wa = np.asarray(w)
        pos_mm = float(np.sum(wa * s) / np.sum(wa))
        extent = [float(s.min()), float(s.max())]
    return {
        "te_pp_unloaded_arcsec": _finite(c.te_pp_unloaded_arcsec),
        "te_pp_loaded_arcsec": _finite(c.te_pp_loaded_arcsec),
        "contact_ratio_loaded": _finite(c.contact_ratio_loaded),
        "p_max_MPa": _finite(c.p_max_MPa),
        "pattern_position_mm": pos_mm,
        "pattern_extent_mm": extent,
        "pattern_measure": _MEASURE.get(r.kind, _MEASURE["spur"])[0],
        "pattern_weighting": "pair force" if loaded else "unloaded contact points",
    }


def _read_summary(folder: Path) -> dict[str, Any] | None:
    """The item's summary.json, only if it is the complete one its marker vouches for."""
    return verified_summary(folder)


def _ratio(a: float | None, b: float | None) -> float | None:
    if a is None or b is None or not b >= TE_FLOOR_ARCSEC:
        return None
    return a / b


def reference_item(items: Sequence, nominal: str | None) -> str | None:
    """The comparison's reference item: ``nominal``, else the first item without installation
    errors, else the first item. It depends on the items only, never on which of them
    finished (a missing reference is an error, not a reason to take another one)."""
    if nominal is not None:
        return nominal
    for it in items:
        if it.case.errors.is_zero:
            return it.name
    return items[0].name if items else None


def comparison(
    items: Sequence, keyres: Mapping[str, dict[str, Any]], nominal: str | None = None
) -> dict[str, Any]:
    """The comparison of the finished items against the nominal one.

    Parameters
    ----------
    items
        The :class:`~fegear.sweep.SweepItem` of the sweep, in order.
    keyres
        ``{item name: key_results(...)}`` of the finished items.
    nominal
        The reference item (default: the first item without installation errors, else the
        first item; :func:`reference_item`).

    Returns
    -------
    dict
        ``{"nominal": name | None, "basis": "loaded" | "unloaded", "rows": [...]}``; a row per
        finished item: ``item``, ``params``, ``te_ratio``, ``te_ratio_unloaded``,
        ``te_ratio_loaded``, ``pattern_shift_mm``, ``pattern_shift_toward``. When the reference
        item (:func:`reference_item`) has no valid results: no rows and ``"error"``.
    """
    nom = reference_item(items, nominal)
    if nom is None:
        return {"nominal": None, "basis": None, "rows": [], "error": "no items"}
    if nom not in keyres:
        return {
            "nominal": nom,
            "basis": None,
            "rows": [],
            "error": f"the reference item {nom!r} has no valid results (failed, not run, or its "
            "summary.json is incomplete): no comparison",
        }
    n = keyres[nom]
    kind = next(it.case.kind for it in items if it.name == nom)
    _, plus, minus = _MEASURE.get(kind, _MEASURE["spur"])
    all_loaded = all(k["te_pp_loaded_arcsec"] is not None for k in keyres.values())
    basis = "loaded" if all_loaded else "unloaded"
    rows = []
    for it in items:
        k = keyres.get(it.name)
        if k is None:
            continue
        r_un = _ratio(k["te_pp_unloaded_arcsec"], n["te_pp_unloaded_arcsec"])
        r_lo = _ratio(k["te_pp_loaded_arcsec"], n["te_pp_loaded_arcsec"])
        shift = None
        if k["pattern_position_mm"] is not None and n["pattern_position_mm"] is not None:
            shift = k["pattern_position_mm"] - n["pattern_position_mm"]
        if it.name == nom:
            r_un = 1.0 if r_un is not None else None
            r_lo = 1.0 if r_lo is not None else None
            shift = 0.0 if shift is not None else None
        toward = None
        if shift is not None:
            toward = "none" if abs(shift) < SHIFT_FLOOR_MM else (plus if shift > 0 else minus)
        rows.append(
            {
                "item": it.name,
                "params": dict(it.params),
                "te_ratio": r_lo if basis == "loaded" else r_un,
                "te_ratio_unloaded": r_un,
                "te_ratio_loaded": r_lo,
                "pattern_shift_mm": shift,
                "pattern_shift_toward": toward,
            }
        )
    return {"nominal": nom, "basis": basis, "rows": rows, "error": None}


def _collect(out: Path, items: Sequence, results: Mapping) -> tuple[dict, dict]:
    docs, keyres = {}, {}
    for it in items:
        r = results.get(it.name)
        if r is None or r.status == "failed":
            continue
        doc = _read_summary(out / it.name)
        if doc is not None:
            docs[it.name] = doc
            keyres[it.name] = key_results(doc)
    return docs, keyres


#: the key results whose spread a sweep reports, with their labels and formats
SPREAD = {
    "te_pp_unloaded_arcsec": ("TE p-p unloaded (arcsec)", ".3f"),
    "te_pp_loaded_arcsec": ("TE p-p loaded (arcsec)", ".3f"),
    "contact_ratio_loaded": ("contact ratio loaded", ".3f"),
    "p_max_MPa": ("p_max away from the edges (MPa)", ".0f"),
    "pattern_position_mm": ("pattern position (mm)", ".3f"),
}


def spread(keyres: Mapping[str, Mapping[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per key result of :data:`SPREAD`: ``min``, ``median``, ``max`` over the items of
    ``keyres`` that have it (``None`` when none has), ``n`` those items, ``null`` the others
    (a value a run could not report: counted, never taken as a number)."""
    out = {}
    for key in SPREAD:
        vals = [k[key] for k in keyres.values() if k.get(key) is not None]
        a = np.asarray(vals, dtype=float)
        out[key] = {
            "n": len(vals),
            "null": len(keyres) - len(vals),
            "min": float(a.min()) if vals else None,
            "median": float(np.median(a)) if vals else None,
            "max": float(a.max()) if vals else None,
        }
    return out


def _document(
    out: Path, items: Sequence, results: Mapping, meta: Mapping[str, Any]
) -> tuple[dict[str, Any], dict, dict]:
    docs, keyres = _collect(out, items, results)
    rows = []
    for it in items:
        r = results.get(it.name)
        rows.append(
            {
                "name": it.name,
                "folder": it.name,
                "base_case": it.base,
                "source": it.case.source,
                "kind": it.case.kind,
                "fidelity": it.case.fidelity,
                "level": it.case.level,
                "params": dict(it.params),
                "status": "pending" if r is None else r.status,
                "seconds": None if r is None else r.seconds,
                "error": None if r is None or not r.error else r.error,
                "results": keyres.get(it.name),
            }
        )
    params = sorted({k for it in items for k in it.params})
    doc = {
        "fegear": __version__,
        "n_items": len(items),
        "parameters": params,
        "status": {
            s: sum(row["status"] == s for row in rows)
            for s in ("done", "skipped", "failed", "pending")
        },
        "workers": meta.get("workers"),
        "scheduler": meta.get("scheduler"),
        "units": {"te": "arcsec", "pressure": "MPa", "length": "mm"},
        "items": rows,
        "comparison": comparison(items, keyres, meta.get("nominal")),
        "spread": spread(keyres),
    }
    return doc, docs, keyres


def write_sweep_json(out: Path, items: Sequence, results: Mapping, meta: Mapping[str, Any]) -> Path:
    """Write ``out/sweep.json`` (the current state of the sweep), atomically."""
    doc, _, _ = _document(Path(out), items, results, meta)
    return write_json(Path(out) / "sweep.json", doc)


def _num(x: float | None, fmt: str) -> str:
    return "—" if x is None else format(x, fmt)


def _markdown(doc: dict[str, Any]) -> str:
    cmp = doc["comparison"]
    res = {row["name"]: row for row in doc["items"]}
    lines = [
        "# Sweep comparison",
        "",
    ]
    if cmp.get("error"):
        lines += [f"**Error: {cmp['error']}.**", ""]
    lines += [
        f"Nominal item: `{cmp['nominal']}`. TE ratio = TE peak-to-peak / nominal "
        f"({cmp['basis']} TE). Pattern shift = mean contact position − nominal "
        f"({_measure_text(doc)}).",
        "",
        "| item | status | TE p-p unloaded (arcsec) | TE p-p loaded (arcsec) | TE ratio "
        "| contact ratio | p_max (MPa) | pattern position (mm) | shift (mm) | toward |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    cmp_rows = {r["item"]: r for r in cmp["rows"]}
    for name, row in res.items():
        k = row["results"] or {}
        c = cmp_rows.get(name, {})
        label = f"**{name}**" if name == cmp["nominal"] else name
        status = row["status"] + (f": {row['error']}" if row["error"] else "")
        lines.append(
            "| "
            + " | ".join(
                [
                    label,
                    status.replace("|", "/"),
                    _num(k.get("te_pp_unloaded_arcsec"), ".3f"),
                    _num(k.get("te_pp_loaded_arcsec"), ".3f"),
                    _num(c.get("te_ratio"), ".3f"),
                    _num(k.get("contact_ratio_loaded"), ".2f"),
                    _num(k.get("p_max_MPa"), ".0f"),
                    _num(k.get("pattern_position_mm"), ".3f"),
                    _num(c.get("pattern_shift_mm"), "+.3f"),
                    c.get("pattern_shift_toward") or "—",
                ]
            )
            + " |"
        )
    sp = doc.get("spread") or {}
    if any(v["n"] for v in sp.values()):
        lines += [
            "",
            f"Spread over the {len(cmp['rows'])} finished items (a value a run could not report "
            "is counted, not taken):",
            "",
            "| result | min | median | max | items | null |",
            "|---|---:|---:|---:|---:|---:|",
        ]
        for key, (label, fmt) in SPREAD.items():
            v = sp[key]
            lines.append(
                f"| {label} | {_num(v['min'], fmt)} | {_num(v['median'], fmt)} | "
                f"{_num(v['max'], fmt)} | {v['n']} | {v['null']} |"
            )
    return "\n".join(lines) + "\n"


def _measure_text(doc: dict[str, Any]) -> str:
    for row in doc["items"]:
        if row["results"]:
            return row["results"]["pattern_measure"]
    return "position along the face"


def _label(it) -> str:
    if it.params:
        return ", ".join(f"{k.split('.', 1)[1]}={v:g}" if isinstance(v, float) else
                         f"{k.split('.', 1)[1]}={v}" for k, v in it.params.items())  # fmt: skip
    return it.name


#: TE below which a curve is numerical noise (arcsec): the TCA's Newton solves stop at
#: :data:`fegear.tca.solve.TOL_MM` (1e-10 mm), over a lever of at least 1 mm 1e-10 rad.
TE_NOISE_ARCSEC = 1e-10 * 180.0 / math.pi * 3600.0
#: Half height of the y range (arcsec) of a panel whose every curve is flat within the noise.
FLAT_HALF_RANGE_ARCSEC = 0.1


def about_mean(te: np.ndarray) -> tuple[np.ndarray, float]:
    """``(te − mean, mean)`` of a TE curve (arcsec, NaN where not reported), with deviations
    below :data:`TE_NOISE_ARCSEC` set to 0: a conjugate pair's unloaded TE is 0 up to the
    solver's round-off (1e-10″), which a plot would otherwise draw as a ripple."""
    te = np.asarray(te, dtype=float)
    mean = float(np.nanmean(te)) if np.any(np.isfinite(te)) else 0.0
    dev = te - mean
    return np.where(np.abs(dev) < TE_NOISE_ARCSEC, 0.0, dev), mean


def flat_limits(curves: Sequence[np.ndarray]) -> tuple[float, float] | None:
    """The y range of a panel whose curves (:func:`about_mean`) are all flat (every finite
    value 0): ``±FLAT_HALF_RANGE_ARCSEC``, so the flat line is drawn as one; else None
    (matplotlib's own range)."""
    vals = np.concatenate([np.ravel(c) for c in curves]) if curves else np.zeros(0)
    vals = vals[np.isfinite(vals)]
    if vals.size and np.all(vals == 0.0):
        return (-FLAT_HALF_RANGE_ARCSEC, FLAT_HALF_RANGE_ARCSEC)
    return None


def _plot_overlay(path: Path, items: Sequence, docs: Mapping[str, dict], nominal: str | None):
    plt = pyplot()
    ready = [it for it in items if it.name in docs]
    loaded = any(docs[it.name]["cycle"].get("te_pp_loaded_arcsec") is not None for it in ready)
    fig, axes = plt.subplots(1, 2 if loaded else 1, figsize=(12 if loaded else 6.5, 4.4),
                             squeeze=False)  # fmt: skip
    cmap = plt.get_cmap("viridis")
    drawn: list[list[np.ndarray]] = [[], []]
    for i, it in enumerate(ready):
        d = docs[it.name]
        deg = [p["pinion_angle_deg"] for p in d["positions"]]
        color = "k" if it.name == nominal else cmap(i / max(len(ready) - 1, 1))
        style = {"color": color, "lw": 2.0 if it.name == nominal else 1.3, "ms": 3}
        label = _label(it) + (" (nominal)" if it.name == nominal else "")
        curves = [np.array([p["te_unloaded_arcsec"] for p in d["positions"]], dtype=float)]
        if loaded:
            curves.append(
                np.array(
                    [
                        np.nan if p["te_loaded_arcsec"] is None else p["te_loaded_arcsec"]
                        for p in d["positions"]
                    ],
                    dtype=float,
                )  # fmt: skip
            )
        for j, te in enumerate(curves):
            # the mean (a constant offset, large under shaft-angle errors) would hide the
            # shape and amplitude: plotted about the cycle mean, the mean in the legend
            dev, mean = about_mean(te)
            drawn[j].append(dev)
            axes[0, j].plot(deg, dev, "os"[j] + "-", label=f"{label} (mean {mean:+.2f})",
                            **style)  # fmt: skip
    titles = ["unloaded TE about its cycle mean", "loaded TE about its cycle mean"]
    for j, ax in enumerate(axes[0]):
        flat = flat_limits(drawn[j])
        if flat is not None:
            ax.set_ylim(*flat)
            ax.text(0.5, 0.9, f"flat: every curve constant within {TE_NOISE_ARCSEC:.0e}″ "
                    "(the TCA's resolution)", transform=ax.transAxes, ha="center",
                    fontsize=8)  # fmt: skip
        ax.set_xlabel("pinion angle φ1 (deg)")
        ax.set_ylabel("TE − mean (arcsec)")
        ax.set_title(titles[j], fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=1 if len(ready) <= 8 else 2, loc="best")
    base = sorted({it.base for it in ready})
    fig.suptitle(f"sweep of {', '.join(base)}: {len(ready)} items", fontsize=10)
    return save_png(fig, path)  # one draw, as the runs' pictures


def write_sweep_outputs(
    out: Path, items: Sequence, results: Mapping, meta: Mapping[str, Any]
) -> list[Path]:
    """Write ``sweep.json``, ``comparison.md`` and ``te_overlay.png`` into ``out`` (atomically).

    Returns
    -------
    list of Path
        The files written (no PNG when no item finished).
    """
    out = Path(out)
    doc, docs, _ = _document(out, items, results, meta)
    paths = []
    if docs:
        paths.append(
            _plot_overlay(out / "te_overlay.png", items, docs, doc["comparison"]["nominal"])
        )
    text = _markdown(doc)
    paths.append(atomic_write(out / "comparison.md", lambda p: p.write_text(text, "utf-8")))
    doc["files"] = [p.name for p in paths] + ["sweep.json"]
    paths.append(write_json(out / "sweep.json", doc))
    return paths


def comparison_error(out: Path, items: Sequence, results: Mapping, meta: Mapping[str, Any]) -> str:
    """Why the comparison of the sweep in ``out`` cannot be made ("" if it can)."""
    _, _, keyres = _document(Path(out), items, results, meta)
    return comparison(items, keyres, meta.get("nominal")).get("error") or ""
