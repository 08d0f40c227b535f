"""``kind = "cylindrical"``: spur and helical pairs with flank modifications from a case file.

A spur case is a cylindrical case with the same keys; the FZG type C case has its real tip
diameters; bad data is refused naming the case-file field."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import fegear
from fegear.errors import InputError
from fegear.io.gear_case import parse_gear_case
from fegear.pipeline.pair import build_pair
from fegear.validation.iso6336 import working_pressure_angle

REPO = Path(__file__).resolve().parents[1]


def doc(**pair):
    base = {"teeth": [16, 24], "module_mm": 4.5, "pressure_angle_deg": 20.0,
            "profile_shift": [0.1817, 0.1715], "face_width_mm": 14.0}  # fmt: skip
    return {
        "case": {"kind": "cylindrical", "name": "t"},
        "pair": {**base, **pair},
        "load": {"torque2_Nm": 200.0},
    }


def test_spur_case_is_a_cylindrical_case():
    spur = fegear.load_case(REPO / "cases" / "fzg_spur.toml")
    d = spur.to_document()
    d["case"]["kind"] = "cylindrical"
    cyl = parse_gear_case(d)
    a, b = build_pair(spur), build_pair(cyl)
    for m0, m1 in ((a.pinion, b.pinion), (a.gear, b.gear)):
        bd = m0.boundaries("drive")
        u = np.linspace(bd.u_root, bd.u_tip, 31)
        z = np.linspace(-7, 7, 31)
        p0, n0 = m0.point_normal("drive", u, z)
        p1, n1 = m1.point_normal("drive", u, z)
        # the same surfaces: generated (spur) and closed form (cylindrical), to round-off
        assert np.abs(p1 - p0).max() < 1e-12 and np.abs(n1 - n0).max() < 1e-12
    assert a.assembly.axes_distance() == pytest.approx(b.assembly.axes_distance(), abs=1e-12)


def test_fzg_type_c_has_its_tip_diameters():
    case = fegear.load_case(REPO / "cases" / "fzg_type_c.toml")
    pair = build_pair(case)
    assert 2 * pair.pinion.r_a == 82.46 and 2 * pair.gear.r_a == 118.36
    assert pair.assembly.axes_distance() == pytest.approx(91.5, abs=1e-3)  # from the shifts
    aw = working_pressure_angle(16, 24, 0.1817, 0.1715)
    rb1, rb2 = pair.pinion.r_b, pair.gear.r_b
    a = (rb1 + rb2) / math.cos(aw)
    ea = (math.sqrt(41.23**2 - rb1**2) + math.sqrt(59.18**2 - rb2**2) - a * math.sin(aw)) / (
        2 * math.pi * rb1 / 16
    )
    assert ea == pytest.approx(1.4375, abs=5e-5)  # the real test gears' transverse ratio


def test_helix_hands_are_opposite():
    for hand, other in (("right", "left"), ("left", "right")):
        pair = build_pair(parse_gear_case(doc(helix_angle_deg=20.0, hand=hand)))
        assert pair.pinion.hand == hand and pair.gear.hand == other
    spur = build_pair(parse_gear_case(doc()))
    assert spur.pinion.hand == "spur"


def test_modifications_reach_the_members():
    case = parse_gear_case(doc(lead_crowning_mm=[0.01, 0.0], tip_relief_mm=0.02,
                               tip_relief_start_roll_deg=[30.0, 25.0], end_relief_mm=0.005,
                               end_relief_length_mm=2.0, end_relief_shape="parabolic"))  # fmt: skip
    p = build_pair(case)
    assert p.pinion.mods.lead_crowning_mm == 0.01 and p.gear.mods.lead_crowning_mm == 0.0
    assert p.pinion.mods.tip_relief_start_roll_deg == 30.0
    assert p.gear.mods.tip_relief_start_roll_deg == 25.0
    assert p.gear.mods.end_relief_shape == "parabolic"


def test_face_offset_moves_the_pinion():
    p0 = build_pair(parse_gear_case(doc()))
    p1 = build_pair(parse_gear_case(doc(face_offset_mm=2.0, face_width_mm=[18.0, 14.0])))
    assert p1.assembly.base1[2, 3] - p0.assembly.base1[2, 3] == 2.0
    assert p1.assembly.face_width_mm == 14.0  # the overlap [-7, 7] of [-7, 11] and [-7, 7]


@pytest.mark.parametrize(
    "pair, field",
    [
        (dict(tip_diameter_mm=[96.0, 118.36]), "pair.tip_diameter_mm[0]"),
        (dict(tip_relief_mm=0.01, tip_relief_start_diameter_mm=[80.0, 60.0]),
         "pair.tip_relief_start_diameter_mm[1]"),
        (dict(end_relief_mm=0.01, end_relief_length_mm=9.0), "pair.end_relief_length_mm"),
        (dict(helix_angle_deg=50.0), "pair.helix_angle_deg"),
        (dict(hand="up"), "pair.hand"),
        (dict(tip_relief_shape="cubic"), "pair.tip_relief_shape"),
        (dict(lead_crowning_mm=-0.01), "pair.lead_crowning_mm"),
        (dict(face_offset_mm=20.0), "pair.face_offset_mm"),
        (dict(lead_crowning=0.01), "pair.lead_crowning"),
    ],
)  # fmt: skip
def test_bad_data_names_the_field(pair, field):
    with pytest.raises(InputError) as exc:
        build_pair(parse_gear_case(doc(**pair)))
    assert exc.value.field == field, str(exc.value)
