"""Is this batch acceptable? The measured helical pinion of ``helical_measured.toml`` against its
design, under two sets of tolerances.

The batch: the pinion's drive flank as a measuring machine reads it
(``helical_measured_pinion_drive.csv``, 5 × 9 points). It is a grid made from a known
modification, not a measurement of a real part: the 10 µm lead crowning of
``helical_crowned.toml`` on a design that has none (docs/measured_flanks.md). The design is the
same case without ``[topography]``: the uncrowned, aligned pair, whose load spreads over the
whole face width.

What to look for: the crowning gathers the load in the middle of the face. At the case's
9 positions p_max away from the edges rises by 16 % and KHβ from 1.03 to 1.67; the loaded TE
p-p by 1.5″ of 25″ (6 %), the unloaded one not at all (conjugate flanks: 0 in both runs); no
pair touches an edge the design's does not (the crowned flank touches fewer: 8 loaded pairs at
an edge against 16).

- ``the defaults`` (p_max +10 %, TE p-p +1″, KHβ +0.1, no new edge contact): **REJECT**:
  p_max, the loaded TE p-p and KHβ fail; the unloaded TE and the edge contact pass;
- ``a noise spec`` (a customer who buys the pair for its TE, with strength margin to spare:
  p_max +25 %, KHβ +0.7, TE p-p loaded +2″ and +10 %, unloaded +0.5″): **ACCEPT**, every check
  within its limit.

    python cases/helical_measured_acceptance.py [FIDELITY]   # default: the case's (hybrid)

Prints each verdict's table and writes ``out/helical_measured_acceptance/<spec>/acceptance.json``.
"""

import sys
from pathlib import Path

import fegear
from fegear.api import Tolerances, accept

CASE = Path(__file__).with_name("helical_measured.toml")
SPECS = {
    "the defaults": Tolerances(),
    "a noise spec": Tolerances(
        p_max_pct=25.0,
        k_h_beta=0.7,
        te_pp_loaded_arcsec=2.0,
        te_pp_loaded_pct=10.0,
        te_pp_unloaded_arcsec=0.5,
    ),  # fmt: skip
}


def main(fidelity=None, out="out/helical_measured_acceptance", n_positions=None):
    case = fegear.load_case(CASE)
    if n_positions is not None:
        case = case.replace(n_positions=n_positions)
    verdicts = {}
    for name, tol in SPECS.items():
        # the second verdict reads both runs back from the cache: the same case, fidelity, level
        v = accept(case, tol, fidelity=fidelity)
        v.write(Path(out) / name.replace(" ", "_"))
        print(f"## {name}\n\n{v.table()}\n")
        verdicts[name] = v
    return verdicts


if __name__ == "__main__":
    main(*sys.argv[1:2])
