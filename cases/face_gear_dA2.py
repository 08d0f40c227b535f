"""Seed face gear under ΔA2 (ΔG, Δq), an axial displacement of the face gear.

What to look for: Δq changes the depth of mesh, and the localized contact answers by sliding
along the face: Δq > 0 (the face gear moved along its axis away from the pinion axis, a
shallower mesh; signs in ``fegear.geometry.pair_placement``) takes the pattern toward the inner
end, about
8 mm per 0.1 mm, and shifts the unloaded TE curve by a constant; the contact ratio follows.

    python cases/face_gear_dA2.py [FIDELITY]   # default: the case's (hybrid); tca: seconds

Prints the table and writes ``out/face_gear_dA2/te.png`` and ``pattern.png``.
"""

import sys
from pathlib import Path

import fegear

CASE = Path(__file__).with_name("face_gear_nominal.toml")
VALUES_MM = (-0.1, 0.0, 0.1)


def main(fidelity=None, out="out/face_gear_dA2"):
    # the numbers of each run only (fields=False): no displacement fields, no VTK written
    case = fegear.load_case(CASE)
    results = {
        f"Δq = {v:+.2f} mm": fegear.run(case.with_errors(dA2_mm=v), fidelity=fidelity, fields=False)
        for v in VALUES_MM
    }
    print(fegear.table(results))
    fegear.plot_te(results, f"{out}/te.png", title="seed face gear under ΔA2 (ΔG, Δq)")
    fegear.plot_patterns(results, f"{out}/pattern.png", title="seed face gear under ΔA2 (Δq)")
    return results


if __name__ == "__main__":
    main(*sys.argv[1:2])
