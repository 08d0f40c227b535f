"""Write ``docs/validation.md``: fegear against references computed without the solver.

Usage::

    python docs/make_validation.py [hertz] [fzg] [bevel] [trend] [root] [cylindrical]  # all
    python docs/make_validation.py render      # rewrite the page from docs/validation.json

Runs the cases (:mod:`fegear.validation.rows`): the Hertz scene at ``fe`` and ``hybrid`` levels
0-5, the FZG pair at its pitch point (``hybrid`` 0-2, ``fe`` 0-3, ``hertz`` 0), the spiral bevel's
unloaded TCA, the seed face gear at its three loads (``hybrid`` and ``hertz`` level 0), and the
ISO 6336-3 root-stress rows of ``fegear.validation.iso6336_root.rows()`` when that exists, and the
helical pairs of :mod:`fegear.validation.cylindrical_rows` (contact ratios, stiffness, line
Hertz, KHβ under misalignment, root stress with Yβ). It takes
tens of minutes on 2 cores with an empty cache (the page states the time it took). The rows are
kept in ``docs/validation.json``: naming sections reruns only those and keeps the others' rows.
The section against CalculiX is rendered from ``benchmarks/results/calculix.json``
(``python benchmarks/calculix_crosscheck.py`` measures it; this script does not run ``ccx``).
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict
from pathlib import Path

from fegear.validation import Row, as_row
from fegear.validation import rows as V

HERE = Path(__file__).resolve().parent
PAGE = HERE / "validation.md"
DATA = HERE / "validation.json"
#: The CalculiX cross-check's rows (``python benchmarks/calculix_crosscheck.py``: hours of
#: ``ccx``, not rerun by this script; the page's section is rendered from them).
CALCULIX = HERE.parent / "benchmarks" / "results" / "calculix.json"
SECTIONS = ("hertz", "fzg", "bevel", "trend", "root", "cylindrical")
#: (fidelity, level) of the FZG pitch-point runs.
FZG_RUNS = (("hybrid", 0), ("hybrid", 1), ("hybrid", 2), ("fe", 0), ("fe", 1), ("fe", 2),
            ("fe", 3), ("hertz", 0))  # fmt: skip
#: (fidelity, level) of the seed face-gear load trend (``fe`` level 0 cannot resolve the patch:
#: every position degenerate, docs/ltca/te_vs_load.md).
TREND_RUNS = (("hybrid", 0), ("hertz", 0))

log = logging.getLogger("make_validation")


def _part(name: str):
    """One run of the page, in this process: a JSON-able result."""
    kind, *arg = name.split(":")
    if kind == "hertz":
        return [asdict(r) for r in V.hertz_scene_rows()]
    if kind == "fzg":
        return asdict(V.pitch_point_run(arg[0], int(arg[1])))
    if kind == "bevel":
        return asdict(V.bevel_te_parabola())
    if kind == "trend":
        return asdict(V.trend_point(V.TREND_CASES[int(arg[2])], arg[0], int(arg[1])))
    if kind == "root":
        rows = V.root_stress_rows()
        return [asdict(r) for r in rows or [V.pending_root_stress_row()]]
    if kind == "cyl":
        from fegear.validation import cylindrical_rows as C

        what = arg[0]
        if what == "ratios":
            return [asdict(r) for r in C.contact_ratio_rows()]
        if what == "stiffness":
            return asdict(C.stiffness_run(arg[1]))
        if what == "hertz":
            return asdict(C.helical_hertz_run())
        if what == "khb":
            return asdict(C.khb_run())
        if what == "root":
            return asdict(C.root_run())
    raise SystemExit(f"unknown part {name!r}")


def _run_part(name: str):
    """:func:`_part` in a child process: the FE operators each run keeps in memory (several GB
    at the fine levels) go with it."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "part.json"
        subprocess.run([sys.executable, __file__, "--part", name, str(out)], check=True)
        return json.loads(out.read_text(encoding="utf-8"))


