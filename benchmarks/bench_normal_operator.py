"""The compliance operator on normal DOFs against the Cartesian one, under mesh refinement.

Runs ``fegear run CASE --level L`` for each level twice: as fegear runs (the operator on the
normal DOFs of the flank and layer nodes, ``docs/ltca/normal_operator.md``) and with the
Cartesian operator (three DOFs per node: ``fegear.ltca.model._normals`` replaced, in a child
process), and tabulates the loaded TE and p_max of every position side by side with the
operator's wall time.

Usage::

    python benchmarks/bench_normal_operator.py [CASE] [--levels 0 1 2]

Default CASE: ``cases/fzg_spur.toml``. Writes ``benchmarks/results/normal_operator_<case>.md``.
Every run uses a fresh cache under a temporary folder (cold operators).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

CHILD = """
import sys
import fegear.ltca.model as model
if sys.argv[1] == "cartesian":
    model._normals = lambda *a, **k: None
from fegear.cli import main
sys.argv = ["fegear"] + sys.argv[2:]
main()
"""


def run(case: Path, level: int, basis: str, work: Path) -> tuple[dict, float]:
    out = work / f"{basis}{level}"
    env = {**os.environ, "FEGEAR_CACHE": str(work / f"cache_{basis}{level}")}
    t0 = time.perf_counter()
    cmd = [sys.executable, "-c", CHILD, basis, "run", str(case), "--level", str(level)]
    subprocess.run(cmd + ["--out", str(out), "-q"], check=True, env=env, cwd=ROOT)
    return json.loads((out / "summary.json").read_text()), time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(ROOT / "cases" / "fzg_spur.toml"))
    ap.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2])
    args = ap.parse_args()
    case = Path(args.case).resolve()
    lines = [
        f"# Normal-DOF against Cartesian compliance operator: {case.stem}",
        "",
        f"`python benchmarks/bench_normal_operator.py {case.relative_to(ROOT)} --levels "
        + " ".join(map(str, args.levels))
        + f"` (each run cold, its own cache; load average before: {os.getloadavg()[0]:.2f})",
        "",
        "| level | pinion tets | operator | TE p-p loaded (arcsec) | p_max interior (MPa) | "
        "loaded TE per position (arcsec) | p_max per position (MPa) | run s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for level in args.levels:
            for basis in ("normal", "cartesian"):
                doc, seconds = run(case, level, basis, Path(tmp))
                te = [p["te_loaded_arcsec"] for p in doc["positions"]]
                pm = [max((q["p_max_MPa"] or 0.0) for q in p["pairs"]) for p in doc["positions"]]
                cyc = doc["cycle"]
                lines.append(
                    f"| {level} | {doc['mesh']['pinion']['tets']} | {basis} | "
                    f"{cyc['te_pp_loaded_arcsec']:.3f} | {cyc['p_max_MPa']:.1f} | "
                    + ", ".join(f"{x:.2f}" for x in te)
                    + " | "
                    + ", ".join(f"{x:.0f}" for x in pm)
                    + f" | {seconds:.1f} |"
                )
                print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n"
    path = HERE / "results" / f"normal_operator_{case.stem}.md"
    path.write_text(text, encoding="utf-8")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
