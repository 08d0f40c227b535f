"""Measured flanks as profile and lead traces (issue 47): ``fegear/io/topography_traces.py``.

- a lead trace of the analytic lead crowning (what a measuring machine reads on the crowned
  flank at mid working depth, :func:`fegear.tca.deviation.normal_deviation`) gives the crowned
  pair's TCA, and the TCA of the same crowning given as the grid ``cases/helical_measured.toml``
  reads, within the interpolation error;
- a profile trace (a parabolic tip relief, in the measuring machines' "plus material" sign)
  gives the TCA of the same deviation given as a grid;
- a zero trace pair reproduces the design run bit for bit;
- the refusals (file, row, column), the crossing rule, the placement, the command line.

The pair is ``cases/helical_crowned.toml`` at 5 positions, fidelity ``tca`` (2-3 s a run).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_checks import assert_refused

import fegear
from fegear.cli import main
from fegear.errors import InputError
from fegear.io.topography_traces import (
    TraceGrid,
    TraceMismatchWarning,
    parse_trace,
    trace_grid,
)
from fegear.pipeline.pair import build_pair
from fegear.tca.deviation import normal_deviation
from fegear.tca.surfaces import flank_map

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
from compare_summaries import differences  # noqa: E402

CROWNED = REPO / "cases" / "helical_crowned.toml"
MEASURED = REPO / "cases" / "helical_measured.toml"
FZG = REPO / "cases" / "fzg_spur.toml"
LEAD_EXAMPLE = REPO / "cases" / "helical_measured_pinion_drive_lead.csv"
ARCSEC = 180 / math.pi * 3600


def _crowned():
    return fegear.load_case(CROWNED).replace(n_positions=5)


def _design(case):
    return case.replace(pair={**case.pair, "lead_crowning_mm": [0.0, 0.0]})


def _tca(case) -> dict:
    return fegear.run(case, fidelity="tca", fields=False).summary


def _doc(summary) -> dict:
    d = dict(summary)
    for k in ("timings_s", "cache", "versions"):
        d.pop(k, None)
    return d


def _write_trace(path: Path, head: str, x, d_um, at: str = "") -> Path:
    lines = ([at] if at else []) + [head]
    lines += [f"{float(a)!r}, {float(b)!r}" for a, b in zip(x, d_um, strict=True)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _mid_diameter(member, side: str = "drive") -> tuple[float, float]:
    """``(u, d)`` of the mid working depth (the middle of the roll length)."""
    bd = member.flank_coordinates(side).bounds
    u = 0.5 * (bd.u_fillet + bd.u_tip)
    return u, 2 * math.hypot(member.r_b, float(member.roll_length(u)))


def _same_tca(a: dict, b: dict, te_tol: float, pt_tol: float) -> tuple[float, float]:
    """Assert and return the largest unloaded-TE (″) and contact-point (mm) differences."""
    te = pt = 0.0
    for pa, pb in zip(a["positions"], b["positions"], strict=True):
        te = max(te, abs(pa["te_unloaded_arcsec"] - pb["te_unloaded_arcsec"]))
        for qa, qb in zip(pa["pairs"], pb["pairs"], strict=True):
            assert (qa["contact_point_mm"] is None) == (qb["contact_point_mm"] is None)
            if qa["contact_point_mm"] is not None:
                d = np.subtract(qa["contact_point_mm"], qb["contact_point_mm"])
                pt = max(pt, float(np.abs(d).max()))
    assert te < te_tol and pt < pt_tol, (te, pt)
    return te, pt


# ------------------------------------------------------------------ a lead trace


#: an axis tilt that moves the contact 2.6 mm along the crowned face: unloaded TE of 3-14″
TILT = {"f_sigma_beta_mm": 0.015}


@pytest.fixture(scope="module")
def lead_runs():
    """The crowned pair, the design with the grid of the crowning (cases/helical_measured.toml)
    and the design with the shipped lead trace of it, all with the axis tilt :data:`TILT`; the
    trace's interpolation error (mm)."""
    case = _crowned().replace(errors=TILT)
    measured = fegear.load_case(MEASURED).replace(n_positions=5, errors=TILT)
    trace = measured.replace(topography={"pinion_drive_lead": LEAD_EXAMPLE.name})
    flat, crowned = build_pair(_design(case)).pinion, build_pair(case).pinion
    nominal, modified = flank_map(flat, "drive"), flank_map(crowned, "drive")
    bd = nominal.bounds
    U, V = np.meshgrid(np.linspace(bd.u_fillet, bd.u_tip, 41),
                       np.linspace(bd.v_start, bd.v_end, 141), indexing="ij")  # fmt: skip
    exact = normal_deviation(nominal, modified, U, V)
    err = float(np.abs(build_pair(trace).pinion.topography("drive").deviation(U, V)[0]
                       - exact).max())  # fmt: skip
    return _tca(case), _tca(measured), _tca(trace), err, build_pair(case)


