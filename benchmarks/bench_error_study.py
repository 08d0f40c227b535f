"""What an installation-error study costs against one cold run (issue 29).

Each job runs as its own process from an EMPTY artefact cache (a fresh ``FEGEAR_CACHE``), then,
where marked, once more on the cache it left (warm):

* ``run``: ``fegear run cases/face_gear_nominal.toml`` (the main job's case): the unit the
  study costs are measured against; then on its cache the same run again (warm: its positions
  read back), with ``--recompute`` (the positions solved again) and with a new installation
  error (``dgamma_deg = 0.01``);
* ``sweep``: ``fegear sweep cases/face_gear_nominal.toml --grid
  errors.dgamma_deg=-0.02:0.02:5`` (five shaft-angle errors; by default the first item alone,
  the others' checks prepared beside it, then one item per core side by side,
  :mod:`fegear.sweep.local`): its wall time, and the cache size after each item (the growth per
  variant after the first);
* ``sweep1``: the same sweep with ``--workers 1`` (the items one after the other, each on
  every core);
* ``dE``, ``dA1``, ``dA2``, ``dgamma``: ``python cases/face_gear_<error>.py`` (three values each
  through the Python API, ``hybrid`` level 0);
* ``level1``: the main job's case at mesh level 1 (``--level 1``), cold and warm.

For each: wall time, the child's peak memory, the cache size at the end, the 1-minute load
average before it and ``others_cpu_s``, the CPU seconds the rest of the machine used meanwhile
(~0 when idle: the times of a shared machine are not an idle machine's).

Usage::

    python benchmarks/bench_error_study.py [JOB ...]     # default: every job

Writes ``benchmarks/results/error_study.json`` (merged with earlier runs of other jobs) and
``benchmarks/results/error_study.md``.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

HERE = Path(__file__).parent
ROOT = HERE.parent
RESULTS = HERE / "results"
NOMINAL = ROOT / "cases" / "face_gear_nominal.toml"
FEGEAR = [sys.executable, "-m", "fegear.cli"]
SWEEP = FEGEAR + ["sweep", str(NOMINAL), "--grid", "errors.dgamma_deg=-0.02:0.02:5",
                  "--out", "{work}/sweep", "-q"]  # fmt: skip
JOBS = {
    "run": (FEGEAR + ["run", str(NOMINAL), "-q", "--out", "{work}/out"], True),
    "sweep": (SWEEP, False),
    "sweep1": (SWEEP + ["--workers", "1"], False),
    **{
        e: ([sys.executable, str(ROOT / "cases" / f"face_gear_{e}.py")], True)
        for e in ("dE", "dA1", "dA2", "dgamma")
    },
    "level1": (FEGEAR + ["run", str(NOMINAL), "--level", "1", "-q", "--out", "{work}/out"], True),
}


def _machine() -> str:
    """The CPU the figures were measured on (they scale with it; the ratios much less)."""
    try:
        with open("/proc/cpuinfo") as fh:
            names = [ln.split(":", 1)[1].strip() for ln in fh if ln.startswith("model name")]
    except OSError:
        names = []
    return f"{os.cpu_count()} × {names[0] if names else 'unknown CPU'}"


def _busy_cpu_s() -> float:
    """CPU seconds all processes of the machine have used since boot (``/proc/stat``)."""
    try:
        with open("/proc/stat") as fh:
            f = [int(x) for x in fh.readline().split()[1:9]]
    except OSError:
        return float("nan")
    return (f[0] + f[1] + f[2] + f[5] + f[6] + f[7]) / os.sysconf("SC_CLK_TCK")


def _children_cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _bytes(folder: Path) -> int:
    """Bytes of the regular files under ``folder`` (files removed meanwhile are skipped)."""
    total = 0
    for p in folder.rglob("*"):
        try:
            if p.is_file():
                total += p.stat().st_size
        except OSError:
            pass
    return total


def _items_done(sweep: Path) -> int:
    return len(list(sweep.glob("*/sweep_item.json"))) if sweep.is_dir() else 0


def _one(argv: list[str], work: Path, cache: Path, watch_sweep: bool) -> dict:
    """Run ``argv`` (``{work}`` substituted) in ``work`` on the cache ``cache``."""
    env = dict(os.environ, FEGEAR_CACHE=str(cache))
    argv = [a.replace("{work}", str(work)) for a in argv]
    load = os.getloadavg()[0]
    busy, mine = _busy_cpu_s(), _children_cpu_s()
    growth: list[dict] = []
    t0 = time.perf_counter()
    logs = tempfile.TemporaryFile("w+"), tempfile.TemporaryFile("w+")
    proc = subprocess.Popen(argv, cwd=work, env=env, stdout=logs[0], stderr=logs[1], text=True)
    stop = threading.Event()

    def watch() -> None:  # the cache size as each sweep item finishes
        seen = 0
        while not stop.wait(0.5):
            n = _items_done(work / "sweep")
            if n > seen:
                seen = n
                growth.append({"items": n, "cache_bytes": _bytes(cache),
                               "t_s": time.perf_counter() - t0})  # fmt: skip

    th = threading.Thread(target=watch, daemon=True)
    if watch_sweep:
        th.start()
    # wait4: this job's own peak memory (RUSAGE_CHILDREN's is the largest of all jobs so far)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    seconds = time.perf_counter() - t0
    for fh in logs:
        fh.seek(0)
    out, err = (fh.read() for fh in logs)
    stop.set()
    if watch_sweep:
        th.join()
    others = (_busy_cpu_s() - busy) - (_children_cpu_s() - mine)
    rss = usage.ru_maxrss / 1024.0
    row = {
        "argv": " ".join(Path(a).name if a.startswith(str(ROOT)) else a for a in argv),
        "exit": proc.returncode,
        "seconds": seconds,
        "cache_bytes": _bytes(cache),
        "load_avg": load,
        "others_cpu_s": others,
        "peak_rss_MB": rss,
    }
    if growth:
        row["cache_by_item"] = growth
    if proc.returncode != 0:
        row["stderr_tail"] = err.strip().splitlines()[-3:]
    return row


def run_job(name: str) -> dict:
    argv, warm = JOBS[name]
    with tempfile.TemporaryDirectory(prefix="fegear_study_") as tmp:
        work, cache = Path(tmp) / "work", Path(tmp) / "cache"
        work.mkdir()
        cold = _one(argv, work, cache, name.startswith("sweep"))
        out = {"job": name, "cold": cold}
        if warm and cold["exit"] == 0:
            out["warm"] = _one(argv, work, cache, False)
        if name == "run" and cold["exit"] == 0:
            # the warm run solving its positions again, and a new installation error
            out["recompute"] = _one(argv + ["--recompute"], work, cache, False)
            text = NOMINAL.read_text().replace("dgamma_deg = 0.0", "dgamma_deg = 0.01")
            (work / "new_error.toml").write_text(text)
            new = [a if a != str(NOMINAL) else str(work / "new_error.toml") for a in argv]
            out["new_error"] = _one(new, work, cache, False)
    return out


def _fmt_s(x: float | None) -> str:
    return "" if x is None else f"{x:.1f}"


def table(rows: dict[str, dict]) -> str:
    ref = rows.get("run", {}).get("cold", {}).get("seconds")
    lines = [
        "| job | cold s | × cold `fegear run` | warm s | cache after MB | growth per variant MB "
        "| load before | others' CPU s | peak RSS MB |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name in JOBS:
        if name not in rows:
            continue
        r = rows[name]
        c, w = r["cold"], r.get("warm", {})
        ratio = f"{c['seconds'] / ref:.2f}" if ref and name != "run" else ("1" if ref else "")
        growth = ""
        by = c.get("cache_by_item") or []
        if len(by) >= 2:
            per = (by[-1]["cache_bytes"] - by[0]["cache_bytes"]) / (
                by[-1]["items"] - by[0]["items"]
            )
            growth = f"{per / 1e6:.1f}"
        failed = "" if c["exit"] == 0 else f" (exit {c['exit']})"
        lines.append(
            f"| `{name}` | {_fmt_s(c['seconds'])}{failed} "
            f"| {ratio} | {_fmt_s(w.get('seconds'))} | {c['cache_bytes'] / 1e6:.0f} | {growth} "
            f"| {c['load_avg']:.2f}{' / ' + format(w['load_avg'], '.2f') if w else ''} "
            f"| {c['others_cpu_s']:.1f}{' / ' + format(w['others_cpu_s'], '.1f') if w else ''} "
            f"| {max(c['peak_rss_MB'], w.get('peak_rss_MB', 0)):.0f} |"
        )  # fmt: skip
    return "\n".join(lines)


def main() -> None:
    names = sys.argv[1:] or list(JOBS)
    bad = [n for n in names if n not in JOBS]
    if bad or "-h" in names or "--help" in names:
        print(__doc__)
        sys.exit(0 if not bad else 2)
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / "error_study.json"
    rows = json.loads(path.read_text()) if path.exists() else {}
    for name in names:
        print(f"{name} ...", file=sys.stderr, flush=True)
        rows[name] = run_job(name)
        rows[name]["when"] = time.strftime("%Y-%m-%d %H:%M")
        path.write_text(json.dumps(rows, indent=1) + "\n")
        print(json.dumps(rows[name])[:400], file=sys.stderr, flush=True)
    text = (
        "# Installation-error studies against one cold run\n\n"
        "`python benchmarks/bench_error_study.py` (2 cores; every job from an empty cache, then "
        "warm on the cache it left; seed face gear, `hybrid` level 0, 25 positions; "
        f"{_machine()}):\n\n"
        + table(rows)
        + "\n\n`sweep`: `fegear sweep cases/face_gear_nominal.toml --grid "
        "errors.dgamma_deg=-0.02:0.02:5` (the default: the first item alone, the others' checks "
        "prepared beside it, then two side by side in processes forked from the first's; "
        "`sweep1`: `--workers 1`, the items one after the other); growth per "
        "variant: the cache size after the last item minus after the first, over the items "
        "between. `dE` … `dgamma`: `python cases/face_gear_<error>.py` (three values each); "
        "`level1`: the main job at `--level 1`. "
        "Load before: the 1-minute load average before the cold / warm run; others' CPU: the CPU "
        "seconds the rest of the machine used during it (~0 on an idle machine).\n"
    )
    run = rows.get("run", {})
    if "recompute" in run:
        text += (
            "\n## The main job warm\n\n"
            "| `fegear run` on the cache of the cold run | s | load before | others' CPU s |\n"
            "|---|---|---|---|\n"
        )
        for key, what in (
            ("warm", "the same run again (its positions and fields read back)"),
            ("recompute", "the same run, `--recompute` (the positions solved again)"),
            ("new_error", "a new installation error (Δγ = 0.01°: TCA, positions, fields)"),
        ):
            r = run[key]
            text += (
                f"| {what} | {r['seconds']:.1f} | {r['load_avg']:.2f} | {r['others_cpu_s']:.1f} |\n"
            )
    (RESULTS / "error_study.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
