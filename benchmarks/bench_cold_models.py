"""The ``models`` phase of the main job's cold start (``fegear run cases/face_gear_nominal.toml``),
part by part, each in this one process: wall and CPU seconds (``time.process_time``: this
process and its threads; gmsh meshes on one thread, MKL on ``MKL_NUM_THREADS`` or 2).

Run: ``python benchmarks/bench_cold_models.py PART [CACHE]`` with PART one of

- ``mesh``: both sector meshes of the case, one after the other, in an empty cache folder
  (the member's limits, the zone's TCA before the clock);
- ``operator``: both members' compliance operators (``build_member_model``: assembly, the
  turned stiffness, the Schur complement and the dense inverse blocks), each member timed on
  its own, on meshes read from ``CACHE`` (a cache folder of an earlier run, copied without its
  ``compliance`` entries; the meshes are made before the clock where their entries are not
  there: their key holds the code of ``fegear.mesh`` and ``fegear.geometry``).

Prints one line per member and part: ``PART member wall_s cpu_s``, and the operator's sizes.
"""

from __future__ import annotations

import logging
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

CASE = Path(__file__).resolve().parents[1] / "cases" / "face_gear_nominal.toml"


def main() -> None:
    part = sys.argv[1]
    tmp = tempfile.mkdtemp(prefix="fegear_cold_")
    if part == "operator":
        src = Path(sys.argv[2])
        shutil.copytree(src, tmp, dirs_exist_ok=True, ignore=shutil.ignore_patterns("compliance"))
    os.environ["FEGEAR_CACHE"] = tmp
    logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
    for noisy in ("fegear.tca", "fegear.geometry", "fegear.store"):
        logging.getLogger(noisy).setLevel(logging.WARNING)

    import fegear
    from fegear.ltca.analysis import cycle_zone
    from fegear.ltca.model import build_member_model
    from fegear.mesh.sector import sector_mesh
    from fegear.pipeline.pair import build_pair
    from fegear.pipeline.run import _ltca_options

    case = fegear.load_case(CASE)
    pair = build_pair(case)
    opt = _ltca_options(case, 1)
    zone = cycle_zone(pair.pinion, pair.gear, pair.assembly, opt)
    members = (pair.pinion, pair.gear)
    sides = (pair.assembly.side1, pair.assembly.side2)
    if part == "mesh":
        for m, s in zip(members, sides, strict=True):
            t, c = time.perf_counter(), time.process_time()
            sector_mesh(m, zone.n_teeth, opt.level, side=s)
            print(f"mesh {m.name} {time.perf_counter() - t:.2f} {time.process_time() - c:.2f}",
                  flush=True)  # fmt: skip
        return
    if part == "operator":
        # the meshes (from CACHE, or made here) before the clock, then each member's model as
        # build_models makes it
        from fegear.ltca.fidelity import fidelity_of
        from fegear.mesh.sector import FINE, mesh_sizes
        from fegear.mesh.sector_geometry import sector_frame

        n = zone.n_teeth
        meshes = [sector_mesh(m, n, opt.level, side=s) for m, s in zip(members, sides, strict=True)]
        fine = [mesh_sizes(sector_frame(m).module, opt.level)[0] for m in members]
        module = min(f / FINE[opt.level] for f in fine)
        layer = fidelity_of(opt.fidelity).layer_depth(max(fine), module, opt)
        for m, sm, s in zip(members, meshes, sides, strict=True):
            t, c = time.perf_counter(), time.process_time()
            build_member_model(m.name, sm, s, opt.E_MPa, opt.nu, opt.backend, layer_mm=layer,
                               teeth=tuple(range(1, n - 1)))  # fmt: skip
            print(f"operator {m.name} {time.perf_counter() - t:.2f} {time.process_time() - c:.2f}",
                  flush=True)  # fmt: skip
        return
    raise SystemExit(f"unknown part {part!r}")


if __name__ == "__main__":
    main()
