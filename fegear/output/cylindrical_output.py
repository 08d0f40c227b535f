"""The picture of a cylindrical (spur/helical) run beside the common ones: ``line_load.png``
(the records it draws are in the result model: :mod:`fegear.results.cylindrical`)."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from fegear.results.cylindrical import load_distribution
from fegear.store.files import atomic_write

__all__ = ["plot_line_load", "ripple", "stiffness_limits"]

Array = NDArray[np.float64]
log = logging.getLogger(__name__)


def ripple(c: Array) -> tuple[float, float] | None:
    """``(mean, peak-to-peak / mean in %)`` of the finite values of ``c`` (None: none, or a
    mean of 0)."""
    f = np.asarray(c, dtype=float)
    f = f[np.isfinite(f)]
    if not f.size or not f.mean() > 0:
        return None
    return float(f.mean()), float(100.0 * np.ptp(f) / f.mean())


def stiffness_limits(c: Array) -> tuple[float, float]:
    """The y range of the mesh stiffness: from zero to 15 % above the largest finite value, so
    that a ripple of a few percent reads as what it is, not as a cliff."""
    f = np.asarray(c, dtype=float)
    f = f[np.isfinite(f)]
    top = float(f.max()) if f.size else 0.0
    return 0.0, 1.15 * top if top > 0 else 1.0


def _face_panel(ax, fig, ld, run) -> None:
    """The load per unit face width of each position (colour: the position index, dotted: left
    out of KHβ) and their mean; the legend outside the axes."""
    import matplotlib as mpl

    qm = ld.face_mm and ld.normal_force_N / ld.face_mm
    n = len(ld.positions)
    cmap = mpl.colormaps["viridis"]
    norm = mpl.colors.Normalize(0, max(n - 1, 1))
    for i, pos in enumerate(ld.positions):
        if pos.force_N > 0:
            ax.step(ld.z_mm, pos.q_N_per_mm / qm, where="mid", lw=0.7, alpha=0.7,
                    color=cmap(norm(i)), ls="-" if pos.usable else ":")  # fmt: skip
    if ld.k_h_beta is not None and ld.q_mean_N_per_mm is not None:
        ax.step(ld.z_mm, ld.q_mean_N_per_mm / qm, where="mid", lw=2.2, color="k",
                label=f"cycle mean: KHβ = {ld.k_h_beta:.3f}")  # fmt: skip
    if any(p.force_N > 0 and not p.usable for p in ld.positions):
        ax.plot([], [], ":", color="0.3", lw=0.8, label="dotted: position left out (not ok)")
    ax.plot([], [], "-", color=cmap(0.5), lw=0.7, label=f"one line per position ({n})")
    ax.axhline(1.0, color="0.5", lw=0.8)
    ax.set_xlabel("axial position z (mm, fixed frame)")
    ax.set_ylabel("load per unit face width / (F_n / b)")
    ax.set_title(f"{run.case.name}: face-width load, {ld.dz_mm:.2f} mm bins", fontsize=9)
    ax.grid(alpha=0.3)
    fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, pad=0.02,
                 label="position index")  # fmt: skip
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=2)


def _stiffness_panel(ax, ld, run) -> None:
    """The secant mesh stiffness over the cycle from zero, its mean and ripple, the positions
    left out (lost, degenerate) marked."""
    deg = np.degrees(run.cycle.phi1)
    c = np.array([np.nan if p.mesh_stiffness is None else p.mesh_stiffness for p in ld.positions])
    ax.plot(deg, c, "o-", ms=3, label="c_γ(φ)")
    status = [p.status for p in run.cycle.positions]
    lo, hi = stiffness_limits(c)
    for s, m in zip(sorted(set(status) - {"ok"}), "DvX", strict=False):
        idx = np.array([i for i, t in enumerate(status) if t == s], dtype=int)
        y = np.where(np.isfinite(c[idx]), c[idx], lo)
        ax.plot(deg[idx], y, m, ms=7, mfc="none", mec="tab:red", mew=1.2, ls="none",
                label=f"left out: {s} ({idx.size})")  # fmt: skip
    if ld.c_gamma is not None:
        ax.axhline(ld.c_gamma, color="k", lw=1.2, label=f"c_γ = {ld.c_gamma:.2f}")
    r = ripple(c)
    log.debug("line_load: c_γ ripple %s, left out %s", r, sorted(set(status) - {"ok"}))
    ax.set_ylim(lo, hi)
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("mesh stiffness c_γ(φ) (N/(mm·µm))")
    rip = "" if r is None else f"; ripple {r[1]:.1f} % p-p of the mean {r[0]:.2f}"
    ax.set_title(f"secant mesh stiffness per unit face width{rip}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.17), ncol=3)


def plot_line_load(out: Path, run) -> Path:
    """``line_load.png``: the load per unit face width of each position (coloured by the
    position index, a colour bar) and their mean (KHβ); the mesh stiffness over the cycle on an
    axis from zero, its ripple written, the positions left out (lost, degenerate) marked; the
    legends below the axes, off the data."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ld = load_distribution(run)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.6))
    _face_panel(a1, fig, ld, run)
    _stiffness_panel(a2, ld, run)
    fig.tight_layout()
    path = atomic_write(out / "line_load.png", lambda q: fig.savefig(q, format="png", dpi=110))
    plt.close(fig)
    return path
