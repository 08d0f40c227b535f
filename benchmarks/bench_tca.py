"""Benchmark: 25-position unloaded TCA of the seed face gear (target < 5 s on 2 cores).

Run: ``python benchmarks/bench_tca.py``. Times (wall clock, best of 3): the full ``run_tca``
(reference phase + 25 positions × 3 pairs, separation grids 15 × 9, Hertz at 350.14 N·m) and the
same without separation grids.
"""

from __future__ import annotations

import logging
import time

from fegear.assembly import InstallationErrors, face_gear_assembly
from fegear.geometry import FaceGearDesign, FaceGearMember, InvoluteDesign, InvoluteMember
from fegear.tca import TCAOptions, run_tca

log = logging.getLogger("bench_tca")


def main() -> dict[str, float]:
    fg = FaceGearMember(FaceGearDesign())
    pinion = InvoluteMember(
        InvoluteDesign(25, 6.35, 25.0, rack_tip_radius_coeff=0.25, face_width_mm=90.0), "pinion"
    )
    fg.boundaries()  # geometry limits (cached), not part of the TCA
    asm = face_gear_assembly(fg, InstallationErrors(dgamma_deg=0.02), pinion)
    out = {}
    for name, opt in (
        ("full", TCAOptions(n_positions=25, pinion_torque_Nm=350.14)),
        ("no_grids", TCAOptions(n_positions=25, separation_grid=None)),
    ):
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            r = run_tca(pinion, fg, asm, opt)
            best = min(best, time.perf_counter() - t0)
        out[name] = best
        log.info("face gear 25-position TCA (%s): %.2f s, TE p-p %.3f arcsec", name, best,
                 r.te_peak_to_peak_arcsec)  # fmt: skip
    return out


if __name__ == "__main__":
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    main()
