"""The CalculiX cross-check's comparisons (fegear.validation.calculix_rows) on hand-made rows."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fegear.validation.calculix_rows import (
    ccx_movement,
    criteria,
    equal_accuracy,
    gear_comparison,
    markdown,
    richardson,
    validation_section,
)

RESULTS = Path(__file__).resolve().parent.parent / "benchmarks" / "results" / "calculix.json"


def _ccx(h: float, shares: dict, theta: float, te: float, p_int: dict, s: float) -> dict:
    pairs = [{"k": k, "j": j, "load_share": v, "p_max_MPa": p_int[(k, j)] or 0.0,
              "p_interior_MPa": p_int[(k, j)], "semi_major_mm": 4.0, "semi_minor_mm": 0.3}
             for (k, j), v in shares.items()]  # fmt: skip
    return {"element_mm": h, "ccx_s": s, "export_s": 1.0, "peak_MB": 100.0, "dofs": 3,
            "result": {"pairs": pairs, "theta_rad": theta, "te_loaded_arcsec": te}}  # fmt: skip


def _fegear(shares: dict, theta: float, te: float, p_int: dict) -> dict:
    pairs = [{"k": k, "j": j, "share": v, "p_interior": p_int[(k, j)], "p_max": 1.0, "a": 4.0,
              "b": 0.3} for (k, j), v in shares.items()]  # fmt: skip
    return {"fidelity": "hybrid", "level": 0, "pairs": pairs, "theta": theta, "te_loaded": te,
            "cold_s": 10.0, "warm_s": 2.0, "peak_MB": 50.0}  # fmt: skip


@pytest.fixture
def section() -> dict:
    """Two CalculiX sizes whose lag grows by 4 % (inside the 5 % bound) and whose interior
    p_max falls by 20 % (outside it), and fegear hybrid 0 with a third pair CalculiX lacks."""
    p = {(0, 0): 1000.0, (1, 1): 900.0}
    rows = {
        "phi1_deg": 1.0,
        "ccx": [
            _ccx(1.0, {(0, 0): 0.60, (1, 1): 0.40}, 1.00e-4, -20.0, p, 100.0),
            _ccx(
                0.5,
                {(0, 0): 0.58, (1, 1): 0.42},
                1.04e-4,
                -20.8,
                {k: 0.8 * v for k, v in p.items()},
                400.0,
            ),  # fmt: skip
        ],
        "fegear": [
            _fegear(
                {(0, 0): 0.57, (1, 1): 0.41, (2, 2): 0.02},
                1.02e-4,
                -20.4,
                {(0, 0): 820.0, (1, 1): None, (2, 2): None},
            )  # fmt: skip
        ],
    }
    return {"face_gear": {"two pairs": rows}}


def test_comparison_against_the_finest_size(section):
    rows = section["face_gear"]["two pairs"]
    c = gear_comparison(rows, rows["fegear"][0])
    # the largest share difference; the pair CalculiX lacks counts with share 0
    assert c["shares"] == pytest.approx(0.02)
    assert c["lag"] == pytest.approx(1.02 / 1.04 - 1)
    assert c["te"] == pytest.approx(20.4 / 20.8 - 1)
    assert c["p_interior"][(0, 0)] == pytest.approx(820.0 / 800.0 - 1)
    assert c["p_interior"][(1, 1)] is None  # no interior peak on fegear's side
    mv = ccx_movement(rows)
    assert mv["shares"] == pytest.approx(0.02) and mv["lag"] == pytest.approx(0.04)
    assert mv["p_interior"][(0, 0)] == pytest.approx(-0.2)


def test_equal_accuracy_picks_the_coarsest_size_as_close_as_fegear(section):
    rows = section["face_gear"]["two pairs"]
    eq = equal_accuracy(rows, rows["fegear"][0])
    # fegear is 0.02 off in shares and 1.9 % in lag; the coarse size is 0.02 and 3.8 % off the
    # finest: only the finest size is as close
    assert eq["ccx"]["element_mm"] == 0.5 and eq["ratio"] == pytest.approx(40.0)


def test_criteria_say_undecided_where_calculix_still_moves(section):
    by = {c["check"]: c for c in criteria(section)}
    assert by["load shares within 0.03"]["holds"]
    te = by["loaded TE within 5 %"]
    assert te["holds"] and abs(te["ccx_moves"]) < 0.05
    p = by["interior p_max of pair (0, 0) within 5 %"]
    assert p["holds"] and abs(p["ccx_moves"]) > 0.05  # within, against a value still moving
    text = validation_section(section)
    assert "interior p_max of pair (0, 0) within 5 %: +2.50% (CalculiX moves -20.00%): not " \
        "decided" in text  # fmt: skip
    assert "loaded TE within 5 %: -1.92% (CalculiX moves +4.00%): holds" in text


@pytest.mark.skipif(not RESULTS.is_file(), reason="no measured calculix.json")
def test_the_measured_rows_render():
    doc = json.loads(RESULTS.read_text(encoding="utf-8"))
    assert "## At equal accuracy" in markdown(doc)
    assert "Acceptance bounds" in validation_section(doc)


def test_richardson_recovers_a_known_limit_and_order():
    # f(h) = 3 + 0.5 h^2 on unequal steps (2, 1.4, 1 mm): the limit 3 and the order 2 exactly
    # (to the fixed point's 1e-10); GCI = 1.25 |f1 - f2| / |f1| / (r21^p - 1) by hand
    h = [2.0, 1.4, 1.0]
    ext = richardson(h, [3 + 0.5 * x**2 for x in h])
    assert ext.value == pytest.approx(3.0, abs=1e-9) and ext.order == pytest.approx(2.0, abs=1e-8)
    assert ext.gci == pytest.approx(1.25 * (0.5 * 1.96 - 0.5) / 3.5 / (1.4**2 - 1), rel=1e-8)
    assert ext.sizes == (2.0, 1.4, 1.0)
    # a first-order quantity approached from above, given fine to coarse with a coarser extra
    hs = [0.5, 1.0, 2.0, 4.0]
    ext = richardson(hs, [-7.0 - 2.0 * x for x in hs])
    assert ext.value == pytest.approx(-7.0, abs=1e-9) and ext.order == pytest.approx(1.0)
    assert ext.sizes == (2.0, 1.0, 0.5)  # the three finest


def test_richardson_refuses_what_is_not_in_the_asymptotic_range():
    assert richardson([2.0, 1.0], [1.0, 2.0]) is None  # two sizes
    assert richardson([2.0, 1.4, 1.0], [1.0, 2.0, 1.5]) is None  # oscillating
    assert richardson([2.0, 1.4, 1.0], [1.0, 1.0, 1.0]) is None  # stalled
    # the last step moves more than the one before: an observed order below 0.5 (diverging)
    assert richardson([2.0, 1.0, 0.5], [1.0, 1.1, 1.4]) is None


def test_criteria_check_the_te_against_the_extrapolated_calculix(section):
    rows = section["face_gear"]["two pairs"]
    # a third, finer size on f(h) = -21.6 + 1.6 h^1 (sizes 1, 0.5, 0.25): the limit -21.6
    rows["ccx"][0]["result"]["te_loaded_arcsec"] = -20.0
    rows["ccx"][1]["result"]["te_loaded_arcsec"] = -20.8
    rows["ccx"].append(_ccx(0.25, {(0, 0): 0.575, (1, 1): 0.425}, 1.05e-4, -21.2,
                            {(0, 0): 790.0, (1, 1): 700.0}, 900.0))  # fmt: skip
    (te,) = [c for c in criteria(section) if c["check"] == "loaded TE within 5 %"]
    ext = te["extrapolation"]
    assert ext.value == pytest.approx(-21.6) and ext.order == pytest.approx(1.0)
    assert te["value"] == pytest.approx(20.4 / 21.6 - 1)  # -5.6 %: outside the bound
    assert te["ccx_moves"] == pytest.approx(1.25 * 0.4 / 21.2)  # GCI 2.4 %: decided
    assert not te["holds"]
    text = validation_section(section)
    assert "loaded TE within 5 %: -5.56% against CalculiX extrapolated to zero element size " \
        "(-21.600″ from 1, 0.5, 0.25 mm, observed order 1.00, GCI ±2.36%): does NOT hold." \
        in text  # fmt: skip


def test_unresolved_pressure_and_an_unbounded_ladder_decide_nothing(section):
    rows = section["face_gear"]["two pairs"]
    # CalculiX's pressures of pair (0, 0) integrate to 7.4 times its force: however little its
    # p_max moves, it is not a reference
    for r in rows["ccx"]:
        for p in r["result"]["pairs"]:
            p["normal_force_N"], p["nodal_force_N"] = 1000.0, 7400.0 if p["k"] == 0 else 1020.0
            p["p_interior_MPa"] = 800.0 if p["k"] == 0 else 700.0
    # a third size whose lag step grows (0.8 then 1.0 arcsec): no order, no extrapolation
    rows["ccx"].append(_ccx(0.25, {(0, 0): 0.58, (1, 1): 0.42}, 1.06e-4, -21.8,
                            {(0, 0): 800.0, (1, 1): 700.0}, 900.0))  # fmt: skip
    for p in rows["ccx"][-1]["result"]["pairs"]:
        p["normal_force_N"], p["nodal_force_N"] = 1000.0, 7400.0 if p["k"] == 0 else 1020.0
    by = {c["check"]: c for c in criteria(section)}
    assert by["interior p_max of pair (0, 0) within 5 %"]["pressure_integral"] == pytest.approx(7.4)
    assert by["loaded TE within 5 %"]["not_extrapolated"]
    text = validation_section(section)
    assert "integrate to 7.40 times the pair's contact force (its pressure is not resolved)" in text
    assert "loaded TE within 5 %: -6.42% (CalculiX moves +4.81%): not decided: CalculiX's three " \
        "finest sizes do not converge" in text  # fmt: skip
