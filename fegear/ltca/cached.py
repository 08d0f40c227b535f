"""The loaded cycle, cached on disk by a content hash of everything that determines it.

A loaded cycle (:func:`fegear.ltca.cycle.run_ltca`: every mesh position solved) is a function of
the two members' design, the assembly (installation errors included), the torque, the analysis
options (fidelity, mesh level, tooth count, material, contact options, chunking) and the code.
A run repeated with the same inputs (the same case again, another output folder, a script run
twice, the nominal item shared by several studies) reads its positions back instead of solving
them again, and needs neither the meshes nor the compliance operators.

The key (:func:`fegear.store.cache.artefact_key`, kind ``cycle``) holds the members' ``repr``
(their complete design data), the assembly's fields, the :class:`~fegear.ltca.analysis.LTCAOptions`
without the worker count (the result does not depend on it: ``docs/ltca/studies.md``), the torque
and the pinion angles, with the code version of every package the positions depend on
(:data:`fegear.store.cache.PRODUCERS`), so a change of the code invalidates the entry by itself.

The entry is plain data, no pickle (:mod:`fegear.store.records`): a ``.npz`` of the arrays and the
JSON record of the :class:`~fegear.ltca.results.LoadedCycle` without its models; a float is
written by its ``repr``, so a hit gives back the positions bit for bit.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from fegear.ltca.analysis import LTCAOptions
from fegear.ltca.grid import PairCells
from fegear.ltca.results import LoadedCycle, LoadedPosition, PairContact
from fegear.ltca.zone import ContactZone
from fegear.mechanics.contact import ContactSolution
from fegear.mesh.sector import FlankZone
from fegear.store.cache import artefact_key
from fegear.store.records import cached_object, registry
from fegear.tca.cached import pair_key

__all__ = ["CachedCycle", "cached_cycle", "cycle_params"]

#: The classes a cycle record holds.
CLASSES = registry(
    LoadedCycle, LoadedPosition, PairContact, PairCells, ContactSolution, ContactZone, FlankZone
)


class CachedCycle(NamedTuple):
    """A loaded cycle and where it came from.

    Attributes
    ----------
    cycle
        The cycle; read from the cache, its ``models`` are None and its ``seconds`` hold only
        ``"read"`` (the seconds reading it took).
    key
        Its artefact key (what a record derived from the cycle, e.g. its displacement fields,
        is keyed on).
    cache_hit
        Whether it was read from the cache.
    """

    cycle: LoadedCycle
    key: str
    cache_hit: bool


def cycle_params(
    pinion,
    gear,
    assembly,
    torque2_Nmm: float,
    options: LTCAOptions,
    phi1: np.ndarray | None = None,
) -> dict[str, object]:
    """The content a loaded cycle is made from: the pair (:func:`fegear.tca.cached.pair_key`),
    the options without ``workers``, the torque (N·mm) and the pinion angles (None: the
    default cycle)."""
    return {
        **pair_key(pinion, gear, assembly, replace(options, workers=None)),
        "torque2_Nmm": float(torque2_Nmm),
        "phi1": None if phi1 is None else np.asarray(phi1, dtype=float),
    }


def cached_cycle(
    params: dict[str, object], solve: Callable[[], LoadedCycle], reuse: bool = True
) -> CachedCycle:
    """The cycle of ``params`` (:func:`cycle_params`) from the cache, else ``solve()`` and
    stored. ``reuse`` False: ``solve()`` without reading or writing the cache (a run asked to
    recompute its positions)."""
    key = artefact_key("cycle", params)
    if not reuse:
        return CachedCycle(solve(), key, False)
    t0 = time.perf_counter()
    cycle, hit = cached_object(
        "cycle", params, solve, CLASSES, lambda c: replace(c, models=None, seconds={})
    )
    if hit:
        cycle = replace(cycle, seconds={"read": time.perf_counter() - t0})
    return CachedCycle(cycle, key, hit)
