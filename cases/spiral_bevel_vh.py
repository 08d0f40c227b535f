"""Spiral bevel V/H check: how far the bearing pattern moves under ΔE, ΔP and ΔG.

V is the pattern shift along the face (cone distance, toe → heel: V > 0 toward the heel), H
across the profile (height above the pitch cone: H > 0 toward the top), both on the gear flank,
for 0.05 mm of each error. What to look for: ΔE is the strong lengthwise mover (V ≈ −3 mm,
toward the toe, for +0.05 mm), ΔG moves the pattern a third as far the other way, ΔP hardly
moves it; each also shifts and tilts the designed TE parabola (TE p-p in the table).

    python cases/spiral_bevel_vh.py [FIDELITY]   # default: the case's (hybrid); tca: ~1 min

Prints the V/H table and writes ``out/spiral_bevel_vh/te.png`` and ``pattern.png``.
"""

import sys
from pathlib import Path

import fegear

CASE = Path(__file__).with_name("spiral_bevel_nominal.toml")
ERRORS = {"ΔE = +0.05 mm": {"dE_mm": 0.05}, "ΔP = +0.05 mm": {"dA1_mm": 0.05},
          "ΔG = +0.05 mm": {"dA2_mm": 0.05}}  # fmt: skip


def main(fidelity=None, out="out/spiral_bevel_vh", errors=ERRORS, n_positions=None):
    # the numbers of each run only (fields=False): no displacement fields, no VTK written
    case = fegear.load_case(CASE)
    if n_positions:
        case = case.replace(n_positions=n_positions)
    results = {"nominal": fegear.run(case, fidelity=fidelity, fields=False)}
    for label, e in errors.items():
        results[label] = fegear.run(case.with_errors(**e), fidelity=fidelity, fields=False)
    print(fegear.table(results))
    ref = results["nominal"].pattern["gear"]
    for label, r in results.items():
        p = r.pattern["gear"]
        v, h = p.face_mm - ref.face_mm, p.profile_mm - ref.profile_mm
        print(f"{label:14s}  V {v:+7.3f} mm ({'heel' if v > 0 else 'toe'})   "
              f"H {h:+7.3f} mm ({'top' if h > 0 else 'root'})")  # fmt: skip
    fegear.plot_te(results, f"{out}/te.png", title="spiral bevel: V/H check")
    fegear.plot_patterns(results, f"{out}/pattern.png", title="spiral bevel: V/H check")
    return results


if __name__ == "__main__":
    main(*sys.argv[1:2])
