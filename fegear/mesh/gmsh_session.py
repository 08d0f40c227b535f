"""Start gmsh without losing the process's signal dispositions.

``gmsh.initialize()`` resets SIGPIPE to its default action (terminate) in the whole process
(measured: ``SigIgn`` of ``/proc/self/status`` loses bit 13 after ``initialize``, with or
without ``interruptible``). Python ignores SIGPIPE so that a write to a closed pipe raises
``BrokenPipeError``; with the default action the process dies silently instead (exit 141). That
killed the test session when a worker process of the loaded cycle had gone and the executor wrote
to its pipe. :func:`initialize` starts gmsh and puts the SIGPIPE disposition back.

Some of gmsh's 3-D meshers print straight to the C streams, past ``General.Terminal = 0`` (seen:
"Found two exactly self-intersecting facets" when HXT gives up on a sector and the next
algorithm takes over). A library must not print: :func:`native_output_to_log` sends what the C
code writes to file descriptors 1 and 2 during a call to the log instead.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import os
import signal
import sys
import tempfile
import threading
from collections.abc import Iterator

__all__ = [
    "initialize",
    "mesh_elsewhere",
    "meshes_elsewhere",
    "native_output_to_log",
    "started_here",
]

#: Whether gmsh was started in this process or in the process it was forked from (a fork
#: copies the flag with the rest of the memory; see :func:`started_here`).
_STARTED = [False]


def started_here() -> bool:
    """Whether gmsh was started (:func:`initialize`) in this process before, or in the process
    it was forked from.

    A process forked after that cannot mesh: gmsh's mesh generation in the child waits forever
    on the threads of the parent's gmsh, which the fork did not copy (measured: a sector meshed
    in the parent, then another in a forked child: ``gmsh::model::mesh::generate`` blocked in
    ``pthread_cond_wait``, no CPU used). Work that meshes in a forked process
    (:func:`fegear.ltca.analysis.build_models`) meshes here instead when this is true."""
    return _STARTED[0]


#: Whether work that meshes should do it in forked processes (:func:`mesh_elsewhere`).
_ELSEWHERE = [False]


def mesh_elsewhere() -> None:
    """From now on, work in this process that meshes a gear sector does it in a forked process
    where it can (:func:`fegear.ltca.analysis.build_models`), so that this process never starts
    gmsh and the processes forked from it later can still mesh (a sweep's worker, whose items
    run in forks of it: :mod:`fegear.sweep.local`)."""
    _ELSEWHERE[0] = True


def meshes_elsewhere() -> bool:
    """Whether :func:`mesh_elsewhere` was called in this process (or the one it was forked
    from) and gmsh was not started here: then sector meshes are made in forked processes."""
    return _ELSEWHERE[0] and not _STARTED[0]


def initialize() -> None:
    """``gmsh.initialize(interruptible=False)``, then SIGPIPE as it was before."""
    import gmsh

    _STARTED[0] = True
    main = threading.current_thread() is threading.main_thread()
    before = signal.getsignal(signal.SIGPIPE) if main else None
    gmsh.initialize(interruptible=False)
    if main and before is not None:
        # Python caches its view of the handler; re-installing it calls sigaction again.
        signal.signal(signal.SIGPIPE, before)


def _flush_c_stdio() -> None:
    """Flush the C library's stdio buffers (output redirected to a file is block-buffered)."""
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # pragma: no cover - no C runtime symbol lookup here
        pass


@contextlib.contextmanager
def native_output_to_log(
    log: logging.Logger, level: int = logging.DEBUG, prefix: str = "gmsh: "
) -> Iterator[None]:
    """Capture what native code writes to file descriptors 1 and 2 inside the block and log it,
    one record per non-empty line, after the block (also when it raises)."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    _flush_c_stdio()
    with tempfile.TemporaryFile() as tmp:
        saved = [os.dup(1), os.dup(2)]
        try:
            os.dup2(tmp.fileno(), 1)
            os.dup2(tmp.fileno(), 2)
            yield
        finally:
            _flush_c_stdio()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            tmp.seek(0)
            for line in tmp.read().decode("utf-8", "replace").splitlines():
                if line.strip():
                    log.log(level, "%s%s", prefix, line.rstrip())
