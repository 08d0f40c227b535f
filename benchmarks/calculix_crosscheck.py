"""CalculiX (full FE contact) against fegear: the Hertz scene and FZG at two positions.

For each problem, CalculiX is refined along a ladder of contact element sizes (its own
convergence shown) and set beside fegear ``hybrid`` (and ``fe``) with the same quantities:
load shares, p_max (interior), patch semi-axes, TE / approach, wall time and peak memory.

- **Hertz scene** (``cases/hertz_scene.toml``, quarter model): p0, a, b against closed-form Hertz;
  fegear ``hybrid`` levels 0-3 (FE of level 0).
- **FZG** (``cases/fzg_spur.toml``, 200 N·m) at the pitch point (single pair) and at a two-pair
  position: load shares, interior p_max, the lag and the loaded TE; fegear ``hybrid`` level 0 and
  ``fe`` level 0.

Every measurement runs in its own process, so the peak memory (max RSS) is its own; CalculiX with
``OMP_NUM_THREADS = --threads``, one run at a time. fegear rows are cold (an empty cache: meshes
and compliance operators built) and warm (the same run again).

Usage::

    python benchmarks/calculix_crosscheck.py [--threads 2] [--work DIR] [--hertz 0.45,0.32,...]
        [--fzg 0.7,0.5,...] [--skip-fzg] [--skip-hertz]

Finds ``ccx`` (``$FEGEAR_CCX`` or the ``PATH``; says so and stops when it is missing). Writes
``benchmarks/results/calculix.md`` and ``calculix.json``; the decks, CalculiX's files and one
``<job>.row.json`` per finished run stay in ``--work`` (a run with a row there is not repeated:
delete the row to measure it again).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CASES = ROOT / "cases"
OUT = ROOT / "benchmarks" / "results"
#: FZG's two-pair position (pinion angle, deg): the middle of the two-pair zone (both pairs in
#: interior contact from 1.25° to 10° by the rigid TCA); the pitch point (one pair) comes from
#: :func:`fegear.validation.rows.pitch_point_phi1`
FZG_TWO_PAIRS_DEG = 5.0
HERTZ_LADDER = (0.45, 0.32, 0.24, 0.16, 0.12)
FZG_LADDER = (0.7, 0.5, 0.35)


def measured(cmd: list[str], env: dict | None = None, cwd: Path | None = None):
    """Run ``cmd``; ``(stdout, wall s, peak RSS MB)`` of that process alone (``os.wait4``)."""
    t0 = time.perf_counter()
    with tempfile.TemporaryFile(mode="w+") as err:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=err, env=env, cwd=cwd,
                                text=True)  # fmt: skip
        out = proc.stdout.read()
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        if proc.returncode != 0:
            err.seek(0)
            raise RuntimeError(f"{cmd[:4]} failed ({proc.returncode}): {err.read()[-2000:]}")
    return out, time.perf_counter() - t0, usage.ru_maxrss / 1024.0


# ---------------------------------------------------------------------------- fegear children
FEGEAR_HERTZ = r"""
import json, sys
from fegear.scenes.hertz_scene import HertzScene, run_level
r = run_level(HertzScene(), int(sys.argv[1]), fidelity="hybrid", fe_level=0)
print(json.dumps({"p0": r.p0_MPa, "e_p0": r.error("p0"), "e_a": r.error("a"),
                  "e_b": r.error("b"), "a": r.a_mm, "b": r.b_mm, "dofs": sum(r.dofs.values())}))
"""

FEGEAR_GEAR = r"""
import json, math, sys
import numpy as np
from fegear.api import load_case
from fegear.ltca import LTCAOptions, run_ltca
from fegear.pipeline.pair import build_pair
case = load_case(sys.argv[1])
phi1, fid, level = math.radians(float(sys.argv[2])), sys.argv[3], int(sys.argv[4])
pair = build_pair(case)
opt = LTCAOptions(n_positions=case.n_positions, level=level, n_teeth=case.n_teeth,
                  E_MPa=case.E_MPa, nu=case.nu, fidelity=fid, workers=1,
                  **case.contact.as_dict())
p = run_ltca(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, opt,
             phi1=np.array([phi1])).positions[0]
print(json.dumps({"theta": p.theta, "te_unloaded": p.te_unloaded_arcsec,
  "te_loaded": p.te_loaded_arcsec, "pairs": [
  {"k": q.k, "j": q.j, "share": q.load_share, "force": q.force_N, "p_max": q.p_max_MPa,
   "p_interior": q.p_interior_MPa, "a": q.semi_major_mm, "b": q.semi_minor_mm,
   "edges": list(q.edges)} for q in p.pairs if q.force_N > 0]}))