def test_the_shipped_lead_trace_is_the_crowning_read_at_mid_depth():
    flat, crowned = build_pair(_design(_crowned())).pinion, build_pair(_crowned()).pinion
    u, d = _mid_diameter(flat)
    t = parse_trace(LEAD_EXAMPLE.read_text(encoding="utf-8"), "pinion_drive_lead", LEAD_EXAMPLE)
    assert t.at == pytest.approx(d, abs=1e-9)
    read = 1e3 * normal_deviation(flank_map(flat, "drive"), flank_map(crowned, "drive"),
                                  np.full(t.coordinate.shape, u), t.coordinate)  # fmt: skip
    assert np.abs(read - t.removed_um).max() < 1e-9  # the file's 10 digits


def test_a_lead_trace_of_the_crowning_gives_the_crowned_tca_and_the_grids(lead_runs):
    crowned, grid, trace, err, pair = lead_runs
    # the exact crowning varies across the profile by 1e-13 mm (the grid's rows): the trace's
    # one row interpolates the whole flank as the 5 x 9 grid does (measured 1.5e-11 mm)
    assert err < 1e-10
    rb2, beta_b = pair.gear.r_b, pair.pinion.beta_b
    # a gap error e turns the gear by at most e / (r_b2 cos β_b); 1e-9″ of the TCA's closing
    te_tol = ARCSEC * err / (rb2 * math.cos(beta_b)) + 1e-9
    # the contact point is the minimum of the crowning's gap a z² along the face: an error e
    # moves it by at most 2 √(e/a) (a = 4 C cos β_b / b²) (measured: 2e-7 mm of 5.5e-4 mm;
    # the TE 1.4e-9″ of 6.5e-8″)
    pt_tol = 2 * math.sqrt(err / (4 * 0.010 * math.cos(beta_b) / 14.0**2))
    _same_tca(crowned, trace, te_tol, pt_tol)
    te = [p["te_unloaded_arcsec"] for p in crowned["positions"]]
    assert max(te) - min(te) > 5.0  # the tilt shows in the TE (measured 3.2-14.0″)
    _same_tca(grid, trace, 2 * te_tol, 2 * pt_tol)  # both within e of the crowning
    for other in (crowned, grid):  # measured 2.5e-7 mm and 1e-8 mm of 8.1 mm
        assert trace["cycle"]["path_length_mm"] == pytest.approx(
            other["cycle"]["path_length_mm"], abs=1e-6
        )
    echo = trace["inputs"]["topography"]["pinion_drive"]
    assert echo["lead_trace"] == LEAD_EXAMPLE.name and echo["shape"] == [1, 9]


# ------------------------------------------------------------------ a profile trace