def measure(section: str) -> list[Row]:
    """Run one section's cases (each run in its own process); its rows."""
    if section == "hertz":
        return [as_row(d) for d in _run_part("hertz")]
    if section == "fzg":
        runs = []
        for fid, lv in FZG_RUNS:
            r = V.PitchPointRun(**_run_part(f"fzg:{fid}:{lv}"))
            r = dataclasses.replace(r, p_mid_range_MPa=tuple(r.p_mid_range_MPa))
            log.warning("fzg %s %d: c' %.2f, p_mid %.1f MPa (%.0f s)", fid, lv, r.c_prime,
                        r.p_mid_MPa, r.seconds)  # fmt: skip
            runs.append(r)
        return V.fzg_rows(runs)
    if section == "bevel":
        return V.bevel_rows(V.BevelParabola(**_run_part("bevel")))
    if section == "trend":
        trends = {}
        for fid, lv in TREND_RUNS:
            n = len(V.TREND_CASES)
            parts = [_run_part(f"trend:{fid}:{lv}:{i}") for i in range(n)]
            trends[(fid, lv)] = [V.TrendPoint(**d) for d in parts]
            log.warning("trend %s %d: %s", fid, lv, trends[(fid, lv)])
        return V.load_trend_rows(trends)
    if section == "root":
        return [as_row(d) for d in _run_part("root")]
    if section == "cylindrical":
        from fegear.validation import cylindrical_rows as C

        rows = [as_row(d) for d in _run_part("cyl:ratios")]
        runs = [
            C.StiffnessRun(**_run_part(f"cyl:stiffness:{n}"))
            for n in ("helical_15", "helical_25", "iso_tr_ex1")
        ]
        rows += C.stiffness_rows(runs)
        rows += C.hertz_rows(C.HertzRun(**_run_part("cyl:hertz")))
        rows += C.khb_rows(C.KHBetaRun(**_run_part("cyl:khb")))
        rows += C.root_rows(C.RootRun(**_run_part("cyl:root")))
        return rows
    raise SystemExit(f"unknown section {section!r}: one of {', '.join(SECTIONS)}")


def _failed(section: str, why: str) -> Row:
    """The row of a section whose run failed (e.g. killed for memory): the reason, no numbers."""
    return Row(
        key=f"{section}_failed",
        check=f"section `{section}`",
        quantity="—",
        reference=None,
        reference_text="—",
        values=(),
        tolerance="—",
        command=f"python docs/make_validation.py {section}",
        test=V.TESTS,
        pending=f"not measured: the run failed ({why}); rerun the section",
    )


def _num(x: float | None, ref: float | None = None) -> str:
    if x is None or not math.isfinite(x):
        return "—"
    mag = abs(ref if ref is not None else x)
    if mag >= 1000:
        return f"{x:.1f}"
    if mag >= 10:
        return f"{x:.2f}"
    return f"{x:.4g}" if mag < 0.1 else f"{x:.3f}"


def _level(v) -> str:
    return "—" if v.level is None else str(v.level)


def _cell(text: str) -> str:
    """Markdown table cell text (a ``|`` would end the cell)."""
    return text.replace("|", "\\|")


