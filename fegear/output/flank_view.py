"""Flank views: the loaded contact cells of each member in its own flank coordinates.

What a gear engineer reads is the pressure on the flank (the bearing pattern), not a sliver on a
3D sector. For each mesh position and member, the loaded contact cells (pressure > 0) are mapped
onto the member's working flank and drawn in **flank coordinates**: ``face`` across (the face
coordinate ``v`` of :class:`~fegear.geometry.surface.FlankBoundaries`: the radius ``L`` of a face
gear, the cone distance of a bevel toe → heel, the axial position ``z`` of a cylindrical gear, mm)
and ``profile`` up (:meth:`FlankBoundaries.profile`: the height above the pitch plane / cone where
the family defines it, else the profile coordinate ``u``, mm). All teeth share the one flank (the
teeth are identical): a cell carries the tooth it lies on.

The cells are the solver's (:class:`fegear.ltca.grid.PairCells`, on the pinion flank): a pinion
cell corner is the point of the exact pinion flank under it (the Newton line hit of
:func:`fegear.tca.solve.line_hit` along the pinion normal); the gear cell is the pinion cell
carried along the pinion normal by the cell's gap onto the exact gear flank, at the gear's
TCA-closed angle (the placement of the sectors in the VTK files), its flank coordinates found the
same way.

Writers and readers:

- :func:`fegear.output.flank_vtp.write_flank_vtp` — ``vtk/flank_<member>_<i>.vtp``: the
  loaded cells as quads in the plane ``(face, profile, 0)`` with cell data ``pressure_MPa``,
  ``force_N``, ``tooth``, ``pair``, ``edge``, and the working-surface outline as a line (cell
  data 0 / −1 there; ``outline`` 1); field data ``pinion_angle_deg`` (the time of the ``.pvd``
  series) and ``time_unit``.
- :func:`plot_flank_pattern` — the bearing pattern over the cycle on one member's flank (the
  envelope of all loaded patches: the largest pressure each point of the flank saw) with the
  working-surface outline (as :func:`fegear.tca.plots.flank_outline` draws it), as a PNG.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fegear.geometry.pair_placement import tooth_transform
from fegear.geometry.transforms import apply_points, apply_vectors, compose, inverse
from fegear.results.model import PatternCentre
from fegear.store.files import atomic_write
from fegear.tca.solve import line_hit
from fegear.tca.surfaces import flank_map

__all__ = [
    "FlankFrame",
    "FlankPatch",
    "PatternCentre",
    "TIME_UNIT",
    "flank_frames",
    "flank_patches",
    "pattern_centre",
    "plot_flank_pattern",
]

log = logging.getLogger(__name__)

Array = NDArray[np.float64]

#: What the time of the ``.pvd`` series is (also in every file's field data).
TIME_UNIT = "pinion angle phi1 (deg)"
MEMBERS = ("pinion", "gear")


@dataclass(frozen=True)
class FlankFrame:
    """One member's working flank in flank coordinates.

    Attributes
    ----------
    member
        ``"pinion"`` or ``"gear"``.
    face_name, profile_name
        What the two coordinates are, with units.
    outline
        ``(k, 2)`` mm, the working surface's boundary as a closed polyline ``(face, profile)``:
        the fillet limit and the tip as curves over the face (first point repeated last).
    face_ends
        Names of the face ends at ``v_start`` and ``v_end`` (``"inner end"``/``"outer end"``,
        ``"toe"``/``"heel"``, ``"-z"``/``"+z"``).
    bounds
        The :class:`~fegear.geometry.surface.FlankBoundaries`.
    """

    member: str
    face_name: str
    profile_name: str
    outline: Array
    face_ends: tuple[str, str] = ("", "")
    bounds: Any = field(default=None, repr=False, compare=False)

    def coordinates(self, u: Array, v: Array) -> Array:
        """``(..., 2)`` ``(face, profile)`` mm of flank coordinates ``(u, v)``."""
        return np.stack(np.broadcast_arrays(v, self.bounds.profile(u, v)), -1)


@dataclass(frozen=True)
class FlankPatch:
    """The loaded contact cells of one member at one position, in its flank coordinates.

    Attributes
    ----------
    member
        ``"pinion"`` or ``"gear"``.
    quads
        ``(m, 4, 2)`` mm, cell corners ``(face, profile)``.
    centres
        ``(m, 2)`` mm, cell centres ``(face, profile)``.
    pressure_MPa, force_N
        ``(m,)`` the cells' pressure and force (the solver's).
    tooth
        ``(m,)`` the member's tooth the cell lies on.
    pair
        ``(m,)`` index of the pair at the position (``positions[i].pairs[pair]`` of
        ``summary.json``).
    edge
        ``(m,)`` the cell touches a boundary of a working flank.
    """

    member: str
    quads: Array
    centres: Array
    pressure_MPa: Array
    force_N: Array
    tooth: NDArray[np.int_]
    pair: NDArray[np.int_]
    edge: NDArray[np.bool_]

    @staticmethod
    def empty(member: str) -> FlankPatch:
        z = np.zeros(0)
        i = np.zeros(0, dtype=np.int64)
        return FlankPatch(member, np.zeros((0, 4, 2)), np.zeros((0, 2)), z, z, i, i,
                          np.zeros(0, dtype=bool))  # fmt: skip


# --------------------------------------------------------------------------------------------
# Flank coordinates
# --------------------------------------------------------------------------------------------


def _face_ends(bounds) -> tuple[str, str]:
    v = (getattr(bounds, "v_name", "") or "").lower()
    if "toe" in v:
        return "toe", "heel"
    if v.startswith("radius"):
        return "inner end", "outer end"
    return "-z", "+z"


def _maps(run):
    """The exact flank maps of both members (the TCA's)."""
    asm = run.assembly
    return {
        "pinion": flank_map(run.pair.pinion, asm.side1),
        "gear": flank_map(run.pair.gear, asm.side2),
    }


def flank_frames(run, maps=None) -> dict[str, FlankFrame]:
    """The working flank of each member of a :class:`~fegear.pipeline.run.GearRun`."""
    maps = maps or _maps(run)
    out = {}
    for member, fm in maps.items():
        b = fm.bounds
        v = np.linspace(b.v_start, b.v_end, 121)
        lo, hi = b.fillet_curve(v), b.tip_curve(v)  # as fegear.tca.plots.flank_outline
        outline = np.stack([np.r_[v, v[::-1], v[:1]], np.r_[lo, hi[::-1], lo[:1]]], -1)
        out[member] = FlankFrame(
            member=member,
            face_name=b.v_name,
            profile_name=b.height_name or b.u_name,
            outline=outline,
            face_ends=_face_ends(b),
            bounds=b,
        )
    return out


def _cell_corners(cells) -> Array:
    """``(n, 4, 3)`` corners of the cells from their 2 × 2 Gauss points (bilinear extrapolation
    from ``±1/√3`` to ``±1``), counter-clockwise in the cell axes."""
    q = cells.quad_points.reshape(-1, 2, 2, 3)
    c = q.mean(axis=(1, 2))
    order = [(0, 0), (1, 0), (1, 1), (0, 1)]
    return np.stack([c + math.sqrt(3.0) * (q[:, a, b] - c) for a, b in order], axis=1)


class _Projector:
    """Flank coordinates ``(u, v)`` of points on (or within a cell of) a member's flank: the
    Newton line hit of the line through the point along a given direction with the exact flank
    (tooth ``t`` of the member placed by ``M``)."""

    def __init__(self, fm, n: int = 21) -> None:
        self.fm = fm
        self.n = n
        self.tree = None

    def start(self, P: Array) -> tuple[Array, Array]:
        """Start values of the native parameters: the nearest of ``n × n`` flank samples (the
        TCA's start grid size)."""
        if self.tree is None:
            from scipy.spatial import cKDTree

            b, n = self.fm.bounds, self.n
            U, V = np.meshgrid(np.linspace(b.u_fillet, b.u_tip, n),
                               np.linspace(b.v_start, b.v_end, n), indexing="ij")  # fmt: skip
            self.a, self.b = (x.ravel() for x in self.fm.native(U.ravel(), V.ravel()))
            self.tree = cKDTree(self.fm.evaluate(self.a, self.b)[0])
        i = self.tree.query(P)[1]
        return self.a[i], self.b[i]

    def __call__(self, P: Array, N: Array, a0: Array, b0: Array):
        a, b, _, p, _, ok = line_hit(self.fm, a0, b0, P, N)
        u, v = self.fm.flank(a, b, p)
        return np.asarray(u, float), np.asarray(v, float), a, b, ok


def flank_patches(run, maps=None, frames=None) -> list[dict[str, FlankPatch]]:
    """The loaded cells of both members at every position of a loaded
    :class:`~fegear.pipeline.run.GearRun`, in flank coordinates (empty for the ``hertz``
    fidelity, which has no contact cells, and at positions without load).

    The Newton solves of all cells of all positions run as one batch per member and stage
    (gear cell centres, then the corners of both members from their centres).
    """
    cyc = run.cycle
    if cyc is None:
        return []
    maps = maps or _maps(run)
    frames = frames or flank_frames(run, maps)
    asm = run.assembly
    # 1. the loaded cells of every position and pair, in each member's tooth frame
    blocks: list[dict[str, Any]] = []
    for i, pos in enumerate(cyc.positions):
        offset = 0
        for ip, (c, p) in enumerate(zip(pos.cells, pos.pressure, strict=True)):
            sl = slice(offset, offset + c.n)
            offset += c.n
            load = np.flatnonzero(p > 0)
            if load.size == 0:
                continue
            corners, normals = _cell_corners(c)[load], c.normals[load]
            gap = c.gap[load]
            row = {"i": i, "ip": ip, "p": p[load], "f": pos.solution.force[sl][load],
                   "edge": c.boundary[load], "k": c.k, "j": c.j}  # fmt: skip
            for member in MEMBERS:
                if member == "pinion":
                    M = compose(asm.placement1(pos.phi1), tooth_transform(asm.n1, c.k))
                    X0, Xc = c.centers[load], corners
                else:  # the pinion cell carried along the pinion normal by its gap
                    M = compose(asm.placement2(run.phi2[i]), tooth_transform(asm.n2, c.j))
                    X0 = c.centers[load] + gap[:, None] * normals
                    Xc = corners + gap[:, None, None] * normals[:, None, :]
                Mi = inverse(M)
                row[member] = (
                    apply_points(Mi, X0),
                    apply_points(Mi, Xc),
                    apply_vectors(Mi, normals),
                )
            row["uv1"] = c.uv[load]
            blocks.append(row)
    out = [{m: FlankPatch.empty(m) for m in MEMBERS} for _ in cyc.positions]
    if not blocks:
        return out
    sizes = np.array([len(b["p"]) for b in blocks])
    failed = 0
    coords: dict[str, tuple[Array, Array]] = {}
    for member in MEMBERS:
        fm, fr = maps[member], frames[member]
        pj = _Projector(fm)
        P0 = np.concatenate([b[member][0] for b in blocks])
        Pc = np.concatenate([b[member][1] for b in blocks])
        N = np.concatenate([b[member][2] for b in blocks])
        if member == "pinion":  # the cells are laid out on the pinion flank: centres known
            uv0 = np.concatenate([b["uv1"] for b in blocks])
            u0, v0 = uv0[:, 0], uv0[:, 1]
            a0, b0 = fm.native(u0, v0)
        else:
            u0, v0, a0, b0, ok0 = pj(P0, N, *pj.start(P0))
            failed += int(np.count_nonzero(~ok0))
        shape = Pc.shape[:2]
        uc, vc, _, _, okc = pj(
            Pc, np.broadcast_to(N[:, None, :], Pc.shape),
            np.broadcast_to(np.asarray(a0)[:, None], shape),
            np.broadcast_to(np.asarray(b0)[:, None], shape),
        )  # fmt: skip
        bad = ~okc
        if bad.any():  # a corner the Newton did not reach: drawn at its cell's centre
            failed += int(np.count_nonzero(bad))
            uc = np.where(bad, np.asarray(u0)[:, None], uc)
            vc = np.where(bad, np.asarray(v0)[:, None], vc)
        coords[member] = (fr.coordinates(uc, vc), fr.coordinates(np.asarray(u0), np.asarray(v0)))
    # 2. back to positions
    cuts = np.cumsum(sizes)[:-1]
    for member in MEMBERS:
        quads = np.split(coords[member][0], cuts)
        centres = np.split(coords[member][1], cuts)
        rows: dict[int, list] = {}
        for b, q, c in zip(blocks, quads, centres, strict=True):
            n = len(b["p"])
            tooth = b["k"] if member == "pinion" else b["j"]
            rows.setdefault(b["i"], []).append(
                (q, c, b["p"], b["f"], np.full(n, tooth, np.int64), np.full(n, b["ip"], np.int64),
                 b["edge"])
            )  # fmt: skip
        for i, parts in rows.items():
            cols = [np.concatenate(x) for x in zip(*parts, strict=True)]
            out[i][member] = FlankPatch(member, *cols)
    if failed:
        # a display matter (a corner of a coarse boundary cell beyond the flank map), no number
        # depends on it: information, not a warning
        log.info("flank views: %d cell corners not found on the exact flank (drawn at the "
                 "cell centre)", failed)  # fmt: skip
    return out


def pattern_centre(run, frames=None, patches=None) -> dict[str, PatternCentre]:
    """:class:`PatternCentre` of both members of a run (loaded: force-weighted centroid of the
    loaded cells; ``tca``: mean of the unloaded contact points of the pairs within the paint
    thickness over the positions with contact; ``hertz``: none, it has no contact cells)."""
    frames = frames or flank_frames(run)
    out = {}
    _none = {"face_mm": None, "profile_mm": None, "face_range_mm": None, "profile_range_mm": None}
    for member in MEMBERS:
        fr = frames[member]
        kw = {"member": member, "face_name": fr.face_name, "profile_name": fr.profile_name}
        if run.cycle is None:
            r = run.tca
            # every pair within the paint thickness, not only "the" pair in contact: where two
            # pairs close together (a conjugate TE) the choice between them is round-off
            uv = [
                (p.pinion_uv if member == "pinion" else p.gear_uv)[k]
                for p in r.positions
                if p.has_contact
                for k in np.flatnonzero(p.pair_valid & (p.backlash_mm <= r.paint_mm))
            ]
            uv = np.reshape(uv, (-1, 2))
            if uv.shape[0] == 0:
                out[member] = PatternCentre(**_none, weighting="unloaded contact path",
                                            reason="no position has contact", **kw)  # fmt: skip
                continue
            xy = fr.coordinates(uv[:, 0], uv[:, 1])
            w = np.ones(xy.shape[0])
            weighting = "unloaded contact path"
        else:
            patches = patches if patches is not None else flank_patches(run, frames=frames)
            got = [p[member] for p in patches if p[member].force_N.size]
            if not got:
                why = (
                    f"the {run.fidelity} fidelity has no contact cells"
                    if run.kind is not None and not run.kind.cells
                    else "no loaded cell at any position"
                )
                out[member] = PatternCentre(**_none, weighting="cell force", reason=why, **kw)
                continue
            xy = np.concatenate([g.centres for g in got])
            w = np.concatenate([g.force_N for g in got])
            weighting = "cell force"
        c = (w @ xy) / w.sum()
        out[member] = PatternCentre(
            face_mm=float(c[0]),
            profile_mm=float(c[1]),
            face_range_mm=(float(xy[:, 0].min()), float(xy[:, 0].max())),
            profile_range_mm=(float(xy[:, 1].min()), float(xy[:, 1].max())),
            weighting=weighting,
            **kw,
        )
    return out


# --------------------------------------------------------------------------------------------
# The bearing pattern over the cycle
# --------------------------------------------------------------------------------------------


def _envelope(frame: FlankFrame, patches: Sequence[FlankPatch], shape=(360, 900)):
    """Pixels ``(ny, nx)`` over the outline's box: the largest pressure each saw (0: none)."""
    box_lo, box_hi = frame.outline.min(axis=0), frame.outline.max(axis=0)
    span = np.maximum(box_hi - box_lo, 1e-9)
    ny, nx = shape
    px = span / np.array([nx, ny])
    img = np.zeros((ny, nx))
    for p in patches:
        if p.pressure_MPa.size == 0:
            continue
        q = (p.quads - box_lo) / px  # corners in pixels
        # samples along each cell edge: at most half a pixel apart (no holes between cells)
        n1 = np.clip(np.ceil(2 * np.linalg.norm(q[:, 1] - q[:, 0], axis=1)), 1, 256).astype(int)
        n2 = np.clip(np.ceil(2 * np.linalg.norm(q[:, 3] - q[:, 0], axis=1)), 1, 256).astype(int)
        for s1, s2 in set(zip(n1.tolist(), n2.tolist(), strict=True)):
            sel = np.flatnonzero((n1 == s1) & (n2 == s2))
            S, T = np.meshgrid((np.arange(s1) + 0.5) / s1, (np.arange(s2) + 0.5) / s2,
                               indexing="ij")  # fmt: skip
            S, T = S.ravel(), T.ravel()
            c = q[sel]  # bilinear over the quad's corners 0-1-2-3
            pts = (
                ((1 - S) * (1 - T))[None, :, None] * c[:, None, 0]
                + (S * (1 - T))[None, :, None] * c[:, None, 1]
                + (S * T)[None, :, None] * c[:, None, 2]
                + ((1 - S) * T)[None, :, None] * c[:, None, 3]
            )
            ix = np.clip(pts[..., 0].astype(int), 0, nx - 1).ravel()
            iy = np.clip(pts[..., 1].astype(int), 0, ny - 1).ravel()
            val = np.repeat(p.pressure_MPa[sel], S.size)
            np.maximum.at(img, (iy, ix), val)
    return img, box_lo, box_hi


def plot_flank_pattern(
    frame: FlankFrame,
    patches: Sequence[FlankPatch],
    path: Path,
    title: str = "",
    p_max_MPa: float | None = None,
) -> Path:
    """The bearing pattern over the cycle on one member's flank as a PNG.

    Parameters
    ----------
    frame
        The member's flank (its outline).
    patches
        The member's :class:`FlankPatch` at every position.
    path
        The PNG to write (atomically).
    title
        First line of the title.
    p_max_MPa
        Top of the colour scale (the cycle's p_max away from the edges: singular edge peaks are
        shown at the top colour); None: the largest pressure.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    img, lo, hi = _envelope(frame, patches)
    fig, ax = plt.subplots(figsize=(8, 4.2))
    top = float(img.max())
    vmax = p_max_MPa if p_max_MPa and p_max_MPa > 0 else (top or None)
    clipped = vmax is not None and top > vmax * (1 + 1e-9)
    if top > 0:
        im = ax.imshow(
            np.ma.masked_where(img <= 0, img),
            origin="lower",
            extent=(lo[0], hi[0], lo[1], hi[1]),
            aspect="auto",
            cmap="inferno",
            vmin=0,
            vmax=vmax,
            interpolation="nearest",
        )
        label = "largest pressure over the cycle (MPa)"
        if clipped:
            label += f"\n(edge contacts up to {top:.0f} MPa at the top colour)"
        fig.colorbar(im, ax=ax, label=label, extend="max" if clipped else "neither")
    force = [(p.force_N, p.centres) for p in patches if p.force_N.size]
    if force:
        w = np.concatenate([f for f, _ in force])
        xy = np.concatenate([c for _, c in force])
        cx, cy = (w @ xy) / w.sum()
        ax.plot([cx], [cy], "c+", ms=14, mew=2, label="pattern centre (force-weighted)")
        ax.legend(fontsize=8, loc="lower right")
    o = frame.outline
    ax.plot(o[:, 0], o[:, 1], "k-", lw=1)
    a, b = frame.face_ends
    ytop = o[:, 1].max()
    if a:
        ax.annotate(a, (o[0, 0], ytop), textcoords="offset points", xytext=(2, 4), fontsize=8)
    if b:
        ax.annotate(b, (o[:, 0].max(), ytop), textcoords="offset points", xytext=(-40, 4),
                    fontsize=8)  # fmt: skip
    pad = 0.04 * (hi - lo)
    ax.set_xlim(lo[0] - pad[0], hi[0] + pad[0])
    ax.set_ylim(lo[1] - pad[1], hi[1] + 3 * pad[1])
    ax.set_xlabel(frame.face_name)
    ax.set_ylabel(frame.profile_name)
    n = sum(bool(p.force_N.size) for p in patches)
    ax.set_title(
        (title + "\n" if title else "")
        + f"bearing pattern on the {frame.member} flank ({n} of {len(patches)} positions loaded)",
        fontsize=9,
    )
    ax.grid(alpha=0.2)
    fig.tight_layout()
    out = atomic_write(Path(path), lambda q: fig.savefig(q, format="png", dpi=110))
    plt.close(fig)
    return out
