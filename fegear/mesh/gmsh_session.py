"""Start gmsh without losing the process's signal dispositions.

``gmsh.initialize()`` resets SIGPIPE to its default action (terminate) in the whole process
(measured: ``SigIgn`` of ``/proc/self/status`` loses bit 13 after ``initialize``, with or
without ``interruptible``). Python ignores SIGPIPE so that a write to a closed pipe raises
``BrokenPipeError``; with the default action the process dies silently instead (exit 141). That
killed the test session when a worker process of the loaded cycle had gone and the executor wrote
to its pipe. :func:`initialize` starts gmsh and puts the SIGPIPE disposition back.
"""

from __future__ import annotations

import signal
import threading

__all__ = ["initialize"]


def initialize() -> None:
    """``gmsh.initialize(interruptible=False)``, then SIGPIPE as it was before."""
    import gmsh

    main = threading.current_thread() is threading.main_thread()
    before = signal.getsignal(signal.SIGPIPE) if main else None
    gmsh.initialize(interruptible=False)
    if main and before is not None:
        # Python caches its view of the handler; re-installing it calls sigaction again.
        signal.signal(signal.SIGPIPE, before)
