"""Atomic file writes: a result file is either complete or absent, never half-written.

A write goes to a temporary file next to its target, named ``.<stem>.tmp<pid>_<random><suffix>``
(:data:`TEMP_PATTERN`: the writer's process id in the name), then renamed into place. A process
killed between the two (kill -9, the OOM killer) leaves the temporary file behind;
:func:`clean_stale_temps` removes those whose writer is gone, in the cache (at the start of a
run) and in an output folder (before a run writes into it, :mod:`fegear.store.outputs`).
"""

from __future__ import annotations

import contextvars
import json
import os
import re
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from fegear.errors import InputError

__all__ = [
    "STALE_AGE_S",
    "TEMP_PATTERN",
    "atomic_write",
    "check_writable_folder",
    "clean_stale_temps",
    "is_stale_temp",
    "journal",
    "write_json",
]

#: Temporary name of :func:`atomic_write`: ``.<stem>.tmp<pid>_<8 random><suffix>``.
TEMP_PATTERN = re.compile(r"^\.(?P<stem>.+)\.tmp(?P<pid>[0-9]+)_[a-z0-9_]{8}(?P<suffix>.*)$")
#: The temporary name of earlier fegear versions (no process id): ``.<stem>.<8 random><suffix>``.
_OLD_TEMP = re.compile(r"^\.(?P<stem>.+)\.[a-z0-9_]{8}(?P<suffix>\.[A-Za-z0-9]+)?$")
#: A temporary file older than this (s) is stale whoever wrote it: no atomic write of fegear
#: lasts a day (a process id can be reused by another process after its writer died).
STALE_AGE_S = 86400.0

#: The manifest an output folder's writes are listed in (:func:`journal`): (folder, manifest).
_JOURNAL: contextvars.ContextVar[tuple[Path, Path] | None] = contextvars.ContextVar(
    "fegear_output_journal", default=None
)


@contextmanager
def journal(folder: Path, manifest: Path) -> Iterator[None]:
    """Inside the block, every :func:`atomic_write` under ``folder`` first appends the file's
    path (relative to ``folder``) to ``manifest``: the list holds a file before it exists, so a
    run killed half-way still names everything it made (:mod:`fegear.store.outputs`)."""
    token = _JOURNAL.set((Path(folder).resolve(), Path(manifest)))
    try:
        yield
    finally:
        _JOURNAL.reset(token)


def _note(path: Path) -> None:
    j = _JOURNAL.get()
    if j is None:
        return
    root, manifest = j
    try:
        rel = path.resolve().relative_to(root).as_posix()
    except ValueError:  # not under the output folder
        return
    with open(manifest, "a", encoding="utf-8") as fh:
        fh.write(rel + "\n")


def _pid_alive(pid: int) -> bool:
    """A process ``pid`` exists (signal 0; a process of another user exists too)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return False
    return True


def is_stale_temp(
    path: Path, stems: re.Pattern[str] | None = None, now: float | None = None
) -> bool:
    """``path`` is the temporary file of an atomic write whose writer is gone: its name is
    :data:`TEMP_PATTERN` and its process is not running (or the file is older than
    :data:`STALE_AGE_S`); or it has the temporary name of an earlier fegear (no process id) and
    a stem matching ``stems`` (the names of the outputs of a folder), or is older than
    :data:`STALE_AGE_S`."""
    name = path.name
    m = TEMP_PATTERN.match(name)
    try:
        age = (time.time() if now is None else now) - path.lstat().st_mtime
    except OSError:
        return False
    if m is not None:
        return not _pid_alive(int(m.group("pid"))) or age > STALE_AGE_S
    m = _OLD_TEMP.match(name)
    if m is None:
        return False
    return (stems is not None and stems.match(m.group("stem")) is not None) or age > STALE_AGE_S


def clean_stale_temps(
    folder: str | Path, recursive: bool = False, stems: re.Pattern[str] | None = None
) -> list[Path]:
    """Remove the stale temporary files of interrupted atomic writes in ``folder`` (and its
    subfolders with ``recursive``; :func:`is_stale_temp`); returns them. Files that vanish or
    cannot be removed meanwhile (another process cleaning) are skipped."""
    root = Path(folder)
    if not root.is_dir():
        return []
    found = root.rglob(".*") if recursive else root.glob(".*")
    gone = []
    for p in found:
        try:
            if p.is_file() and not p.is_symlink() and is_stale_temp(p, stems):
                p.unlink()
                gone.append(p)
        except OSError:
            continue
    return gone


def atomic_write(path: Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file next to ``path`` (:data:`TEMP_PATTERN`), then
    rename it into place."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _note(path)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{path.stem}.tmp{os.getpid()}_", suffix=path.suffix, dir=path.parent
    )
    os.close(fd)
    tmp_path = Path(tmp)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp_path, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual mode
    try:
        write(tmp_path)
        os.replace(tmp_path, path)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()
    return path


def write_json(path: Path, data: object) -> Path:
    """Write ``data`` as indented JSON, atomically."""
    text = json.dumps(data, indent=2, allow_nan=False)
    return atomic_write(path, lambda p: p.write_text(text + "\n", encoding="utf-8"))


def check_writable_folder(path: str | Path, field: str = "--out") -> Path:
    """Refuse, before any work, an output folder that cannot be written: a file, a path under
    a file, or a folder (or the nearest existing parent of one to be made) where a file cannot
    be created (:class:`~fegear.errors.InputError` naming ``field``). Nothing is created; a
    probe file is made and removed in the nearest existing folder (``os.access`` is not enough:
    it says yes to root on a read-only file system)."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise InputError(field, str(p), "a folder (it is an existing file)")
    parent = p
    while not parent.exists() and parent.parent != parent:
        parent = parent.parent
    if not parent.is_dir():
        raise InputError(field, str(p), f"a folder path (it lies under the file {parent})")
    try:
        fd, probe = tempfile.mkstemp(prefix=".fegear-probe-", dir=parent)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise InputError(
            field, str(p), "a folder fegear can write to", f"{parent}: {exc.strerror or exc}"
        ) from exc
    return p
