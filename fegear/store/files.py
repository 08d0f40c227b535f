"""Atomic file writes: a result file is either complete or absent, never half-written."""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

__all__ = ["atomic_write", "check_writable_folder", "write_json"]


def atomic_write(path: Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file next to ``path``, then rename it into place."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
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
    from fegear.errors import InputError

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