def test_a_profile_trace_gives_the_tca_of_the_same_grid(tmp_path):
    """A parabolic tip relief of 8 µm read on 11 diameters at mid-face, given as a profile
    trace in "plus material" sign and as a diameter grid (the same rows, 3 equal columns)."""
    design = _design(_crowned())
    relieved = design.replace(pair={**design.pair, "tip_relief_mm": [0.008, 0.0],
                                    "tip_relief_shape": "parabolic"})  # fmt: skip
    flat, mod = build_pair(design).pinion, build_pair(relieved).pinion
    bd = flat.flank_coordinates("drive").bounds
    u = np.linspace(bd.u_fillet, bd.u_tip, 11)
    d = 2 * np.hypot(flat.r_b, flat.roll_length(u))
    dev = 1e3 * normal_deviation(flank_map(flat, "drive"), flank_map(mod, "drive"), u, 0 * u)
    assert 7.0 < dev.max() < 8.0  # 8 µm along the transverse line of action: 8 cos β_b
    _write_trace(tmp_path / "p.csv", "diameter_mm, added_um", d[::-1], -dev[::-1])  # tip first
    rows = zip(d.tolist(), dev.tolist(), strict=True)
    grid = ["diameter_mm, -7, 0, 7"] + [f"{a!r}, {b!r}, {b!r}, {b!r}" for a, b in rows]
    (tmp_path / "g.csv").write_text("\n".join(grid) + "\n", encoding="utf-8")
    a = _tca(design.replace(topography={"pinion_drive_profile": str(tmp_path / "p.csv")}))
    b = _tca(design.replace(topography={"pinion_drive": str(tmp_path / "g.csv")}))
    # the same spline in d (the grid's equal columns are constant to rounding, 1e-19 mm):
    # the same TCA to the Newton solves' closing (1e-9″, 1e-9 mm; measured: 0 and 0)
    te, pt = _same_tca(a, b, 1e-9, 1e-9)
    assert a["cycle"]["te_pp_unloaded_arcsec"] > 0.1  # the relief shows in the TE
    assert a["inputs"]["topography"]["pinion_drive"]["max_um"] == pytest.approx(dev.max())


def test_a_profile_trace_in_roll_length_gives_the_profile_crowned_tca(tmp_path):
    """An 8 µm profile crowning (a parabola in the roll length L) read at 11 points at mid-face,
    given against L (``roll_mm``) and against the diameter: each gives the crowned pair's TCA
    to its own interpolation error, which is rounding in L and 1.8e-4 mm in d (L ∝ √(d − d_b)
    is steep at the form circle). The spur pair (β = 0): the crowned helical pair touches at the
    face ends, where the analytic crowning (along the transverse line of action) and the trace
    (along the normal) put the flank's edge δ_t sin β_b ≈ 2 µm apart (TE 5e-5″ apart)."""
    design = _design(_crowned())
    design = design.replace(pair={**design.pair, "helix_angle_deg": 0.0})
    crowned = design.replace(pair={**design.pair, "profile_crowning_mm": [0.008, 0.0]})
    flat, mod = build_pair(design).pinion, build_pair(crowned).pinion
    nominal, modified = flank_map(flat, "drive"), flank_map(mod, "drive")
    bd = nominal.bounds
    u = np.linspace(bd.u_fillet, bd.u_tip, 11)
    L = flat.roll_length(u)
    dev = 1e3 * normal_deviation(nominal, modified, u, 0 * u)
    _write_trace(tmp_path / "roll.csv", "roll_mm, removed_um", L, dev)
    _write_trace(tmp_path / "dia.csv", "diameter_mm, removed_um", 2 * np.hypot(flat.r_b, L), dev)
    U, V = np.meshgrid(np.linspace(bd.u_fillet, bd.u_tip, 81),
                       np.linspace(bd.v_start, bd.v_end, 5), indexing="ij")  # fmt: skip
    exact = normal_deviation(nominal, modified, U, V)
    a = _tca(crowned)
    te = [p["te_unloaded_arcsec"] for p in a["positions"]]
    assert max(te) - min(te) > 4.0  # the crowning shows in the TE (measured 9.5″ p-p)
    rb2, beta_b = build_pair(design).gear.r_b, flat.beta_b
    errs = {}
    for name in ("roll", "dia"):
        case = design.replace(topography={"pinion_drive_profile": str(tmp_path / f"{name}.csv")})
        topo = build_pair(case).pinion.topography("drive")
        errs[name] = err = float(np.abs(topo.deviation(U, V)[0] - exact).max())
        # a gap error e turns the gear by at most e / (r_b2 cos β_b); 1e-9″ the TCA's closing
        # (measured: roll 9e-11″ of 1.03e-9″, diameter 0.016″ of 0.73″)
        te_tol = ARCSEC * err / (rb2 * math.cos(beta_b)) + 1e-9
        b = _tca(case)
        for pa, pb in zip(a["positions"], b["positions"], strict=True):
            assert abs(pa["te_unloaded_arcsec"] - pb["te_unloaded_arcsec"]) < te_tol, name
    assert b["inputs"]["topography"]["pinion_drive"]["coordinates"] == "diameter_mm"
    # the parabola in L, reproduced by the cubic: rounding (measured 7e-15 mm); in d 1.8e-4 mm
    assert errs["roll"] < 1e-12 and 1e-5 < errs["dia"] < 3e-4


