"""The items of a sweep on this machine: one warm process, the later items side by side.

An installation-error study runs the same gears many times: every item needs the sector meshes,
the compliance operators and the factorisations of the displacement fields, and they are the
same for every item (they depend on the members, the mesh level and the material, not on where
the mate sits). So all items run in ONE worker process (forked from the calling one, or a fresh
interpreter where it cannot fork), which keeps them in memory after the first item:

1. the first item alone, with every core (:func:`_first`): it builds (or reads from the cache)
   the meshes and operators. Meanwhile a forked, low-priority process prepares the later items:
   their TCA and engagement checks (``prepare``: :func:`fegear.pipeline.run.check_case`), kept in
   the artefact cache, so that each later item finds them there. While the first item builds
   its operators the cores are not all busy (dense and sparse factorisations in turns); the
   preparation takes what they leave (``nice``).
2. the others in groups of ``workers`` (:func:`_side_by_side`): the first item of a group in the
   worker process, the others in processes forked from it
   (:func:`fegear.forked.fork_map`), each inheriting the models, operators and
   factorisations the worker holds, so none reads or factorises them again; each item then
   solves its positions in one process. Two items side by side keep both cores busy through
   the parts of an item that run on one core (the TCA, the VTK files, the pictures); one
   item on both cores leaves one idle there. Measured: ``benchmarks/results/error_study.md``.
   A process forked after gmsh started in its parent cannot mesh
   (:func:`fegear.mesh.gmsh_session.started_here`): the worker makes its sector meshes in forked
   processes (:func:`fegear.mesh.gmsh_session.mesh_elsewhere`), so an item with members of its
   own meshes them in its own process; where gmsh ran in the worker all the same (the remeshed
   stress sectors of ``root_stress``), the items run one after the other in it.

With ``workers = 1`` the later items run one after the other in the worker process, each with
every core for its positions. The items' results do not depend on the grouping (the positions
use one BLAS thread in every process: :mod:`fegear.ltca.cycle`). An item that fails is its own
:class:`ItemResult`; a side-by-side process that dies has its item run again in the worker
(:func:`fegear.forked.apart`).
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import sys
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from typing import TypeVar

from fegear.forked import die_with_parent, fork_map, process_count
from fegear.mesh.gmsh_session import mesh_elsewhere, started_here
from fegear.output.figure import pyplot

__all__ = ["run_local"]

log = logging.getLogger(__name__)

Item = TypeVar("Item")
Result = TypeVar("Result")
#: ``run_one(item, processes)``: one item with that many processes for its positions (None:
#: one per core); never raises for a failure of the item (its result says so).
RunOne = Callable[[Item, "int | None"], Result]
#: ``prepare(item)``: work of the item that needs no model, kept in the cache (may raise).
Prepare = Callable[[Item], object]
#: ``failed(item, exc)``: the result of an item whose worker process died.
Failed = Callable[[Item, BaseException], Result]


def _worker_init() -> None:  # pragma: no cover  (runs in the worker process)
    """The worker: ends with the sweep process (Linux), and has matplotlib imported once: every
    item draws its pictures in this process or one forked from it, which then finds it imported
    instead of importing it again (about a second per item)."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes
            import signal

            ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
        except Exception:  # noqa: BLE001  (best effort)
            pass
    pyplot()
    # the items run in forks of this process: it must not start gmsh (a process forked after
    # gmsh started cannot mesh: fegear.mesh.gmsh_session.started_here)
    mesh_elsewhere()


def _prepare_all(prepare: Prepare, items: Sequence, parent: int) -> None:
    """In the preparation process: ``prepare`` each item at low priority; an item it cannot
    prepare is left to its run (which reports why)."""
    die_with_parent(parent)
    try:
        os.nice(19)  # the lowest: only what the first item leaves
    except OSError:
        pass
    for it in items:
        try:
            prepare(it)
        except Exception as exc:  # noqa: BLE001  (the item's own run reports it)
            log.debug("not prepared: %s", exc)


def _start_preparing(prepare: Prepare, items: Sequence) -> None:
    """``prepare`` the ``items`` in a forked daemon process (none where this process cannot
    fork, or for no items)."""
    if not items or process_count(None, 2) < 2:
        return
    ctx = multiprocessing.get_context("fork")
    proc = ctx.Process(
        target=_prepare_all,
        args=(prepare, list(items), os.getpid()),
        name="fegear-prepare",
        daemon=True,  # ends with the worker; it forks nothing (prepare runs on one process)
    )
    try:
        proc.start()  # a daemon: ended with the worker if still running then
    except OSError as exc:  # out of processes or memory: each item does its own checks
        log.info("no preparation process (%s)", exc)


def _first(run_one: RunOne, prepare: Prepare | None, item, later: Sequence) -> list:
    """The first item with every core, the ``later`` ones prepared beside it."""
    if prepare is not None:
        _start_preparing(prepare, later)
    return [run_one(item, None)]


def _side_by_side(run_one: RunOne, items: Sequence) -> list:
    """``items`` at the same time, one process each (forked from this one), in order."""
    if len(items) == 1:
        return [run_one(items[0], None)]
    if started_here():  # gmsh ran here (a root-stress remesh): a fork could not mesh
        log.info("gmsh was started in the sweep's worker: the items one after the other")
        return [run_one(it, None) for it in items]
    return fork_map(lambda it: run_one(it, 1), list(items))


def _pool() -> ProcessPoolExecutor:
    """The worker: forked from this process where it can fork (it starts with fegear and
    matplotlib imported, imported here first: a second against starting an interpreter and
    importing them again, measured on 2 cores), else a fresh ``spawn`` interpreter: where this
    process cannot fork, or has started gmsh (a process forked after that cannot mesh). A
    process with Dask's threads never gets here (a sweep on a scheduler has no local worker)."""
    can_fork = "fork" in multiprocessing.get_all_start_methods()
    method = "fork" if can_fork and not started_here() else "spawn"  # gmsh: see started_here
    if method == "fork":
        pyplot()  # the sweep's own pictures need it too
    return ProcessPoolExecutor(
        max_workers=1,
        mp_context=multiprocessing.get_context(method),
        initializer=_worker_init,
    )


def run_local(
    todo: Sequence[Item],
    run_one: RunOne,
    workers: int,
    failed: Failed,
    prepare: Prepare | None = None,
) -> Iterator[Result]:
    """Run ``todo`` in one worker process, the first item alone, then ``workers`` at a time
    (see the module's docstring); yield each group's results as the group finishes, in order.

    ``run_one`` and ``prepare`` are sent to the worker (picklable: module-level functions or
    :func:`functools.partial` of them)."""
    if not todo:
        return
    groups = [list(todo[i : i + workers]) for i in range(1, len(todo), workers)]
    pool = _pool()
    try:
        futures: list[Future] = [pool.submit(_first, run_one, prepare, todo[0], todo[1:])]
        futures += [pool.submit(_side_by_side, run_one, g) for g in groups]
        for fut, group in zip(futures, [[todo[0]], *groups], strict=True):
            try:
                yield from fut.result()
            except Exception as exc:  # noqa: BLE001  (BrokenProcessPool: the worker died)
                yield from (failed(it, exc) for it in group)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
