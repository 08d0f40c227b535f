"""Loaded TE amplitude and contact ratio of the seed face gear against the load, every fidelity.

Run: ``python docs/ltca/te_vs_load.py`` (fe, hertz and hybrid at level 0, 25 positions, 10 … 200 %
of the seed load 3e6 N·mm, the whole generated flank). Writes ``te_vs_load.png`` and
``te_vs_load.md`` here. The headlines are those of ``summary.json``
(:meth:`fegear.ltca.results.LoadedCycle.headline`): the TE peak-to-peak over the usable positions
(a position whose loaded patch the cells do not resolve is left out and counted), p_max away from
the flank edges, the edge value beside it. The TE over the cycle is drawn for ``hybrid``: the
fidelity that resolves the 0.5 mm wide patch at level 0 (``fe`` level 0 smears it over 2.9 mm
cells; ``hertz`` is a closed-form law per pair on a lumped compliance).
"""

from __future__ import annotations

import logging
import time
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from fegear.geometry.face_gear import FaceGearDesign, FaceGearMember  # noqa: E402
from fegear.geometry.pair_placement import InstallationErrors, face_gear_assembly  # noqa: E402
from fegear.ltca import LTCAOptions, build_models, run_ltca  # noqa: E402

HERE = Path(__file__).parent
NOTE = (
    "How to read it. `hybrid` and `hertz` agree: the loaded contact ratio is the same at every "
    "load, p_max away from the edges within 6.1 % (Hertz theory on both: the closed form per "
    "pair against the half-space near field of the hybrid), the mean loaded TE within 8 %; the "
    "TE peak-to-peak within 0.01-0.56″, 4-41 % of the hybrid's (the most at the heaviest "
    "load): `hertz` "
    "lumps each tooth pair into one spring at its closest point, so it does not see the "
    "entering pair's corner contact at the face-gear tip that shapes the hybrid TE between "
    "-4 and 0° (the edge column: the singular corner pressure of the hybrid; `hertz` gives no "
    "pressure at an edge, docs/ltca/hertz_edges.md). `fe` level 0 reports no TE peak-to-peak "
    "and no p_max: its "
    "cells are element faces (2.9 mm) on a patch 0.5 mm wide at every position, so every "
    "position is degenerate; its mean TE goes from 17 % less lag than hybrid's at the lightest "
    "load to 26 % more at 3e6 N·mm. On the flank cut at "
    "one height (before the whole generated flank) `hertz` gave 8.4″ at 6e6 N·mm against 1.0″ "
    "for `hybrid`: the cut edge, not the gear, set both."
)
LOADS = np.array([3e5, 5e5, 1.5e6, 3e6, 6e6])  # N·mm on the face gear


def _num(x, fmt: str) -> str:
    return "—" if x is None else format(x, fmt)


def main() -> None:
    logging.basicConfig(level=logging.WARNING)
    t_start = time.perf_counter()
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
            h = c.headline()
            pp.append(np.nan if h.te_pp_loaded_arcsec is None else h.te_pp_loaded_arcsec)
            cr.append(c.contact_ratio_loaded)
            te.append(c.te_loaded_arcsec)
            rows.append((fid, T, h, float(np.mean(c.te_loaded_arcsec))))
        lab = fid if np.isfinite(pp).any() else f"{fid}: not reported (cells wider than patch)"
        ax[0].plot(LOADS / 1e6, pp, mark, label=lab)
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
    fig.suptitle("Seed face gear (whole flank), level 0: loaded TE and contact ratio against load")
    fig.tight_layout()
    fig.savefig(HERE / "te_vs_load.png")
    lines = [
        "| fidelity | T2 (N·mm) | TE p-p unloaded (″) | TE p-p loaded (″) | positions used "
        "| mean loaded TE (″) | loaded contact ratio | p_max away from edges (MPa) "
        "| edge p_max (MPa), edge |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for f, T, h, mean in rows:
        edge = (
            "—"
            if h.p_max_edge_MPa is None
            else (f"{h.p_max_edge_MPa:.0f}, {', '.join(h.p_max_edge_edges)}")
        )
        lines.append(
            f"| {f} | {T:.3g} | {_num(h.te_pp_unloaded_arcsec, '.3f')} | "
            f"{_num(h.te_pp_loaded_arcsec, '.3f')} | "
            f"{h.te_pp_loaded_positions_used}/{h.n_positions} | "
            f"{mean:.2f} | {h.contact_ratio_loaded:.2f} | {_num(h.p_max_MPa, '.0f')} | {edge} |"
        )
    wall = time.perf_counter() - t_start
    lines += ["", NOTE, "", f"Command: `python docs/ltca/te_vs_load.py` ({wall:.0f} s, 2 cores)."]
    (HERE / "te_vs_load.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
