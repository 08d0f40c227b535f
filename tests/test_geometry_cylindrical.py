"""Cylindrical members: the modified involute helicoid against the generated surface and the
analytic involute, the hand of the helix, the modifications as a profile/helix chart reads them.
"""

import math

import numpy as np
import pytest

from fegear.errors import DesignError, InputError
from fegear.geometry import GeneratedMember, InvoluteDesign, InvoluteMember
from fegear.geometry.cylindrical import (
    CylindricalMember,
    FlankModifications,
    signed_helix_deg,
)
from fegear.geometry.involute import involute_function
from fegear.tca.surfaces import HelicoidMap, flank_map

# FZG type C data with a helix: z 16/24, m_n 4.5, α_n 20°, x 0.1817/0.1715, b 14 mm
FZG = {"pinion": (16, 0.1817), "gear": (24, 0.1715)}


def design(name, beta=0.0, **kw):
    z, x = FZG[name]
    return InvoluteDesign(n_teeth=z, module_mm=4.5, pressure_angle_deg=20.0, profile_shift=x,
                          face_width_mm=14.0, helix_angle_deg=beta, **kw)  # fmt: skip


def grid(member, side, nu=13, nv=9):
    bd = member.boundaries(side)
    u = np.linspace(bd.u_fillet, bd.u_tip, nu)[:, None]
    v = np.linspace(bd.v_start, bd.v_end, nv)[None, :]
    return np.broadcast_arrays(u, v)


@pytest.mark.parametrize("name", ["pinion", "gear"])
@pytest.mark.parametrize("beta", [0.0, 15.0, -25.0])
@pytest.mark.parametrize("side", ["drive", "coast"])
def test_unmodified_flank_is_the_generated_surface(name, beta, side):
    gen, cyl = InvoluteMember(design(name, beta), name), CylindricalMember(design(name, beta), name)
    assert isinstance(cyl, GeneratedMember)
    U, V = grid(gen, side)
    p0, n0 = gen.point_normal(side, U, V)
    p1, n1 = cyl.point_normal(side, U, V)
    # both exact: the envelope is solved to round-off (~1e-14 mm at radii of 60 mm)
    assert np.abs(p1 - p0).max() < 1e-12, np.abs(p1 - p0).max()
    assert np.abs(n1 - n0).max() < 1e-12, np.abs(n1 - n0).max()
    # the fillet is the generated one
    bd = gen.boundaries(side)
    uf = np.linspace(bd.u_root, bd.u_fillet, 6)[:-1]
    fillet = cyl.point_normal(side, uf, 0 * uf)[0]
    assert np.array_equal(fillet, gen.point_normal(side, uf, 0 * uf)[0])


@pytest.mark.parametrize("beta", [0.0, 15.0, -25.0])
@pytest.mark.parametrize("side", ["drive", "coast"])
def test_points_on_the_analytic_involute_helicoid(beta, side):
    g = CylindricalMember(design("pinion", beta), "pinion")
    d = g.design
    U, V = grid(g, side, 21, 7)
    P = g.point_normal(side, U, V)[0]
    ry = np.hypot(P[..., 0], P[..., 1])
    half = (np.pi / 2 + 2 * d.profile_shift * np.tan(np.radians(d.pressure_angle_deg))) / d.n_teeth
    half = half + involute_function(g.alpha_t) - involute_function(np.arccos(g.r_b / ry))
    sg = 1 if side == "drive" else -1
    expected = sg * half - P[..., 2] * np.tan(np.radians(beta)) / g.r_p
    err = ry * np.abs(np.arctan2(P[..., 1], P[..., 0]) - expected)
    # closed form against the polar form of the same surface: round-off of ~60 mm radii
    assert err.max() < 1e-12, err.max()


