"""The ``ease_off`` section of ``summary.json``: the numbers that describe a run's ease-off.

The map itself (the grid of ``ε`` over the pinion's working flank) is in ``ease_off.json``,
``ease_off.vts`` and ``ease_off.png`` (:mod:`fegear.output.ease_off_output`); the section holds
what a reader compares between runs (``docs/ease_off.md``):

- ``grid``: ``[profile nodes, face nodes]``; ``defined_fraction``: the share of nodes with a
  contact position on the gear's working flank;
- ``eps_max_um``: the largest ``ε`` over the defined nodes (µm, above its minimum);
  ``eps_min_mm``: the minimum's absolute level (the smallest gap of the flank, mm; negative where
  the pair closes with the gear ahead of its ratio). Where on the flank the minimum lies is in
  ``ease_off.json``: it is a grid node, and along a flat valley (a lead crowning alone, a
  conjugate pair) it is decided by round-off, so it is no number to compare;
- ``fit``: the quadratic fit (:func:`fegear.tca.ease_off_pair.fit_ease_off`): profile and
  lengthwise slope and crowning, twist, the fit's rms residual (µm), or null with fewer than a
  dozen defined nodes;
- a run with measured flanks: ``design`` (the same numbers of the design pair) and
  ``measured_minus_design_um`` (``min``, ``max``, ``rms`` over the nodes both define).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fegear.tca.ease_off import EaseOff
from fegear.tca.ease_off_pair import fit_ease_off

__all__ = ["FILE", "ease_off_section"]

#: the file that holds the map
FILE = "ease_off.json"


def _num(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def _describe(e: EaseOff) -> dict[str, Any]:
    ok = np.isfinite(e.eps_um)
    fit = fit_ease_off(e)
    return {
        "defined_fraction": float(ok.mean()),
        "eps_max_um": _num(np.nanmax(e.eps_um)) if ok.any() else None,
        "eps_min_mm": _num(e.eps_min_mm),
        "fit": (
            None
            if fit is None
            else {k: (v if k == "nodes" else float(v)) for k, v in fit._asdict().items()}
        ),
    }


def ease_off_section(run) -> dict[str, Any] | None:
    """The ``ease_off`` section of a :class:`~fegear.pipeline.run.GearRun` (module docstring),
    or None for a run without an ease-off."""
    pe = run.ease_off
    if pe is None:
        return None
    e = pe.ease_off
    doc = {"file": FILE, "grid": [int(e.u.size), int(e.v.size)], **_describe(e)}
    if pe.design is not None:
        doc["design"] = _describe(pe.design)
        d = pe.difference_um
        ok = np.isfinite(d)
        doc["measured_minus_design_um"] = (
            {
                "min": float(d[ok].min()),
                "max": float(d[ok].max()),
                "rms": float(np.sqrt(np.mean(d[ok] ** 2))),
            }
            if ok.any()
            else None
        )
    return doc
