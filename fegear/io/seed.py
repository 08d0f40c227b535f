"""The built-in seed face-gear case: what ``fegear run`` runs when no case file is given.

The text is ``cases/face_gear_nominal.toml`` (a test checks that both give the same case), kept
here so that the command works from an installed package without the repository's ``cases/``.
"""

from __future__ import annotations

import tomllib

from fegear.io.gear_case import GearCase, parse_gear_case

__all__ = ["SEED_CASE_TOML", "seed_case"]

SEED_CASE_TOML = """
[case]
kind = "face_gear"
name = "face_gear_nominal"
description = "Seed face gear 160/25, m 6.35 mm, 25 deg; pinion torque 350.14 N·m; no errors"

[pair]
n_face_gear = 160
n_pinion = 25
module_mm = 6.35
pressure_angle_deg = 25.0
shaft_angle_deg = 90.0
inner_radius_mm = 471.0
outer_radius_mm = 560.0
pinion_face_width_mm = 90.0
blank_thickness_mm = 40.0
n_shaper = 27

[load]
pinion_torque_Nm = 350.14
speed_rpm = 100.0

[errors]
dE_mm = 0.0
dA1_mm = 0.0
dA2_mm = 0.0
dgamma_deg = 0.0

[analysis]
fidelity = "hybrid"
level = 0
n_positions = 25

[material]
E_MPa = 206000.0
nu = 0.3
"""


def seed_case() -> GearCase:
    """The seed face-gear case (nominal assembly, hybrid level 0, 25 positions)."""
    return parse_gear_case(tomllib.loads(SEED_CASE_TOML), source="<built-in seed case>")
