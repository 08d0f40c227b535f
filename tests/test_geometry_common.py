"""Shared geometry machinery: transforms, curvature formulas, the generation engine."""

import numpy as np
import pytest

from fegear.geometry import (
    FlankBoundaries,
    FlankSurface,
    apply_points,
    apply_vectors,
    compose,
    finite_difference_curvatures,
    inverse,
    principal_curvatures,
    rot_axis,
    rot_x,
    rot_y,
    rot_z,
    translation,
)
from fegear.geometry.generation import Fixed, Motion, Rotation, Translation


def test_rotations_are_active_right_handed():
    # exact trigonometry of quarter turns: 1e-15 is round-off of cos(π/2)
    q = np.pi / 2
    np.testing.assert_allclose(apply_points(rot_z(q), [1, 0, 0]), [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(apply_points(rot_x(q), [0, 1, 0]), [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(apply_points(rot_y(q), [0, 0, 1]), [1, 0, 0], atol=1e-15)
    a = np.linspace(0, 3, 7)
    np.testing.assert_allclose(rot_axis([0, 0, 1], a), rot_z(a), atol=1e-15)


def test_compose_inverse_and_vectors():
    M = compose(translation([1.0, 2.0, 3.0]), rot_x(0.3), rot_z(-1.1))
    p = np.random.default_rng(0).normal(size=(5, 3))
    # rigid inverse is exact up to round-off of O(|p|) numbers
    np.testing.assert_allclose(apply_points(inverse(M), apply_points(M, p)), p, atol=1e-14)
    np.testing.assert_allclose(apply_vectors(M, p), apply_points(M, p) - M[:3, 3], atol=1e-14)


def test_motion_derivatives_match_finite_differences():
    mo = Motion(
        (Rotation("z", (0.1, -0.7, 0.05)), Translation((1, 0, 0), (0.0, 3.0)),
         Fixed(rot_y(0.4)), Rotation("x", (0.0, 1.0)))
    )  # fmt: skip
    psi, h = np.array(0.3), 1e-5
    M, M1, M2 = mo.matrices(psi)
    # central difference error O(h²·|M'''|) ≈ 1e-9 plus round-off 1e-16/h
    np.testing.assert_allclose((mo.matrices(psi + h)[0] - mo.matrices(psi - h)[0]) / (2 * h), M1,
                               atol=1e-8)  # fmt: skip
    np.testing.assert_allclose((mo.matrices(psi + h)[1] - mo.matrices(psi - h)[1]) / (2 * h), M2,
                               atol=1e-8)  # fmt: skip


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a).view(np.uint64)  # bit patterns: -0.0 differs from 0.0


@pytest.mark.parametrize("first", ["fixed", "moving"])
def test_motion_over_a_stack_is_the_motion_of_each_point(first):
    """The matrices of a stack of ψ (products batched over the stack) are those of each ψ alone,
    bit for bit: a point's generated surface does not depend on the points solved with it."""
    head = (Fixed(compose(rot_z(0.3), translation([0.0, 0.0, 80.0]))),) if first == "fixed" else ()
    oblique = compose(rot_axis([1.0, 2.0, 3.0], 0.7), translation([5.0, -2.0, 1.0]))
    mo = Motion(
        head + (Rotation("z", (0.1, -0.7, 0.05)), Translation((1, 0, 0), (0.0, 3.0)),
                Fixed(oblique), Fixed(rot_y(np.pi / 2)), Rotation("x", (0.0, 1.0)))
    )  # fmt: skip
    psi = np.random.default_rng(1).uniform(-0.6, 0.6, (9, 11))
    psi[0, :2] = 0.0, -0.0
    stack = mo.matrices(psi)
    for i, j in [(0, 0), (0, 1), (4, 7), (8, 10)]:
        one = mo.matrices(psi[i, j])
        for S, M in zip(stack, one, strict=True):
            assert np.array_equal(_bits(S[i, j]), _bits(M))


def test_envelope_points_do_not_depend_on_their_batch():
    """The equation of meshing solved for many points at once gives each point what it gives
    alone, bit for bit (each point's Newton iteration stops on its own test)."""
    from fegear.geometry.face_gear import FaceGearDesign, FaceGearMember

    fg = FaceGearMember(FaceGearDesign())
    t = np.linspace(0.35, 0.75, 9)[:, None]
    us = np.linspace(472.0, 558.0, 8)[None, :]
    batch = fg.envelope("drive", t, us)
    for i, j in [(0, 0), (3, 5), (8, 7)]:
        one = fg.envelope("drive", t[i, 0], us[0, j])
        for f in ("psi", "points", "normals", "r_u", "r_t", "n_u", "n_t", "residual"):
            assert np.array_equal(_bits(getattr(batch, f)[i, j]), _bits(getattr(one, f))), f


def test_principal_curvatures_sphere_and_saddle_sign():
    # sphere radius 4, outward normal: convex, both +1/4 (exact formula, round-off only)
    u, v = np.array([0.3, 1.0]), np.array([0.2, -0.5])

    def sph(u, v):
        return 4 * np.stack([np.cos(u) * np.cos(v), np.sin(u) * np.cos(v), np.sin(v)], -1)

    n = sph(u, v) / 4
    k, d = finite_difference_curvatures(sph, u, v, 1e-4, normals=n)
    # FD second derivatives with h = 1e-4 on |r| = 4: error ~ h² + 1e-16·4/h² ≈ 1e-7
    np.testing.assert_allclose(k, 0.25, atol=1e-6)
    # saddle z = (x² − y²)/2 at the origin, normal +z: κ = ±1, directions x and y
    z3 = np.zeros(3)
    k, d = principal_curvatures([1, 0, 0], [0, 1, 0], [0, 0, 1], z3, [0, 0, -1], [0, 0, 1])
    np.testing.assert_allclose(k, [1, -1], atol=1e-15)  # exact arithmetic
    # r_uu·n = +1 bends toward n: concave along x under the convex-positive sign
    assert k[0] == 1.0 and abs(d[0, 1]) == 1.0


def test_flank_surface_validates_shapes():
    bd = FlankBoundaries(0.0, 0.0, 1.0, 0.0, 1.0)
    good = dict(member="m", side="drive", u=np.zeros(2), v=np.zeros(3),
                points=np.zeros((2, 3, 3)), normals=np.zeros((2, 3, 3)), kappa=np.zeros((2, 3, 2)),
                directions=np.zeros((2, 3, 2, 3)), meshing_residual=np.zeros((2, 3)),
                boundaries=bd)  # fmt: skip
    FlankSurface(**good)
    with pytest.raises(ValueError, match="kappa"):
        FlankSurface(**{**good, "kappa": np.zeros((2, 3, 3))})
    with pytest.raises(ValueError, match="side"):
        FlankSurface(**{**good, "side": "left"})
    with pytest.raises(ValueError):
        FlankBoundaries(1.0, 0.0, 2.0, 0.0, 1.0)
