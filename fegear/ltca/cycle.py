"""The loaded mesh cycle: the TCA positions, the member models, and every position solved.

The positions are solved in chunks of ``LTCAOptions.chunk_positions`` consecutive positions. Inside
a chunk each position starts from its predecessor (``hybrid`` cell grids and ``g_max``, and, for
every fidelity, the contact solver's active set: :func:`fegear.ltca.position.solve_position`); the
first position of a chunk starts from the default cells. The chunks are independent, so they run
in parallel worker processes, forked once the models are built (the compliance operators are
memory-mapped, the TCA and the meshes shared copy-on-write: a worker costs ~10 ms to start). The
chunking is part of the method, the number of workers is not: the result is the same with one
worker or eight (``tests/test_ltca_cycle.py``). Measured on the seed face gear, ``hybrid`` level
0, 25 positions, 2 cores: positions 4.5 s in one process, 2.3 s in two (chunks of 13 and 12;
session 5). Chunks of 7 (four chunks on two workers, taken as workers free up) balance the
workers better than one chunk each (:class:`~fegear.ltca.analysis.LTCAOptions`).

Where a process cannot fork (no ``fork`` start method, or a daemon process such as a Dask worker),
the chunks run one after the other in the calling process. ``$FEGEAR_WORKERS`` sets the default
worker count (the test suite runs with 1 and forks only where a test asks for workers).
"""

from __future__ import annotations

import itertools
import logging
import math
import multiprocessing
import os
import time
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from types import SimpleNamespace
from typing import Any

import numpy as np

from fegear.errors import InputError, SolverError
from fegear.forked import die_with_parent, process_count
from fegear.ltca.analysis import (
    LTCAOptions,
    MemberModels,
    build_models,
    cycle_zone,
)
from fegear.ltca.fidelity import fidelity_of
from fegear.ltca.results import LoadedCycle, LoadedPosition
from fegear.ltca.zone import ContactZone
from fegear.tca import TCA, TCAOptions
from fegear.tca.cached import cached_tca
from fegear.tca.results import PositionResult

