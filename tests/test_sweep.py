"""``fegear sweep`` (issue 8): grids, atomic items, resume after a kill, Dask, bad input.

All on the FZG spur pair at fe level 0 with 3 positions (~2-4 s per item once the sector meshes
and compliance operators are cached; the first item of the session builds them, ~10 s).
"""

from __future__ import annotations

import functools
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from cli_checks import assert_refused, one_line

from fegear.case_files import load_case
from fegear.cli import main
from fegear.pipeline.run import check_case, run_gear_case
from fegear.store.cache import record_cache_use
from fegear.sweep import MARKER, build_items, parse_grid
from fegear.sweep.local import run_local

REPO = Path(__file__).resolve().parents[1]
FZG = REPO / "cases" / "fzg_spur.toml"
N_POS = 3


@pytest.fixture(scope="module")
def fzg3(tmp_path_factory) -> Path:
    """The FZG case with 3 positions at the ``hertz`` fidelity (fast: milliseconds per position
    once the sectors are cached; the shipped case runs ``hybrid``)."""
    text = FZG.read_text(encoding="utf-8")
    assert "n_positions = 9" in text and '\nfidelity = "hybrid"' in text
    path = tmp_path_factory.mktemp("case") / "fzg3.toml"
    text = text.replace("n_positions = 9", f"n_positions = {N_POS}")
    path.write_text(text.replace('\nfidelity = "hybrid"', '\nfidelity = "hertz"'), "utf-8")
    return path


def _check_items(out: Path, names: list[str]) -> None:
    """Every item folder is complete: summary.json parses, marker present; no tmp leftovers."""
    for name in names:
        doc = json.loads((out / name / "summary.json").read_text())
        assert doc["case"] == name and len(doc["positions"]) == N_POS
        assert json.loads((out / name / MARKER).read_text())["name"] == name
        for f in doc["files"]:
            assert (out / name / f).is_file(), (name, f)
    assert not [p.name for p in out.glob(".*.tmp")]
    assert not [p for p in out.rglob("*") if p.name.startswith(".") and p.name != ".sweep.lock"]


