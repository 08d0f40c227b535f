"""The on-disk TCA cache (fegear.tca.cached): a hit gives back exactly what a fresh TCA gives,
and anything the positions depend on (installation errors, options, angles) is in the key."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fegear.geometry import InvoluteDesign, InvoluteMember
from fegear.geometry.pair_placement import InstallationErrors, involute_assembly
from fegear.tca import TCA, TCAOptions, reference_phase
from fegear.tca.cached import cached_tca

PINION = InvoluteMember(
    InvoluteDesign(16, 4.5, 20, profile_shift=0.1817, face_width_mm=14), "pinion"
)
GEAR = InvoluteMember(InvoluteDesign(24, 4.5, 20, profile_shift=0.1715, face_width_mm=14), "gear")
OPT = TCAOptions(n_positions=5, separation_grid=(8, 4))
PHI1 = np.linspace(-0.1, 0.1, 5)


@pytest.fixture()
def private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path))
    return tmp_path


def _same(a, b) -> None:
    assert len(a) == len(b)
    for p, q in zip(a, b, strict=True):
        assert p.phi1 == q.phi1 and p.te_rad == q.te_rad  # bit-identical: a JSON + npz round trip
        np.testing.assert_array_equal(p.points, q.points)
        assert len(p.grids) == len(q.grids)
        for g, h in zip(p.grids, q.grids, strict=True):
            np.testing.assert_array_equal(g.separation, h.separation)
            np.testing.assert_array_equal(g.h, h.h)


def test_hit_returns_what_a_fresh_tca_computes(private_cache) -> None:
    asm = involute_assembly(PINION, GEAR, InstallationErrors(f_sigma_beta_mm=0.01))
    first = cached_tca(PINION, GEAR, asm, OPT, PHI1)
    second = cached_tca(PINION, GEAR, asm, OPT, PHI1)
    assert not first.cache_hit and second.cache_hit
    fresh_asm = asm.with_phase2(reference_phase(PINION, GEAR, asm, OPT))
    fresh = TCA(PINION, GEAR, fresh_asm, OPT).positions(PHI1)
    assert second.tca.asm.phase2 == fresh_asm.phase2
    _same(second.positions, fresh)
    _same(first.positions, fresh)
    assert len(list((private_cache / "tca").glob("*.json"))) == 1


@pytest.mark.parametrize(
    "change",
    [
        pytest.param(dict(errors=InstallationErrors(f_sigma_beta_mm=0.02)), id="errors"),
        pytest.param(dict(options=replace(OPT, separation_grid=(10, 4))), id="options"),
        pytest.param(dict(phi1=PHI1 + 1e-9), id="angles"),
    ],
)
def test_a_changed_input_is_a_miss(private_cache, change) -> None:
    base = InstallationErrors(f_sigma_beta_mm=0.01)
    cached_tca(PINION, GEAR, involute_assembly(PINION, GEAR, base), OPT, PHI1)
    asm = involute_assembly(PINION, GEAR, change.get("errors", base))
    again = cached_tca(PINION, GEAR, asm, change.get("options", OPT), change.get("phi1", PHI1))
    assert not again.cache_hit
    assert len(list((private_cache / "tca").glob("*.json"))) == 2
