"""CalculiX (full FE contact) against fegear: Hertz scene, FZG, face gear, spiral bevel.

For each problem, CalculiX is refined along a ladder of contact element sizes (its own
convergence shown) and set beside fegear ``hybrid`` (and ``fe``) with the same quantities:
load shares, p_max (interior), patch semi-axes, TE / approach, wall time and peak memory, and the
machine's 1-minute load average before each run.

- **Hertz scene** (``cases/hertz_scene.toml``, quarter model): p0, a, b against closed-form Hertz;
  fegear ``hybrid`` levels 0-3 (FE of level 0).
- **FZG** (``cases/fzg_spur.toml``, 200 N·m) at the pitch point (single pair) and at a two-pair
  position; **seed face gear** (``cases/face_gear_nominal.toml``) at two positions of its cycle
  (:data:`FACE_GEAR_POSITIONS`); **spiral bevel** (``cases/spiral_bevel_nominal.toml``) at one
  (:data:`SPIRAL_BEVEL_POSITIONS`): load shares, interior p_max, patch semi-axes, the lag and the
  loaded TE; fegear ``hybrid`` level 0 and ``fe`` level 0.

Every measurement runs in its own process, so the peak memory (max RSS) is its own; CalculiX with
``OMP_NUM_THREADS = --threads``, one run at a time. fegear rows: cold (an empty cache: meshes
and compliance operators built) and warm (the same run again); a case's later positions warm only,
on the cache of its first.

Usage::

    python benchmarks/calculix_crosscheck.py [--threads 2] [--work DIR]
        [--hertz 0.45,0.32,...] [--fzg 0.7,...] [--face-gear 2,1.4,1/2,1.4] [--spiral-bevel 1,...]
        [--skip-hertz] [--skip-fzg] [--skip-face-gear] [--skip-spiral-bevel] [--report-only]

Finds ``ccx`` (``$FEGEAR_CCX`` or the ``PATH``; says so and stops when it is missing). Writes
``benchmarks/results/calculix.md`` and ``calculix.json`` (the page from
:func:`fegear.validation.calculix_rows.markdown`; ``docs/make_validation.py`` puts the rows in
``docs/validation.md``). A skipped section keeps its rows (and the command that measured them)
from the last ``calculix.json``. The decks, CalculiX's files and one ``<job>.row.json`` per
finished run stay in ``--work`` (a run with a row there is not repeated: delete the row to
measure it again; likewise the fegear rows in ``--work/fegear_rows``). A gear option's sizes
may differ per position: ``2,1.4,1/2,1.4`` is the first position's ladder, then the others'.
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
#: Seed face gear: positions of its 25-position cycle (labels) picked from fegear's own loaded
#: analysis (``hybrid`` level 0, ``fegear run cases/face_gear_nominal.toml``): position 16 (φ1 =
#: 2.016°) has two pairs with interior patches sharing 0.53 / 0.47; no position of the cycle has a
#: single pair loaded, position 6 (φ1 = −3.744°) is the nearest (one pair carries 0.96, its
#: neighbour 0.04 on the pinion's tip edge).
FACE_GEAR_POSITIONS = (("two pairs", 16), ("one pair carrying 0.96", 6))
FACE_GEAR_LADDER = (1.0, 0.7)
#: Spiral bevel: one position of its 13-position cycle, from its `hybrid` level-0 analysis:
#: position 3 (φ1 = −8.077°), two pairs with interior patches sharing 0.44 / 0.56.
SPIRAL_BEVEL_POSITIONS = (("two pairs", 3),)
SPIRAL_BEVEL_LADDER = (1.0, 0.7)


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


def fegear_rows(code: str, arg_lists: list[list[str]], keep: Path | None = None) -> list[dict]:
    """fegear measurements on one fresh cache: the first cold (meshes and operators built) then
    warm, each later one warm only (the operators do not depend on the position). With ``keep``,
    each finished row is kept in ``keep/<hash>.json`` and not measured again."""
    import hashlib

    rows: list[dict | None] = []
    for args in arg_lists:
        tag = hashlib.sha1(json.dumps([code, args]).encode()).hexdigest()[:16]
        f = None if keep is None else keep / f"{tag}.json"
        rows.append(json.loads(f.read_text()) if f is not None and f.is_file() else None)
    if all(r is not None for r in rows):
        return rows
    with tempfile.TemporaryDirectory(prefix="fegear_ccx_bench_") as cache:
        env = {**os.environ, "FEGEAR_CACHE": cache, "FEGEAR_WORKERS": "1"}
        for i, args in enumerate(arg_lists):
            cmd = [sys.executable, "-c", code, *args]
            load = os.getloadavg()[0]
            cold = mem = None
            if i == 0:
                _, cold, mem = measured(cmd, env)
            load_w = os.getloadavg()[0]
            out, warm, mem_w = measured(cmd, env)
            row = json.loads(out.strip().splitlines()[-1])
            row.update(cold_s=cold, warm_s=warm, peak_MB=mem if mem is not None else mem_w,
                       peak_warm_MB=mem_w, load_before=load if i == 0 else load_w)  # fmt: skip
            rows[i] = row
            if keep is not None:
                keep.mkdir(parents=True, exist_ok=True)
                tag = hashlib.sha1(json.dumps([code, args]).encode()).hexdigest()[:16]
                (keep / f"{tag}.json").write_text(json.dumps(row, indent=1))
    return rows


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


# ------------------------------------------------------------------------------ the sections
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
        (r,) = fegear_rows(FEGEAR_HERTZ, [[str(level)]])
        r["level"] = level
        out["fegear"].append(r)
    return out


def gear_positions(key: str) -> tuple[Path, list[tuple[str, float, int | None]]]:
    """The case of gear section ``key`` and its positions ``(label, φ1 deg, cycle index)``."""
    from fegear.api import load_case
    from fegear.export import position_angle

    if key == "fzg":
        from fegear.pipeline.pair import build_pair
        from fegear.validation.rows import pitch_point_phi1

        path = CASES / "fzg_spur.toml"
        pitch = round(math.degrees(pitch_point_phi1(build_pair(load_case(path)))), 3)
        return path, [("pitch point", pitch, None), ("two pairs", FZG_TWO_PAIRS_DEG, None)]
    path, picks = {"face_gear": (CASES / "face_gear_nominal.toml", FACE_GEAR_POSITIONS),
                   "spiral_bevel": (CASES / "spiral_bevel_nominal.toml",
                                    SPIRAL_BEVEL_POSITIONS)}[key]  # fmt: skip
    case = load_case(path)
    return path, [(label, round(math.degrees(position_angle(case, i)), 3), i) for label, i in picks]


def gear_rows(key: str, work: Path, threads: int, ladders: list[list[float]]) -> dict:
    """A gear section: per position, CalculiX along its ladder (``ladders``: one per position,
    the last one repeated for the positions after it), then fegear ``hybrid`` and ``fe`` level
    0 (each cold at the first position, warm at every one)."""
    path, where = gear_positions(key)
    out: dict = {}
    if key == "fzg":
        from fegear.api import load_case
        from fegear.validation.rows import fzg_reference

        out["line_hertz_p0_MPa"] = fzg_reference(load_case(path))[0].p_H_MPa
    for i, (label, phi, index) in enumerate(where):
        rows = {"phi1_deg": phi, "position": index, "ccx": [], "fegear": []}
        for h in ladders[min(i, len(ladders) - 1)]:
            r = ccx_row(path, work, threads, h, phi)
            rows["ccx"].append(r)
            res = r.get("result", {})
            print(f"  {key} {label} ccx {h} mm: {r['ccx_s']:.0f} s, {r['peak_MB']} MB, "
                  f"lag {res.get('theta_rad')}", file=sys.stderr, flush=True)  # fmt: skip
        out[label] = rows
    for fid, level in (("hybrid", 0), ("fe", 0)):
        args = [[str(path), str(phi), fid, str(level)] for _, phi, _ in where]
        for (label, _, _), r in zip(where, fegear_rows(FEGEAR_GEAR, args, work / "fegear_rows"),
                                    strict=True):  # fmt: skip
            r.update(fidelity=fid, level=level)
            if r.get("cold_s") is None:
                r["cold_at"] = where[0][0]
            out[label]["fegear"].append(r)
    return out


#: Sections of ``calculix.json``: key -> (option, default ladder).
SECTIONS = {"hertz_scene": ("hertz", HERTZ_LADDER), "fzg": ("fzg", FZG_LADDER),
            "face_gear": ("face-gear", FACE_GEAR_LADDER),
            "spiral_bevel": ("spiral-bevel", SPIRAL_BEVEL_LADDER)}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    from fegear.validation.calculix_rows import markdown

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--work", default="ccx_work", help="decks and CalculiX files")
    for opt, ladder in SECTIONS.values():
        sizes = ",".join(map(str, ladder))
        ap.add_argument(f"--{opt}", help=f"contact element sizes (mm), default {sizes}; gears: "
                        "'/' between the ladders of the positions")  # fmt: skip
        ap.add_argument(f"--skip-{opt}", action="store_true",
                        help="do not run it (its rows are kept from --out's .json)")  # fmt: skip
    ap.add_argument("--out", default=str(OUT / "calculix"), help="report path without extension")
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite the .md from the .json of the last run (no runs)")  # fmt: skip
    args = ap.parse_args(argv)
    out = Path(args.out)
    old = (
        json.loads(out.with_suffix(".json").read_text())
        if out.with_suffix(".json").is_file()
        else {}
    )
    if args.report_only:
        text = markdown(old)
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
    for key, (opt, default) in SECTIONS.items():
        attr = opt.replace("-", "_")
        if getattr(args, f"skip_{attr}"):
            if key in old:  # kept from the last run, with the command that measured it
                doc[key] = old[key]
                doc[key].setdefault("command", old.get("command"))
            continue
        sizes = getattr(args, attr)
        ladders = ([[float(x) for x in part.split(",") if x.strip()] for part in sizes.split("/")]
                   if sizes else [list(default)])  # fmt: skip
        sec = hertz_rows(work, args.threads, ladders[0]) if key == "hertz_scene" else gear_rows(
            key, work, args.threads, ladders)  # fmt: skip
        sec["command"] = cmd
        doc[key] = sec
        out.with_suffix(".json").write_text(json.dumps(doc, indent=1))  # kept if a later fails
    out.with_suffix(".json").write_text(json.dumps(doc, indent=1))
    text = markdown(doc)
    out.with_suffix(".md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
