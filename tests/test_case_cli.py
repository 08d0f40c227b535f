"""Case files and the ``fegear run`` command on the Hertz scene.

Bad input must end with exit code 2 and one line on stderr naming the problem, before any FE
work; a good case writes ``summary.json``, a VTU per body plus the contact grid, and PNGs.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import meshio
import numpy as np
import pytest
from cli_checks import assert_refused, one_line, summary_value

from fegear.case_files import load_case
from fegear.cli import main

REPO = Path(__file__).resolve().parents[1]
CASE = REPO / "cases" / "hertz_scene.toml"
TEXT = CASE.read_text(encoding="utf-8")


def test_shipped_case_loads():
    case = load_case(CASE)
    sc = case.scene
    assert case.name == "hertz_scene"
    assert sc.force_N == 2000.0
    assert sc.roller_radii_mm == (20.0, 100.0)
    assert (sc.E_roller_MPa, sc.E_block_MPa) == (206000.0, 206000.0)
    assert (sc.nu_roller, sc.nu_block) == (0.3, 0.3)
    assert sc.symmetry == "quarter"
    assert case.level == 3
    assert case.study_levels == ()


def _edit(old: str, new: str) -> str:
    assert old in TEXT, old
    return TEXT.replace(old, new, 1)


# (id, case text, words the one-line message must contain)
BAD_CASES = [
    ("missing force", _edit("force_N = 2000.0\n", ""), ["load.force_N", "required"]),
    ("force in kN", _edit("force_N = 2000.0", "force_kN = 2.0"), ["load.force_kN", "force_N"]),
    ("negative force", _edit("force_N = 2000.0", "force_N = -2000.0"), ["force_N", "-2000"]),
    ("zero force", _edit("force_N = 2000.0", "force_N = 0.0"), ["force_N", "> 0"]),
    ("nan force", _edit("force_N = 2000.0", "force_N = nan"), ["load.force_N", "finite"]),
    ("force as text", _edit("force_N = 2000.0", 'force_N = "2000"'), ["load.force_N", "number"]),
    ("radii as text", _edit("radii_mm = [20.0, 100.0]", 'radii_mm = "20, 100"'), ["radii_mm"]),
    ("three radii", _edit("[20.0, 100.0]", "[20.0, 100.0, 5.0]"), ["roller.radii_mm"]),
    ("zero radius", _edit("[20.0, 100.0]", "[0.0, 100.0]"), ["roller.radii_mm[0]"]),
    ("nu 0.5", _edit("nu = 0.3", "nu = 0.5"), ["nu", "(-1, 0.5)"]),
    ("unknown key", _edit("[block]\n", '[block]\ncolour = "red"\n'), ["block.colour"]),
    ("unknown section", TEXT + "\n[loads]\nforce_N = 1.0\n", ["loads", "[load]"]),
    ("missing section", _edit("[load]\nforce_N = 2000.0\n", ""), ["load", "required"]),
    ("bad TOML", _edit("force_N = 2000.0", "force_N = "), ["TOML", "line"]),
    ("level as float", _edit("level = 3 ", "level = 3.0 "), ["mesh.level", "integer"]),
    ("level too high", _edit("level = 3 ", "level = 9 "), ["mesh.level", "9"]),
    ("unknown symmetry", _edit('"quarter"', '"half"'), ["mesh.symmetry", "half"]),
]


@pytest.mark.parametrize(
    ("text", "words"), [c[1:] for c in BAD_CASES], ids=[c[0] for c in BAD_CASES]
)
def test_malformed_case_is_refused_with_one_line(tmp_path, capsys, text, words):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out)])
    assert_refused(code, capsys.readouterr().err, words)
    assert not out.exists()  # refused before any work


@pytest.mark.parametrize(
    ("argv", "word"),
    [
        (["--level", "9"], "--level"),
        (["--study", "0,x"], "--study"),
    ],
)
def test_bad_command_line_values_are_refused(tmp_path, capsys, argv, word):
    code = main(["run", str(CASE), "--out", str(tmp_path / "out"), *argv])
    err = capsys.readouterr().err
    assert code == 2, err
    assert word in one_line(err)


def test_missing_case_file_is_refused(tmp_path, capsys):
    code = main(["run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    assert "nope.toml" in one_line(err)


# --------------------------------------------------------------------------------------------
# End to end
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def level0_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("run_level0")
    code = main(["run", str(CASE), "--level", "0", "--out", str(out), "-q"])
    return code, out


def test_run_writes_the_summary(level0_run):
    code, out = level0_run
    assert code == 0
    doc = json.loads((out / "summary.json").read_text())
    assert summary_value(doc, "inputs.force_N") == 2000.0
    # Principal radii of each body, [Rx, Ry]; the block is flat.
    assert summary_value(doc, "inputs.radii_mm") == [[20.0, 100.0], [None, None]]
    assert summary_value(doc, "inputs.E_MPa") == [206000.0, 206000.0]
    assert summary_value(doc, "inputs.nu") == [0.3, 0.3]
    for key in ("p0_MPa", "a_mm", "b_mm"):
        fe, ref = summary_value(doc, "result." + key), summary_value(doc, "hertz." + key)
        assert math.isfinite(fe) and ref > 0
        # Level 0 (6 cells across 2b) is within ~2.5 % of Hertz (see test_hertz_scene.py).
        assert abs(fe / ref - 1) < 0.04, (key, fe, ref)
    # The Hertz reference of the nominal scene (closed form, independent of the mesh).
    assert summary_value(doc, "hertz.p0_MPa") == pytest.approx(1447.7, rel=1e-4)
    assert summary_value(doc, "hertz.a_mm") == pytest.approx(1.3807, rel=1e-4)
    assert summary_value(doc, "hertz.b_mm") == pytest.approx(0.47773, rel=1e-4)
    assert summary_value(doc, "levels") == []  # no study asked for
    # The whole force is transmitted (the quarter model, scaled back).
    assert summary_value(doc, "result.total_force_N") == pytest.approx(2000.0, rel=1e-9)
    # Level 0 is too coarse for percent accuracy, and the summary says so.
    assert any("cells across the minor axis" in w for w in summary_value(doc, "result.warnings"))


def test_run_writes_readable_vtu_files(level0_run):
    code, out = level0_run
    assert code == 0
    cells = meshio.read(out / "contact_cells.vtu")
    force = np.asarray(cells.cell_data["force_N"][0])
    pressure = np.asarray(cells.cell_data["pressure_MPa"][0])
    assert np.all(force >= 0) and np.all(pressure >= 0)
    # The contact grid of the quarter model carries a quarter of the 2000 N, to round-off.
    assert abs(4 * force.sum() - 2000.0) <= 1e-9 * 2000.0
    doc = json.loads((out / "summary.json").read_text())
    assert pressure.max() == pytest.approx(doc["result"]["p_max_cell_MPa"], rel=1e-12)
    for body in ("block", "roller"):
        m = meshio.read(out / f"{body}.vtu")
        assert "tetra" in m.cells_dict
        u = np.asarray(m.point_data["displacement_mm"])
        p = np.asarray(m.point_data["pressure_MPa"])
        assert u.shape == (len(m.points), 3) and p.shape == (len(m.points),)
        assert np.all(np.isfinite(u)) and np.all(np.isfinite(p))
        # The contact pressure shows on the contact face, up to the largest cell pressure.
        assert 0 < p.max() <= pressure.max() * (1 + 1e-12), body
    # At the first point of contact (the origin) the block sinks and the roller rises; together
    # they make up the rigid approach (the gap there closes). The node sits at the corner of
    # the central cells, not at their quadrature points: 5 %.
    block, roller = meshio.read(out / "block.vtu"), meshio.read(out / "roller.vtu")
    ib = np.argmin(np.linalg.norm(block.points, axis=1))
    ir = np.argmin(np.linalg.norm(roller.points, axis=1))
    assert np.linalg.norm(block.points[ib]) < 1e-9 and np.linalg.norm(roller.points[ir]) < 1e-9
    w_block = -block.point_data["displacement_mm"][ib, 2]
    w_roller = roller.point_data["displacement_mm"][ir, 2]
    assert w_block > 0 and w_roller > 0, (w_block, w_roller)
    approach = doc["result"]["approach_mm"]
    assert w_block + w_roller == pytest.approx(approach, rel=0.05)


def test_run_draws_the_pressure_map(level0_run):
    code, out = level0_run
    assert code == 0
    png = out / "pressure_map.png"
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not (out / "convergence.png").exists()  # only with a study


def test_study_writes_the_level_table_and_the_convergence_plot(tmp_path):
    out = tmp_path / "study"
    code = main(["run", str(CASE), "--level", "0", "--study", "0,1", "--out", str(out), "-q"])
    assert code == 0
    doc = json.loads((out / "summary.json").read_text())
    rows = doc["levels"]
    assert [r["level"] for r in rows] == [0, 1]
    assert [r["cells_across_minor"] for r in rows] == [6, 8]
    units = {"p0": "p0_MPa", "a": "a_mm", "b": "b_mm"}
    for row in rows:
        for key, col in units.items():
            # Each row's error is its value against the Hertz reference of the summary.
            expected = row[col] / doc["hertz"][col] - 1
            assert row[f"error_{key}"] == pytest.approx(expected, abs=1e-12)
    assert set(doc["convergence_rate"]) <= {"p0", "a", "b"} and "a" in doc["convergence_rate"]
    png = out / "convergence.png"
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# --------------------------------------------------------------------------------------------
# Regressions: swapped radii refused at load time; errors name the case-file key
# --------------------------------------------------------------------------------------------


def test_swapped_radii_are_refused_when_the_case_loads(tmp_path, capsys):
    path = tmp_path / "swapped.toml"
    path.write_text(_edit("[20.0, 100.0]", "[100.0, 20.0]"), encoding="utf-8")
    code = main(["run", str(path), "--level", "0", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    assert "roller.radii_mm" in one_line(err)


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("force_N = 2000.0", "force_N = -2000.0", "load.force_N"),
        ("nu = 0.3", "nu = 0.5", "roller.nu"),
    ],
)
def test_scene_errors_name_the_case_file_key(tmp_path, capsys, old, new, field):
    path = tmp_path / "bad.toml"
    path.write_text(_edit(old, new), encoding="utf-8")
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    assert one_line(capsys.readouterr().err).startswith(f"fegear: error: {field} = ")
