"""The loaded cycle's driver (fegear.ltca.cycle): positions in chunks, chunks in worker processes.

The chunking is part of the method, the number of workers is not: the same chunks give the same
numbers in one process or several. Within a chunk a position starts from its predecessor; for
`fe` that only warm-starts the contact solver, so `fe` does not depend on the chunking either.
"""

from __future__ import annotations

import math
import pickle
from dataclasses import replace

import numpy as np
import pytest

from fegear.errors import InputError
from fegear.geometry import InvoluteDesign, InvoluteMember
from fegear.geometry.pair_placement import involute_assembly
from fegear.ltca import LTCAOptions, build_models, run_ltca
from fegear.ltca.cycle import chunks

PINION = InvoluteMember(
    InvoluteDesign(16, 4.5, 20, profile_shift=0.1817, face_width_mm=14), "pinion"
)
GEAR = InvoluteMember(InvoluteDesign(24, 4.5, 20, profile_shift=0.1715, face_width_mm=14), "gear")
RATED = 2.0e5  # N·mm on the gear, as in test_ltca.py


@pytest.fixture(scope="module")
def fzg():
    asm = involute_assembly(PINION, GEAR)
    opt = LTCAOptions(n_positions=6, level=0, fidelity="hybrid", chunk_positions=3)
    return asm, opt, build_models(PINION, GEAR, asm, opt)


def _numbers(cycle) -> np.ndarray:
    shares = [[q.load_share for q in p.pairs] for p in cycle.positions]
    width = max(len(s) for s in shares)
    padded = np.array([s + [0.0] * (width - len(s)) for s in shares])
    return np.concatenate([cycle.te_loaded_arcsec, padded.ravel()])


@pytest.mark.parametrize(
    ("n", "size", "lengths"),
    [(25, 13, [13, 12]), (5, 13, [5]), (7, 1, [1] * 7), (26, 13, [13, 13]), (27, 13, [9, 9, 9])],
)
def test_chunks_cover_the_positions_in_order(n: int, size: int, lengths: list[int]) -> None:
    parts = chunks(n, size)
    assert [len(r) for r in parts] == lengths
    assert [i for r in parts for i in r] == list(range(n))


def test_the_result_does_not_depend_on_the_number_of_workers(fzg) -> None:
    asm, opt, models = fzg
    calls: list[tuple[int, int]] = []
    runs = [
        run_ltca(
            PINION,
            GEAR,
            asm,
            RATED,
            replace(opt, workers=w),
            models=models,
            progress=lambda i, n: calls.append((i, n)),
        )
        for w in (1, 2)
    ]
    # the same chunks, the same arithmetic; 1e-12: BLAS round-off only (thread count differs)
    np.testing.assert_allclose(_numbers(runs[0]), _numbers(runs[1]), rtol=1e-12, atol=1e-12)
    # progress: once per position and run, counting up to n
    assert calls == [(i, 6) for i in range(1, 7)] * 2


def test_fe_does_not_depend_on_the_chunking(fzg) -> None:
    asm, opt, _ = fzg
    fe = replace(opt, fidelity="fe", workers=1)
    models = build_models(PINION, GEAR, asm, fe)
    runs = [
        run_ltca(PINION, GEAR, asm, RATED, replace(fe, chunk_positions=k), models=models)
        for k in (1, 6)
    ]
    # each position's QP has one minimiser; the active-set warm start of a chained position
    # changes the solver's path only (1e-9: the factorisations' round-off, relative)
    np.testing.assert_allclose(_numbers(runs[0]), _numbers(runs[1]), rtol=1e-9, atol=1e-9)
    assert sum(p.solution.iterations for p in runs[1].positions) < sum(
        p.solution.iterations for p in runs[0].positions
    )


@pytest.mark.parametrize(
    ("field", "value"), [("workers", 0), ("workers", 1.5), ("chunk_positions", 0)]
)
def test_bad_chunking_options_are_refused(field: str, value) -> None:
    with pytest.raises(InputError) as info:
        LTCAOptions(**{field: value})
    assert info.value.field == field


def test_typed_errors_survive_the_trip_from_a_worker() -> None:
    err = pickle.loads(pickle.dumps(InputError("torque2_Nmm", -1.0, "> 0", "detail")))
    assert type(err) is InputError and err.field == "torque2_Nmm" and "detail" in str(err)


