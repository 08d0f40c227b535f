"""Unloaded tooth contact analysis (TCA) over the mesh cycle, multi-pair (``docs/tca/README.md``).

Use :func:`run_tca` on an :class:`~fegear.geometry.pair_placement.Assembly`; results are
:class:`CycleResult` / :class:`PositionResult`; :class:`SeparationGrid` is the contact grid of
the loaded analysis.
"""

from __future__ import annotations

from .core import TCA, TCAOptions
from .cycle import contact_interval, cycle_result, reference_phase, run_tca
from .results import ARCSEC, ContactEllipseAt, CycleResult, PositionResult, SeparationGrid
from .surfaces import (
    FaceGearMap,
    FlankMap,
    GenericFlankMap,
    SpiralBevelMap,
    SpurInvoluteMap,
    flank_map,
)

__all__ = [
    "ARCSEC",
    "TCA",
    "TCAOptions",
    "ContactEllipseAt",
    "CycleResult",
    "PositionResult",
    "SeparationGrid",
    "FlankMap",
    "GenericFlankMap",
    "SpurInvoluteMap",
    "FaceGearMap",
    "SpiralBevelMap",
    "flank_map",
    "contact_interval",
    "cycle_result",
    "reference_phase",
    "run_tca",
]
