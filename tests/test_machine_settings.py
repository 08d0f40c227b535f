"""Machine settings given as a summary sheet prints them (``[machine]``, fegear.io.machine_table;
fegear.geometry.bevel.sheet): the same machine cuts the same flanks, in mm or in inches, and a
table that cannot cut a tooth is refused naming the field."""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_checks import assert_refused

from fegear.case_files import load_case
from fegear.cli import main
from fegear.errors import DesignError, InputError
from fegear.geometry.bevel import SpiralBevelPair
from fegear.geometry.bevel.sheet import FLANKS, flank_table, settings_from_tables
from fegear.io.machine_table import INCH, degmin, format_machine, parse_machine

CASES = Path(__file__).resolve().parents[1] / "cases"
SIDES = ("drive", "coast")


def tables_of(pair):
    index = {"pinion": 1, "gear": 2}
    return {
        f: flank_table(pair.blank, index[f.split("_")[0]], pair.settings.get(*f.split("_")))
        for f in FLANKS
    }


def flank_grid(member, side):
    b = member.boundaries()
    U, V = np.meshgrid(np.linspace(-1, 1, 9), np.linspace(b.v_start, b.v_end, 7), indexing="ij")
    return member.flank_points(side, U, V)[0]


@pytest.fixture(scope="module")
def rebuilt(spiral_bevel_pair):
    """The nominal pair cut again from its own settings written as sheet tables (no
    synthesis): tool phases 0, the blade tips in the cradle plane, the blank phases found."""
    pair = spiral_bevel_pair
    return SpiralBevelPair.from_settings(
        pair.blank, settings_from_tables(pair.blank, tables_of(pair))
    )


def test_the_sheet_tables_of_a_pair_cut_the_same_flanks(spiral_bevel_pair, rebuilt):
    # the same surfaces, parameterized from another tool phase and reference: to the solves'
    # tolerance (1e-11 mm per point, plus round-off of the re-expressed blade)
    for a, b in (
        (spiral_bevel_pair.pinion, rebuilt.pinion),
        (spiral_bevel_pair.gear, rebuilt.gear),
    ):
        for side in SIDES:
            assert np.abs(flank_grid(a, side) - flank_grid(b, side)).max() < 1e-9
        # the root cone the point planes sweep is the blank's root cone (the synthesized point
        # plane touches it at the mean point): to round-off
        np.testing.assert_allclose(b.root_cone_line(), a.root_cone_line(), atol=1e-12)
    for side in SIDES:
        p, q = spiral_bevel_pair.placements[side], rebuilt.placements[side]
        assert p.sigma == q.sigma
        assert q.gear_flank_angle == pytest.approx(p.gear_flank_angle, abs=1e-12)
        assert q.pinion_flank_angle == pytest.approx(p.pinion_flank_angle, abs=1e-12)


def test_straight_blades_are_given_at_their_point_and_parabolic_ones_at_their_vertex(
    spiral_bevel_pair,
):
    t = tables_of(spiral_bevel_pair)
    for f in ("gear_drive", "gear_coast"):
        assert t[f].parabola_per_mm == 0.0 and t[f].blade_height_mm == 0.0
    for f in ("pinion_drive", "pinion_coast"):
        # the pinion's parabola has its vertex at the mean point's height above the blade tip
        assert t[f].parabola_per_mm > 0.0 and t[f].blade_height_mm > 0.0


def test_the_settings_read_back_from_mm_exactly_and_from_inches_to_their_digits(spiral_bevel_pair):
    t = tables_of(spiral_bevel_pair)
    back = parse_machine(tomllib.loads(format_machine(t, "mm"))["machine"])
    assert back == t  # repr of the floats: exact
    inch = parse_machine(tomllib.loads(format_machine(t, "in"))["machine"])
    for f in FLANKS:
        for fld in dataclasses.fields(t[f]):
            a, b = getattr(t[f], fld.name), getattr(inch[f], fld.name)
            if isinstance(a, float):
                # 1e-9 in and 1e-8 arcmin printed: half of that in mm / deg (or round-off)
                tol = {"_deg": 1e-8 / 60, "_mm": 0.5e-9 * INCH}.get(fld.name[-4:], 1e-15)
                tol = 0.5e-9 * INCH if fld.name.endswith("_mm") else tol
                assert b == pytest.approx(a, abs=max(tol, 1e-12 * abs(a))), (f, fld.name)


def test_degrees_and_minutes():
    assert degmin("x", "58 36") == pytest.approx(58.6)
    assert degmin("x", "58°36.5'") == pytest.approx(58.0 + 36.5 / 60)
    assert degmin("x", "-2 05") == pytest.approx(-(2 + 5 / 60))
    assert degmin("x", [58, 30]) == 58.5
    assert degmin("x", "-0 30") == -0.5
    for bad in ("58", "58 61", "abc", [1, 2, 3]):
        with pytest.raises(InputError, match="x"):
            degmin("x", bad)


