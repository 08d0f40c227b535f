"""The rigid contact of ``SpiralBevelPair.design()`` solved natively is the engine's contact.

:func:`fegear.geometry.bevel.pair.transmission_error` solves the contact equations (Litvin &
Fuentes 2004 §9.4) in the flanks' native cutter parameters through their fast exact evaluators
(:class:`~fegear.geometry.bevel.pair._MeshContact`); ``engine=True`` solves them in flank
coordinates through the envelope engine (``point_normal``), the code they replace. Both must give
the same contact to round-off, and the native contact must satisfy the equations evaluated with
the engine's surface.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from fegear.geometry.bevel import SpiralBevelBlank
from fegear.geometry.bevel.pair import (
    SpiralBevelPair,
    _members,
    _MeshContact,
    transmission_error,
)
from fegear.geometry.bevel.synthesis import SynthesisTargets, synthesize
from fegear.geometry.transforms import apply_points, apply_vectors


@pytest.fixture(scope="module")
def synthesized():
    """The 12/36 reference pair as synthesized (first-order settings, no third-order roll):
    the pair the third-order roll's first trial solves."""
    blank = SpiralBevelBlank(module_mm=4.941634)
    targets = SynthesisTargets()
    settings, reports = synthesize(blank, targets)
    return SpiralBevelPair._build(blank, targets, settings, reports)


def _engine_residual(pair, side, phi1, x):
    """The contact equations at flank coordinates ``x = (u1, v1, u2, v2, φ2)`` evaluated with
    the engine's surface (``point_normal``): max abs (mm / unit normals)."""
    pin, gear = pair.mesh_placement(side)
    p1, n1 = pair.pinion.point_normal(side, x[0:1], x[1:2])
    p2, n2 = pair.gear.point_normal(side, x[2:3], x[3:4])
    P, G = pin(phi1), gear(x[4])
    r = np.concatenate(
        [apply_points(P, p1) - apply_points(G, p2), apply_vectors(P, n1) + apply_vectors(G, n2)],
        -1,
    )
    return float(np.max(np.abs(r)))


@pytest.mark.parametrize("side", ["drive", "coast"])
def test_native_contact_is_the_engine_contact(synthesized, side):
    """TE and contact parameters of the native solve equal the engine solve's to round-off at
    the third-order roll's angles ``±π/N1`` (and 0); the native contact satisfies the equations
    with the engine's surface to 1e-9 mm."""
    pair = synthesized
    phi = np.array([-math.pi / pair.blank.n1, 0.0, math.pi / pair.blank.n1])
    te, X, res = transmission_error(pair, side, phi)
    te0, X0, res0 = transmission_error(pair, side, phi, engine=True)
    assert np.all(res < 1e-11) and np.all(res0 < 1e-11)
    assert np.max(np.abs(te - te0)) < 1e-13  # rad (TE ~5e-5 rad at the ends)
    assert np.max(np.abs(X[:, [0, 2]] - X0[:, [0, 2]])) < 1e-9  # u
    assert np.max(np.abs(X[:, [1, 3]] - X0[:, [1, 3]])) < 1e-8  # v = L, mm
    for a, x in zip(phi, X, strict=True):
        assert _engine_residual(pair, side, a, x) <= 1e-9


def test_native_jacobian_is_the_derivative_of_the_residual(synthesized):
    """The Newton's Jacobian (analytic tangents, differenced normals, analytic gear turn) is the
    derivative of the contact equations (central differences, 1e-6 relative)."""
    mc = _MeshContact.of(synthesized, "drive")
    phi1 = 0.05
    pin, gear = synthesized.pinion, synthesized.gear
    x = np.array([*pin.mean_parameters("drive"), *gear.mean_parameters("drive"), 0.0])
    y = mc.native(x) + [0.3, 0.01, -0.2, 0.01, synthesized.blank.m21 * phi1]
    J = mc.linearize(phi1, y)[1]
    h = np.array([1e-5, 1e-7, 1e-5, 1e-7, 1e-7])
    Jfd = np.empty((6, 5))
    for k in range(5):
        e = np.zeros(5)
        e[k] = h[k]
        Jfd[:, k] = (mc.residual(phi1, y + e) - mc.residual(phi1, y - e)) / (2 * h[k])
    scale = np.max(np.abs(Jfd), axis=0)
    assert np.max(np.abs(J - Jfd) / scale) < 1e-5


def test_members_pool_shares_equal_settings_only(synthesized):
    """Within one design the members of equal settings are one object (their caches shared);
    another third-order roll makes another pinion, the gear stays."""
    pair = synthesized
    pool: dict = {}
    p1, g1 = _members(pair.blank, pair.settings, pool)
    p2, g2 = _members(pair.blank, pair.settings, pool)
    assert p1 is p2 and g1 is g2
    st = replace(pair.settings, pinion_drive=replace(pair.settings.pinion_drive,
                                                     modified_roll_third=0.05))  # fmt: skip
    p3, g3 = _members(pair.blank, st, pool)
    assert p3 is not p1 and g3 is g1
    assert p3.drive.modified_roll_third == 0.05
    assert _members(pair.blank, pair.settings)[0] is not p1  # no pool: new members
