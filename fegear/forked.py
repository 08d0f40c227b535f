"""Work in forked processes beside the calling one: the cores of a 2-core machine used by one run.

- :func:`process_count`: how many processes a piece of work may use (``$FEGEAR_WORKERS``, else one
  per core; 1 where this process cannot fork).
- :func:`apart`: one piece of work in a second process while the caller goes on (the pictures of a
  run drawn while its VTK files are written).
- :func:`fork_map`: independent parts of one computation, the first here and the others in
  forked processes, results in order (the TCA's positions: :func:`fegear.tca.parallel.positions`).
- :func:`die_with_parent`: a forked process ends with the process that forked it.

A child is a fork of this process: it sees the caller's objects as they are (nothing is sent to
it) and sends back only what the work returns (pickled). Where this process cannot fork (not
POSIX, a daemonic process such as a Dask worker), or the caller keeps to one process, the work
runs here; so it does if a child fails, which raises the error here, where the caller sees it.
The work of a child is the same code on the same inputs as here, so the results are the same.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
import sys
import time
from collections.abc import Callable, Sequence
from typing import TypeVar

from fegear.errors import InputError

__all__ = ["apart", "die_with_parent", "fork_map", "process_count"]

log = logging.getLogger(__name__)
T = TypeVar("T")
S = TypeVar("S")


def process_count(requested: int | None, n_chunks: int) -> int:
    """Processes for ``n_chunks`` chunks: ``requested`` (validated by LTCAOptions), else
    ``$FEGEAR_WORKERS``, else one per core; 1 where this process cannot fork."""
    env = os.environ.get("FEGEAR_WORKERS", "").strip()
    if requested is None and env:
        if not (env.isdigit() and int(env) >= 1):
            raise InputError("FEGEAR_WORKERS", env, "an integer >= 1")
        requested = int(env)
    want = requested if requested is not None else (os.cpu_count() or 1)
    want = min(want, n_chunks)
    if want > 1 and (
        "fork" not in multiprocessing.get_all_start_methods()
        or multiprocessing.current_process().daemon
    ):
        log.info("the work runs in this process (no fork here)")
        return 1
    return want


#: ``prctl`` option of Linux: the signal the calling process gets when its parent ends.
PR_SET_PDEATHSIG = 1


def die_with_parent(parent: int, poll_s: float = 1.0) -> None:
    """End this worker when the process that forked it (pid ``parent``) ends, however it ends
    (SIGTERM of a job manager or ``timeout``, SIGKILL of the OOM killer): the pool's own
    shutdown never runs then, and a worker holds some hundred MB.

    On Linux the kernel sends SIGKILL to this process when its parent dies
    (``prctl(PR_SET_PDEATHSIG, SIGKILL)``, set through ctypes); the parent may have died between
    the fork and that call, so the parent pid is checked after it (a dead parent's orphans are
    re-parented: ``getppid()`` no longer returns it) and the worker exits at once. The forking
    thread is the thread that runs the pool (the caller's), alive as long as the pool is. Where
    ``prctl`` is not available (macOS forks too), a daemon thread polls ``getppid()`` every
    ``poll_s`` seconds and ends the process when it changes."""
    import signal

    armed = False
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
        except (OSError, AttributeError):
            armed = False
    if os.getppid() != parent:  # the parent died before the signal was armed
        os._exit(1)
    if armed:
        return
    import threading

    def watch() -> None:
        while True:
            time.sleep(poll_s)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, name="fegear-parent-watch", daemon=True).start()


def _child(work: Callable[[], object], conn, parent: int) -> None:
    # ends with the caller however it ends, as the workers of the positions do
    die_with_parent(parent)
    try:
        result: tuple[str, object] = ("done", work())
    except BaseException as exc:  # noqa: BLE001 (reported to the parent, which redoes the work)
        result = ("failed", f"{type(exc).__name__}: {exc}")
    try:
        conn.send(result)
    except OSError:  # the caller is gone
        pass
    finally:
        conn.close()


def apart(work: Callable[[], T], fork: bool) -> Callable[[], T]:
    """Start ``work()`` in a forked process if ``fork`` and this process can fork; returns the
    function that waits for it and returns its result (``work()`` run here instead where it was
    not started, or if the child failed)."""
    if not fork or "fork" not in multiprocessing.get_all_start_methods():
        return work
    if multiprocessing.current_process().daemon:
        return work
    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(work, send, os.getpid()), name="fegear-apart")
    try:
        proc.start()
    except OSError as exc:  # out of processes or memory: here instead
        log.info("no second process (%s): the work runs here", exc)
        return work
    send.close()

    def wait() -> T:
        try:
            status, value = recv.recv()
        except (EOFError, OSError):
            status, value = "failed", f"the process exited ({proc.exitcode})"
        finally:
            recv.close()
            proc.join()
        if status == "done":
            return value
        log.warning("work in a second process failed (%s): done again here", value)
        return work()

    return wait


def fork_map(work: Callable[[S], T], parts: Sequence[S], fork: bool = True) -> list[T]:
    """``[work(p) for p in parts]``, the first part computed here and every other one in a forked
    process at the same time (:func:`apart`), the results in the order of ``parts``.

    For independent parts of one computation (a batch of TCA positions split in contiguous
    chunks): with ``len(parts)`` equal to :func:`process_count`, every core works on one part.
    ``fork=False``, or a process that cannot fork: all parts here, one after the other."""
    waits = [apart(lambda p=p: work(p), fork) for p in parts[1:]]
    first = work(parts[0]) if len(parts) else None
    return ([first] if len(parts) else []) + [w() for w in waits]  # type: ignore[list-item]
