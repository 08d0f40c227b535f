"""Content-hash cache of expensive artefacts (meshes, compliance operators).

An artefact is stored under ``<cache root>/<kind>/<hash>.<suffix>`` where the hash is the SHA-256
of a canonical JSON of everything that determines it (geometry, mesh parameters, material, boundary
conditions, code version of the producer). The root is ``$FEGEAR_CACHE`` if set, else
``meshes/cache`` under the current working directory (git keeps only ``meshes/README.md``).

Files are written to a temporary name in the same folder and renamed into place, so an interrupted
run never leaves a half-written artefact that a later run would trust.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from fegear.io.files import atomic_write

__all__ = ["cache_dir", "content_hash", "cached_file"]

log = logging.getLogger(__name__)


def cache_dir(kind: str) -> Path:
    """The folder holding artefacts of one kind (created if missing)."""
    root = Path(os.environ.get("FEGEAR_CACHE", Path.cwd() / "meshes" / "cache"))
    path = root / kind
    path.mkdir(parents=True, exist_ok=True)
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
        return path, True
    atomic_write(path, build)
    log.info("cache write %s/%s", kind, path.name)
    return path, False
