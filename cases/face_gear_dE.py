"""Seed face gear under ΔE, a change of the shortest distance between the axes (the offset).

What to look for: ΔE slides the bearing pattern along the face (ΔE > 0 toward the inner end)
and shifts the whole unloaded TE curve by a constant, so the unloaded TE stays flat; the
contact ratio grows with ΔE. Sign conventions: ``fegear.geometry.pair_placement`` (docs/tca).

    python cases/face_gear_dE.py [FIDELITY]   # default: the case's (hybrid); tca: seconds

Prints the table and writes ``out/face_gear_dE/te.png`` and ``pattern.png``.
"""

import sys
from pathlib import Path

import fegear

CASE = Path(__file__).with_name("face_gear_nominal.toml")
VALUES_MM = (-0.1, 0.0, 0.1)


def main(fidelity=None, out="out/face_gear_dE"):
    # the numbers of each run only (fields=False): no displacement fields, no VTK written
    case = fegear.load_case(CASE)
    results = {
        f"ΔE = {v:+.2f} mm": fegear.run(case.with_errors(dE_mm=v), fidelity=fidelity, fields=False)
        for v in VALUES_MM
    }
    print(fegear.table(results))
    fegear.plot_te(results, f"{out}/te.png", title="seed face gear under ΔE")
    fegear.plot_patterns(results, f"{out}/pattern.png", title="seed face gear under ΔE")
    return results


if __name__ == "__main__":
    main(*sys.argv[1:2])
