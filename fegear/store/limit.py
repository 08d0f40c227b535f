"""The size cap of the artefact cache and the eviction of its least recently used entries.

The cache (:mod:`fegear.store.cache`) holds one entry per artefact: its data files and the JSON
record that makes it valid. Every use of an entry (a hit, or its writing) sets the modification
time of its record, so the record's ``mtime`` is the entry's last use. When the cache grows past
its cap, the entries used longest ago are deleted, whole, until it fits again; the entries the
running process has used are never deleted (it has them open, and a study needs them next).

The cap is ``$FEGEAR_CACHE_LIMIT`` (``"20GB"``, ``"500 MB"``, ``"2.5G"``, a number of bytes, or
``"none"`` for no cap), else :data:`DEFAULT_LIMIT` (10 GB: the seed face gear at mesh level 0
takes 1.5 GB for all its fidelities and installation errors; level 1 about 4 GB).
"""

from __future__ import annotations

import logging
import math
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from fegear.errors import InputError

__all__ = [
    "DEFAULT_LIMIT",
    "ENV_LIMIT",
    "StoredEntry",
    "cache_limit",
    "evict",
    "parse_size",
    "stored_entries",
]

log = logging.getLogger(__name__)

#: The environment variable of the cap.
ENV_LIMIT = "FEGEAR_CACHE_LIMIT"
#: The cap when ``$FEGEAR_CACHE_LIMIT`` is not set (bytes).
DEFAULT_LIMIT = 10 * 10**9

_UNITS = {"": 1, "b": 1, "k": 10**3, "m": 10**6, "g": 10**9, "t": 10**12}
_SIZE = re.compile(r"^\s*([0-9]+(?:\.[0-9]*)?)\s*([kmgt]?)(i?)(b?)\s*$", re.IGNORECASE)
_KEY = re.compile(r"^([0-9a-f]{20})(\..+)$")


def parse_size(text: str, field: str = ENV_LIMIT) -> float:
    """Bytes of a size written as ``"10GB"``, ``"500 MB"``, ``"2.5G"``, ``"1GiB"`` or a plain
    number of bytes; ``"none"``/``"unlimited"``: no cap (``inf``).

    Raises
    ------
    InputError
        Anything else, naming ``field``.
    """
    t = str(text).strip()
    if t.lower() in ("none", "unlimited", "inf"):
        return math.inf
    m = _SIZE.match(t)
    if m is None:
        raise InputError(field, text, "a size such as 10GB, 500MB or 2.5G (or 'none' for no cap)")
    value, unit, binary, _ = m.groups()
    scale = _UNITS[unit.lower()]
    if binary and unit:
        scale = 1024 ** "bkmgt".index(unit.lower())
    return float(value) * scale


def cache_limit() -> float:
    """The cap in bytes: ``$FEGEAR_CACHE_LIMIT`` if set, else :data:`DEFAULT_LIMIT`."""
    env = os.environ.get(ENV_LIMIT, "").strip()
    return parse_size(env) if env else float(DEFAULT_LIMIT)


@dataclass(frozen=True)
class StoredEntry:
    """One complete entry in the cache folder.

    Attributes
    ----------
    kind, key
        Its kind (folder) and key.
    files
        Its files (data files and the JSON record).
    bytes
        Their total size.
    last_used
        Modification time of its record (s since the epoch): its last use.
    """

    kind: str
    key: str
    files: tuple[Path, ...]
    bytes: int
    last_used: float


def stored_entries(root: Path, record_suffix: str = ".json") -> list[StoredEntry]:
    """The entries under ``root`` that have a record (files named ``<key><suffix>`` in kind
    folders), least recently used first. Files of no record (an entry being written by
    another process, or a file of an older fegear) are not entries and are left alone."""
    out = []
    for folder in sorted(p for p in Path(root).iterdir() if p.is_dir()):
        groups: dict[str, list[Path]] = {}
        for p in folder.iterdir():
            m = _KEY.match(p.name)
            if m and p.is_file():
                groups.setdefault(m.group(1), []).append(p)
        for key, files in groups.items():
            record = folder / f"{key}{record_suffix}"
            if record not in files:
                continue
            try:
                size = sum(f.stat().st_size for f in files)
                used = record.stat().st_mtime
            except OSError:  # deleted meanwhile by another process
                continue
            out.append(StoredEntry(folder.name, key, tuple(sorted(files)), size, used))
    out.sort(key=lambda e: (e.last_used, e.kind, e.key))
    return out


def evict(
    root: Path, limit: float, keep: Iterable[tuple[str, str]] = ()
) -> tuple[list[StoredEntry], int]:
    """Delete the least recently used entries under ``root`` until its entries take at most
    ``limit`` bytes, never one of ``keep`` (``(kind, key)`` pairs). Returns the entries deleted
    and the bytes the entries take afterwards (above ``limit`` when the kept ones alone do).
    The record of an entry goes first, so that an entry cut short by an error is a miss."""
    entries = stored_entries(root)
    total = sum(e.bytes for e in entries)
    kept = set(keep)
    gone = []
    for e in entries:
        if total <= limit:
            break
        if (e.kind, e.key) in kept:
            continue
        records = [f for f in e.files if f.suffix == ".json" and f.stem == e.key]
        for f in records + [f for f in e.files if f not in records]:
            try:
                f.unlink()
            except FileNotFoundError:
                pass
        total -= e.bytes
        gone.append(e)
        log.info("cache: evicted %s/%s (%d bytes, least recently used)", e.kind, e.key, e.bytes)
    return gone, total