def _die(r, job=None):
    """A worker's chunk whose process ends abruptly (as when the OOM killer takes it)."""
    import os

    os._exit(3)


def test_a_dying_worker_is_a_solver_error(fzg, monkeypatch) -> None:
    """A worker killed mid-chunk (the OOM killer, say) is reported as a typed error."""
    import fegear.ltca.cycle as cycle
    from fegear.errors import SolverError

    asm, opt, models = fzg
    monkeypatch.setattr(cycle, "_solve_chunk", _die)
    with pytest.raises(SolverError, match="worker"):
        run_ltca(PINION, GEAR, asm, RATED, replace(opt, workers=2), models=models)


@pytest.fixture(scope="module")
def seed_face_gear():
    """The seed face gear (cases/face_gear_nominal.toml), its ``hybrid`` level 0 options and
    models (one worker: the positions are solved in this process)."""
    from pathlib import Path

    from fegear.case_files import load_case
    from fegear.pipeline.pair import build_pair

    case = load_case(Path(__file__).parents[1] / "cases" / "face_gear_nominal.toml")
    pair = build_pair(case)
    opt = LTCAOptions(n_positions=25, level=0, fidelity="hybrid", workers=1)
    return case, pair, opt, build_models(pair.pinion, pair.gear, pair.assembly, opt)


def _seed_angles(pair, positions) -> np.ndarray:
    """Pinion angles (rad) of the ``positions`` of the 25-position cycle."""
    n1 = pair.assembly.n1
    return -np.pi / n1 + 2 * np.pi / n1 * np.asarray(positions) / 25


def test_a_hybrid_chunk_may_start_where_a_pair_leaves_at_a_flank_edge(seed_face_gear) -> None:
    """Seed face gear, ``hybrid`` level 0, rated load, φ1 = −4.896, −4.32, −3.744° (positions
    4-6 of the 25-position cycle): the leaving pair (1, 1) runs on the pinion's tip edge and
    carries 13, 8 and 4 % of the torque. A chunk that starts at an edge pair once got no cell for
    it (the normals of element-sized cells missed the mate's flank at the edge) and lost it for
    the rest of the chunk (on the flank cut at one height: 7 % of the torque, the cycle's TE
    peak-to-peak 0.54″ instead of 0.42″). Each position solved on its own or chained from its
    predecessor: the same pairs carry the same load."""
    case, pair, opt, models = seed_face_gear
    phi1 = _seed_angles(pair, [4, 5, 6])
    runs = [
        run_ltca(
            pair.pinion,
            pair.gear,
            pair.assembly,
            case.torque2_Nmm,
            replace(opt, chunk_positions=k),
            phi1=phi1,
            models=models,
        )
        for k in (3, 1)
    ]
    chained, alone = (
        [{(q.k, q.j): q.load_share for q in p.pairs} for p in r.positions] for r in runs
    )
    for a, b in zip(chained, alone, strict=True):
        assert b.get((1, 1), 0.0) > 0.02  # the leaving pair carries 4-13 % here
        # 0.005: two refinement paths end on different grids across the edge patch
        # (measured 0.0007)
        assert b[(1, 1)] == pytest.approx(a[(1, 1)], abs=0.005)
    # 0.015″ of ~3.6″ (0.4 %): the same grid-to-grid scatter (measured 0.0025″ at −4.32°)
    np.testing.assert_allclose(runs[1].te_loaded_arcsec, runs[0].te_loaded_arcsec, atol=0.015)
    assert not any(
        "no contact cell represents it" in w for p in runs[1].positions for w in p.warnings
    )


