"""Work done in a forked process beside the calling one: the pictures of a run drawn while the
VTK files are written.

Drawing the PNGs of a run (matplotlib: importing it, laying out and rasterising four figures)
takes about as long as writing its VTK files and its summary; neither reads what the other
writes, so on a machine with a second core they run side by side. The child is a fork of this
process (it sees the run as it is, nothing is sent to it) and sends back only what the work
returns (the paths written); it ends with the caller, as the workers of the positions do.
Where this process cannot fork (not POSIX, a daemonic process), or
the caller keeps to one process, the work runs here when its result is asked for; so it does if
the child fails, which raises the error here, where the caller sees it.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
from collections.abc import Callable
from typing import TypeVar

from fegear.ltca.cycle import _die_with_parent

__all__ = ["apart"]

log = logging.getLogger(__name__)
T = TypeVar("T")


def _child(work: Callable[[], object], conn, parent: int) -> None:
    # ends with the caller however it ends, as the workers of the positions do

    _die_with_parent(parent)
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
