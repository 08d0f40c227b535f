"""The contact zone of a cycle (docs/mesh/README.md, :mod:`fegear.ltca.zone`): which teeth the
sectors need and where their meshes must be fine, from the TCA alone (FZG type C spur pair, contact
ratio 1.46, and a face gear with localized contact)."""

from __future__ import annotations

import numpy as np
import pytest

from fegear.errors import InputError
from fegear.geometry import InvoluteDesign, InvoluteMember
from fegear.geometry.pair_placement import involute_assembly
from fegear.ltca.zone import contact_zone
from fegear.tca import TCA, TCAOptions, reference_phase

PINION = InvoluteMember(
    InvoluteDesign(16, 4.5, 20, profile_shift=0.1817, face_width_mm=14), "pinion"
)
GEAR = InvoluteMember(InvoluteDesign(24, 4.5, 20, profile_shift=0.1715, face_width_mm=14), "gear")


@pytest.fixture(scope="module")
def cycle():
    asm = involute_assembly(PINION, GEAR)
    opt = TCAOptions(n_positions=13, separation_grid=(24, 12))
    a = asm.with_phase2(reference_phase(PINION, GEAR, asm, opt))
    tca = TCA(PINION, GEAR, a, opt)
    phi1 = -np.pi / 16 + 2 * np.pi / 16 * np.arange(13) / 13
    return tca, tca.positions(phi1)


def _inside(zones, tooth, u, v) -> np.ndarray:
    """Points ``(u, v)`` of sector tooth ``tooth`` covered by one of its boxes."""
    hit = np.zeros(u.shape, dtype=bool)
    for z in zones:
        if z.tooth == tooth:
            hit |= (
                (u >= z.u[0] - 1e-12)
                & (u <= z.u[1] + 1e-12)
                & (v >= z.v[0] - 1e-12)
                & (v <= z.v[1] + 1e-12)
            )
    return hit


def test_teeth_cover_every_pair_that_can_touch_plus_a_neighbour(cycle):
    tca, pos = cycle
    z = contact_zone(pos, tca.fm1.bounds, tca.fm2.bounds, "drive", "drive", 0.02)
    # contact ratio 1.46: over one pitch the pairs -1, 0, +1 come within 20 µm of touching
    assert sorted(z.pairs[:, 0].tolist()) == [-1, 0, 1]
    # ... so 3 loaded teeth + one unloaded neighbour on each side, symmetric about tooth 0
    assert z.n_teeth == 5
    teeth1 = {q.tooth for q in z.pinion}
    assert teeth1 == {1, 2, 3}  # the neighbours 0 and 4 carry nothing: no fine zone there
    # an explicit count is kept (pairs outside it get no zone)
    z3 = contact_zone(pos, tca.fm1.bounds, tca.fm2.bounds, "drive", "drive", 0.02, n_teeth=3)
    assert z3.n_teeth == 3 and {q.tooth for q in z3.pinion} <= {0, 1, 2}


def test_zone_holds_every_cell_that_can_touch_on_both_flanks(cycle):
    tca, pos = cycle
    gap = 0.02
    z = contact_zone(pos, tca.fm1.bounds, tca.fm2.bounds, "drive", "drive", gap)
    c = z.n_teeth // 2
    b1, b2 = tca.fm1.bounds, tca.fm2.bounds
    for box, b in [(q, b1) for q in z.pinion] + [(q, b2) for q in z.gear]:
        # boxes lie on the working flank (clipped to its limits)
        assert b.u_fillet - 1e-12 <= box.u[0] < box.u[1] <= b.u_tip + 1e-12
        assert b.v_start - 1e-12 <= box.v[0] < box.v[1] <= b.v_end + 1e-12
    n_checked = 0
    for p in pos:
        for g in p.grids:
            near = g.valid & (g.separation <= gap)
            if not near.any():
                continue
            U, V = np.meshgrid(g.u, g.v, indexing="ij")
            assert _inside(z.pinion, g.k + c, U[near], V[near]).all(), (g.k, g.j)
            gu, gv = g.gear_uv[near].T
            assert _inside(z.gear, g.j + c, gu, gv).all(), (g.k, g.j)
            n_checked += int(near.sum())
    assert n_checked > 100  # the check saw the contact zone


def test_a_larger_gap_never_shrinks_the_zone(cycle):
    tca, pos = cycle
    small = contact_zone(pos, tca.fm1.bounds, tca.fm2.bounds, "drive", "drive", 0.005)
    large = contact_zone(pos, tca.fm1.bounds, tca.fm2.bounds, "drive", "drive", 0.05)
    rng = np.random.default_rng(0)
    c = small.n_teeth // 2
    for q in small.pinion:
        u = rng.uniform(*q.u, 200)
        v = rng.uniform(*q.v, 200)
        t = q.tooth - c + large.n_teeth // 2
        assert _inside(large.pinion, t, u, v).all()


def test_positions_without_grids_are_refused(cycle):
    tca, _ = cycle
    bare = tca.positions(np.array([0.0]), with_grids=False)
    with pytest.raises(InputError, match="separation grids"):
        contact_zone(bare, tca.fm1.bounds, tca.fm2.bounds, "drive", "drive", 0.02)


