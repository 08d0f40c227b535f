"""Rack-generated involute members against the analytic involute (FZG type C reference)."""

import numpy as np
import pytest

from fegear.errors import DesignError, InputError
from fegear.geometry import GeneratedMember, finite_difference_curvatures
from fegear.geometry.involute import InvoluteDesign, InvoluteMember, involute_function

# FZG type C: z 16/24, m 4.5, α 20°, x 0.1817/0.1715, a 91.5 mm, b 14 mm
FZG = {
    "pinion": dict(n_teeth=16, profile_shift=0.1817),
    "gear": dict(n_teeth=24, profile_shift=0.1715),
}


def member(name, beta=0.0, **kw):
    d = InvoluteDesign(module_mm=4.5, pressure_angle_deg=20.0, face_width_mm=14.0,
                       helix_angle_deg=beta, **FZG[name], **kw)  # fmt: skip
    return InvoluteMember(d, name)


def analytic_error(g, fl):
    """Distance (mm, along the circle) of the working-flank points from the exact involute."""
    d = g.design
    w = fl.u >= fl.boundaries.u_fillet
    P = fl.points[w]
    ry = np.hypot(P[..., 0], P[..., 1])
    ay = np.arccos(g.r_b / ry)
    half = (np.pi / 2 + 2 * d.profile_shift * np.tan(np.radians(d.pressure_angle_deg))) / d.n_teeth
    half = half + involute_function(g.alpha_t) - involute_function(ay)
    sg = 1 if fl.side == "drive" else -1
    expected = sg * half - P[..., 2] * np.tan(np.radians(d.helix_angle_deg)) / g.r_p
    return ry * np.abs(np.arctan2(P[..., 1], P[..., 0]) - expected), ry, w


@pytest.mark.parametrize("name", ["pinion", "gear"])
@pytest.mark.parametrize("beta", [0.0, 15.0])
@pytest.mark.parametrize("side", ["drive", "coast"])
def test_points_on_analytic_involute(name, beta, side):
    g = member(name, beta)
    assert isinstance(g, GeneratedMember)
    fl = g.flank(side, 41, 7)
    err, ry, _ = analytic_error(g, fl)
    # the envelope is solved to round-off: 1e-9 mm leaves ~1e5 × ε·r of margin
    assert err.max() < 1e-9, f"max distance from the analytic involute {err.max():.3e} mm"
    assert ry.max() == pytest.approx(g.r_a, abs=1e-9)  # u_tip generates the tip circle
    # meshing residual: a sine, solved to round-off
    assert fl.meshing_residual.max() < 1e-12, fl.meshing_residual.max()


@pytest.mark.parametrize("beta", [0.0, 15.0])
def test_normals_unit_and_orthogonal_to_tangents(beta):
    g = member("pinion", beta)
    fl = g.flank("drive", 21, 5)
    U, V = np.meshgrid(fl.u, fl.v, indexing="ij")
    env = g.envelope("drive", U, V)
    # unit normalisation and orthogonality hold to round-off (|n| = 1, tangents O(1))
    assert np.abs(np.linalg.norm(fl.normals, axis=-1) - 1).max() < 1e-12
    for tan in (env.r_u, env.r_t):
        cos = np.sum(fl.normals * tan, -1) / np.linalg.norm(tan, axis=-1)
        assert np.abs(cos).max() < 1e-12, np.abs(cos).max()
    # outward: the drive flank faces +θ (the root point u = 0 faces radially: excluded)
    e_th = np.stack([-fl.points[..., 1], fl.points[..., 0], 0 * U], -1)
    assert np.all(np.sum(fl.normals * e_th, -1)[fl.u > 0] > 0)


@pytest.mark.parametrize("name", ["pinion", "gear"])
def test_profile_curvature_radius_is_rb_tan_alpha(name):
    g = member(name)
    fl = g.flank("coast", 41, 5)
    _, ry, w = analytic_error(g, fl)
    rho = g.r_b * np.tan(np.arccos(g.r_b / ry))
    k = fl.kappa[w]
    # spur involute cylinder: κ1 = 1/ρ (convex), κ2 = 0; relative error is round-off
    assert np.abs(k[..., 0] * rho - 1).max() < 1e-9
    assert np.abs(k[..., 1]).max() < 1e-12
    assert np.all(fl.kappa[~w][..., 0] <= 1e-12)  # the trochoidal fillet is concave


@pytest.mark.parametrize(
    "beta, mods",
    [(0.0, {}), (15.0, {}), (0.0, dict(profile_crowning_mm=0.01, lead_crowning_mm=0.015))],
)
def test_curvatures_match_finite_differences(beta, mods):
    g = member("pinion", beta, **mods)
    fl = g.flank("drive", 25, 7)
    U, V = np.meshgrid(fl.u, fl.v, indexing="ij")
    kf, df = finite_difference_curvatures(
        lambda a, b: g.point_normal("drive", a, b)[0], U, V, 1e-3, normals=fl.normals
    )
    # the rack tip arc meets the straight flank at u_fillet: curvature jumps there, skip that row
    keep = ~np.isclose(fl.u, fl.boundaries.u_fillet)
    err = np.abs(kf - fl.kappa)[keep]
    # FD with h = 1e-3 mm: truncation O(h²κ''') and round-off ε·r/h² ≈ 5e-9 → 1e-5 1/mm is ample
    assert err.max() < 1e-5, f"max |κ_FD − κ| = {err.max():.3e} 1/mm"


def test_crowning_removes_material():
    plain, crowned = member("pinion"), member("pinion", lead_crowning_mm=0.02)
    u = np.array([6.0]), np.array([7.0])
    p0, n0 = plain.point_normal("drive", *u)
    p1, _ = crowned.point_normal("drive", *u)
    # at the face end z = b/2 lead crowning C_β removes C_β along the normal (to 1e-4 C_β)
    assert np.sum((p1 - p0) * n0) == pytest.approx(-0.02, rel=1e-2)


def test_validation_names_the_field():
    with pytest.raises(InputError, match="pressure_angle_deg"):
        InvoluteDesign(n_teeth=16, module_mm=4.5, pressure_angle_deg=40.0)
    with pytest.raises(InputError, match="module_mm"):
        InvoluteDesign(n_teeth=16, module_mm=-1.0)
    with pytest.raises(InputError, match="n_teeth"):
        InvoluteDesign(n_teeth=2, module_mm=1.0)
    with pytest.raises(DesignError, match="profile_shift.*undercut"):
        InvoluteDesign(n_teeth=8, module_mm=1.0, profile_shift=0.0)
    # a tip radius that follows from the shift: the shift is named, with the shift of a pointed
    # tip (the tooth thickness at the tip circle, closed form, vanishes there to 1e-9 rad)
    with pytest.raises(DesignError, match=r"profile_shift.*<= 0\.6996.*pointed") as e:
        InvoluteDesign(n_teeth=10, module_mm=1.0, profile_shift=1.2)
    from fegear.geometry.design_checks import _pointed_shift, _tip_half_angle

    d = InvoluteDesign(n_teeth=10, module_mm=1.0, profile_shift=0.5)
    x_max = _pointed_shift(d)  # bisection to 1e-12 in x; dψ_a/dx ~ 0.1 rad
    assert abs(_tip_half_angle(d, x_max)) < 1e-11 and f"<= {x_max:.4f}" in str(e.value)
    # a given tip radius is named itself
    with pytest.raises(DesignError, match="tip_radius_mm.*pointed"):
        InvoluteDesign(n_teeth=10, module_mm=1.0, profile_shift=0.5, tip_radius_mm=6.9)
