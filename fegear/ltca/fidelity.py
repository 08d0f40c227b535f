"""The loaded fidelities as objects: what each one models and how it solves a position.

A fidelity differs from the others in a few decisions, and everything else (the TCA, the
sectors and their compliance operators, the contact solver, the cycle over the positions, the
results) is shared. The decisions are the members of :class:`Fidelity` (with ``models_text`` and
``positions_text``, what its two stages do, for progress reports):

- ``cells``: whether the position is solved on contact cells of the FE flanks (``fe``,
  ``hybrid``) or with per-pair closed-form laws (``hertz``: no cells, so no cell loads, no
  displacement fields, no pressure patterns);
- ``resolves_patch``: whether the pressure of a patch narrower than an element is resolved
  (``hybrid`` refines its cells to the patch, ``hertz`` is closed-form; ``fe`` cells are one
  element wide, so its pressures and TE there are cell averages: the run warns);
- :meth:`~Fidelity.layer_depth`: the depth of the matching layer read from the FE under every
  cell (``hybrid``: the FE is read at a depth ``d`` where the element is accurate, and the
  half-space gives the near field above it; ``docs/fidelity.md``), 0 for the others;
- :meth:`~Fidelity.max_cells`: the cap on the cells of one pair;
- ``trims``, ``warm_grids``, ``refine_rounds``: whether a position's cells are trimmed to the
  ones its neighbour's solution predicts in contact, whether it starts from its neighbour's
  refined grids, and how many times the cells are refined until every patch has ``n_across``
  cells across it (``hybrid`` only: the ``fe`` cells stay one element wide, so refining them
  would not resolve a narrower patch);
- :meth:`~Fidelity.compliance`: ``C`` of a set of cells (both members);
- :meth:`~Fidelity.solve_position`: the loaded contact at one position.

The registry :data:`FIDELITIES` maps the ``[analysis] fidelity`` names to the objects; the
unloaded ``tca`` is not a contact model and is run by :mod:`fegear.pipeline.run` directly.
A new fidelity is one more class here, registered in :data:`FIDELITIES`, and its name in the
case-file choices (:data:`fegear.io.gear_case.FIDELITIES`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import numpy as np

from fegear.errors import InputError
from fegear.ltca.hertz_fidelity import solve_position_hertz
from fegear.ltca.hybrid import hybrid_compliance
from fegear.ltca.model import cell_load_operators, member_compliance
from fegear.ltca.position import solve_position

if TYPE_CHECKING:  # the option and model types (fegear.ltca.analysis imports this module)
    from fegear.ltca.analysis import LTCAOptions, MemberModels
    from fegear.ltca.results import LoadedPosition

__all__ = ["FE", "FIDELITIES", "Fidelity", "Hertz", "Hybrid", "fidelity_of"]

#: Cap on the contact cells of one pair at ``fe``: its cells are element-sized, the cap only
#: bounds the dense compliance of a huge zone.
FE_MAX_CELLS = 1500


class Fidelity(Protocol):
    """A loaded fidelity (see the module docstring)."""

    name: str
    models_text: str
    positions_text: str
    cells: bool
    resolves_patch: bool
    trims: bool
    warm_grids: bool
    refine_rounds: int

    def layer_depth(self, h_mm: float, module_mm: float, options: LTCAOptions) -> float:
        """Depth (mm) of the layer the FE is read at, from the fine element size ``h_mm`` and
        the smallest module of the pair."""
        ...

    def max_cells(self, models: MemberModels) -> int:
        """Cap on the contact cells of one pair."""
        ...

    def compliance(self, tca, pos, models: MemberModels, cells, loads=None) -> np.ndarray:
        """``C = C_pinion + C_gear`` (mm/N) of ``cells`` at position ``pos`` (``loads``: their
        load operators if already made)."""
        ...

    def solve_position(
        self,
        tca,
        pos,
        models: MemberModels,
        torque2_Nmm: float,
        options: LTCAOptions,
        previous: LoadedPosition | None,
    ) -> LoadedPosition:
        """The loaded contact at one position (``previous``: its neighbour's solution)."""
        ...


class FE:
    """``fe``: contact cells one element wide, compliance from the FE operators alone."""

    name = "fe"
    models_text = "sector meshes and compliance operators"
    positions_text = "TCA + contact"
    cells = True
    resolves_patch = False
    trims = False
    warm_grids = False
    refine_rounds = 0

    def layer_depth(self, h_mm: float, module_mm: float, options: LTCAOptions) -> float:
        return 0.0

    def max_cells(self, models: MemberModels) -> int:
        return FE_MAX_CELLS

    def compliance(self, tca, pos, models: MemberModels, cells, loads=None) -> np.ndarray:
        """``C_m = P_mᵀ (K_m⁻¹)_cc P_m`` of both members (:mod:`fegear.ltca.model`)."""
        if loads is None:
            asm = tca.asm
            loads = cell_load_operators(
                models, asm.placement1(pos.phi1), asm.placement2(pos.phi2), cells
            )
        P1, P2 = loads
        return member_compliance(models.pinion, P1) + member_compliance(models.gear, P2)

    def solve_position(self, tca, pos, models, torque2_Nmm, options, previous):
        return solve_position(tca, pos, models, torque2_Nmm, options.g_max_mm, previous)


class Hybrid(FE):
    """``hybrid`` (the default): FE read at a matching depth below every cell plus the
    closed-form half-space near field on cells refined to the patch (:mod:`fegear.ltca.hybrid`)."""

    name = "hybrid"
    models_text = "sector meshes and compliance operators and their layer below the flanks"
    resolves_patch = True
    trims = True
    warm_grids = True
    refine_rounds = 3

    def layer_depth(self, h_mm: float, module_mm: float, options: LTCAOptions) -> float:
        """``d = min(depth_elements · h, depth_max_modules · m)``: deep enough for the FE to be
        accurate there (a few elements), shallow against the tooth (``docs/fidelity.md``)."""
        return min(options.depth_elements * h_mm, options.depth_max_modules * module_mm)

    def max_cells(self, models: MemberModels) -> int:
        return models.max_cells

    def compliance(self, tca, pos, models: MemberModels, cells, loads=None) -> np.ndarray:
        return hybrid_compliance(tca, pos, models, cells, loads)


class Hertz(FE):
    """``hertz``: per-pair Hertz laws with the lumped FE compliance of each pair
    (:mod:`fegear.ltca.hertz_fidelity`, which reads the FE compliance of the cells near each
    pair's contact point: :meth:`FE.compliance`); no contact cells are reported."""

    name = "hertz"
    positions_text = "TCA + Hertz laws"
    cells = False
    resolves_patch = True

    def solve_position(self, tca, pos, models, torque2_Nmm, options, previous):
        return solve_position_hertz(tca, pos, models, torque2_Nmm, options.E_MPa, options.nu)


#: The loaded fidelities by ``[analysis] fidelity`` name.
FIDELITIES: dict[str, Fidelity] = {f.name: f for f in (FE(), Hertz(), Hybrid())}


def fidelity_of(name: str) -> Fidelity:
    """The :class:`Fidelity` called ``name``; :class:`~fegear.errors.InputError` if there is
    none."""
    try:
        return FIDELITIES[name]
    except (KeyError, TypeError):
        allowed = ", ".join(repr(n) for n in FIDELITIES)
        raise InputError("fidelity", name, f"one of {allowed}") from None
