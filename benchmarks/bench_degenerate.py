"""What an unresolved pair does to the loaded TE: the basis of the "degenerate" rule
(docs/ltca/degenerate.md, fegear/ltca/degenerate.py).

The seed face gear at ``hybrid`` level 0, at the positions where the pair entering or leaving at
a flank edge carries a small share on a patch the cells do not resolve: each position solved
alone from the default cells, once as ``hybrid`` does (pairs below 1 % of the torque keep their
grid, three refinement rounds) and once with every loaded pair refined, six rounds. The table
gives the pair's share and cells across, the status, how far the TE moves when the pair is
resolved, and the bound of the rule (the pair's share of the elastic lag).

Usage::

    python benchmarks/bench_degenerate.py

Prints a Markdown table (about 3 min cold: the seed face gear's sectors and operators).
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: (case, positions of its 25-position cycle)
JOBS = (
    ("face_gear_load_light", (8, 4)),
    ("face_gear_load_moderate", (6,)),
    ("face_gear_load_heavy", (5,)),
    ("face_gear_nominal", (7,)),
)


def main() -> int:
    import fegear
    import fegear.ltca.fidelity as fidelity
    import fegear.ltca.hybrid as hybrid
    from fegear.ltca import LTCAOptions, build_models, run_ltca
    from fegear.pipeline.pair import build_pair
    from fegear.tca.results import ARCSEC

    print("| case | φ1 | pair, share, cells across | status | TE moved by | share × lag |")
    print("|---|---|---|---|---|---|")
    models = None
    for name, idx in JOBS:
        case = fegear.load_case(ROOT / "cases" / f"{name}.toml")
        pair = build_pair(case)
        opt = LTCAOptions(n_positions=25, level=0, fidelity="hybrid", workers=1)
        if models is None:  # the sectors do not depend on the load: one build for all cases
            models = build_models(pair.pinion, pair.gear, pair.assembly, opt)
        n1 = pair.assembly.n1
        for i in idx:
            phi1 = np.array([-np.pi / n1 + 2 * np.pi / n1 * i / 25])
            runs = []
            for share, rounds in ((hybrid.MIN_REFINE_SHARE, 3), (0.0, 6)):
                saved = hybrid.MIN_REFINE_SHARE, fidelity.Hybrid.refine_rounds
                hybrid.MIN_REFINE_SHARE, fidelity.Hybrid.refine_rounds = share, rounds
                try:
                    c = run_ltca(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm,
                                 replace(opt), phi1, models)  # fmt: skip
                finally:
                    hybrid.MIN_REFINE_SHARE, fidelity.Hybrid.refine_rounds = saved
                runs.append(c.positions[0])
            p, fine = runs
            q = min(
                (q for q in p.pairs if q.in_contact and not q.resolved),
                key=lambda q: q.load_share,
                default=None,
            )
            if q is None:
                continue
            lag = p.theta / ARCSEC
            moved = abs(fine.te_loaded_arcsec - p.te_loaded_arcsec)
            print(
                f"| {name} | {np.degrees(p.phi1):.3f}° | ({q.k}, {q.j}) "
                f"{100 * q.load_share:.2f} %, {q.cells_across:.2f} | {p.status} | "
                f"{moved:.4f}″ | {q.load_share * lag:.4f}″ |",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
