"""Measured flanks (issue 47) through the TCA and the loaded analysis.

- a zero grid reproduces the design run bit for bit (every number of ``summary.json`` but the
  echo of the grid), at the ``tca`` and the default ``hybrid`` fidelity, and reads the design's
  meshes and compliance operators but not its TCA or cycle;
- a grid of an analytic lead crowning (what a measuring machine reads of it:
  :func:`fegear.tca.deviation.normal_deviation`) on the uncrowned pair gives the crowned pair's
  TCA and loaded results, within tolerances derived from the spline's interpolation error
  measured on the grid.

The pair is ``cases/helical_crowned.toml`` (10 µm of lead crowning on the pinion) at 5 positions.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import fegear
from fegear.pipeline.pair import build_pair
from fegear.tca.deviation import normal_deviation
from fegear.tca.surfaces import flank_map

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
from compare_summaries import differences  # noqa: E402

CASE = REPO / "cases" / "helical_crowned.toml"
ARCSEC = 180 / math.pi * 3600


def _case(helix_deg: float | None = None):
    c = fegear.load_case(CASE).replace(n_positions=5)
    if helix_deg is not None:
        c = c.replace(pair={**c.pair, "helix_angle_deg": helix_deg})
    return c


def _uncrowned(case):
    return case.replace(pair={**case.pair, "lead_crowning_mm": [0.0, 0.0]})


def _write_grid(path: Path, s, t, d_um) -> None:
    lines = ["normalized," + ",".join(repr(float(x)) for x in t)]
    for i, x in enumerate(s):
        lines.append(repr(float(x)) + "," + ",".join(repr(float(y)) for y in d_um[i]))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _crowning_grid(case, path: Path, nx: int = 5, ny: int = 9) -> float:
    """Write the pinion drive flank's lead crowning of ``case`` as a measured grid (µm) and
    return the spline's interpolation error (mm) against the measured deviation on a 41 × 141
    check grid of the working flank."""
    crowned = build_pair(case).pinion
    flat = build_pair(_uncrowned(case)).pinion
    nominal, modified = flank_map(flat, "drive"), flank_map(crowned, "drive")
    bd = nominal.bounds
    s, t = np.linspace(0, 1, nx), np.linspace(0, 1, ny)
    U = bd.u_fillet + s[:, None] * (bd.u_tip - bd.u_fillet) + 0 * t[None, :]
    V = bd.v_start + t[None, :] * (bd.v_end - bd.v_start) + 0 * s[:, None]
    _write_grid(path, s, t, 1e3 * normal_deviation(nominal, modified, U, V))
    measured = build_pair(_uncrowned(case).replace(topography={"pinion_drive": str(path)}))
    Uc, Vc = np.meshgrid(np.linspace(bd.u_fillet, bd.u_tip, 41),
                         np.linspace(bd.v_start, bd.v_end, 141), indexing="ij")  # fmt: skip
    exact = normal_deviation(nominal, modified, Uc, Vc)
    return float(np.abs(measured.pinion.topography("drive").deviation(Uc, Vc)[0] - exact).max())


def _doc(result) -> dict:
    d = dict(result.summary)
    for k in ("timings_s", "cache", "versions"):
        d.pop(k, None)
    return d


# ------------------------------------------------------------------ a zero grid


@pytest.fixture(scope="module")
def zero_grid(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("topography") / "zero.csv"
    _write_grid(path, [0.0, 0.5, 1.0], [0.0, 0.5, 1.0], np.zeros((3, 3)))
    return path


@pytest.mark.parametrize("fidelity", ["tca", "hybrid"])
def test_a_zero_grid_reproduces_the_design_run(fidelity, zero_grid):
    case = _case()
    design = fegear.run(case, fidelity=fidelity, fields=False)
    grids = {"pinion_drive": str(zero_grid), "gear_drive": str(zero_grid)}
    zero = fegear.run(case.replace(topography=grids), fidelity=fidelity, fields=False)
    a, b = _doc(design), _doc(zero)
    # the echo of the grids is the only difference: every number is the same, bit for bit
    assert b["inputs"].pop("topography")["pinion_drive"]["max_um"] == 0.0
    # and the measured run's ease-off section holds the design's too: the same, no difference
    design_eo, diff = b["ease_off"].pop("design"), b["ease_off"].pop("measured_minus_design_um")
    assert design_eo == {k: v for k, v in a["ease_off"].items() if k not in ("file", "grid")}
    assert diff == {"min": 0.0, "max": 0.0, "rms": 0.0}
    assert differences(a, b) == []
    # the measured run never reads the design's TCA or cycle; it reads its meshes and operators
    used = zero.summary["cache"]
    assert used["built"].get("tca", 0) >= 1 and "cycle" not in used["hits"]
    if fidelity == "hybrid":
        assert used["built"].get("cycle") == 1
        assert used["hits"].get("mesh") == 2 and "mesh" not in used["built"]
        assert used["hits"].get("compliance", 0) > 0 and "compliance" not in used["built"]


# ------------------------------------------------------------------ an analytic crowning


@pytest.fixture(scope="module")
def crowning(tmp_path_factory):
    """The crowned pair and the uncrowned pair with the crowning's grid, at ``tca`` and
    ``hybrid``; and the grid's interpolation error (mm)."""
    path = tmp_path_factory.mktemp("topography") / "crowning.csv"
    case = _case()
    err = _crowning_grid(case, path)
    measured = _uncrowned(case).replace(topography={"pinion_drive": str(path)})
    runs = {f: (fegear.run(case, fidelity=f, fields=False).summary,
                fegear.run(measured, fidelity=f, fields=False).summary)
            for f in ("tca", "hybrid")}  # fmt: skip
    return runs, err, build_pair(case)