# ------------------------------------------------------------------ a zero trace


def test_zero_traces_reproduce_the_design_run(tmp_path):
    case = _design(_crowned())
    p = _write_trace(tmp_path / "p.csv", "diameter_mm, removed_um", [70.5, 78.0, 84.5], [0, 0, 0])
    ld = _write_trace(tmp_path / "l.csv", "z_mm, added_um", [-7, 0, 7], [0, 0, 0])
    zero = case.replace(topography={"pinion_drive_profile": str(p), "gear_drive_lead": str(ld)})
    a, b = _doc(_tca(case)), _doc(_tca(zero))
    echo = b["inputs"].pop("topography")
    assert set(echo) == {"pinion_drive", "gear_drive"} and echo["gear_drive"]["max_um"] == 0.0
    # a measured run's ease-off also describes the design's and the difference: zero here (to
    # the rounding of its µm-and-mm sum, measured 7e-24 µm)
    ease = b.get("ease_off") or {}
    diff = ease.pop("measured_minus_design_um", None)
    assert diff is None or max(abs(diff["min"]), abs(diff["max"])) < 1e-12
    ease.pop("design", None)
    assert differences(a, b) == []  # every other number of summary.json, bit for bit


# ------------------------------------------------------------------ the surface


def _trace(text: str, key: str = "pinion_drive_lead", name: str = "t.csv"):
    return parse_trace(text, key, Path(name))


def test_the_surface_is_separable_through_the_crossing():
    p = _trace("at_z_mm, 2\ndiameter_mm, removed_um\n70, 1\n75, 3\n80, 2\n85, 5\n",
               "pinion_drive_profile", "p.csv")  # fmt: skip
    ld = _trace("# helix\nat_diameter_mm, 75\nz_mm, removed_um\n-7, 4\n0, 1\n2, 3\n7, 6\n")
    g = trace_grid("pinion_drive", p, ld)
    assert isinstance(g, TraceGrid) and g.crossing == (75.0, 2.0) and g.mismatch_um == 0.0
    # rows: the profile trace's diameters, columns: the lead trace's z; δ_c = 3 at (75, 2)
    assert g.profile.tolist() == [70, 75, 80, 85] and g.face.tolist() == [-7, 0, 2, 7]
    assert g.deviation_um[:, 2].tolist() == [1, 3, 2, 5]  # the profile trace at z_P
    # both files are named where the flank's source is reported (acceptance.json, echo)
    assert g.files == (Path("p.csv"), Path("t.csv"))
    assert g.echo()["file"] == "p.csv + t.csv"
    assert g.deviation_um[1].tolist() == [4, 1, 3, 6]  # the lead trace at d_L
    assert g.rows == (3, 4, 5, 6) and g.cols == (4, 5, 6, 7)  # the files' lines
    # disagreeing traces: averaged at the crossing (each shifted by half), with a warning
    ld2 = _trace("at_diameter_mm, 75\nz_mm, removed_um\n-7, 4\n0, 1\n2, 4\n7, 6\n")
    with pytest.warns(TraceMismatchWarning, match=r"differ by -1.000 µm"):
        g2 = trace_grid("pinion_drive", p, ld2)
    assert g2.mismatch_um == pytest.approx(-1.0) and g2.deviation_um[1, 2] == pytest.approx(3.5)
    # the defaults: z_P = 0 (mid-face), d_L the middle of the profile trace's diameters
    p0 = _trace("diameter_mm, removed_um\n70, 0\n80, 2\n", "pinion_drive_profile", "p.csv")
    assert trace_grid("pinion_drive", p0, ld).crossing == (75.0, 0.0)  # 1 µm on both


