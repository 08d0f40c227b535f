"""Content-hash cache of expensive artefacts (meshes, compliance operators, TCA, …).

**One key rule.** An artefact is stored under ``<cache root>/<kind>/<key>.<suffix>``; the key
(:func:`artefact_key`) is the SHA-256 of a canonical JSON (:func:`content_hash`) of

- ``kind``: the kind of artefact (the folder);
- ``params``: the content it is made from (geometry, mesh parameters, material, boundary
  conditions, options, …), canonicalised by :func:`canonical`, which refuses any object it does
  not know instead of falling back on its ``repr``;
- ``code``: the code version of its producer, :func:`code_hash` of the source files of the
  fegear packages and modules that produce the kind (:data:`PRODUCERS`);
- ``deps``: the versions of the third-party distributions that produce it
  (:func:`dependency_versions`, e.g. gmsh for the meshes).

A change of any of them is a new key, so nothing is ever invalidated by hand (no version strings
to bump). Every kind declares its producer in :data:`PRODUCERS`; a kind without one is refused.

**No pickles.** An artefact is one file written by its producer (:func:`cached_file`: ``.npy``,
``.npz`` loaded without pickles, ``.msh``, ``.json``), or a *record* (:func:`cached_record`): data
files plus a JSON document (``<key>.json``) that is written last and lists them.

**Atomic writes.** Every file is written to a temporary name in the same folder and renamed into
place (:func:`fegear.store.files.atomic_write`), so an interrupted run never leaves a half-written
file; a record is trusted only when its JSON exists and every data file it lists is there, so an
entry whose writing was cut short is a miss, rebuilt by the next run.

The root (:func:`cache_root`) is ``$FEGEAR_CACHE`` if set, else the per-user cache folder of the
platform (``platformdirs.user_cache_dir("fegear")``: ``~/.cache/fegear`` on Linux,
``~/Library/Caches/fegear`` on macOS, ``%LOCALAPPDATA%\\fegear\\Cache`` on Windows), so runs from
any working directory share one cache.

The root holds a ``CACHEDIR.TAG`` (the Cache Directory Tagging convention: backup tools skip the
folder) that also marks it as a fegear cache: :func:`clear_cache` refuses to delete anything in a
folder without it (a folder of an older fegear, made before the tag, is recognised by its layout:
only kind folders of content-hash files).

Every lookup is counted (:func:`record_cache_use`), so a caller can tell a warm run from a cold
one by what it read, not by its timing.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import importlib.metadata
import json
import logging
import math
import os
import re
import shutil
from collections import Counter
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import NamedTuple, TypeVar

import numpy as np

from fegear.errors import InputError
from fegear.store.checksum import file_checksum
from fegear.store.files import atomic_write, check_writable_folder
from fegear.store.limit import ENV_LIMIT, cache_limit, evict, stored_entries

__all__ = [
    "CACHE_TAG",
    "PRODUCERS",
    "CacheInfo",
    "CacheUse",
    "Entry",
    "KindInfo",
    "Producer",
    "artefact_key",
    "cache_dir",
    "cache_info",
    "cache_root",
    "cached_file",
    "count_lookups",
    "Lookups",
    "recorded",
    "cached_record",
    "find_record",
    "canonical",
    "check_cache_root",
    "RECORD_SUFFIX",
    "clear_cache",
    "code_hash",
    "content_hash",
    "dependency_versions",
    "is_cache_folder",
    "record_cache_use",
]

log = logging.getLogger(__name__)
T = TypeVar("T")

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
#: (``.<20 hex>.<random>.<suffix>``, :func:`fegear.store.files.atomic_write`).
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


# --------------------------------------------------------------------------------------------
# The key rule: content + code version + dependency versions
# --------------------------------------------------------------------------------------------


def canonical(obj: object) -> object:
    """``obj`` as plain JSON data, the same for equal content (the hashed form of a key).

    Known: ``None``, ``bool``, ``int``, ``float``, ``str``; numpy scalars (as the Python number);
    lists and tuples (as lists); mappings with ``str`` keys (sorted by key); numpy arrays of
    numbers or booleans (their dtype, shape and the SHA-256 of their bytes); dataclass instances
    (their class name and the fields that take part in their equality, ``compare=True``).

    Raises
    ------
    TypeError
        Anything else (naming its type and where it sits): an object is never hashed by its
        ``repr``, which may be partial (numpy abbreviates long arrays) or hold an address.
    """
    return _canonical(obj, "params")


def _canonical(obj: object, where: str) -> object:
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if type(obj) in (int, float):
        return obj
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        return float(obj)
    if isinstance(obj, Mapping):
        out = {}
        for k, v in obj.items():
            if not isinstance(k, str):
                raise TypeError(
                    f"cache key: {where} has a key of type {type(k).__qualname__} ({k!r}); "
                    "only str keys are hashed"
                )
            out[k] = _canonical(v, f"{where}[{k!r}]")
        return dict(sorted(out.items()))
    if isinstance(obj, (list, tuple)):
        return [_canonical(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind not in "biuf":
            raise TypeError(
                f"cache key: {where} is an array of dtype {obj.dtype}; only arrays of numbers "
                "or booleans are hashed"
            )
        return {
            "__array__": hashlib.sha256(np.ascontiguousarray(obj).tobytes()).hexdigest(),
            "shape": list(obj.shape),
            "dtype": str(obj.dtype),
        }
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        fields = {
            f.name: _canonical(getattr(obj, f.name), f"{where}.{f.name}")
            for f in dataclasses.fields(obj)
            if f.compare
        }
        return {"__dataclass__": type(obj).__qualname__, **fields}
    raise TypeError(
        f"cache key: {where} is a {type(obj).__module__}.{type(obj).__qualname__}, which the "
        "cache cannot hash (numbers, str, bool, None, lists, tuples, str-keyed mappings, numpy "
        "arrays and scalars, dataclasses)"
    )


def content_hash(params: Mapping[str, object]) -> str:
    """SHA-256 (hex, 20 characters) of the canonical JSON (:func:`canonical`) of ``params``.

    Raises
    ------
    TypeError
        ``params`` holds an object :func:`canonical` does not know.
    """
    text = json.dumps(_canonical(params, "params"), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:20]


#: The folder of the fegear package (the source files :func:`code_hash` reads).
_FEGEAR = Path(__file__).resolve().parents[1]


def _sources(module: str) -> list[Path]:
    """The source files of a fegear package (every ``.py`` below it) or module."""
    parts = module.split(".")
    if parts[0] != "fegear" or len(parts) < 2 or not all(p.isidentifier() for p in parts):
        raise ValueError(f"code_hash: {module!r} is not a fegear package or module")
    base = _FEGEAR.joinpath(*parts[1:])
    if base.is_dir():
        return sorted(base.rglob("*.py"))
    if base.with_suffix(".py").is_file():
        return [base.with_suffix(".py")]
    raise ValueError(f"code_hash: no package or module {module} in {_FEGEAR}")


@functools.cache
def _code_hash(modules: tuple[str, ...]) -> str:
    files = sorted({f for m in modules for f in _sources(m)})
    h = hashlib.sha256()
    for f in files:
        h.update(f.relative_to(_FEGEAR).as_posix().encode())
        h.update(b"\0")
        h.update(f.read_bytes())
        h.update(b"\0")
    return h.hexdigest()[:20]


def code_hash(*modules: str) -> str:
    """SHA-256 (hex, 20 characters) of the source files of the fegear packages and modules
    ``modules`` (``"fegear.mesh"``: every ``.py`` below ``fegear/mesh``;
    ``"fegear.mechanics.hertz_closed_form"``:
    ``fegear/mechanics/hertz_closed_form.py``), read once per process. The code version of an
    artefact: any change of the code that produces it changes its key."""
    return _code_hash(tuple(sorted(set(modules))))


@functools.cache
def _version(dist: str) -> str | None:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return None


def dependency_versions(*dists: str) -> dict[str, str | None]:
    """``{distribution: installed version}`` (None: not installed) of third-party packages, by
    their distribution names (``"gmsh"``, ``"scikit-fem"``), read once per process."""
    return {d: _version(d) for d in sorted(set(dists))}


@dataclass(frozen=True)
class Producer:
    """What produces a kind of artefact: its key holds the code version of ``code`` and the
    versions of ``deps``.

    Attributes
    ----------
    code
        fegear packages and modules whose source produces the artefact (:func:`code_hash`).
    deps
        Third-party distributions whose code produces it (:func:`dependency_versions`).
    """

    code: tuple[str, ...]
    deps: tuple[str, ...] = ()


_MESH_CODE = ("fegear.mesh", "fegear.geometry")
_MESH_DEPS = ("gmsh", "meshio", "numpy", "scipy")
_FE_DEPS = (*_MESH_DEPS, "scikit-fem")
_TCA_CODE = ("fegear.tca", "fegear.geometry", "fegear.mechanics.hertz_closed_form")
_TCA = Producer(_TCA_CODE, ("numpy", "scipy"))
_CYCLE_CODE = (
    *_MESH_CODE, "fegear.fem", "fegear.linalg", "fegear.mechanics", "fegear.tca", "fegear.ltca",
    "fegear.store.records",
)  # fmt: skip

#: The producer of every kind of artefact (a kind not listed here cannot be cached).
PRODUCERS: Mapping[str, Producer] = MappingProxyType(
    {
        # sector meshes (fegear.mesh.sector) and the Hertz scene's bodies
        # (fegear.mesh.hertz_scene_bodies)
        "mesh": Producer(_MESH_CODE, _MESH_DEPS),
        # the flank operators (fegear.mechanics.compliance.candidate_operator) of a meshed body
        "compliance": Producer(
            (*_MESH_CODE, "fegear.fem", "fegear.linalg", "fegear.mechanics.compliance"), _FE_DEPS
        ),
        # the vertex displacements of a contact sector under a run's cell loads (for the VTK
        # files; fegear.pipeline.fields)
        "fields": Producer(
            (*_MESH_CODE, "fegear.fem", "fegear.linalg", "fegear.pipeline.fields"), _FE_DEPS
        ),
        # the tetrahedra below a flank (fegear.ltca.model)
        "layer": Producer((*_MESH_CODE, "fegear.ltca.model"), _FE_DEPS),
        # the unloaded TCA (fegear.tca.cached), its reference phase, its path of contact and its
        # hand-over check
        "tca": _TCA,
        "phase": _TCA,
        "contact_path": _TCA,
        "handover": _TCA,
        # the ease-off of a run's pair on its grid (fegear.tca.ease_off_pair)
        "ease_off": _TCA,
        # a loaded cycle, every position solved (fegear.ltca.cached), and the displacement
        # fields of a run of it (fegear.pipeline.fields): everything they are computed with
        "cycle": Producer(_CYCLE_CODE, (*_FE_DEPS, "threadpoolctl")),
        "member_fields": Producer(
            (*_CYCLE_CODE, "fegear.pipeline.fields"), (*_FE_DEPS, "threadpoolctl")
        ),
        # a bevel or hypoid flank's table (fegear.tca.flank_tables)
        "flank_table": Producer(("fegear.geometry",), ("numpy", "scipy")),
        # the synthesized spiral bevel pair (fegear.pipeline.pair)
        "bevel_pair": Producer(("fegear.geometry",), ("numpy", "scipy")),
        # the face gear's undercut/pointing limits and fillet-limit tables (fegear.pipeline.pair)
        "face_gear_limits": Producer(("fegear.geometry",), ("numpy", "scipy")),
        # the PNG pictures of a loaded run (fegear.output.picture_cache), keyed on its cycle
        # and its summary: a run read back from the cache copies them instead of drawing them
        "pictures": Producer(("fegear.output", "fegear.results"), ("matplotlib", "numpy")),
    }
)


def _producer(kind: str, producer: Producer | None) -> Producer:
    if producer is not None:
        return producer
    try:
        return PRODUCERS[kind]
    except KeyError:
        raise ValueError(
            f"cache kind {kind!r} has no producer (fegear.store.cache.PRODUCERS: "
            f"{sorted(PRODUCERS)})"
        ) from None


def artefact_key(kind: str, params: Mapping[str, object], producer: Producer | None = None) -> str:
    """The key of an artefact: :func:`content_hash` of ``kind``, ``params``, the code hash of
    its producer's fegear sources and the versions of its third-party dependencies.

    Parameters
    ----------
    kind
        Kind of artefact (its folder).
    params
        The content it is made from.
    producer
        Its producer; default the kind's in :data:`PRODUCERS`.

    Raises
    ------
    ValueError
        ``kind`` has no producer.
    TypeError
        ``params`` holds an object :func:`canonical` does not know.
    """
    p = _producer(kind, producer)
    return content_hash(
        {
            "kind": kind,
            "params": params,
            "code": code_hash(*p.code),
            "deps": dependency_versions(*p.deps),
        }
    )


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

    def joined(self, other: CacheUse) -> CacheUse:
        """The lookups of this and ``other`` together (counts added per kind; this root)."""
        hits, built = Counter(self.hits), Counter(self.built)
        hits.update(other.hits)
        built.update(other.built)
        return CacheUse(self.root, dict(sorted(hits.items())), dict(sorted(built.items())))


@dataclass
class _Recorder:
    """What one :func:`record_cache_use` block has looked up: counts per kind, and the entries
    it used (``(kind, key)``: kept by the size cap while the block runs)."""

    hits: Counter = dataclasses.field(default_factory=Counter)
    built: Counter = dataclasses.field(default_factory=Counter)
    pinned: set[tuple[str, str]] = dataclasses.field(default_factory=set)


_RECORDERS: list[_Recorder] = []


@contextlib.contextmanager
def record_cache_use() -> Iterator[Callable[[], CacheUse]]:
    """Count the cache lookups made in this process inside the ``with`` block.

    Yields a function returning the :class:`CacheUse` so far (call it after the block for the
    whole of it). Lookups in worker processes are not seen unless sent back (the artefacts of a
    run are looked up in the main process: operators, TCA; the workers solve positions; the
    sector mesh made in a forked process comes back with its lookups: :func:`recorded`,
    :func:`count_lookups`). The entries used
    inside the block are never evicted by the cache's size cap while it runs (a run's operators
    stay however small the cap).
    """
    rec = _Recorder()
    _RECORDERS.append(rec)
    root = cache_root()
    try:
        yield lambda: CacheUse(
            root, dict(sorted(rec.hits.items())), dict(sorted(rec.built.items()))
        )
    finally:
        _drop(rec)


def _drop(rec: _Recorder) -> None:
    """Remove ``rec`` itself from :data:`_RECORDERS` (not a recorder equal to it: two blocks
    that have counted the same compare equal)."""
    for i, r in enumerate(_RECORDERS):
        if r is rec:
            del _RECORDERS[i]
            return


class Lookups(NamedTuple):
    """The cache lookups one piece of work made (:func:`recorded`), to be counted by the
    process it was done for (:func:`count_lookups`): ``pid`` of the process that made them,
    ``{kind: n}`` read and built, and the ``(kind, key)`` entries used."""

    pid: int
    hits: dict[str, int]
    built: dict[str, int]
    used: frozenset[tuple[str, str]]


def recorded(work: Callable[[], T]) -> tuple[T, Lookups]:
    """``(work(), lookups)``: the value and the cache lookups made while it ran here."""
    rec = _Recorder()
    _RECORDERS.append(rec)
    try:
        value = work()
    finally:
        _drop(rec)
    return value, Lookups(os.getpid(), dict(rec.hits), dict(rec.built), frozenset(rec.pinned))


def count_lookups(lookups: Lookups) -> None:
    """Count in this process's :func:`record_cache_use` blocks the lookups a forked process made
    for it (:func:`recorded` there; its entries are then kept by the size cap as this
    process's own). Lookups made in this process were counted when made: nothing to add."""
    if lookups.pid == os.getpid():
        return
    for rec in _RECORDERS:
        rec.hits.update(lookups.hits)
        rec.built.update(lookups.built)
        rec.pinned.update(lookups.used)


def entries_stamp(used: frozenset[tuple[str, str]]) -> tuple:
    """The identity of the files of the cache entries ``used`` (``(kind, key)``, as
    :attr:`Lookups.used`): the cache root, and for each file of each entry its name, inode and
    size, and for a data file its modification time too (a record's is its last use). Equal
    stamps: the entries are the very files they were (not deleted, rebuilt, truncated or
    rewritten since)."""
    root = cache_root()
    stamp = []
    for kind, key in sorted(used):
        files = []
        for p in sorted((root / kind).glob(f"{key}.*")):
            try:
                st = p.stat()
            except OSError:
                continue
            record = p.name == f"{key}{RECORD_SUFFIX}"
            files.append((p.name, st.st_ino, st.st_size, None if record else st.st_mtime_ns))
        stamp.append((kind, key, tuple(files)))
    return (str(root), tuple(stamp))


def reuse_entries(lookups: Lookups, stamp: tuple) -> bool:
    """Count a value made from cache entries and kept in the process as read from them again:
    when the entries are still the files they were (:func:`entries_stamp` equal to ``stamp``),
    each is marked used (its last use, and kept by the size cap while the work runs) and the
    lookups that made the value (``lookups``: hits and builds) count as hits of their kinds;
    True. False when anything changed (the value must be made again from the cache)."""
    if entries_stamp(lookups.used) != stamp:
        return False
    for kind, key in lookups.used:
        _used(cache_dir(kind), key)
    for kind, n in (Counter(lookups.hits) + Counter(lookups.built)).items():
        for _ in range(n):
            _count(kind, True)
    return True


def _count(kind: str, hit: bool) -> None:
    for rec in _RECORDERS:
        (rec.hits if hit else rec.built)[kind] += 1


def cached_file(
    kind: str,
    params: Mapping[str, object],
    suffix: str,
    build: Callable[[Path], None],
    producer: Producer | None = None,
) -> tuple[Path, bool]:
    """Return the cached artefact for ``params``, building it with ``build(tmp_path)`` if absent.

    An entry of one data file (:func:`cached_record` with an empty record): verified when read,
    counted, and evicted as a whole.

    Parameters
    ----------
    kind
        Sub-folder, e.g. ``"mesh"`` or ``"compliance"``.
    params
        The content the artefact is made from (:func:`artefact_key`).
    suffix
        File suffix including the dot, e.g. ``".msh"``.
    build
        Writes the artefact to the path it is given (a temporary file in the cache folder,
        renamed into place once ``build`` returns).
    producer
        The kind's producer; default its entry in :data:`PRODUCERS`.

    Returns
    -------
    (path, hit)
        The artefact path and whether it came from the cache.
    """

    data = ".data" + suffix if suffix == RECORD_SUFFIX else suffix  # the record is <key>.json

    def write(entry: Entry) -> dict[str, object]:
        entry.write(data, build)
        return {}

    entry, _, hit = cached_record(kind, params, write, producer)
    return entry.path(data), hit


#: Suffix of a record's JSON document.
RECORD_SUFFIX = ".json"
_RECORD_FORMAT = "fegear.cache_record/2"
_SUFFIX = re.compile(r"^(\.[A-Za-z0-9_]+)+$")


class Entry:
    """The files of one record (:func:`cached_record`): ``<key><suffix>`` in the kind's folder.

    Attributes
    ----------
    folder
        The kind's folder.
    key
        The artefact key.
    """

    def __init__(self, folder: Path, key: str, files: tuple[str, ...] = ()) -> None:
        self.folder = folder
        self.key = key
        self._files = list(files)

    def path(self, suffix: str) -> Path:
        """The data file ``<key><suffix>`` (``suffix`` e.g. ``".npz"``, ``".msh"``)."""
        if not _SUFFIX.match(suffix) or suffix == RECORD_SUFFIX:
            raise ValueError(f"data file suffix {suffix!r}: '.name' other than {RECORD_SUFFIX!r}")
        return self.folder / f"{self.key}{suffix}"

    @property
    def record_path(self) -> Path:
        """The JSON document that makes the entry valid (written last)."""
        return self.folder / f"{self.key}{RECORD_SUFFIX}"

    @property
    def files(self) -> tuple[str, ...]:
        """Suffixes of the data files written (a new entry) or listed by the record (a hit)."""
        return tuple(self._files)

    def write(self, suffix: str, write: Callable[[Path], None]) -> Path:
        """Write the data file ``<key><suffix>`` atomically with ``write(tmp_path)``."""
        path = atomic_write(self.path(suffix), write)
        if suffix not in self._files:
            self._files.append(suffix)
        return path


def _read_record(folder: Path, key: str) -> tuple[dict, list[str]] | None:
    """``(record, data file suffixes)`` of a complete, intact entry, else None.

    None for no JSON document (a miss, or an entry whose writing was cut short); a data file it
    lists that is gone, of another size, or whose checksum (:func:`~fegear.store.checksum.
    file_checksum`) is not the one written makes the entry damaged: a warning names it, its
    files are deleted and it is a miss (built again)."""
    path = folder / f"{key}{RECORD_SUFFIX}"
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        return _damaged(folder, key, f"its record cannot be read ({exc})")
    if not isinstance(doc, dict) or doc.get("format") != _RECORD_FORMAT:
        return None  # an entry of another fegear: rebuilt under the same key
    files, record, sizes, sums = (doc.get(k) for k in ("files", "record", "sizes", "sums"))
    if not (isinstance(record, dict) and isinstance(files, list) and isinstance(sizes, dict)
            and isinstance(sums, dict)):  # fmt: skip
        return _damaged(folder, key, "its record is incomplete")
    for f in files:
        if not (isinstance(f, str) and _SUFFIX.match(f)):
            return _damaged(folder, key, f"its record lists {f!r}")
        data = folder / f"{key}{f}"
        try:
            size = data.stat().st_size
        except OSError:
            return _damaged(folder, key, f"{data.name} is missing")
        if size != sizes.get(f):
            return _damaged(folder, key, f"{data.name} has {size} bytes, {sizes.get(f)} written")
        if file_checksum(data) != sums.get(f):
            return _damaged(folder, key, f"{data.name} does not have its checksum")
    return record, files


def _damaged(folder: Path, key: str, why: str) -> None:
    """Delete a damaged entry (record first), with a warning naming it; returns None."""
    log.warning(
        "cache entry %s/%s is damaged (%s): deleted, building it again (the cache is %s; "
        "`fegear cache clear` empties it)",
        folder.name,
        key,
        why,
        folder.parent,
    )
    for p in sorted(folder.glob(f"{key}.*"), key=lambda p: p.suffix != RECORD_SUFFIX):
        with contextlib.suppress(OSError):
            p.unlink()
    return None


def _used(folder: Path, key: str) -> None:
    """Mark an entry used now (its record's mtime: :mod:`fegear.store.limit`) and by the
    pieces of work recording their cache use (:func:`record_cache_use`: never evicted while
    they run)."""
    for rec in _RECORDERS:
        rec.pinned.add((folder.name, key))
    with contextlib.suppress(OSError):
        os.utime(folder / f"{key}{RECORD_SUFFIX}")


def _enforce_limit(written: tuple[str, str]) -> None:
    """Evict the least recently used entries beyond the cap (:mod:`fegear.store.limit`), never
    the entry just ``written`` nor one a running piece of work has used."""
    root, cap = cache_root(), cache_limit()
    if not math.isfinite(cap):
        return
    keep = {written}.union(*(rec.pinned for rec in _RECORDERS))
    gone, total = evict(root, cap, keep)
    if gone:
        log.info(
            "cache: %d least recently used entries evicted (%s) to stay within %s",
            len(gone),
            _gb(sum(e.bytes for e in gone)),
            _gb(cap),
        )
    if total > cap:
        log.warning(
            "the cache holds %s, above its cap of %s (%s): this run uses all of it; raise the cap "
            "or clear the cache",
            _gb(total),
            _gb(cap),
            ENV_LIMIT,
        )


def _gb(n: float) -> str:
    return f"{n / 1e9:.2f} GB"


def find_record(
    kind: str, params: Mapping[str, object], producer: Producer | None = None
) -> tuple[Entry, dict] | None:
    """``(entry, record)`` of ``params`` if the cache holds it complete and intact (a hit:
    counted and marked used, as :func:`cached_record` does), else None (nothing counted).

    For work that looks first and builds later, elsewhere (pictures drawn in a second process,
    :mod:`fegear.output.picture_cache`): the entry is then written by :func:`cached_record`.

    Raises
    ------
    ValueError
        ``kind`` has no producer.
    """
    return _lookup(kind, params, producer)[1]


def _lookup(
    kind: str, params: Mapping[str, object], producer: Producer | None
) -> tuple[Entry, tuple[Entry, dict] | None]:
    """``(entry, found)``: the entry of ``params`` (its key computed once) and, for a hit, what
    :func:`find_record` returns (the hit counted and marked used), else None."""
    key = artefact_key(kind, params, producer)  # a kind without a producer: refused first
    folder = cache_dir(kind)
    found = _read_record(folder, key)
    if found is None:
        return Entry(folder, key), None
    entry = Entry(folder, key, tuple(found[1]))
    log.info("cache hit %s/%s", kind, entry.record_path.name)
    _used(folder, key)
    _count(kind, True)
    return entry, (entry, found[0])


def cached_record(
    kind: str,
    params: Mapping[str, object],
    build: Callable[[Entry], Mapping[str, object]],
    producer: Producer | None = None,
) -> tuple[Entry, dict, bool]:
    """Return the cached record for ``params``, building it with ``build(entry)`` if absent.

    A record is data files (written by ``build`` through :meth:`Entry.write`, each atomically)
    and a JSON document ``<key>.json`` holding what ``build`` returns, the list of the data
    files, their sizes and checksums (:func:`~fegear.store.checksum.file_checksum`), written
    last: an entry is trusted only when that document exists and every file it lists is there
    with its size and checksum, so an entry cut short (by an error or a kill) is a miss and a
    damaged one (truncated, overwritten) is deleted with a warning and built again. Every use
    marks the entry (its last use, for the size cap: :mod:`fegear.store.limit`); after a new
    entry the least recently used ones beyond the cap are evicted.

    Parameters
    ----------
    kind
        Sub-folder, e.g. ``"tca"``.
    params
        The content the artefact is made from (:func:`artefact_key`).
    build
        Writes the data files of the entry and returns its record: plain JSON data (floats are
        written by their ``repr``, so they read back bit for bit; NaN and infinities allowed).
    producer
        The kind's producer; default its entry in :data:`PRODUCERS`.

    Returns
    -------
    (entry, record, hit)
        The entry (:meth:`Entry.path` of its data files), the record, and whether it came from
        the cache.
    """
    entry, found = _lookup(kind, params, producer)
    if found is not None:
        return found[0], found[1], True
    key, folder = entry.key, entry.folder
    record = dict(build(entry))  # the data files, each written atomically
    paths = {f: entry.path(f) for f in entry.files}
    doc = {
        "format": _RECORD_FORMAT,
        "files": list(entry.files),
        "sizes": {f: p.stat().st_size for f, p in paths.items()},
        "sums": {f: file_checksum(p) for f, p in paths.items()},
        "record": record,
    }
    text = json.dumps(doc, separators=(",", ":"))
    atomic_write(entry.record_path, lambda p: p.write_text(text, encoding="utf-8"))
    log.info("cache write %s/%s", kind, entry.record_path.name)
    _used(folder, key)
    _count(kind, False)
    _enforce_limit((kind, key))
    return entry, json.loads(text)["record"], False  # as a hit reads it (tuples become lists)


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
        Number of artefact files (data files and records).
    bytes
        Their total size (bytes).
    entries
        Complete entries (a record and its data files).
    """

    kind: str
    files: int
    bytes: int
    entries: int = 0


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
    limit
        The size cap in bytes (``inf``: none; :func:`fegear.store.limit.cache_limit`).
    entries
        Complete entries (artefacts with their record) in all kinds.
    """

    root: Path
    source: str
    exists: bool
    is_cache: bool
    kinds: tuple[KindInfo, ...]
    limit: float = math.inf
    entries: int = 0

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
    """The cache root, where it comes from, its size cap, and the files and bytes of each
    kind."""
    root = cache_root()
    source = "FEGEAR_CACHE" if os.environ.get("FEGEAR_CACHE", "").strip() else "platform"
    limit = cache_limit()
    if not root.is_dir():
        return CacheInfo(root, source, False, False, (), limit)
    stored = Counter(e.kind for e in stored_entries(root, RECORD_SUFFIX))
    kinds = []
    for folder in _kind_folders(root):
        files = _artefacts(folder)
        size = sum(f.stat().st_size for f in files)
        kinds.append(KindInfo(folder.name, len(files), size, stored[folder.name]))
    entries = sum(stored.values())
    return CacheInfo(root, source, True, is_cache_folder(root), tuple(kinds), limit, entries)


def check_cache_root() -> Path:
    """Refuse, before any work, a cache root fegear cannot use: not a folder, not writable (a
    read-only mount), or a non-empty folder that is not a fegear cache (the size cap deletes
    files in it). The message names ``FEGEAR_CACHE`` when it comes from there. Creates the
    root (with its tag) when it is missing; returns it.

    Raises
    ------
    InputError
        The root is unusable (the CLI's exit code 2).
    """
    root = cache_root()
    field = "FEGEAR_CACHE" if os.environ.get("FEGEAR_CACHE", "").strip() else "cache folder"
    check_writable_folder(root, field)
    if root.is_dir() and any(root.iterdir()) and not is_cache_folder(root):
        raise InputError(
            field,
            str(root),
            "an empty folder or a fegear cache (the cache deletes its least recently used "
            "files): this folder holds other files",
        )
    cap = cache_limit()  # a bad FEGEAR_CACHE_LIMIT is refused here too
    try:
        root.mkdir(parents=True, exist_ok=True)
        _tag(root)
    except OSError as exc:
        raise InputError(field, str(root), "a folder fegear can write to", str(exc)) from exc
    log.debug("cache %s, cap %s", root, _gb(cap))
    return root


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
        return CacheInfo(info.root, info.source, False, False, (), info.limit)
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
    return CacheInfo(info.root, info.source, True, True, tuple(gone), info.limit)
