"""The main job's cold start: ``fegear run cases/face_gear_nominal.toml -q`` in a fresh process
with an empty ``FEGEAR_CACHE``, timed from outside: wall seconds, the CPU seconds of the run and
of every process it forked (``getrusage(RUSAGE_CHILDREN)``), the phases of its
``summary.json`` (``timings_s``) and the load averages before and after.

Run: ``python benchmarks/bench_cold_start.py [REPEATS] [TREE ...]``: each repeat runs every
code tree in turn (alternating, so that a change in the machine's load falls on both); a TREE is
a folder holding a ``fegear`` package put first on ``PYTHONPATH`` (e.g. ``git archive main
fegear | tar -x -C /tmp/main``), ``.`` the installed one. Prints one JSON line per run, and
writes them to ``benchmarks/results/cold_start.json``. The processes' thread settings are the
caller's (unset: MKL 2 threads, OpenBLAS one per core).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "face_gear_nominal.toml"


def run(tree: str) -> dict[str, object]:
    """One cold run of the main job with the ``fegear`` of ``tree``."""
    tmp = Path(tempfile.mkdtemp(prefix="fegear_cold_"))
    env = dict(os.environ, FEGEAR_CACHE=str(tmp / "cache"))
    if tree != ".":
        env["PYTHONPATH"] = str(Path(tree).resolve())
    cmd = [sys.executable, "-m", "fegear.cli", "run", str(CASE), "-q", "--out", str(tmp / "out")]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    load0 = os.getloadavg()
    t = time.perf_counter()
    # cwd outside the repository: its fegear folder would come first on sys.path otherwise
    done = subprocess.run(cmd, env=env, cwd=tmp, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"{tree}: exit {done.returncode}\n{done.stderr[-2000:]}")
    summary = json.loads((tmp / "out" / "summary.json").read_text(encoding="utf-8"))
    return {
        "tree": tree,
        "wall_s": round(wall, 2),
        "user_s": round(after.ru_utime - before.ru_utime, 2),
        "sys_s": round(after.ru_stime - before.ru_stime, 2),
        "load_before": [round(x, 2) for x in load0],
        "load_after": [round(x, 2) for x in os.getloadavg()],
        "timings_s": {k: round(v, 2) for k, v in summary["timings_s"].items()},
        "summary": str(tmp / "out" / "summary.json"),
    }


def main() -> None:
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 2
    trees = sys.argv[2:] or ["."]
    rows = []
    for _ in range(repeats):
        for tree in trees:
            rows.append(run(tree))
            print(json.dumps(rows[-1]), flush=True)
    out = ROOT / "benchmarks" / "results" / "cold_start.json"
    out.write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
