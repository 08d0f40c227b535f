"""Loaded TE amplitude and contact ratio of the seed face gear against the load (issue 6).

Run: ``python docs/ltca/te_vs_load.py`` (fe, hertz and hybrid at level 0, 25 positions, 10 … 200 %
of the seed load 3e6 N·mm). Writes ``te_vs_load.png`` and ``te_vs_load.md`` here. The TE over the
cycle is drawn for ``hybrid``: the fidelity that is converged in its mesh level on this gear
(README, "Fidelities"; ``fe`` level 0 smears the 0.5 mm wide patch over 2.9 mm cells).
"""

from __future__ import annotations

import logging
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from fegear.assembly import InstallationErrors, face_gear_assembly  # noqa: E402
from fegear.geometry.face_gear import FaceGearDesign, FaceGearMember  # noqa: E402
from fegear.ltca import LTCAOptions, build_models, run_ltca  # noqa: E402

HERE = Path(__file__).parent
LOADS = np.array([3e5, 5e5, 1.5e6, 3e6, 6e6])  # N·mm on the face gear
NOTE = (
    "p_max is the largest cell pressure of the cycle, edge contacts included: singular and "
    "grid-dependent where the hybrid resolves a patch running off the pinion tip (README, "
    "'Fidelities', for p_max away from the edges)."
)


def main() -> None:
    logging.basicConfig(level=logging.WARNING)
    fg = FaceGearMember(FaceGearDesign())
    pin = fg.pinion()
    asm = face_gear_assembly(fg, InstallationErrors(), pin)
    opt = LTCAOptions(n_positions=25, level=0)
    rows = []
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8), dpi=100)
    for fid, mark in (("fe", "o-"), ("hertz", "s--"), ("hybrid", "d-")):
        o = replace(opt, fidelity=fid)
        models = build_models(pin, fg, asm, o)  # cached: the hertz models are the fe ones
        pp, cr, te = [], [], []
        for T in LOADS:
            c = run_ltca(pin, fg, asm, T, o, models=models)
            pp.append(c.te_pp_loaded_arcsec)
            cr.append(c.contact_ratio_loaded)
            te.append(c.te_loaded_arcsec)
            rows.append(
                (
                    fid,
                    T,
                    c.te_pp_unloaded_arcsec,
                    c.te_pp_loaded_arcsec,
                    float(np.mean(c.te_loaded_arcsec)),
                    c.contact_ratio_loaded,
                    c.p_max_MPa,
                )
            )
        ax[0].plot(LOADS / 1e6, pp, mark, label=fid)
        ax[1].plot(LOADS / 1e6, cr, mark, label=fid)
        if fid == "hybrid":
            for T, t in zip(LOADS, te, strict=True):
                ax[2].plot(np.degrees(c.phi1), t, "-", label=f"{T / 1e6:g}e6 N·mm")
    ax[0].set_ylabel("loaded TE peak-to-peak (arcsec)")
    ax[1].set_ylabel("loaded contact ratio")
    ax[2].set_ylabel("loaded TE, hybrid (arcsec)")
    ax[2].set_xlabel("pinion angle (deg)")
    for a in ax[:2]:
        a.set_xlabel("torque on the face gear (1e6 N·mm)")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle("Seed face gear, level 0: loaded TE and contact ratio against the load")
    fig.tight_layout()
    fig.savefig(HERE / "te_vs_load.png")
    lines = [
        "| fidelity | T2 (N·mm) | TE p-p unloaded (″) | TE p-p loaded (″) | mean loaded TE (″) "
        "| loaded contact ratio | p_max (MPa) |",
        "|---|---|---|---|---|---|---|",
    ]
    lines += [f"| {f} | {T:.3g} | {a:.3f} | {b:.3f} | {m:.2f} | {r:.2f} | {p:.0f} |"
              for f, T, a, b, m, r, p in rows]  # fmt: skip
    lines += ["", NOTE]
    (HERE / "te_vs_load.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
