"""The ease-off (fegear/tca/ease_off.py, docs/ease_off.md): the gap of each pinion point in its
contact position, over the pinion flank. On the reference spiral bevel pair it holds the designed
TE parabola along the path and its valley is the path; a conjugate pair has none; a lead
crowning shows up as itself."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import fegear
from fegear.case_files import load_case
from fegear.geometry.pair_placement import spiral_bevel_assembly
from fegear.pipeline.pair import build_pair
from fegear.tca import TCAOptions
from fegear.tca.cached import cached_tca
from fegear.tca.ease_off import EaseOff, ease_off, ease_off_at
from fegear.tca.ease_off_pair import fit_ease_off
from fegear.tca.results import ARCSEC

CASES = Path(__file__).resolve().parents[1] / "cases"


def _tca(pinion, gear, asm, n: int):
    """The TCA object and its positions over one mesh cycle (``n`` positions from −π/N1)."""
    phi1 = -math.pi / asm.n1 + 2 * math.pi / asm.n1 * np.arange(n) / n
    tca, pos, _ = cached_tca(pinion, gear, asm, TCAOptions(n_positions=n), phi1)
    return tca, pos


@pytest.fixture(scope="module")
def bevel(spiral_bevel_pair):
    pair = spiral_bevel_pair
    tca, pos = _tca(pair.pinion, pair.gear, spiral_bevel_assembly(pair, "drive"), 13)
    return pair, tca, pos, ease_off(tca)


def test_ease_off_at_the_contact_points_is_the_unloaded_te(bevel):
    pair, tca, pos, _ = bevel
    uv = np.array([p.pinion_uv[p.contact_pair] for p in pos])
    te = np.array([p.te_rad for p in pos])
    th, phi, _ = ease_off_at(tca, uv[:, 0], uv[:, 1])
    assert np.isfinite(th).all()
    # θ_e is a minimum over the pinion angle, φ1 among them: never above the gap there (−TE),
    # to the circle solves' 1e-10 mm over a ~50 mm radius
    assert np.all(th <= -te + 1e-11), (th + te) / ARCSEC
    # equal to second order: the TCA's point lies off the contact line of φ1 by the ease-off's
    # slope across it (contact positions up to 0.1° from φ1); measured 0.6 % of the TE
    assert np.all(np.abs(th + te) <= 0.01 * np.abs(te) + 1e-3 * ARCSEC), (th + te) / ARCSEC
    # each point's contact position is its own position (or one pitch away: the next pair's)
    d = np.degrees(phi - np.array([p.phi1 for p in pos]))
    d = d - 360 / pair.blank.n1 * np.round(d / (360 / pair.blank.n1))
    assert np.abs(d).max() < 0.15, d


def test_ease_off_along_the_path_is_the_designed_te_parabola(bevel):
    pair, tca, pos, _ = bevel
    uv = np.array([p.pinion_uv[p.contact_pair] for p in pos])
    phi = np.array([p.phi1 for p in pos])
    th = ease_off_at(tca, uv[:, 0], uv[:, 1])[0] / ARCSEC
    target = pair.targets.te_amplitude_arcsec
    # the tolerance of the TCA test (tests/test_tca_spiral_bevel.py): 10 % of the 8″
    assert abs(np.ptp(th) - target) < 0.1 * target, np.ptp(th)
    # a parabola in φ1 with its vertex at the mean position: the quadratic fit leaves < 1 %
    c = np.polyfit(phi, th, 2)
    rms = np.sqrt(np.mean((np.polyval(c, phi) - th) ** 2))
    assert rms < 0.01 * target and abs(math.degrees(-c[1] / (2 * c[0]))) < 0.2, (rms, c)


def test_the_valley_of_the_ease_off_is_the_contact_path(bevel):
    _, _, pos, e = bevel
    uv = np.array([p.pinion_uv[p.contact_pair] for p in pos])
    o = np.argsort(uv[:, 1])
    inside = (e.v >= uv[:, 1].min()) & (e.v <= uv[:, 1].max())
    assert inside.sum() >= 10
    valley = np.array([e.u[np.nanargmin(e.eps_um[:, j])] for j in np.flatnonzero(inside)])
    path = np.interp(e.v[inside], uv[o, 1], uv[o, 0])
    # per face section the profile node of the smallest ε: within one grid step of the path
    # (measured 0.035 of 0.05)
    du = e.u[1] - e.u[0]
    assert np.abs(valley - path).max() <= du, (valley - path, du)
    # and the minimum of the whole flank lies on the path too (the TE parabola's vertex)
    assert abs(e.min_uv[0] - np.interp(e.min_uv[1], uv[o, 1], uv[o, 0])) <= du


def test_a_conjugate_pair_has_no_ease_off():
    pair = build_pair(load_case(CASES / "fzg_type_c.toml"))
    tca, _ = _tca(pair.pinion, pair.gear, pair.assembly, 5)
    e = ease_off(tca)
    ok = np.isfinite(e.eps_um)
    # defined where the gear's working flank reaches (below the SAP: no contact position)
    assert 0.7 < ok.mean() < 1.0, ok.mean()
    # θ_e ≡ 0 to the circle solves (1e-10 mm over a ~40 mm radius), ε to round-off
    assert np.nanmax(np.abs(e.theta_rad)) < 1e-11, np.nanmax(np.abs(e.theta_rad))
    assert np.nanmax(e.eps_um) < 1e-6, np.nanmax(e.eps_um)


def test_a_lead_crowning_is_a_parabola_across_the_face():
    case = load_case(CASES / "helical_crowned.toml")
    c_um = 1e3 * case.pair["lead_crowning_mm"][0]
    flat = case.replace(pair={**case.pair, "lead_crowning_mm": [0.0, 0.0]})
    out = []
    for cs in (case, flat):
        p = build_pair(cs)
        out.append(ease_off(_tca(p.pinion, p.gear, p.assembly, 5)[0]))
    e, e0 = out
    assert np.nanmax(e0.eps_um) < 1e-6  # the uncrowned helical pair is conjugate
    # the crowning is laid along the transverse line of action: along the normal c cos β_b
    # (docs/measured_flanks.md: 9.693-9.706 µm of 10)
    beta_b = math.asin(math.sin(math.radians(15.0)) * math.cos(math.radians(20.0)))
    amp = c_um * math.cos(beta_b)
    x = 2 * (e.v - 0.5 * (e.v[0] + e.v[-1])) / (e.v[-1] - e.v[0])
    j0 = int(np.argmin(np.abs(x)))
    rows = [i for i in range(e.u.size) if np.isfinite(e.eps_um[i]).all()]
    assert len(rows) >= 10
    for i in rows:
        d = e.eps_um[i] - e.eps_um[i, j0]
        # a parabola of the crowning's height over the face: 2 % (the first-order ε = θ h and
        # the crowned point's shift along the flank, 2.4 µm, in a grid laid in flank coordinates)
        assert np.abs(d - amp * x**2).max() < 0.02 * amp, (e.u[i], d - amp * x**2)


# ------------------------------------------------------------------ the numbers of summary.json


def test_the_fit_holds_a_quadratic_exactly():
    """fit_ease_off on an ease-off that IS a quadratic in the normalised coordinates gives its
    coefficients back, the undefined corner left out."""
    u, v = np.linspace(0.2, 1.4, 21), np.linspace(-7.0, 7.0, 41)
    s = 2 * (u - 0.8) / 1.2
    t = v / 7.0
    S, T = np.meshgrid(s, t, indexing="ij")
    c = (3.0, -1.5, 2.0, 4.0, 7.0, -2.5)
    eps = c[0] + c[1] * S + c[2] * T + c[3] * S**2 + c[4] * T**2 + c[5] * S * T
    eps[:4, :6] = np.nan  # below the gear's working flank: no contact position
    nan = np.full(eps.shape, np.nan)
    e = EaseOff(u, v, np.zeros(eps.shape + (3,)), nan, nan, nan, eps, 0.0, np.zeros(2))
    fit = fit_ease_off(e)
    # a least-squares solve of an exact quadratic: round-off of 6 coefficients of size ~10
    assert np.allclose(fit[:6], c, rtol=0, atol=1e-12), fit
    assert fit.rms_um < 1e-12 and fit.nodes == eps.size - 24


def test_the_summary_reads_a_lead_crowning_as_lengthwise_crowning():
    """summary.json's ease_off section of the crowned helical pair: its lengthwise crowning is
    the lead crowning along the normal, C_β cos β_b, and nothing else is there; the measured
    pair (the same crowning as a 5 x 9 grid on the uncrowned pair) says the same and that its
    design pair has none."""
    beta_b = math.asin(math.sin(math.radians(15.0)) * math.cos(math.radians(20.0)))
    amp = 10.0 * math.cos(beta_b)  # µm: both cases' 10 µm crowning
    crowned = fegear.run(load_case(CASES / "helical_crowned.toml"), fidelity="tca")
    fit = crowned.summary["ease_off"]["fit"]
    # the first-order ε = θ h of an exact parabola (measured 7e-6 relative)
    assert abs(fit["lengthwise_crowning_um"] - amp) < 1e-4 * amp, fit
    # no other term: the pair is conjugate but for the crowning (measured below 1e-7 µm)
    for k in ("profile_slope_um", "lengthwise_slope_um", "profile_crowning_um", "twist_um"):
        assert abs(fit[k]) < 1e-5 * amp, (k, fit)
    measured = fegear.run(load_case(CASES / "helical_measured.toml"), fidelity="tca")
    eo = measured.summary["ease_off"]
    # the spline through 5 x 9 grid points of the parabola: 1e-4 relative (measured 6e-5)
    assert abs(eo["fit"]["lengthwise_crowning_um"] - amp) < 1e-4 * amp, eo["fit"]
    assert eo["design"]["eps_max_um"] < 1e-6  # the design pair is conjugate
    # measured minus design: the crowning itself, from 0 at the valley to its height
    diff = eo["measured_minus_design_um"]
    assert abs(diff["min"]) < 1e-6 and abs(diff["max"] - eo["eps_max_um"]) < 1e-6, diff
