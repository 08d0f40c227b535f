"""Seed face gear under ΔA1 (ΔP), an axial displacement of the spur pinion.

What to look for: nothing moves. The pinion is a spur gear whose axis runs along the face-gear
radius, so sliding it along its axis slides a uniform tooth along itself: the pattern, the TE
and the contact ratio are those of the error-free pair (as long as the pinion face, 90 mm,
still covers the face-gear tooth, 89 mm). The face gear is insensitive to ΔA1 by design.

    python cases/face_gear_dA1.py [FIDELITY]   # default: the case's (hybrid); tca: seconds

Prints the table and writes ``out/face_gear_dA1/te.png`` and ``pattern.png``.
"""

import sys
from pathlib import Path

import fegear

CASE = Path(__file__).with_name("face_gear_nominal.toml")
VALUES_MM = (-0.5, 0.0, 0.5)


def main(fidelity=None, out="out/face_gear_dA1"):
    # the numbers of each run only (fields=False): no displacement fields, no VTK written
    case = fegear.load_case(CASE)
    results = {
        f"ΔA1 = {v:+.1f} mm": fegear.run(
            case.with_errors(dA1_mm=v), fidelity=fidelity, fields=False
        )
        for v in VALUES_MM
    }
    print(fegear.table(results))
    fegear.plot_te(results, f"{out}/te.png", title="seed face gear under ΔA1 (ΔP)")
    fegear.plot_patterns(results, f"{out}/pattern.png", title="seed face gear under ΔA1 (ΔP)")
    return results


if __name__ == "__main__":
    main(*sys.argv[1:2])