def table(rows: list[Row]) -> str:
    """The summary table: one line per fegear value."""
    rows = [
        dataclasses.replace(
            r,
            check=_cell(r.check),
            quantity=_cell(r.quantity),
            reference_text=_cell(r.reference_text),
        )  # fmt: skip
        for r in rows
    ]
    out = [
        "| check | quantity | reference | fidelity | level | fegear | ratio | command |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if r.pending:
            out.append(f"| {r.check} | {r.quantity} | {r.reference_text} | — | — | "
                       f"{r.pending} | — | `{r.command}` |")  # fmt: skip
            continue
        ref = "rises with load" if r.reference is None else _num(r.reference)
        for i, v in enumerate(r.values):
            check, quantity, ref_i, cmd = (
                (r.check, r.quantity, ref, f"`{r.command}`") if i == 0 else ("", "", "", "")
            )
            if r.loads:
                val = " → ".join(_num(x) for x in v.series)
                up = r.increasing(v)
                s = v.series
                grow = (s[-1] / s[0]) if up is not None and s[0] else None
                ratio = ("—" if up is None else
                         f"×{grow:.2f} {'increasing' if up else 'NOT increasing'}")  # fmt: skip
            else:
                val = _num(v.value, r.reference)
                q = r.ratio(v)
                ratio = "—" if q is None else f"{q:.3f}"
            out.append(f"| {check} | {quantity} | {ref_i} | `{v.fidelity}` | {_level(v)} | "
                       f"{val} | {ratio} | {cmd} |")  # fmt: skip
    return "\n".join(out)


def details(rows: list[Row]) -> str:
    """Per row: the reference, the tolerance and test, and each value's notes."""
    out = []
    for r in rows:
        out += [f"### {r.check}", "", f"- quantity: {r.quantity}"]
        out.append(f"- reference: {r.reference_text}"
                   + ("" if r.reference is None else f" → **{_num(r.reference)}**"))  # fmt: skip
        if r.loads:
            out.append(f"- loads: {', '.join(r.loads)}")
        out.append(f"- test: `{r.test}`, tolerance {r.tolerance}")
        out.append(f"- command: `{r.command}`")
        if r.pending:
            out.append(f"- **{r.pending}**")
        for v in r.values:
            t = "" if v.seconds is None else f", {v.seconds:.1f} s"
            note = f": {v.note}" if v.note else ""
            out.append(f"- `{v.fidelity}` level {_level(v)}{t}{note}")
        out.append("")
    return "\n".join(out)


def _times(section_seconds: dict[str, float]) -> str:
    """``"12.0 min: hertz 110 s, fzg 74 s, ..."`` (the wall time of each section's last run)."""
    parts = [f"{s} {section_seconds[s]:.0f} s" for s in SECTIONS if s in section_seconds]
    total = sum(section_seconds.values()) / 60
    return f"{total:.1f} min: " + ", ".join(parts) if parts else "not timed"


def write(rows: list[Row], section_seconds: dict[str, float]) -> None:
    head = f"""# Validation

Each row sets a fegear result against a reference computed without the solver: a closed form, a
standard (ISO 6336), or the design target the geometry was synthesized for. The references are in
`fegear/validation/iso6336.py` and `fegear/mechanics/hertz_closed_form.py`, the measurements in
`fegear/validation/rows.py`; each row is a test in `tests/test_validation.py` (the slow ones
under `-m slow`) with its tolerance and the reason for it.

This page is generated: `python docs/make_validation.py` runs every case below and rewrites it
({_times(section_seconds)} on 2 cores, each section as last run; a section named on the command
line is rerun alone, the other rows are kept from `docs/validation.json`).
Ratio = fegear / reference; a trend row gives its values at the three loads and how much the
quantity grew. The seconds under "Rows" are the wall time of each run with the artefact cache as
this run found it (meshes and operators built once are read back later): not a benchmark.

The two papers fegear was built from are checked number by number on their own pages, each
generated the same way: [the face-gear paper](papers/face_gear_2013.md) (its Tables 1-3, the TE
at three loads, Δγ = ±0.02°, the shaper its ellipses imply; `python
docs/papers/make_face_gear_2013.py`) and [the multi-pair spiral bevel
paper](papers/spiral_bevel_multipair.md) (pairs in contact, contact ratio, patch, bearing and TE
against the load; `python docs/papers/make_spiral_bevel_multipair.py`).

## Summary

"""
    PAGE.write_text(
        head + table(rows) + "\n\n" + calculix_section() + "\n## Rows\n\n"
        + details(rows).rstrip() + "\n",
        encoding="utf-8",
    )  # fmt: skip


def calculix_section() -> str:
    """The CalculiX rows, rendered from :data:`CALCULIX` (none when it is missing)."""
    from fegear.validation.calculix_rows import validation_section

    if not CALCULIX.is_file():
        return ""
    return validation_section(json.loads(CALCULIX.read_text(encoding="utf-8")))


def main(argv: list[str]) -> None:
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    if argv[:1] == ["--part"]:  # a child of _run_part
        Path(argv[2]).write_text(json.dumps(_part(argv[1])), encoding="utf-8")
        return
    if argv == ["render"]:  # rewrite the page from docs/validation.json, no runs
        doc = json.loads(DATA.read_text(encoding="utf-8"))
        rows = [as_row(d) for s in SECTIONS for d in doc["sections"].get(s, [])]
        write(rows, doc.get("section_seconds", {}))
        print(PAGE)
        return
    sections = tuple(argv) or SECTIONS
    for s in sections:
        if s not in SECTIONS:
            raise SystemExit(f"unknown section {s!r}: one of {', '.join(SECTIONS)}")
    old: dict[str, list[dict]] = {}
    times: dict[str, float] = {}
    if DATA.exists() and set(sections) != set(SECTIONS):
        kept = json.loads(DATA.read_text(encoding="utf-8"))
        old, times = kept["sections"], kept.get("section_seconds", {})
    t0 = time.perf_counter()
    new: dict[str, list[dict]] = {}
    for s in SECTIONS:
        if s in sections:
            t = time.perf_counter()
            try:
                new[s] = [asdict(r) for r in measure(s)]
            except subprocess.CalledProcessError as e:  # the page says so: no number stands in
                why = f"signal {-e.returncode}" if e.returncode < 0 else f"exit {e.returncode}"
                log.warning("%s failed: %s", s, why)
                new[s] = [asdict(_failed(s, f"{why} in `{' '.join(e.cmd[2:4])}`"))]
            times[s] = time.perf_counter() - t
            log.warning("%s: %.0f s", s, times[s])
        elif s in old:
            new[s] = old[s]
        seconds = time.perf_counter() - t0
        doc = {"sections": new, "seconds": seconds, "ran": list(sections), "section_seconds": times}
        DATA.write_text(json.dumps(doc, indent=1), encoding="utf-8")  # kept if a later one fails
    rows = [as_row(d) for s in SECTIONS for d in new.get(s, [])]
    write(rows, times)
    print(PAGE)


if __name__ == "__main__":
    main(sys.argv[1:])
