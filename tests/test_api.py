"""The public Python API (issue 22): ``fegear.load_case``, ``case.replace``/``with_errors``,
``fegear.run`` and its typed results, ``result.write`` (the files of ``fegear run``), the flank
views and ``fegear plot``.

- Cases are frozen and validated like case files: every change goes through the case-file
  parser, so a bad field raises the very ``InputError`` a bad case file raises.
- A result holds the numbers of its ``summary.json`` (both are its result model) and writes
  the same files as the command line.
- The flank views hold the solver's loaded cells on each member's flank: their forces add up to
  the position's, and on the FZG gear the face coordinate is the cells' axial position.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_checks import summary_value

import fegear
from fegear.case_files import parse_case
from fegear.cli import main
from fegear.errors import InputError

REPO = Path(__file__).resolve().parents[1]
CASES = sorted((REPO / "cases").glob("*.toml"))
FZG = REPO / "cases" / "fzg_spur.toml"
FACE_GEAR = REPO / "cases" / "face_gear_nominal.toml"
HERTZ = REPO / "cases" / "hertz_scene.toml"
N_FZG = 5


# --------------------------------------------------------------------------------------------
# The package top
# --------------------------------------------------------------------------------------------


def test_top_level_names_resolve():
    for name in fegear.__all__:
        assert getattr(fegear, name) is not None, name
    assert fegear.GearCase is fegear.io.gear_case.GearCase
    assert set(fegear.__all__) <= set(dir(fegear))


def test_import_fegear_stays_light():
    """``import fegear`` loads no analysis code (the CLI's ``--version`` and spawned sweep
    workers import it): the API is imported on first use."""
    code = "import sys, fegear; print(sorted(m for m in sys.modules if m.startswith('fegear')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "['fegear']", out.stdout


# --------------------------------------------------------------------------------------------
# Cases: frozen, changed only through the case-file validation
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_case_document_round_trip(path):
    case = fegear.load_case(path)
    assert parse_case(case.to_document(), source=case.source) == case  # exact
    assert case.replace() == case


def test_with_errors_changes_the_named_errors_only():
    case = fegear.load_case(FACE_GEAR)
    a = case.with_errors(dgamma_deg=0.02)
    b = a.with_errors(dE_mm=0.1)
    assert (b.errors.dgamma_deg, b.errors.dE_mm, b.errors.dA1_mm) == (0.02, 0.1, 0.0)
    assert case.errors.dgamma_deg == 0.0  # the case itself is frozen
    assert b.replace(errors={}).errors == case.errors
    # the same case as the shipped file with the seed's error (the file differs in its name)
    shipped = fegear.load_case(REPO / "cases" / "face_gear_dgamma_plus.toml")
    assert a.replace(name=shipped.name, description=shipped.description, source=shipped.source) == (
        shipped
    )
    with pytest.raises(AttributeError):
        case.level = 3  # frozen dataclass


def _file_error(tmp_path, old: str, new: str) -> str:
    text = FACE_GEAR.read_text(encoding="utf-8")
    assert old in text
    p = tmp_path / "bad.toml"
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    with pytest.raises(InputError) as info:
        fegear.load_case(p)
    return str(info.value)


@pytest.mark.parametrize(
    ("change", "old", "new"),
    [
        ({"level": 7}, "level = 0", "level = 7"),
        ({"n_positions": 1}, "n_positions = 25", "n_positions = 1"),
        ({"fidelity": "exact"}, 'fidelity = "hybrid"', 'fidelity = "exact"'),
        ({"nu": 0.5}, "nu = 0.3", "nu = 0.5"),
        ({"pinion_torque_Nm": -1.0}, "pinion_torque_Nm = 350.14", "pinion_torque_Nm = -1.0"),
    ],
)
def test_replace_raises_what_the_case_file_raises(tmp_path, change, old, new):
    case = fegear.load_case(FACE_GEAR)
    with pytest.raises(InputError) as info:
        case.replace(**change)
    assert str(info.value) == _file_error(tmp_path, old, new)


def test_with_errors_raises_what_the_case_file_raises(tmp_path):
    case = fegear.load_case(FACE_GEAR)
    with pytest.raises(InputError) as info:
        case.with_errors(dgamma_rad=0.02)
    assert str(info.value) == _file_error(tmp_path, "dgamma_deg = 0.0", "dgamma_rad = 0.02")
    assert "did you mean 'dgamma_deg'" in str(info.value)
    with pytest.raises(InputError, match=r"^errors\.da_mm .*kind 'face_gear'"):
        case.with_errors(da_mm=0.1)  # a parallel-axes error on intersecting axes


def test_replace_refuses_unknown_and_fixed_fields():
    case = fegear.load_case(FACE_GEAR)
    with pytest.raises(InputError, match="did you mean 'level'"):
        case.replace(levle=1)
    with pytest.raises(InputError, match=r"^kind = 'spur'"):
        case.replace(kind="spur")
    t = case.replace(torque2_Nm=100.0)  # a load replaces the case's torque key
    assert (t.load_key, t.torque2_Nmm) == ("torque2_Nm", 100e3)
    assert case.replace(level=np.int64(2)).level == 2  # numpy scalars are numbers


def test_hertz_case_replace():
    case = fegear.load_case(HERTZ)
    assert case.replace(force_N=1000.0).scene.force_N == 1000.0
    with pytest.raises(InputError, match=r"^load\.force_N = -1"):
        case.replace(force_N=-1.0)
    with pytest.raises(InputError, match="did you mean 'force_N'"):
        case.replace(force_n=1.0)


@pytest.mark.parametrize(
    ("kw", "field"),
    [
        ({"fidelity": "exact"}, "fidelity"),
        ({"level": 9}, "level"),
        ({"workers": 0}, "workers"),
        ({"study": (0, 1)}, "study"),
        ({"backend": "mumps"}, "backend"),
    ],
)
def test_run_refuses_bad_arguments_before_any_work(kw, field):
    with pytest.raises(InputError) as info:
        fegear.run(fegear.load_case(FZG), **kw)
    assert info.value.field == field


# --------------------------------------------------------------------------------------------
# A loaded run: typed result = summary.json; write() = the command's files
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def fzg(tmp_path_factory):
    """FZG at hybrid level 0, 5 positions: through the API (written to ``api/``) and through
    the command line (``cli/``), the second run warm."""
    root = tmp_path_factory.mktemp("api")
    case = fegear.load_case(FZG).replace(n_positions=N_FZG)
    result = fegear.run(case, workers=1)
    api_files = result.write(root / "api")
    path = root / "fzg.toml"
    text = FZG.read_text(encoding="utf-8").replace("n_positions = 9", f"n_positions = {N_FZG}")
    path.write_text(text, encoding="utf-8")
    code = main(["run", str(path), "--out", str(root / "cli"), "-q", "--workers", "1"])
    return result, api_files, root, code


def test_result_holds_the_summary_numbers(fzg):
    result, _, root, _ = fzg
    doc = json.loads((root / "api" / "summary.json").read_text())
    c = doc["cycle"]
    assert result.fidelity == doc["fidelity"] == "hybrid" and result.level == 0
    keys = ("te_pp_unloaded_arcsec", "te_pp_loaded_arcsec", "contact_ratio_loaded", "p_max_MPa",
            "p_max_edge_MPa", "te_pp_loaded_positions_used", "n_positions")  # fmt: skip
    for key in keys:
        assert getattr(result.cycle, key) == c[key], key  # the same model: exact
    assert result.cycle.p_max_pair == tuple(c["p_max_at"]["pair"])
    assert result.checks.contact_ratio_unloaded == c["contact_ratio_unloaded"]
    assert result.checks.path_ends == tuple(c["path_ends"])
    assert result.warnings == tuple(doc["warnings"])
    assert len(result.positions) == len(doc["positions"]) == N_FZG
    for p, row in zip(result.positions, doc["positions"], strict=True):
        assert p.te_loaded_arcsec == row["te_loaded_arcsec"]
        assert p.status == row["status"]
        for q, qrow in zip(p.pairs, row["pairs"], strict=True):
            assert (q.load_share, q.force_N, q.p_max_MPa) == (
                qrow["load_share"], qrow["force_N"], qrow["p_max_MPa"])  # fmt: skip
        shares = sum(q.load_share for q in p.pairs)
        assert abs(shares - 1.0) < 1e-9  # the solver balances the torque: round-off
    assert doc["pattern"]["gear"]["face_mm"] == result.pattern["gear"].face_mm
    te = [p["te_loaded_arcsec"] for p in doc["positions"]]
    np.testing.assert_array_equal(result.te_loaded_arcsec, te)


def test_write_writes_the_files_of_the_command_line(fzg):
    from fegear.store.outputs import MANIFEST

    result, api_files, root, code = fzg
    assert code == 0
    api, cli = root / "api", root / "cli"
    names = sorted(
        str(p.relative_to(api)) for p in api.rglob("*") if p.is_file() and p.name != MANIFEST
    )  # the folder's list of its run's files is not one of them
    assert names == sorted(
        str(p.relative_to(cli)) for p in cli.rglob("*") if p.is_file() and p.name != MANIFEST
    )
    assert sorted(str(p.relative_to(api)) for p in api_files) == names
    a, b = (json.loads((d / "summary.json").read_text()) for d in (api, cli))
    for doc in (a, b):  # what differs between two runs of the same case: times, cache, source
        for key in ("timings_s", "cache", "versions"):
            doc.pop(key)
        doc["inputs"].pop("source")
        doc["inputs"].pop("name")
        doc.pop("case")
    assert a == b
    for f in sorted((api / "vtk").iterdir()):  # the same solver output, written the same way
        assert f.read_bytes() == (cli / "vtk" / f.name).read_bytes(), f.name
    # the command's run read everything from the cache the API's run built
    assert json.loads((cli / "summary.json").read_text())["cache"]["built"] == {}


def test_a_run_without_fields_has_the_numbers_and_writes_the_same_files(fzg, tmp_path):
    """``fields=False`` (a study reading numbers): no displacement field is computed, every
    number but the fields' mesh sizes is the full run's (the fields are read from the solved
    contact, never fed back), and ``write`` computes the fields it writes: the same files."""
    import dataclasses

    result, _, root, _ = fzg
    case = fegear.load_case(FZG).replace(n_positions=N_FZG)
    lean = fegear.run(case, workers=1, fields=False)
    assert lean.run.fields_pending and not lean.run.members
    assert not result.run.fields_pending and len(result.run.members) == 2
    assert lean.model.mesh == {} and set(result.model.mesh) == {"pinion", "gear"}
    assert lean.cycle == result.cycle and lean.checks == result.checks
    bare = [[dataclasses.replace(p, members=()) for p in r.positions] for r in (lean, result)]
    assert bare[0] == bare[1]
    lean.write(tmp_path / "lean")
    a, b = (json.loads((d / "summary.json").read_text()) for d in (tmp_path / "lean", root / "api"))
    for doc in (a, b):  # what differs between two runs of the same case: times, cache, source
        for key in ("timings_s", "cache", "versions"):
            doc.pop(key)
    assert a == b
    for f in sorted((root / "api" / "vtk").iterdir()):  # the same fields, written the same way
        assert f.read_bytes() == (tmp_path / "lean" / "vtk" / f.name).read_bytes(), f.name


def test_pvd_says_its_time_unit(fzg):
    _, _, root, _ = fzg
    text = (root / "api" / "cycle.pvd").read_text()
    assert "timestep = pinion angle phi1 (deg)" in text
    assert "3 pinion flank view, 4 gear flank view" in text


def test_flank_views_hold_the_loaded_cells_in_flank_coordinates(fzg):
    """Read back from the files: every loaded cell of both members, its force and pressure the
    solver's; the FZG gear's face coordinate is the axial position of the gear-side cell
    centres (an independent measure: the fixed frame's z)."""
    from fegear.output.flank_vtp import read_flank_vtp

    result, _, root, _ = fzg
    run = result.run
    for i, pos in enumerate(run.cycle.positions):
        loaded = [(c, p) for c, p in zip(pos.cells, pos.pressure, strict=True)]
        z = np.concatenate([(c.centers + c.gap[:, None] * c.normals)[p > 0, 2] for c, p in loaded])
        total = pos.solution.force.sum()
        for member in ("pinion", "gear"):
            frame, patch, t = read_flank_vtp(root / "api" / "vtk" / f"flank_{member}_{i:03d}.vtp")
            assert t == pytest.approx(math.degrees(pos.phi1), abs=1e-12)
            assert frame.member == member and frame.face_name == "axial position z (mm)"
            # float64 sums of the same forces in another order: round-off
            assert patch.force_N.sum() == pytest.approx(total, rel=1e-12)
            assert patch.pressure_MPa.max() == pytest.approx(pos.p_max_MPa, rel=1e-12)
            # the cells lie on the working flank: their centres inside the outline's box (to
            # the Newton tolerance, 1e-6 mm), a boundary cell reaching past it by at most half
            # its size (the contact grid keeps the cells whose centre is on the flank)
            lo, hi = frame.outline.min(axis=0), frame.outline.max(axis=0)
            c = patch.centres
            assert (c >= lo - 1e-6).all() and (c <= hi + 1e-6).all()
            reach = np.abs(patch.quads - c[:, None, :]).max(axis=1)  # (m, 2) half sizes
            assert (patch.quads.min(axis=1) >= lo - reach - 1e-6).all()
            assert (patch.quads.max(axis=1) <= hi + reach + 1e-6).all()
            if member == "gear":
                # the same points (the line hit along the normal from a point on the flank
                # stays there): to the Newton tolerance
                np.testing.assert_allclose(np.sort(patch.centres[:, 0]), np.sort(z), atol=1e-6)


def test_fegear_plot_draws_the_pattern_over_the_cycle(fzg, capsys):
    result, _, root, _ = fzg
    assert main(["plot", str(root / "api"), "--member", "gear"]) == 0
    png = root / "api" / "bearing_pattern_gear_flank.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = result.plot_pattern(root / "pinion.png", member="pinion")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code = main(["plot", str(root / "nothing-here")])
    assert code == 2 and "FOLDER" in capsys.readouterr().err


def test_compare_runs_table_and_pictures(fzg, tmp_path):
    result, _, _, _ = fzg
    text = fegear.table({"a": result, "b": result})
    rows = [r for r in text.splitlines() if r.startswith("| a |") or r.startswith("| b |")]
    assert len(rows) == 2 and "| +0.00 | +0.000 |" in rows[1]  # b against a: no shift
    for f in (fegear.plot_te, fegear.plot_patterns):
        assert f({"a": result}, tmp_path / f"{f.__name__}.png").read_bytes()[:4] == b"\x89PNG"


# --------------------------------------------------------------------------------------------
# End to end through `fegear run`: the FZG spur pair as shipped (hybrid level 0), 5 positions
# (was in tests/test_gear_cli.py; here the run reads what the API's run above built)
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def fzg_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("fzg")
    case = tmp_path_factory.mktemp("case") / "fzg.toml"
    text = FZG.read_text(encoding="utf-8")
    assert "n_positions = 9" in text
    case.write_text(text.replace("n_positions = 9", f"n_positions = {N_FZG}"), "utf-8")
    # --recompute: solved here although the API's run above is in the cache (read from the
    # cache, a run has no models timing, asserted below); its sectors, operators and checks
    # are read
    code = main(["run", str(case), "--level", "0", "--out", str(out), "-q", "--recompute"])
    return code, out


def test_fzg_run_writes_the_summary_keys(fzg_run):
    code, out = fzg_run
    assert code == 0
    doc = json.loads((out / "summary.json").read_text())
    assert doc["kind"] == "spur" and doc["fidelity"] == "hybrid" and doc["level"] == 0
    for key in ("te_pp_unloaded_arcsec", "te_pp_loaded_arcsec", "contact_ratio_loaded",
                "p_max_MPa"):  # fmt: skip
        v = summary_value(doc, f"cycle.{key}")
        assert isinstance(v, float) and math.isfinite(v), key
    assert len(doc["positions"]) == N_FZG
    # conjugate involute pair: no unloaded TE (invariant, to the TCA's round-off)
    assert summary_value(doc, "cycle.te_pp_unloaded_arcsec") < 1e-6
    # loaded: a lag (negative TE) at every position; one or two pairs (contact ratio 1.46)
    assert 1.0 <= summary_value(doc, "cycle.contact_ratio_loaded") <= 2.0
    for i, pos in enumerate(doc["positions"]):
        assert summary_value(pos, "te_loaded_arcsec") < 0
        # one cycle, 360/16 = 22.5 deg
        assert -12.0 <= summary_value(pos, "pinion_angle_deg") < 12.0
        shares = [summary_value(q, "load_share") for q in pos["pairs"]]
        # torque balance is enforced by the solver: round-off
        assert abs(sum(shares) - 1.0) < 1e-9, (i, shares)
        assert pos["solver"]["equilibrium_residual"] < 1e-9
        for q in pos["pairs"]:
            assert isinstance(q["edge_contact"], bool)
            assert q["p_max_MPa"] >= 0
            if q["in_contact"]:
                cp = np.array(q["contact_point_mm"])
                # fixed frame: pinion axis +z at the origin; the contact lies between the base
                # circle (r_b1 = 33.8 mm) and the tip circle (~41.6 mm) of the pinion
                r = math.hypot(cp[0], cp[1])
                assert 33.0 < r < 42.0 and abs(cp[2]) <= 7.0 + 1e-9, cp
            else:
                assert q["contact_point_mm"] is None
    assert doc["versions"]["fegear"] and doc["timings_s"]["models"] > 0
    assert doc["units"]["pressure"] == "MPa"
    # what the sectors modelled: every pair in contact at some position has a fine zone, and
    # 5 teeth hold the pairs -1, 0, +1 of a contact ratio of 1.46 with a neighbour each side
    zone = summary_value(doc, "cycle.contact_zone")
    modelled = {tuple(p) for p in zone["pairs"]}
    touching = {(q["pinion_tooth"], q["gear_tooth"]) for p in doc["positions"] for q in p["pairs"]}
    assert touching <= modelled and zone["sector_teeth"] == 5 and zone["gap_mm"] > 0
    # the headline p_max is the largest pressure away from the edges over the usable positions,
    # the edge value beside it (issue 21)
    usable = [p for p in doc["positions"] if p["status"] == "ok"]
    assert summary_value(doc, "cycle.te_pp_loaded_positions_used") == len(usable) == N_FZG
    assert summary_value(doc, "cycle.p_max_MPa") == max(
        q["p_interior_MPa"] for p in usable for q in p["pairs"] if q["p_interior_MPa"] is not None
    )
    edge = [q["p_edge_MPa"] for p in usable for q in p["pairs"] if q["p_edge_MPa"] is not None]
    assert summary_value(doc, "cycle.p_max_edge_MPa") == (max(edge) if edge else None)


def test_the_default_spur_run_reports_its_te_harmonics():
    """cases/fzg_spur.toml as shipped (9 positions; the sectors of the runs above): every
    position resolved, so the first three mesh orders of the loaded TE are read from all 9
    (orders up to 4 fit below Nyquist); a hand-over corner left out would have nulled them all."""
    r = fegear.run(fegear.load_case(FZG), fields=False)
    h = r.summary["cycle"]["te_harmonics"]["loaded"]
    assert [p.status for p in r.positions] == ["ok"] * 9
    assert all(a is not None and a > 0 for a in h["amplitude_arcsec"]), h
    assert h["positions_used"] == h["positions"] == 9 and h["reason"] == ""


def test_fzg_pvd_reads_back_with_pyvista(fzg_run):
    import pyvista as pv

    code, out = fzg_run
    assert code == 0
    doc = json.loads((out / "summary.json").read_text())
    reader = pv.get_reader(str(out / "cycle.pvd"))
    assert reader.number_time_points == N_FZG
    angles = [p["pinion_angle_deg"] for p in doc["positions"]]
    np.testing.assert_allclose(reader.time_values, angles, rtol=0, atol=1e-9)
    for i, t in enumerate(reader.time_values):
        reader.set_active_time_value(t)
        blocks = reader.read()
        assert blocks.n_blocks == 5  # pinion, gear, contact cells, pinion and gear flank views
        pinion, gear, cells = blocks[0], blocks[1], blocks[2]
        for b in (pinion, gear, cells, blocks[3], blocks[4]):
            # the time of the series is the pinion angle in degrees, in every file's field data
            assert b.field_data["pinion_angle_deg"][0] == pytest.approx(t, abs=1e-9)
        for flank in (blocks[3], blocks[4]):
            assert flank.field_data["time_unit"][0] == "pinion angle phi1 (deg)"
            loaded = flank.cell_data["outline"] == 0
            # the flank views hold the solver's loaded cells: their forces add up to the
            # position's force, their largest pressure is the position's (float64: round-off)
            total_i = doc["positions"][i]["total_force_N"]
            assert flank.cell_data["force_N"][loaded].sum() == pytest.approx(total_i, rel=1e-9)
            assert flank.cell_data["pressure_MPa"].max() == pytest.approx(
                doc["positions"][i]["p_max_MPa"], rel=1e-12
            )
        for member in (pinion, gear):
            assert {"pressure_MPa", "displacement_mm", "in_contact"} <= set(member.point_data)
            u = member.point_data["displacement_mm"]
            assert u.shape == (member.n_points, 3) and np.all(np.isfinite(u))
            assert member.point_data["pressure_MPa"].max() > 0  # the loaded flank shows
        force = cells.cell_data["force_N"]
        pressure = cells.cell_data["pressure_MPa"]
        area = cells.cell_data["area_mm2"]
        total = doc["positions"][i]["total_force_N"]
        pairs = sum(q["force_N"] for q in doc["positions"][i]["pairs"])
        # the cell field is the solver output written in float64: equal to round-off
        assert abs(force.sum() - total) <= 1e-6 * total
        assert abs((pressure * area).sum() - total) <= 1e-6 * total
        assert abs(pairs - total) <= 1e-9 * total
        assert pressure.max() == pytest.approx(doc["positions"][i]["p_max_MPa"], rel=1e-12)
        # the flank-node pressures are cell pressures (no interpolation overshoot)
        assert pinion.point_data["pressure_MPa"].max() <= pressure.max() * (1 + 1e-12)


def test_fzg_members_are_placed_and_deformed_consistently(fzg_run):
    """The loaded flank vertices of pinion and gear face each other (within an element of the
    coarse mesh) and each member is pushed into its flank: the displacement at a loaded vertex
    has a positive component against that member's outward flank direction."""
    import meshio
    from scipy.spatial import cKDTree

    code, out = fzg_run
    assert code == 0
    for i in range(N_FZG):
        pin = meshio.read(out / "vtk" / f"pinion_{i:03d}.vtu")
        gear = meshio.read(out / "vtk" / f"gear_{i:03d}.vtu")
        cells = meshio.read(out / "vtk" / f"contact_cells_{i:03d}.vtu")
        centres = cells.points[cells.cells_dict["quad"]].mean(axis=1)
        for m in (pin, gear):
            loaded = m.points[m.point_data["pressure_MPa"] > 0]
            # every loaded vertex sits over a contact cell: within a cell diagonal of one
            # (cells ~2 mm at level 0)
            assert cKDTree(centres).query(loaded)[0].max() < 4.0
        # pinion: the pinion axis is +z at the origin; the gear centre is on +x
        up = pin.point_data["displacement_mm"][pin.point_data["pressure_MPa"] > 0]
        ug = gear.point_data["displacement_mm"][gear.point_data["pressure_MPa"] > 0]
        # equal and opposite loads: the two members move apart along the line of action
        assert np.dot(up.mean(axis=0), ug.mean(axis=0)) < 0


def test_fzg_pngs_are_written(fzg_run):
    code, out = fzg_run
    assert code == 0
    for name in ("te", "load_share", "p_max", "bearing_pattern"):
        png = out / f"{name}.png"
        assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    # no temporary file left behind (atomic writes); the folder's list of the run's files
    assert [p.name for p in out.rglob(".*")] == [".fegear-outputs"]


def test_hertz_scene_through_the_api(tmp_path):
    case = fegear.load_case(HERTZ)
    r = fegear.run(case, level=0)
    assert isinstance(r, fegear.HertzResult)
    # level 0 (6 cells across 2b) is within ~2.5 % of Hertz (tests/test_hertz_scene.py)
    assert abs(r.p0_MPa / r.hertz_p0_MPa - 1) < 0.04
    r.write(tmp_path)
    doc = json.loads((tmp_path / "summary.json").read_text())
    assert doc["result"]["p0_MPa"] == r.p0_MPa


def test_tca_result_of_the_seed_face_gear():
    """Fidelity ``tca``: the loaded values are None with the reason, the checks and the
    unloaded pattern are there (the seed's contact ratio 1.554, tests/test_gear_cli.py)."""
    r = fegear.run(fegear.load_case(FACE_GEAR), fidelity="tca")
    assert r.cycle.te_pp_loaded_arcsec is None and "tca" in r.cycle.te_pp_loaded_reason
    assert r.cycle.p_max_MPa is None and r.cycle.p_max_reason
    assert 1.5 < r.checks.contact_ratio_unloaded < 1.6
    pc = r.pattern["gear"]
    # the pattern lies on the face-gear tooth (radii 471-560 mm), near the pitch radius 508 mm
    assert 471.0 < pc.face_range_mm[0] < pc.face_mm < pc.face_range_mm[1] < 560.0
    assert abs(pc.face_mm - 508.0) < 5.0
    assert all(p.te_loaded_arcsec is None for p in r.positions)
    # the case file's toml and the case agree: the run used the file's positions
    assert len(r.positions) == tomllib.loads(FACE_GEAR.read_text())["analysis"]["n_positions"]
