"""A left-hand bevel pair is the mirror image of the right-hand one (fegear.geometry.bevel:
``SpiralBevelPair.mirrored``, ``machine.mirrored``)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fegear.geometry.bevel.machine import head_cutter, machine_motion, mirrored
from fegear.geometry.generation import generate
from fegear.geometry.pair_placement import spiral_bevel_assembly
from fegear.tca import TCAOptions, run_tca

Y = np.array([1.0, -1.0, 1.0])  # the reflection y -> -y
SIDES = ("drive", "coast")


@pytest.fixture(scope="module")
def left(spiral_bevel_pair):
    return spiral_bevel_pair.mirrored(dataclasses.replace(spiral_bevel_pair.blank, hand="left"))


def test_mirrored_settings_cut_the_mirror_image(spiral_bevel_pair):
    """The cradle chain reflected: every generated point and normal at (s, θ, ψ) is the mirror
    image of the one at (s, −θ, −ψ), to round-off."""
    for m in (spiral_bevel_pair.pinion, spiral_bevel_pair.gear):
        for side in SIDES:
            ms = m.settings(side)
            ms_l = mirrored(ms)
            assert mirrored(ms_l) == ms  # an involution
            S, T = np.meshgrid(np.linspace(-3, 3, 5), np.linspace(-0.2, 0.2, 5), indexing="ij")
            a = generate(head_cutter(ms), machine_motion(ms), S, T, 0.0, half_width=0.3)
            b = generate(head_cutter(ms_l), machine_motion(ms_l), S, -T, 0.0, half_width=0.3)
            np.testing.assert_allclose(b.points, a.points * Y, atol=1e-12)
            np.testing.assert_allclose(b.normals, a.normals * Y, atol=1e-13)
            np.testing.assert_allclose(b.psi, -a.psi, atol=1e-14)


def test_the_left_hand_pair_has_mirrored_flanks_and_the_same_tca(spiral_bevel_pair, left):
    right = spiral_bevel_pair
    assert left.blank.hand == "left"
    for a, b in ((right.pinion, left.pinion), (right.gear, left.gear)):
        for side in SIDES:
            bd = a.boundaries()
            U, V = np.meshgrid(np.linspace(-1, 1, 7), np.linspace(bd.v_start, bd.v_end, 5),
                               indexing="ij")  # fmt: skip
            # the same solves on mirrored surfaces: to their tolerance (1e-11 mm)
            np.testing.assert_allclose(
                b.flank_points(side, U, V)[0], a.flank_points(side, U, V)[0] * Y, atol=1e-10
            )
    for side in SIDES:
        p, q = right.placements[side], left.placements[side]
        assert (q.sigma, q.gear_flank_angle, q.pinion_flank_angle) == (
            -p.sigma, -p.gear_flank_angle, -p.pinion_flank_angle)  # fmt: skip
    # the mirrored mesh turns the other way: the same transmission errors (driving-sense angles)
    phi = np.linspace(-np.pi / 12, np.pi / 12, 5)
    te = [
        [x.te_arcsec for x in run_tca(p.pinion, p.gear, spiral_bevel_assembly(p, "drive"),
                                      TCAOptions(), phi1=phi).positions]
        for p in (right, left)
    ]  # fmt: skip
    np.testing.assert_allclose(te[1], te[0], atol=1e-8)  # arcsec: round-off of the mirror


def test_a_hand_other_than_right_or_left_is_refused():
    from fegear.errors import InputError
    from fegear.geometry.bevel import SpiralBevelBlank

    with pytest.raises(InputError, match="hand"):
        SpiralBevelBlank(hand="up")
