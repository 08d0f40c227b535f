"""Loaded tooth contact analysis (LTCA): the loaded mesh cycle of a gear pair
(``docs/ltca/contact_formulation.md``, ``docs/fidelity.md``)."""

from fegear.ltca.analysis import LTCAOptions, MemberModels, build_models
from fegear.ltca.cycle import run_ltca
from fegear.ltca.grid import PairCells, pair_cells
from fegear.ltca.position import solve_position
from fegear.ltca.results import LoadedCycle, LoadedPosition, PairContact

__all__ = [
    "LTCAOptions",
    "MemberModels",
    "build_models",
    "run_ltca",
    "solve_position",
    "PairCells",
    "pair_cells",
    "LoadedCycle",
    "LoadedPosition",
    "PairContact",
]
