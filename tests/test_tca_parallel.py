"""TCA positions on several processes (:mod:`fegear.tca.parallel`): a position's result does not
depend on the batch it is solved in, so a batch split over processes is the batch solved here,
bit for bit, and so are the path of contact and the hand-overs built on it."""

from __future__ import annotations

import dataclasses
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from fegear.case_files import load_case
from fegear.pipeline.pair import build_pair
from fegear.tca import TCA, TCAOptions, reference_phase
from fegear.tca.engagement import handover
from fegear.tca.parallel import positions
from fegear.tca.path import contact_path

FZG = Path(__file__).resolve().parents[1] / "cases" / "fzg_spur.toml"


@pytest.fixture(scope="module")
def tilted():
    """FZG with a helix slope deviation: a localized contact whose path ends inside the cycle
    (both ends are bisected) and whose hand-overs are at tip edges."""
    case = load_case(FZG)
    case = replace(case, errors=replace(case.errors, f_sigma_beta_mm=0.01))
    pair = build_pair(case)
    opt = TCAOptions(n_positions=13)
    asm = pair.assembly.with_phase2(reference_phase(pair.pinion, pair.gear, pair.assembly, opt))
    tca = TCA(pair.pinion, pair.gear, asm, opt)
    phi1 = -np.pi / asm.n1 + 2 * np.pi / asm.n1 * np.arange(13) / 13
    return tca, phi1


def _same(a, b, where="") -> list[str]:
    """Paths at which ``a`` and ``b`` differ (arrays bit for bit, NaN equal to NaN)."""
    if dataclasses.is_dataclass(a):
        return [d for f in dataclasses.fields(a) for d in _same(
            getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")]  # fmt: skip
    if isinstance(a, (tuple, list)):
        if len(a) != len(b):
            return [f"{where} (length)"]
        return [
            d
            for i, (x, y) in enumerate(zip(a, b, strict=True))
            for d in _same(x, y, f"{where}[{i}]")
        ]
    if isinstance(a, np.ndarray):
        same = a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
        return [] if same else [where]
    if isinstance(a, float) and np.isnan(a):
        return [] if np.isnan(b) else [where]
    return [] if a == b else [where]


def test_a_position_does_not_depend_on_its_batch(tilted):
    """One batch, two uneven batches and one position at a time: equal bit for bit (every
    Newton iteration acts on each position's own points and stops on its own residual)."""
    tca, phi1 = tilted
    whole = tca.positions(phi1)
    split = tca.positions(phi1[:5]) + tca.positions(phi1[5:])
    alone = [tca.positions(phi1[i : i + 1])[0] for i in (0, 6, 12)]
    assert _same(whole, split) == []
    assert _same([whole[i] for i in (0, 6, 12)], alone) == []


@pytest.mark.parametrize("workers", [2, 3])
def test_positions_on_several_processes_are_those_of_one(tilted, workers):
    """Chunks in forked processes, concatenated in order: the batch solved here."""
    tca, phi1 = tilted
    assert _same(positions(tca, phi1, workers=workers), tca.positions(phi1)) == []
    # grids and ellipses left out as the path's and hand-overs' searches do
    assert _same(
        positions(tca, phi1, with_grids=False, ellipses=False, workers=workers),
        tca.positions(phi1, with_grids=False, ellipses=False),
    ) == []  # fmt: skip


def test_path_of_contact_and_handovers_do_not_depend_on_the_processes(tilted):
    """Both ends of the path bisected in one batch per round, on two processes; the hand-overs'
    samples and brackets on two processes: the one-process results bit for bit."""
    tca, phi1 = tilted
    pos = tca.positions(phi1, with_grids=False)
    one, two = contact_path(tca, pos, workers=1), contact_path(tca, pos, workers=2)
    assert one is not None and "unresolved" not in one.start_limit + one.end_limit
    assert _same(one, two) == []
    h1, h2 = handover(tca, workers=1), handover(tca, workers=2)
    assert _same(h1, h2) == []
