"""The TCA of a cycle, cached on disk by a content hash of everything that determines it.

The unloaded TCA (reference phase + the positions with their separation grids) depends only on
the two members' design, the assembly (installation errors included), the TCA options and the
pinion angles, not on the torque or the FE model. A loaded analysis on the same pair (another
torque, another fidelity or mesh level, a re-run) reads it back instead of solving it again
(measured on the seed face gear, 25 positions: 2.9 s -> 0.01 s).

The key (:func:`fegear.store.cache.artefact_key`) holds the members' ``repr`` (their complete
design data, as for the sector meshes), the assembly's fields, the options and the angles, with
the code version of the TCA's producer (the source of ``fegear.tca``, ``fegear.geometry``,
``fegear.geometry.pair_placement`` and ``fegear.mechanics.hertz_closed_form``) and the numpy and
scipy versions
(:data:`fegear.store.cache.PRODUCERS`), so a change of the code that produces the positions
invalidates the entry by itself.

The entry (:func:`fegear.store.records.cached_object`) is plain data, no pickle: a ``.npz`` of the
arrays (read with ``allow_pickle=False``) and the JSON record, written last, of the phase, the
:class:`~fegear.tca.results.PositionResult` tuple and the TCA's precomputed state
(:meth:`~fegear.tca.TCA.state_record`) with their numbers (a float is written by its ``repr``,
so a hit gives back the positions bit for bit).
"""

from __future__ import annotations

import dataclasses
import logging
from typing import NamedTuple

import numpy as np

from fegear.store.cache import cached_record
from fegear.store.records import cached_object

from ..geometry.pair_placement import Assembly
from .core import TCA, TCAOptions
from .cycle import reference_phase
from .parallel import positions as parallel_positions
from .results import RECORD_CLASSES, PositionResult

__all__ = ["CachedTCA", "cached_phase", "cached_tca"]

log = logging.getLogger(__name__)


class CachedTCA(NamedTuple):
    """The TCA object of the phased assembly and its positions."""

    tca: TCA
    positions: tuple[PositionResult, ...]
    cache_hit: bool


def _assembly_key(asm: Assembly) -> dict[str, object]:
    """The assembly's data fields (its ``nominal`` builder is a callable, rebuilt from them)."""
    return {f.name: getattr(asm, f.name) for f in dataclasses.fields(asm) if f.name != "nominal"}


def pair_key(pinion, gear, assembly: Assembly, options: TCAOptions) -> dict[str, object]:
    """The content of the pair's TCA artefacts (``tca``, ``contact_path``, ``handover``): the
    members' ``repr``, the assembly's fields and the options."""
    return {
        "pinion": repr(pinion),
        "gear": repr(gear),
        "assembly": _assembly_key(assembly),
        "options": options,
    }


def cached_phase(pinion, gear, assembly: Assembly, options: TCAOptions) -> float:
    """:func:`~fegear.tca.reference_phase` of ``assembly`` (rad), from the cache when the pair
    was phased before. The phase is that of the ERROR-FREE pair, so its key holds the assembly
    without its errors: every installation error of a study reads the one entry (on the seed
    face gear the phasing is about 60 % of a new error's TCA)."""
    from dataclasses import replace

    nominal = assembly.without_errors()
    opt = replace(options, separation_grid=None, pinion_torque_Nm=None)
    params = pair_key(pinion, gear, nominal, opt)

    def build(entry) -> dict[str, object]:
        return {"phase2": float(reference_phase(pinion, gear, assembly, options))}

    _, record, _ = cached_record("phase", params, build)
    return float(record["phase2"])


def cached_tca(
    pinion,
    gear,
    assembly: Assembly,
    options: TCAOptions,
    phi1: np.ndarray,
    workers: int | None = None,
) -> CachedTCA:
    """Phase the assembly (:func:`~fegear.tca.reference_phase`) and run the TCA at ``phi1``
    (rad, ``(n,)``), reading both from the cache when the same pair was analysed before.

    Returns the :class:`~fegear.tca.TCA` of the phased assembly (the loaded analysis evaluates
    its flank maps) and the positions. ``workers``: processes for the positions
    (:func:`fegear.tca.parallel.positions`; the same result with any number).
    """
    phi1 = np.atleast_1d(np.asarray(phi1, dtype=float))
    params = {**pair_key(pinion, gear, assembly, options), "phi1": phi1}
    phase2 = cached_phase(pinion, gear, assembly, options)  # one small record, shared by errors

    def make() -> CachedTCA:
        tca = TCA(pinion, gear, assembly.with_phase2(phase2), options)
        return CachedTCA(tca, tuple(parallel_positions(tca, phi1, workers=workers)), False)

    def stored(made: CachedTCA) -> dict[str, object]:
        tca = made.tca
        return {"phase2": float(tca.asm.phase2), "positions": made.positions,
                "state": tca.state_record()}  # fmt: skip

    def restore(data) -> CachedTCA:
        asm = assembly.with_phase2(float(data["phase2"]))
        tca = TCA.from_state_record(data["state"], pinion, gear, asm, options)
        log.info("TCA positions read from the cache (%d)", len(data["positions"]))
        return CachedTCA(tca, tuple(data["positions"]), True)

    return cached_object("tca", params, make, RECORD_CLASSES, stored, restore)[0]
