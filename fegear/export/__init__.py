"""Full-FE decks of fegear's problems for CalculiX (and Abaqus), and their results read back.

- :func:`export_ccx`: a case (the Hertz scene, or a gear pair at chosen positions) as
  ready-to-run ``.inp`` decks (:mod:`fegear.export.hertz_scene_deck`,
  :mod:`fegear.export.gear_deck`);
- :func:`~fegear.export.ccx_run.run_ccx`: runs ``ccx`` on one, with its wall time and memory;
- :func:`~fegear.export.ccx_results.read_results`: load shares, p_max, patch semi-axes, TE.

``docs/calculix.md`` documents the decks and how they compare with fegear.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from fegear.errors import InputError
from fegear.export.ccx_results import CcxPair, CcxResult, read_results
from fegear.export.ccx_run import CcxMissing, CcxRun, find_ccx, run_ccx
from fegear.export.deck import Deck

__all__ = [
    "CcxMissing",
    "CcxPair",
    "CcxResult",
    "CcxRun",
    "Deck",
    "export_ccx",
    "find_ccx",
    "position_angle",
    "read_results",
    "run_ccx",
    "DEFAULT_GEAR_ELEMENT_MM",
    "DEFAULT_HERTZ_LEVEL",
]

#: Default contact element size of a gear deck (mm).
DEFAULT_GEAR_ELEMENT_MM = 0.5
#: Default Hertz-scene level of a deck's contact elements (twice the cell size of that level:
#: 0.239 mm at level 1). Measured on 2 cores (``benchmarks/results/calculix.md``): the coarsest
#: level from which on CalculiX's p0 stays within 1 % of Hertz (−0.82 %, 146 s, 202 MB); its
#: semi-minor axis from the nodal forces reads 16 % long there (7 % at level 2, 0.159 mm, 291 s;
#: 3.4 % at level 3, 0.119 mm, 757 s and 731 MB).
DEFAULT_HERTZ_LEVEL = 1


def position_angle(case, index: int) -> float:
    """Pinion angle (rad) of position ``index`` of the case's cycle of ``n_positions``
    (``−π/N1 + 2π index / (N1 n)``: the positions of ``fegear run``)."""
    # local: the pipeline pulls scipy; the `fegear` command's parser imports this package
    from fegear.pipeline.pair import build_pair

    n = case.n_positions
    if not (isinstance(index, int) and 0 <= index < n):
        raise InputError("position", index, f"an index in 0..{n - 1} (the case's n_positions)")
    n1 = build_pair(case).assembly.n1
    return -math.pi / n1 + 2 * math.pi / n1 * index / n


def export_ccx(
    case,
    out: str | Path,
    element_mm: float | None = None,
    phi1: Sequence[float] = (),
    reach_mm: float | None = None,
    level: int | None = None,
    patch_mm: float | None = None,
    patch_gap_mm: float | None = None,
) -> list[Path]:
    """Write the CalculiX decks of ``case`` into ``out``: ``<job>.inp`` and its record
    ``<job>.json`` each. Returns the ``.inp`` paths.

    Parameters
    ----------
    case
        A :class:`~fegear.scenes.hertz_case.HertzCase` (one deck) or a
        :class:`~fegear.io.gear_case.GearCase` (one deck per pinion angle of ``phi1``).
    element_mm
        Contact element size (mm). Default: the Hertz scene, twice the cell size of ``level``
        (as fegear meshes that level); gears, :data:`DEFAULT_GEAR_ELEMENT_MM`.
    phi1
        Gear pairs: pinion angles (rad; :func:`position_angle` of a cycle index).
    reach_mm
        Gear pairs: :func:`fegear.export.gear_deck.gear_deck`'s reach (default
        :data:`~fegear.export.gear_deck.DEFAULT_REACH_MM`).
    level
        Gear pairs: sector mesh level away from the contact (default: the case's). The Hertz
        scene: the level whose element size the contact gets when ``element_mm`` is not given
        (default :data:`DEFAULT_HERTZ_LEVEL`, not the case's level: level 3, the case's, takes
        CalculiX 12 minutes).
    patch_mm, patch_gap_mm
        Gear pairs: elements of ``patch_mm`` along each pair's contact patch (the strip where
        the TCA separation is below ``patch_gap_mm``, default
        :data:`~fegear.export.gear_deck.DEFAULT_PATCH_GAP_MM`), coarse elsewhere
        (:func:`fegear.export.gear_deck.gear_deck`).
    """
    # local: the scene and the decks pull scipy, scikit-fem and meshio; the `fegear` command's
    # parser imports this package
    from fegear.scenes.hertz_case import HertzCase

    if isinstance(case, HertzCase):
        # local: as above
        from fegear.export.hertz_scene_deck import hertz_deck
        from fegear.scenes.hertz_scene import (
            CELLS_ACROSS_MINOR,
            ELEMENT_TO_CELL,
            hertz_reference,
        )

        if phi1:
            raise InputError("positions", list(phi1), "none for the Hertz scene")
        if patch_mm is not None:
            raise InputError("patch_mm", patch_mm, "none for the Hertz scene (--element-mm)")
        if element_mm is None:
            lv = DEFAULT_HERTZ_LEVEL if level is None else level
            if not (isinstance(lv, int) and 0 <= lv < len(CELLS_ACROSS_MINOR)):
                raise InputError(
                    "level", lv, f"a Hertz-scene level 0..{len(CELLS_ACROSS_MINOR) - 1}"
                )
            b = hertz_reference(case.scene).b_mm
            element_mm = ELEMENT_TO_CELL * 2 * b / CELLS_ACROSS_MINOR[lv]
        return [hertz_deck(case.scene, element_mm, name=f"{case.name}_{element_mm:.3g}mm")
                .write(out)]  # fmt: skip
    from fegear.export.gear_deck import (  # local: as above
        DEFAULT_PATCH_GAP_MM,
        DEFAULT_REACH_MM,
        gear_deck,
    )

    if not phi1:
        raise InputError("positions", [], "at least one position of a gear pair")
    h = DEFAULT_GEAR_ELEMENT_MM if element_mm is None else element_mm
    reach = DEFAULT_REACH_MM if reach_mm is None else reach_mm
    gap = DEFAULT_PATCH_GAP_MM if patch_gap_mm is None else patch_gap_mm
    return [
        gear_deck(case, p, h, reach_mm=reach, level=level, patch_mm=patch_mm,
                  patch_gap_mm=gap).write(out)
        for p in phi1
    ]  # fmt: skip
