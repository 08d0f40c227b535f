"""The speed/accuracy trade of the fidelities on the gear scenes (issue 7).

For the seed face gear (`cases/face_gear_nominal.toml`, 3e6 N·mm on the face gear), the
reference spiral bevel (`cases/spiral_bevel_nominal.toml`, 100 N·m on the pinion) and the
reference hypoid (`cases/hypoid_nominal.toml`, 100 N·m on the pinion), each
``FIDELITY:LEVEL`` runs the loaded cycle twice in fresh processes:

* cold: an empty mesh/operator cache (sector meshes, compliance operators, positions);
* warm: the same case again on the cache the cold run left (operators read from disk).

The times exclude the tooth-surface generation (the same for every fidelity; the bevel's machine
settings take ~10-20 s). Peak memory is the child's maximum RSS. The errors are taken against the
finest ``fe`` level run for the scene (the reference): load share of the pair (0, 0) (largest
absolute difference over the positions), loaded TE peak-to-peak (relative), mean loaded TE, and
p_max (relative), both over the whole cycle and over the positions where no pair touches a flank
edge (edge contact makes the pressure singular: a grid-dependent number, not a converging one).

Usage::

    python benchmarks/bench_fidelity.py SCENE [FIDELITY:LEVEL ...]
    python benchmarks/bench_fidelity.py face_gear fe:0 fe:1 fe:2 hertz:0 hybrid:0 hybrid:1
    python benchmarks/bench_fidelity.py spiral_bevel fe:0 fe:1 fe:2 hertz:0 hybrid:0

Writes benchmarks/results/fidelity_SCENE.json / .md (merged with earlier runs of other specs; with
no spec, only the .md is re-made from the .json; benchmarks/results/fidelity_SCENE_notes.md, if
present, is copied under the table);
`python benchmarks/plot_pareto.py` draws docs/fidelity/pareto_*.png from them.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).parent
ROOT = HERE.parent
SCENES = {
    "face_gear": (ROOT / "cases" / "face_gear_nominal.toml", 25),
    "spiral_bevel": (ROOT / "cases" / "spiral_bevel_nominal.toml", 25),
    "hypoid": (ROOT / "cases" / "hypoid_nominal.toml", 25),
}
CHILD = r"""
import json, resource, sys, time
import numpy as np
from fegear.case_files import load_case
from fegear.pipeline.pair import build_pair
from fegear.ltca import LTCAOptions, run_ltca
path, fid, lv, npos = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
case = load_case(path)
t0 = time.perf_counter()
pair = build_pair(case)
t_geom = time.perf_counter() - t0
opt = LTCAOptions(n_positions=npos, level=lv, fidelity=fid, n_teeth=case.n_teeth,
                  E_MPa=case.E_MPa, nu=case.nu)