def test_one_trace_is_one_row_or_one_column_and_added_is_negated():
    p = _trace("diameter_mm, added_um\n80, -3\n70, -1\n", "gear_coast_profile", "p.csv")
    assert p.coordinate.tolist() == [70, 80] and p.removed_um.tolist() == [1, 3]  # sorted
    g = trace_grid("gear_coast", p, None)
    assert g.face.tolist() == [0.0] and g.deviation_um.tolist() == [[1.0], [3.0]]
    assert g.member == "gear" and g.side == "coast"
    g = trace_grid("gear_coast", None, _trace("z_mm, removed_um\n-5, 2\n5, 2\n"))
    assert g.deviation_um.shape == (1, 2) and np.isnan(g.profile).all()  # placed on the member


def test_roll_lengths_for_profile_traces_and_grids(tmp_path):
    p = _trace("roll_mm, removed_um\n5, 1\n15, 3\n", "pinion_drive_profile", "p.csv")
    ld = _trace("at_roll_mm, 10\nz_mm, removed_um\n-7, 2\n7, 2\n")
    g = trace_grid("pinion_drive", p, ld)
    assert g.coordinates == "roll_mm" and g.crossing == (10.0, 0.0) and g.mismatch_um == 0.0
    # a lead trace's position in the other coordinate than the profile trace's: refused
    with pytest.raises(InputError, match=r"t.csv: row 1, column 1\).*'at_roll_mm'"):
        trace_grid("pinion_drive", p, _trace(GOOD))
    # a lead trace alone at a roll length; placed on the member in roll length without one
    assert trace_grid("pinion_drive", None, ld).coordinates == "roll_mm"
    # a grid in roll lengths: the rows off the working flank (as roll lengths) are refused
    (tmp_path / "g.csv").write_text("roll_mm, -7, 7\n3, 0, 0\n30, 0, 0\n", encoding="utf-8")
    case = _design(_crowned()).replace(topography={"pinion_drive": str(tmp_path / "g.csv")})
    with pytest.raises(InputError, match=r"g.csv: row 3, column 1\).*as a roll length"):
        build_pair(case)


def test_a_lead_trace_alone_sits_on_the_mid_working_depth(tmp_path):
    ld = _write_trace(tmp_path / "l.csv", "z_mm, removed_um", [-7, 7], [1.0, 3.0])
    case = _design(_crowned()).replace(topography={"pinion_drive_lead": str(ld)})
    m = build_pair(case).pinion
    u, d = _mid_diameter(m.base)
    t = m.topography("drive")
    assert t.x.tolist() == [pytest.approx(d)]
    bd = m.flank_coordinates("drive").bounds
    dev, du, dv = t.deviation([bd.u_fillet, u, bd.u_tip], [0.0, 7.0, -7.0])
    assert dev == pytest.approx([2e-3, 3e-3, 1e-3]) and not du.any()  # linear in z alone
    assert dv == pytest.approx([1e-3 / 7] * 3)


# ------------------------------------------------------------------ refusals

GOOD = "at_diameter_mm, 75\nz_mm, removed_um\n-7, 1\n0, 0\n7, 1\n"
# (what is wrong, text, (row, column) named, words in the message)
BAD_TRACES = [
    ("not a number", GOOD.replace("0, 0", "0, x"), (4, 2), "a number"),
    ("nan", GOOD.replace("0, 0", "0, nan"), (4, 2), "finite"),
    ("infinite", GOOD.replace("\n7, 1", "\ninf, 1"), (5, 1), "finite"),
    ("non-monotone", GOOD.replace("\n7, 1", "\n-1, 1"), (5, 1), "strictly increasing"),
    ("one point only", "z_mm, removed_um\n0, 1\n", (1, None), "at least 2 points"),
    ("three cells", GOOD.replace("0, 0", "0, 0, 1"), (4, 3), "2 cells"),
    ("one cell", GOOD.replace("0, 0", "0"), (4, 2), "2 cells"),
    ("unknown sign", GOOD.replace("removed_um", "dev_um"), (2, 2), "removed_um"),
    ("unknown coordinate", GOOD.replace("z_mm", "x_mm"), (2, 1), "'z_mm'"),
    ("a profile header", GOOD.replace("z_mm", "diameter_mm"), (2, 1), "pinion_drive_profile"),
    ("bad position", GOOD.replace("75", "big"), (1, 2), "a number"),
]  # fmt: skip


