"""Gear-pair cases and ``fegear run`` on them (issue 8; docs/conventions.md, docs/architecture.md,
docs/testing.md).

- Every case file in ``cases/`` loads and validates (fast); malformed gear cases end with one
  line on stderr naming the problem and exit code 2, before any work.
- End to end on the FZG spur pair at level 0 (default suite): in ``tests/test_api.py``, beside
  the API's run of the same case, whose sectors, operators and checks it reads.
- Smoke runs: the spiral bevel cases (unloaded TCA of ΔE by default, of the others ``slow``;
  loaded at hybrid: ``slow``) and the face-gear cases and the no-argument main job (``slow``:
  ~1 min cold each).
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import pytest
from cli_checks import assert_refused, one_line

from fegear.case_files import load_case
from fegear.cli import main
from fegear.io.gear_case import GearCase, parse_gear_case
from fegear.io.seed import SEED_CASE_TOML, seed_case
from fegear.scenes.hertz_case import HertzCase

REPO = Path(__file__).resolve().parents[1]
CASES = sorted((REPO / "cases").glob("*.toml"))
FZG = REPO / "cases" / "fzg_spur.toml"
FACE_GEAR = REPO / "cases" / "face_gear_nominal.toml"
BEVEL = REPO / "cases" / "spiral_bevel_nominal.toml"


# --------------------------------------------------------------------------------------------
# Every shipped case loads
# --------------------------------------------------------------------------------------------


def test_the_issue_cases_are_shipped():
    names = {p.stem for p in CASES}
    expected = {
        "hertz_scene",
        "fzg_spur",
        "face_gear_nominal",
        "face_gear_dgamma_minus",
        "face_gear_dgamma_plus",
        "face_gear_load_light",
        "face_gear_load_moderate",
        "face_gear_load_heavy",
        "spiral_bevel_nominal",
        "spiral_bevel_dE",
        "spiral_bevel_dP",
        "spiral_bevel_dG",
        "spiral_bevel_dgamma",
    }
    assert expected <= names, expected - names


@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_every_case_loads_and_validates(path):
    case = load_case(path)
    assert case.name == path.stem  # one file per scenario, named as its file
    if isinstance(case, HertzCase):
        return
    assert isinstance(case, GearCase)
    assert case.torque2_Nmm > 0 and math.isfinite(case.torque2_Nmm)
    # issue 21: every gear case runs the fidelity that resolves the patch at its level
    assert case.fidelity == "hybrid" and case.level == 0


def test_seed_loads_and_errors_are_the_issue_values():
    """Torques on the face gear 5e5, 3e6, 6e6 N·mm; Δγ = ∓0.02°; pinion torque 350.14 N·m."""
    t2 = {
        n: load_case(REPO / "cases" / f"face_gear_load_{n}.toml").torque2_Nmm
        for n in ("light", "moderate", "heavy")
    }
    assert t2 == {"light": 5e5, "moderate": 3e6, "heavy": 6e6}
    nominal = load_case(FACE_GEAR)
    # pinion torque × N2/N1 (quasi-static, no friction): exact in binary to round-off
    assert nominal.torque2_Nmm == pytest.approx(350.14e3 * 160 / 25, rel=1e-15)
    for sign, name in ((-1, "minus"), (1, "plus")):
        c = load_case(REPO / "cases" / f"face_gear_dgamma_{name}.toml")
        assert c.errors.dgamma_deg == sign * 0.02
        assert c.pair == nominal.pair and c.torque2_Nmm == nominal.torque2_Nmm
    bevel = {n: load_case(REPO / "cases" / f"spiral_bevel_{n}.toml").errors
             for n in ("dE", "dP", "dG", "dgamma")}  # fmt: skip
    assert (bevel["dE"].dE_mm, bevel["dP"].dA1_mm, bevel["dG"].dA2_mm) == (0.05, 0.05, 0.05)
    assert bevel["dgamma"].dgamma_deg == 0.02


def test_built_in_seed_case_is_the_nominal_case_file():
    from dataclasses import replace

    seed, file = seed_case(), load_case(FACE_GEAR)
    assert replace(seed, source=file.source) == file
    assert tomllib.loads(SEED_CASE_TOML)["case"]["kind"] == "face_gear"


# --------------------------------------------------------------------------------------------
# Malformed gear cases: one line, exit 2, nothing written
# --------------------------------------------------------------------------------------------

FZG_TEXT = FZG.read_text(encoding="utf-8")
FG_TEXT = FACE_GEAR.read_text(encoding="utf-8")
BEVEL_TEXT = BEVEL.read_text(encoding="utf-8")


def _edit(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


# (id, case text, words the one-line message must contain)
BAD_GEAR_CASES = [
    ("missing module", _edit(FZG_TEXT, "module_mm = 4.5\n", ""), ["pair.module_mm", "required"]),
    ("missing teeth", _edit(FG_TEXT, "n_pinion = 25\n", ""), ["pair.n_pinion", "required"]),
    ("module in inches", _edit(FZG_TEXT, "module_mm = 4.5", "module_in = 0.177"),
     ["pair.module_in", "did you mean 'module_mm'"]),
    ("torque in kNm", _edit(FZG_TEXT, "torque2_Nm = 200.0", "torque2_kNm = 0.2"),
     ["load.torque2_kNm", "did you mean 'torque2_Nm'"]),
    ("angle in rad", _edit(FG_TEXT, "dgamma_deg = 0.0", "dgamma_rad = 0.0"),
     ["errors.dgamma_rad", "dgamma_deg"]),
    ("negative teeth", _edit(FZG_TEXT, "[16, 24]", "[-16, 24]"), ["pair.teeth[0]", "-16", ">= 5"]),
    ("negative face-gear teeth", _edit(FG_TEXT, "n_face_gear = 160", "n_face_gear = -160"),
     ["pair.n_face_gear", "-160"]),
    ("zero bevel teeth", _edit(BEVEL_TEXT, "n_gear = 36", "n_gear = 0"), ["pair.n_gear", "0"]),
    ("teeth as float", _edit(FZG_TEXT, "[16, 24]", "[16.0, 24]"), ["pair.teeth[0]", "integer"]),
    ("one tooth count", _edit(FZG_TEXT, "[16, 24]", "[16]"), ["pair.teeth", "two integers"]),
    ("unknown key", _edit(FZG_TEXT, "[pair]\n", '[pair]\ncolour = "red"\n'), ["pair.colour"]),
    ("key of another kind", _edit(FZG_TEXT, "da_mm = 0.0", "dgamma_deg = 0.0"),
     ["errors.dgamma_deg", "kind 'spur'"]),
    ("unknown section", FZG_TEXT + "\n[loads]\ntorque2_Nm = 1.0\n", ["loads", "[load]"]),
    ("missing section", _edit(FZG_TEXT, "[load]\ntorque2_Nm = 200.0", ""), ["load", "required"]),
    ("bad TOML", _edit(FZG_TEXT, "module_mm = 4.5", "module_mm = "), ["TOML", "line"]),
    ("two torques",
     _edit(FZG_TEXT, "torque2_Nm = 200.0", "torque2_Nm = 200.0\npinion_torque_Nm = 1.0"),
     ["load", "exactly one"]),
    ("no torque", _edit(FZG_TEXT, "torque2_Nm = 200.0", "speed_rpm = 100.0"), ["exactly one"]),
    ("negative torque", _edit(FZG_TEXT, "torque2_Nm = 200.0", "torque2_Nm = -200.0"),
     ["load.torque2_Nm", "-200", "> 0"]),
    ("nan module", _edit(FZG_TEXT, "module_mm = 4.5", "module_mm = nan"),
     ["pair.module_mm", "finite"]),
    ("pressure angle", _edit(FZG_TEXT, "pressure_angle_deg = 20.0", "pressure_angle_deg = 50.0"),
     ["pair.pressure_angle_deg", "50", "[10, 35]"]),
    ("radii swapped", _edit(FG_TEXT, "outer_radius_mm = 560.0", "outer_radius_mm = 400.0"),
     ["pair.outer_radius_mm", "inner_radius_mm"]),
    ("level", _edit(FZG_TEXT, "level = 0", "level = 7"), ["analysis.level", "7", "[0, 4]"]),
    ("fidelity", _edit(FZG_TEXT, 'fidelity = "hybrid"', 'fidelity = "exact"'),
     ["analysis.fidelity", "exact"]),
    ("positions", _edit(FZG_TEXT, "n_positions = 9", "n_positions = 1"),
     ["analysis.n_positions", "[2, 400]"]),
    ("nu", _edit(FZG_TEXT, "nu = 0.3", "nu = 0.5"), ["material.nu", "(-1, 0.5)"]),
    ("unknown kind", _edit(FZG_TEXT, 'kind = "spur"', 'kind = "worm"'), ["case.kind", "worm"]),
    ("shaper too small", _edit(FG_TEXT, "n_shaper = 27", "n_shaper = 25"),
     ["pair.n_shaper", "n_pinion"]),
]  # fmt: skip


@pytest.mark.parametrize(
    ("text", "words"), [c[1:] for c in BAD_GEAR_CASES], ids=[c[0] for c in BAD_GEAR_CASES]
)
def test_malformed_gear_case_is_refused_with_one_line(tmp_path, capsys, text, words):
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
        (["--fidelity", "exact"], "--fidelity"),
        (["--study", "0,1"], "--study"),
        (["--workers", "0"], "--workers"),
    ],
)
def test_bad_command_line_values_for_a_gear_case(tmp_path, capsys, argv, word):
    out = tmp_path / "out"
    code = main(["run", str(FZG), "--out", str(out), *argv])
    err = capsys.readouterr().err
    assert code == 2, err
    assert word in one_line(err)
    assert not out.exists()


def test_design_errors_name_the_case_key():
    """A geometry refusal (undercut, pointed tooth, …) names the case-file key, not the
    geometry's field; a pair given only in memory goes through the same schema."""
    from fegear.errors import InputError
    from fegear.pipeline.pair import build_pair

    data = tomllib.loads(_edit(FZG_TEXT, "profile_shift = [0.1817, 0.1715]",
                               "profile_shift = [0.1817, 1.9]"))  # fmt: skip
    case = parse_gear_case(data, "mem.toml")
    # x2 = 1.9 makes the gear tooth pointed below its tip circle (the tip radius follows from
    # the shift): the refusal names the member's shift and the shift of a pointed tip
    with pytest.raises(InputError, match=r"^pair\.profile_shift\[1\] = 1\.9 .*<= 1\.3923") as e:
        build_pair(case)
    assert "pointed" in str(e.value)
    data = tomllib.loads(_edit(FG_TEXT, "n_shaper = 27", "n_shaper = 25"))
    with pytest.raises(InputError, match=r"^pair\.n_shaper = 25 "):
        build_pair(parse_gear_case(data, "mem.toml"))


