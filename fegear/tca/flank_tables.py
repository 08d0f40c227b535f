"""The bevel and hypoid flank tables kept in the artefact cache (kind ``flank_table``).

A generated bevel flank is evaluated through a table of the exact flank
(:mod:`fegear.geometry.bevel.tabulated`, ``docs/geometry/tabulated_flank.md``): building it
tabulates the meshing root (ψ table, 41 × 41 engine roots) and then the flank on 201 × 201
nodes, about half a second per flank, in every process that evaluates the flank (a warm run
reads its TCA and its loaded cycle from the cache, but its flank views evaluate the flanks).
The table's arrays (~2 MB per flank) are kept under the member's ``repr`` (its blank and machine
settings: what the TCA's cache keys hold too) and the side, and the code that makes them
(``fegear.geometry``); a table read back is the one built, bit for bit.
"""

from __future__ import annotations

from fegear.geometry.bevel.tabulated import FlankTableRecord
from fegear.store.records import cached_object, registry

__all__ = ["KIND", "flank_table"]

#: the cache kind of the tables
KIND = "flank_table"
_CLASSES = registry(FlankTableRecord)


def flank_table(member, side: str):
    """``member.tabulated_flank(side)`` of a bevel or hypoid member, its table read from the
    artefact cache when made before (module docstring); the exact evaluator where no table meets
    the tolerance (:func:`fegear.geometry.bevel.tabulated.tabulate`)."""
    params = {"member": repr(member), "side": side}
    record, _ = cached_object(KIND, params, lambda: member.tabulated_record(side), _CLASSES)
    if record is None:
        return member.tabulated_flank(side)
    return member.adopt_tabulated(side, record)
