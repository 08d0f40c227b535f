"""Comparing runs: :func:`table` (the headline numbers and the pattern shift side by side),
:func:`plot_te` (the TE curves on one figure) and :func:`plot_patterns` (where the contact is on
one member's flank)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from fegear.api.gear_result import GearResult
from fegear.errors import InputError
from fegear.io.gear_case import error_fields
from fegear.store.files import atomic_write

__all__ = ["plot_patterns", "plot_te", "table"]


def _fmt(x: float | None, spec: str) -> str:
    return "—" if x is None or not math.isfinite(x) else format(x, spec)


def table(
    results: Mapping[str, GearResult], reference: str | None = None, member: str = "gear"
) -> str:
    """A text table of runs side by side: TE peak-to-peak, contact ratio, p_max and where the
    bearing pattern is on ``member``'s flank, with its shift against ``reference``.

    Parameters
    ----------
    results
        ``{label: result}``, in the order of the rows.
    reference
        Label of the reference row of the shifts (default: the first result without
        installation errors, else the first).
    member
        ``"gear"`` or ``"pinion"``: whose flank the pattern is measured on.

    Returns
    -------
    str
        The table (Markdown): ``TE p-p`` unloaded / loaded (arcsec), the unloaded contact ratio
        of one pair's path and the loaded contact ratio, p_max away from the edges (MPa), the
        pattern centre ``face`` and ``profile`` (mm, :class:`~fegear.output.flank_view.FlankFrame`)
        and their shifts ``Δface``, ``Δprofile`` against the reference ("—": not reported).
    """
    if not results:
        raise InputError("results", "{}", "at least one result")
    if member not in ("pinion", "gear"):
        raise InputError("member", member, "'pinion' or 'gear'")
    labels = list(results)
    if reference is None:
        reference = next((k for k in labels if not error_fields(results[k].case)), labels[0])
    if reference not in results:
        raise InputError("reference", reference, f"one of the labels {labels}")
    ref = results[reference].pattern[member]
    first = results[labels[0]].pattern[member]
    head = (
        "| case | TE p-p unloaded (arcsec) | TE p-p loaded (arcsec) | contact ratio unloaded | "
        "contact ratio loaded | p_max (MPa) | face (mm) | profile (mm) | Δface (mm) | "
        "Δprofile (mm) |"
    )
    rows = [
        f"{member} flank: face = {first.face_name}; profile = {first.profile_name}; "
        f"pattern centre by {first.weighting}; shifts against {reference!r}",
        "",
        head,
        "|" + "---|" * 10,
    ]
    for label, r in results.items():
        c, pc = r.cycle, r.pattern[member]
        dface = dprof = None
        if pc.face_mm is not None and ref.face_mm is not None:
            dface, dprof = pc.face_mm - ref.face_mm, pc.profile_mm - ref.profile_mm
        rows.append(
            f"| {label} | {_fmt(c.te_pp_unloaded_arcsec, '.2f')} | "
            f"{_fmt(c.te_pp_loaded_arcsec, '.2f')} | "
            f"{_fmt(r.checks.contact_ratio_unloaded, '.3f')} | "
            f"{_fmt(c.contact_ratio_loaded, '.2f')} | {_fmt(c.p_max_MPa, '.0f')} | "
            f"{_fmt(pc.face_mm, '.2f')} | {_fmt(pc.profile_mm, '.3f')} | {_fmt(dface, '+.2f')} | "
            f"{_fmt(dprof, '+.3f')} |"
        )
    return "\n".join(rows)


def _savefig(fig, path: str | Path) -> Path:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    out = atomic_write(Path(path), lambda q: fig.savefig(q, format="png", dpi=110))
    plt.close(fig)
    return out


def plot_te(results: Mapping[str, GearResult], path: str | Path, title: str = "") -> Path:
    """The TE curves of several runs on one figure (unloaded dashed, loaded solid), PNG.

    Parameters
    ----------
    results
        ``{label: result}``.
    path
        The PNG (its folder is made if missing).
    title
        Figure title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for i, (label, r) in enumerate(results.items()):
        color = f"C{i % 10}"
        ax.plot(r.pinion_angle_deg, r.te_unloaded_arcsec, "--", color=color, lw=1,
                label=f"{label} unloaded")  # fmt: skip
        if np.isfinite(r.te_loaded_arcsec).any():
            ax.plot(r.pinion_angle_deg, r.te_loaded_arcsec, "-", color=color, lw=1.5,
                    label=f"{label} loaded")  # fmt: skip
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("TE (arcsec; negative: the gear lags)")
    ax.set_title(title or "transmission error over one mesh cycle", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return _savefig(fig, path)


def plot_patterns(
    results: Mapping[str, GearResult], path: str | Path, member: str = "gear", title: str = ""
) -> Path:
    """Where the contact is on one member's flank for several runs, on one figure (PNG):
    the unloaded contact path (fidelity ``tca``) or the loaded cells' force centroids per
    position (loaded fidelities), the pattern centre (+) and the working-surface outline.

    Parameters
    ----------
    results
        ``{label: result}`` (runs of the same pair).
    path
        The PNG (its folder is made if missing).
    member
        ``"gear"`` or ``"pinion"``.
    title
        Figure title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if member not in ("pinion", "gear"):
        raise InputError("member", member, "'pinion' or 'gear'")
    fig, ax = plt.subplots(figsize=(8, 4.2))
    frame = None
    for i, (label, r) in enumerate(results.items()):
        color = f"C{i % 10}"
        v = r._views
        frame = v.frames[member]
        if r.run.cycle is None:
            t = r.run.tca
            uv = (t.pinion_uv if member == "pinion" else t.gear_uv)[t.has_contact]
            xy = frame.coordinates(uv[:, 0], uv[:, 1])
            ax.plot(xy[:, 0], xy[:, 1], "-o", ms=3, color=color, lw=1, label=label)
        else:
            pts = [
                (p[member].force_N @ p[member].centres) / p[member].force_N.sum()
                for p in v.patches
                if p[member].force_N.size
            ]
            if pts:
                xy = np.array(pts)
                ax.plot(xy[:, 0], xy[:, 1], "o", ms=3, color=color, label=label)
        pc = r.pattern[member]
        if pc.face_mm is not None:
            ax.plot([pc.face_mm], [pc.profile_mm], "+", ms=14, mew=2, color=color)
    if frame is not None:
        o = frame.outline
        ax.plot(o[:, 0], o[:, 1], "k-", lw=1)
        a, b = frame.face_ends
        ax.set_xlabel(f"{frame.face_name}  ({a} → {b})" if a else frame.face_name)
        ax.set_ylabel(frame.profile_name)
    ax.set_title(title or f"contact on the {member} flank (+: pattern centre)", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return _savefig(fig, path)
