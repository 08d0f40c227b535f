"""Values made from cache entries, kept in the process for the next run that asks for them.

Reading an artefact back from the disk cache (:mod:`fegear.store.cache`) is cheap, but what a
run makes of it may not be: a member's FE model (:func:`fegear.ltca.analysis.build_models`) is
its sector mesh and compliance operator read back, then a finite-element basis, the clamped
DOFs and the flank maps built on them (about a second per member on the seed face gear). A
process that runs several cases of one pair (a sweep worker, a case script over installation
errors, a notebook calling :func:`fegear.run` in a loop) asks for the same models each time.

A :class:`Memo` keeps the last few such values, each with the cache lookups that made it
(:class:`~fegear.store.cache.Lookups`) and the identity of the entries' files
(:func:`~fegear.store.cache.entries_stamp`). A value is given again only while those files are
the ones it was made from (not cleared, evicted, rebuilt or damaged since): the run then counts
the same lookups as hits of the cache and marks the entries used
(:func:`~fegear.store.cache.reuse_entries`), as reading them again would. Anything changed: the
value is dropped and made again from the cache (which then rebuilds what is gone).
"""

from __future__ import annotations

import logging
from collections import OrderedDict
from collections.abc import Callable, Mapping
from typing import Generic, NamedTuple, TypeVar

from fegear.store.cache import Lookups, content_hash, entries_stamp, recorded, reuse_entries

__all__ = ["Memo"]

log = logging.getLogger(__name__)

T = TypeVar("T")


class _Kept(NamedTuple, Generic[T]):
    value: T
    lookups: Lookups
    stamp: tuple


class Memo(Generic[T]):
    """The ``size`` values last made from the cache, keyed on what they are made from.

    Parameters
    ----------
    name
        What the values are (for the log).
    size
        How many are kept (least recently used dropped first): a value may hold large arrays.
    """

    def __init__(self, name: str, size: int) -> None:
        self.name = name
        self.size = size
        self._kept: OrderedDict[str, _Kept[T]] = OrderedDict()

    def holds(self, params: Mapping[str, object]) -> bool:
        """Whether :meth:`get` would give the kept value of ``params`` (nothing counted)."""
        kept = self._kept.get(content_hash(dict(params)))
        return kept is not None and entries_stamp(kept.lookups.used) == kept.stamp

    def get(self, params: Mapping[str, object], make: Callable[[], T]) -> tuple[T, bool]:
        """``(value, kept)``: the value of ``params`` kept in the process if its cache entries
        are unchanged (counted as cache hits), else ``make()`` (its cache lookups counted as
        usual) and kept."""
        key = content_hash(dict(params))
        kept = self._kept.get(key)
        if kept is not None:
            if reuse_entries(kept.lookups, kept.stamp):
                self._kept.move_to_end(key)
                log.info("%s kept in the process, its cache entries unchanged", self.name)
                return kept.value, True
            del self._kept[key]
            log.info("%s: its cache entries changed, made again", self.name)
        value, lookups = recorded(make)
        self._kept[key] = _Kept(value, lookups, entries_stamp(lookups.used))
        while len(self._kept) > self.size:
            self._kept.popitem(last=False)
        return value, False

    def clear(self) -> None:
        """Forget every value."""
        self._kept.clear()
