"""Honest at the extremes (issue 30, items 1 and 3): a pressure is "away from the edges" only
beyond the edge's reach (fegear/ltca/edges.py), and a result outside the model's validity range
is said so on the terminal and in ``summary.json`` (fegear/ltca/validity.py)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import fegear
from fegear.cli import main
from fegear.ltca.edges import EDGE_REACH_CELLS, EDGE_REACH_SEMI_WIDTHS, near_edge
from fegear.ltca.validity import APPROACH_LIMIT, P_ELASTIC_LIMIT_MPA, validity_checks

REPO = Path(__file__).resolve().parents[1]
FZG = REPO / "cases" / "fzg_spur.toml"
FACE_GEAR = REPO / "cases" / "face_gear_nominal.toml"


def _fzg(**errors):
    case = fegear.load_case(FZG)
    return case.with_errors(**errors) if errors else case


def _pair(result, position: int, k: int, j: int):
    return next(
        q for q in result.positions[position].pairs if (q.pinion_tooth, q.gear_tooth) == (k, j)
    )


@pytest.fixture(scope="module")
def fzg_rated():
    """``cases/fzg_spur.toml`` as shipped (200 N·m, hybrid level 0, 9 positions)."""
    return fegear.run(_fzg())


# --------------------------------------------------------------------------------------------
# Item 1: the edge's reach
# --------------------------------------------------------------------------------------------


def test_near_edge_is_three_semi_widths_or_two_cells():
    """A row of cells along ``ξ`` (0.1 mm) with the edge cell at 0: within ``3 b`` (b = 0.2 mm)
    or two cells, near; beyond both, away."""
    x = 0.1 * np.arange(12)
    local = np.column_stack([x, np.zeros_like(x)])
    on = x == 0.0
    near = near_edge(local, np.array([0.1, 1.0]), on, b=0.2)
    assert EDGE_REACH_SEMI_WIDTHS == 3.0 and EDGE_REACH_CELLS == 2.0
    np.testing.assert_array_equal(near, x <= 0.6 + 1e-12)  # 3 b = 0.6 mm > 2 cells = 0.2 mm
    # a narrow patch on coarse cells: the two cells (2 × 0.5 mm along ξ) set the reach
    near = near_edge(local * 5.0, np.array([0.5, 1.0]), on, b=0.05)
    np.testing.assert_array_equal(near, 5.0 * x <= 1.0 + 1e-12)


def test_fzg_at_400_Nm_reports_the_interior_not_the_pinion_tip_corner(fzg_rated):
    """FZG at 400 N·m on the gear: the entering pair at position 0 loads a 0.1 mm sliver along
    the pinion tip (7751 MPa). It was reported as "p_max away from the edges" because the grid's
    last cells before the tip were not marked as edge cells; every cell of that sliver lies
    within 3 semi-widths of the tip. ``cycle.p_max_MPa`` is the interior value of the
    single-pair positions: within 10 % of the rated run's scaled by √T (Hertz: p ∝ √F)."""
    r = fegear.run(_fzg().replace(torque2_Nm=400.0))
    c, rated = r.cycle, fzg_rated.cycle
    expected = rated.p_max_MPa * math.sqrt(400.0 / 200.0)
    assert c.p_max_MPa == pytest.approx(expected, rel=0.10), (c.p_max_MPa, expected)
    assert c.p_max_pair == (0, 0)  # the single pair, not the sliver
    sliver = _pair(r, 0, 1, -1)
    assert sliver.in_contact and sliver.p_interior_MPa is None
    assert "pinion tip" in sliver.edges and sliver.p_edge_MPa > 3.0 * c.p_max_MPa
    assert c.p_max_edge_MPa == sliver.p_edge_MPa  # the corner value beside the headline


