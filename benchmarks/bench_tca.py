"""Benchmark: 25-position unloaded TCA of the seed face gear (target < 5 s on 2 cores) and of the
reference spiral bevel pair.

Run: ``python benchmarks/bench_tca.py``. Times (wall clock, best of 3): the full ``run_tca``
(reference phase + 25 positions × 3 pairs, separation grids 15 × 9, Hertz at 350.14 N·m) and the
same without separation grids. Spiral bevel (12/36, docs/reference_pairs.md;
``SpiralBevelPair.design()`` is not timed): the first run ("cold") includes building the native
flank tables of both members (:class:`fegear.geometry.bevel.native.NativeFlank`), then best of 3
with and without grids.
"""

from __future__ import annotations

import logging
import time

from fegear.geometry import FaceGearDesign, FaceGearMember, InvoluteDesign, InvoluteMember
from fegear.geometry.bevel import SpiralBevelPair
from fegear.geometry.pair_placement import (
    InstallationErrors,
    face_gear_assembly,
    spiral_bevel_assembly,
)
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
    out.update(spiral_bevel())
    return out


def spiral_bevel() -> dict[str, float]:
    """25-position TCA of the reference spiral bevel pair (drive side, ΔE = 0.05 mm)."""
    pair = SpiralBevelPair.design()
    asm = spiral_bevel_assembly(pair, "drive", InstallationErrors(dE_mm=0.05))
    out = {}
    t0 = time.perf_counter()
    r = run_tca(pair.pinion, pair.gear, asm, TCAOptions(n_positions=25))
    out["bevel_cold"] = time.perf_counter() - t0
    log.info("spiral bevel 25-position TCA (cold, incl. native tables): %.2f s", out["bevel_cold"])
    for name, opt in (
        ("bevel_full", TCAOptions(n_positions=25, pinion_torque_Nm=200.0)),
        ("bevel_no_grids", TCAOptions(n_positions=25, separation_grid=None)),
    ):
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            r = run_tca(pair.pinion, pair.gear, asm, opt)
            best = min(best, time.perf_counter() - t0)
        out[name] = best
        log.info("spiral bevel 25-position TCA (%s): %.2f s, TE p-p %.3f arcsec", name, best,
                 r.te_peak_to_peak_arcsec)  # fmt: skip
    return out


if __name__ == "__main__":
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    main()
