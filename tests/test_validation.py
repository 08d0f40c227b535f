"""The rows of docs/validation.md as tests: fegear against references computed without the solver.

The references (:mod:`fegear.validation.iso6336`, :mod:`fegear.mechanics.hertz_closed_form`) are
checked against
hand-computed numbers and each other; each row then runs fegear (:mod:`fegear.validation.rows`)
at the fidelity and level its tolerance is stated for. Runs reuse the session's artefact cache:
the FZG sectors at ``hybrid`` level 0 and the spiral bevel's TCA are those of
``tests/test_reliability.py`` and ``tests/test_gear_cli.py`` when the whole suite runs.
"""

from __future__ import annotations

import sys
import types
from dataclasses import asdict
from pathlib import Path

import pytest
from test_references import NOMINAL, _check, summaries

from fegear.validation import Row, Value, as_row
from fegear.validation import rows as V
from fegear.validation.iso6336 import (
    basic_rack_factor,
    inverse_involute,
    involute,
    iso6336_2_sigma_H0,
    pitch_point_line_hertz,
    single_stiffness,
    theoretical_single_stiffness,
)

REPO = Path(__file__).resolve().parents[1]
FZG = dict(z1=16, z2=24, x1=0.1817, x2=0.1715)


# --------------------------------------------------------------------------------------------
# The references
# --------------------------------------------------------------------------------------------


def test_iso6336_1_theoretical_single_stiffness_of_the_fzg_pair():
    # by hand: q' = 0.04723 + 0.15551/16 + 0.25791/24 - 0.00635·0.1817 - 0.11654·0.1817/16
    #   - 0.00193·0.1715 - 0.24188·0.1715/24 + 0.00529·0.1817² + 0.00182·0.1715² = 0.0633872
    # (7 digits: the hand sum's rounding)
    assert theoretical_single_stiffness(**FZG) == pytest.approx(1 / 0.0633872, rel=2e-6)
    s = single_stiffness(**FZG)
    # the factors of c' (ISO 6336-1:2006): CM 0.8, solid disc CR 1, CB of a 1.25 m dedendum
    assert (s.CM, s.CR, s.cos_beta) == (0.8, 1.0, 1.0)
    assert s.CB == pytest.approx(0.975, rel=1e-15)
    assert s.c_prime == pytest.approx(s.c_th * 0.8 * 0.975, rel=1e-15)
    assert basic_rack_factor(1.2, 20.0) == 1.0  # ISO's reference rack: no correction
    # a helix raises the virtual tooth numbers, hence c'th (q' falls with 1/zn)
    assert theoretical_single_stiffness(**FZG, beta_deg=15.0) > s.c_th


def test_line_hertz_at_the_pitch_point_is_iso6336_2_sigma_H0():
    h = pitch_point_line_hertz(16, 24, 4.5, 20.0, 0.1817, 0.1715, 14.0, 2.0e5)
    iso = iso6336_2_sigma_H0(16, 24, 4.5, 20.0, 0.1817, 0.1715, 14.0, 2.0e5)
    # the same formula written twice (Johnson's cylinders, ISO's Z_H Z_E): round-off apart
    assert h.p_H_MPa == pytest.approx(iso, rel=1e-12)
    assert h.p_H_MPa == pytest.approx(1100.04, abs=0.01)  # the "line Hertz 1100.0 MPa"
    # the working centre distance from the profile shifts is the FZG's 91.5 mm (rounded data)
    assert h.centre_distance_mm == pytest.approx(91.5, abs=1e-3)
    assert involute(inverse_involute(involute(h.alpha_w_rad))) == pytest.approx(
        involute(h.alpha_w_rad), rel=1e-14
    )