@pytest.mark.parametrize(
    ("text", "where", "words"), [b[1:] for b in BAD_TRACES], ids=[b[0] for b in BAD_TRACES]
)
def test_a_bad_trace_is_refused_naming_file_row_and_column(text, where, words):
    with pytest.raises(InputError) as exc:
        _trace(text)
    msg, (row, col) = str(exc.value), where
    place = f"row {row}" + (f", column {col}" if col else "")
    assert f"topography.pinion_drive_lead (t.csv: {place})" in msg, msg
    assert words in msg, msg


def test_the_traces_must_cross():
    p = _trace("diameter_mm, removed_um\n70, 1\n80, 3\n", "pinion_drive_profile", "p.csv")
    far = _trace("at_diameter_mm, 90\nz_mm, removed_um\n-7, 1\n7, 1\n")
    with pytest.raises(InputError, match=r"t.csv: row 1, column 2\).*\[70, 80\]"):
        trace_grid("pinion_drive", p, far)
    inset = _trace("z_mm, removed_um\n1, 1\n7, 1\n")  # mid-face (the default z_P) not on it
    with pytest.raises(InputError, match=r"pinion_drive_profile \(p.csv\).*give at_z_mm"):
        trace_grid("pinion_drive", p, inset)


def _case_file(tmp_path: Path, keys: dict[str, str], base: Path = CROWNED) -> Path:
    (tmp_path / "l.csv").write_text(GOOD, encoding="utf-8")
    lines = "".join(f'{k} = "{v}"\n' for k, v in keys.items())
    path = tmp_path / "case.toml"
    path.write_text(base.read_text(encoding="utf-8") + f"\n[topography]\n{lines}", "utf-8")
    return path


def test_a_trace_and_a_grid_of_one_flank_and_traces_off_cylinders_are_refused(tmp_path):
    path = _case_file(tmp_path, {"pinion_drive": str(REPO / "cases" / (MEASURED.stem +
                      "_pinion_drive.csv")), "pinion_drive_lead": "l.csv"})  # fmt: skip
    with pytest.raises(InputError, match=r"topography.pinion_drive_lead.*topography.pinion_drive"):
        fegear.load_case(path)
    for base in (FZG, REPO / "cases" / "spiral_bevel_nominal.toml"):
        with pytest.raises(InputError, match=r"topography.pinion_drive_lead.*'cylindrical'"):
            fegear.load_case(_case_file(tmp_path, {"pinion_drive_lead": "l.csv"}, base))


def test_a_trace_off_the_working_flank_is_refused_naming_its_line(tmp_path):
    case = fegear.load_case(_case_file(tmp_path, {"pinion_drive_lead": "l.csv"}))
    m = build_pair(_design(case)).pinion  # the position line: 75 mm is on the flank
    assert m.topography("drive").x.tolist() == [75.0]
    (tmp_path / "l.csv").write_text(GOOD.replace("\n7, 1", "\n7.5, 1"), encoding="utf-8")
    with pytest.raises(InputError, match=r"l.csv: row 5, column 1\).*the face"):
        build_pair(fegear.load_case(tmp_path / "case.toml"))
    (tmp_path / "l.csv").write_text(GOOD.replace("75", "95"), encoding="utf-8")
    with pytest.raises(InputError, match=r"l.csv: row 1, column 2\).*form circle to tip"):
        build_pair(fegear.load_case(tmp_path / "case.toml"))


def test_the_command_line_refuses_a_bad_trace_before_any_work(tmp_path, capsys):
    path = _case_file(tmp_path, {"pinion_drive_lead": "l.csv"})
    (tmp_path / "l.csv").write_text(GOOD.replace("0, 0", "0, nan"), encoding="utf-8")
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out)])
    assert_refused(code, capsys.readouterr().err, ["l.csv", "row 4", "column 2", "finite"])
    assert not out.exists()  # nothing written


def test_the_case_keeps_its_trace_keys():
    case = fegear.load_case(MEASURED).replace(topography={"pinion_drive_lead": LEAD_EXAMPLE.name})
    assert case.topography_files == {"pinion_drive_lead": LEAD_EXAMPLE.name}
    assert case.to_document()["topography"] == {"pinion_drive_lead": LEAD_EXAMPLE.name}
    again = case.replace(n_positions=3)
    assert again.topography["pinion_drive"].sha256 == case.topography["pinion_drive"].sha256