@pytest.mark.slow  # two sets of face-gear sectors built cold: minutes
def test_a_load_beyond_the_zone_grows_it_and_models_the_new_pair():
    """Seed face gear at 2x its rated load (6e6 N·mm on the face gear). The sectors start on the
    sampled zone at ``g_max`` = 0.02 mm: pairs (0, 0) and (-1, -1). Pair (1, 1) comes within
    17.8 µm of contact at its closest point (every coarse sample reads more than 22.9 µm): the
    rated load (lag x lever 9.5 µm) cannot close it, twice the load can. The cycle must see that
    the lag closes a pair it left out, rebuild the sectors on the exact zone that holds it and
    solve again: nothing left out, equilibrium kept."""
    from fegear.geometry.face_gear import FaceGearDesign, FaceGearMember
    from fegear.geometry.pair_placement import InstallationErrors, face_gear_assembly
    from fegear.ltca import LTCAOptions, run_ltca

    fg = FaceGearMember(FaceGearDesign())
    pin = fg.pinion()
    asm = face_gear_assembly(fg, InstallationErrors(), pin)
    opt = LTCAOptions(n_positions=25, level=0)
    phi1 = np.linspace(-np.pi / pin.n_teeth, np.pi / pin.n_teeth, 5, endpoint=False)
    c = run_ltca(pin, fg, asm, 6e6, opt, phi1=phi1)
    zone_pairs = {tuple(p) for p in c.zone.pairs.tolist()}
    assert (1, 1) in zone_pairs  # the zone grew to the pair the load closes ...
    assert c.zone_gap_mm >= opt.g_max_mm
    assert all(p.left_out == () for p in c.positions)  # ... and nothing is left out
    left_out = [w for p in c.positions for w in p.warnings if "outside the contact zone" in w]
    assert left_out == []
    for p in c.positions:
        # torque balance, enforced by the contact solve up to round-off: the shares add up to one
        assert sum(q.load_share for q in p.pairs) == pytest.approx(1.0, abs=1e-9)


def test_the_grown_zone_reaches_as_far_as_the_lag_can_close(monkeypatch):
    """The rebuilt zone's gap is the rigid approach the solved lag can produce, ``1.5 θ ℓ`` (ℓ the
    largest lever of a position's pairs), and the closest point of a left-out pair where it was
    left out, rounded up to a ladder of bounds; not that pair's closest point at the positions
    where it is far from contact (the session-6 rule took those and grew the fine zone of every
    loaded tooth with them)."""
    from types import SimpleNamespace

    from fegear.ltca import cycle as cyc

    seen = []

    def fake_zone(pinion, gear, assembly, opt, gap_mm, exact):
        seen.append((gap_mm, exact))
        boxes = tuple(SimpleNamespace(tooth=2 + t) for t in (-1, 0, 1))
        return SimpleNamespace(n_teeth=5, pinion=boxes, gear=boxes, gap_mm=gap_mm)

    monkeypatch.setattr(cyc, "cycle_zone", fake_zone)
    models = SimpleNamespace(zone=SimpleNamespace(gap_mm=0.02))
    pairs = np.array([[0, 0], [1, 1]])
    lever = 500.0  # mm
    # position 0: pair (1, 1) 15 µm away and left out by a lag of 4e-5 rad (20 µm at the lever);
    # position 1: the same pair 80 µm away, not closed, lag 3e-5 rad
    tca = [
        SimpleNamespace(
            pairs=pairs,
            pair_valid=np.array([True, True]),
            backlash_mm=np.array([0.0, b]),
            backlash_rad=np.array([0.0, b / lever]),
        )
        for b in (0.015, 0.080)
    ]
    solved = [
        SimpleNamespace(theta=4e-5, left_out=((1, 1),), g_max_mm=0.1),
        SimpleNamespace(theta=3e-5, left_out=(), g_max_mm=0.1),
    ]
    z = cyc.grown_zone(None, None, None, None, models, solved, tca)
    assert z is not None and seen[-1][1] is True
    # 1.5 x 4e-5 rad x 500 mm = 0.030 mm: the reach of position 0; neither the 0.080 mm of the
    # far position nor the g_max of 0.1 mm the solves used. Rounded up to the ladder
    # 0.01 mm x sqrt(2)^k so that nearby loads share the rebuilt sectors: 0.02 sqrt(2) = 0.0283
    # < 0.030 <= 0.04 mm
    assert seen[-1][0] == pytest.approx(0.04, rel=1e-12)
    # a load 10 % higher reaches 0.033 mm: the same zone, so the same cached sectors
    solved[0] = SimpleNamespace(theta=4.4e-5, left_out=((1, 1),), g_max_mm=0.1)
    cyc.grown_zone(None, None, None, None, models, solved, tca)
    assert seen[-1][0] == seen[-2][0]
    # nothing left out: no rebuild
    solved_ok = [SimpleNamespace(theta=4e-5, left_out=(), g_max_mm=0.1)] * 2
    assert cyc.grown_zone(None, None, None, None, models, solved_ok, tca) is None
