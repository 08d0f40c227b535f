"""Size the lead crowning of a helical pair against misalignment: KHβ and TE p-p against the
crowning C_β of the pinion, one curve per out-of-plane axis deviation f_Σβ.

The study engineers run to choose a crowning: without crowning a misalignment piles the load
up at one face end (KHβ high); crowning moves it back towards the middle but, too strong, makes
a peak of its own in the middle of the face (KHβ high again, and more TE). The best crowning
for a given f_Σβ is where the curve of that f_Σβ has its minimum. Every run after the first
reads the sector meshes and compliance operators from the cache (modifications and errors do not
change the sectors): one cold run and seconds per variant.

    python cases/helical_crowning_sweep.py [FIDELITY]   # default: the case's (hybrid)

Prints the table and writes ``out/helical_crowning_sweep/crowning.png``.
"""

import sys
from pathlib import Path

import fegear

CASE = Path(__file__).with_name("helical_crowned.toml")
CROWNING_MM = (0.0, 0.005, 0.010, 0.020, 0.030)
F_SIGMA_BETA_MM = (0.0, 0.010, 0.020)


def main(fidelity=None, out="out/helical_crowning_sweep", crowning=CROWNING_MM,
    # the numbers of each run only (fields=False): no displacement fields, no VTK written
         misalignment=F_SIGMA_BETA_MM, n_positions=None):  # fmt: skip
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    case = fegear.load_case(CASE)
    if n_positions is not None:
        case = case.replace(n_positions=n_positions)
    results = {}
    rows = ["| f_Σβ (mm) | C_β pinion (mm) | KHβ | KHβ max position | TE p-p loaded (arcsec) |",
            "|---|---|---|---|---|"]  # fmt: skip
    for f in misalignment:
        for c in crowning:
            pair = {**case.pair, "lead_crowning_mm": [c, 0.0]}
            r = fegear.run(case.replace(pair=pair).with_errors(f_sigma_beta_mm=f),
                           fidelity=fidelity, fields=False)  # fmt: skip
            results[(f, c)] = r
            load = r.summary["cylindrical"]["load"]
            kmax = load["k_h_beta_max_position"]
            te = r.cycle.te_pp_loaded_arcsec
            rows.append(
                f"| {f:.3f} | {c:.3f} | {_num(load['k_h_beta'])} | "
                f"{_num(kmax and kmax['value'])} | {_num(te)} |"
            )
    print("\n".join(rows))
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    for f in misalignment:
        cs = [c for c in crowning]
        k = [results[(f, c)].summary["cylindrical"]["load"]["k_h_beta"] for c in cs]
        te = [results[(f, c)].cycle.te_pp_loaded_arcsec for c in cs]
        um = [1000 * c for c in cs]
        a1.plot(um, [float("nan") if x is None else x for x in k], "o-", label=f"f_Σβ = {f:g} mm")
        a2.plot(um, [float("nan") if x is None else x for x in te], "o-", label=f"f_Σβ = {f:g} mm")
    a1.set_xlabel("lead crowning C_β of the pinion (µm)")
    a1.set_ylabel("KHβ (face-width load, cycle mean)")
    a2.set_xlabel("lead crowning C_β of the pinion (µm)")
    a2.set_ylabel("loaded TE peak-to-peak (arcsec)")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle(f"{case.name}: crowning against misalignment, {case.torque2_Nmm / 1000:g} N·m",
                 fontsize=10)  # fmt: skip
    fig.tight_layout()
    Path(out).mkdir(parents=True, exist_ok=True)
    fig.savefig(Path(out) / "crowning.png", dpi=110)
    plt.close(fig)
    return results


def _num(x):
    return "—" if x is None else f"{x:.3f}"


if __name__ == "__main__":
    main(*sys.argv[1:2])
