"""The pictures of a loaded run kept in the artefact cache (kind ``pictures``).

A run read back from the cache (the same case again: its loaded cycle and fields are cache hits,
``docs/ltca/studies.md``) would draw the same PNGs again, which costs more than the rest of its
work together (matplotlib's import and five figures, ~2.5 s on 2 cores, against ~0.5 s for
reading the run back). The pictures are a function of the run's loaded cycle and of what its
titles and curves quote, so they are kept under

* ``cycle``: the key of the loaded cycle (:mod:`fegear.ltca.cached`: the members, the assembly
  with its errors, the torque, the fidelity, the options and the code of the analysis), which
  fixes every cell the bearing pattern paints, and
* ``summary``: the SHA-256 of the run's ``summary.json`` document without what describes the
  run rather than its result (``timings_s``, ``cache``, ``versions``, ``files``, ``mesh``: the
  pictures show no displacement field), which holds the case's name, the curves and the
  headlines the titles quote;

and the code that draws them (``fegear.output``, ``fegear.results``, matplotlib's version:
:data:`fegear.store.cache.PRODUCERS`). A run without a cycle key (``fegear run --recompute``,
``reuse=False``) draws them and keeps nothing. The files copied into the output folder are the
bytes drawn the first time.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from collections.abc import Callable, Sequence
from pathlib import Path

from fegear.pipeline.run import GearRun
from fegear.results.model import GearRunResult
from fegear.results.summary import summary_document
from fegear.store.cache import cached_record, find_record
from fegear.store.files import atomic_write

__all__ = ["KIND", "kept_pictures", "keep_pictures", "picture_params"]

#: The cache kind of the pictures.
KIND = "pictures"

#: Keys of ``summary.json`` the pictures do not depend on.
_NOT_DRAWN = ("timings_s", "cache", "versions", "files", "mesh")


def picture_params(run: GearRun, result: GearRunResult) -> dict[str, str] | None:
    """The cache parameters of the pictures of ``run`` drawn from ``result`` (see the module
    docstring), or None for a run without a cycle key."""
    if not run.cycle_key:
        return None
    doc = summary_document(result)
    for k in _NOT_DRAWN:
        doc.pop(k, None)
    text = json.dumps(doc, sort_keys=True, allow_nan=True, default=str)
    return {"cycle": run.cycle_key, "summary": hashlib.sha256(text.encode()).hexdigest()}


def kept_pictures(out: Path, params: dict[str, str] | None) -> list[Path] | None:
    """The kept pictures of ``params`` copied into ``out`` (each atomically; their paths, in the
    order they were drawn), or None when the cache does not hold them."""
    found = None if params is None else find_record(KIND, params)
    if found is None:
        return None
    entry, record = found
    paths = []
    for name in record["names"]:
        src = entry.path(_suffix(name))
        paths.append(atomic_write(Path(out) / name, lambda q, s=src: shutil.copyfile(s, q)))
    return paths


def keep_pictures(params: dict[str, str] | None, drawn: Sequence[Path]) -> None:
    """Keep the pictures ``drawn`` (the PNG files, and the ease-off's files drawn with them) under
    ``params`` (nothing for None)."""
    if params is None:
        return

    def build(entry) -> dict[str, list[str]]:
        for p in drawn:
            entry.write(_suffix(p.name), _copy_from(p))
        return {"names": [p.name for p in drawn]}

    cached_record(KIND, params, build)


def _copy_from(src: Path) -> Callable[[Path], None]:
    return lambda q: shutil.copyfile(src, q)


def _suffix(name: str) -> str:
    """The data-file suffix of a picture in its entry: ``te.png`` -> ``.te.png``."""
    return "." + name
