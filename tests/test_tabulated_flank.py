"""The tabulated bevel flank (fegear/geometry/bevel/tabulated.py) is the exact flank: points,
normals and tangents against the exact evaluator inside the table, exact outside it, its own
error measured when built, and the exact evaluator kept where no table meets the tolerance."""

from __future__ import annotations

import numpy as np
import pytest

from fegear.geometry.bevel import tabulated
from fegear.geometry.bevel.native import NativeFlank
from fegear.geometry.bevel.tabulated import TABLE_TOL_MM, TabulatedFlank, tabulate


def _members(pair):
    return [(m, side) for m in (pair.pinion, pair.gear) for side in ("drive", "coast")]


def _sample(nf, n: int, widen: float, seed: int = 0):
    """``n`` random ``(s, θ)`` over the working box widened by ``widen`` of its span."""
    lo, hi = nf.box
    span = hi - lo
    rng = np.random.default_rng(seed)
    x = rng.random((n, 2)) * (1 + 2 * widen) - widen
    return lo[0] + x[:, 0] * span[0], lo[1] + x[:, 1] * span[1]


@pytest.mark.parametrize("which", ["spiral_bevel_pair", "hypoid_pair"])
def test_the_table_is_the_exact_flank(which, request):
    pair = request.getfixturevalue(which)
    for m, side in _members(pair):
        tf = m.tabulated_flank(side)
        assert isinstance(tf, TabulatedFlank), (m.name, side)
        # the error the table measured on itself when built holds
        assert tf.error_mm <= TABLE_TOL_MM
        s, th = _sample(tf, 4000, tabulated.MARGIN, seed=1)
        p0, n0, rs0, rt0 = NativeFlank.evaluate(tf, s, th, tangents=True)
        p, n, rs, rt = tf.evaluate(s, th, tangents=True)
        lo, hi = tf.box
        x = np.stack([s, th], -1)
        near = (np.maximum(lo - x, x - hi) / (hi - lo)).max(-1) <= tabulated.NEAR
        # the build measures between every 4th node pair; random points between all nodes
        # may reach a little past it: 2x (the spline's error is smooth, no node is special)
        for sel, tol in ((near, TABLE_TOL_MM), (~near, tabulated.FAR_TOL_MM)):
            assert np.linalg.norm(p - p0, axis=-1)[sel].max() < 2 * tol, (m.name, side)
            # unit normals: ~the point error over the flank's curvature radii (> 1 mm)
            assert np.linalg.norm(n - n0, axis=-1)[sel].max() < 2 * tol, (m.name, side)
        # tangents near the flank: one order of the grid step less (h ~ span/90), scaled by
        # |r_s|, |r_θ| (~1-100 mm per unit): 1e-8 of them
        assert np.abs(rs - rs0)[near].max() < 1e-8 * np.abs(rs0).max(), (m.name, side)
        assert np.abs(rt - rt0)[near].max() < 1e-8 * np.abs(rt0).max(), (m.name, side)
        # a point is the same number whether its tangents are asked or not
        p1, n1 = tf.evaluate(s, th)
        assert np.array_equal(p1, p) and np.array_equal(n1, n)


def test_outside_the_table_the_flank_is_exact(spiral_bevel_pair):
    tf = spiral_bevel_pair.pinion.tabulated_flank("drive")
    s, th = _sample(tf, 400, 1.0, seed=2)
    lo, hi = tf.table_box
    out = (s < lo[0]) | (s > hi[0]) | (th < lo[1]) | (th > hi[1])
    assert 50 < out.sum() < 400  # both kinds in one call
    p, n = tf.evaluate(s, th)
    p0, n0 = NativeFlank.evaluate(tf, s[out], th[out])
    assert np.array_equal(p[out], p0) and np.array_equal(n[out], n0)


def test_a_flank_no_table_can_meet_keeps_its_exact_evaluator(spiral_bevel_pair, monkeypatch):
    nf = spiral_bevel_pair.gear.native_flank("drive")
    # 21 nodes (h ~ span/2): far from 1e-11 mm
    monkeypatch.setattr(tabulated, "NODES", (21,))
    assert tabulate(nf) is nf
    # and a table that meets it is returned with its error
    monkeypatch.setattr(tabulated, "NODES", (21, 201))
    tf = tabulate(nf)
    assert isinstance(tf, TabulatedFlank) and tf.error_mm <= TABLE_TOL_MM


def test_the_tca_map_of_a_bevel_member_is_the_table(spiral_bevel_pair):
    from fegear.tca import flank_map

    fm = flank_map(spiral_bevel_pair.gear, "drive")
    assert fm._nf() is spiral_bevel_pair.gear.tabulated_flank("drive")


def test_a_table_read_back_from_the_cache_is_the_table_built(spiral_bevel_pair):
    """fegear/tca/flank_tables.py: a member that reads its table from the artefact cache (a new
    process's member: same settings, no table yet) evaluates bit for bit as the member that
    built it, its inversion and its exact evaluator included; the second read is a cache hit."""
    import dataclasses

    from fegear.store.cache import record_cache_use
    from fegear.tca.flank_tables import flank_table

    built = spiral_bevel_pair.pinion
    fresh = dataclasses.replace(built, _cache={})  # the same member as another process has it
    assert repr(fresh) == repr(built)
    with record_cache_use() as used:
        a = flank_table(built, "drive")  # built (or read: another test may have stored it)
        b = flank_table(fresh, "drive")
    assert used().hits.get("flank_table", 0) >= 1
    assert b is not a and isinstance(b, TabulatedFlank)
    s, th = _sample(a, 500, 1.0, seed=3)  # inside and outside the table
    for x, y in zip(a.evaluate(s, th, True), b.evaluate(s, th, True), strict=True):
        assert np.array_equal(x, y)
    bd = built.boundaries()
    u, v = np.meshgrid(np.linspace(0.1, 0.9, 5), np.linspace(bd.v_start, bd.v_end, 5))
    for x, y in zip(a.native(u, v), b.native(u, v), strict=True):
        assert np.array_equal(x, y)
    na, nb = built.native_flank("drive"), fresh.native_flank("drive")
    for x, y in zip(na.evaluate(s, th), nb.evaluate(s, th), strict=True):
        assert np.array_equal(x, y)
