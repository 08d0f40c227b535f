"""The PNG pictures of a gear run: ``te.png``, ``load_share.png``, ``p_max.png``,
``root_stress.png`` (loaded fidelities), and the unloaded TE of the TCA. Their titles quote the
headlines of the result model (:class:`fegear.results.GearRunResult`), never recompute them."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from fegear.output.figure import pyplot as _plt
from fegear.output.figure import run_title as _title
from fegear.output.figure import save_png as _save
from fegear.output.p_max_plot import save_p_max
from fegear.output.pattern_plot import plot_loaded_pattern, plot_unloaded_pattern
from fegear.pipeline.run import GearRun
from fegear.results.model import GearRunResult
from fegear.store.files import atomic_write
from fegear.tca.plots import plot_te

__all__ = ["TESeries", "loaded_plots", "per_pair", "tca_plots", "te_series"]

Array = NDArray[np.float64]


def _num(x: float | None, fmt: str) -> str:
    return "not reported" if x is None else format(x, fmt)


@dataclass(frozen=True)
class TESeries:
    """What ``te.png`` draws.

    Attributes
    ----------
    phi1_deg
        ``(n,)`` pinion angles of the positions (deg).
    unloaded
        ``(n,)`` arcsec, the unloaded TE (NaN where the TCA found no contact: a placeholder).
    loaded
        ``(n,)`` arcsec, the loaded TE of the usable positions (NaN at those left out).
    left_out
        ``{status: (m,) position indices}`` of the positions left out of the loaded TE
        (``"degenerate"``, ``"lost"``).
    left_out_te
        ``(n,)`` arcsec, the loaded TE as the cycle holds it at every position (where the
        left-out positions are marked).
    """

    phi1_deg: Array
    unloaded: Array
    loaded: Array
    left_out: dict[str, NDArray[np.int_]]
    left_out_te: Array


def te_series(cycle) -> TESeries:
    """The :class:`TESeries` of a :class:`~fegear.ltca.results.LoadedCycle`."""
    pos = cycle.positions
    ok = np.array([p.status == "ok" for p in pos], dtype=bool)
    seen = np.array([p.unloaded_contact for p in pos], dtype=bool)
    te_l = np.asarray(cycle.te_loaded_arcsec, dtype=float)
    te_u = np.asarray(cycle.te_unloaded_arcsec, dtype=float)
    status = sorted({p.status for p in pos} - {"ok"})
    left = {s: np.array([i for i, p in enumerate(pos) if p.status == s], dtype=int) for s in status}
    return TESeries(
        np.degrees(np.asarray(cycle.phi1, dtype=float)),
        np.where(seen, te_u, np.nan),
        np.where(ok, te_l, np.nan),
        left,
        te_l,
    )


def _plot_te(out: Path, run: GearRun, result: GearRunResult) -> Path:
    """``te.png``: the unloaded TE (a gap where the TCA found no contact) and the loaded TE of
    the usable positions, the headline's; the positions left out of it (lost, degenerate) as
    open markers at the value the cycle holds there."""
    plt = _plt()
    s = te_series(run.cycle)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.plot(s.phi1_deg, s.unloaded, "o-", ms=3, label="unloaded")
    ok = np.isfinite(s.loaded)  # the line joins the usable positions (the headline's)
    ax.plot(s.phi1_deg[ok], s.loaded[ok], "s-", ms=3, label="loaded (usable positions)")
    for (status, idx), m in zip(s.left_out.items(), "DvX", strict=False):
        ax.plot(s.phi1_deg[idx], s.left_out_te[idx], m, ms=7, mfc="none", mec="tab:red",
                mew=1.2, ls="none", label=f"left out: {status} ({idx.size})")  # fmt: skip
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("TE (arcsec)")
    h = result.cycle
    ax.set_title(
        f"{_title(run)}\nTE p-p unloaded {_num(h.te_pp_unloaded_arcsec, '.2f')}, loaded "
        f"{_num(h.te_pp_loaded_arcsec, '.2f')} arcsec "
        f"(over {h.te_pp_loaded_positions_used} of {h.n_positions} positions)",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, out / "te.png")


def per_pair(cycle, attr: str) -> dict[int, Array]:
    """``{pinion tooth: (n,) values of attr}`` of the loaded pairs of ``cycle`` (NaN where the
    pair is not modelled or carries no load: out of contact)."""
    teeth = sorted({q.k for p in cycle.positions for q in p.pairs})
    out = {k: np.full(len(cycle.positions), np.nan) for k in teeth}
    for i, p in enumerate(cycle.positions):
        for q in p.pairs:
            if q.force_N > 0:
                out[q.k][i] = getattr(q, attr)
    return out


def _plot_load_share(out: Path, run: GearRun, result: GearRunResult) -> Path:
    """``load_share.png``: each pair's share of the torque where it is in contact (a gap where
    it is not: its curve starts and ends where its contact does)."""
    plt = _plt()
    deg = np.degrees(run.cycle.phi1)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for k, v in per_pair(run.cycle, "load_share").items():
        ax.plot(deg, v, "o-", ms=3, label=f"pinion tooth {k:+d}")
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("load share (torque fraction)")
    ax.set_ylim(-0.05, 1.05)
    cr = result.cycle.contact_ratio_loaded
    ax.set_title(f"{_title(run)}\nloaded contact ratio {_num(cr, '.2f')}; each pair drawn "
                 "where it carries load", fontsize=9)  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, out / "load_share.png")


def _plot_p_max(out: Path, run: GearRun, result: GearRunResult) -> Path:
    """``p_max.png`` (:mod:`fegear.output.p_max_plot`: the values away from the edges as lines,
    the singular edge values marked apart)."""
    h = result.cycle
    edge = (
        f"; at the edges {h.p_max_edge_MPa:.0f} MPa (singular)"
        if h.p_max_edge_MPa is not None
        else ""
    )
    title = f"{_title(run)}\ncycle p_max away from the edges {_num(h.p_max_MPa, '.0f')} MPa{edge}"
    return save_p_max(out / "p_max.png", run.cycle, title, _save)


def _one_tooth(mf, phi1_deg: np.ndarray, pitch_deg: float):
    """The root stress of one tooth over its whole passage through the mesh, pieced together
    from the teeth of the cycle: tooth ``t`` at ``φ1`` is tooth 0 at ``φ1 − σ t p`` (``p`` the
    pinion's angular pitch; ``σ = ±1``, the sense that makes the loaded stretches of the teeth
    one: the smaller spread). Returns ``(x_deg, tension, compression)`` sorted by ``x``."""
    teeth = mf.root_teeth
    best = None
    for sigma in (1.0, -1.0):
        xs = [phi1_deg - sigma * t * pitch_deg for t in teeth]
        loaded = [
            x[[any(r.tooth == t and r.loaded for r in row) for row in mf.root]]
            for t, x in zip(teeth, xs, strict=True)
        ]
        centres = [float(np.mean(v)) for v in loaded if v.size]
        spread = float(np.ptp(centres)) if centres else 0.0
        if best is None or spread < best[0]:
            best = (spread, xs)
    x = np.concatenate(best[1])
    ten = np.concatenate([mf.root_series(t) for t in teeth])
    com = np.concatenate([mf.root_series(t, "compression_MPa") for t in teeth])
    o = np.argsort(x)
    return x[o], ten[o], com[o]


def _plot_root_stress(out: Path, run: GearRun) -> Path:
    """``root_stress.png``: per member, the tension-fillet maximum principal stress and the
    compression-fillet minimum principal stress of one tooth over its passage through the mesh
    (:func:`_one_tooth`), against the pinion angle of the cycle."""
    plt = _plt()
    c = run.cycle
    deg = np.degrees(c.phi1)
    pitch = 360.0 / run.assembly.n1
    fig, axes = plt.subplots(1, len(run.members), figsize=(11, 4), squeeze=False)
    for ax, mf in zip(axes[0], run.members, strict=True):
        if not mf.root_teeth:
            ax.set_title(f"{mf.name}: no loaded position", fontsize=9)
            continue
        x, ten, com = _one_tooth(mf, deg, pitch)
        ax.plot(x, ten, "o-", ms=3, color="tab:red", label="tension fillet, max principal")
        ax.plot(x, com, "s--", ms=3, color="tab:blue", label="compression fillet, min principal")
        ax.axhline(0.0, color="gray", lw=0.5)
        ax.set_xlabel("pinion angle of the tooth's passage φ1 (deg)")
        ax.set_ylabel("root stress (MPa)")
        top = float(np.nanmax(ten))
        ax.set_title(
            f"{mf.name}: one tooth through the mesh; max {top:.0f} MPa "
            f"(fillet elements {mf.fillet_mm:.3g} mm)",
            fontsize=9,
        )
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(_title(run), fontsize=9)
    return _save(fig, out / "root_stress.png")


def tca_plots(out: Path, run: GearRun) -> list[Path]:
    """``te.png`` (the unloaded TE) and ``bearing_pattern.png`` (paint thickness) of an unloaded
    run."""
    r, name = run.tca, run.case.name
    paths = [atomic_write(out / "te.png", lambda q: plot_te({name: r}, q,
                          title=f"{name}: unloaded TE (TCA)"))]  # fmt: skip
    paths.append(plot_unloaded_pattern(out, run))
    return paths


def loaded_plots(out: Path, run: GearRun, result: GearRunResult) -> list[Path]:
    """``te.png``, ``load_share.png``, ``p_max.png``, ``bearing_pattern.png`` and, with the
    root stress, ``root_stress.png`` of a loaded run (``result``: its model, whose headlines the
    titles quote)."""
    paths = [_plot_te(out, run, result), _plot_load_share(out, run, result),
             _plot_p_max(out, run, result), plot_loaded_pattern(out, run)]  # fmt: skip
    if run.members and any(mf.root for mf in run.members):
        paths.append(_plot_root_stress(out, run))
    return paths
