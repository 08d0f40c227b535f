"""The two bevel families side by side: the hypoid main case against the spiral bevel's.

For each family, from an EMPTY artefact cache (a fresh ``FEGEAR_CACHE``): ``fegear run
cases/<family>_nominal.toml`` (the synthesis of the machine settings, the TCA, the sector meshes
and compliance operators, the loaded cycle at ``hybrid`` level 0, 13 positions, all outputs:
cold), the same run again on the cache it left (warm), and ``cases/<family>_dE.toml`` on that
cache (a new installation error: the same meshes, its own TCA and positions). Wall time, peak
memory, the 1-minute load average before each run and the CPU seconds the rest of the machine
used meanwhile (``others_cpu_s``: ~0 when idle) per run, via ``bench_error_study``'s runner.

Usage::

    python benchmarks/bench_bevel_families.py [spiral_bevel] [hypoid]    # default: both

Writes ``benchmarks/results/bevel_families.json`` and ``benchmarks/results/bevel_families.md``.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
from bench_error_study import FEGEAR, ROOT, _machine, _one  # noqa: E402

RESULTS = HERE / "results"
FAMILIES = ("spiral_bevel", "hypoid")


def run_family(family: str) -> dict:
    nominal = ROOT / "cases" / f"{family}_nominal.toml"
    new_error = ROOT / "cases" / f"{family}_dE.toml"
    with tempfile.TemporaryDirectory(prefix="fegear_bevel_") as tmp:
        work, cache = Path(tmp) / "work", Path(tmp) / "cache"
        work.mkdir()
        argv = FEGEAR + ["run", str(nominal), "-q", "--out", "{work}/out"]
        out = {"family": family, "cold": _one(argv, work, cache, False)}
        if out["cold"]["exit"] == 0:
            out["warm"] = _one(argv, work, cache, False)
            argv_e = FEGEAR + ["run", str(new_error), "-q", "--out", "{work}/out_dE"]
            out["new_error"] = _one(argv_e, work, cache, False)
    out["when"] = time.strftime("%Y-%m-%d %H:%M")
    return out


def table(rows: dict[str, dict]) -> str:
    lines = [
        "| family (`cases/<family>_nominal.toml`) | cold s | warm s | new error (ΔE) s "
        "| cache MB | peak RSS MB | load before cold | others' CPU s (cold / warm / ΔE) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for fam in FAMILIES:
        if fam not in rows:
            continue
        r = rows[fam]
        c, w, e = r["cold"], r.get("warm", {}), r.get("new_error", {})
        s = lambda x: f"{x['seconds']:.1f}" if x else ""  # noqa: E731
        o = " / ".join(f"{x['others_cpu_s']:.1f}" for x in (c, w, e) if x)
        rss = max(x.get("peak_rss_MB", 0) for x in (c, w, e) if x)
        lines.append(f"| `{fam}` | {s(c)} | {s(w)} | {s(e)} | {c['cache_bytes'] / 1e6:.0f} "
                     f"| {rss:.0f} | {c['load_avg']:.2f} | {o} |")  # fmt: skip
    return "\n".join(lines)


def main() -> None:
    names = sys.argv[1:] or list(FAMILIES)
    if any(n not in FAMILIES for n in names):
        print(__doc__)
        sys.exit(2)
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / "bevel_families.json"
    rows = json.loads(path.read_text()) if path.exists() else {}
    for name in names:
        print(f"{name} ...", file=sys.stderr, flush=True)
        rows[name] = run_family(name)
        path.write_text(json.dumps(rows, indent=1) + "\n")
    text = (
        "# The bevel families: hypoid against spiral bevel\n\n"
        "`python benchmarks/bench_bevel_families.py` (each family from an empty cache: cold, "
        "then warm on the cache it left, then its ΔE case on that cache; `hybrid` level 0, 13 "
        f"positions, all outputs; {_machine()}):\n\n"
        + table(rows)
        + "\n\nCold includes the synthesis of the machine settings (cached after it). Load "
        "before: the 1-minute load average; others' CPU: the CPU seconds the rest of the "
        "machine used during the run (~0 on an idle machine).\n"
    )
    (RESULTS / "bevel_families.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
