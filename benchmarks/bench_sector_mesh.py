"""Sector-mesh benchmark: mesh time, elements and P2 DOFs per level for each family; the
deflection-convergence study of the FZG pinion (levels 0-4); cut-face BC effect; PNGs.

Run: ``python benchmarks/bench_sector_mesh.py [max_level]`` (uses a private cache folder so
times are cold). Writes ``docs/mesh/*.png`` and prints a Markdown table.
"""

from __future__ import annotations

import logging
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("FEGEAR_CACHE", tempfile.mkdtemp(prefix="fegear_bench_"))

from fegear.errors import FegearError  # noqa: E402
from fegear.geometry import FaceGearDesign, FaceGearMember, InvoluteDesign, InvoluteMember  # noqa: E402
from fegear.mesh.sector import mesh_sizes, sector_mesh  # noqa: E402
from fegear.mesh.sector_check import tooth_compliance  # noqa: E402
from fegear.mesh.sector_geometry import (  # noqa: E402
    fillet_distance,
    flank_distance,
    section_integral_volume,
    sector_frame,
)

log = logging.getLogger("bench_sector_mesh")
DOCS = Path(__file__).resolve().parents[1] / "docs" / "mesh"


def members():
    d = FaceGearDesign()
    yield (
        "fzg_pinion",
        InvoluteMember(
            InvoluteDesign(16, 4.5, 20.0, profile_shift=0.1817, face_width_mm=14.0), "pinion"
        ),
    )
    yield (
        "fzg_gear",
        InvoluteMember(
            InvoluteDesign(24, 4.5, 20.0, profile_shift=0.1715, face_width_mm=14.0), "gear"
        ),
    )
    yield "face_gear", FaceGearMember(d)
    yield "face_gear_pinion", InvoluteMember(
        InvoluteDesign(25, d.module_mm, d.pressure_angle_deg, rack_tip_radius_coeff=0.3,
                       face_width_mm=d.pinion_face_width_mm), "pinion")  # fmt: skip
    from fegear.geometry.bevel import SpiralBevelPair

    pair = SpiralBevelPair.design()
    yield "bevel_pinion", pair.pinion
    yield "bevel_gear", pair.gear


def p2_dofs(sm) -> int:
    t = np.sort(sm.tets, axis=1)
    edges = np.vstack([t[:, [a, b]] for a in range(4) for b in range(a + 1, 4)])
    return 3 * (len(sm.points) + len(np.unique(edges, axis=0)))


def node_deviation(sm, fr) -> float:
    """Max over the centre tooth's flank nodes of (distance to the analytic flank) / (mean length
    of the flank triangle edges at the node)."""
    worst = 0.0
    j = sm.centre_tooth
    for side in ("drive", "coast"):
        tri = sm.boundaries[f"flank_{side}_{j}"]
        p = sm.points
        e = np.linalg.norm(p[tri] - p[np.roll(tri, 1, axis=1)], axis=-1).mean(axis=1)
        acc, cnt = np.zeros(len(p)), np.zeros(len(p))
        for c in range(3):
            np.add.at(acc, tri[:, c], e)
            np.add.at(cnt, tri[:, c], 1)
        nodes = np.unique(tri)
        d, _ = flank_distance(fr, side, 0, p[nodes])
        worst = max(worst, float(np.max(d / (acc[nodes] / cnt[nodes]))))
    return worst


def fillet_deviation(sm, fr) -> float | None:
    """Max over all fillet/root nodes of (distance to the generated fillet and root, within the
    node's section) / (mean length of the triangle edges at the node); None without a generated
    fillet (root blend)."""
    if not fr.has_fillet:
        return None
    worst = 0.0
    p = sm.points
    for j in range(sm.n_teeth):
        tri = sm.boundaries[f"fillet_{j}"]
        e = np.linalg.norm(p[tri] - p[np.roll(tri, 1, axis=1)], axis=-1).mean(axis=1)
        acc, cnt = np.zeros(len(p)), np.zeros(len(p))
        for c in range(3):
            np.add.at(acc, tri[:, c], e)
            np.add.at(cnt, tri[:, c], 1)
        nodes = np.unique(tri)
        d = fillet_distance(fr, j - sm.centre_tooth, p[nodes])
        worst = max(worst, float(np.max(d / (acc[nodes] / cnt[nodes]))))
    return worst


