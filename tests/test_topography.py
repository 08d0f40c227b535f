"""Measured flanks (issue 47): grid files, their refusals, the spline, the deviated flank map.

No analysis runs here (``tests/test_topography_runs.py`` runs the pairs).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from cli_checks import assert_refused

import fegear
from fegear.cli import main
from fegear.errors import InputError
from fegear.io.topography import parse_topography
from fegear.pipeline.pair import build_pair
from fegear.tca.deviation import DeviatedFlankMap, FlankTopography, MeasuredMember
from fegear.tca.surfaces import flank_map

REPO = Path(__file__).resolve().parents[1]
HELICAL = REPO / "cases" / "helical_crowned.toml"
MEASURED = REPO / "cases" / "helical_measured.toml"
FZG = REPO / "cases" / "fzg_spur.toml"

GOOD = """# a comment
normalized, 0, 0.5, 1

0,   1.0, 0.0, 1.0
0.5, 2.0, 0.5, 2.0
# another comment
1,   3.0, 1.0, 3.0
"""


def _parse(text: str):
    return parse_topography(text, "pinion_drive", Path("grid.csv"))


def _refused(text: str) -> InputError:
    with pytest.raises(InputError) as exc:
        _parse(text)
    return exc.value


def test_a_grid_reads_with_its_rows_and_columns():
    g = _parse(GOOD)
    assert g.coordinates == "normalized"
    assert g.profile.tolist() == [0.0, 0.5, 1.0] and g.face.tolist() == [0.0, 0.5, 1.0]
    assert g.deviation_um[1].tolist() == [2.0, 0.5, 2.0]
    assert g.rows == (4, 5, 7) and g.cols == (2, 3, 4) and g.header_row == 2  # file lines
    assert g.echo()["max_um"] == 3.0 and g.echo()["min_um"] == 0.0
    # the hash is of the numbers, not of the text: comments and formatting do not count
    assert _parse(GOOD.replace("1.0,", "1.00,").replace("# a comment", "")).sha256 == g.sha256
    assert _parse(GOOD.replace("3.0, 1.0", "3.0, 1.1")).sha256 != g.sha256


# (what is wrong, text, (row, column) named, words in the message)
BAD_GRIDS = [
    ("not a number", GOOD.replace("0.5, 2.0", "0.5, x"), (5, 2), "a number"),
    ("nan", GOOD.replace("2.0, 0.5", "2.0, nan"), (5, 3), "finite"),
    ("infinite", GOOD.replace("1,   3.0", "1,   inf"), (7, 2), "finite"),
    ("short row", GOOD.replace("0.5, 2.0, 0.5, 2.0", "0.5, 2.0, 0.5"), (5, 4), "4 cells"),
    ("long row", GOOD.replace("0.5, 2.0, 0.5, 2.0", "0.5, 2.0, 0.5, 2.0, 1"), (5, 5), "4 cells"),
    ("face not increasing", GOOD.replace("0, 0.5, 1", "0, 0.5, 0.5"), (2, 4), "increasing"),
    ("profile not increasing", GOOD.replace("1,   3.0", "0.4, 3.0"), (7, 1), "increasing"),
    ("face outside the flank", GOOD.replace("0, 0.5, 1", "0, 0.5, 1.2"), (2, 4), "[0, 1]"),
    ("profile outside the flank", GOOD.replace("0,   1.0", "-0.1, 1.0"), (4, 1), "[0, 1]"),
    ("unknown coordinates", GOOD.replace("normalized", "roll_deg"), (2, 1), "normalized"),
]  # fmt: skip


@pytest.mark.parametrize(
    ("text", "where", "words"), [b[1:] for b in BAD_GRIDS], ids=[b[0] for b in BAD_GRIDS]
)
def test_a_bad_grid_is_refused_naming_file_row_and_column(text, where, words):
    msg = str(_refused(text))
    row, col = where
    assert f"topography.pinion_drive (grid.csv: row {row}, column {col})" in msg, msg
    assert words in msg


def test_too_small_a_grid_is_refused():
    # the spline needs 2 points in each direction
    assert "2 face coordinates" in str(_refused("normalized, 0\n0, 1\n1, 2\n"))
    assert "2 rows" in str(_refused("normalized, 0, 1\n0, 1, 2\n"))


def _case_file(tmp_path: Path, grid: str, key: str = "pinion_drive", base: Path = HELICAL):
    (tmp_path / "grid.csv").write_text(grid, encoding="utf-8")
    text = base.read_text(encoding="utf-8") + f'\n[topography]\n{key} = "grid.csv"\n'
    path = tmp_path / "case.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_the_command_line_refuses_a_bad_grid_before_any_work(tmp_path, capsys):
    path = _case_file(tmp_path, GOOD.replace("2.0, 0.5", "2.0, nan"))
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out)])
    assert_refused(code, capsys.readouterr().err, ["grid.csv", "row 5", "column 3"])
    assert not out.exists()  # nothing written


def _diameters(member, side="drive"):
    bd = member.flank_coordinates(side).bounds
    us = (bd.u_fillet, bd.u_tip)
    return [2 * math.hypot(member.r_b, float(member.roll_length(u))) for u in us]


def test_a_physical_grid_off_the_working_flank_is_refused(tmp_path, capsys):
    pinion = build_pair(fegear.load_case(HELICAL)).pinion
    d_form, d_tip = _diameters(pinion)
    grid = f"diameter_mm, -7, 0, 7\n{d_form:.6f}, 1, 0, 1\n{d_tip + 0.01:.6f}, 1, 0, 1\n"
    path = _case_file(tmp_path, grid)
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out)])
    assert_refused(code, capsys.readouterr().err, ["grid.csv", "row 3, column 1", "form circle"])
    assert not out.exists()
    # the face: z beyond b/2 = 7 mm
    grid = f"diameter_mm, -7, 0, 7.5\n{d_form:.6f}, 1, 0, 1\n{d_tip:.6f}, 1, 0, 1\n"
    case = fegear.load_case(_case_file(tmp_path, grid))
    with pytest.raises(InputError, match=r"grid.csv: row 1, column 4\)"):
        build_pair(case)


def test_physical_coordinates_are_for_cylindrical_members(tmp_path):
    # kind "spur" members have no roll lengths: a diameter grid is refused, naming the corner
    case = fegear.load_case(_case_file(tmp_path, "diameter_mm, -5, 5\n60, 0, 0\n70, 0, 0\n",
                                       base=FZG))  # fmt: skip
    with pytest.raises(InputError, match=r"grid.csv: row 1, column 1\).*cylindrical"):
        build_pair(case)


def test_the_case_file_section_and_the_summary_echo(tmp_path):
    case = fegear.load_case(_case_file(tmp_path, GOOD))
    assert set(case.topography) == {"pinion_drive"}
    echo = case.to_dict()["topography"]["pinion_drive"]
    sha = case.topography["pinion_drive"].sha256
    assert echo == {"file": "grid.csv", "sha256": sha, "coordinates": "normalized",
                    "shape": [3, 3], "max_um": 3.0, "min_um": 0.0}  # fmt: skip
    # a new case keeps its grids (paths relative to the case file); {} removes them
    assert case.replace(n_positions=5).topography == case.topography
    assert case.replace(topography={}).topography == {}
    assert "topography" not in case.replace(topography={}).to_dict()
    with pytest.raises(InputError, match="topography.pinion_drve"):
        case.replace(topography={"pinion_drve": "grid.csv"})  # misspelt key
    with pytest.raises(InputError, match="a readable grid file"):
        case.replace(topography={"gear_drive": "missing.csv"})


def test_the_shipped_example_loads():
    case = fegear.load_case(MEASURED)
    g = case.topography["pinion_drive"]
    assert g.deviation_um.shape == (5, 9) and g.coordinates == "normalized"


# ------------------------------------------------------------------ the spline


def _topo(x, y, d_mm, **kw) -> FlankTopography:
    return FlankTopography("normalized", np.asarray(x, float), np.asarray(y, float),
                           np.asarray(d_mm, float), **kw)  # fmt: skip


def test_the_spline_passes_through_the_grid_and_reproduces_cubics():
    x, y = np.linspace(0, 1, 5), np.array([0.0, 0.1, 0.3, 0.6, 0.8, 1.0])
    f = lambda x, y: 1e-3 * (1 + x - 2 * x**3 + 3 * x * y**2 - y**3)  # noqa: E731
    t = _topo(x, y, f(x[:, None], y[None, :]))
    X, Y = np.meshgrid(x, y, indexing="ij")
    assert np.abs(t.deviation(X, Y)[0] - f(X, Y)).max() < 1e-18  # rounding of µm numbers
    r = np.random.default_rng(0).random((2, 200))
    d, du, dv = t.deviation(*r)
    assert np.abs(d - f(*r)).max() < 1e-17  # cubic in each direction: reproduced
    h = 1e-6  # central differences: truncation ~h² |f'''| ~ 1e-15
    assert np.abs(du - (f(r[0] + h, r[1]) - f(r[0] - h, r[1])) / (2 * h)).max() < 1e-12
    assert np.abs(dv - (f(r[0], r[1] + h) - f(r[0], r[1] - h)) / (2 * h)).max() < 1e-12


def test_few_points_lower_the_degree():
    # 2 x 3 points: linear across the profile, quadratic along the face (reproduced exactly)
    x, y = np.array([0.0, 1.0]), np.array([0.0, 0.5, 1.0])
    f = lambda x, y: 1e-3 * (2 * x + (2 * y - 1) ** 2)  # noqa: E731
    t = _topo(x, y, f(x[:, None], y[None, :]))
    r = np.random.default_rng(1).random((2, 50))
    assert np.abs(t.deviation(*r)[0] - f(*r)).max() < 1e-17


def test_outside_the_grid_the_tangent_plane_continues_it():
    # a grid inset from the flank's edges: value and slope continue across the grid's edge
    x, y = np.linspace(0.1, 0.9, 5), np.linspace(0.05, 0.95, 7)
    f = lambda x, y: 1e-3 * np.sin(3 * x) * np.cos(2 * y)  # noqa: E731
    t = _topo(x, y, f(x[:, None], y[None, :]))
    eps = 1e-9
    for u, v in ((0.9, 0.5), (0.1, 0.3), (0.5, 0.95), (0.9, 0.95)):
        inside, outside = t.deviation(u - eps, v - eps), t.deviation(u + eps, v + eps)
        for a, b in zip(inside, outside, strict=True):
            assert abs(a - b) < 1e-10  # C1: jumps of O(eps) only
    # linear beyond the edge: the slope at the edge, exactly
    d0, du0, _ = t.deviation(0.9, 0.5)
    d1, du1, _ = t.deviation(1.0, 0.5)
    assert d1 == pytest.approx(d0 + 0.1 * du0, abs=1e-18) and du1 == pytest.approx(du0, abs=1e-15)


# ------------------------------------------------------------------ the deviated flank


def _measured(member, side: str, t: FlankTopography) -> MeasuredMember:
    bd = member.flank_coordinates(side).bounds
    from dataclasses import replace

    t = replace(t, u_span=(bd.u_fillet, bd.u_tip), v_span=(bd.v_start, bd.v_end))
    return MeasuredMember(member, ((side, t),))


@pytest.mark.parametrize("case", [HELICAL, FZG], ids=["helicoid", "spur involute"])
def test_the_deviated_flank_is_the_point_moved_along_its_normal(case):
    """Native = flank coordinates (helicoid) and an affine map (spur involute: the flank
    coordinates' Jacobian by differences)."""
    m = build_pair(fegear.load_case(case)).pinion
    x, y = np.linspace(0, 1, 5), np.linspace(0, 1, 9)
    d_mm = 0.02 * ((2 * y - 1) ** 2)[None, :] + 0.005 * x[:, None] ** 2  # crowning, 20 µm
    mm = _measured(m, "drive", _topo(x, y, d_mm))
    base, fm = flank_map(m, "drive"), flank_map(mm, "drive")
    assert isinstance(fm, DeviatedFlankMap) and fm.pointwise == base.pointwise
    bd = fm.bounds
    U, V = np.meshgrid(np.linspace(bd.u_fillet, bd.u_tip, 7), np.linspace(bd.v_start, bd.v_end, 9))
    a, b = fm.native(U, V)
    p, n = base.evaluate(a, b)
    P, N = fm.evaluate(a, b)
    d = mm.topography("drive").deviation(U, V)[0]
    # X = p − δ n, to the rounding of coordinates of ~40 mm (40 × 2.2e-16 ≈ 1e-14)
    assert np.abs(np.sum((P - p) * n, -1) + d).max() < 5e-14
    assert np.abs(np.linalg.norm(np.cross(P - p, n), axis=-1)).max() < 5e-14
    # the normal is normal to the deviated surface: central differences of its points
    h = 1e-4
    Xa = (fm.evaluate(a + h, b)[0] - fm.evaluate(a - h, b)[0]) / (2 * h)
    Xb = (fm.evaluate(a, b + h)[0] - fm.evaluate(a, b - h)[0]) / (2 * h)
    cos_a = np.sum(N * Xa, -1) / np.linalg.norm(Xa, axis=-1)
    cos_b = np.sum(N * Xb, -1) / np.linalg.norm(Xb, axis=-1)
    # O(δ κ |∇δ|) of the neglected Weingarten term: 0.02 mm × 0.1/mm × 6e-3 ≈ 1e-5 at most
    # (the differences' truncation is ~1e-9); without the tilt it would be |∇δ| ~ 6e-3
    assert np.abs(cos_a).max() < 2e-5 and np.abs(cos_b).max() < 2e-5
    # the tangents: r − δ_a n, what the Newton solves use (their error O(δ κ) = 2e-3 relative)
    _, _, Ra, Rb = fm.point_jacobian(a, b)
    assert np.abs(Ra - Xa).max() < 5e-3 * np.abs(Xa).max()
    # flank coordinates are the generated point's
    u, v = fm.flank(a, b, P)
    assert np.abs(u - U).max() < 1e-12 and np.abs(v - V).max() < 1e-12


def test_a_zero_grid_changes_no_bit_of_the_flank_map():
    m = build_pair(fegear.load_case(HELICAL)).pinion
    mm = _measured(m, "drive", _topo([0, 1], [0, 0.5, 1], np.zeros((2, 3))))
    base, fm = flank_map(m, "drive"), flank_map(mm, "drive")
    a = np.linspace(0, 12, 30)
    b = np.linspace(-8, 8, 30)  # past the flank too
    for x, y in zip(base.point_jacobian(a, b), fm.point_jacobian(a, b), strict=True):
        assert np.array_equal(x, y)
    assert flank_map(mm, "coast").__class__ is base.__class__  # a flank without a grid


def test_the_cache_keys_hold_the_grid_and_the_meshes_do_not():
    m = build_pair(fegear.load_case(HELICAL)).pinion
    t = _topo([0, 1], [0, 1], np.zeros((2, 2)), sha256="abc123")
    mm = _measured(m, "drive", t)
    assert "abc123" in repr(mm) and repr(m) in repr(mm)  # the TCA and the cycle: another key
    assert repr(mm.mesh_member()) == repr(m.mesh_member())  # the meshes: the design's
    assert mm.name == m.name and mm.n_teeth == m.n_teeth  # the rest is the member's
