"""The FE contact engine on the Hertz scene: a crowned roller pressed on a flat block.

The closed-form Hertz solution is the reference. Each FE level is solved once per module (cold
cache: see ``conftest.py``) and reused by the tests that read it.

Measured on the reference machine (2 cores, cold): errors against Hertz

    level  cells across 2b   p0       a        b        approach
    0      6                 +1.5 %   -0.95 %  -2.3 %   -2.5 %
    1      8                 -0.07 %  -0.31 %  -2.0 %   -2.4 %
    2      12                -0.59 %  -0.11 %  -0.71 %  -2.3 %
    3      16                -0.86 %  -0.04 %  -0.46 %  -2.3 %

observed rates over levels 0-2 (cell size h): a 3.0, b 1.7 (p0 0.9, not asserted).

The approach is not asserted against Hertz: both bodies are finite and clamped at their far faces
(the block on its table, the roller at its axle), not half-spaces, so their rigid approach differs
from the half-space value by a few percent at every level.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fegear.errors import InputError
from fegear.mechanics.convergence import observed_rate
from fegear.scenes.hertz_scene import (
    CELLS_ACROSS_MINOR,
    MIN_CELLS_ACROSS_MINOR,
    HertzScene,
    run_level,
)

NOMINAL = HertzScene()  # Rx 20 / Ry 100 mm roller on a 40 x 40 x 20 mm block, 2000 N, steel
COARSE_LEVELS = (0, 1, 2)


def _errors(r) -> str:
    return (
        f"level {r.level} ({r.cells_across_minor} cells across 2b, cell {r.cell_size_mm:.4f} mm): "
        f"p0 {r.error('p0'):+.3%}, a {r.error('a'):+.3%}, b {r.error('b'):+.3%}, "
        f"approach {r.error('approach'):+.3%}"
    )


@pytest.fixture(scope="module")
def coarse() -> dict[int, object]:
    """The nominal scene at the coarse levels, each solved once (cold cache)."""
    return {lv: run_level(NOMINAL, lv) for lv in COARSE_LEVELS}


# --------------------------------------------------------------------------------------------
# Convergence under refinement
# --------------------------------------------------------------------------------------------


def test_patch_semi_axes_converge_at_an_observed_rate_above_one(coarse):
    runs = [coarse[lv] for lv in COARSE_LEVELS]
    h = np.array([r.cell_size_mm for r in runs])
    rates = {k: observed_rate(h, [r.error(k) for r in runs]) for k in ("p0", "a", "b")}
    report = (
        "observed rates: "
        + ", ".join(f"{k} {v:.2f}" for k, v in rates.items())
        + "\n"
        + "\n".join(_errors(r) for r in runs)
    )
    print(report)
    # The semi-axes are second moments of the cell forces: they converge at least linearly in
    # the cell size (measured: a 3.0, b 1.7). The recovered p0 carries element-scale noise of
    # a few tenths of a percent, so its fitted rate over three coarse levels is not asserted.
    assert rates["a"] > 1.0, report
    assert rates["b"] > 1.0, report


def test_errors_at_level_2_are_capped(coarse):
    r = coarse[2]
    report = _errors(r)
    print(report)
    # 12 cells across the minor axis: the recovered peak is within 1.5 % (measured -0.59 %; the
    # remaining error is the FE element-scale noise the quadratic fit averages out) ...
    assert abs(r.error("p0")) < 0.015, report
    # ... and the second-moment semi-axes within 1 % (measured a -0.11 %, b -0.71 %: b is
    # resolved by only 12 cells, a by ~35).
    assert abs(r.error("a")) < 0.01, report
    assert abs(r.error("b")) < 0.01, report
    assert r.warnings == (), r.warnings


@pytest.mark.slow
@pytest.mark.parametrize("level", [3, 5])
def test_fine_levels_meet_the_accuracy_target(level):
    r = run_level(NOMINAL, level)
    report = _errors(r)
    # The target of the Hertz scene: p0 within 1 %, a and b within 2 %. Measured: level 3 (the
    # case file's level, 16 cells across 2b) p0 -0.97 %, a -0.04 %, b -0.47 %; level 5 (the
    # finest, 32 across, 230k DOFs) p0 -0.22 %, a +0.01 %, b -0.10 %.
    assert abs(r.error("p0")) < 0.01, report
    assert abs(r.error("a")) < 0.02, report
    assert abs(r.error("b")) < 0.02, report


# --------------------------------------------------------------------------------------------
# Solver invariants
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("level", COARSE_LEVELS)
def test_contact_solution_invariants(coarse, level):
    r = coarse[level]
    s = r.solution
    F, gap, act = s.force, s.gap, s.active
    approach = s.theta
    assert approach > 0.0  # the roller moved towards the block
    # Force balance: the modelled quarter carries F/4, to round-off (1e-9 relative).
    assert r.modelled_fraction == 0.25
    assert abs(F.sum() - NOMINAL.force_N / 4) <= 1e-9 * NOMINAL.force_N / 4
    assert s.equilibrium_residual <= 1e-9
    # No tension: every active cell pushes (F > 0), inactive cells carry nothing.
    assert np.all(F[act] > 0.0)
    assert np.all(F[~act] == 0.0)
    assert s.min_active_force > 0.0
    # No penetration on the inactive cells, to round-off of the displacement scale (the approach):
    assert np.all(gap[~act] >= -1e-9 * approach), gap[~act].min()
    assert s.max_penetration <= 1e-9 * approach
    # ... and the gap is closed on the active cells (complementarity F d = 0).
    assert np.all(np.abs(gap[act]) <= 1e-9 * approach), np.abs(gap[act]).max()
    # The patch stays inside the contact grid (the grid margin is 1.35 x the Hertz semi-axes).
    assert not any("edge of the contact grid" in w for w in r.warnings)
    assert np.all(np.isfinite(r.pressure)) and np.isfinite(r.p0_MPa)


def test_repeated_run_on_a_warm_cache_is_bit_identical(coarse):
    first = coarse[0]
    again = run_level(NOMINAL, 0)
    # The second run reads the meshes and compliance operators back from the cache (the first
    # may or may not have, depending on which tests ran before in this session) ...
    assert again.cache_hit
    # ... and the contact solve is deterministic: the same bits, not merely close.
    assert np.array_equal(again.force, first.force)
    assert np.array_equal(again.solution.active, first.solution.active)
    assert again.approach_mm == first.approach_mm
    assert again.p0_MPa == first.p0_MPa
    assert (again.a_mm, again.b_mm) == (first.a_mm, first.b_mm)


# --------------------------------------------------------------------------------------------
# Symmetry
# --------------------------------------------------------------------------------------------


def test_full_model_agrees_with_the_quarter_model(coarse):
    quarter = coarse[0]
    full = run_level(HertzScene(symmetry="none"), 0)
    assert full.modelled_fraction == 1.0
    # The full model carries the whole force.
    assert abs(full.force.sum() - NOMINAL.force_N) <= 1e-9 * NOMINAL.force_N
    # The full patch is centred on the first point of contact (symmetric loading).
    cx, cy = full.centers.T @ full.force / full.force.sum()
    assert abs(cx) < 0.05 * full.b_mm and abs(cy) < 0.05 * full.a_mm, (cx, cy)
    report = f"quarter: {_errors(quarter)}\nfull:    {_errors(full)}"
    print(report)
    # Same physics, different FE meshes (the full bodies are meshed independently, not mirrored):
    # at level 0 each differs from Hertz by 1-4 %, so they agree to within 3 % of each other
    # (measured: p0 1.3 %, a 0.25 %, b 1.1 %).
    for key in ("p0", "a", "b"):
        assert abs(full.error(key) - quarter.error(key)) < 0.03, report


# --------------------------------------------------------------------------------------------
# Extremes
# --------------------------------------------------------------------------------------------


def _check_balanced_and_finite(r, force_N: float) -> None:
    s = r.solution
    assert np.all(np.isfinite(s.force)) and np.all(np.isfinite(s.gap))
    assert all(math.isfinite(v) for v in (r.p0_MPa, r.a_mm, r.b_mm, r.approach_mm))
    assert (
        abs(s.force.sum() - force_N * r.modelled_fraction) <= 1e-9 * force_N * r.modelled_fraction
    )
    assert np.all(s.force >= 0.0)
    assert s.max_penetration <= 1e-9 * s.theta


def test_micro_newton_force():
    r = run_level(HertzScene(force_N=1e-6), 0)
    _check_balanced_and_finite(r, 1e-6)
    assert r.a_mm < 2e-3  # a patch of about a micrometre
    report = _errors(r)
    print(report)
    # Linear elasticity: the problem scales with F^(1/3) and the grid and refined mesh scale with
    # the Hertz b, while the bodies stay 20 mm: even more of a half-space than at 2000 N. Level 0
    # (6 cells across 2b) is within 2.3 % of Hertz at the nominal load, so 3 % here (measured
    # p0 +1.2 %, a -0.9 %, b -2.1 %).
    for key in ("p0", "a", "b"):
        assert abs(r.error(key)) < 0.03, report
    # Half-spaces indeed: with the bodies ~5e4 patch sizes large, the approach meets Hertz too
    # (measured -0.42 %, against -2.5 % at the nominal load).
    assert abs(r.error("approach")) < 0.01, report


def test_hundred_times_nominal_force():
    scene = HertzScene(force_N=100 * NOMINAL.force_N)
    r = run_level(scene, 0)
    _check_balanced_and_finite(r, scene.force_N)
    report = _errors(r)
    print(report)
    # The patch is now 2a ~ 13 mm on a 30 mm long roller of radius 20 mm (a/Rx ~ 0.3): the
    # bodies are no longer half-spaces and the contact no longer small against the radii, so
    # Hertz holds only roughly: p0, a, b within 5 % (measured +1.3 %, -1.2 %, -3.1 %) ...
    for key in ("p0", "a", "b"):
        assert abs(r.error(key)) < 0.05, report
    # ... and the approach, dominated by the finite bodies, within 15 % (measured -10 %).
    assert abs(r.error("approach")) < 0.15, report


def test_sphere_gives_a_circular_patch():
    scene = HertzScene(roller_radii_mm=(20.0, 20.0))
    # Level 1 (8 cells across the diameter): at level 0 only ~3 P2 elements span the patch and
    # their element-scale stiffness noise, which does not respect the x <-> y swap, is ~1 %.
    r = run_level(scene, 1)
    _check_balanced_and_finite(r, scene.force_N)
    report = _errors(r) + f", a/b - 1 = {r.a_mm / r.b_mm - 1:+.3%}"
    print(report)
    # Curvature ratio 1: Hertz gives a circle (a = b). The FE patch is circular to 1 %: the square
    # grid is symmetric under x <-> y, the meshes are not (the roller's axis is y; measured 0.3 %).
    assert r.hertz.a_mm == pytest.approx(r.hertz.b_mm, rel=1e-12)
    assert abs(r.a_mm - r.b_mm) < 0.01 * r.b_mm, report
    # 8 cells across the circle: within 3 % of Hertz (measured p0 +0.7 %, a -1.7 %, b -1.9 %).
    for key in ("p0", "a", "b"):
        assert abs(r.error(key)) < 0.03, report


def test_curvature_ratio_fifty():
    scene = HertzScene(roller_radii_mm=(20.0, 1000.0))
    r = run_level(scene, 0)
    # The elongated patch must fit on the roller: the grid reaches 1.35 a along its axis.
    assert scene.roller_half_length_mm >= scene.grid_margin * r.hertz.a_mm
    assert r.hertz.a_mm / r.hertz.b_mm > 10  # a long, thin ellipse
    _check_balanced_and_finite(r, scene.force_N)
    report = _errors(r)
    print(report)
    # Level 0 puts 6 cells across the thin minor axis (b: ~-3 %, like the -2 % of the nominal
    # scene) and ~50 along the long one (a: -0.2 %): p0, a, b within 4 % of Hertz
    # (measured p0 +2.3 %, a -0.19 %, b -2.9 %).
    for key in ("p0", "a", "b"):
        assert abs(r.error(key)) < 0.04, report
    assert abs(r.a_mm / r.b_mm - r.hertz.a_mm / r.hertz.b_mm) < 0.05 * r.hertz.a_mm / r.hertz.b_mm


def test_grid_too_coarse_warns_with_the_ratio(coarse):
    r = coarse[0]
    assert CELLS_ACROSS_MINOR[0] < MIN_CELLS_ACROSS_MINOR
    ratio = 2.0 * r.b_mm / r.cell_size_mm
    coarse_warnings = [w for w in r.warnings if "cells across the minor axis" in w]
    assert len(coarse_warnings) == 1, r.warnings
    # The warning names the measured ratio (cells across the computed minor axis 2b).
    assert f"{ratio:.1f} cells across the minor axis" in coarse_warnings[0]
    # Level 2 (12 cells) is fine enough: no warning.
    assert not any("cells across" in w for w in coarse[2].warnings)


# --------------------------------------------------------------------------------------------
# Refused inputs
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"force_N": 0.0}, "force_N"),
        ({"force_N": -2000.0}, "force_N"),
        ({"force_N": math.nan}, "force_N"),
        ({"force_N": math.inf}, "force_N"),
        ({"roller_radii_mm": (0.0, 100.0)}, "roller.radii_mm[0]"),
        ({"roller_radii_mm": (20.0, -100.0)}, "roller.radii_mm[1]"),
        ({"roller_radii_mm": (math.nan, 100.0)}, "roller.radii_mm[0]"),
        ({"nu_roller": 0.5}, "nu_roller"),
        ({"nu_roller": -1.0}, "nu_roller"),
        ({"nu_block": 0.7}, "nu_block"),
        ({"nu_block": math.nan}, "nu_block"),
    ],
    ids=lambda v: repr(v) if isinstance(v, dict) else None,
)
def test_bad_inputs_are_refused_naming_the_field(kwargs, field):
    with pytest.raises(InputError) as exc:
        HertzScene(**kwargs)
    assert exc.value.field == field
    assert str(exc.value).startswith(field + " = "), str(exc.value)


def test_level_out_of_range_is_refused():
    with pytest.raises(InputError, match="^level = "):
        run_level(NOMINAL, len(CELLS_ACROSS_MINOR))
