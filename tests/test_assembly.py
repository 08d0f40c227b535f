"""Assembly placements and installation-error sign conventions (fegear.geometry.pair_placement)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fegear.errors import InputError
from fegear.geometry import FaceGearDesign, FaceGearMember, InvoluteDesign, InvoluteMember
from fegear.geometry.pair_placement import InstallationErrors, face_gear_assembly, involute_assembly

P = InvoluteMember(InvoluteDesign(16, 4.5, 20, profile_shift=0.1817, face_width_mm=14), "pinion")
G = InvoluteMember(InvoluteDesign(24, 4.5, 20, profile_shift=0.1715, face_width_mm=14), "gear")
FG = FaceGearMember(FaceGearDesign())
# FaceGearMember.pinion() is refused by the involute validation (rack tip radius at 25°)
FP = InvoluteMember(
    InvoluteDesign(25, 6.35, 25.0, rack_tip_radius_coeff=0.25, face_width_mm=90), "pinion"
)


def test_parallel_centre_distance_and_errors():
    a0 = involute_assembly(P, G)
    # zero-backlash working centre distance of FZG C (x1 + x2 rounded in the source): 91.5 mm
    assert abs(a0.axes_distance() - 91.5) < 1e-3
    a1 = involute_assembly(P, G, InstallationErrors(da_mm=0.1))
    # exact: a translation along +x
    assert abs(a1.axes_distance() - a0.axes_distance() - 0.1) < 1e-12
    f = 0.02
    ad = involute_assembly(P, G, InstallationErrors(f_sigma_delta_mm=f))
    o, e = ad.axis2()
    x_at = lambda z: o[0] + e[0] * (z - o[2]) / e[2]  # noqa: E731
    # in-plane: the centre distance grows by f from z = -b/2 to z = +b/2 (exact for the tilt)
    assert abs(x_at(7.0) - x_at(-7.0) - f) < 1e-12
    ab = involute_assembly(P, G, InstallationErrors(f_sigma_beta_mm=f))
    o, e = ab.axis2()
    # out-of-plane: the gear axis leans toward +y at +z by f over b
    assert abs(e[1] / e[2] * 14.0 - f) < 1e-12 and abs(e[0]) < 1e-15


def test_intersecting_errors():
    a0 = face_gear_assembly(FG, None, FP)
    assert abs(a0.shaft_angle_deg() - 90.0) < 1e-12 and a0.axes_distance() < 1e-12
    a = face_gear_assembly(FG, InstallationErrors(dgamma_deg=0.02, dE_mm=0.3), FP)
    # Δγ opens the shaft angle, ΔE is the new shortest distance (exact placements)
    assert abs(a.shaft_angle_deg() - 90.02) < 1e-9
    assert abs(a.axes_distance() - 0.3) < 1e-12
    q = face_gear_assembly(FG, InstallationErrors(dA2_mm=0.5), FP)
    # Δq > 0 moves the face gear away from the pinion axis (along -z)
    assert q.placement2(0.0)[2, 3] == pytest.approx(-0.5)
    p = face_gear_assembly(FG, InstallationErrors(dA1_mm=0.5), FP)
    d = p.axis1()[0] - a0.axis1()[0]
    # ΔA1 > 0 moves the pinion along its axis away from the crossing point (+x here)
    assert np.allclose(d, [0.5, 0, 0], atol=1e-12)


def test_placements_are_rigid_and_turn_in_the_driving_sense():
    a = face_gear_assembly(FG, None, FP)
    M = a.placement1(np.array([0.0, 0.1]))
    R = M[:, :3, :3]
    assert np.allclose(R @ np.swapaxes(R, 1, 2), np.eye(3), atol=1e-14)
    # member 2 angle advances by the ratio: φ2 = (N1/N2) φ1 keeps the pitch point rolling
    assert a.ratio == pytest.approx(25 / 160)
    assert math.isclose(a.sense2 * a.sense1, 1)


def test_bad_errors_refused():
    with pytest.raises(InputError):
        InstallationErrors(dgamma_deg=float("nan"))
    with pytest.raises(InputError):
        InstallationErrors(dgamma_deg=45.0)
