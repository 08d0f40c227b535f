"""Parameter sweeps of gear cases: the items of a grid run in parallel, each resumable
(:mod:`fegear.sweep.run`), and their comparison (:mod:`fegear.sweep.output`: ``sweep.json``,
``comparison.md``, ``te_overlay.png``)."""

from fegear.sweep.run import (
    MARKER,
    GridAxis,
    ItemResult,
    SweepItem,
    SweepResult,
    build_items,
    is_done,
    parse_grid,
    require_dask,
    run_item,
    run_sweep,
    verified_summary,
)

__all__ = [
    "GridAxis",
    "SweepItem",
    "ItemResult",
    "SweepResult",
    "parse_grid",
    "build_items",
    "run_item",
    "run_sweep",
    "require_dask",
    "is_done",
    "verified_summary",
    "MARKER",
]