def test_the_references_agree_with_fegear_geometry():
    """The closed-form pair (ISO 21771) is the pair fegear generates: same base radii, same
    centre distance (the assembly's, from the generated profiles), to round-off."""
    from fegear.api import load_case
    from fegear.pipeline.pair import build_pair

    pair = build_pair(load_case(REPO / "cases" / "fzg_spur.toml"))
    h, _ = V.fzg_reference()
    assert pair.pinion.r_b == pytest.approx(h.r_b1_mm, rel=1e-12)
    assert pair.gear.r_b == pytest.approx(h.r_b2_mm, rel=1e-12)
    # the assembly solves the zero-backlash distance numerically (measured 3e-10 mm apart)
    assert pair.assembly.axes_distance() == pytest.approx(h.centre_distance_mm, abs=1e-7)


# --------------------------------------------------------------------------------------------
# The rows
# --------------------------------------------------------------------------------------------


def _ratios(rows: list[Row], fidelity: str, level: int | None) -> dict[str, float]:
    return {
        r.key: r.ratio(v)
        for r in rows
        for v in r.values
        if v.fidelity == fidelity and v.level == level
    }


def test_hertz_scene_hybrid_matches_closed_form_hertz():
    rows = V.hertz_scene_rows(fe_levels=(), hybrid_levels=(3,))
    q = _ratios(rows, "hybrid", 3)
    assert set(q) == {"hertz_scene_p0", "hertz_scene_a", "hertz_scene_b"}
    # 1 %: the recovered peak on 16 cells across 2b (measured +0.21 %, −0.02 %, −0.14 %);
    # the block is 20 mm deep, not a half-space
    for key, ratio in q.items():
        assert abs(ratio - 1.0) < 0.01, (key, ratio)


def test_fzg_pitch_point_hybrid_matches_line_hertz_and_iso_stiffness():
    run = V.pitch_point_run("hybrid", 0)
    assert run.n_pairs == 1  # the pitch point lies in the single-pair zone
    assert run.cells_across >= 8  # the patch is resolved (n_across of the hybrid)
    q = _ratios(V.fzg_rows([run]), "hybrid", 0)
    # 3 %: cells 1/10 of the 0.33 mm contact width; mid-face of a 14 mm line contact is in
    # plane strain as line Hertz assumes (measured +0.15 %, row peaks −0.6 … +1.1 %)
    assert abs(q["fzg_line_hertz"] - 1.0) < 0.03, q
    # 10 %: ISO's c'th is a regression on solid-disc deflections with a 1.2 m dedendum (fegear
    # cuts 1.25 m: CB −2.5 %); the sector's fixed bore and clamped cuts are not a disc on a
    # shaft (measured +4.0 %; +2.7 % and +0.8 % at hybrid levels 1 and 2)
    assert abs(q["fzg_single_stiffness"] - 1.0) < 0.10, q


@pytest.mark.slow
def test_fzg_pitch_point_converges_towards_the_references():
    """hybrid level 1 within the same tolerances; fe refinement stiffens less and less (c' falls
    towards c'th) and raises the mid-face pressure towards line Hertz from far below."""
    hy = V.pitch_point_run("hybrid", 1)
    q = _ratios(V.fzg_rows([hy]), "hybrid", 1)
    assert abs(q["fzg_line_hertz"] - 1.0) < 0.03, q  # same reasons as at level 0
    assert abs(q["fzg_single_stiffness"] - 1.0) < 0.10, q
    fe = [V.pitch_point_run("fe", lv) for lv in (0, 1, 2)]
    c = [r.c_prime for r in fe]
    p = [r.p_mid_MPa for r in fe]
    # measured c' 20.66 / 19.25 / 18.40, p 128 / 179 / 261 MPa: monotone, far from converged
    assert c[0] > c[1] > c[2] > hy.c_prime, c
    assert p[0] < p[1] < p[2] < hy.p_mid_MPa, p


