"""Finding and running CalculiX (``ccx``) on an exported deck, with its wall time and peak memory.

``ccx`` is looked up as ``$FEGEAR_CCX``, else ``ccx`` on the ``PATH`` (Debian/Ubuntu:
``apt-get install calculix-ccx``, version 2.20 there). A run is one ``ccx -i <job>`` in the deck's
folder with ``OMP_NUM_THREADS`` threads; its peak memory is the child's maximum resident set
(``os.wait4``: the process's own, not the caller's).
"""

from __future__ import annotations

import logging
import os
import shutil
import subprocess
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from fegear.errors import FegearError, InputError

__all__ = ["CcxRun", "CcxMissing", "find_ccx", "run_ccx"]

log = logging.getLogger(__name__)


class CcxMissing(FegearError):
    """No CalculiX executable."""


@dataclass(frozen=True)
class CcxRun:
    """One CalculiX run.

    Attributes
    ----------
    job
        The job path without extension.
    returncode
        ``ccx``'s exit code (0: finished).
    seconds
        Wall time (s).
    peak_MB
        Peak resident memory of ``ccx`` (MB).
    threads
        ``OMP_NUM_THREADS`` of the run.
    """

    job: Path
    returncode: int
    seconds: float
    peak_MB: float
    threads: int


def find_ccx() -> str:
    """The ``ccx`` executable (``$FEGEAR_CCX`` or ``ccx`` on the ``PATH``).

    Raises
    ------
    CcxMissing
        Neither exists.
    """
    exe = os.environ.get("FEGEAR_CCX") or shutil.which("ccx")
    if not exe or not Path(exe).exists():
        raise CcxMissing(
            "CalculiX (ccx) not found: install it (Debian/Ubuntu: apt-get install calculix-ccx) "
            "or set FEGEAR_CCX to the executable"
        )
    return exe


def run_ccx(inp: str | Path, threads: int = 1, timeout_s: float | None = None) -> CcxRun:
    """Run ``ccx -i <job>`` on the deck ``inp`` (``<job>.inp``) in its folder; its output goes
    to ``<job>.log`` there. A run past ``timeout_s`` is killed (exit code −9).

    Raises
    ------
    CcxMissing
        No ``ccx``.
    InputError
        No such deck, or ``threads < 1``.
    """
    inp = Path(inp)
    if not inp.is_file() or inp.suffix != ".inp":
        raise InputError("inp", str(inp), "an existing .inp deck")
    if not (isinstance(threads, int) and threads >= 1):
        raise InputError("threads", threads, "an integer >= 1")
    exe = find_ccx()
    job = inp.with_suffix("")
    env = {**os.environ, "OMP_NUM_THREADS": str(threads), "CCX_NPROC_EQUATION_SOLVER":
           str(threads)}  # fmt: skip
    t0 = time.perf_counter()
    with open(job.parent / (job.name + ".log"), "w", encoding="utf-8") as log_file:
        proc = subprocess.Popen(
            [exe, "-i", job.name], cwd=job.parent, stdout=log_file, stderr=subprocess.STDOUT,
            env=env,
        )  # fmt: skip
        timer = threading.Timer(timeout_s, proc.kill) if timeout_s is not None else None
        if timer is not None:
            timer.start()
        try:
            _, status, usage = os.wait4(proc.pid, 0)  # its own rusage (proc.wait has none)
        finally:
            if timer is not None:
                timer.cancel()
        proc.returncode = code = os.waitstatus_to_exitcode(status)
        peak = usage.ru_maxrss / 1024.0
    seconds = time.perf_counter() - t0
    log.info("ccx %s: exit %d, %.1f s, %.0f MB", job.name, code, seconds, peak)
    return CcxRun(job=job, returncode=code, seconds=seconds, peak_MB=peak, threads=threads)
