"""Error against time (the Pareto front of the fidelities), one PNG per scene.

Reads benchmarks/results/hertz_scene.json (`bench_hertz_scene.py`) and
benchmarks/results/fidelity_*.json (`bench_fidelity.py`); writes docs/fidelity/pareto_*.png.

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
    import sys

    sys.path.insert(0, str(HERE))
    from bench_fidelity import errors

    path = HERE / "results" / f"fidelity_{scene}.json"
    if not path.exists():
        return None
    ref, rows = errors(json.loads(path.read_text()))
    rows = [r for r in rows if not (r.get("fidelity") == "fe" and r["level"] == ref["level"])]
    fig, axes = plt.subplots(1, 3, figsize=(14, 4))
    _series(axes[0], rows, lambda r: r["err_te_pp"])
    axes[0].set_title("loaded TE peak-to-peak (relative)")
    axes[0].axhline(0.05, color="k", lw=0.6, ls="--")
    _series(axes[1], rows, lambda r: r["err_share"])
    axes[1].set_title("load share of pair (0, 0): max abs difference")
    axes[1].axhline(0.02, color="k", lw=0.6, ls="--")
    _series(axes[2], rows, lambda r: r["err_p_max_interior"])
    axes[2].set_title("p_max, positions without edge contact (relative)")
    axes[2].axhline(0.02, color="k", lw=0.6, ls="--")
    for ax in axes:
        ax.set_xlabel("cold time (s), 2 cores")
        ax.legend(fontsize=8)
    fig.suptitle(
        f"{scene.replace('_', ' ')}: error against the finest fe level ({ref['level']}, "
        f"{ref['cold_s']:.0f} s cold); dashed: the issue's targets"
    )
    fig.tight_layout()
    OUT.mkdir(parents=True, exist_ok=True)
    out = OUT / f"pareto_{scene}.png"
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def main() -> None:
    for p in (hertz_scene(), gear_scene("face_gear"), gear_scene("spiral_bevel")):
        if p is not None:
            print(p)


if __name__ == "__main__":
    main()