def test_the_spline_interpolates_the_measured_crowning(crowning):
    _, err, _ = crowning
    # the measured crowning is the quadratic C cos β_b (2z/b)² (reproduced by the cubic
    # spline to rounding) plus its second-order part O(δ |∂δ/∂z| sin β_b) = 6.5e-6 mm, which
    # the 9 points along the face interpolate to 1.5e-11 mm
    assert err < 1e-10


def test_a_grid_of_a_lead_crowning_gives_the_crowned_tca(crowning):
    runs, err, pair = crowning
    a, b = runs["tca"]
    rb2, beta_b = pair.gear.r_b, pair.pinion.beta_b
    # a gap error e turns the gear by at most e / (r_b2 cos β_b); 1e-9″ of the TCA's closing
    te_tol = ARCSEC * err / (rb2 * math.cos(beta_b)) + 1e-9
    for pa, pb in zip(a["positions"], b["positions"], strict=True):
        assert abs(pa["te_unloaded_arcsec"] - pb["te_unloaded_arcsec"]) < te_tol
    # the contact point sits at the minimum of a gap a z² (a = 4 C_β cos β_b / b², the
    # crowning's) along the face: an error e moves it by at most 2 √(e/a) (measured: 6e-7 mm)
    a_gap = 4 * 0.010 * math.cos(beta_b) / 14.0**2
    pt_tol = 2 * math.sqrt(err / a_gap)
    for pa, pb in zip(a["positions"], b["positions"], strict=True):
        for qa, qb in zip(pa["pairs"], pb["pairs"], strict=True):
            assert (qa["contact_point_mm"] is None) == (qb["contact_point_mm"] is None)
            if qa["contact_point_mm"] is not None:
                d = np.subtract(qa["contact_point_mm"], qb["contact_point_mm"])
                assert np.abs(d).max() < pt_tol
    # the path along the flank (mid-face section): measured 1.4e-8 mm of 8.1 mm
    assert a["cycle"]["path_length_mm"] == pytest.approx(b["cycle"]["path_length_mm"], abs=1e-6)


def test_a_grid_of_a_lead_crowning_gives_the_crowned_loaded_results(crowning):
    """The same flanks to 1.5e-11 mm, but not the same parametrization: the analytic crowning
    moves a point of flank coordinates (u, z) along the transverse line of action, the grid
    along the flank normal, so the two points of the same (u, z) are up to δ_t sin β_b = 2.4 µm
    apart along the flank. The contact cells are laid in flank coordinates, so the two runs
    discretize the same contact on cells shifted by up to 2.4 µm: about 1/20 of a cell across
    the line, times the level-0 discretization error of some percent (docs/validation.md), gives
    the 5e-4 (relative) tolerances. Measured: loaded TE 3e-3″ of 60-85″ (4e-5), p_max away from
    the edges 2.3e-5, load shares 5e-5. (β = 0 has no such shift:
    test_a_grid_of_a_spur_lead_crowning_gives_the_crowned_loaded_results.)"""
    runs, _, _ = crowning
    a, b = runs["hybrid"]
    tol = 5e-4
    ca, cb = a["cycle"], b["cycle"]
    assert cb["te_pp_loaded_arcsec"] == pytest.approx(ca["te_pp_loaded_arcsec"], rel=tol)
    assert cb["p_max_MPa"] == pytest.approx(ca["p_max_MPa"], rel=tol)
    for pa, pb in zip(a["positions"], b["positions"], strict=True):
        assert pb["te_loaded_arcsec"] == pytest.approx(pa["te_loaded_arcsec"], rel=tol)
        for qa, qb in zip(pa["pairs"], pb["pairs"], strict=True):
            assert qb["load_share"] == pytest.approx(qa["load_share"], abs=tol)
            if qa["p_interior_MPa"] is not None:
                assert qb["p_interior_MPa"] == pytest.approx(qa["p_interior_MPa"], rel=tol)


def test_a_grid_of_a_spur_lead_crowning_gives_the_crowned_loaded_results(tmp_path):
    """β = 0: the transverse line of action is the flank normal, the two flanks have the same
    parametrization, and the loaded results agree to the interpolation error and the solvers'
    convergence (measured: TE 2.5e-9″, p_max 2.3e-8, load shares 3e-10)."""
    case = _case(helix_deg=0.0)
    path = tmp_path / "crowning.csv"
    err = _crowning_grid(case, path)
    assert err < 1e-12  # the quadratic, reproduced: rounding (measured 1.4e-14 mm)
    measured = _uncrowned(case).replace(topography={"pinion_drive": str(path)})
    a = fegear.run(case, fidelity="hybrid", fields=False).summary
    b = fegear.run(measured, fidelity="hybrid", fields=False).summary
    rb2 = build_pair(case).gear.r_b
    # e / r_b2 of the gap, 1e-7″ the contact and Newton solves' convergence (measured 2.5e-9″)
    te_tol = ARCSEC * err / rb2 + 1e-7
    for pa, pb in zip(a["positions"], b["positions"], strict=True):
        assert abs(pb["te_loaded_arcsec"] - pa["te_loaded_arcsec"]) < te_tol
        for qa, qb in zip(pa["pairs"], pb["pairs"], strict=True):
            assert qb["load_share"] == pytest.approx(qa["load_share"], abs=1e-8)
            if qa["p_interior_MPa"] is not None:  # solver convergence: 1e-6 (measured 2.3e-8)
                assert qb["p_interior_MPa"] == pytest.approx(qa["p_interior_MPa"], rel=1e-6)