def test_hand_of_the_helix():
    right = CylindricalMember(design("pinion", signed_helix_deg(15.0, "right")), "pinion")
    left = CylindricalMember(design("pinion", signed_helix_deg(15.0, "left")), "pinion")
    assert right.hand == "right" and left.hand == "left"
    u = np.full(2, 0.5 * (right.boundaries("drive").u_fillet + right.boundaries("drive").u_tip))
    z = np.array([-5.0, 5.0])
    for m, sense in ((right, 1.0), (left, -1.0)):
        p = m.point_normal("drive", u, z)[0]
        dth = np.diff(np.arctan2(p[:, 1], p[:, 0]))[0]
        # a right-hand helix turns counter-clockwise (+θ) along +z, like a right-hand screw:
        # by z tan β / r over 10 mm
        assert dth == pytest.approx(sense * 10 * math.tan(math.radians(15)) / m.r_p, rel=1e-9)


MODS = FlankModifications(
    lead_crowning_mm=0.012, helix_slope_mm=-0.008, end_relief_mm=0.01, end_relief_length_mm=2.5,
    end_relief_shape="parabolic", profile_crowning_mm=0.004, tip_relief_mm=0.015,
    tip_relief_start_diameter_mm=80.0, root_relief_mm=0.009, root_relief_start_roll_deg=14.0,
)  # fmt: skip


def chart_deviation(m, side, P):
    """The deviation a measuring machine reads: in the transverse section of the point, along
    the base tangent (the involutes of one base circle are parallel curves, a common normal
    meets them ``r_b Δθ`` apart), from the unmodified involute through the same radius."""
    ry = np.hypot(P[..., 0], P[..., 1])
    half = m._psi_b - involute_function(np.arccos(m.r_b / ry))
    sg = 1 if side == "drive" else -1
    om = -P[..., 2] * np.tan(np.radians(m.design.helix_angle_deg)) / m.r_p
    return m.r_b * sg * (sg * half + om - np.arctan2(P[..., 1], P[..., 0]))


@pytest.mark.parametrize("beta", [0.0, -20.0])
@pytest.mark.parametrize("side", ["drive", "coast"])
def test_modifications_as_the_charts_read_them(beta, side):
    m = CylindricalMember(design("pinion", beta), "pinion", MODS)
    U, V = grid(m, side, 41, 29)
    P = m.point_normal(side, U, V)[0]
    dev = chart_deviation(m, side, P)
    L = m.roll_length(U)
    b, z = 14.0, V
    pr = m._profile
    Lm, Lw = 0.5 * (pr.L_form + pr.L_tip), pr.L_tip - pr.L_form
    L_ca = math.sqrt(40.0**2 - m.r_b**2)  # start diameter 80 mm
    L_cf = m.r_b * math.radians(14.0)  # start roll angle 14°
    expected = (
        0.004 * (2 * (L - Lm) / Lw) ** 2
        + 0.015 * np.maximum(L - L_ca, 0) / (pr.L_tip - L_ca)
        + 0.009 * np.maximum(L_cf - L, 0) / (L_cf - pr.L_form)
        + 0.012 * (2 * z / b) ** 2
        - 0.008 * z / b
        + 0.01 * (np.maximum(np.abs(z) - (7 - 2.5), 0) / 2.5) ** 2
    )
    # the chart reading and the definition agree to round-off (both exact)
    assert np.abs(dev - expected).max() < 1e-12, np.abs(dev - expected).max()
    # tip relief reaches C_a at the tip, root relief C_f at the form circle, lead crowning C_β
    # at the face ends: read off the chart at the corners of the middle of the face
    assert m.modification(pr.L_tip, 0.0)[0] == pytest.approx(0.004 + 0.015, abs=1e-15)


