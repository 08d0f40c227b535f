"""What ``--root-stress`` costs on the main job: the seed face gear with and without it.

Two jobs, each its own process from an EMPTY artefact cache (a fresh ``FEGEAR_CACHE``):

* ``plain``: ``fegear run cases/face_gear_nominal.toml`` (the main job);
* ``root``: the same with ``--root-stress`` (the stress sectors: the contact sectors remeshed
  with the loaded teeth's fillets refined, one sparse Cholesky factorisation per member,
  :func:`fegear.pipeline.fields.displacements`).

For each: wall time, the child's peak resident memory (``wait4``), the 1-minute load average
before it and ``others_cpu_s`` (the CPU seconds the rest of the machine used meanwhile: ~0 when
idle; the times of a shared machine are not an idle machine's), the root-stress headlines of
its ``summary.json``; and the CPU model (``/proc/cpuinfo``). The runs take the machine's BLAS
and MKL threads as they are (no ``OPENBLAS_NUM_THREADS``).

Usage::

    python benchmarks/bench_root_stress_cost.py [--pause SECONDS]

``--pause`` (default 30 s) waits between the jobs, so that the load of one does not start the
other. Writes ``benchmarks/results/root_stress_cost.json`` and ``.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent
ROOT = HERE.parent
RESULTS = HERE / "results"
NOMINAL = ROOT / "cases" / "face_gear_nominal.toml"
FEGEAR = [sys.executable, "-m", "fegear.cli", "run", str(NOMINAL), "-q"]
JOBS = {"plain": [], "root": ["--root-stress"]}
sys.path.insert(0, str(HERE))
from bench_error_study import _busy_cpu_s, _children_cpu_s, _machine  # noqa: E402


def _one(extra: list[str], work: Path) -> dict:
    """One cold run of the main job (``extra`` flags) in ``work`` on a fresh cache there."""
    cache = work / "cache"
    env = dict(os.environ, FEGEAR_CACHE=str(cache))
    argv = FEGEAR + ["--out", str(work / "out"), *extra]
    load = os.getloadavg()[0]
    busy, mine = _busy_cpu_s(), _children_cpu_s()
    t0 = time.perf_counter()
    with tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen(argv, cwd=work, env=env, stdout=subprocess.DEVNULL, stderr=err,
                                text=True)  # fmt: skip
        # wait4: this job's own peak memory (RUSAGE_CHILDREN's is the largest of all so far)
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.perf_counter() - t0
        err.seek(0)
        tail = err.read().strip().splitlines()[-3:]
    code = os.waitstatus_to_exitcode(status)
    row = {
        "argv": " ".join(
            Path(a).name if a.startswith(str(ROOT)) else a.replace(str(work), "{work}")
            for a in argv[1:]
        ),
        "exit": code,
        "seconds": seconds,
        "peak_rss_MB": usage.ru_maxrss / 1024.0,
        "load_avg_before": load,
        "others_cpu_s": (_busy_cpu_s() - busy) - (_children_cpu_s() - mine),
    }
    if code != 0:
        row["stderr_tail"] = tail
        return row
    doc = json.loads((work / "out" / "summary.json").read_text())
    c = doc["cycle"]
    if c.get("root_stress_max_MPa"):
        row["root_stress_max_MPa"] = {
            m: {k: v for k, v in top.items() if not k.endswith("_at")}
            for m, top in c["root_stress_max_MPa"].items()
        }
        row["root_stress_fillet_mm"] = c.get("root_stress_fillet_mm")
        row["equilibrium_residual"] = c.get("root_stress_max_equilibrium_residual")
    return row


def _markdown(doc: dict) -> str:
    rows = doc["runs"]
    lines = [
        "# `--root-stress` on the main job: cost (`benchmarks/bench_root_stress_cost.py`)",
        "",
        f"Seed face gear, `hybrid` 0, 25 positions, all outputs, each run cold (its own empty "
        f"cache); {doc['machine']}; measured {doc['date']}.",
        "",
        "| job | wall s | peak RSS MB | load avg before | others' CPU s | exit |",
        "|---|---|---|---|---|---|",
    ]
    for name, r in rows.items():
        lines.append(
            f"| {name}: `{r['argv']}` | {r['seconds']:.1f} | {r['peak_rss_MB']:.0f} | "
            f"{r['load_avg_before']:.2f} | {r['others_cpu_s']:.1f} | {r['exit']} |"
        )
    if all(r.get("exit") == 0 for r in rows.values()) and {"plain", "root"} <= set(rows):
        ratio = rows["root"]["seconds"] / rows["plain"]["seconds"]
        lines += ["", f"`--root-stress` / without: {ratio:.2f} × the wall time."]
    top = rows.get("root", {}).get("root_stress_max_MPa")
    if top:
        lines += [
            "",
            "Root stress headlines of the `--root-stress` run (`cycle.root_stress_max_MPa`):",
            "",
            "| member | tension σ1 MPa | compression σ3 MPa | von Mises MPa |",
            "|---|---|---|---|",
        ]
        for m, t in top.items():
            lines.append(
                f"| {m} | {t['tension_max_principal']:.2f} | {t['compression_min_principal']:.2f}"
                f" | {t['von_mises_max']:.2f} |"
            )
    notes = doc.get("notes")
    if notes:
        lines += ["", *notes]
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pause", type=float, default=30.0, help="seconds between the jobs")
    args = ap.parse_args()
    runs: dict[str, dict] = {}
    for k, (name, extra) in enumerate(JOBS.items()):
        if k:
            time.sleep(args.pause)
        work = Path(tempfile.mkdtemp(prefix=f"fegear_rs_{name}_"))
        try:
            runs[name] = _one(extra, work)
        finally:
            shutil.rmtree(work, ignore_errors=True)
        print(json.dumps({name: runs[name]}), flush=True)
    RESULTS.mkdir(exist_ok=True)
    out = RESULTS / "root_stress_cost.json"
    old = json.loads(out.read_text()) if out.is_file() else {}
    doc = {
        "machine": _machine(),
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "runs": runs,
        "notes": old.get("notes", []),
    }
    out.write_text(json.dumps(doc, indent=1) + "\n")
    (RESULTS / "root_stress_cost.md").write_text(_markdown(doc))


if __name__ == "__main__":
    main()
