"""Speed/accuracy of the FE contact engine on the Hertz scene, level by level.

For each fidelity and level: cold time (empty mesh/operator cache), warm time (cached meshes
and compliance operators: reading the meshes, the load operators, the contact solve), peak
memory (max RSS of the child process), DOFs, and the p0 / a / b / approach errors against Hertz.
Each configuration runs in its own process so that the peak memory is its own.

Usage::

    python benchmarks/bench_hertz_scene.py [fe:L | hybrid:L:FE_L ...]   # default: all below

Writes a Markdown table to stdout and to benchmarks/results/hertz_scene.md (rows also in
hertz_scene.json, for `benchmarks/plot_pareto.py`).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import json, resource, sys, time
from fegear.scenes.hertz_scene import HertzScene, run_level
fid, lv, fel = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
t0 = time.perf_counter()
r = run_level(HertzScene(), lv, fidelity=fid, fe_level=fel)
dt = time.perf_counter() - t0
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
print(json.dumps({"level": lv, "fidelity": fid, "fe_level": fel, "t": dt, "rss_MB": rss,
  "n": r.cells_across_minor,
  "cell": r.cell_size_mm, "h": r.h_fine_mm, "dofs": sum(r.dofs.values()),
  "cells": r.n_cells, "active": r.n_active, "p0": r.p0_MPa, "pcell": r.p_max_cell_MPa,
  "e_p0": r.error("p0"), "e_pcell": (r.p_max_cell_MPa - r.hertz.p0_MPa) / r.hertz.p0_MPa,
  "e_a": r.error("a"), "e_b": r.error("b"), "e_app": r.error("approach"),
  "seconds": r.seconds, "hit": r.cache_hit, "backend": r.backend}))
"""


def run(spec: tuple[str, int, int], cache: str) -> dict:
    env = dict(os.environ, FEGEAR_CACHE=cache)
    args = [str(x) for x in spec]
    out = subprocess.run(
        [sys.executable, "-c", CHILD, *args], env=env, check=True, capture_output=True, text=True
    ).stdout
    return json.loads(out.strip().splitlines()[-1])


DEFAULT = (
    [("fe", lv, lv) for lv in range(6)]
    + [("hybrid", lv, 0) for lv in (1, 2, 3, 4, 5)]
    + [("hybrid", 4, 1), ("hybrid", 4, 2)]
)


def parse(arg: str) -> tuple[str, int, int]:
    """``fe:3`` or ``hybrid:4:0`` (fidelity, grid level, FE level)."""
    parts = arg.split(":")
    lv = int(parts[1])
    return (parts[0], lv, int(parts[2]) if len(parts) > 2 else lv)


def main() -> None:
    specs = [parse(a) for a in sys.argv[1:]] or DEFAULT
    rows = []
    for spec in specs:
        # Each configuration starts from an empty cache: cold = meshes + operators built.
        with tempfile.TemporaryDirectory() as cache:
            cold = run(spec, cache)
            warm = run(spec, cache)
        rows.append((cold, warm))
        print(f"{spec}: cold {cold['t']:.1f} s, warm {warm['t']:.1f} s", file=sys.stderr)
    head = (
        "| fidelity | level | cells across 2b | cell mm | element mm | DOFs (both bodies) | "
        "cold s | warm s | peak RSS MB | p0 err (recovered) | p0 err (max cell) | a err | b err | "
        "approach err |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    )
    lines = [head]
    for c, w in rows:
        fid = c["fidelity"] if c["fidelity"] == "fe" else f"hybrid (FE of level {c['fe_level']})"
        lines.append(
            f"| {fid} | {c['level']} | {c['n']} | {c['cell']:.4f} | {c['h']:.4f} | {c['dofs']} | "
            f"{c['t']:.1f} | {w['t']:.1f} | {c['rss_MB']:.0f} | {c['e_p0']:+.2%} | "
            f"{c['e_pcell']:+.2%} | {c['e_a']:+.2%} | {c['e_b']:+.2%} | {c['e_app']:+.2%} |"
        )
    text = "\n".join(lines)
    print(text)
    out = Path(__file__).parent / "results" / "hertz_scene.md"
    out.parent.mkdir(exist_ok=True)
    rows_json = [dict(c, t_warm=w["t"], rss_MB=max(c["rss_MB"], w["rss_MB"])) for c, w in rows]
    out.with_suffix(".json").write_text(json.dumps(rows_json, indent=1), encoding="utf-8")
    out.write_text(
        "# Hertz scene benchmark\n\n`python benchmarks/bench_hertz_scene.py`\n\n" + text + "\n",
        encoding="utf-8",
    )


if __name__ == "__main__":
    main()
