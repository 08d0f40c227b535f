"""Write a PNG of each family's flank grid and VTK (.vts) of the surfaces into docs/geometry/.

Run: ``python docs/geometry/make_pictures.py``.
"""

from __future__ import annotations

import logging
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pyvista as pv  # noqa: E402

from fegear.geometry import (  # noqa: E402
    FaceGearDesign,
    FaceGearMember,
    FlankSurface,
    InvoluteDesign,
    InvoluteMember,
    rot_z,
)
from fegear.geometry.transforms import apply_points  # noqa: E402

pv.OFF_SCREEN = True
OUT = Path(__file__).resolve().parent
log = logging.getLogger("make_pictures")


def grid(fl: FlankSurface, turn: float = 0.0) -> pv.StructuredGrid:
    p = apply_points(rot_z(turn), fl.points)
    g = pv.StructuredGrid(p[..., 0], p[..., 1], p[..., 2])
    g.point_data["kappa_1"] = fl.kappa[..., 0].ravel(order="F")
    g.point_data["kappa_2"] = fl.kappa[..., 1].ravel(order="F")
    g.point_data["normal"] = fl.normals.reshape(-1, 3, order="F")
    g.point_data["meshing_residual"] = fl.meshing_residual.ravel(order="F")
    return g


def picture(name: str, flanks: list[FlankSurface], turns: list[float], title: str) -> None:
    fig = plt.figure(figsize=(5, 4), dpi=90)
    ax = fig.add_subplot(projection="3d")
    blocks = pv.MultiBlock()
    for k, (fl, turn) in enumerate(zip(flanks, turns, strict=True)):
        p = apply_points(rot_z(turn), fl.points)
        color = "C0" if fl.side == "drive" else "C1"
        ax.plot_wireframe(p[..., 0], p[..., 1], p[..., 2], color=color, linewidth=0.5)
        blocks[f"{fl.side}_{k}"] = grid(fl, turn)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x mm")
    ax.set_ylabel("y mm")
    ax.set_zlabel("z mm")
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(OUT / f"{name}.png")
    plt.close(fig)
    merged = blocks.combine().cast_to_unstructured_grid().extract_surface()  # all flanks
    merged.save(OUT / f"{name}.vtp")
    blocks["drive_0"].save(OUT / f"{name}_drive_0.vts")
    log.info("wrote %s.png/.vtp", name)


def main() -> None:
    logging.basicConfig(level=logging.INFO)
    for beta, tag in ((0.0, "spur"), (15.0, "helical")):
        g = InvoluteMember(
            InvoluteDesign(16, 4.5, 20.0, beta, 0.1817, face_width_mm=14.0), "pinion"
        )
        fls, turns = [], []
        for k in range(3):
            for side in ("drive", "coast"):
                fls.append(g.flank(side, 21, 9))
                turns.append(k * g.tooth_angle)
        picture(f"involute_{tag}", fls, turns, f"FZG C pinion, {tag} (β = {beta:g}°), 3 teeth")
    fg = FaceGearMember(FaceGearDesign())
    fls = [fg.flank(s, 12, 15, include_fillet=True) for s in ("drive", "coast")]
    fls, turns = fls * 3, [k * fg.tooth_angle for k in range(3) for _ in range(2)]
    picture("face_gear", fls, turns,
            "face gear N2 160 (shaper N_s 27), 3 teeth, 471–560 mm,\nworking flank and "
            "generated fillet (curved fillet limit)")  # fmt: skip
    face_gear_sections(fg)


def face_gear_sections(fg: FaceGearMember) -> None:
    """Sections ρ = L of one face-gear tooth space (drive flank of tooth 0, coast flank of tooth
    1): working flank, generated fillet (the trace of the shaper's tip edge) and root, drawn at
    the arc length ρφ; the dot is the fillet limit."""
    import numpy as np

    Ls = (471.0, 490.0, 508.0, 530.0, 555.0)
    fig, axs = plt.subplots(1, len(Ls), figsize=(14, 3.6), sharey=True)
    for ax, L in zip(axs, Ls, strict=True):
        for side, k, c in (("drive", 0, "C0"), ("coast", 1, "C1")):
            for u0, u1, lw in ((0.0, 1.0, 1.2), (-1.0, 0.0, 2.5)):
                u = np.linspace(u0, u1, 80)
                p = fg.point_normal(side, u, np.full_like(u, L))[0]
                phi = np.arctan2(p[:, 1], p[:, 0]) + k * fg.tooth_angle
                ax.plot(L * phi, p[:, 2], color=c, lw=lw)
            q = fg.point_normal(side, 0.0, L)[0]
            ax.plot(L * (np.arctan2(q[1], q[0]) + k * fg.tooth_angle), q[2], "ko", ms=4)
        ax.axhline(fg.root_height, color="k", lw=0.5)
        ax.set_title(f"L = {L:g} mm (z_f = {float(fg.fillet_height(L)):.2f} mm)", fontsize=9)
        ax.set_xlabel("arc length ρφ (mm)")
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    axs[0].set_ylabel("height z (mm)")
    fig.suptitle("seed face gear: tooth space sections — working flank (thin), generated fillet "
                 "(thick), fillet limit (dot)", fontsize=10)  # fmt: skip
    fig.tight_layout()
    fig.savefig(OUT / "face_gear_sections.png", dpi=100)
    plt.close(fig)
    log.info("wrote face_gear_sections.png")


if __name__ == "__main__":
    main()
