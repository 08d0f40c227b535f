"""Error against time (the Pareto front of the fidelities), one PNG per scene.

Reads benchmarks/results/hertz_scene.json (`bench_hertz_scene.py`) and
benchmarks/results/fidelity_*.json (`bench_fidelity.py`); writes docs/fidelity/pareto_*.png and
docs/fidelity/cycle_*.png (load share and loaded TE over the cycle, every fidelity and level).

Usage::

    python benchmarks/plot_pareto.py
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE.parent / "docs" / "fidelity"
STYLE = {"fe": ("o", "tab:blue"), "hybrid": ("s", "tab:red"), "hertz": ("^", "tab:green")}


def _series(ax, rows, key_err, key_t="cold_s", label_fn=None):
    for fid, (marker, color) in STYLE.items():
        pts = [r for r in rows if r.get("fidelity") == fid and "failed" not in r]
        pts = [r for r in pts if math.isfinite(abs(key_err(r))) and abs(key_err(r)) > 0]
        if not pts:
            continue
        pts.sort(key=lambda r: r[key_t])
        x = [r[key_t] for r in pts]
        y = [abs(key_err(r)) for r in pts]
        ax.plot(x, y, marker=marker, color=color, label=fid, lw=1)
        for r, xi, yi in zip(pts, x, y, strict=True):
            ax.annotate(label_fn(r) if label_fn else f"L{r['level']}", (xi, yi), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())  # the labels overlapped
    ax.grid(True, which="both", lw=0.3)


def hertz_scene() -> Path | None:
    path = HERE / "results" / "hertz_scene.json"
    if not path.exists():
        return None
    rows = json.loads(path.read_text())
    for r in rows:
        r["cold_s"] = r["t"]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    label = lambda r: (  # noqa: E731
        f"g{r['level']}" if r["fidelity"] == "fe" else f"g{r['level']}/FE{r['fe_level']}"
    )
    _series(axes[0], rows, lambda r: r["e_p0"], label_fn=label)
    axes[0].set_title("recovered p0 vs Hertz")
    _series(axes[1], rows, lambda r: max(abs(r["e_a"]), abs(r["e_b"])), label_fn=label)
    axes[1].set_title("semi-axes max(|err a|, |err b|) vs Hertz")
    for ax in axes:
        ax.set_xlabel("cold time (s), 2 cores")
        ax.set_ylabel("|relative error|")
        ax.axhline(0.01, color="k", lw=0.6, ls="--")
        ax.legend(fontsize=8)
    fig.suptitle("Hertz scene: error against time (g = contact grid level, FE = mesh level)")
    fig.tight_layout()
    OUT.mkdir(parents=True, exist_ok=True)
    out = OUT / "pareto_hertz_scene.png"
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def gear_scene(scene: str) -> Path | None:
    """Top row: errors against the finest ``fe`` level; bottom row: against the finest
    ``hybrid`` level (on localized contact the hybrid is converged in the FE level where ``fe``
    is not, so both views are shown)."""
    import sys

    sys.path.insert(0, str(HERE))
    from bench_fidelity import errors

    path = HERE / "results" / f"fidelity_{scene}.json"
    if not path.exists():
        return None
    runs = json.loads(path.read_text())
    refs = [f for f in ("fe", "hybrid") if any(r.get("fidelity") == f and "failed" not in r
                                               for r in runs)]  # fmt: skip
    fig, axes = plt.subplots(len(refs), 3, figsize=(14, 4 * len(refs)), squeeze=False)
    for row, reference in zip(axes, refs, strict=True):
        ref, rows = errors(runs, reference)
        rows = [
            r for r in rows if not (r.get("fidelity") == reference and r["level"] == ref["level"])
        ]
        name = f"{reference} L{ref['level']}"
        _series(row[0], rows, lambda r: r["err_te_pp"])
        row[0].set_title(f"loaded TE peak-to-peak vs {name} (relative)", fontsize=9)
        row[0].axhline(0.05, color="k", lw=0.6, ls="--")
        _series(row[1], rows, lambda r: r["err_share"])
        row[1].set_title(f"load share of pair (0, 0) vs {name}: max abs diff", fontsize=9)
        row[1].axhline(0.02, color="k", lw=0.6, ls="--")
        _series(row[2], rows, lambda r: r["err_p_max_interior"])
        row[2].set_title(f"p_max without edge contact vs {name} (relative)", fontsize=9)
        row[2].axhline(0.02, color="k", lw=0.6, ls="--")
        for ax in row:
            ax.set_xlabel("cold time (s), 2 cores")
            ax.legend(fontsize=8)
    fig.suptitle(
        f"{scene.replace('_', ' ')}: error against time; dashed: the issue's targets "
        "(2 %, 0.02, 5 %)"
    )
    fig.tight_layout()
    OUT.mkdir(parents=True, exist_ok=True)
    out = OUT / f"pareto_{scene}.png"
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


def gear_curves(scene: str) -> Path | None:
    """Load share of pair (0, 0) and loaded TE over the positions, every fidelity and level."""
    path = HERE / "results" / f"fidelity_{scene}.json"
    if not path.exists():
        return None
    rows = [r for r in json.loads(path.read_text()) if "failed" not in r]
    rows.sort(key=lambda r: (r["fidelity"], r["level"]))
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    shades = {"fe": plt.cm.Blues, "hybrid": plt.cm.Reds, "hertz": plt.cm.Greens}
    for r in rows:
        lv = [x["level"] for x in rows if x["fidelity"] == r["fidelity"]]
        shade = shades[r["fidelity"]](
            0.45 + 0.55 * (r["level"] - min(lv)) / max(1, max(lv) - min(lv))
        )
        kw = {"color": shade, "marker": STYLE[r["fidelity"]][0], "ms": 3, "lw": 1}
        label = f"{r['fidelity']} L{r['level']}"
        axes[0].plot(r["phi1_deg"], r["share00"], label=label, **kw)
        axes[1].plot(r["phi1_deg"], r["te_loaded"], label=label, **kw)
    axes[0].set_ylabel("load share of pair (0, 0)")
    axes[1].set_ylabel("loaded TE (arcsec)")
    for ax in axes:
        ax.set_xlabel("pinion angle (deg)")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, ncol=2)
    fig.suptitle(f"{scene.replace('_', ' ')}: every fidelity and level over the mesh cycle")
    fig.tight_layout()
    out = OUT / f"cycle_{scene}.png"
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def main() -> None:
    for p in (
        hertz_scene(),
        gear_scene("face_gear"),
        gear_scene("spiral_bevel"),
        gear_curves("face_gear"),
        gear_curves("spiral_bevel"),
    ):
        if p is not None:
            print(p)


if __name__ == "__main__":
    main()