def picture(sm, fr, path: Path) -> None:
    """Offscreen PNG of the sector surface coloured by the local element size (the refined
    contact zone shows as the dark, dense patch on the centre teeth's drive flanks), seen from
    outside the teeth (along the tooth height direction of the centre tooth, tilted)."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    tri = np.vstack([t for k, t in sm.boundaries.items()])
    p = sm.points
    size = np.linalg.norm(p[tri] - p[np.roll(tri, 1, axis=1)], axis=-1).mean(axis=1)
    surf = pv.PolyData(p, np.hstack([np.full((len(tri), 1), 3), tri]).ravel())
    surf.cell_data["element size mm"] = size
    pl = pv.Plotter(off_screen=True, window_size=(900, 700))
    pl.add_mesh(surf, scalars="element size mm", cmap="viridis", show_edges=True,
                edge_color="black", line_width=0.4)  # fmt: skip
    M = fr.meridian
    e_h = np.array([M[0, 1], 0.0, M[1, 1]])
    e_L = np.array([M[0, 0], 0.0, M[1, 0]])
    centre = p[np.unique(sm.boundaries[f"flank_drive_{sm.centre_tooth}"])].mean(axis=0)
    view = e_h + 0.5 * e_L + 0.5 * np.array([0.0, 1.0, 0.0])
    pl.camera.focal_point = centre
    pl.camera.position = centre + 6 * np.ptp(p, axis=0).max() * view / np.linalg.norm(view)
    pl.camera.up = tuple(e_L)
    pl.reset_camera()
    pl.add_text(f"{path.stem}: {len(sm.tets)} tets, level {sm.parameters['level']}",
                font_size=10)  # fmt: skip
    pl.screenshot(str(path))
    pl.close()


def main(max_level: int = 2) -> None:
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    t_start = time.perf_counter()
    logging.getLogger("fegear").setLevel(logging.WARNING)
    DOCS.mkdir(parents=True, exist_ok=True)
    rows = []
    for name, m in members():
        fr = sector_frame(m)
        ref = section_integral_volume(fr, 3)
        for lv in range(max_level + 1):
            t = time.perf_counter()
            try:
                sm = sector_mesh(m, n_teeth=3, level=lv)
            except FegearError as exc:
                rows.append(f"| {name} | {lv} | failed: {exc} |")
                log.info(rows[-1])
                break
            wall = time.perf_counter() - t
            dg = sm.diagnostics
            fd = fillet_deviation(sm, fr)
            fil = "blend" if fd is None else f"{100 * fd:.3f}"
            rows.append(
                f"| {name} | {lv} | {mesh_sizes(fr.module, lv)[0]:.2f} | {wall:.1f} | "
                f"{dg.get('mesh_s', 0):.1f} | {len(sm.tets)} | {p2_dofs(sm)} | "
                f"{dg.get('min_sicn', 0):.3f} | {1e3 * dg.get('flank_cad_deviation_mm', 0):.2f} | "
                f"{100 * node_deviation(sm, fr):.3f} | {fil} | "
                f"{100 * (sm.volume() / ref - 1):+.2f} |"
            )
            log.info(rows[-1])
            if lv == min(1, max_level):
                picture(sm, fr, DOCS / f"{name}.png")
    print("| member | level | h_fine mm | total s | 3-D mesh s | tets | P2 DOFs | min SICN "
          "| flank CAD dev µm | node dist / h % | fillet node dist / h % "
          "| vol. err % |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))

    m = next(iter(members()))[1]
    fr = sector_frame(m)
    levels = list(range(max(max_level, 4) + 1))
    d_fix, d_free = [], []
    for lv in levels:
        sm = sector_mesh(m, level=lv)
        d_fix.append(tooth_compliance(sm, fr))
        d_free.append(tooth_compliance(sm, fr, fixed=("bore",)))
        log.info("level %d: fixed cuts %.5e mm/N, free cuts %.5e mm/N", lv, d_fix[-1], d_free[-1])
    h = np.array([mesh_sizes(fr.module, lv)[0] for lv in levels])
    d = np.array(d_fix)
    e = np.abs(np.diff(d))
    rates = np.log(e[:-1] / e[1:]) / np.log(h[:-2] / h[1:-1])
    print("\nFZG pinion centre-tooth deflection (mm/N), bore + cuts fixed:", d)
    print("observed rates:", rates)
    print("bore only fixed (cuts free):", np.array(d_free))
    print("free/fixed ratio:", np.array(d_free) / d)
    print(f"benchmark wall time {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2)