@pytest.mark.parametrize("beta", [0.0, 20.0])
def test_normals_of_the_modified_flank(beta):
    m = CylindricalMember(design("pinion", beta), "pinion", MODS)
    for side in ("drive", "coast"):
        U, V = grid(m, side, 11, 11)
        # away from the kinks of the linear reliefs (their slope jumps there)
        X, N, Xu, Xv = m.helicoid(side, U, V)
        h = 1e-5
        fu = (m.helicoid(side, U + h, V)[0] - m.helicoid(side, U - h, V)[0]) / (2 * h)
        fv = (m.helicoid(side, U, V + h)[0] - m.helicoid(side, U, V - h)[0]) / (2 * h)
        L = m.roll_length(U)
        pr = m._profile
        near = np.minimum(np.abs(L - m.r_b * math.radians(14.0)),
                          np.abs(L - math.sqrt(40**2 - m.r_b**2))) < 2 * h  # fmt: skip
        ok = ~near & (np.abs(np.abs(V) - 4.5) > 2 * h) & (pr.L_form < L)
        # central differences: truncation h² X''' ~ 1e-10, round-off 1e-16·60/1e-5 ~ 1e-9
        assert np.abs(fu - Xu)[ok].max() < 1e-7
        assert np.abs(fv - Xv)[ok].max() < 1e-7
        assert np.abs(np.sum(N * Xu, -1)).max() < 1e-12
        assert np.abs(np.sum(N * Xv, -1)).max() < 1e-12
        assert np.abs(np.linalg.norm(N, axis=-1) - 1).max() < 1e-14


def test_tca_map_is_the_member_surface():
    m = CylindricalMember(design("pinion", 15.0), "pinion", MODS)
    fm = flank_map(m, "drive")
    assert isinstance(fm, HelicoidMap)
    U, V = grid(m, "drive")
    p, n = fm.evaluate(*fm.native(U, V))
    p0, n0 = m.point_normal("drive", U, V)
    assert np.array_equal(p, p0) and np.array_equal(n, n0)


def test_sector_meshes_are_made_of_the_unmodified_solid():
    m = CylindricalMember(design("pinion", 15.0), "pinion", MODS)
    mm = m.mesh_member()
    assert type(mm) is InvoluteMember and mm.design == m.design
    assert repr(mm) == repr(CylindricalMember(design("pinion", 15.0), "pinion").mesh_member())


def test_curvatures_of_the_flank():
    gen = InvoluteMember(design("pinion", 15.0), "p")
    cyl = CylindricalMember(design("pinion", 15.0), "p")
    a, b = gen.flank("drive", 17, 5), cyl.flank("drive", 17, 5)
    w = a.u >= a.boundaries.u_fillet
    # central differences with 1e-3 mm steps: truncation ~1e-7 1/mm
    assert np.abs(a.kappa[w] - b.kappa[w]).max() < 1e-6
    assert np.abs(a.points - b.points).max() < 1e-12


@pytest.mark.parametrize(
    "kw, field",
    [
        (dict(tip_relief_mm=0.01, tip_relief_start_diameter_mm=90.0),
         "tip_relief_start_diameter_mm"),
        (dict(root_relief_mm=0.01, root_relief_start_roll_deg=2.0), "root_relief_start_roll_deg"),
        (dict(end_relief_mm=0.01, end_relief_length_mm=8.0), "end_relief_length_mm"),
        (dict(end_relief_mm=0.01), "end_relief_length_mm"),
        (dict(lead_crowning_mm=-0.01), "lead_crowning_mm"),
        (dict(tip_relief_shape="cubic"), "tip_relief_shape"),
        (dict(tip_relief_start_diameter_mm=80.0, tip_relief_start_roll_deg=20.0),
         "tip_relief_start_roll_deg"),
        (dict(tip_relief_mm=0.01, root_relief_mm=0.01, tip_relief_start_diameter_mm=76.0,
              root_relief_start_diameter_mm=79.0), "root_relief_start_diameter_mm"),
    ],
)  # fmt: skip
def test_bad_modifications_name_the_field(kw, field):
    with pytest.raises(InputError, match=field):
        CylindricalMember(design("pinion"), "pinion", FlankModifications(**kw))


def test_design_modifications_are_refused():
    with pytest.raises(InputError, match="lead_crowning_mm"):
        CylindricalMember(design("pinion", lead_crowning_mm=0.01), "pinion")
    with pytest.raises(DesignError, match="tip_radius_mm.*pointed"):
        design("pinion", tip_radius_mm=48.0)