t0 = time.perf_counter()
c = run_ltca(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, opt)
t = time.perf_counter() - t0
edge = [any(q.edge_contact for q in p.pairs) for p in c.positions]
pm = [max((q.p_max_MPa for q in p.pairs), default=0.0) for p in c.positions]
pk = [max((q.p_peak_MPa for q in p.pairs), default=0.0) for p in c.positions]
share = [sum(q.load_share for q in p.pairs if q.k == 0 and q.j == 0) for p in c.positions]
print(json.dumps({
    "fidelity": fid, "level": lv, "seconds": t, "geometry_s": t_geom, "stages": c.seconds,
    "rss_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    "te_loaded": c.te_loaded_arcsec.tolist(), "te_pp": c.te_pp_loaded_arcsec,
    "te_mean": float(np.mean(c.te_loaded_arcsec)), "contact_ratio": c.contact_ratio_loaded,
    "p_max": pm, "p_peak": pk, "edge": edge, "share00": share,
    "n_in_contact": c.n_in_contact.tolist(), "phi1_deg": np.degrees(c.phi1).tolist(),
    "warnings": sorted({w.split(":")[0] for p in c.positions for w in p.warnings})[:5],
}))
"""


def _busy_cpu_s() -> float:
    """CPU seconds all processes of the machine have used since boot (``/proc/stat``: user, nice,
    system, irq, softirq, steal); NaN where there is no ``/proc/stat``."""
    try:
        with open("/proc/stat") as fh:
            f = [int(x) for x in fh.readline().split()[1:9]]
    except OSError:
        return float("nan")
    return (f[0] + f[1] + f[2] + f[5] + f[6] + f[7]) / os.sysconf("SC_CLK_TCK")


def _children_cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _child(path: Path, fid: str, level: int, npos: int, cache: str) -> dict:
    """One run in a fresh process, with ``others_cpu_s``: the CPU seconds the rest of the machine
    used meanwhile (all processes' CPU over the run minus the child's and its workers'); ~0 on
    an idle machine, the load average before a run says nothing of what starts during it."""
    env = dict(os.environ, FEGEAR_CACHE=cache)
    busy, mine = _busy_cpu_s(), _children_cpu_s()
    res = subprocess.run(
        [sys.executable, "-c", CHILD, str(path), fid, str(level), str(npos)],
        env=env,
        capture_output=True,
        text=True,
    )
    others = (_busy_cpu_s() - busy) - (_children_cpu_s() - mine)
    if res.returncode != 0:
        tail = res.stderr.strip().splitlines()[-1] if res.stderr.strip() else "?"
        return {"fidelity": fid, "level": level, "failed": tail}
    return {**json.loads(res.stdout.strip().splitlines()[-1]), "others_cpu_s": others}


def run(scene: str, fid: str, level: int) -> dict:
    """Cold and warm run of one ``FIDELITY:LEVEL``, with the 1-minute load average of the machine
    before each (the other processes sharing the cores; 2 cores: above ~0.5 the times are not
    those of an idle machine)."""
    path, npos = SCENES[scene]
    with tempfile.TemporaryDirectory() as cache:
        load_cold = os.getloadavg()[0]
        cold = _child(path, fid, level, npos, cache)
        if "failed" in cold:
            return cold
        load_warm = os.getloadavg()[0]
        warm = _child(path, fid, level, npos, cache)
    out = dict(cold)
    out["cold_s"] = cold["seconds"]
    out["warm_s"] = warm.get("seconds", float("nan"))
    out["warm_stages"] = warm.get("stages", {})
    out["load_avg"] = [load_cold, load_warm]
    out["others_cpu_s"] = [cold["others_cpu_s"], warm.get("others_cpu_s", float("nan"))]
    out["rss_MB"] = max(cold["rss_MB"], warm.get("rss_MB", 0.0))
    return out


def _rel(a: float, b: float) -> float:
    return (a - b) / b if b else float("nan")


def errors(runs: list[dict], reference: str = "fe") -> tuple[dict, list[dict]]:
    """Errors of every run against the finest level of the ``reference`` fidelity."""
    fe = [r for r in runs if r.get("fidelity") == reference and "failed" not in r]
    ref = max(fe, key=lambda r: r["level"])
    inner = [not e for e in ref["edge"]]
    out = []
    for r in runs:
        if "failed" in r:
            out.append(r)
            continue
        ok = [a and not b for a, b in zip(inner, r["edge"], strict=True)]
        pm_in = max((p for p, k in zip(r["p_max"], ok, strict=True) if k), default=float("nan"))
        pm_ref = max((p for p, k in zip(ref["p_max"], ok, strict=True) if k), default=float("nan"))
        pk_in = max((p for p, k in zip(r["p_peak"], ok, strict=True) if k), default=float("nan"))
        pk_ref = max((p for p, k in zip(ref["p_peak"], ok, strict=True) if k), default=float("nan"))
        e = dict(r)
        e["err_share"] = max(abs(a - b) for a, b in zip(r["share00"], ref["share00"], strict=True))
        e["err_te_pp"] = _rel(r["te_pp"], ref["te_pp"])
        e["err_te_mean"] = _rel(r["te_mean"], ref["te_mean"])
        e["err_p_max"] = _rel(max(r["p_max"]), max(ref["p_max"]))
        e["p_max_interior"] = pm_in
        e["err_p_max_interior"] = _rel(pm_in, pm_ref)
        e["p_peak_interior"] = pk_in
        e["err_p_peak_interior"] = _rel(pk_in, pk_ref)
        e["n_interior"] = int(sum(ok))
        out.append(e)
    return ref, out


def table(scene: str, runs: list[dict]) -> str:
    """Markdown table of all runs with their errors against the finest ``fe`` and the finest
    ``hybrid`` level (the README's tables are these)."""
    ref_fe, e_fe = errors(runs, "fe")
    have_hybrid = any(r.get("fidelity") == "hybrid" and "failed" not in r for r in runs)
    ref_hy, e_hy = errors(runs, "hybrid") if have_hybrid else (None, [])
    hy = {(r["fidelity"], r["level"]): r for r in e_hy if "failed" not in r}
    what = "TE p-p / share / p_max int. / p_peak int."
    vs_hy = f" vs hybrid L{ref_hy['level']}: {what} |" if ref_hy else ""
    lines = [
        f"# Fidelity trade: {scene.replace('_', ' ')}",
        "",
        f"`python benchmarks/bench_fidelity.py {scene} ...` (2 cores; times exclude the "
        "tooth-surface generation; warm positions = the warm run's time solving the positions "
        "(the rest is reading the cached operators and TCA); load avg = the machine's 1-minute "
        "load average before the cold / warm run (— not recorded; before the warm run it still "
        "holds the cold run's own load); others = the CPU seconds the other processes of the "
        "machine used during the cold / warm run; "
        "p_max int. = over the positions where neither run has an "
        "edge contact; p_peak = the recovered peak of "
        ":func:`fegear.mechanics.patch.measure_patch`, p_max = the largest cell pressure)",
        "",
        "| fidelity | level | cold s | warm s | warm positions s | load avg | peak RSS MB "
        "| TE p-p ″ | mean TE ″ | contact ratio "
        f"| p_max / p_peak int. MPa | vs fe L{ref_fe['level']}: {what} |{vs_hy}",
        "|---|---|---|---|---|---|---|---|---|---|---|---|" + ("---|" if ref_hy else ""),
    ]

    def err(e: dict) -> str:
        return (
            f"{100 * e['err_te_pp']:+.0f} % / {e['err_share']:.3f} / "
            f"{100 * e['err_p_max_interior']:+.0f} % / {100 * e['err_p_peak_interior']:+.0f} %"
        )

    order = {"hertz": 0, "fe": 1, "hybrid": 2}
    for r in sorted(e_fe, key=lambda r: (order.get(r["fidelity"], 9), r["level"])):
        if "failed" in r:
            lines.append(f"| {r['fidelity']} | {r['level']} | failed: {r['failed']} |")
            continue
        key = (r["fidelity"], r["level"])
        a = "reference" if key == ("fe", ref_fe["level"]) else err(r)
        pos = r.get("warm_stages", {}).get("positions")
        load = r.get("load_avg")
        others = r.get("others_cpu_s")
        row = (
            f"| {r['fidelity']} | {r['level']} | {r['cold_s']:.1f} | {r['warm_s']:.1f} | "
            f"{'—' if pos is None else f'{pos:.1f}'} | "
            f"{'—' if load is None else ' / '.join(f'{x:.2f}' for x in load)}"
            f"{'' if others is None else '; others ' + ' / '.join(f'{x:.1f}' for x in others)} | "
            f"{r['rss_MB']:.0f} | {r['te_pp']:.3f} | {r['te_mean']:.3f} | "
            f"{r['contact_ratio']:.2f} | {r['p_max_interior']:.0f} / {r['p_peak_interior']:.0f} | "
            f"{a} |"
        )
        if ref_hy:
            row += " reference |" if key == ("hybrid", ref_hy["level"]) else f" {err(hy[key])} |"
        lines.append(row)
    return "\n".join(lines) + "\n"


def main() -> None:
    if len(sys.argv) < 2 or sys.argv[1] not in SCENES:
        print(__doc__)
        sys.exit(0 if sys.argv[1:2] in (["-h"], ["--help"]) else 2)
    scene = sys.argv[1]
    specs = [(a.split(":")[0], int(a.split(":")[1])) for a in sys.argv[2:]]  # none: table only
    out_json = HERE / "results" / f"fidelity_{scene}.json"
    runs = json.loads(out_json.read_text()) if out_json.exists() else []
    for fid, lv in specs:
        r = run(scene, fid, lv)
        runs = [x for x in runs if (x["fidelity"], x["level"]) != (fid, lv)] + [r]
        msg = r.get("failed") or f"cold {r['cold_s']:.1f} s, warm {r['warm_s']:.1f} s"
        print(f"{scene} {fid}:{lv}: {msg}", flush=True)
        out_json.write_text(json.dumps(runs, indent=1))
    text = table(scene, runs)
    notes = HERE / "results" / f"fidelity_{scene}_notes.md"  # kept under the table
    if notes.exists():
        text += "\n" + notes.read_text()
    (HERE / "results" / f"fidelity_{scene}.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
