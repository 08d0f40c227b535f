"""The result model of a gear run, between the pipeline and the writers.

:func:`build_result` builds it once from a :class:`~fegear.pipeline.run.GearRun`;
``summary.json`` (:func:`summary_document`), the PNG titles, the command line's report and the
Python API (:class:`fegear.api.GearResult`) read it; :func:`load_result` reads a saved
``summary.json`` back into the same model. The classes (:mod:`fegear.results.model`) are frozen
dataclasses with the units in the field names.

The Hertz scene's run has its own model, :mod:`fegear.results.hertz_scene`
(:class:`HertzSceneResult`: built by :func:`build_hertz_result`, written as ``summary.json`` by
:func:`hertz_summary_document`, read back by :func:`load_hertz_result`).
"""

from fegear.results.build import build_result
from fegear.results.hertz_scene import (
    HertzSceneResult,
    build_hertz_result,
    hertz_summary_document,
    load_hertz_result,
)
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
    "HertzSceneResult",
    "PairLoad",
    "PatternCentre",
    "Position",
    "build_hertz_result",
    "build_result",
    "hertz_summary_document",
    "load_hertz_result",
    "load_result",
    "result_from_summary",
    "summary_document",
]
