"""Content-hash cache of expensive artefacts (meshes, compliance operators, TCA, …).

An artefact is stored under ``<cache root>/<kind>/<hash>.<suffix>`` where the hash is the SHA-256
of a canonical JSON of everything that determines it (geometry, mesh parameters, material, boundary
conditions, code version of the producer). The root (:func:`cache_root`) is ``$FEGEAR_CACHE`` if
set, else the per-user cache folder of the platform (``platformdirs.user_cache_dir("fegear")``:
``~/.cache/fegear`` on Linux, ``~/Library/Caches/fegear`` on macOS,
``%LOCALAPPDATA%\\fegear\\Cache`` on Windows), so runs from any working directory share one cache.

The root holds a ``CACHEDIR.TAG`` (the Cache Directory Tagging convention: backup tools skip the
folder) that also marks it as a fegear cache: :func:`clear_cache` refuses to delete anything in a
folder without it (a folder of an older fegear, made before the tag, is recognised by its layout:
only kind folders of content-hash files).

Files are written to a temporary name in the same folder and renamed into place, so an interrupted
run never leaves a half-written artefact that a later run would trust.

Every lookup is counted (:func:`record_cache_use`), so a caller can tell a warm run from a cold
one by what it read, not by its timing.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import re
import shutil
from collections import Counter
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fegear.errors import InputError
from fegear.io.files import atomic_write

__all__ = [
    "CACHE_TAG",
    "CacheInfo",
    "CacheUse",
    "KindInfo",
    "cache_dir",
    "cache_info",
    "cache_root",
    "cached_file",
    "clear_cache",
    "content_hash",
    "is_cache_folder",
    "record_cache_use",
]

log = logging.getLogger(__name__)

#: Name of the tag file at the cache root.
CACHE_TAG = "CACHEDIR.TAG"
_TAG_TEXT = (
    "Signature: 8a477f597d28d172789f06886806bc55\n"
    "# This file is a cache directory tag created by fegear (mesh and operator cache).\n"
    "# For information about cache directory tags see https://bford.info/cachedir/\n"
)
_SIGNATURE = "Signature: 8a477f597d28d172789f06886806bc55"
_KIND = re.compile(r"^[a-z][a-z0-9_]*$")
#: An artefact (``<20 hex>.<suffix>``) or the temporary file of an interrupted write
#: (``.<20 hex>.<random>.<suffix>``, :func:`fegear.io.files.atomic_write`).
_ARTEFACT = re.compile(r"^\.?[0-9a-f]{20}(\.[A-Za-z0-9_]+)*$")


def cache_root() -> Path:
    """The cache root: ``$FEGEAR_CACHE`` if set (and not empty), else the per-user cache folder
    of the platform. Not created here."""
    env = os.environ.get("FEGEAR_CACHE", "").strip()
    if env:
        return Path(env).expanduser()
    import platformdirs

    return Path(platformdirs.user_cache_dir("fegear", appauthor=False))


def _tag(root: Path) -> None:
    tag = root / CACHE_TAG
    if not tag.exists():
        try:
            atomic_write(tag, lambda p: p.write_text(_TAG_TEXT, encoding="utf-8"))
        except OSError as exc:  # a read-only cache still serves hits
            log.warning("cannot write %s: %s", tag, exc)


def cache_dir(kind: str) -> Path:
    """The folder holding artefacts of one kind (created, with the root's tag, if missing)."""
    if not _KIND.match(kind):
        raise InputError("kind", kind, "a cache kind of lower-case letters, digits and '_'")
    root = cache_root()
    path = root / kind
    path.mkdir(parents=True, exist_ok=True)
    _tag(root)
    return path


def _canonical(obj: object) -> object:
    if isinstance(obj, Mapping):
        return {str(k): _canonical(v) for k, v in sorted(obj.items(), key=lambda kv: str(kv[0]))}
    if isinstance(obj, (list, tuple)):
        return [_canonical(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return {
            "__array__": hashlib.sha256(np.ascontiguousarray(obj).tobytes()).hexdigest(),
            "shape": list(obj.shape),
            "dtype": str(obj.dtype),
        }
    if isinstance(obj, (np.floating, float)):
        return float(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    return obj


def content_hash(params: Mapping[str, object]) -> str:
    """SHA-256 (hex, 20 characters) of a canonical JSON of ``params`` (arrays hashed by bytes)."""
    text = json.dumps(_canonical(params), sort_keys=True, separators=(",", ":"), default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:20]


# --------------------------------------------------------------------------------------------
# What a run read and built
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CacheUse:
    """The cache lookups of a piece of work (:func:`record_cache_use`).

    Attributes
    ----------
    root
        The cache root they went to.
    hits
        ``{kind: artefacts read from the cache}``.
    built
        ``{kind: artefacts built and written to the cache}``.
    """

    root: Path
    hits: Mapping[str, int]
    built: Mapping[str, int]

    @property
    def warm(self) -> bool:
        """Everything came from the cache (at least one hit, nothing built)."""
        return bool(self.hits) and not self.built

    def as_dict(self) -> dict[str, object]:
        """JSON-ready (``summary.json``: ``cache``)."""
        return {"folder": str(self.root), "hits": dict(self.hits), "built": dict(self.built)}


_RECORDERS: list[tuple[Counter, Counter]] = []


@contextlib.contextmanager
def record_cache_use() -> Iterator[Callable[[], CacheUse]]:
    """Count the cache lookups made in this process inside the ``with`` block.

    Yields a function returning the :class:`CacheUse` so far (call it after the block for the
    whole of it). Lookups in worker processes are not seen (the artefacts of a run are looked up
    in the main process: meshes, operators, TCA; the workers solve positions).
    """
    hits: Counter = Counter()
    built: Counter = Counter()
    entry = (hits, built)
    _RECORDERS.append(entry)
    root = cache_root()
    try:
        yield lambda: CacheUse(root, dict(sorted(hits.items())), dict(sorted(built.items())))
    finally:
        _RECORDERS.remove(entry)


def _count(kind: str, hit: bool) -> None:
    for hits, built in _RECORDERS:
        (hits if hit else built)[kind] += 1


def cached_file(
    kind: str, params: Mapping[str, object], suffix: str, build: Callable[[Path], None]
) -> tuple[Path, bool]:
    """Return the cached artefact for ``params``, building it with ``build(tmp_path)`` if absent.

    Parameters
    ----------
    kind
        Sub-folder, e.g. ``"mesh"`` or ``"compliance"``.
    params
        Everything the artefact depends on.
    suffix
        File suffix including the dot, e.g. ``".msh"``.
    build
        Writes the artefact to the path it is given (a temporary file in the cache folder).

    Returns
    -------
    (path, hit)
        The artefact path and whether it came from the cache.
    """
    folder = cache_dir(kind)
    key = content_hash(params)
    path = folder / f"{key}{suffix}"
    if path.exists():
        log.info("cache hit %s/%s", kind, path.name)
        _count(kind, True)
        return path, True
    atomic_write(path, build)
    log.info("cache write %s/%s", kind, path.name)
    _count(kind, False)
    return path, False


# --------------------------------------------------------------------------------------------
# fegear cache info / clear
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class KindInfo:
    """One kind of artefact in the cache.

    Attributes
    ----------
    kind
        Folder name (``"mesh"``, ``"compliance"``, ``"tca"``, …).
    files
        Number of artefacts.
    bytes
        Their total size (bytes).
    """

    kind: str
    files: int
    bytes: int


@dataclass(frozen=True)
class CacheInfo:
    """Where the cache is and what it holds (:func:`cache_info`).

    Attributes
    ----------
    root
        The cache root.
    source
        ``"FEGEAR_CACHE"`` (set in the environment) or ``"platform"`` (the per-user default).
    exists
        The root exists.
    is_cache
        It is a fegear cache folder (:func:`is_cache_folder`).
    kinds
        One :class:`KindInfo` per kind folder, by name.
    """

    root: Path
    source: str
    exists: bool
    is_cache: bool
    kinds: tuple[KindInfo, ...]

    @property
    def files(self) -> int:
        """Artefacts in all kinds."""
        return sum(k.files for k in self.kinds)

    @property
    def bytes(self) -> int:
        """Their total size (bytes)."""
        return sum(k.bytes for k in self.kinds)


def _artefacts(folder: Path) -> list[Path]:
    return [p for p in folder.iterdir() if p.is_file() and _ARTEFACT.match(p.name)]


def _kind_folders(root: Path) -> list[Path]:
    return sorted(p for p in root.iterdir() if p.is_dir() and _KIND.match(p.name))


def is_cache_folder(root: Path) -> bool:
    """Whether ``root`` is a fegear cache: it holds the fegear ``CACHEDIR.TAG``, or (a cache of an
    older fegear, made before the tag) every entry is a kind folder holding only content-hash
    artefacts and at least one such folder exists."""
    root = Path(root)
    if not root.is_dir():
        return False
    tag = root / CACHE_TAG
    if tag.is_file():
        try:
            text = tag.read_text(encoding="utf-8", errors="replace")
        except OSError:
            return False
        return text.startswith(_SIGNATURE) and "fegear" in text
    entries = list(root.iterdir())
    if not entries:
        return False
    for p in entries:
        if not (p.is_dir() and _KIND.match(p.name)):
            return False
        if any(not (q.is_file() and _ARTEFACT.match(q.name)) for q in p.iterdir()):
            return False
    return True


def cache_info() -> CacheInfo:
    """The cache root, where it comes from, and the files and bytes of each kind."""
    root = cache_root()
    source = "FEGEAR_CACHE" if os.environ.get("FEGEAR_CACHE", "").strip() else "platform"
    if not root.is_dir():
        return CacheInfo(root, source, False, False, ())
    kinds = []
    for folder in _kind_folders(root):
        files = _artefacts(folder)
        kinds.append(KindInfo(folder.name, len(files), sum(f.stat().st_size for f in files)))
    return CacheInfo(root, source, True, is_cache_folder(root), tuple(kinds))


def clear_cache(kind: str | None = None) -> CacheInfo:
    """Delete the cached artefacts (of one ``kind``, or all); returns what was deleted.

    Only content-hash artefacts inside kind folders are deleted (and a kind folder left empty);
    anything else in the root stays.

    Raises
    ------
    InputError
        The root is not a fegear cache folder (:func:`is_cache_folder`; nothing is deleted), or
        ``kind`` is not a kind folder of the cache.
    """
    info = cache_info()
    if not info.exists:
        return CacheInfo(info.root, info.source, False, False, ())
    if not info.is_cache:
        raise InputError(
            "cache folder",
            str(info.root),
            f"a fegear cache folder (with fegear's {CACHE_TAG}); nothing was deleted",
            "check FEGEAR_CACHE" if info.source == "FEGEAR_CACHE" else "",
        )
    names = [k.kind for k in info.kinds]
    if kind is not None and kind not in names:
        raise InputError("--kind", kind, f"one of the kinds in the cache {names}")
    gone = []
    for k in info.kinds:
        if kind is not None and k.kind != kind:
            continue
        folder = info.root / k.kind
        n = size = 0
        for f in _artefacts(folder):
            size += f.stat().st_size
            f.unlink()
            n += 1
        if not any(folder.iterdir()):
            shutil.rmtree(folder, ignore_errors=True)
        gone.append(KindInfo(k.kind, n, size))
        log.info("cache clear %s: %d files, %d bytes", k.kind, n, size)
    return CacheInfo(info.root, info.source, True, True, tuple(gone))
