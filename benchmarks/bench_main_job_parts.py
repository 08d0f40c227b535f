"""Parts of the main job (``fegear run cases/face_gear_nominal.toml``) outside the compliance
operators, timed one per fresh process: wall and CPU seconds of this process.

Run: ``python benchmarks/bench_main_job_parts.py PART [REPEATS]`` with PART one of

- ``sector``: the seed face gear's 5-tooth sector mesh at level 0 in an empty cache folder
  (geometry of the sections, the CAD loft and trimming, the check of the CAD flank faces
  against the exact flank, gmsh), after the member's limits;
- ``flank``: the face gear's exact flanks: limits, fillet-limit tables, ``point_normal`` on a
  21 × 21 grid of both working flanks (the generation engine);
- ``pair``: ``build_pair`` of the case, once to fill the cache, then timed (what every run of
  the case does first).

To compare another checkout, put its ``fegear`` first on ``PYTHONPATH``. Prints one line per
repeat: ``PART wall_s cpu_s``.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

os.environ["FEGEAR_CACHE"] = tempfile.mkdtemp(prefix="fegear_parts_")

import numpy as np  # noqa: E402

CASE = Path(__file__).resolve().parents[1] / "cases" / "face_gear_nominal.toml"


def _sector() -> None:
    from fegear.geometry import FaceGearDesign, FaceGearMember
    from fegear.mesh.sector import sector_mesh

    m = FaceGearMember(FaceGearDesign())
    m.check_limits()
    yield
    sector_mesh(m, n_teeth=5, level=0)


def _flank() -> None:
    from fegear.geometry import FaceGearDesign, FaceGearMember

    yield
    m = FaceGearMember(FaceGearDesign())
    m.check_limits()
    u = np.linspace(0.0, 1.0, 21)[:, None]
    v = np.linspace(471.0, 560.0, 21)[None, :]
    for side in ("drive", "coast"):
        m.point_normal(side, u, v)


def _pair() -> None:
    import fegear
    from fegear.pipeline.pair import build_pair

    case = fegear.load_case(CASE)
    build_pair(case)
    yield
    build_pair(case)


PARTS = {"sector": _sector, "flank": _flank, "pair": _pair}


def main() -> None:
    part = sys.argv[1]
    steps = PARTS[part]()
    next(steps)  # set-up, not timed
    t, c = time.perf_counter(), time.process_time()
    for _ in steps:
        pass
    print(f"{part} {time.perf_counter() - t:.2f} {time.process_time() - c:.2f}", flush=True)


if __name__ == "__main__":
    main()
