"""CalculiX with elements refined locally along the loaded contact patch: a ladder of patch sizes.

The gear deck of :func:`fegear.export.gear_deck.gear_deck` with ``patch_mm``: elements of that
size along each pair's contact patch (the flank strip where fegear's TCA separation is below
``--patch-gap-mm``, two elements wider each side), growing with the sector mesh's slope to the
case level's size on the rest of the flank (FZG level 0: 2 mm; 7.2 mm in the body). For each
rung: the deck's size, CalculiX's wall time and peak memory (``OMP_NUM_THREADS = --threads``,
one run at a time), and what the reader (:mod:`fegear.export.ccx_results`) gives: the pressure
integral over the contact force (the integration points' ``Σ p A``), CalculiX's nodal
``CPRESS`` integrated over the force, the lag θ and the loaded TE, p_max (largest nodal
pressure, and away from the flank edges), the recovered peak, the largest integration-point
pressure, the semi-axes and the contact area. fegear ``hybrid`` level 0 beside it is read from
``benchmarks/results/calculix.json`` (``benchmarks/calculix_crosscheck.py``), not measured
again.

Usage::

    python benchmarks/calculix_local.py [--case cases/fzg_spur.toml] [--phi1-deg A]
        [--patch 0.35,0.25,0.18] [--element-mm 0.7] [--threads 1] [--work DIR] [--report-only]

Default position: the case's pitch point (:func:`fegear.validation.rows.pitch_point_phi1`).
Writes ``benchmarks/results/calculix_local.md`` and ``.json``; each finished rung is kept as
``<work>/<tag>.row.json`` and not run again.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "benchmarks" / "results"
LADDER = (0.35, 0.25, 0.18)


def rung(case_path: Path, phi1_deg: float, element_mm: float, patch_mm: float, gap_mm: float,
         threads: int, work: Path) -> dict:  # fmt: skip
    """Export, run and read one rung (cached in ``<work>/<tag>.row.json``)."""
    from fegear.api import load_case
    from fegear.export import export_ccx, read_results, run_ccx

    case = load_case(case_path)
    tag = f"{case.name}_{phi1_deg:+g}deg_patch{patch_mm:g}mm_gap{gap_mm:g}"
    row_file = work / f"{tag}.row.json"
    if row_file.is_file():
        return json.loads(row_file.read_text())
    folder = work / tag
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    (inp,) = export_ccx(case, folder, element_mm=element_mm, phi1=[math.radians(phi1_deg)],
                        patch_mm=patch_mm, patch_gap_mm=gap_mm)  # fmt: skip
    export_s = time.perf_counter() - t0
    rec = json.loads(inp.with_suffix(".json").read_text())
    print(f"  ccx {tag}: {rec['n_nodes']} nodes, {rec['n_elements']} C3D10 ...", file=sys.stderr,
          flush=True)  # fmt: skip
    load = os.getloadavg()[0]
    run = run_ccx(inp, threads=threads, timeout_s=4 * 3600)
    row = {"patch_mm": patch_mm, "gap_mm": gap_mm, "element_mm": element_mm,
           "phi1_deg": phi1_deg, "export_s": export_s, "nodes": rec["n_nodes"],
           "elements": rec["n_elements"], "dofs": rec["dofs"], "ccx_s": run.seconds,
           "peak_MB": run.peak_MB, "threads": threads, "returncode": run.returncode,
           "load_before": load, "load_after": os.getloadavg()[0]}  # fmt: skip
    if run.returncode == 0:
        row["result"] = read_results(inp).to_dict()
    row_file.write_text(json.dumps(row, indent=1))
    return row


def _fegear_row(case_name: str, phi1_deg: float) -> dict | None:
    """fegear ``hybrid`` level 0 at this position from ``calculix.json``, if measured there."""
    f = OUT / "calculix.json"
    if not f.is_file():
        return None
    doc = json.loads(f.read_text())

    def walk(x):
        if isinstance(x, dict):
            yield x
            for v in x.values():
                yield from walk(v)
        elif isinstance(x, list):
            for v in x:
                yield from walk(v)

    for d in walk(doc):
        if (isinstance(d.get("phi1_deg"), (int, float)) and abs(d["phi1_deg"] - phi1_deg) < 1e-3
                and isinstance(d.get("fegear"), list)):  # fmt: skip
            for r in d["fegear"]:
                if r.get("fidelity") == "hybrid" and r.get("level") == 0:
                    return r
    return None


def _f(x, spec: str) -> str:
    return "—" if x is None else format(x, spec)


def markdown(doc: dict) -> str:
    a = doc["args"]
    L = [
        "# CalculiX refined locally along the contact patch",
        "",
        f"{doc['case']} at φ1 = {a['phi1_deg']:.3f}°: the deck of `fegear export-ccx` with "
        f"`--patch-mm` (elements of that size along the pair's contact patch, the flank strip "
        f"where fegear's TCA separation is below {a['gap_mm']:g} mm, two elements wider each "
        f"side; the mesh grows from it to the level's size), CalculiX 2.20 with "
        f"{a['threads']} thread(s), one run at a time on a shared 2-core machine (load "
        "average before each run in the JSON). Made by:",
        "",
        "```bash",
        doc["command"],
        "```",
        "",
        "Pressure integral: the integration points' Σ p A over the pair's contact force "
        "(`*CONTACT PRINT CF`); `CPRESS` integral: CalculiX's nodal pressures integrated with the "
        "six-node faces' shape functions, over the same force (docs/calculix.md, Reading back). "
        "p_max: the largest nodal pressure (force / tributary area), and away from the flank "
        "edges; peak: recovered from the nodal forces; points: the largest integration-point "
        "pressure.",
        "",
        "| patch elements | nodes | DOFs | pressure integral / CF | `CPRESS` integral / CF | "
        "lag θ µrad | loaded TE ″ | p_max MPa | interior p_max MPa | peak MPa | points max MPa "
        "| semi-axes a × b mm | contact area mm² | ccx s | peak MB |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in doc["rows"]:
        if "result" not in r:
            L.append(f"| {r['patch_mm']:g} mm | {r['nodes']} | {r['dofs']} | failed (ccx exit "
                     f"{r['returncode']}) | | | | | | | | | | {r['ccx_s']:.0f} | "
                     f"{_f(r['peak_MB'], '.0f')} |")  # fmt: skip
            continue
        res = r["result"]
        for q in res["pairs"]:
            fn = q["normal_force_N"]
            ip = None if q.get("ip_force_N") is None or not fn else q["ip_force_N"] / fn
            nod = None if not fn else q["nodal_force_N"] / fn
            L.append(
                f"| {r['patch_mm']:g} mm | {r['nodes']} | {r['dofs']} | {_f(ip, '.6f')} | "
                f"{_f(nod, '.3f')} | {1e6 * res['theta_rad']:.1f} | "
                f"{res['te_loaded_arcsec']:.2f} | {q['p_max_MPa']:.0f} | "
                f"{_f(q['p_interior_MPa'], '.0f')} | {q['p_peak_MPa']:.0f} | "
                f"{_f(q.get('p_max_points_MPa'), '.0f')} | {q['semi_major_mm']:.2f} × "
                f"{q['semi_minor_mm']:.3f} | {_f(q.get('contact_area_mm2'), '.2f')} | "
                f"{r['ccx_s']:.0f} | {_f(r['peak_MB'], '.0f')} |"
            )
    from fegear.validation.calculix_rows import richardson

    ok = [r for r in doc["rows"] if "result" in r]
    quantities = (("lag θ", "µrad", lambda r: 1e6 * r["result"]["theta_rad"], ".1f"),
                  ("loaded TE", "″", lambda r: r["result"]["te_loaded_arcsec"], ".2f"),
                  ("recovered peak", "MPa", lambda r: r["result"]["pairs"][0]["p_peak_MPa"],
                   ".0f"))  # fmt: skip
    lines = []
    for name, unit, get, spec in quantities:
        ext = richardson([r["patch_mm"] for r in ok], [get(r) for r in ok])
        if ext is not None:
            lines.append(f"{name} {format(ext.value, spec)} {unit} (observed order "
                         f"{ext.order:.2f}, GCI ±{100 * ext.gci:.2f} %)")  # fmt: skip
        elif len(ok) >= 3:
            lines.append(f"{name}: no extrapolation (the three finest sizes do not converge "
                         "at an order in [0.5, 6])")  # fmt: skip
    if lines:
        head = ("Extrapolated to zero element size from the three finest patch sizes "
                "(`fegear.validation.calculix_rows.richardson`): ")  # fmt: skip
        L += ["", head + "; ".join(lines) + "."]
    fe = doc.get("fegear")
    if fe:
        q = fe["pairs"][0] if fe.get("pairs") else {}
        ab = f"{q['a']:.2f} × {q['b']:.3f}" if q.get("a") else "—"
        L += [
            "",
            f"fegear `hybrid` level 0 at the same position (from `calculix.json`): lag "
            f"{1e6 * fe['theta']:.1f} µrad, loaded TE {fe['te_loaded']:.2f}″, interior p_max "
            f"{_f(q.get('p_interior'), '.0f')} MPa (largest cell pressure "
            f"{_f(q.get('p_max'), '.0f')} MPa), semi-axes {ab} mm.",
        ]
    return "\n".join(L) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", default=str(ROOT / "cases" / "fzg_spur.toml"))
    ap.add_argument("--phi1-deg", type=float, help="pinion angle (default: the pitch point)")
    ap.add_argument("--patch", default=",".join(map(str, LADDER)),
                    help="patch element sizes (mm), comma-separated")  # fmt: skip
    ap.add_argument("--patch-gap-mm", type=float, default=None)
    ap.add_argument("--element-mm", type=float, default=0.7,
                    help="sets how far the contact surfaces reach around the pairs")  # fmt: skip
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--report-only", action="store_true",
                    help="write the page from calculix_local.json, run nothing")  # fmt: skip
    ap.add_argument("--work", default="ccx_local_work", help="decks and CalculiX files")
    args = ap.parse_args(argv)
    if args.report_only:
        doc = json.loads((OUT / "calculix_local.json").read_text())
        (OUT / "calculix_local.md").write_text(markdown(doc))
        return 0
    from fegear.api import load_case
    from fegear.export import find_ccx
    from fegear.export.gear_deck import DEFAULT_PATCH_GAP_MM
    from fegear.pipeline.pair import build_pair
    from fegear.validation.rows import pitch_point_phi1

    find_ccx()
    case_path = Path(args.case)
    case = load_case(case_path)
    phi = args.phi1_deg
    if phi is None:
        phi = round(math.degrees(pitch_point_phi1(build_pair(case))), 3)
    gap = DEFAULT_PATCH_GAP_MM if args.patch_gap_mm is None else args.patch_gap_mm
    work = Path(args.work).resolve()
    work.mkdir(parents=True, exist_ok=True)
    given = list(argv if argv is not None else sys.argv[1:])
    if "--work" in given:  # where the files go is not part of the measurement
        i = given.index("--work")
        del given[i : i + 2]
    rows = []
    for h in [float(x) for x in args.patch.split(",") if x.strip()]:
        rows.append(rung(case_path, phi, args.element_mm, h, gap, args.threads, work))
        doc = {
            "case": case.name,
            "args": {
                "phi1_deg": phi,
                "gap_mm": gap,
                "element_mm": args.element_mm,
                "threads": args.threads,
            },  # fmt: skip
            "command": " ".join(["python benchmarks/calculix_local.py", *given]),
            "rows": rows,
            "fegear": _fegear_row(case.name, phi),
        }
        OUT.mkdir(parents=True, exist_ok=True)
        (OUT / "calculix_local.json").write_text(json.dumps(doc, indent=1))
        (OUT / "calculix_local.md").write_text(markdown(doc))
    return 0


if __name__ == "__main__":
    sys.exit(main())
