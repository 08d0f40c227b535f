"""Every family's main case: cold, warm, a new installation error and a five-value sweep.

For each family, from an EMPTY artefact cache (a fresh ``FEGEAR_CACHE``), in one process per
job (``bench_error_study``'s runner: wall time, peak memory, the 1-minute load average before it
and the CPU seconds the rest of the machine used meanwhile):

* ``cold``: ``fegear run cases/<case>.toml`` (every output; the bevel pairs' synthesis of the
  machine settings included);
* ``warm``: the same run again on the cache it left (its positions read back);
* ``new error``: the case with one installation error changed (the key below), on that cache:
  the same meshes and operators, its own TCA and positions;
* ``sweep``: ``fegear sweep`` of five values of that error, on that cache (the first value is
  the new error's, so four are new).

The cases and errors (each family's own kind of error):

=================  ==============================  ==================================
family             case                            error (new value; sweep)
=================  ==============================  ==================================
face gear          ``face_gear_nominal``           ``dgamma_deg`` 0.01; -0.02:0.02
spiral bevel       ``spiral_bevel_nominal``        ``dE_mm`` 0.05; -0.05:0.05
hypoid             ``hypoid_nominal``              ``dE_mm`` 0.05; -0.05:0.05
spur (FZG C)       ``fzg_type_c``                  ``f_sigma_beta_mm`` 0.01; 0:0.02
helical            ``helical_crowned``             ``f_sigma_beta_mm`` 0.01; 0:0.02
=================  ==============================  ==================================

Usage::

    python benchmarks/bench_families.py [FAMILY ...]    # default: every family

Writes ``benchmarks/results/families.json`` (merged with earlier runs of other families) and
``benchmarks/results/families.md`` (the table, with the CPU and the ratios to the face gear's
cold run, the issue's yardstick).
"""

from __future__ import annotations

import json
import re
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_error_study import FEGEAR, ROOT, _machine, _one  # noqa: E402

RESULTS = HERE / "results"
#: family → (case, error key, new value, sweep grid)
FAMILIES = {
    "face_gear": ("face_gear_nominal", "dgamma_deg", 0.01, "-0.02:0.02:5"),
    "spiral_bevel": ("spiral_bevel_nominal", "dE_mm", 0.05, "-0.05:0.05:5"),
    "hypoid": ("hypoid_nominal", "dE_mm", 0.05, "-0.05:0.05:5"),
    "spur": ("fzg_type_c", "f_sigma_beta_mm", 0.01, "0:0.02:5"),
    "helical": ("helical_crowned", "f_sigma_beta_mm", 0.01, "0:0.02:5"),
}


def _with_error(case: Path, key: str, value: float, out: Path) -> Path:
    """``case`` with ``[errors] key = value`` (the line replaced, or added to the table)."""
    text = case.read_text()
    line = re.compile(rf"^{re.escape(key)}\s*=.*$", re.M)
    if line.search(text):
        text = line.sub(f"{key} = {value!r}", text, count=1)
    else:
        text = text.replace("[errors]", f"[errors]\n{key} = {value!r}", 1)
    text = re.sub(r'^name = ".*"$', f'name = "{case.stem}_new_error"', text, count=1, flags=re.M)
    out.write_text(text)
    return out


def run_family(family: str) -> dict:
    name, key, value, grid = FAMILIES[family]
    case = ROOT / "cases" / f"{name}.toml"
    with tempfile.TemporaryDirectory(prefix="fegear_family_") as tmp:
        work, cache = Path(tmp) / "work", Path(tmp) / "cache"
        work.mkdir()
        new = _with_error(case, key, value, work / "new_error.toml")
        argv = FEGEAR + ["run", str(case), "-q", "--out", "{work}/out"]
        out = {"family": family, "case": name, "error": f"{key} = {value}", "grid": grid}
        out["cold"] = _one(argv, work, cache, False)
        if out["cold"]["exit"] == 0:
            out["warm"] = _one(argv, work, cache, False)
            out["new_error"] = _one(FEGEAR + ["run", str(new), "-q", "--out", "{work}/out_e"],
                                    work, cache, False)  # fmt: skip
            sweep = FEGEAR + ["sweep", str(case), "--grid", f"errors.{key}={grid}", "--out",
                              "{work}/sweep", "-q"]  # fmt: skip
            out["sweep"] = _one(sweep, work, cache, True)
    out["when"] = time.strftime("%Y-%m-%d %H:%M")
    return out


def table(rows: dict[str, dict]) -> str:
    ref = rows.get("face_gear", {}).get("cold", {}).get("seconds")
    lines = [
        "| family (case) | cold s | warm s | new error s | sweep of 5 s | new error / face-gear "
        "cold | cache MB | peak RSS MB | load before cold | others' CPU s (cold / warm / new / "
        "sweep) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for fam in FAMILIES:
        if fam not in rows:
            continue
        r = rows[fam]
        jobs = [r.get(k) or {} for k in ("cold", "warm", "new_error", "sweep")]
        s = lambda x: f"{x['seconds']:.1f}" if x else ""  # noqa: E731
        ratio = f"{jobs[2]['seconds'] / ref:.2f}" if ref and jobs[2] else ""
        o = " / ".join(f"{x['others_cpu_s']:.1f}" for x in jobs if x)
        rss = max(x.get("peak_rss_MB", 0) for x in jobs if x)
        cache = jobs[3].get("cache_bytes") or jobs[0]["cache_bytes"]
        lines.append(
            f"| {fam} (`{r['case']}`, {r['error']}) | {' | '.join(s(x) for x in jobs)} | {ratio} "
            f"| {cache / 1e6:.0f} | {rss:.0f} | {jobs[0]['load_avg']:.2f} | {o} |"
        )
    return "\n".join(lines)


def main() -> None:
    names = sys.argv[1:] or list(FAMILIES)
    if any(n not in FAMILIES for n in names):
        print(__doc__)
        sys.exit(2)
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / "families.json"
    rows = json.loads(path.read_text()) if path.exists() else {}
    for name in names:
        print(f"{name} ...", file=sys.stderr, flush=True)
        rows[name] = run_family(name)
        path.write_text(json.dumps(rows, indent=1) + "\n")
    md = (
        "# Every family: cold, warm, a new installation error, a sweep\n\n"
        "`python benchmarks/bench_families.py` (each family from an empty cache: cold, then on "
        "the cache it left the same run (warm), the case with one installation error changed "
        "(new error) and a five-value `fegear sweep` of that error; `hybrid` level 0, every "
        f"output; {_machine()}):\n\n" + table(rows) + "\n\nCold includes the bevel pairs' "
        "synthesis of the machine settings. Load before: the 1-minute load average; others' "
        "CPU: the CPU seconds the rest of the machine used during each job (~0 when idle).\n"
    )
    (RESULTS / "families.md").write_text(md)
    print(md)


if __name__ == "__main__":
    main()
