"""Pictures of the reference spiral bevel pair (docs/reference_pairs.md): flank grids, contact path,
TE, generated fillets.

Run: ``python docs/geometry/spiral_bevel_pictures.py`` (writes ``spiral_bevel_*.png`` here).
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from fegear.geometry.bevel import SpiralBevelPair, transmission_error  # noqa: E402
from fegear.geometry.transforms import apply_points, rot_z  # noqa: E402

HERE = Path(__file__).parent
ARCSEC = math.pi / (180 * 3600)
log = logging.getLogger("spiral_bevel_pictures")


def flank_grids(pair: SpiralBevelPair, member: str, path: dict) -> Path:
    """3-D wireframe of the drive (red) and coast (blue) flanks of three teeth."""
    m = getattr(pair, member)
    fig = plt.figure(figsize=(7, 6), dpi=90)
    ax = fig.add_subplot(projection="3d")
    for side, colour in (("drive", "tab:red"), ("coast", "tab:blue")):
        fl = m.flank(side, 15, 11)
        for k in (-1, 0, 1):
            P = apply_points(rot_z(k * m.tooth_angle), fl.points)
            for i in range(P.shape[0]):
                ax.plot(*P[i].T, color=colour, lw=0.6)
            for j in range(P.shape[1]):
                ax.plot(*P[:, j].T, color=colour, lw=0.6)
        u, v = path[side]
        pts, _ = m.point_normal(side, u, v)
        ax.plot(*pts.T, "k-", lw=2.0)
    ax.set_title(
        f"{member} ({m.n_teeth} teeth): drive (red) / coast (blue) flanks,\n"
        "black: TCA contact path of the mean tooth pair over one mesh cycle"
    )
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_aspect("equal")
    out = HERE / f"spiral_bevel_{member}.png"
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)
    return out


def flank_vtk(pair: SpiralBevelPair, member: str) -> Path:
    """Both flanks of one tooth as a VTK multiblock of structured grids (points, normals,
    principal curvatures, meshing residual), ``spiral_bevel_<member>.vtm`` for ParaView."""
    import pyvista as pv

    m = getattr(pair, member)
    blocks = pv.MultiBlock()
    for side in ("drive", "coast"):
        fl = m.flank(side, 21, 15)
        P = fl.points
        grid = pv.StructuredGrid(P[..., 0], P[..., 1], P[..., 2])
        grid.point_data["normal"] = fl.normals.reshape(-1, 3, order="F")
        grid.point_data["kappa_1_per_mm"] = fl.kappa[..., 0].ravel(order="F")
        grid.point_data["kappa_2_per_mm"] = fl.kappa[..., 1].ravel(order="F")
        grid.point_data["meshing_residual"] = fl.meshing_residual.ravel(order="F")
        blocks[side] = grid
    out = HERE / f"spiral_bevel_{member}.vtm"
    blocks.save(out)
    return out


def fillet_sections(pair: SpiralBevelPair) -> Path:
    """One tooth space of each member in the back-cone sections ``L = const`` at the toe, the
    mean and the heel: flanks (``u`` 0 → 1) and generated fillets (``u`` −1 → 0) of the two
    flanks facing the space, the root cone between the fillet bottoms, the fillet limits (dots)
    and the working depth the mate's tip reaches (dashed). Coordinates: arc length from the
    middle of the space along the section's pitch circle, ``ρ_p (φ − φ_mid)`` (mm), and the
    height ``h`` above the pitch cone."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.5), dpi=90)
    b = pair.blank
    A0, F = b.outer_cone_distance(2), b.face_width_mm
    u = np.concatenate([np.linspace(-1.0, 0.0, 25), np.linspace(0.0, 1.0, 41)[1:]])
    for ax, m in zip(axes, (pair.pinion, pair.gear), strict=True):
        g = m.pitch_angle
        for L, colour in ((A0 - F, "tab:blue"), (A0 - F / 2, "tab:green"), (A0, "tab:red")):
            ends = {}
            for side in ("drive", "coast"):
                p, _ = m.flank_points(side, u, np.full_like(u, L))
                rho = np.hypot(p[:, 0], p[:, 1])
                h = rho * math.cos(g) - p[:, 2] * math.sin(g)
                phi = np.arctan2(p[:, 1], p[:, 0])
                ends[side] = (phi, h, rho)
            # the space between the +θ flank of tooth 0 and the −θ flank of tooth 1
            plus = "drive" if ends["drive"][0][-1] > ends["coast"][0][-1] else "coast"
            minus = "coast" if plus == "drive" else "drive"
            r0 = L * math.sin(g)  # the pitch-cone radius at L: the arc-length scale
            mid = 0.5 * (ends[plus][0][0] + ends[minus][0][0] + m.tooth_angle)  # space middle
            xp = (ends[plus][0] - mid) * r0
            xm = (ends[minus][0] + m.tooth_angle - mid) * r0
            for x, side in ((xp, plus), (xm, minus)):
                h = ends[side][1]
                ax.plot(x[25:], h[25:], "-", color=colour, lw=1.2)
                ax.plot(x[:25], h[:25], "-", color=colour, lw=2.4)
                ax.plot(x[24], h[24], "o", color=colour, ms=4)
            ax.plot([xp[0], xm[0]], [ends[plus][1][0], ends[minus][1][0]], "-", color=colour,
                    lw=2.4, label=f"L = {L:.1f} mm")  # fmt: skip
            hw = float(b.flank_heights(m.index, L)[0])
            ax.plot([xp.min(), xm.max()], [hw, hw], "--", color=colour, lw=0.8)
        ax.set_title(f"{m.name}: one tooth space (thick: fillets and root cone)")
        ax.set_xlabel("arc length ρ_p (φ − φ_space middle) at the section (mm)")
        ax.set_ylabel("height h above the pitch cone (mm)")
        ax.set_aspect("equal")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(
        f"Generated fillets (edge radius {pair.settings.gear_drive.edge_radius_mm:.3f} mm); "
        "dots: fillet limits, dashed: the mate's face cone"
    )
    fig.tight_layout()
    out = HERE / "spiral_bevel_fillet.png"
    fig.savefig(out)
    plt.close(fig)
    return out


def main() -> None:
    logging.basicConfig(level=logging.INFO)
    pair = SpiralBevelPair.design()
    n1 = pair.blank.n1
    phi = np.linspace(-math.pi / n1, math.pi / n1, 9)
    paths = {"pinion": {}, "gear": {}}
    fig, ax = plt.subplots(figsize=(6, 4), dpi=90)
    for side in ("drive", "coast"):
        te, X, _ = transmission_error(pair, side, phi)
        paths["pinion"][side] = (X[:, 0], X[:, 1])
        paths["gear"][side] = (X[:, 2], X[:, 3])
        ax.plot(np.degrees(phi), te / ARCSEC, "o-", label=side)
    ax.set_xlabel("pinion rotation φ1 (deg) over one mesh cycle")
    ax.set_ylabel("unloaded TE (arcsec)")
    ax.set_title("Predesigned parabolic TE, mean tooth pair (rigid TCA)")
    ax.grid(True)
    ax.legend()
    fig.tight_layout()
    fig.savefig(HERE / "spiral_bevel_te.png")
    plt.close(fig)
    for member in ("pinion", "gear"):
        log.info("wrote %s", flank_grids(pair, member, paths[member]))
        log.info("wrote %s", flank_vtk(pair, member))
    log.info("wrote %s", fillet_sections(pair))


if __name__ == "__main__":
    main()