__all__ = ["run_ltca", "chunks", "cycle_tca", "grown_zone"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class CycleJob:
    """What the workers solving the positions share: the TCA and its positions, the models,
    the options and the torque; ``done`` takes the index of each finished position (a queue to
    the parent, or the progress callback in one process)."""

    tca: TCA
    positions: tuple[PositionResult, ...]
    models: MemberModels
    options: LTCAOptions
    torque2_Nmm: float
    done: Any = None


# The job of the forked workers: set in the parent just before the pool forks (the children
# inherit it; nothing is pickled but the chunk bounds and the results).
_JOB: list[CycleJob] = []


def chunks(n: int, size: int) -> list[range]:
    """``n`` positions in consecutive chunks of at most ``size``, as even as possible
    (25 in chunks of 13: 13 + 12)."""
    k = max(1, -(-n // max(1, size)))
    lengths = [n // k + (i < n % k) for i in range(k)]
    edges = np.concatenate([[0], np.cumsum(lengths)])
    return [range(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]


def _solve_chunk(r: range, job: CycleJob | None = None) -> list[LoadedPosition]:
    """Solve the positions ``r`` in sequence, each from its predecessor, with the job's
    fidelity (:meth:`fegear.ltca.fidelity.Fidelity.solve_position`)."""
    j = _JOB[0] if job is None else job
    fid = fidelity_of(j.options.fidelity)
    out: list[LoadedPosition] = []
    for i in r:
        previous = out[-1] if out else None
        res = fid.solve_position(
            j.tca, j.positions[i], j.models, j.torque2_Nmm, j.options, previous
        )
        out.append(res)
        j.done.put(i)
    return out


def _prime_flank_maps(tca: TCA) -> None:
    """Evaluate both exact flank maps of ``tca`` once, at the middle of their working flanks
    (native parameters, point, and back to flank coordinates), their native bounds, and the
    TCA's start values of the Newton solves on the gear flank (:meth:`fegear.tca.TCA.gear_start`,
    an interpolator made on first use).

    What a map builds on first use is then built once, in this process, before the workers
    fork, instead of once in every worker (they share it copy-on-write): the native bounds (a
    Newton inversion for the spiral bevel), and what a member computes lazily to evaluate its
    flank, e.g. the face gear's fillet-limit tables
    (:meth:`fegear.geometry.face_gear.FaceGearMember.height` and ``working_u``), which the TCA
    read from the cache does not carry. A lazily built value is the same wherever it is built:
    the positions' numbers do not change. Timed apart from the positions (``seconds["flanks"]``
    of the cycle): a cost per run, not per position."""
    for fm in (tca.fm1, tca.fm2):
        fm.native_box()
        bd = fm.bounds
        u = np.array([0.5 * (bd.u_fillet + bd.u_tip)])
        v = np.array([0.5 * (bd.v_start + bd.v_end)])
        a, b, p, _ = fm.native_point(u, v)
        fm.flank(a, b, p)
    tca.gear_start(*tca.gtree.data[:1].T)


def _prepare(models: MemberModels) -> float:
    """Build in this process, before the workers fork, what every position reads and would
    otherwise be built on first use in each worker (:meth:`fegear.ltca.model.MemberModel.prepare`:
    the mesh and flank point locators, the operator's row and column maps); the workers share
    them copy-on-write, and later runs on the same models (a torque sweep) reuse them. Returns
    the seconds taken (part of the models' time: structures of the models, not of a
    position)."""
    t0 = time.perf_counter()
    models.pinion.prepare()
    models.gear.prepare()
    return time.perf_counter() - t0


def _worker_init(threads: int, parent: int | None = None) -> None:
    """In a forked worker: an end with its parent ``parent``
    (:func:`fegear.forked.die_with_parent`), its share of the cores for the threaded half-space
    evaluation (row blocks, each computed whole by one thread: the same numbers with any thread
    count), one BLAS thread (:func:`_one_blas_thread`), and a heap that keeps its pages
    (:func:`_keep_heap`)."""
    if parent is not None:
        die_with_parent(parent)
    os.environ["FEGEAR_THREADS"] = str(threads)
    _one_blas_thread()  # for the worker's lifetime (never restored)
    _keep_heap()


#: glibc ``mallopt`` parameters (``malloc.h``): ``M_TRIM_THRESHOLD``, ``M_MMAP_THRESHOLD``.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3


def _keep_heap() -> None:
    """Let this worker's heap keep the pages it has touched (glibc only; elsewhere a no-op).

    A position allocates and frees many dense arrays of megabytes (compliance blocks, half-space
    influences, gathers of the operator). By default glibc serves each one above its mmap
    threshold (128 kB at start, raised only as such blocks are freed) with a fresh ``mmap`` and
    gives the heap's free top back to the system above twice that, so a new array is faulted in
    and zeroed by the kernel page by page again, in every worker. With both thresholds raised
    (64 MB, 256 MB) the freed pages are reused; the worker's peak memory is unchanged (it exits
    with the pool). Only the worker's process is affected; the arithmetic is the same."""
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(_M_MMAP_THRESHOLD, 64 << 20)
        libc.mallopt(_M_TRIM_THRESHOLD, 256 << 20)
    except (OSError, AttributeError):
        pass


def _one_blas_thread():
    """Limit OpenBLAS (numpy's and SciPy's BLAS) to one thread in this process; returns the
    limiter (a context manager that restores the previous limits).

    The positions' dense algebra (Cholesky of the active compliance block, products) runs on
    one BLAS thread whatever the worker count, so that ``--workers 1`` and ``--workers N`` do the
    same arithmetic: with the BLAS thread count following the worker count (2 threads in one
    process, 1 in each of two workers) the FZG pair at ``hybrid`` level 0 differed by 9e-6″ in
    the loaded TE and 1.4e-7 in the shares (the contact problem of fine cells is ill-conditioned
    and amplifies the round-off of a different summation order); with one thread the two runs
    are bitwise equal (measured, and ``tests/test_reliability.py``). One thread is also faster
    here: OpenBLAS threads left spinning next to the half-space threads made the same cycle
    6.1 s in one process against 3.0 s with one BLAS thread (2 cores, measured), and in every
    worker 1.6-3x slower, erratically. MKL and its OpenMP runtime (used by the operators before
    the positions) are not touched."""
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController().select(internal_api="openblas").limit(limits=1)


def _solve_all(job: CycleJob, parts: list[range], workers: int, progress) -> list:
    n = sum(len(r) for r in parts)
    if workers == 1:
        finished = itertools.count(1)
        done = SimpleNamespace(put=lambda _i: progress and progress(next(finished), n))
        with _one_blas_thread():
            return [p for r in parts for p in _solve_chunk(r, replace(job, done=done))]
    ctx = multiprocessing.get_context("fork")
    done = ctx.SimpleQueue()
    _JOB[:] = [replace(job, done=done)]
    try:
        threads = max(1, (os.cpu_count() or 1) // workers)
        with ProcessPoolExecutor(
            max_workers=workers,
            mp_context=ctx,
            initializer=_worker_init,
            initargs=(threads, os.getpid()),
        ) as pool:
            futures = [pool.submit(_solve_chunk, r) for r in parts]
            k, pending = 0, set(futures)
            while pending:
                _, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
                while not done.empty():
                    done.get()
                    k += 1
                    if progress is not None:
                        progress(k, n)
            return [p for f in futures for p in f.result()]
    except BrokenProcessPool as exc:
        raise SolverError(
            "a worker solving mesh positions died (out of memory?); "
            "re-run with workers=1 (CLI: --workers 1) to see the error in this process"
        ) from exc
    finally:
        _JOB.clear()


def cycle_tca(pinion, gear, assembly, options: LTCAOptions, phi1: np.ndarray | None = None):
    """The TCA of the loaded cycle's positions (:func:`fegear.tca.cached.cached_tca`, from the
    cache when the pair was analysed before): ``(tca, positions, cache_hit)``. ``phi1``: pinion
    angles (rad), default ``n_positions`` over one cycle ``[−π/N1, π/N1)``. What
    :func:`run_ltca` solves; a caller that checks the positions first
    (:func:`fegear.io.gear_run.check_engagement`) gets the same ones."""
    tca_opt = TCAOptions(
        n_positions=options.n_positions,
        separation_grid=options.tca_grid,
        E_MPa=options.E_MPa,
        nu=options.nu,
    )
    if phi1 is None:
        n = options.n_positions
        phi1 = -np.pi / assembly.n1 + 2 * np.pi / assembly.n1 * np.arange(n) / n
    phi1 = np.atleast_1d(np.asarray(phi1, dtype=float))
    return cached_tca(pinion, gear, assembly, tca_opt, phi1, workers=options.workers)


def run_ltca(
    pinion,
    gear,
    assembly,
    torque2_Nmm: float,
    options: LTCAOptions | None = None,
    phi1: np.ndarray | None = None,
    models: MemberModels | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> LoadedCycle:
    """Loaded tooth contact analysis over one mesh cycle (or at the pinion angles ``phi1``).

    Parameters
    ----------
    pinion, gear
        Generated members.
    assembly
        The assembled pair (:mod:`fegear.geometry.pair_placement`), with its installation errors.
    torque2_Nmm
        Resisting torque on member 2 (N·mm, > 0).
    options
        :class:`~fegear.ltca.analysis.LTCAOptions`.
    phi1
        Pinion angles (rad); default ``n_positions`` over one cycle ``[−π/N1, π/N1)``.
    models
        Pre-built member models (to reuse over several torques); the solve options of
        ``options`` (``n_across``, ``max_cells``, ``trim``) replace those they were built with.
    progress
        Optional callable ``progress(i, n)`` called after each position (in the order they
        finish).
    """
    if not (np.isfinite(torque2_Nmm) and torque2_Nmm > 0):
        raise InputError("torque2_Nmm", torque2_Nmm, "a finite number > 0")
    opt = options or LTCAOptions()
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    tca, tca_pos, _ = cycle_tca(pinion, gear, assembly, opt, phi1)
    phi1 = np.array([p.phi1 for p in tca_pos], dtype=float)
    asm = tca.asm
    seconds["tca"] = time.perf_counter() - t0
    if models is None:
        models = build_models(pinion, gear, assembly, opt)
    else:
        models = replace(
            models,
            n_across=opt.n_across,
            n_along=opt.n_along,
            max_cells=opt.max_cells,
            trim=opt.trim,
        )
    seconds["models"] = models.seconds + _prepare(models)
    t0 = time.perf_counter()
    _prime_flank_maps(tca)
    seconds["flanks"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    parts = chunks(len(tca_pos), opt.chunk_positions)
    workers = process_count(opt.workers, len(parts))
    job = CycleJob(tca, tuple(tca_pos), models, opt, float(torque2_Nmm))
    out = _solve_all(job, parts, workers, progress)
    for _ in range(3):
        grown = grown_zone(pinion, gear, assembly, opt, models, out, tca_pos)
        if grown is None:
            break
        log.warning(
            "the loaded lag closes a pair outside the contact zone of the sectors; rebuilding "
            "them on the exact zone within %.3g mm (pairs %s) and solving again",
            grown.gap_mm,
            [tuple(int(x) for x in p) for p in grown.pairs],
        )
        models = build_models(pinion, gear, assembly, opt, zone=grown)
        seconds["models"] += models.seconds + _prepare(models)
        out = _solve_all(replace(job, models=models), parts, workers, progress)
    seconds["positions"] = time.perf_counter() - t0
    log.info("%d positions in %.2f s (%d workers)", len(out), seconds["positions"], workers)
    return LoadedCycle(
        positions=tuple(out),
        torque2_Nmm=float(torque2_Nmm),
        phi1=phi1,
        te_unloaded_arcsec=np.array([p.te_unloaded_arcsec for p in out]),
        te_loaded_arcsec=np.array([p.te_loaded_arcsec for p in out]),
        n_in_contact=np.array([p.n_pairs_in_contact for p in out], dtype=int),
        fidelity=opt.fidelity,
        level=opt.level,
        seconds=seconds,
        phase2=float(asm.phase2),
        zone_gap_mm=float(models.zone.gap_mm) if models.zone is not None else 0.0,
        zone=models.zone,
        models=models,
    )


#: Grown zone gaps are rounded up to ``_LADDER_MM · √2^k``: runs at nearby loads (a torque sweep)
#: then grow to the same zone and share its cached sectors and operators.
_LADDER_MM = 0.01


def _on_ladder(gap_mm: float) -> float:
    """The smallest ``0.01 mm · √2^k`` (k integer) at or above ``gap_mm`` (at most √2 wider)."""
    if not gap_mm > 0.0:
        return gap_mm
    k = math.ceil(2.0 * math.log2(gap_mm / _LADDER_MM) - 1e-9)
    return _LADDER_MM * math.sqrt(2.0) ** k


def grown_zone(
    pinion,
    gear,
    assembly,
    opt: LTCAOptions,
    models: MemberModels,
    solved: list[LoadedPosition],
    positions: list,
) -> ContactZone | None:
    """The contact zone the solved positions need, if the models' zone is too small for them.

    The first zone is the sampled one at ``g_max`` (:func:`fegear.ltca.analysis.cycle_zone`). A
    pair outside its teeth that the solved lag closes (``LoadedPosition.left_out``: its angular
    gap at its closest point is below the lag ``θ``) must be modelled: returns the exact zone
    (``exact=True``) within the reach of the load, when it brings every such pair into the
    model; else None (nothing left out, or a fixed ``n_teeth`` too small for the pair: reported
    per position).

    The reach is the rigid approach the solved lag can produce, with the margin of the
    ``hybrid`` grids: ``1.5 θ_p ℓ_p`` at each position ``p``, ``ℓ_p`` the largest lever
    ``backlash_mm / backlash_rad`` of its pairs (the TCA ``positions``), and at least the
    closest point of each pair where it was left out and the models' own gap. The elastic
    deformation only opens a gap further, so no point beyond the reach can touch. The gap is
    rounded up to the ladder ``0.01 mm · √2^k`` (:func:`_on_ladder`) so that nearby loads share
    the rebuilt sectors in the cache. (Session 6 took the largest ``g_max`` and the closest
    points of the left-out pairs at every position of the cycle, where they are far from
    contact: on the seed face gear at 6e6 N·mm, ``hertz`` level 0, 0.0675 mm, and the fine zone
    of every loaded tooth grew with it.) ``positions``: the TCA positions ``solved`` came from,
    in the same order.
    """
    if models.zone is None:
        return None
    missing = sorted({q for p in solved for q in p.left_out})
    if not missing:
        return None
    gap = models.zone.gap_mm
    for p, pos in zip(solved, positions, strict=True):
        ok = np.asarray(pos.pair_valid, dtype=bool) & (np.asarray(pos.backlash_rad) > 0)
        if ok.any() and p.theta > 0:
            lever = np.asarray(pos.backlash_mm)[ok] / np.asarray(pos.backlash_rad)[ok]
            gap = max(gap, 1.5 * p.theta * float(lever.max()))
        for (k, j), v, b in zip(pos.pairs, pos.pair_valid, pos.backlash_mm, strict=True):
            if v and (int(k), int(j)) in p.left_out:
                gap = max(gap, float(b))
    gap = _on_ladder(gap)  # >= the models' gap already
    zone = cycle_zone(pinion, gear, assembly, opt, gap_mm=gap, exact=True)
    c = zone.n_teeth // 2
    teeth1 = {z.tooth - c for z in zone.pinion}
    teeth2 = {z.tooth - c for z in zone.gear}
    if not all(k in teeth1 and j in teeth2 for k, j in missing):
        return None
    return zone
