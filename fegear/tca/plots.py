"""TCA plots (matplotlib, Agg): TE over the cycle, contact paths, bearing pattern, conventions."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .ellipse import outline
from .results import CycleResult

Array = NDArray[np.float64]
#: the dash of a line contact's contact line (:func:`draw_ellipses`)
LINE_STYLE = (0, (4, 2))

__all__ = [
    "plot_te",
    "plot_paths",
    "plot_pattern",
    "plot_assembly_conventions",
    "flank_outline",
    "draw_ellipses",
    "Drawn",
    "contact_kind",
    "contact_line",
    "clip_to_box",
    "legend_entries",
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


@dataclass(frozen=True)
class Drawn:
    """What :func:`draw_ellipses` drew: ``ellipses`` outlines, ``lines`` contact-line segments
    (line contacts, :func:`contact_kind`)."""

    ellipses: int
    lines: int

    def __bool__(self) -> bool:
        return self.ellipses + self.lines > 0


def _extent(bounds) -> Array:
    """``(2,)`` the flank's coordinate extent ``(u_tip − u_fillet, v_end − v_start)``."""
    return np.array([bounds.u_tip - bounds.u_fillet, bounds.v_end - bounds.v_start], dtype=float)


def contact_kind(e, member: str, which: str, bounds=None) -> str:
    """``"point"``, ``"line"`` or ``"none"``: how the ellipse ``which`` (``"paint"`` or
    ``"hertz"``) of :class:`~fegear.tca.ellipse.EllipseAt` ``e`` is to be drawn on ``member``'s
    flank.

    A line contact (``e.line_contact``) has no ellipse; an ellipse whose outline spans more of
    either flank coordinate than the flank has (``bounds``: its
    :class:`~fegear.geometry.surface.FlankBoundaries`) is a line contact too: the flank cannot
    hold it, its contact is the line the flank cuts from the major axis. ``"none"``: no ellipse
    of that kind (e.g. no Hertz ellipse without a load) and no line to draw.
    """
    if e.line_contact:
        return "line"
    o = outline(e, member, which)
    if o is None:
        return "none"
    if bounds is not None and np.any(np.ptp(o, axis=0) > _extent(bounds)):
        return "line"
    return "point"


def clip_to_box(p0: Array, d: Array, lo: Array, hi: Array) -> Array | None:
    """``(2, 2)`` the segment of the line ``p0 + t d`` inside the box ``[lo, hi]`` (2-D;
    Liang-Barsky), or None when the line misses it."""
    t0, t1 = -np.inf, np.inf
    for k in range(2):
        if abs(d[k]) < 1e-300:
            if not lo[k] <= p0[k] <= hi[k]:
                return None
            continue
        a, b = sorted(((lo[k] - p0[k]) / d[k], (hi[k] - p0[k]) / d[k]))
        t0, t1 = max(t0, a), min(t1, b)
    if not t0 < t1:
        return None
    return np.array([p0 + t0 * d, p0 + t1 * d])


def contact_line(e, member: str, bounds) -> Array | None:
    """``(2, 2)`` flank coordinates ``(u, v)`` of the contact line of a line contact: the major
    axis through the contact point, taken to the flank through its tangents (first order) and
    clipped to the flank's ``[u_fillet, u_tip] × [v_start, v_end]`` (None: it misses it)."""
    c = e.curvature
    T, uv0 = (
        (c.pinion_tangents, e.pinion_uv) if member == "pinion" else (c.gear_tangents, e.gear_uv)
    )
    d = np.linalg.lstsq(T, c.major_axis, rcond=None)[0]
    lo = np.array([bounds.u_fillet, bounds.v_start], dtype=float)
    hi = np.array([bounds.u_tip, bounds.v_end], dtype=float)
    return clip_to_box(np.asarray(uv0, dtype=float), d, lo, hi)


def draw_ellipses(
    ax,
    ellipses,
    member: str = "pinion",
    which: Sequence[str] = ("paint", "hertz"),
    xy=None,
    color: str = "tab:blue",
    lw: float = 0.6,
    bounds=None,
    lines: bool = True,
) -> Drawn:
    """Draw the contact ellipses of a TCA path (:func:`fegear.tca.ellipse.ellipses`) on a flank.

    ``member``: whose flank coordinates; ``which``: ``"paint"`` (Litvin's instantaneous ellipse,
    solid) and/or ``"hertz"`` (one pair carrying the whole load, dashed); ``xy(uv (n, 2)) ->
    (x (n,), y (n,))`` the plot coordinates of flank coordinates (default ``(v, u)``).
    ``bounds`` (the flank's boundaries): a line contact (:func:`contact_kind`: none, or an
    ellipse longer than the flank) is drawn as its contact line clipped to the flank (dashed,
    twice as wide), once per position (``lines`` False: not drawn); without ``bounds`` line
    contacts are left out. Returns the :class:`Drawn` counts.
    """
    xy = xy or (lambda uv: (uv[:, 1], uv[:, 0]))
    styles = {"paint": "-", "hertz": "--"}
    n = n_lines = 0
    for e in ellipses:
        if e is None:
            continue
        line = False
        for w in which:
            kind = contact_kind(e, member, w, bounds)
            if kind == "point":
                x, y = xy(outline(e, member, w))
                ax.plot(x, y, styles[w], color=color, lw=lw)
                n += 1
            line |= kind == "line"
        seg = contact_line(e, member, bounds) if line and lines and bounds is not None else None
        if seg is not None:
            x, y = xy(seg)
            ax.plot(x, y, ls=LINE_STYLE, color=color, lw=2 * lw)
            n_lines += 1
    return Drawn(n, n_lines)


def legend_entries(ax, drawn: Drawn, which: str, color: str, label: str, lw: float) -> None:
    """Legend entries for what :func:`draw_ellipses` drew: ``label`` for the ellipses (``which``
    their style), and "line contact" for the contact lines, with their counts."""
    if drawn.ellipses:
        ax.plot([], [], "-" if which == "paint" else "--", color=color, lw=lw, label=label)
    if drawn.lines:
        ax.plot([], [], ls=LINE_STYLE, color=color, lw=2 * lw,
                label=f"line contact at {drawn.lines} positions (ellipse longer than the "
                "flank): contact line, no ellipse")  # fmt: skip


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
    if ellipses is not None:
        T1 = next((e.pinion_torque_Nm for e in ellipses if e is not None), 0.0)
        d = draw_ellipses(ax, ellipses, "pinion", ("paint",), lw=0.5, bounds=bounds)
        legend_entries(ax, d, "paint", "tab:blue", f"ellipse, paint {1e3 * r.paint_mm:.2f} µm", 0.5)
        d = draw_ellipses(ax, ellipses, "pinion", ("hertz",), color="tab:green", lw=0.5,
                          bounds=bounds, lines=False)  # fmt: skip
        legend_entries(ax, d, "hertz", "tab:green",
                       f"Hertz, one pair at {T1:.4g} N·m", 0.5)  # fmt: skip
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
