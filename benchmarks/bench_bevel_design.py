"""``SpiralBevelPair.design()`` (the machine-settings synthesis) old against new.

Times ``design()`` of the 12/36 reference spiral bevel (``cases/spiral_bevel_nominal.toml``) and
the 10/41 hypoid (``cases/hypoid_nominal.toml``), each in a fresh Python process (nothing
memoized; ``design()`` reads no cache), for three codes:

- ``old``: the commit given (default ``5495f2b``, before the native rigid contact), checked out
  in a temporary ``git worktree`` and put first on ``PYTHONPATH``;
- ``new``: this checkout, ``design(native_tune=False)`` (the third-order roll tuned on the
  engine's contact, as the old code: the same settings bit for bit);
- ``new native_tune``: this checkout, ``design()`` as the pipeline calls it
  (``native_tune=True``: the roll tuned on the native rigid contact; its D differs by ~1e-10
  relative).

Each run's settings are compared with the old run's (largest relative difference of any
number of the pair's ``record()``, and of the two third-order rolls D). Best of ``--repeat``
runs (default 2) per code and family; the 1-minute load average before each run is recorded
(the machine may be shared).

Usage::

    python benchmarks/bench_bevel_design.py [--old-commit 5495f2b] [--repeat 2]

Writes ``benchmarks/results/bevel_design.json`` and ``benchmarks/results/bevel_design.md``.
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

HERE = Path(__file__).parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from bench_error_study import _machine  # noqa: E402

RESULTS = HERE / "results"
FAMILIES = ("spiral_bevel", "hypoid")

#: run in the child: design() of one case file, timed; the pair's record as JSON on stdout
CHILD = r"""
import json, sys, time, tomllib
from fegear.pipeline.pair import SpiralBevelFamily, HypoidFamily
from fegear.geometry.bevel.pair import SpiralBevelPair
from fegear.geometry.bevel.synthesis import SynthesisTargets
fam, case, native = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
p = tomllib.load(open(case, "rb"))["pair"]
family = {"spiral_bevel": SpiralBevelFamily, "hypoid": HypoidFamily}[fam]()
blank = family.blank_type(**family.blank_kw(p))
targets = SynthesisTargets(te_amplitude_arcsec=float(p["te_amplitude_arcsec"]))
import inspect
# the old code has no choice (engine tune); the new one is asked for each explicitly
has = "native_tune" in inspect.signature(SpiralBevelPair.design).parameters
kw = {"native_tune": native} if has else {}
t = time.perf_counter()
pair = SpiralBevelPair.design(blank, targets, **kw)
dt = time.perf_counter() - t
import fegear
print(json.dumps({"seconds": dt, "fegear": fegear.__file__, "record": pair.record()}))
"""


def _load() -> float:
    return os.getloadavg()[0]


def _one(code_root: Path, family: str, native: bool) -> dict:
    env = dict(os.environ, PYTHONPATH=str(code_root), OPENBLAS_NUM_THREADS="1")
    case = ROOT / "cases" / f"{family}_nominal.toml"
    load = _load()
    out = subprocess.run(
        [sys.executable, "-c", CHILD, family, str(case), "1" if native else "0"],
        env=env,
        cwd=code_root,
        capture_output=True,
        text=True,
        check=True,
    )  # fmt: skip  (cwd: ``-c`` puts the working folder first on sys.path)
    res = json.loads(out.stdout.strip().splitlines()[-1])
    res["load_avg"] = load
    return res


def _leaves(x, path=""):
    if isinstance(x, dict):
        for k, v in x.items():
            yield from _leaves(v, f"{path}.{k}")
    elif isinstance(x, list):
        for i, v in enumerate(x):
            yield from _leaves(v, f"{path}[{i}]")
    elif isinstance(x, (int, float)) and not isinstance(x, bool):
        yield path, float(x)


def _agreement(new: dict, old: dict) -> dict:
    """Largest relative difference of any number of the records, and of each D."""
    a, b = dict(_leaves(new)), dict(_leaves(old))
    rel = {k: abs(a[k] - b[k]) / max(abs(b[k]), 1e-300) for k in b}
    worst = max(rel, key=rel.get)
    d = {side: rel[f".settings.pinion_{side}.modified_roll_third"] for side in ("drive", "coast")}
    return {"max_rel": rel[worst], "where": worst, "D_rel": d}


def run(old_root: Path, repeat: int) -> dict:
    codes = {"old": (old_root, False), "new": (ROOT, False), "new native_tune": (ROOT, True)}
    rows: dict = {}
    for family in FAMILIES:
        runs: dict[str, list[dict]] = {c: [] for c in codes}
        for _ in range(repeat):  # interleaved: the codes see the same machine load
            for code, (root, native) in codes.items():
                print(f"{family} {code} ...", file=sys.stderr, flush=True)
                runs[code].append(_one(root, family, native))
        ref = runs["old"][0]["record"]
        rows[family] = {}
        for code, rs in runs.items():
            best = min(rs, key=lambda r: r["seconds"])
            rows[family][code] = {
                "seconds": [r["seconds"] for r in rs],
                "best_s": best["seconds"],
                "load_avg": [r["load_avg"] for r in rs],
                "fegear": best["fegear"],
                "D": {
                    s: best["record"]["settings"][f"pinion_{s}"]["modified_roll_third"]
                    for s in ("drive", "coast")
                },
                "agreement_with_old": _agreement(best["record"], ref),
            }
    return rows


def table(rows: dict) -> str:
    lines = [
        "| family | code | design() s (best) | runs s | load before | D drive | D coast "
        "| max rel. diff. to old (D drive / coast; any number) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for family, codes in rows.items():
        for code, r in codes.items():
            ag = r["agreement_with_old"]
            runs = " / ".join(f"{s:.1f}" for s in r["seconds"])
            loads = " / ".join(f"{x:.2f}" for x in r["load_avg"])
            lines.append(
                f"| `{family}` | {code} | {r['best_s']:.2f} | {runs} | {loads} "
                f"| {r['D']['drive']:.12f} | {r['D']['coast']:.12f} "
                f"| {ag['D_rel']['drive']:.1e} / {ag['D_rel']['coast']:.1e}; {ag['max_rel']:.1e} |"
            )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old-commit", default="5495f2b")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    RESULTS.mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="fegear_old_") as tmp:
        old = Path(tmp) / "old"
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(old), args.old_commit],
            check=True, capture_output=True,
        )  # fmt: skip
        try:
            rows = run(old, args.repeat)
        finally:
            subprocess.run(
                ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(old)],
                check=False, capture_output=True,
            )  # fmt: skip
    doc = {
        "machine": _machine(),
        "when": time.strftime("%Y-%m-%d %H:%M"),
        "old_commit": args.old_commit,
        "rows": rows,
    }
    (RESULTS / "bevel_design.json").write_text(json.dumps(doc, indent=1) + "\n")
    text = (
        "# `SpiralBevelPair.design()`: old against new\n\n"
        f"`python benchmarks/bench_bevel_design.py` ({doc['when']}, {doc['machine']}; "
        f"old = `{args.old_commit}`). Each run a fresh process, `OPENBLAS_NUM_THREADS=1`; "
        "the load before each run is the 1-minute load average (the machine is shared).\n\n"
        + table(rows)
        + "\n\n`new`: `design(native_tune=False)`: the third-order roll is tuned on the "
        "engine's rigid contact (only the trials' shared gear, the skipped residuals and the "
        "members reused within the design are new), so its pair is the old one bit for bit. "
        "`new native_tune`: `design()` as the pipeline calls it, the roll tuned on the native "
        "rigid contact (`_MeshContact`: the members' fast exact evaluators, analytic tangents); "
        "its D agrees with the old to the relative difference shown, every other number of the "
        "pair is the old one. The sector meshes follow D's last digits (3206 or 3210 "
        "tetrahedra on the reference pair for a change of 1e-13), so the stored loaded "
        "references of the synthesized bevel cases were made again with it.\n"
    )
    (RESULTS / "bevel_design.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
