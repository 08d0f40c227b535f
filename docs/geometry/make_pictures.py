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
    fls = [fg.flank(s, 7, 15) for s in ("drive", "coast")]
    fls, turns = fls * 3, [k * fg.tooth_angle for k in range(3) for _ in range(2)]
    picture("face_gear", fls, turns, "face gear N2 160 (shaper N_s 27), 3 teeth, 471–560 mm")


if __name__ == "__main__":
    main()
