"""TCA plots (matplotlib, Agg): TE over the cycle, contact paths, bearing pattern, conventions."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .ellipse import outline
from .results import CycleResult

__all__ = [
    "plot_te",
    "plot_paths",
    "plot_pattern",
    "plot_assembly_conventions",
    "flank_outline",
    "draw_ellipses",
    "axis_label",
]


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_te(results: dict[str, CycleResult], path: str | Path, title: str = "") -> Path:
    """TE over the cycle: every pair's curve (thin), the TE (thick), transfer points (dots)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4))
    for i, (label, r) in enumerate(results.items()):
        c = f"C{i}"
        deg = np.degrees(r.phi1)
        for p in range(r.pairs.shape[0]):
            m = r.pair_valid[:, p] & (r.pair_te_arcsec[:, p] > r.te_arcsec.min() - 50)
            ax.plot(deg[m], r.pair_te_arcsec[m, p], color=c, lw=0.6, ls=":")
        ax.plot(deg[r.has_contact], r.te_arcsec[r.has_contact], color=c, lw=2, label=label)
        if len(r.transfer_points):
            ax.plot(np.degrees(r.transfer_points[:, 0]), r.transfer_points[:, 1], "o", color=c)
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("unloaded TE (arcsec)")
    ax.set_title(title or "unloaded TE (dotted: single pairs; dots: transfer points)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def plot_paths(
    results: dict[str, CycleResult],
    path: str | Path,
    member: str = "gear",
    bounds=None,
    labels: Sequence[str] = ("inner", "outer"),
    ellipses: bool = True,
    title: str = "",
    pair_paths: dict[str, np.ndarray] | None = None,
) -> Path:
    """Contact paths in flank coordinates (face width × profile) of ``member``.

    ``bounds`` (a :class:`FlankBoundaries`) draws the flank outline; ``labels`` name the face
    ends ``v_start`` / ``v_end`` (e.g. inner/outer, toe/heel). Ellipses: paint-thickness ellipses
    drawn as their projected major-axis extent along the path (a, to scale in ``v``).
    ``pair_paths`` (same keys as ``results``): ``(n, 2)`` flank coordinates of one pair over its
    whole contact interval (:func:`fegear.tca.path.contact_path`), drawn as a dashed line — where
    two pairs touch at once the cycle's contact point shows only one of them.
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4))

    def y(uv):  # the profile coordinate drawn: physical where the family defines it
        return uv[:, 0] if bounds is None else bounds.profile(uv[:, 0], uv[:, 1])

    for i, (label, r) in enumerate(results.items()):
        uv = r.gear_uv if member == "gear" else r.pinion_uv
        m = r.has_contact
        ax.plot(uv[m, 1], y(uv[m]), "-o", ms=3, color=f"C{i}", label=label)
        e = r.edge & m
        if e.any():
            ax.plot(uv[e, 1], y(uv[e]), "x", ms=7, color=f"C{i}")
        if pair_paths and label in pair_paths:
            pp = np.asarray(pair_paths[label])
            ax.plot(pp[:, 1], y(pp), "--", lw=1.5, color=f"C{i}")
        if ellipses:
            yy = y(uv)
            for k in np.nonzero(m)[0]:
                a = r.paint_axes_mm[k, 0]
                if a > 0:
                    ax.plot([uv[k, 1] - a, uv[k, 1] + a], [yy[k]] * 2, color=f"C{i}", lw=0.4)
    if bounds is not None:
        flank_outline(ax, bounds, labels)
    ax.set_title(title or f"contact paths on the {member} flank (x: edge contact)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def flank_outline(ax, bounds, labels: Sequence[str] = ("", "")) -> None:
    """Draw the working surface of a flank on ``ax``: face (``v``) across, the profile
    coordinate up — physical (:meth:`FlankBoundaries.profile`) where the family defines it, so
    a fillet limit that is a curve over the face is drawn as one."""
    b = bounds
    v = np.linspace(b.v_start, b.v_end, 121)
    lo, hi = b.fillet_curve(v), b.tip_curve(v)
    ax.plot(np.r_[v, v[::-1], v[:1]], np.r_[lo, hi[::-1], lo[:1]], "k-", lw=1)
    if labels[0]:
        ax.annotate(labels[0], (v[0], hi[0]), textcoords="offset points", xytext=(2, 4))
    if labels[1]:
        ax.annotate(labels[1], (v[-1], hi[-1]), textcoords="offset points", xytext=(-30, 4))
    ax.set_xlabel(b.v_name)
    ax.set_ylabel(b.height_name or b.u_name)


def axis_label(text: str, width: int = 42) -> str:
    """An axis label wrapped to lines of at most ``width`` characters (a flank coordinate's
    long name, e.g. the spiral bevel's working-height fraction, would run off the figure)."""
    import textwrap

    return "\n".join(textwrap.wrap(text, width)) or text


def draw_ellipses(
    ax,
    ellipses,
    member: str = "pinion",
    which: Sequence[str] = ("paint", "hertz"),
    xy=None,
    color: str = "tab:blue",
    lw: float = 0.6,
) -> int:
    """Draw the contact ellipses of a TCA path (:func:`fegear.tca.ellipse.ellipses`) on a flank.

    ``member``: whose flank coordinates; ``which``: ``"paint"`` (Litvin's instantaneous ellipse,
    solid) and/or ``"hertz"`` (one pair carrying the whole load, dashed); ``xy(uv (n, 2)) ->
    (x (n,), y (n,))`` the plot coordinates of flank coordinates (default ``(v, u)``). Returns the
    number of outlines drawn (line contacts have none).
    """
    xy = xy or (lambda uv: (uv[:, 1], uv[:, 0]))
    styles = {"paint": "-", "hertz": "--"}
    n = 0
    for e in ellipses:
        if e is None:
            continue
        for w in which:
            o = outline(e, member, w)
            if o is None:
                continue
            x, y = xy(o)
            ax.plot(x, y, styles[w], color=color, lw=lw)
            n += 1
    return n


def plot_pattern(
    r: CycleResult, path: str | Path, bounds=None, title: str = "", ellipses=None
) -> Path:
    """Unloaded bearing pattern on the pinion flank: cells within the paint thickness, the
    contact path and, with ``ellipses`` (:func:`fegear.tca.ellipse.ellipses` of the positions),
    at each contact point Litvin's instantaneous ellipse for the paint thickness (solid) and the
    Hertz ellipse of one pair carrying the whole load (dashed), as a path of ellipses (the
    contact area of Litvin's TCA)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    if r.pattern_pinion.size:
        V, U = np.meshgrid(r.grid_v, r.grid_u)
        ax.pcolormesh(V, U, r.pattern_pinion.astype(float), cmap="Greys", vmin=0, vmax=1.5)
    m = r.has_contact
    ax.plot(r.pinion_uv[m, 1], r.pinion_uv[m, 0], "r.-", ms=3, label="contact path")
    if ellipses is not None and draw_ellipses(ax, ellipses, "pinion", ("paint",), lw=0.5):
        ax.plot([], [], "-", color="tab:blue", lw=0.5,
                label=f"ellipse, paint {1e3 * r.paint_mm:.2f} µm")  # fmt: skip
        if draw_ellipses(ax, ellipses, "pinion", ("hertz",), color="tab:green", lw=0.5):
            T1 = next(e.pinion_torque_Nm for e in ellipses if e is not None)
            ax.plot([], [], "--", color="tab:green", lw=0.5,
                    label=f"Hertz, one pair at {T1:.4g} N·m")  # fmt: skip
    if bounds is not None:
        ax.set_xlim(bounds.v_start, bounds.v_end)
        ax.set_ylim(bounds.u_fillet, bounds.u_tip)
        ax.set_xlabel(axis_label(bounds.v_name))
        ax.set_ylabel(axis_label(bounds.u_name))
    ax.set_title(title or f"unloaded bearing pattern (paint {1e3 * r.paint_mm:.2f} µm)", fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def plot_assembly_conventions(path: str | Path) -> Path:
    """The sign conventions of :mod:`fegear.geometry.pair_placement` in two schematic panels."""
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4.5))
    # intersecting axes (face-gear frame: gear axis z, pinion axis x at height r_p1)
    a1.set_title("intersecting axes (face gear / bevel)")
    a1.arrow(0, -1, 0, 3.2, width=0.02, color="k")
    a1.text(0.08, 2.1, "member-2 axis (z)")
    a1.arrow(0, 1, 3.0, 0, width=0.02, color="b")
    a1.text(2.2, 1.15, "pinion axis", color="b")
    a1.plot(0, 1, "ko")
    a1.text(-0.45, 1.1, "O")
    a1.annotate("", (2.6, 1.6), (2.6, 1.0), arrowprops=dict(arrowstyle="->", color="r"))
    a1.text(2.65, 1.3, "+ΔA1 (ΔP): pinion along its axis, away from O", color="r", fontsize=7)
    a1.annotate("", (0.3, -0.9), (0.3, -0.3), arrowprops=dict(arrowstyle="->", color="g"))
    a1.text(0.35, -0.8, "+ΔA2 (ΔG, Δq): member 2 away from O", color="g", fontsize=7)
    a1.annotate("", (2.9, 1.45), (3.0, 1.0), arrowprops=dict(arrowstyle="->", color="m",
                connectionstyle="arc3,rad=0.3"))  # fmt: skip
    a1.text(1.2, 0.55, "+Δγ: shaft angle γ → γ + Δγ", color="m", fontsize=7)
    a1.text(1.2, 0.25, "+ΔE: pinion moved along +y (common\nperpendicular, out of the page)",
            color="c", fontsize=7)  # fmt: skip
    a1.set_xlim(-1, 4.5)
    a1.set_ylim(-1.2, 2.6)
    a1.set_aspect("equal")
    a1.axis("off")
    # parallel axes
    a2.set_title("parallel axes (spur / helical), plane of the axes = xz")
    a2.plot([0, 0], [-1.5, 1.5], "b-")
    a2.text(0.05, 1.55, "pinion axis (z)", color="b")
    t = np.radians(6)
    a2.plot([3 - 1.5 * np.sin(t), 3 + 1.5 * np.sin(t)], [-1.5, 1.5], "k-")
    a2.plot([3, 3], [-1.5, 1.5], "k:")
    a2.text(3.1, 1.55, "gear axis", color="k")
    a2.annotate("", (3.6, 0), (3.0, 0), arrowprops=dict(arrowstyle="->", color="r"))
    a2.text(3.2, 0.1, "+Δa", color="r")
    a2.text(0.4, -1.9, "+f_Σδ: gear axis turned about +y (in the plane of the axes):\n"
            "centre distance grows by f_Σδ from z = −b/2 to z = +b/2\n"
            "+f_Σβ: gear axis leans toward +y at z = +b/2 (out of plane)\n"
            "both in mm over the face width b, pivot at the face centre", fontsize=7)  # fmt: skip
    a2.set_xlim(-0.5, 4.5)
    a2.set_ylim(-2.6, 2.0)
    a2.set_aspect("equal")
    a2.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)