@pytest.mark.slow
def test_fzg_tilted_axis_reports_the_interior_not_the_tip_sliver(fzg_rated):
    """(slow: the tilted pair's contact zone gets its own sectors and operators, ~40 s cold.)
    FZG with ``f_sigma_beta_mm = 0.03``: the entering pair's sliver at the pinion tip is an
    edge value; the headline is an interior pressure of another pair, above the aligned pair's
    (the tilt loads one face end), and it is line Hertz of its own row of cells: the load per
    unit length of the row through it, the relative radius of the flanks there (the roll
    lengths of the contact point on both base circles). Measured: the entering pair near the
    gear tip (ρ1 4.8 mm against 12.2 mm at the aligned headline), 1676 MPa, 0.3 % from it."""
    from fegear.geometry.transforms import apply_points, inverse
    from fegear.mechanics.hertz_closed_form import effective_modulus, hertz_line

    r = fegear.run(_fzg(f_sigma_beta_mm=0.03))
    c, aligned = r.cycle, fzg_rated.cycle.p_max_MPa
    sliver = _pair(r, 0, 1, -1)
    assert sliver.in_contact and sliver.p_interior_MPa is None and "pinion tip" in sliver.edges
    assert c.p_max_pair != (1, -1) and c.p_max_MPa > aligned
    pos = r.run.cycle.positions[c.p_max_position]
    (ip,) = [i for i, q in enumerate(pos.pairs) if (q.k, q.j) == tuple(c.p_max_pair)]
    cells, start = pos.cells[ip], sum(x.n for x in pos.cells[:ip])
    force = pos.solution.force[start : start + cells.n]
    i = int(np.argmin(np.abs(force / cells.area - c.p_max_MPa)))  # the headline's cell
    assert force[i] / cells.area[i] == pytest.approx(c.p_max_MPa, rel=1e-12)
    # the row of cells through it (one cell length along the line) and its load per length
    row = np.abs(cells.local[:, 1] - cells.local[i, 1]) < 0.5 * cells.cell_mm[1]
    w = force[row].sum() / cells.cell_mm[1]
    asm, pinion, gear = r.run.assembly, r.run.pair.pinion, r.run.pair.gear
    # (a radius about a member's axis does not depend on the member's turn)
    x1 = apply_points(inverse(asm.placement1(0.0)), cells.centers[i])
    rho1 = math.sqrt(math.hypot(x1[0], x1[1]) ** 2 - pinion.r_b**2)
    x2 = apply_points(inverse(asm.placement2(0.0)), cells.centers[i])
    rho2 = math.sqrt(math.hypot(x2[0], x2[1]) ** 2 - gear.r_b**2)
    h = hertz_line(w, 1.0 / (1.0 / rho1 + 1.0 / rho2), effective_modulus(206e3, 0.3, 206e3, 0.3))
    # 6 cells across the 0.26 mm strip; the FZG validation row's line Hertz: within 3 %
    assert c.p_max_MPa == pytest.approx(h.p0_MPa, rel=0.03), (c.p_max_MPa, h.p0_MPa, rho1, w)


# --------------------------------------------------------------------------------------------
# Item 3: the validity range
# --------------------------------------------------------------------------------------------


def _validity(out: Path) -> dict:
    doc = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    return {v["name"]: v for v in doc["validity"]["checks"]} | {
        "in_range": doc["validity"]["in_range"]
    }


def test_rated_fzg_is_inside_the_validity_range(fzg_rated):
    doc = fzg_rated.summary
    assert doc["validity"]["in_range"] is True
    checks = {c["name"]: c for c in doc["validity"]["checks"]}
    # rated FZG: the approach 0.39 % of the module, p_max 1170 MPa (measured)
    assert 0.0 < checks["approach_over_module"]["value"] < 0.25 * APPROACH_LIMIT
    assert checks["p_max_over_steel_limit"]["value"] == doc["cycle"]["p_max_MPa"]
    assert checks["patch_spans_flank"]["value"] == 0


def test_fzg_at_1e4_times_its_torque_is_flagged_outside_the_range(tmp_path, capsys):
    """FZG at 2e6 N·m (1e4 × 200 N·m): the loaded TE is 156 026″ (0.76 rad) and every patch
    covers the flank. Still exit 0 (the equations have a solution), with a terminal warning per
    exceeded check and ``validity`` in summary.json naming the number and the limit."""
    path = tmp_path / "fzg.toml"
    path.write_text(FZG.read_text().replace("torque2_Nm = 200.0", "torque2_Nm = 2e6"))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert err.count("warning: outside the model's validity range") == 2, err
    assert "the elastic approach at the contact is" in err and "limit 2 %" in err
    v = _validity(out)
    assert v["in_range"] is False
    # 0.76 rad × 95 mm arm, over the 4.5 mm module: 16 modules (measured 16.0)
    assert v["approach_over_module"]["exceeded"] and v["approach_over_module"]["value"] > 10.0
    assert v["approach_over_module"]["limit"] == APPROACH_LIMIT
    assert v["patch_spans_flank"]["exceeded"] and v["patch_spans_flank"]["value"] == 9
    # every loaded contact runs to a flank edge: no p_max away from them, so no pressure check
    assert v["p_max_over_steel_limit"]["value"] is None and v["p_max_over_steel_limit"]["reason"]


