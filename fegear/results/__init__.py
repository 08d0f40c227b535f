"""The result model of a gear run, between the pipeline and the writers.

:func:`build_result` builds it once from a :class:`~fegear.pipeline.run.GearRun`;
``summary.json`` (:func:`summary_document`), the PNG titles, the command line's report and the
Python API (:class:`fegear.api.GearResult`) read it; :func:`load_result` reads a saved
``summary.json`` back into the same model. The classes (:mod:`fegear.results.model`) are frozen
dataclasses with the units in the field names.
"""

from fegear.results.build import build_result
from fegear.results.model import (
    Checks,
    Cycle,
    Excluded,
    GearRunResult,
    PairLoad,
    PatternCentre,
    Position,
)
from fegear.results.summary import load_result, result_from_summary, summary_document

__all__ = [
    "Checks",
    "Cycle",
    "Excluded",
    "GearRunResult",
    "PairLoad",
    "PatternCentre",
    "Position",
    "build_result",
    "load_result",
    "result_from_summary",
    "summary_document",
]
