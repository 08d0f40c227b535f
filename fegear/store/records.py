"""Plain-data records of result objects for the on-disk cache: JSON plus numpy arrays, no pickle.

:func:`to_record` turns a tree of result dataclasses, tuples, lists, ``str``-keyed dicts, numbers,
strings and numpy arrays into JSON data, the arrays set aside in a dict (written with
:func:`save_arrays`); :func:`from_record` builds the same tree back from the JSON data and the
arrays (:func:`load_arrays`). A float is written by its ``repr``, which reads back exactly, and an
array keeps its dtype and shape, so a tree read back is equal to the one written bit for bit.

Only the dataclasses named in the ``classes`` registry of the caller are written or built (by
their class name): a record never names code to run, and a class outside the registry is an
error, not a silent fallback on ``repr``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TypeVar

import numpy as np

from fegear.store.cache import cached_record

T = TypeVar("T")

__all__ = [
    "cached_object",
    "from_record",
    "load_arrays",
    "registry",
    "save_arrays",
    "to_record",
]


def registry(*classes: type) -> dict[str, type]:
    """``{name: class}`` of the dataclasses and named tuples a record may hold (names must be
    unique)."""
    out: dict[str, type] = {}
    for c in classes:
        if not (dataclasses.is_dataclass(c) or _is_namedtuple(c)):
            raise TypeError(f"record classes: {c.__qualname__} is not a dataclass or NamedTuple")
        if out.get(c.__name__, c) is not c:
            raise ValueError(f"record classes: two classes named {c.__name__}")
        out[c.__name__] = c
    return out


def _is_namedtuple(c: type) -> bool:
    return isinstance(c, type) and issubclass(c, tuple) and hasattr(c, "_fields")


def _fields(obj: object) -> tuple[str, ...]:
    if _is_namedtuple(type(obj)):
        return type(obj)._fields  # type: ignore[attr-defined]
    return tuple(f.name for f in dataclasses.fields(obj))  # type: ignore[arg-type]


def to_record(
    obj: object, arrays: dict[str, np.ndarray], key: str, classes: Mapping[str, type]
) -> object:
    """``obj`` as plain JSON data, its arrays put in ``arrays`` under names starting with
    ``key`` (dtype and shape kept); :func:`from_record` gives back an equal object bit for bit.

    Handles ``None``, ``bool``, ``int``, ``float``, ``str``; numpy arrays of numbers or booleans
    and numpy scalars; tuples and lists; dicts with ``str`` keys; instances of the dataclasses and
    named tuples in ``classes`` (:func:`registry`), by their fields.

    Raises
    ------
    TypeError
        Anything else (naming its type and ``key``).
    """
    if obj is None or type(obj) in (bool, int, float, str):
        return obj
    if isinstance(obj, (np.ndarray, np.generic)):
        arr = np.asarray(obj)
        if arr.dtype.kind not in "biuf":
            raise TypeError(f"record: {key} has dtype {arr.dtype} (numbers or booleans only)")
        if key in arrays:
            raise ValueError(f"record: two arrays named {key!r}")
        arrays[key] = arr
        return {"npz": key, "scalar": isinstance(obj, np.generic)}
    cls = type(obj)
    if classes.get(cls.__name__) is cls:
        fields = {
            name: to_record(getattr(obj, name), arrays, f"{key}.{name}", classes)
            for name in _fields(obj)
        }
        return {"dataclass": cls.__name__, "fields": fields}
    if isinstance(obj, tuple):
        return {"tuple": [to_record(v, arrays, f"{key}.{i}", classes) for i, v in enumerate(obj)]}
    if isinstance(obj, list):
        return [to_record(v, arrays, f"{key}.{i}", classes) for i, v in enumerate(obj)]
    if isinstance(obj, dict) and all(isinstance(k, str) for k in obj):
        return {"dict": {k: to_record(v, arrays, f"{key}.{k}", classes) for k, v in obj.items()}}
    raise TypeError(f"record: {key} is a {cls.__module__}.{cls.__qualname__}")


def from_record(doc: object, arrays: Mapping[str, np.ndarray], classes: Mapping[str, type]):
    """The object of :func:`to_record` (``arrays``: its arrays; ``classes``: the same registry).

    Raises
    ------
    ValueError
        ``doc`` is not a record, or names a class outside ``classes``.
    """
    if doc is None or isinstance(doc, (bool, int, float, str)):
        return doc
    if isinstance(doc, list):
        return [from_record(v, arrays, classes) for v in doc]
    if isinstance(doc, dict):
        if "npz" in doc:
            arr = arrays[doc["npz"]]
            return arr[()] if doc["scalar"] else arr
        if "tuple" in doc:
            return tuple(from_record(v, arrays, classes) for v in doc["tuple"])
        if "dict" in doc:
            return {k: from_record(v, arrays, classes) for k, v in doc["dict"].items()}
        if "dataclass" in doc:
            cls = classes.get(doc["dataclass"])
            if cls is None:
                raise ValueError(
                    f"record: class {doc['dataclass']!r} is not one of {sorted(classes)}"
                )
            return cls(**{k: from_record(v, arrays, classes) for k, v in doc["fields"].items()})
    raise ValueError(f"record: not a record: {str(doc)[:80]}")


def save_arrays(path: Path, arrays: dict[str, np.ndarray]) -> dict[str, list]:
    """Write ``arrays`` at ``path`` as an uncompressed ``.npz`` of one flat array per dtype (a
    TCA of 25 positions has ~1000 small arrays: one ``.npz`` member each would take 0.15 s to
    read); returns the index ``{name: [member, offset, shape]}`` that :func:`load_arrays` needs
    (kept in the entry's JSON record)."""
    members: dict[str, str] = {}  # dtype.str -> member name
    parts: dict[str, list[np.ndarray]] = {}
    sizes: dict[str, int] = {}
    index: dict[str, list] = {}
    for name, arr in arrays.items():
        arr = np.asarray(arr)
        if arr.dtype.kind not in "biuf":
            raise TypeError(f"array {name!r}: dtype {arr.dtype} (numbers or booleans only)")
        member = members.setdefault(arr.dtype.str, f"a{len(members)}")
        index[name] = [member, sizes.get(member, 0), list(arr.shape)]
        sizes[member] = sizes.get(member, 0) + arr.size
        parts.setdefault(member, []).append(arr.ravel())
    blobs = {m: np.concatenate(p) for m, p in parts.items()}
    with open(path, "wb") as fh:
        np.savez(fh, **blobs)
    return index


def load_arrays(path: Path, index: dict[str, list]) -> dict[str, np.ndarray]:
    """The arrays of :func:`save_arrays` (``index`` is what it returned), read without pickles:
    each a copy of its slice of the flat arrays, with its dtype and shape."""
    with np.load(path, allow_pickle=False) as z:
        blobs = {m: z[m] for m in z.files}
    out = {}
    for name, (member, offset, shape) in index.items():
        size = int(np.prod(shape, dtype=np.int64))
        out[name] = blobs[member][offset : offset + size].reshape(shape).copy()
    return out


def cached_object(
    kind: str,
    params: Mapping[str, object],
    make: Callable[[], T],
    classes: Mapping[str, type],
    stored: Callable[[T], object] = lambda obj: obj,
    restore: Callable[[object], T] = lambda data: data,  # type: ignore[assignment,return-value]
) -> tuple[T, bool]:
    """``(obj, hit)``: the object of ``params`` from the cache entry of ``kind``
    (:func:`fegear.store.cache.cached_record`), else ``make()``, stored as ``stored(obj)`` (e.g.
    without what must not be kept) in a record of this module: a ``.npz`` of its arrays
    (:func:`save_arrays`) and its JSON data (:func:`to_record` with ``classes``); a hit is
    ``restore`` of what was stored (default: it as it is)."""
    made: list[T] = []

    def build(entry) -> dict[str, object]:
        obj = make()
        made.append(obj)
        arrays: dict[str, np.ndarray] = {}
        doc = to_record(stored(obj), arrays, kind, classes)
        index: dict[str, list] = {}
        entry.write(".npz", lambda p: index.update(save_arrays(p, arrays)))  # data first
        return {"object": doc, "index": index}

    entry, record, hit = cached_record(kind, params, build)
    if not hit:
        return made[0], False
    arrays = load_arrays(entry.path(".npz"), record["index"])
    return restore(from_record(record["object"], arrays, classes)), True