def test_spiral_bevel_unloaded_te_is_the_design_parabola():
    b = V.bevel_te_parabola()
    q = _ratios(V.bevel_rows(b), "tca", None)
    # 5 %: the synthesis fixes the TE's second order at the mean point only; the third-order
    # roll centres it; the TCA's higher orders and transfer points set the rest (measured
    # +1.8 % peak-to-peak, +2.1 % curvature)
    assert abs(q["bevel_te_pp"] - 1.0) < 0.05, q
    assert abs(q["bevel_te_curvature"] - 1.0) < 0.05, q
    # the parabola's vertex is the mean point (φ1 = 0): within 1 % of the cycle's 30°
    assert abs(b.vertex_deg) < 0.3, b.vertex_deg


@pytest.mark.slow
def test_face_gear_te_contact_ratio_and_patch_grow_with_load():
    """The seed trend at hybrid level 0 over the seed's light, moderate, heavy torques."""
    rows = V.load_trend_rows({("hybrid", 0): V.load_trend("hybrid", 0)})
    for r in rows:
        (v,) = r.values
        # strictly increasing: a heavier load closes more pairs (contact ratio), spreads each
        # patch (Hertz: a ~ F^(1/3)) and deflects the teeth more (TE)
        assert r.increasing(v), (r.key, v.series)


# --------------------------------------------------------------------------------------------
# The ISO 6336-3 root-stress hook
# --------------------------------------------------------------------------------------------


def test_root_stress_hook_takes_rows_from_the_module_or_reports_pending(monkeypatch):
    monkeypatch.setattr(V, "ROOT_STRESS_MODULE", "fegear.validation._no_such_module")
    assert V.root_stress_rows() is None
    pending = V.pending_root_stress_row()
    assert pending.pending and pending.values == () and pending.reference is None  # no numbers
    fake = types.ModuleType("fegear_validation_fake_root")
    row = {
        "key": "root_pinion",
        "check": "FZG root stress, pinion",
        "quantity": "σF (MPa)",
        "reference": 300.0,
        "reference_text": "ISO 6336-3 σF0",
        "values": [{"fidelity": "hybrid", "level": 0, "value": 310.0}],
        "tolerance": "15 %",
        "command": "python docs/make_validation.py root",
        "test": "tests/test_root.py::test_x",
    }
    fake.rows = lambda: [row]  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, fake.__name__, fake)
    monkeypatch.setattr(V, "ROOT_STRESS_MODULE", fake.__name__)
    (r,) = V.root_stress_rows()
    assert isinstance(r, Row) and r.ratio(r.values[0]) == pytest.approx(310.0 / 300.0)


# --------------------------------------------------------------------------------------------
# The page
# --------------------------------------------------------------------------------------------


def test_rows_survive_the_json_round_trip_of_the_generator():
    r = Row(
        key="k",
        check="c",
        quantity="q",
        reference=None,
        reference_text="rises",
        values=(Value("hybrid", 0, 3.0, series=(1.0, 2.0, 3.0), seconds=1.0),),
        tolerance="t",
        command="cmd",
        test="test",
        loads=("a", "b", "c"),
    )
    back = as_row(asdict(r))
    assert list(back.values[0].series) == [1.0, 2.0, 3.0]  # JSON gives lists for tuples
    assert back.increasing(back.values[0]) is True and back.ratio(back.values[0]) is None


def test_the_page_has_every_row_and_its_command():
    text = (REPO / "docs" / "validation.md").read_text(encoding="utf-8")
    assert "python docs/make_validation.py" in text
    for what in ("Hertz scene", "line Hertz", "ISO 6336-1", "ISO 6336-3", "parabolic TE",
                 "grows with the load"):  # fmt: skip
        assert what in text, what


# --------------------------------------------------------------------------------------------
# The nominal cases give their stored reference summaries (tests/reference/)
# --------------------------------------------------------------------------------------------
# From tests/test_references.py (whose slow tests check every case): here the nominal spiral
# bevel's run at the TCA is the one of test_spiral_bevel_unloaded_te_is_the_design_parabola
# above, read back from the cache.


@pytest.mark.parametrize("name", NOMINAL)
def test_the_nominal_cases_give_the_reference_tca(name):
    _check(summaries.CASES / f"{name}.toml", "tca")