def test_the_sheet_case_in_inches_has_the_nominal_unloaded_contact():
    """cases/spiral_bevel_sheet.toml: the nominal pair's settings in inches and degrees-minutes:
    the rigid TCA of the nominal case to the printed digits (1e-9 in, 1e-8 arcmin)."""
    import fegear

    nominal = fegear.run(load_case(CASES / "spiral_bevel_nominal.toml"), fidelity="tca")
    sheet_case = load_case(CASES / "spiral_bevel_sheet.toml")
    assert sheet_case.machine is not None
    sheet = fegear.run(sheet_case, fidelity="tca")
    a, b = nominal.cycle, sheet.cycle
    # the TE is ~8″ from differences of µm: printed digits move it by ~1e-6 of that
    assert b.te_pp_unloaded_arcsec == pytest.approx(a.te_pp_unloaded_arcsec, rel=1e-5)
    te_a = [p.te_unloaded_arcsec for p in nominal.positions]
    te_b = [p.te_unloaded_arcsec for p in sheet.positions]
    np.testing.assert_allclose(te_b, te_a, atol=1e-4)
    assert sheet.checks.path_length_mm == pytest.approx(nominal.checks.path_length_mm, rel=1e-6)


SHEET = (CASES / "spiral_bevel_sheet.toml").read_text(encoding="utf-8")
BAD = [
    ("wrong_unit", ("radial_in = ", "radial_cm = "), ["machine.gear_drive.radial_cm", "radial_in"]),
    ("no_blade_angle", ('blade_angle_degmin = "23 35', 'x_blade = "'),
     ["machine.pinion_drive.x_blade"]),
    ("impossible_blade_angle", ('blade_angle_degmin = "19 50', 'blade_angle_degmin = "79 50'),
     ["machine.gear_drive.blade_angle_degmin", "(0, 60)"]),
    ("tilt", ("[machine.gear_coast]\n", "[machine.gear_coast]\ntilt_deg = 2.0\n"),
     ["machine.gear_coast.tilt_deg", "not modelled"]),
    ("two_units", ("[machine.gear_coast]\n", "[machine.gear_coast]\nradial_mm = 74.6\n"),
     ["machine.gear_coast.radial", "one unit only"]),
    ("synthesis_key", ("side = ", "te_amplitude_arcsec = 8.0\nside = "),
     ["pair.te_amplitude_arcsec", "[machine]"]),
    ("missing_flank", ("[machine.pinion_coast]", "[machine.pinion_coasts]"),
     ["machine.pinion_coasts", "pinion_coast"]),
]  # fmt: skip


@pytest.mark.parametrize(("edit", "words"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_a_bad_table_is_refused_at_input_naming_the_field(tmp_path, capsys, edit, words):
    old, new = edit
    assert old in SHEET
    text = SHEET.replace(old, new, 1)
    if edit[0] == 'blade_angle_degmin = "23 35':  # the whole line goes: the blade angle is missing
        text = SHEET.replace(SHEET[SHEET.index(old) :].split("\n")[0] + "\n", "", 1)
        words = ["machine.pinion_drive.blade_angle", "required"]
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    code = main(["run", str(path), "--fidelity", "tca", "--out", str(tmp_path / "out")])
    assert_refused(code, capsys.readouterr().err, words)
    assert not (tmp_path / "out").exists()  # nothing written


BAD_SETTINGS = [
    # the roll 30 % fast: the envelope passes 24 mm from the mean point
    ("roll", "gear_drive", lambda t: {"ratio_of_roll": 1.3 * t.ratio_of_roll}, "mean point"),
    # the cutter 15 mm off radially: the two flanks of a tooth space run into each other
    ("radial", "gear_drive", lambda t: {"radial_mm": t.radial_mm + 15.0}, "overlap"),
    # an edge radius of 3 mm: more than the tooth space's point width carries
    ("edge_radius", "gear_coast", lambda t: {"edge_radius_mm": 3.0}, "overlap"),
]


@pytest.mark.parametrize(("flank", "change", "word"), [b[1:] for b in BAD_SETTINGS],
                         ids=[b[0] for b in BAD_SETTINGS])  # fmt: skip
def test_settings_that_cannot_cut_the_tooth_are_refused_naming_the_table(
    spiral_bevel_pair, flank, change, word
):
    t = tables_of(spiral_bevel_pair)
    bad = {**t, flank: dataclasses.replace(t[flank], **change(t[flank]))}
    member = flank.split("_")[0]
    with pytest.raises(DesignError, match=rf"machine\.{member}_.*{word}"):
        blank = spiral_bevel_pair.blank
        SpiralBevelPair.from_settings(blank, settings_from_tables(blank, bad))


def test_fegear_settings_prints_tables_that_run(tmp_path, capsys):
    code = main(["settings", str(CASES / "spiral_bevel_sheet.toml"), "--units", "mm"])
    assert code == 0
    text = capsys.readouterr().out
    sheet = parse_machine(tomllib.loads(text)["machine"])
    given = load_case(CASES / "spiral_bevel_sheet.toml").flank_tables()
    for f in FLANKS:  # the case's own settings, printed in mm: the same to round-off
        assert sheet[f].radial_mm == pytest.approx(given[f].radial_mm, abs=1e-12)
        assert sheet[f].cradle_angle_deg == pytest.approx(given[f].cradle_angle_deg, abs=1e-10)
    assert math.isclose(sheet["gear_drive"].blade_height_mm, 0.0)