# --------------------------------------------------------------------------------------------
# Spiral bevel: unloaded TCA; the loaded analysis is refused with a clear message
# --------------------------------------------------------------------------------------------


@pytest.mark.slow  # a loaded fe cycle of the face gear: minutes
def test_fe_says_plainly_that_its_cells_are_wider_than_the_patch(tmp_path, capsys):
    """The loaded analysis of the spiral bevel pair at ``fe`` level 0 (5 positions): it runs and
    balances the torque, but its 2.2 mm cells are wider than the 0.4-0.6 mm patch at every
    position, so every position is degenerate, the headline TE p-p and p_max are null with the
    reason, and the terminal says why (issue 21)."""
    case = tmp_path / "bevel.toml"
    case.write_text(_edit(BEVEL_TEXT, "n_positions = 13", "n_positions = 5"), "utf-8")
    out = tmp_path / "out"
    assert main(["run", str(case), "--fidelity", "fe", "--out", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert "warning: fe: the contact cells" in err and "wider than the loaded patch" in err
    doc = json.loads((out / "summary.json").read_text())
    c = doc["cycle"]
    # the solver enforces the torque balance: round-off only
    assert c["max_equilibrium_residual"] < 1e-9
    assert c["te_pp_loaded_arcsec"] is None and "degenerate" in c["te_pp_loaded_reason"]
    assert c["p_max_MPa"] is None and c["p_max_reason"]
    assert c["te_pp_loaded_positions_used"] == 0
    assert {e["status"] for e in c["excluded_positions"]} == {"degenerate"}
    for p in doc["positions"]:
        assert p["status"] == "degenerate" and "across its patch" in p["status_reason"]
        assert all(not q["resolved"] for q in p["pairs"] if q["in_contact"])


BEVEL_CASES = sorted((REPO / "cases").glob("spiral_bevel_*.toml"))


# dE by default; dG and dP (the same machinery, one more unloaded cycle each) slow. The nominal
# case slow too: its unloaded TCA (13 positions, every number of its summary) is
# tests/test_validation.py::test_the_nominal_cases_give_the_reference_tca[spiral_bevel_nominal];
# and dgamma: the TE of its installation (Δγ = +0.02°) is checked against the designed parabola
# by tests/test_tca_spiral_bevel.py::test_errors_move_the_pattern_as_theory_says. The command
# line and its pictures are those of dE here.
@pytest.mark.parametrize(
    "path",
    [
        pytest.param(p, marks=pytest.mark.slow) if p.stem != "spiral_bevel_dE" else p
        for p in BEVEL_CASES
    ],
    ids=[p.stem for p in BEVEL_CASES],
)
def test_spiral_bevel_case_smoke(tmp_path, path):
    """Unloaded TCA of each spiral bevel case at 5 positions (the machine-setting synthesis,
    ~15 s, runs once per process for the shared blank data); the cases ask for ``hybrid``, run
    loaded in ``test_spiral_bevel_case_hybrid_smoke`` (slow) and, for the nominal case, in
    ``tests/test_reliability.py``."""
    case = tmp_path / path.name
    case.write_text(_edit(path.read_text("utf-8"), "n_positions = 13", "n_positions = 5"), "utf-8")
    out = tmp_path / "out"
    assert main(["run", str(case), "--fidelity", "tca", "--out", str(out), "-q"]) == 0
    doc = json.loads((out / "summary.json").read_text())
    assert doc["fidelity"] == "tca"
    assert 0 < doc["cycle"]["te_pp_unloaded_arcsec"] < 60  # designed parabola ~8 arcsec
    assert doc["cycle"]["te_pp_loaded_arcsec"] is None
    for name in ("te", "bearing_pattern"):
        assert (out / f"{name}.png").is_file()


@pytest.mark.slow
@pytest.mark.parametrize("path", BEVEL_CASES, ids=[p.stem for p in BEVEL_CASES])
def test_spiral_bevel_case_hybrid_smoke(tmp_path, path):
    """Each spiral bevel case as shipped (hybrid level 0) at 5 positions (~40 s cold each: every
    installation has its own contact zone, so its own sectors)."""
    case = tmp_path / path.name
    case.write_text(_edit(path.read_text("utf-8"), "n_positions = 13", "n_positions = 5"), "utf-8")
    out = tmp_path / "out"
    assert main(["run", str(case), "--out", str(out), "-q"]) == 0
    doc = json.loads((out / "summary.json").read_text())
    c = doc["cycle"]
    assert doc["fidelity"] == "hybrid" and c["max_equilibrium_residual"] < 1e-9
    assert c["te_pp_loaded_positions_used"] == 5 and c["p_max_MPa"] > 0


# --------------------------------------------------------------------------------------------
# Face gear (slow: ~1 min cold for meshing and operators, then cached within the session)
# --------------------------------------------------------------------------------------------

FACE_GEAR_CASES = sorted((REPO / "cases").glob("face_gear_*.toml"))


@pytest.mark.slow
@pytest.mark.parametrize("path", FACE_GEAR_CASES, ids=[p.stem for p in FACE_GEAR_CASES])
def test_face_gear_case_smoke(tmp_path, path):
    out = tmp_path / "out"
    code = main(["run", str(path), "--level", "0", "--out", str(out), "-q"])
    assert code == 0
    doc = json.loads((out / "summary.json").read_text())
    c = doc["cycle"]
    assert doc["fidelity"] == "hybrid" and c["max_equilibrium_residual"] < 1e-9
    assert c["p_max_MPa"] > 0 and c["contact_ratio_loaded"] >= 1.0
    assert c["positions_without_contact"] == 0


def test_face_gear_tca_reports_the_whole_path(tmp_path):
    """Seed face gear, ``--fidelity tca``: on the whole generated flank one pair's contact runs
    from the face-gear tip to the pinion tip, never onto the face gear's flank bottom (its fillet
    limit), with a contact ratio above 1; ``summary.json`` says so (issue 20)."""
    out = tmp_path / "out"
    case = REPO / "cases" / "face_gear_nominal.toml"
    assert main(["run", str(case), "--fidelity", "tca", "--out", str(out), "-q"]) == 0
    doc = json.loads((out / "summary.json").read_text())
    c = doc["cycle"]
    assert c["path_ends"] == ["gear:tip", "pinion:tip"]
    # measured 1.554 (ε p_b = 28.10 mm in space) and 13.11 mm on the face-gear flank
    assert 1.5 < c["contact_ratio_unloaded"] < 1.6
    assert 12.5 < c["path_length_mm"] < 13.7
    p_b = math.pi * 6.35 * math.cos(math.radians(25.0))
    # the involute pinion unrolls the path in space along its plane of action: ε p_b
    assert c["path_length_in_space_mm"] == pytest.approx(
        c["contact_ratio_unloaded"] * p_b, rel=1e-4
    )
    edges = {e for p in doc["positions"] for q in p["pairs"] for e in q["edge"].split(",") if e}
    assert "gear:root" not in edges  # the face-gear fillet limit is never touched


@pytest.mark.slow
def test_no_argument_main_job_writes_all_outputs(tmp_path, monkeypatch):
    """``fegear run`` with no case: the seed face gear, hybrid level 0, 25 positions."""
    monkeypatch.chdir(tmp_path)
    assert main(["run", "-q"]) == 0
    out = tmp_path / "out"
    doc = json.loads((out / "summary.json").read_text())
    assert doc["case"] == "face_gear_nominal" and doc["kind"] == "face_gear"
    assert doc["fidelity"] == "hybrid" and doc["level"] == 0
    assert len(doc["positions"]) == 25
    for f in doc["files"]:
        assert (out / f).is_file(), f
    import pyvista as pv

    reader = pv.get_reader(str(out / "cycle.pvd"))
    assert reader.number_time_points == 25
    reader.set_active_time_value(reader.time_values[12])
    cells = reader.read()[2]
    total = doc["positions"][12]["total_force_N"]
    assert abs(cells.cell_data["force_N"].sum() - total) <= 1e-6 * total


def test_fzg_hertz_fidelity_runs_from_the_command_line(tmp_path):
    out = tmp_path / "hertz"
    assert main(["run", str(FZG), "--fidelity", "hertz", "--out", str(out), "-q"]) == 0
    doc = json.loads((out / "summary.json").read_text())
    cyc = doc["cycle"]
    # one scalar torque equation solved to 1e-14: balance to round-off
    assert cyc["max_equilibrium_residual"] < 1e-9
    assert cyc["te_pp_loaded_arcsec"] > 0.0 and cyc["p_max_MPa"] > 0.0
    for pos in doc["positions"]:
        shares = [p["load_share"] for p in pos["pairs"]]
        assert abs(sum(shares) - 1.0) < 1e-9  # the shares of one balanced torque


def test_fzg_hybrid_fidelity_runs_from_the_command_line(tmp_path):
    out = tmp_path / "hybrid"
    argv = ["run", str(FZG), "--fidelity", "hybrid", "--out", str(out), "-q", "--workers", "1"]
    assert main(argv) == 0
    doc = json.loads((out / "summary.json").read_text())
    assert doc["cycle"]["max_equilibrium_residual"] < 1e-9  # the solver balances the torque
    assert doc["fidelity"] == "hybrid" and doc["level"] == 0  # the FE level under the hybrid
    assert (out / "cycle.pvd").is_file()