@pytest.mark.slow
def test_face_gear_at_1e4_times_its_torque_is_flagged_outside_the_range(tmp_path, capsys):
    """(slow: the load closes pairs outside the rated contact zone, whose sectors are built
    again, ~4 min cold.) The seed face gear at 1e4 × its pinion torque (5 positions): the
    approach is 1.5 modules and the patches run over the flank."""
    text = FACE_GEAR.read_text().replace("= 350.14 ", "= 3501400.0 ")
    path = tmp_path / "fg.toml"
    path.write_text(text.replace("n_positions = 25", "n_positions = 5"))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "-q"]) == 0
    assert "outside the model's validity range" in capsys.readouterr().err
    v = _validity(out)
    assert v["in_range"] is False
    assert v["approach_over_module"]["exceeded"] and v["patch_spans_flank"]["exceeded"]


def test_p_max_beyond_the_steel_limit_is_flagged_with_number_and_limit():
    """The pressure check on a synthetic cycle: p_max 3990 MPa inside, 4010 MPa outside."""
    from test_reliability import _cycle, _pair

    for p, exceeded in ((3990.0, False), (4010.0, True)):
        c = _cycle([(-10.0, [_pair(0, 1.0, p_int=p)], "ok")])
        checks = {v.name: v for v in validity_checks(c, 4.5, "spur", p, 0)}
        v = checks["p_max_over_steel_limit"]
        assert v.value == p and v.limit == P_ELASTIC_LIMIT_MPA and v.exceeded is exceeded
        assert v.positions == ((0,) if exceeded else ())
        assert ("4000 MPa hardened steel" in v.text) is exceeded


@pytest.mark.parametrize("tilt", [0.0, 0.03])
def test_the_last_cells_before_the_pinion_tip_are_edge_cells(tilt):
    """The cells of FZG's entering pair at φ1 = -11.25° on a grid turned against the flank (as
    ``hybrid`` turns it to the patch): in every row along the face, the cell nearest the pinion
    tip carries the pinion-tip bit, whether it reaches the tip or stops up to a cell short of it
    (the grid keeps only cells whose centre is on the flank). The TCA alone: no FE."""
    from fegear.ltca import LTCAOptions
    from fegear.ltca.cycle import cycle_tca
    from fegear.ltca.grid import EDGE_TAGS, pair_cells
    from fegear.pipeline.pair import build_pair

    pair = build_pair(_fzg(f_sigma_beta_mm=tilt))
    tca, positions, _ = cycle_tca(pair.pinion, pair.gear, pair.assembly, LTCAOptions(n_positions=9))
    pos = positions[0]
    gi = next(i for i, g in enumerate(pos.grids) if (g.k, g.j) == (1, -1))
    tip = 1 << EDGE_TAGS.index(("pinion", "tip"))
    face_ends = sum(1 << EDGE_TAGS.index(e) for e in EDGE_TAGS if e[1].startswith("v_"))
    for angle in (0.0, 3e-3, -3e-3):
        c = pair_cells(tca, pos, gi, (0.01, 0.5), 0.02, max_cells=4000, angle=angle)
        assert c is not None and c.boundary_edges is not None
        eta = c.local[:, 1] - c.local[:, 1].min()
        rows = np.round(eta / 0.5).astype(int)  # the cell rows across the face
        checked = 0
        for r in np.unique(rows):
            row = np.flatnonzero(rows == r)
            if np.any(c.boundary_edges[row] & face_ends):
                continue  # a row at a face end may stop at the face end first (a corner)
            last = row[np.argmax(c.uv[row, 0])]
            assert c.boundary_edges[last] & tip, (tilt, angle, r)
            checked += 1
        assert checked >= 4  # rows within g_max of contact (the tilted pair: one face end)
