"""Typed results of the loaded tooth contact analysis (frozen dataclasses).

Units: force N, torque N·mm (reported N·m in summaries), pressure MPa, lengths mm, TE arcsec.
Sign conventions (DESIGN §3): ``theta`` is the elastic lag of member 2 (rad, positive against its
driving sense); the loaded TE is the unloaded TE minus that lag.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from fegear.contact import ContactSolution
from fegear.ltca.grid import PairCells
from fegear.ltca.zone import ContactZone

__all__ = ["PairLoad", "LoadedPosition", "LoadedCycle"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class PairLoad:
    """Load on one tooth pair at one position.

    Attributes
    ----------
    k, j
        Pinion and gear tooth of the pair.
    force_N
        Total normal force.
    torque_Nmm
        Its torque about the member-2 axis (``Σ h F``).
    load_share
        ``torque / total torque`` (the shares of a position sum to 1).
    p_max_MPa
        Largest cell pressure.
    p_peak_MPa
        Recovered peak pressure (:func:`fegear.patch.measure_patch`).
    semi_major_mm, semi_minor_mm
        Equivalent-ellipse semi-axes from the second moments of the pressure.
    n_active
        Cells in contact.
    edge_contact
        An active cell touches a boundary of a working flank.
    contact_point
        ``(3,)`` mm, force centroid in the fixed frame (zeros if no load).
    """

    k: int
    j: int
    force_N: float
    torque_Nmm: float
    load_share: float
    p_max_MPa: float
    p_peak_MPa: float
    semi_major_mm: float
    semi_minor_mm: float
    n_active: int
    edge_contact: bool
    contact_point: Array

    @property
    def in_contact(self) -> bool:
        return self.force_N > 0.0


@dataclass(frozen=True)
class LoadedPosition:
    """One mesh position under load.

    Attributes
    ----------
    phi1
        Pinion angle (rad).
    te_unloaded_arcsec, te_loaded_arcsec
        Unloaded and loaded transmission error.
    theta
        Elastic lag of member 2 (rad).
    pairs
        One :class:`PairLoad` per modelled pair (in contact or not).
    cells
        The contact cells of each pair (same order as ``pairs``).
    pressure
        One ``(n_i,)`` array (MPa) per pair.
    solution
        The contact solution over all cells (forces, gaps, residuals).
    g_max_mm
        Separation cut-off used for the cells.
    warnings
        Human-readable warnings (e.g. a grid coarser than the patch).
    left_out
        Pairs ``(k, j)`` the lag closes that lie outside the modelled teeth (the cycle grows its
        zone to hold them: :func:`fegear.ltca.cycle.grown_zone`).
    """

    phi1: float
    te_unloaded_arcsec: float
    te_loaded_arcsec: float
    theta: float
    pairs: tuple[PairLoad, ...]
    cells: tuple[PairCells, ...]
    pressure: tuple[Array, ...]
    solution: ContactSolution
    g_max_mm: float
    warnings: tuple[str, ...]
    left_out: tuple[tuple[int, int], ...] = ()

    @property
    def n_pairs_in_contact(self) -> int:
        return sum(p.in_contact for p in self.pairs)

    @property
    def p_max_MPa(self) -> float:
        return max((p.p_max_MPa for p in self.pairs), default=0.0)


@dataclass(frozen=True)
class LoadedCycle:
    """The loaded analysis over a mesh cycle.

    Attributes
    ----------
    positions
        Per-position results.
    torque2_Nmm
        Torque on member 2 (N·mm).
    phi1
        ``(n,)`` rad.
    te_unloaded_arcsec, te_loaded_arcsec
        ``(n,)``.
    n_in_contact
        ``(n,)`` pairs in contact per position.
    fidelity, level
        How the compliance was modelled.
    seconds
        Wall times of the stages.
    phase2
        rad, the member-2 phase the TCA closed the pair with (``assembly.with_phase2(phase2)`` is
        the assembly every position was solved in).
    zone_gap_mm
        mm, the separation bound of the contact zone the sectors were built on (larger than
        ``g_max`` when the load made the zone grow, :func:`fegear.ltca.cycle.grown_zone`); 0 for
        models without a zone.
    zone
        That contact zone (:class:`fegear.ltca.zone.ContactZone`; the models of the cycle are
        ``build_models(..., zone=zone)``, read back from the cache), or None.
    """

    positions: tuple[LoadedPosition, ...]
    torque2_Nmm: float
    phi1: Array
    te_unloaded_arcsec: Array
    te_loaded_arcsec: Array
    n_in_contact: NDArray[np.int_]
    fidelity: str
    level: int
    seconds: dict[str, float]
    phase2: float = 0.0
    zone_gap_mm: float = 0.0
    zone: ContactZone | None = None

    @property
    def te_pp_unloaded_arcsec(self) -> float:
        return float(np.ptp(self.te_unloaded_arcsec)) if self.phi1.size else 0.0

    @property
    def te_pp_loaded_arcsec(self) -> float:
        return float(np.ptp(self.te_loaded_arcsec)) if self.phi1.size else 0.0

    @property
    def contact_ratio_loaded(self) -> float:
        """Mean number of pairs in contact over the cycle (uniformly spaced positions)."""
        return float(np.mean(self.n_in_contact)) if self.phi1.size else 0.0

    @property
    def p_max_MPa(self) -> float:
        return max((p.p_max_MPa for p in self.positions), default=0.0)