# --------------------------------------------------------------------------------------------
# A grid sweep: per-item outputs, sweep.json, overlay PNG, comparison table; re-run skips
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def grid_sweep(fzg3, tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep")
    argv = ["sweep", str(fzg3), "--grid", "errors.f_sigma_beta_mm=-0.01:0.01:3",
            "--out", str(out), "-q"]  # fmt: skip
    t0 = time.perf_counter()
    code = main(argv)
    return code, out, argv, time.perf_counter() - t0


def test_grid_sweep_writes_items_and_sweep_outputs(grid_sweep):
    code, out, _, seconds = grid_sweep
    assert code == 0
    names = [f"fzg_spur__f_sigma_beta_mm={v}" for v in ("-0.01", "0", "0.01")]
    _check_items(out, names)
    doc = json.loads((out / "sweep.json").read_text())
    assert [it["name"] for it in doc["items"]] == names
    assert doc["parameters"] == ["errors.f_sigma_beta_mm"]
    assert doc["status"] == {"done": 3, "skipped": 0, "failed": 0, "pending": 0}
    for it, v in zip(doc["items"], (-0.01, 0.0, 0.01), strict=True):
        assert it["params"] == {"errors.f_sigma_beta_mm": v}
        r = it["results"]
        for key in ("te_pp_unloaded_arcsec", "te_pp_loaded_arcsec", "contact_ratio_loaded",
                    "p_max_MPa", "pattern_position_mm"):  # fmt: skip
            assert isinstance(r[key], float) and math.isfinite(r[key]), (it["name"], key)
        # the summary of the item folder is where the key results come from: exact copies
        s = json.loads((out / it["name"] / "summary.json").read_text())["cycle"]
        assert r["te_pp_loaded_arcsec"] == s["te_pp_loaded_arcsec"]
    cmp = doc["comparison"]
    assert cmp["nominal"] == names[1]  # the item without installation errors
    assert cmp["basis"] == "loaded"
    rows = {r["item"]: r for r in cmp["rows"]}
    assert rows[names[1]]["te_ratio"] == 1.0 and rows[names[1]]["pattern_shift_mm"] == 0.0
    for r in rows.values():
        assert math.isfinite(r["te_ratio"]) and r["te_ratio"] > 0
    # the axis tilted one way moves the pattern to one end of the face, the other way to the
    # other end (physics sanity, sign only: coarse level 0)
    lo, hi = rows[names[0]]["pattern_shift_mm"], rows[names[2]]["pattern_shift_mm"]
    assert lo * hi < 0 and min(abs(lo), abs(hi)) > 0.1, (lo, hi)
    assert {rows[names[0]]["pattern_shift_toward"], rows[names[2]]["pattern_shift_toward"]} == {
        "+z end",
        "-z end",
    }
    md = (out / "comparison.md").read_text()
    assert md.count("\n| fzg_spur") + md.count("\n| **fzg_spur") == 3 and "TE ratio" in md
    png = out / "te_overlay.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    print(f"grid sweep of 3 items: {seconds:.1f} s")


def test_the_sweep_reports_the_spread_of_its_headlines(grid_sweep):
    """A tolerance study's answer: min / median / max of each key result over the items (here
    the FZG axis tilted −0.01, 0, +0.01 mm), the exact extremes and middle of the items' own
    values, and the table in comparison.md."""
    _, out, _, _ = grid_sweep
    doc = json.loads((out / "sweep.json").read_text())
    for key, v in doc["spread"].items():
        vals = sorted(it["results"][key] for it in doc["items"])
        assert (v["n"], v["null"]) == (3, 0), key
        assert [v["min"], v["median"], v["max"]] == vals, key  # 3 items: the middle one
    md = (out / "comparison.md").read_text()
    assert "| p_max away from the edges (MPa) |" in md and "Spread over the 3 finished items" in md


def test_rerun_skips_finished_items(grid_sweep, capsys):
    code, out, argv, _ = grid_sweep
    assert code == 0
    mtimes = {p: p.stat().st_mtime_ns for p in out.glob("*/summary.json")}
    assert len(mtimes) == 3
    capsys.readouterr()
    assert main([a for a in argv if a != "-q"]) == 0
    err = capsys.readouterr().err
    assert err.count("  skipped (done)\n") == 3, err
    assert {p: p.stat().st_mtime_ns for p in out.glob("*/summary.json")} == mtimes
    doc = json.loads((out / "sweep.json").read_text())
    assert doc["status"]["skipped"] == 3
    assert all(it["results"] is not None for it in doc["items"])


# --------------------------------------------------------------------------------------------
# Killed mid-run, then resumed
# --------------------------------------------------------------------------------------------


def test_killed_sweep_resumes_without_recomputing(fzg3, tmp_path):
    out = tmp_path / "sweep"
    argv = [sys.executable, "-m", "fegear.cli", "sweep", str(fzg3), "--out", str(out),
            "--grid", "load.torque2_Nm=150:250:3"]  # fmt: skip
    names = [f"fzg_spur__torque2_Nm={t}" for t in (150, 200, 250)]
    proc = subprocess.Popen(
        argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True
    )
    first = out / names[0] / MARKER
    t0 = time.monotonic()
    try:
        while not first.exists():
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() - t0 < 60, "first item not done within 60 s"
            time.sleep(0.05)
        time.sleep(0.3)  # most likely inside the second item now (its .tmp folder on disk)
    finally:
        # kill the sweep and its worker process (its own process group) without warning
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        proc.stderr.close()
    done_before = [n for n in names if (out / n / MARKER).exists()]
    assert names[0] in done_before and len(done_before) < 3, done_before
    mtimes = {n: (out / n / "summary.json").stat().st_mtime_ns for n in done_before}
    # whatever is on disk now is either a complete item or hidden in a .tmp folder
    for n in names:
        if (out / n).exists():
            json.loads((out / n / "summary.json").read_text())

    res = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    for n in done_before:
        assert f"{n}  skipped (done)" in res.stderr, res.stderr
        assert (out / n / "summary.json").stat().st_mtime_ns == mtimes[n]
    for n in set(names) - set(done_before):
        assert f"{n}  done in" in res.stderr, res.stderr
    _check_items(out, names)
    doc = json.loads((out / "sweep.json").read_text())
    assert [it["status"] for it in doc["items"]].count("skipped") == len(done_before)
    assert doc["comparison"]["nominal"] == names[0]  # no errors anywhere: the first item
    ratios = [r["te_ratio"] for r in doc["comparison"]["rows"]]
    assert ratios[0] == 1.0 and all(math.isfinite(r) for r in ratios)


def test_stale_or_foreign_item_folder_is_recomputed(fzg3, tmp_path, capsys):
    """A folder without a matching marker is not trusted: it is recomputed and replaced; a
    leftover tmp folder is removed."""
    out = tmp_path / "sweep"
    (out / "fzg_spur").mkdir(parents=True)
    (out / "fzg_spur" / "summary.json").write_text("{half-writ")
    (out / ".fzg_spur.deadbeef.tmp").mkdir()
    (out / ".fzg_spur.deadbeef.tmp" / "te.png").write_bytes(b"\x89PN")
    assert main(["sweep", str(fzg3), "--out", str(out)]) == 0
    assert "fzg_spur  done in" in capsys.readouterr().err
    _check_items(out, ["fzg_spur"])
    # another level: another fingerprint, recomputed
    (out / "fzg_spur" / "summary.json").touch()
    t = (out / "fzg_spur" / "summary.json").stat().st_mtime_ns
    assert main(["sweep", str(fzg3), "--out", str(out), "--fidelity", "tca", "-q"]) == 0
    assert (out / "fzg_spur" / "summary.json").stat().st_mtime_ns != t
    assert json.loads((out / "fzg_spur" / "summary.json").read_text())["fidelity"] == "tca"


def test_truncated_summary_is_not_trusted(fzg3, tmp_path, capsys):
    """A finished item whose summary.json was cut short afterwards (its marker intact) is not
    skipped as done: the marker's SHA-256 no longer matches, the item is recomputed (issue 21;
    it was skipped and the comparison took another item as its reference)."""
    out = tmp_path / "sweep"
    argv = ["sweep", str(fzg3), "--out", str(out), "--fidelity", "tca"]
    assert main([*argv, "-q"]) == 0
    summary = out / "fzg_spur" / "summary.json"
    text = summary.read_text()
    summary.write_text(text[: len(text) // 2])  # truncated, marker left as it was
    capsys.readouterr()
    assert main(argv) == 0
    assert "fzg_spur  done in" in capsys.readouterr().err  # recomputed, not "skipped (done)"
    assert json.loads(summary.read_text())["case"] == "fzg_spur"


def test_missing_reference_item_is_an_error(fzg3, tmp_path, capsys):
    """The comparison's reference is the item without installation errors whether or not it
    finished; if its results are missing the comparison is an error (exit 1 naming it), never
    another item taken silently as the reference (issue 21)."""
    out = tmp_path / "sweep"
    argv = ["sweep", str(fzg3), "--grid", "errors.f_sigma_beta_mm=0,0.005", "--out", str(out),
            "--fidelity", "tca"]  # fmt: skip
    assert main([*argv, "-q"]) == 0
    ref = "fzg_spur__f_sigma_beta_mm=0"
    assert json.loads((out / "sweep.json").read_text())["comparison"]["nominal"] == ref
    from fegear.sweep import build_items, verified_summary
    from fegear.sweep.output import comparison, key_results, reference_item

    items = build_items([fzg3], ["errors.f_sigma_beta_mm=0,0.005"], fidelity="tca")
    other = items[1].name
    keyres = {other: key_results(verified_summary(out / other))}
    assert reference_item(items, None) == ref  # not the only finished item
    cmp = comparison(items, keyres)
    assert cmp["nominal"] == ref and cmp["rows"] == [] and ref in cmp["error"]


def test_failing_item_does_not_stop_the_others(fzg3, tmp_path, capsys):
    """x2 = 1.9 passes the schema but makes a pointed gear tooth: that item fails (one line),
    the other runs, exit code 1."""
    out = tmp_path / "sweep"
    text = fzg3.read_text()
    bad = tmp_path / "pointed.toml"
    bad.write_text(
        text.replace("profile_shift = [0.1817, 0.1715]", "profile_shift = [0.1817, 1.9]")
        .replace('name = "fzg_spur"', 'name = "pointed"'),
        "utf-8",
    )  # fmt: skip
    assert main(["sweep", str(bad), str(fzg3), "--out", str(out), "--fidelity", "tca"]) == 1
    err = capsys.readouterr().err
    assert "pointed  failed: pair.profile_shift[1] = 1.9" in err, err
    assert "fzg_spur  done in" in err
    doc = json.loads((out / "sweep.json").read_text())
    status = {it["name"]: it["status"] for it in doc["items"]}
    assert status == {"pointed": "failed", "fzg_spur": "done"}
    assert not (out / "pointed").exists() and not list(out.glob(".*.tmp"))
    assert "pointed** | failed: pair.profile_shift[1] = 1.9" in (out / "comparison.md").read_text()
    # the reference is the first item without errors, "pointed": it failed, so there is no
    # comparison, and the sweep says so; fzg_spur is not taken instead (issue 21)
    assert "fegear: failed: the reference item 'pointed' has no valid results" in err
    assert doc["comparison"]["nominal"] == "pointed" and doc["comparison"]["rows"] == []
    assert "Error: the reference item 'pointed'" in (out / "comparison.md").read_text()


# --------------------------------------------------------------------------------------------
# Dask
# --------------------------------------------------------------------------------------------


def test_dask_local_cluster(fzg3, tmp_path, capsys):
    pytest.importorskip("dask")
    distributed = pytest.importorskip("distributed")
    out = tmp_path / "sweep"
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        argv = ["sweep", str(fzg3), "--grid", "errors.da_mm=0,0.02", "--out", str(out),
                "--scheduler", cluster.scheduler_address]  # fmt: skip
        assert main(argv) == 0
    err = capsys.readouterr().err
    assert "Dask scheduler" in err and err.count("done in") == 2, err
    names = ["fzg_spur__da_mm=0", "fzg_spur__da_mm=0.02"]
    _check_items(out, names)
    doc = json.loads((out / "sweep.json").read_text())
    assert doc["scheduler"].startswith(("tcp://", "inproc://"))
    rows = doc["comparison"]["rows"]
    assert rows[0]["te_ratio"] == 1.0 and math.isfinite(rows[1]["te_ratio"])


def test_scheduler_without_dask_is_one_line(fzg3, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import fails as if not installed
    out = tmp_path / "sweep"
    code = main(["sweep", str(fzg3), "--out", str(out), "--scheduler", "tcp://127.0.0.1:1"])
    assert code == 1
    line = one_line(capsys.readouterr().err)
    assert "Dask" in line and "pip install" in line, line


# --------------------------------------------------------------------------------------------
# Bad input: one line, exit 2, nothing run
# --------------------------------------------------------------------------------------------

BAD = [
    ("no =", ["--grid", "errors.dgamma_deg"], ["--grid", "KEY=START:STOP:N"]),
    ("no section", ["--grid", "da_mm=0:1:3"], ["--grid", "section.key"]),
    ("unknown key", ["--grid", "errors.da_m=0:0.1:3"], ["errors.da_m", "did you mean 'da_mm'"]),
    ("key of another kind", ["--grid", "errors.dgamma_deg=-0.04:0.04:5"],
     ["errors.dgamma_deg", "kind 'spur'", "--grid errors.dgamma_deg"]),
    ("unknown section", ["--grid", "loads.torque2_Nm=1:2:2"], ["loads", "[load]"]),
    ("bad N", ["--grid", "errors.da_mm=0:0.1:x"], ["--grid", "N an integer"]),
    ("N = 0", ["--grid", "errors.da_mm=0:0.1:0"], ["--grid", "N in [2, 1000]"]),
    ("bad start", ["--grid", "errors.da_mm=a:0.1:3"], ["--grid", "START and STOP"]),
    ("two colons", ["--grid", "errors.da_mm=0:0.1"], ["--grid", "three fields"]),
    ("bad value", ["--grid", "load.torque2_Nm=-100:100:3"], ["load.torque2_Nm", "-100", "> 0"]),
    ("string for a number", ["--grid", "pair.module_mm=big,small"],
     ["pair.module_mm", "'big'", "a number"]),
    ("float for an integer", ["--grid", "analysis.n_positions=3.5,4"],
     ["analysis.n_positions", "integer"]),
    ("case identity", ["--grid", "case.name=a,b"], ["--grid", "outside [case]"]),
    ("same key twice", ["--grid", "errors.da_mm=0,1", "--grid", "errors.da_mm=2,3"],
     ["--grid", "at most once"]),
    ("level", ["--level", "9"], ["--level", "[0, 4]"]),
    ("workers", ["--workers", "0"], ["--workers", ">= 1"]),
    ("nominal", ["--nominal", "nope"], ["--nominal", "nope"]),
]  # fmt: skip


@pytest.mark.parametrize(("argv", "words"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_grid_is_one_line_exit_2(fzg3, tmp_path, capsys, argv, words):
    out = tmp_path / "sweep"
    code = main(["sweep", str(fzg3), "--out", str(out), *argv])
    assert_refused(code, capsys.readouterr().err, words)
    if argv[0] != "--nominal":
        assert not out.exists()  # refused before any work


def test_bad_case_file_and_duplicate_names(fzg3, tmp_path, capsys):
    assert main(["sweep", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "o")]) == 2
    assert "missing.toml" in one_line(capsys.readouterr().err)
    assert main(["sweep", str(fzg3), str(fzg3), "--out", str(tmp_path / "o")]) == 2
    assert "distinct case names" in one_line(capsys.readouterr().err)
    hertz = REPO / "cases" / "hertz_scene.toml"
    assert main(["sweep", str(hertz), "--out", str(tmp_path / "o")]) == 2
    assert "a gear pair" in one_line(capsys.readouterr().err)
    assert not (tmp_path / "o").exists()


def test_grid_values_and_names(fzg3):
    ax = parse_grid("errors.dgamma_deg=-0.04:0.04:5")
    assert ax.values == (-0.04, -0.02, 0.0, 0.02, 0.04)  # tidy: no linspace round-off
    assert parse_grid("load.torque2_Nm=100:400:4").values == (100, 200, 300, 400)
    assert parse_grid("analysis.backend=superlu,auto").values == ("superlu", "auto")
    items = build_items([fzg3], ["load.torque2_Nm=100:400:4", "errors.da_mm=0,0.01"], level=0)
    assert len(items) == 8
    assert items[1].name == "fzg_spur__torque2_Nm=100__da_mm=0.01"
    assert items[1].case.torque2_Nmm == 100e3 and items[1].case.errors.da_mm == 0.01
    assert items[1].case.name == items[1].name
    assert len({it.fingerprint() for it in items}) == 8


def test_one_sweep_per_folder(fzg3, tmp_path, capsys):
    fcntl = pytest.importorskip("fcntl")
    out = tmp_path / "sweep"
    out.mkdir()
    with open(out / ".sweep.lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)  # another sweep holds the folder
        assert main(["sweep", str(fzg3), "--out", str(out), "-q"]) == 1
    assert "another sweep is writing" in one_line(capsys.readouterr().err)
    assert not (out / "fzg_spur").exists()


def test_leftovers_of_a_killed_run_are_cleaned(tmp_path):
    """A run killed between an atomic write and its rename leaves ``.sweep.<random>.json``
    (seen once in CI: the kill of the resume test landed there); the next run removes it with the
    unfinished item folders, and keeps the lock file."""
    from fegear.sweep.run import _clean_tmp

    (tmp_path / ".item.ab12.tmp").mkdir()
    (tmp_path / ".item.ab12.tmp" / "summary.json").write_text("{")
    (tmp_path / ".sweep.x7k2.json").write_text("{")
    (tmp_path / ".sweep.lock").write_text("")
    (tmp_path / "done_item").mkdir()
    gone = _clean_tmp(tmp_path)
    assert sorted(gone) == [".item.ab12.tmp", ".sweep.x7k2.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [".sweep.lock", "done_item"]


def _two_worker_sweep(fzg3: Path, tmp_path: Path, monkeypatch, grid: str) -> list[dict]:
    """``fegear sweep --workers 2`` of ``fzg3`` over ``grid`` from an empty cache; every item
    complete; their ``cache`` records (hits, built) in item order."""
    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path / "cache"))
    out = tmp_path / "sw"
    assert main(["sweep", str(fzg3), "--grid", grid, "--out", str(out), "--workers", "2",
                 "-q"]) == 0  # fmt: skip
    names = [it.name for it in build_items([str(fzg3)], [grid])]
    _check_items(out, names)
    return [json.loads((out / n / "summary.json").read_text())["cache"] for n in names]


def test_with_two_workers_the_first_item_builds_what_the_others_read(fzg3, tmp_path,
                                                                      monkeypatch):  # fmt: skip
    """``--workers 2`` from an empty cache: the first item runs alone and builds the sector
    meshes and operators; the two after it, side by side, read them (each item's own cache
    records in its summary.json): items started together would each build them."""
    uses = _two_worker_sweep(fzg3, tmp_path, monkeypatch, "errors.da_mm=0,0.01,0.02")
    built, hits = [u["built"] for u in uses], [u["hits"] for u in uses]
    assert "mesh" in built[0] and "compliance" in built[0], built[0]
    for b, h in zip(built[1:], hits[1:], strict=True):
        assert "mesh" not in b and "compliance" not in b, b
        assert h.get("mesh") == 2 and h.get("compliance", 0) >= 2, h


# --------------------------------------------------------------------------------------------
# The local execution: one warm worker, later items side by side, checks prepared beforehand
# --------------------------------------------------------------------------------------------


def _where(item: str, processes: int | None) -> tuple:
    """``run_one`` of the tests below: which process ran ``item``, with how many processes."""
    return item, processes, os.getpid(), os.getppid()


def _failed(item: str, exc: BaseException) -> tuple:
    return item, "failed", repr(exc)


def test_later_items_run_side_by_side_in_forks_of_the_warm_worker():
    """Five items, two at a time: the first alone in the worker (every core: ``None``), then
    (b, c) and (d, e), the first of each group in the worker and the other in a process forked
    from it (so it has the worker's models), each on one process; results in order."""
    out = list(run_local(list("abcde"), _where, 2, _failed))
    assert [o[0] for o in out] == list("abcde")
    worker = out[0][2]
    assert out[0][1] is None and worker != os.getpid()
    for lead, other in (out[1:3], out[3:5]):
        assert lead[2] == worker and lead[1] == 1, lead
        assert other[3] == worker and other[2] != worker and other[1] == 1, other


def test_one_worker_runs_the_items_one_after_the_other_on_every_core():
    out = list(run_local(list("abc"), _where, 1, _failed))
    assert [o[0] for o in out] == list("abc")
    assert len({o[2] for o in out}) == 1 and all(o[1] is None for o in out), out


def _mark(folder: str, item: str) -> None:
    """``prepare`` of the test below: a file per item, with the preparing process."""
    (Path(folder) / item).write_text(f"{os.getpid()} {os.getppid()}")


def _wait_marked(folder: str, item: str, processes: int | None) -> tuple:
    """``run_one``: the item's run waits (up to 20 s) for its preparation, as a real item
    would read its checks from the cache."""
    deadline = time.monotonic() + 20
    while item != "a" and not (Path(folder) / item).exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    return _where(item, processes)


def test_later_items_are_prepared_beside_the_first(tmp_path, monkeypatch):
    """``prepare`` runs for every item but the first, in one process forked from the worker
    (beside the first item, which it does not delay: nothing waits for it); not where the
    work keeps to one process (``FEGEAR_WORKERS=1``, as the other tests run)."""
    monkeypatch.delenv("FEGEAR_WORKERS")
    out = list(
        run_local(
            list("abcd"),
            functools.partial(_wait_marked, str(tmp_path)),
            2,
            _failed,
            functools.partial(_mark, str(tmp_path)),
        )
    )
    worker = out[0][2]
    marks = {p.name: p.read_text().split() for p in tmp_path.iterdir()}
    assert sorted(marks) == ["b", "c", "d"]  # not the first item
    (preparer,) = {pid for pid, _ in marks.values()}
    assert {ppid for _, ppid in marks.values()} == {str(worker)} and preparer != str(worker)


def test_a_prepared_item_reads_its_checks_from_the_cache(fzg3):
    """:func:`check_case` keeps the TCA of the positions and the engagement checks (contact
    path, handover) where the run of the same case finds them: the run reads every one of them
    (the same keys) and builds none of the checks' kinds again (its own ``tca``: the closing of
    the loaded cycle's phase, :mod:`fegear.ltca.cycle`, is not a check)."""
    case = load_case(fzg3).with_errors(f_sigma_beta_mm=0.00731)  # an error no test uses
    with record_cache_use() as used:
        check_case(case)
    checks = used().built
    assert {"tca", "contact_path", "handover"} <= set(checks), checks
    run = run_gear_case(case, fields=False)
    for kind in ("contact_path", "handover"):
        assert run.cache.hits.get(kind) == checks[kind] and kind not in run.cache.built
    assert run.cache.hits.get("tca", 0) >= checks["tca"], run.cache


def test_items_side_by_side_mesh_their_own_members(fzg3, tmp_path, monkeypatch):
    """A grid over the module: every item has members of its own, meshed in the process forked
    for it (the worker never starts gmsh: a process forked after gmsh started cannot mesh,
    fegear.mesh.gmsh_session.started_here); every item finishes, each built its two meshes."""
    for use in _two_worker_sweep(fzg3, tmp_path, monkeypatch, "pair.module_mm=4.5,4.6,4.7"):
        assert use["built"].get("mesh") == 2, use


def test_a_sweep_over_measured_flank_grids_runs_each_into_its_own_folder(tmp_path):
    """A tolerance study over measured grids: ``--grid topography.pinion_drive=...`` with a grid
    named relative to the case file and one by an absolute path; each item is the case with that
    grid (at ``tca``: the unloaded TE of the 10 µm crowning against a zero grid) in a folder of
    its own (the path's separators are not folder separators in the item's name)."""
    case = Path(__file__).resolve().parents[1] / "cases" / "helical_measured.toml"
    crowned = (case.parent / "helical_measured_pinion_drive.csv").read_text(encoding="utf-8")
    rows = [ln for ln in crowned.splitlines() if ln.strip() and not ln.startswith("#")]
    zero = tmp_path / "grids" / "zero.csv"
    zero.parent.mkdir()
    zero.write_text(
        "\n".join([rows[0]] + [r.split(",")[0] + ",0" * (len(r.split(",")) - 1) for r in rows[1:]])
        + "\n",
        encoding="utf-8",
    )
    out = tmp_path / "sweep"
    grid = f"topography.pinion_drive=helical_measured_pinion_drive.csv,{zero}"
    assert main(["sweep", str(case), "--grid", grid, "--fidelity", "tca", "--out", str(out),
                 "-q", "--workers", "1"]) == 0  # fmt: skip
    doc = json.loads((out / "sweep.json").read_text())
    assert doc["status"]["done"] == 2 and doc["status"]["failed"] == 0
    names = [it["name"] for it in doc["items"]]
    assert all("/" not in n and (out / n / "summary.json").is_file() for n in names), names
    shas = [
        json.loads((out / n / "summary.json").read_text())["inputs"]["topography"]["pinion_drive"][
            "sha256"
        ]
        for n in names
    ]
    assert len(set(shas)) == 2  # each item ran with its own grid