"""


def fegear_row(code: str, args: list[str]) -> dict:
    """A fegear measurement, cold (fresh cache) then warm (the same cache)."""
    with tempfile.TemporaryDirectory(prefix="fegear_ccx_bench_") as cache:
        env = {**os.environ, "FEGEAR_CACHE": cache, "FEGEAR_WORKERS": "1"}
        cmd = [sys.executable, "-c", code, *args]
        load = os.getloadavg()[0]
        out, cold, mem = measured(cmd, env)
        _, warm, mem_w = measured(cmd, env)
    row = json.loads(out.strip().splitlines()[-1])
    row.update(cold_s=cold, warm_s=warm, peak_MB=mem, peak_warm_MB=mem_w, load_before=load)
    return row


# -------------------------------------------------------------------------------- CalculiX
def ccx_row(case_path: Path, work: Path, threads: int, element_mm: float,
            phi1_deg: float | None = None) -> dict:  # fmt: skip
    """Export (in a child process: its time is the deck's), run ccx, read back; cached in
    ``<job>.row.json``."""
    from fegear.api import load_case
    from fegear.export import export_ccx, read_results, run_ccx

    case = load_case(case_path)
    tag = f"{case.name}_{element_mm:g}mm" + ("" if phi1_deg is None else f"_{phi1_deg:+g}deg")
    folder = work / tag
    row_file = work / f"{tag}.row.json"
    if row_file.is_file():
        return json.loads(row_file.read_text())
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    phi = [] if phi1_deg is None else [math.radians(phi1_deg)]
    (inp,) = export_ccx(case, folder, element_mm=element_mm, phi1=phi)
    export_s = time.perf_counter() - t0
    rec = json.loads(inp.with_suffix(".json").read_text())
    print(f"  ccx {inp.name}: {rec['n_nodes']} nodes, {rec['n_elements']} C3D10 ...",
          file=sys.stderr, flush=True)  # fmt: skip
    load = os.getloadavg()[0]
    run = run_ccx(inp, threads=threads)
    row = {"load_before": load, "load_after": os.getloadavg()[0], "element_mm": element_mm,
           "phi1_deg": phi1_deg, "export_s": export_s,
           "nodes": rec["n_nodes"], "elements": rec["n_elements"], "dofs": rec["dofs"],
           "ccx_s": run.seconds, "peak_MB": run.peak_MB, "threads": threads,
           "returncode": run.returncode}  # fmt: skip
    if run.returncode == 0:
        row["result"] = read_results(inp).to_dict()
    sta = inp.with_suffix(".sta")
    if sta.is_file():
        row["iterations"] = sum(int(line.split()[3]) for line in sta.read_text().splitlines()[2:]
                                if line.split() and line.split()[0].isdigit())  # fmt: skip
    row_file.write_text(json.dumps(row, indent=1))
    return row


# --------------------------------------------------------------------------------- report
def _pct(x: float | None) -> str:
    return "—" if x is None else f"{100 * x:+.2f}%"


def hertz_rows(work: Path, threads: int, ladder) -> dict:
    from fegear.api import load_case
    from fegear.scenes.hertz_scene import hertz_reference

    case = load_case(CASES / "hertz_scene.toml")
    ref = hertz_reference(case.scene)
    out = {"hertz": {"p0_MPa": ref.p0_MPa, "a_mm": ref.a_mm, "b_mm": ref.b_mm}, "ccx": [],
           "fegear": []}  # fmt: skip
    for h in ladder:
        r = ccx_row(CASES / "hertz_scene.toml", work, threads, h)
        if "result" in r:
            (p,) = r["result"]["pairs"]
            r["e_p0"] = p["p_max_MPa"] / ref.p0_MPa - 1
            r["e_p0_recovered"] = p["p_peak_MPa"] / ref.p0_MPa - 1
            r["e_a"] = p["semi_major_mm"] / ref.a_mm - 1
            r["e_b"] = p["semi_minor_mm"] / ref.b_mm - 1
            r["elements_across_2b"] = 2 * ref.b_mm / h
        out["ccx"].append(r)
        print(f"  hertz ccx {h} mm: {r.get('e_p0')}", file=sys.stderr, flush=True)
    for level in (0, 1, 2, 3):
        r = fegear_row(FEGEAR_HERTZ, [str(level)])
        r["level"] = level
        out["fegear"].append(r)
    return out


def fzg_rows(work: Path, threads: int, ladder) -> dict:
    from fegear.api import load_case
    from fegear.pipeline.pair import build_pair
    from fegear.validation.rows import fzg_reference, pitch_point_phi1

    case = load_case(CASES / "fzg_spur.toml")
    pitch = round(math.degrees(pitch_point_phi1(build_pair(case))), 3)
    out = {"line_hertz_p0_MPa": fzg_reference(case)[0].p_H_MPa}
    for label, phi in (("pitch point", pitch), ("two pairs", FZG_TWO_PAIRS_DEG)):
        rows = {"phi1_deg": phi, "ccx": [], "fegear": []}
        for h in ladder:
            rows["ccx"].append(ccx_row(CASES / "fzg_spur.toml", work, threads, h, phi))
        for fid, level in (("hybrid", 0), ("fe", 0)):
            r = fegear_row(FEGEAR_GEAR, [str(CASES / "fzg_spur.toml"), str(phi), fid, str(level)])
            r.update(fidelity=fid, level=level)
            rows["fegear"].append(r)
        out[label] = rows
    return out


def markdown(doc: dict) -> str:
    L = ["# CalculiX cross-check", "", f"`{doc['command']}`", "",
         f"CalculiX {doc['ccx_version']} (`{doc['ccx']}`), {doc['threads']} thread(s); fegear "
         "in one process (`FEGEAR_WORKERS=1`). Cold: an empty cache (meshes and compliance "
         "operators built); warm: the same run again. Peak memory: max RSS of the process. The "
         "machine (2 cores) was shared with other work: the load average (1 min) before each "
         "run is in `calculix.json` (`load_before`).",
         ""]  # fmt: skip
    if "hertz_scene" in doc:
        h = doc["hertz_scene"]
        ref = h["hertz"]
        L += ["## Hertz scene (quarter model, 2000 N)", "",
              f"Hertz: p0 {ref['p0_MPa']:.1f} MPa, a {ref['a_mm']:.4f} mm, b "
              f"{ref['b_mm']:.4f} mm. CalculiX: p0 is the largest nodal `CPRESS` (and the "
              "peak recovered from the nodal forces, `fegear.mechanics.patch.measure_patch`), "
              "a and b the "
              "semi-axes of the nodal forces' second moments; fegear `hybrid` (FE of level 0): "
              "the recovered peak and the same second moments on its cells.", "",
              "| solver | contact elements (mm) | elements across 2b | DOFs | p0 err | p0 err "
              "(recovered) | a err | b err | force balance | Newton iterations | time s | "
              "peak MB |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
        for r in h["ccx"]:
            if "result" not in r:
                L.append(f"| CalculiX | {r['element_mm']} | | {r['dofs']} | failed (exit "
                         f"{r['returncode']}) | | | | | | {r['ccx_s']:.0f} | |")  # fmt: skip
                continue
            L.append(
                f"| CalculiX | {r['element_mm']} | {r['elements_across_2b']:.1f} | {r['dofs']} | "
                f"{_pct(r['e_p0'])} | {_pct(r['e_p0_recovered'])} | {_pct(r['e_a'])} | "
                f"{_pct(r['e_b'])} | {r['result']['balance']:.6f} | {r.get('iterations', '')} | "
                f"{r['ccx_s']:.1f} | {r['peak_MB']:.0f} |"
            )
        for r in h["fegear"]:
            L.append(
                f"| fegear hybrid level {r['level']} | | | {r['dofs']} | {_pct(r['e_p0'])} | | "
                f"{_pct(r['e_a'])} | {_pct(r['e_b'])} | | | {r['cold_s']:.1f} cold, "
                f"{r['warm_s']:.1f} warm | {r['peak_MB']:.0f} |"
            )
        L.append("")
    if "fzg" in doc:
        L += ["## FZG type C, 200 N·m on the gear", "",
              "Load share: the pair's torque on the gear axis over T2. p_max: the largest "
              "pressure away from the flank borders (fegear's rule, `fegear.ltca.edges`; — "
              "where none is reported), in brackets the largest overall. Lag θ: the gear's "
              "elastic rotation (µrad); loaded TE = unloaded TE − θ.", ""]  # fmt: skip
        L += [f"ISO 6336-2 line Hertz at the pitch point: p_H {doc['fzg']['line_hertz_p0_MPa']:.0f}"
              " MPa.", ""]  # fmt: skip
        for label, rows in doc["fzg"].items():
            if not isinstance(rows, dict):
                continue
            L += [f"### {label} (φ1 = {rows['phi1_deg']}°)", "",
                  "| solver | contact elements (mm) | DOFs | load shares (k, j): share | "
                  "p_max interior (overall) MPa | semi-minor mm | lag µrad | loaded TE arcsec | "
                  "time s | peak MB |",
                  "|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
            for r in rows["ccx"]:
                if "result" not in r:
                    L.append(f"| CalculiX | {r['element_mm']} | {r['dofs']} | failed (exit "
                             f"{r['returncode']}) | | | | | {r['ccx_s']:.0f} | |")  # fmt: skip
                    continue
                res = r["result"]
                prs = res["pairs"]
                shares = ", ".join(f"({p['k']}, {p['j']}): {p['load_share']:.4f}" for p in prs)
                pm = ", ".join(
                    ("—" if p["p_interior_MPa"] is None else f"{p['p_interior_MPa']:.0f}")
                    + f" ({p['p_max_MPa']:.0f})" for p in prs
                )  # fmt: skip
                b = ", ".join(f"{p['semi_minor_mm']:.3f}" for p in prs)
                L.append(
                    f"| CalculiX | {r['element_mm']} | {r['dofs']} | {shares} | {pm} | {b} | "
                    f"{1e6 * res['theta_rad']:.1f} | {res['te_loaded_arcsec']:.2f} | "
                    f"{r['ccx_s']:.1f} (+{r['export_s']:.0f} export) | {r['peak_MB']:.0f} |"
                )
            for r in rows["fegear"]:
                prs = r["pairs"]
                shares = ", ".join(f"({p['k']}, {p['j']}): {p['share']:.4f}" for p in prs)
                pm = ", ".join(
                    ("—" if p["p_interior"] is None else f"{p['p_interior']:.0f}")
                    + f" ({p['p_max']:.0f})" for p in prs
                )  # fmt: skip
                b = ", ".join(f"{p['b']:.3f}" for p in prs)
                L.append(
                    f"| fegear {r['fidelity']} level {r['level']} | | | {shares} | {pm} | {b} | "
                    f"{1e6 * r['theta']:.1f} | {r['te_loaded']:.2f} | {r['cold_s']:.1f} cold, "
                    f"{r['warm_s']:.1f} warm | {r['peak_MB']:.0f} |"
                )
            L.append("")
    L += summary(doc)
    return "\n".join(L) + "\n"


def _settled(rows: list[dict], keys, tol: float) -> dict | None:
    """The first of ``rows`` (coarse to fine) from which on every row is within ``tol`` in
    every ``keys`` (a coarse row within it by chance, with a finer one outside, does not
    count)."""
    for i, r in enumerate(rows):
        if all(abs(q[k]) <= tol for q in rows[i:] for k in keys):
            return r
    return None


def _shares(pairs: list[dict]) -> dict:
    return {(p["k"], p["j"]): p["load_share"] for p in pairs}


def _dev(ref: dict, shares: dict) -> float:
    """Largest difference of two sets of load shares (a pair missing from one: share 0)."""
    return max(abs(ref.get(k, 0.0) - shares.get(k, 0.0)) for k in set(ref) | set(shares))


def summary(doc: dict) -> list[str]:
    """The comparisons at equal accuracy, computed from the rows."""
    L = ["## At equal accuracy", ""]
    if "hertz_scene" in doc:
        h = doc["hertz_scene"]
        ok = [r for r in h["ccx"] if "result" in r]
        for what, keys, tol in (
            ("p0 within 1 % from this size on", ("e_p0",), 0.01),
            ("p0, a and b within 2 % from this size on", ("e_p0", "e_a", "e_b"), 0.02),
        ):
            cc = _settled(sorted(ok, key=lambda r: -r["element_mm"]), keys, tol)
            ff = _settled(sorted(h["fegear"], key=lambda r: r["level"]), keys, tol)
            if cc and ff:
                L.append(f"- Hertz scene, {what}: CalculiX {cc['element_mm']} mm in "
                         f"{cc['ccx_s']:.0f} s and {cc['peak_MB']:.0f} MB; fegear hybrid level "
                         f"{ff['level']} in {ff['cold_s']:.1f} s cold ({ff['warm_s']:.1f} s "
                         f"warm) and {ff['peak_MB']:.0f} MB: {cc['ccx_s'] / ff['cold_s']:.0f}x "
                         f"the cold time.")  # fmt: skip
            elif ff and ok:
                fin = min(ok, key=lambda r: r["element_mm"])
                errs = ", ".join(f"{k[2:]} {_pct(fin[k])}" for k in keys)
                L.append(f"- Hertz scene, {what}: not reached by CalculiX within its ladder (at "
                         f"{fin['element_mm']} mm, {fin['ccx_s']:.0f} s: {errs}); fegear hybrid "
                         f"level {ff['level']}: {ff['cold_s']:.1f} s cold.")  # fmt: skip
    for label, rows in doc.get("fzg", {}).items():
        if not isinstance(rows, dict):
            continue
        ok = sorted((r for r in rows["ccx"] if "result" in r), key=lambda r: -r["element_mm"])
        if not ok:
            continue
        fin = ok[-1]["result"]
        ref = _shares(fin["pairs"])

        step = [f"{r['element_mm']} mm: {_dev(ref, _shares(r['result']['pairs'])):.4f}"
                for r in ok[:-1]]  # fmt: skip
        L.append(f"- FZG {label}: CalculiX's load shares against its finest size "
                 f"({ok[-1]['element_mm']} mm): " + (", ".join(step) or "one size only")
                 + f"; its lag {1e6 * fin['theta_rad']:.1f} µrad.")  # fmt: skip
        for r in rows["fegear"]:
            sh = {(p["k"], p["j"]): p["share"] for p in r["pairs"]}
            lag = 100 * (r["theta"] / fin["theta_rad"] - 1)
            L.append(f"  fegear {r['fidelity']} level {r['level']}: load shares within "
                     f"{_dev(ref, sh):.4f}, lag {lag:+.1f} %, in "
                     f"{r['cold_s']:.1f} s cold ({r['warm_s']:.1f} s warm), {r['peak_MB']:.0f} "
                     f"MB; CalculiX at {ok[-1]['element_mm']} mm: {ok[-1]['ccx_s']:.0f} s, "
                     f"{ok[-1]['peak_MB']:.0f} MB ({ok[-1]['ccx_s'] / r['cold_s']:.0f}x the "
                     f"cold time).")  # fmt: skip
    return L + [""]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--work", default="ccx_work", help="decks and CalculiX files")
    ap.add_argument("--hertz", help="comma-separated element sizes (mm)")
    ap.add_argument("--fzg", help="comma-separated element sizes (mm)")
    ap.add_argument("--skip-hertz", action="store_true")
    ap.add_argument("--skip-fzg", action="store_true")
    ap.add_argument("--out", default=str(OUT / "calculix"), help="report path without extension")
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite the .md from the .json of the last run (no runs)")  # fmt: skip
    args = ap.parse_args(argv)
    out = Path(args.out)
    if args.report_only:
        text = markdown(json.loads(out.with_suffix(".json").read_text()))
        out.with_suffix(".md").write_text(text)
        print(text)
        return 0
    from fegear.export import CcxMissing, find_ccx

    try:
        exe = find_ccx()
    except CcxMissing as exc:
        print(f"calculix_crosscheck: {exc}", file=sys.stderr)
        return 2
    version = subprocess.run([exe, "-v"], capture_output=True, text=True).stdout.strip()
    work = Path(args.work).resolve()
    work.mkdir(parents=True, exist_ok=True)
    os.environ.setdefault("FEGEAR_CACHE", str(work / "cache"))
    given = list(argv if argv is not None else sys.argv[1:])
    for opt in ("--work", "--out"):  # where the files go is not part of the measurement
        if opt in given:
            i = given.index(opt)
            del given[i : i + 2]
    cmd = " ".join(["python benchmarks/calculix_crosscheck.py", *given])
    doc = {"command": cmd, "ccx": exe, "ccx_version": version.split()[-1] if version else "?",
           "threads": args.threads}  # fmt: skip
    if not args.skip_hertz:
        ladder = [float(x) for x in args.hertz.split(",")] if args.hertz else HERTZ_LADDER
        doc["hertz_scene"] = hertz_rows(work, args.threads, ladder)
    if not args.skip_fzg:
        ladder = [float(x) for x in args.fzg.split(",")] if args.fzg else FZG_LADDER
        doc["fzg"] = fzg_rows(work, args.threads, ladder)
    out.with_suffix(".json").write_text(json.dumps(doc, indent=1))
    text = markdown(doc)
    out.with_suffix(".md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
