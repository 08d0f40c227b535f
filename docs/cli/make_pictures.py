"""Pictures of docs/cli/README.md from a finished run: ``python docs/cli/make_pictures.py OUT``.

Copies the PNGs of the run, renders position 12 of ``OUT/cycle.pvd`` off-screen with pyvista
(what ParaView shows after *Warp By Vector* and colouring by ``pressure_MPa``), renders the gear
flank view of the same position (``vtk/flank_gear_012.vtp``: the loaded cells on the face-gear
flank in flank coordinates) and draws the bearing pattern over the cycle on the gear flank
(what ``fegear plot OUT`` writes).
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pyvista as pv

HERE = Path(__file__).resolve().parent


def main(out: Path) -> None:
    for name in ("te", "load_share", "p_max", "bearing_pattern"):
        shutil.copy(out / f"{name}.png", HERE / f"{name}.png")
    reader = pv.get_reader(str(out / "cycle.pvd"))
    i = min(12, reader.number_time_points - 1)
    reader.set_active_time_value(reader.time_values[i])
    blocks = reader.read()  # parts: pinion, gear, contact cells, pinion / gear flank views
    pinion, gear, cells = blocks[0], blocks[1], blocks[2]
    pv.OFF_SCREEN = True
    pl = pv.Plotter(off_screen=True, window_size=(1100, 750))
    scale = 200.0  # displacements are µm: exaggerated as in ParaView's Warp By Vector
    for m in (pinion, gear):
        m["|u| (um)"] = 1e3 * (m["displacement_mm"] ** 2).sum(axis=1) ** 0.5
    clim = [0.0, max(float(m["|u| (um)"].max()) for m in (pinion, gear))]
    for m, opacity in ((pinion, 0.35), (gear, 1.0)):
        w = m.warp_by_vector("displacement_mm", factor=scale)
        pl.add_mesh(w, scalars="|u| (um)", cmap="viridis", clim=clim, show_edges=True,
                    edge_color="gray", line_width=0.3, opacity=opacity,
                    scalar_bar_args={"title": "|u| (um)"})  # fmt: skip
    pl.add_mesh(cells, scalars="pressure_MPa", cmap="inferno",
                scalar_bar_args={"title": "cell pressure (MPa)", "position_y": 0.85})  # fmt: skip
    c = cells.center if cells.n_cells else pinion.center
    # face gear: pinion axis +x, face-gear axis +z; look across the pinion axis, from above
    pl.camera.focal_point = c
    pl.camera.position = (c[0] + 60.0, c[1] - 200.0, c[2] + 110.0)
    pl.camera.up = (0.0, 0.0, 1.0)
    pl.add_text(f"position {i}: pinion angle {reader.time_values[i]:.2f} deg, "
                f"displacement x{scale:.0f}", font_size=10)  # fmt: skip
    pl.screenshot(str(HERE / "paraview_view.png"))
    pl.close()
    flank = blocks[4]  # the gear flank view: x face coordinate, y profile coordinate (mm)
    p_max = json.loads((out / "summary.json").read_text())["cycle"]["p_max_MPa"]
    pl = pv.Plotter(off_screen=True, window_size=(1100, 560))
    pl.add_mesh(flank, scalars="pressure_MPa", cmap="inferno", clim=[0.0, p_max],
                line_width=2, scalar_bar_args={"title": "pressure (MPa)"})  # fmt: skip
    pl.set_scale(yscale=4.0)  # the flank is 6x wider than high: profile stretched 4x
    pl.view_xy()
    pl.camera.zoom(1.6)
    pl.add_text(f"gear flank view, position {i} ({flank.field_data['x_axis'][0]} across, "
                f"{flank.field_data['y_axis'][0]} up, x4)", font_size=9)  # fmt: skip
    pl.screenshot(str(HERE / "flank_view.png"))
    pl.close()
    from fegear.cli import main as fegear

    fegear(["plot", str(out), "--member", "gear", "--png", str(HERE / "gear_flank_pattern.png")])


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "out"))
