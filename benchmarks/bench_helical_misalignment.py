"""A helical pair under misalignment: ISO/TR 6336-30 example 1 with f_Hβ = 0, 10, 20 µm.

``cases/iso_tr6336_30_ex1.toml`` (m_n 8, z 17/103, β 15.8°, b 100 mm, F_t/b 500 N/mm) at
``hybrid`` level 0 over 25 positions, with a helix slope deviation ``f_Hβ`` on the pinion of 0,
10 and 20 µm (``[pair] helix_slope_mm``). Per run: the positions left out (degenerate, lost),
the cells across the narrowest loaded patch, KHβ of the cycle-mean face-width load and the
range of the per-position KHβ (over all positions, and over the single-contact-line span of
the aligned spur pair FZG type C for the binning's scatter), the loaded TE p-p and its first
mesh order, p_max away from the edges, c_γ and c', and the wall time (one process, an empty
artefact cache: the first run of each pair builds its sectors and operators).

Usage::

    python benchmarks/bench_helical_misalignment.py

Writes ``benchmarks/results/helical_misalignment.json`` and ``.md``.
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from pathlib import Path

import fegear
from fegear.ltca.results import DEGENERATE_SHARE

HERE = Path(__file__).parent
ROOT = HERE.parent
RESULTS = HERE / "results"
FHB_UM = (0, 10, 20)


def measure(case, label: str) -> dict:
    t0 = time.perf_counter()
    r = fegear.run(case, fields=False)
    dt = time.perf_counter() - t0
    d = r.summary
    load = d["cylindrical"]["load"]
    cyc = r.run.cycle
    status = [p.status for p in cyc.positions]
    # the patches the degenerate rule weighs: pairs carrying at least DEGENERATE_SHARE
    across = [
        q.cells_across
        for p in cyc.positions
        for q in p.pairs
        if q.force_N > 0 and q.load_share >= DEGENERATE_SHARE
    ]
    khb = [p["k_h_beta"] for p in load["positions"] if p["usable"]]
    single = [
        lp["k_h_beta"]
        for p, lp in zip(cyc.positions, load["positions"], strict=True)
        if lp["usable"] and sum(q.force_N > 0 for q in p.pairs) == 1
    ]
    h = d["cycle"]["te_harmonics"]["loaded"]
    return {
        "run": label,
        "positions": len(status),
        "degenerate": status.count("degenerate"),
        "lost": status.count("lost"),
        "cells_across_min": float(min(across)),
        "k_h_beta": load["k_h_beta"],
        "k_h_beta_positions": [float(min(khb)), float(max(khb))],
        "k_h_beta_single_contact": [float(min(single)), float(max(single))] if single else None,
        "te_pp_loaded_arcsec": d["cycle"]["te_pp_loaded_arcsec"],
        "te_order1_arcsec": h["amplitude_arcsec"][0],
        "p_max_MPa": d["cycle"]["p_max_MPa"],
        "c_gamma": load["c_gamma_N_per_mm_um"],
        "c_prime": load["c_prime_N_per_mm_um"],
        "seconds": dt,
    }


def main() -> None:
    # an empty artefact cache: the first run of each pair builds its sectors and operators
    os.environ["FEGEAR_CACHE"] = tempfile.mkdtemp(prefix="fegear_helical_")
    case = fegear.load_case(ROOT / "cases" / "iso_tr6336_30_ex1.toml")
    rows = []
    for f in FHB_UM:
        c = case.replace(pair={**case.pair, "helix_slope_mm": [f * 1e-3, 0.0]})
        rows.append(measure(c, f"ISO/TR 6336-30 ex. 1, f_Hβ {f} µm"))
    fzg = fegear.load_case(ROOT / "cases" / "fzg_type_c.toml").replace(n_positions=25)
    rows.append(measure(fzg, "FZG type C (spur, aligned), 25 positions"))
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "helical_misalignment.json").write_text(json.dumps(rows, indent=1) + "\n")
    lines = [
        "# A helical pair under misalignment",
        "",
        "`python benchmarks/bench_helical_misalignment.py` (`hybrid` level 0, 25 positions; "
        "ISO/TR 6336-30 example 1 = `cases/iso_tr6336_30_ex1.toml` with `helix_slope_mm` "
        "on the pinion; FZG type C = `cases/fzg_type_c.toml`):",
        "",
        "| run | degenerate / lost of 25 | cells across (min, pairs ≥ 1 %) | KHβ "
        "| KHβ per position | KHβ, single contact | TE p-p ″ | TE order 1 ″ | p_max MPa "
        "| c_γ | c′ | s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        sc = r["k_h_beta_single_contact"]
        lines.append(
            f"| {r['run']} | {r['degenerate']} / {r['lost']} | {r['cells_across_min']:.1f} | "
            f"{r['k_h_beta']:.3f} | {r['k_h_beta_positions'][0]:.3f}-"
            f"{r['k_h_beta_positions'][1]:.3f} | "
            + (f"{sc[0]:.3f}-{sc[1]:.3f}" if sc else "—")
            + f" | {r['te_pp_loaded_arcsec']:.3f} | {r['te_order1_arcsec']:.3f} | "
            f"{r['p_max_MPa']:.0f} | {r['c_gamma']:.2f} | "
            + (f"{r['c_prime']:.2f}" if r["c_prime"] is not None else "—")
            + f" | {r['seconds']:.1f} |"
        )
    lines += [
        "",
        "KHβ: max/mean of the cycle-mean face-width load (16 bins); per position: the same of "
        "each usable position; single contact: the positions with one loaded pair (a contact "
        "line over the whole face; none for the helical pair, whose ε_γ is 2.6). c_γ, c′ in "
        "N/(mm·µm). Cells across: the narrowest patch of the pairs carrying at least 1 % of the "
        "torque (below 2 such a pair makes its position degenerate: docs/ltca/degenerate.md). "
        "Seconds: the run in this process from an empty cache (the first run of each pair builds "
        "its sector meshes and operators; the others read them).",
    ]
    (RESULTS / "helical_misalignment.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
