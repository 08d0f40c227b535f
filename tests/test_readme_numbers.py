"""The README's fidelity tables are the measured results of ``benchmarks/bench_fidelity.py``
(``benchmarks/results/fidelity_<scene>.json``), to the digits they show.

A re-measured benchmark that leaves the README behind fails here: the README is updated from
the results (``python benchmarks/bench_fidelity.py SCENE`` re-makes the results table from the
JSON), never typed in.
"""

from __future__ import annotations

import importlib.util
import json
import math
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
HEADER = "| fidelity | level | cold s | warm s | TE p-p ″ | mean TE ″ | contact ratio |"


def _bench():
    spec = importlib.util.spec_from_file_location(
        "bench_fidelity", REPO / "benchmarks" / "bench_fidelity.py"
    )
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _tables() -> list[list[list[str]]]:
    """The README's fidelity tables (face gear, then spiral bevel): rows of cells."""
    lines = (REPO / "README.md").read_text(encoding="utf-8").splitlines()
    out = []
    for i, line in enumerate(lines):
        if line.startswith(HEADER):
            rows = []
            for row in lines[i + 2 :]:
                if not row.startswith("|"):
                    break
                rows.append([c.strip() for c in row.strip("|").split("|")])
            out.append(rows)
    return out


def _number(cell: str) -> tuple[float, float]:
    """The number a cell shows (``*`` and units dropped, ``−`` read as minus) and half a unit of
    its last digit: what it may differ from the measured value by."""
    text = cell.replace("−", "-").replace("*", "").replace("%", "").strip()
    m = re.fullmatch(r"([+-]?[0-9]+(?:\.([0-9]+))?)", text.strip())
    assert m, cell
    decimals = len(m.group(2) or "")
    return float(m.group(1)), 0.5 * 10.0**-decimals


def _check(cell: str, value: float, what: str, wrong: list[str]) -> None:
    if cell.replace("*", "").strip() == "—":  # not reported (every position degenerate): NaN
        if value is not None and not math.isnan(value):
            wrong.append(f"{what}: README {cell!r}, measured {value!r}")
        return
    shown, half = _number(cell)
    if not abs(shown - value) <= half * (1 + 1e-9):
        wrong.append(f"{what}: README {cell!r}, measured {value!r}")


@pytest.mark.parametrize(("index", "scene"), [(0, "face_gear"), (1, "spiral_bevel")])
def test_readme_fidelity_table_is_the_benchmark(index, scene):
    bench = _bench()
    runs = json.loads((REPO / "benchmarks" / "results" / f"fidelity_{scene}.json").read_text())
    _, vs_fe = bench.errors(runs, "fe")
    _, vs_hy = bench.errors(runs, "hybrid")
    fe = {(r["fidelity"], r["level"]): r for r in vs_fe}
    hy = {(r["fidelity"], r["level"]): r for r in vs_hy}
    rows = _tables()[index]
    assert rows, f"no fidelity table {index} in the README"
    wrong: list[str] = []
    for cells in rows:
        key = (cells[0].strip("`"), int(cells[1]))
        r, h = fe[key], hy[key]
        name = f"{scene} {key[0]} {key[1]}"
        _check(cells[2], r["cold_s"], f"{name} cold s", wrong)
        _check(cells[3], r["warm_s"], f"{name} warm s", wrong)
        _check(cells[4], r["te_pp"], f"{name} TE p-p", wrong)
        _check(cells[5], r["te_mean"], f"{name} mean TE", wrong)
        _check(cells[6], r["contact_ratio"], f"{name} contact ratio", wrong)
        _check(cells[7], r["p_max_interior"], f"{name} p_max int.", wrong)
        if cells[8] == "reference":
            assert h["err_te_pp"] == 0.0, name
            continue
        te, share, pm = (c.strip() for c in cells[8].split("/"))
        _check(te, 100 * h["err_te_pp"], f"{name} vs hybrid TE p-p %", wrong)
        _check(share, h["err_share"], f"{name} vs hybrid share", wrong)
        _check(pm, 100 * h["err_p_max_interior"], f"{name} vs hybrid p_max int. %", wrong)
    assert not wrong, "\n".join(wrong)
