"""The TCA of a cycle, cached on disk by a content hash of everything that determines it.

The unloaded TCA (reference phase + the positions with their separation grids) depends only on
the two members' design, the assembly (installation errors included), the TCA options and the
pinion angles, not on the torque or the FE model. A loaded analysis on the same pair (another
torque, another fidelity or mesh level, a re-run) reads it back instead of solving it again
(measured on the seed face gear, 25 positions: 2.9 s -> 0.01 s).

The key holds the members' ``repr`` (their complete design data, as for the sector meshes),
the assembly's fields, the options, the angles and a hash of the source of the geometry and TCA
packages, so a change of the code that produces the positions invalidates the entry by itself.
The entry is a pickle of the phase, the :class:`~fegear.tca.results.PositionResult` tuple and
the TCA's precomputed state (:meth:`~fegear.tca.TCA.state`); it is written atomically
(:func:`fegear.mesh.cache.cached_file`) and only ever read by the same code version.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import logging
import pickle
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..assembly import Assembly
from .core import TCA, TCAOptions
from .cycle import reference_phase
from .results import PositionResult

__all__ = ["CachedTCA", "cached_tca"]

log = logging.getLogger(__name__)


class CachedTCA(NamedTuple):
    """The TCA object of the phased assembly and its positions."""

    tca: TCA
    positions: tuple[PositionResult, ...]
    cache_hit: bool


@functools.lru_cache(maxsize=1)
def _source_hash() -> str:
    """SHA-256 of the source of the packages that produce the positions."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for pkg in ("geometry", "tca"):
        for f in sorted((root / pkg).glob("*.py")):
            h.update(f.name.encode())
            h.update(f.read_bytes())
    for f in ("assembly.py", "hertz.py"):
        h.update((root / f).read_bytes())
    return h.hexdigest()[:20]


def _assembly_key(asm: Assembly) -> dict[str, object]:
    """The assembly's data fields (its ``nominal`` builder is a callable, rebuilt from them)."""
    return {f.name: getattr(asm, f.name) for f in dataclasses.fields(asm) if f.name != "nominal"}


def cached_tca(
    pinion, gear, assembly: Assembly, options: TCAOptions, phi1: np.ndarray
) -> CachedTCA:
    """Phase the assembly (:func:`~fegear.tca.reference_phase`) and run the TCA at ``phi1``
    (rad, ``(n,)``), reading both from the cache when the same pair was analysed before.

    Returns the :class:`~fegear.tca.TCA` of the phased assembly (the loaded analysis evaluates
    its flank maps) and the positions.
    """
    from fegear.mesh.cache import cached_file

    phi1 = np.atleast_1d(np.asarray(phi1, dtype=float))
    params = {
        "pinion": repr(pinion),
        "gear": repr(gear),
        "assembly": _assembly_key(assembly),
        "options": repr(options),
        "phi1": phi1,
        "source": _source_hash(),
    }
    box: dict[str, object] = {}

    def build(path: Path) -> None:
        asm = assembly.with_phase2(reference_phase(pinion, gear, assembly, options))
        tca = TCA(pinion, gear, asm, options)
        positions = tuple(tca.positions(phi1))
        box["tca"], box["positions"] = tca, positions
        with open(path, "wb") as fh:
            entry = (float(asm.phase2), positions, tca.state())
            pickle.dump(entry, fh, protocol=pickle.HIGHEST_PROTOCOL)

    path, hit = cached_file("tca", params, ".pkl", build)
    if not hit:
        return CachedTCA(box["tca"], box["positions"], False)  # type: ignore[arg-type]
    with open(path, "rb") as fh:
        phase2, positions, state = pickle.load(fh)
    tca = TCA.restore(state, assembly.with_phase2(phase2))
    log.info("TCA positions read from the cache (%d)", len(positions))
    return CachedTCA(tca, tuple(positions), True)