def test_the_loaded_te_converges_in_the_cell_length_along_the_patch(seed_face_gear) -> None:
    """Seed face gear, ``hybrid`` level 0, φ1 = 2.592° (position 17): two pairs share the load,
    both patches ~35 mm long and 0.5 mm wide, inside the flanks. Halving the cell length along
    the patches (``n_along`` 8 → 16 → 32; the cells across stay 0.05 mm) moves the loaded TE by
    0.0064″ then 0.0002″ (measured; observed order ≈ 5): the default ``n_along = 16`` is within
    0.001″ of the finer grid, ``n_along = 8`` (the element-length cells, 2.7 mm) 0.006″ away:
    0.2 % of the 2.7″ lag."""
    case, pair, opt, models = seed_face_gear
    phi1 = _seed_angles(pair, [17])
    te, length = [], []
    for n in (8, 16, 32):
        # max_cells 4000: the cap must not coarsen the finer grids across the patch.
        run = replace(opt, n_along=n, max_cells=4000)
        c = run_ltca(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, run, phi1, models)
        (p,) = c.positions
        loaded = [cells for q, cells in zip(p.pairs, p.cells, strict=True) if q.in_contact]
        assert len(loaded) == 2 and not any(q.edge_contact for q in p.pairs if q.in_contact)
        te.append(p.te_loaded_arcsec)
        length.append(max(float(cl.cell_mm[1]) for cl in loaded))
    d1, d2 = abs(te[1] - te[0]), abs(te[2] - te[1])
    rate = math.log(d1 / d2) / math.log(length[1] / length[2])
    msg = f"TE {te}, cell lengths {length} mm, observed order {rate:.2f}"
    assert length[1] < 0.7 * length[0] and length[2] < 0.6 * length[1], msg  # refined along
    assert rate > 1.0, msg  # converging (measured 5.3; irregular at this scale)
    # 0.002″ = 0.07 % of the lag: the default grid's distance to the finer one (measured 0.0002)
    assert d2 < 0.002, msg


def _cells(cycle) -> int:
    return sum(c.n for p in cycle.positions for c in p.cells)


def test_trimming_the_cells_far_from_contact_does_not_change_the_answer(fzg) -> None:
    """``hybrid`` leaves out of each solve the cells whose loaded gap, predicted from the
    previous solution, exceeds ``trim θ h_max``. The contact problem restricted to cells that
    include its active set has the same solution, so the loaded TE and the shares are those of
    all cells, on fewer cells."""
    asm, opt, models = fzg
    full = run_ltca(PINION, GEAR, asm, RATED, replace(opt, trim=0.0, workers=1), models=models)
    trimmed = run_ltca(PINION, GEAR, asm, RATED, replace(opt, trim=0.3, workers=1), models=models)
    # The same QP on a subset of its cells holding the active set: equal up to the round-off of
    # two active-set paths, which the edge-contact pair's compliance amplifies (its cells are
    # 4 µm wide here: θ 1.5e-7 apart at one solve; measured 1e-5″ on TE ~ 50″, 1e-6 on shares).
    np.testing.assert_allclose(_numbers(trimmed), _numbers(full), rtol=0, atol=1e-4)
    assert _cells(trimmed) < 0.85 * _cells(full)  # measured 0.65: the trimming did something


def test_a_trim_that_leaves_loaded_cells_out_is_caught(fzg, caplog) -> None:
    """A trim far too tight (cells predicted within 1 % of the rigid approach only) leaves
    loaded cells out; the check on the ring of left-out cells sees them close and the position
    is solved again on all cells: the answer is that of all cells."""
    asm, opt, models = fzg
    full = run_ltca(PINION, GEAR, asm, RATED, replace(opt, trim=0.0, workers=1), models=models)
    with caplog.at_level("INFO", logger="fegear.ltca.position"):
        tight = run_ltca(
            PINION, GEAR, asm, RATED, replace(opt, trim=0.01, workers=1), models=models
        )
    assert any("solved on all cells" in r.getMessage() for r in caplog.records)
    # as above: round-off of two active-set paths
    np.testing.assert_allclose(_numbers(tight), _numbers(full), rtol=0, atol=1e-4)


@pytest.mark.parametrize("value", [-0.1, float("nan"), float("inf")])
def test_a_bad_trim_is_refused(value: float) -> None:
    with pytest.raises(InputError, match="trim"):
        LTCAOptions(trim=value)


@pytest.mark.parametrize(
    ("field", "value"), [("n_along", 0), ("n_along", 2.5), ("n_across", -1), ("max_cells", 0)]
)
def test_bad_grid_counts_are_refused(field: str, value) -> None:
    with pytest.raises(InputError, match=field):
        LTCAOptions(**{field: value})
