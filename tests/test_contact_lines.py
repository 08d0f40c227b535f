"""Contact lines of cylindrical pairs: contact ratios against their closed forms, the lines in
the plane of action at the base helix angle, the unloaded TE of modified flanks."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from fegear.io.gear_case import parse_gear_case
from fegear.pipeline.pair import build_pair
from fegear.tca import ARCSEC, TCAOptions, run_tca
from fegear.tca.contact_lines import (
    contact_line,
    contact_ratios,
    iso_contact_ratios,
    plane_of_action,
    section_contact,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_cylindrical_case import doc  # noqa: E402

DESIGNS = {
    "fzg_spur": {},
    "fzg_type_c": dict(tip_diameter_mm=[82.46, 118.36]),
    "helical_15_right": dict(helix_angle_deg=15.0),
    "helical_30_left_offset": dict(helix_angle_deg=30.0, hand="left", face_width_mm=[20.0, 14.0],
                                   face_offset_mm=2.0),
    "helical_22_small": dict(teeth=[23, 41], module_mm=3.0, helix_angle_deg=22.0,
                             profile_shift=[0.3, -0.1], face_width_mm=30.0),
}  # fmt: skip


def pair(name, **more):
    return build_pair(parse_gear_case(doc(**{**DESIGNS[name], **more})))


@pytest.mark.parametrize("name", DESIGNS)
def test_contact_ratios_are_the_closed_forms(name):
    p = pair(name)
    cr = contact_ratios(p.pinion, p.gear, p.assembly)
    ea, eb, eg = iso_contact_ratios(p.pinion, p.gear, p.assembly)
    assert cr.start_limit == "gear tip" and cr.end_limit == "pinion tip"  # the closed forms' case
    # the ends of the contact are bisected to 1e-14 rad: 1e-6 leaves ample room
    assert cr.eps_gamma == pytest.approx(eg, abs=1e-6)
    assert cr.eps_alpha == pytest.approx(ea, abs=1e-6)
    assert cr.eps_beta == pytest.approx(eb, abs=1e-6)
    # the path of contact is ε_α base pitches long
    assert cr.path_mm == pytest.approx(ea * 2 * math.pi * p.pinion.r_b / p.pinion.n_teeth, 1e-9)


def test_fzg_type_c_transverse_ratio():
    cr = contact_ratios(*(lambda p: (p.pinion, p.gear, p.assembly))(pair("fzg_type_c")))
    assert cr.eps_alpha == pytest.approx(1.4375, abs=1e-4)  # the FZG test gears' value


@pytest.mark.parametrize("name", ["helical_15_right", "helical_30_left_offset"])
def test_contact_lines_lie_in_the_plane_of_action_at_the_base_helix_angle(name):
    p = pair(name)
    pa = plane_of_action(p.pinion, p.gear, p.assembly)
    X = section_contact(p.pinion, p.gear, pa, 0.02, np.linspace(*pa.face, 7))[0]
    assert np.abs(X @ pa.normal - p.pinion.r_b).max() < 1e-12  # on the plane
    line = contact_line(p.pinion, p.gear, p.assembly, 0.0)
    d = line.end - line.start
    # across the plane of action at β_b from the axis direction: tan β_b = tan β cos α_t
    beta_b = p.pinion.beta_b
    assert math.atan2(abs(d @ pa.direction), abs(d[2])) == pytest.approx(beta_b, abs=1e-12)
    assert line.length_mm == pytest.approx((line.z_end - line.z_start) / math.cos(beta_b), 1e-12)


def expected_te(p, phi1):
    """Rigid TE of modified flanks: the pair with the smallest total modification δ1 + δ2
    along its contact line closes first; a transverse deviation δ along the line of action is a
    gear rotation δ/r_b2 (TE = −δ/r_b2), measured from the reference position φ1 = 0."""
    pa = plane_of_action(p.pinion, p.gear, p.assembly)
    tau = 2 * math.pi / p.pinion.n_teeth

    def delta(psi):
        best = math.inf
        line = contact_line(p.pinion, p.gear, p.assembly, psi)
        if not line.in_contact:
            return best

        def f(z):
            _, L1, L2, _ = section_contact(p.pinion, p.gear, pa, psi, z)
            d1 = p.pinion.modification(L1, z - pa.pinion_offset_mm)[0]
            return float(d1 + p.gear.modification(L2, z)[0])

        r = minimize_scalar(f, bounds=(line.z_start, line.z_end), method="bounded",
                            options={"xatol": 1e-9})  # fmt: skip
        return min(r.fun, f(line.z_start), f(line.z_end))

    def dmin(phi):
        return min(delta(phi - m * tau) for m in (-1, 0, 1))

    d0 = dmin(0.0)
    return np.array([-(dmin(f) - d0) / p.gear.r_b for f in phi1]) / ARCSEC


@pytest.mark.parametrize(
    "name, mods",
    [
        ("fzg_type_c", dict(profile_crowning_mm=[0.006, 0.0], tip_relief_mm=[0.0, 0.012],
                            tip_relief_shape="parabolic")),
        ("helical_15_right", dict(profile_crowning_mm=[0.008, 0.004], lead_crowning_mm=[0.0, 0.01],
                                  helix_slope_mm=[0.006, 0.0])),
    ],
)  # fmt: skip
def test_unloaded_te_of_modified_flanks(name, mods):
    """The TCA (minimum angular gap over the exact modified flanks) against the first-order
    theory of the plane of action: they differ by terms of second order in the modifications
    (the modified point sits δ along the line of action from where δ is evaluated, the
    conjugate separation off the line), so the difference falls with the square of the
    modifications' scale."""
    phi1 = np.linspace(-math.pi / 16, math.pi / 16, 7)
    err = []
    for scale in (1.0, 0.1):
        scaled = {k: np.multiply(v, scale).tolist() if k.endswith("_mm") else v
                  for k, v in mods.items()}  # fmt: skip
        p = pair(name, **scaled)
        r = run_tca(p.pinion, p.gear, p.assembly, TCAOptions(separation_grid=None), phi1)
        te = expected_te(p, phi1)
        assert np.ptp(te) > scale  # the modifications make a TE of some arcsec
        err.append(np.abs(r.te_arcsec - te).max() / np.ptp(te))
    # measured: 0.44 % and 0.046 % (FZG type C), 0.81 % and 0.083 % (helical) of the TE's
    # range: the absolute difference falls with the scale squared (order 1.98 and 1.99)
    assert err[0] < 0.02, err
    rate = math.log10(err[0] / err[1]) + 1  # absolute difference ~ scale**rate
    assert rate > 1.8, f"observed order {rate:.2f}"
