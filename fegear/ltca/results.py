"""Typed results of the loaded tooth contact analysis (frozen dataclasses).

Units: force N, torque N·mm (reported N·m in summaries), pressure MPa, lengths mm, TE arcsec.
Sign conventions (``docs/conventions.md``): ``theta`` is the elastic lag of member 2 (rad, positive
against its driving sense); the loaded TE is the unloaded TE minus that lag.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fegear.ltca.grid import PairCells
from fegear.ltca.zone import ContactZone
from fegear.mechanics.contact import ContactSolution

__all__ = [
    "DEGENERATE_SHARE",
    "MIN_CELLS_ACROSS",
    "CycleHeadline",
    "Excluded",
    "LoadedCycle",
    "LoadedPosition",
    "PairContact",
]

Array = NDArray[np.float64]

#: A patch is resolved when its minor axis spans at least this many contact cells. On fewer the
#: cell pressures are averages over cells wider than the patch and the patch compliance is the
#: cell's, not the contact's: the issue's FZG case with 0.5 mm axis errors had pairs on a single
#: 2 mm cell reading 220-950 MPa next to positions at 10-15 GPa, and the loaded TE jumped
#: 130-200″ there; ``fe`` level 0 on FZG has 0.2 cells across (126-160 MPa where line Hertz says
#: about 1100 MPa).
MIN_CELLS_ACROSS = 2.0
#: A position is degenerate when the loaded pairs the cells do not resolve carry together at
#: least this share of the torque: the loaded TE is then uncertain by up to that share of the
#: elastic lag (:mod:`fegear.ltca.degenerate`, the rule and its reason).
DEGENERATE_SHARE = 0.01


@dataclass(frozen=True)
class PairContact:
    """The contact solution of one tooth pair at one position (solver units: N·mm torque, the
    contact point as an array). What a run reports of it is :class:`fegear.results.PairLoad`.

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
        Recovered peak pressure (:func:`fegear.mechanics.patch.measure_patch`).
    semi_major_mm, semi_minor_mm
        Equivalent-ellipse semi-axes from the second moments of the pressure.
    n_active
        Cells in contact.
    edge_contact
        An active cell touches a boundary of a working flank.
    contact_point
        ``(3,)`` mm, force centroid in the fixed frame (zeros if no load).
    edges
        The boundaries its active cells touch, named (:func:`fegear.ltca.grid.edge_names`:
        ``"pinion tip"``, ``"gear toe"``, ...); empty for an interior contact.
    p_interior_MPa
        Largest pressure away from the edges: over the active cells beyond the edges' reach
        (:mod:`fegear.ltca.edges`: three patch semi-widths and two cells from every active
        cell on a boundary; all active cells of an interior contact); None when no such cell
        exists (the whole patch is an edge contact) or the patch is not resolved
        (``resolved`` False: its cell pressures are cell averages of an unresolved patch, not a
        pressure).
    p_edge_MPa
        Largest pressure within that reach of the edges (singular, grid-dependent); None for an
        interior contact.
    cells_across
        Contact cells across the patch's minor axis (``2 b`` over the cell width; 0 for a patch
        on one cell; ``inf`` for the closed-form ``hertz`` fidelity).
    resolved
        ``cells_across >= MIN_CELLS_ACROSS``: the grid resolves the patch.
    pressure_reason
        Why the fidelity gives no pressure for this loaded pair ("" when it does): ``hertz`` at
        a flank edge, where ``p_max_MPa`` and ``p_peak_MPa`` are NaN and ``p_interior_MPa``,
        ``p_edge_MPa`` None.
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
    edges: tuple[str, ...] = ()
    p_interior_MPa: float | None = None
    p_edge_MPa: float | None = None
    cells_across: float = math.inf
    resolved: bool = True
    pressure_reason: str = ""

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
        One :class:`PairContact` per modelled pair (in contact or not).
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
    status
        ``"ok"``; ``"lost"``: no pair carries load here (the flanks do not meet, or their only
        contact is an edge the cells do not represent); ``"degenerate"``: the loaded pairs the
        cells do not resolve (on one cell, or a grid coarser than the patch) carry together at
        least :data:`DEGENERATE_SHARE` of the torque (:mod:`fegear.ltca.degenerate`). The
        cycle's headline TE peak-to-peak leaves out the positions that are not ``"ok"``
        (:meth:`LoadedCycle.headline`).
    status_reason
        Why, in words ("" when ok).
    unloaded_contact
        The unloaded TCA found contact at this position (False: its unloaded TE is a
        placeholder 0, not a TE).
    """

    phi1: float
    te_unloaded_arcsec: float
    te_loaded_arcsec: float
    theta: float
    pairs: tuple[PairContact, ...]
    cells: tuple[PairCells, ...]
    pressure: tuple[Array, ...]
    solution: ContactSolution
    g_max_mm: float
    warnings: tuple[str, ...]
    left_out: tuple[tuple[int, int], ...] = ()
    status: str = "ok"
    status_reason: str = ""
    unloaded_contact: bool = True

    @classmethod
    def lost(cls, phi1: float, te_unloaded_arcsec: float, unloaded_contact: bool, reason: str):
        """A position that carries no load (status ``"lost"``, ``reason`` why): no pairs, an
        empty contact solution, the loaded TE equal to the unloaded one."""
        empty = ContactSolution(
            force=np.zeros(0),
            gap=np.zeros(0),
            active=np.zeros(0, dtype=bool),
            theta=0.0,
            iterations=0,
            equilibrium_residual=0.0,
            complementarity_residual=0.0,
            max_penetration=0.0,
            min_active_force=0.0,
        )
        return cls(
            phi1=phi1,
            te_unloaded_arcsec=te_unloaded_arcsec,
            te_loaded_arcsec=te_unloaded_arcsec,
            theta=0.0,
            pairs=(),
            cells=(),
            pressure=(),
            solution=empty,
            g_max_mm=0.0,
            warnings=(reason,),
            status="lost",
            status_reason=reason,
            unloaded_contact=unloaded_contact,
        )

    @property
    def n_pairs_in_contact(self) -> int:
        return sum(p.in_contact for p in self.pairs)

    @property
    def p_max_MPa(self) -> float:
        """The largest pressure of its pairs (those the fidelity gives: NaN ones left out)."""
        return max((p.p_max_MPa for p in self.pairs if not math.isnan(p.p_max_MPa)), default=0.0)


@dataclass(frozen=True)
class Excluded:
    """A position left out of the cycle's headline TE peak-to-peak.

    Attributes
    ----------
    index
        Position index.
    pinion_angle_deg
        Pinion angle φ1 (deg).
    status
        ``"lost"`` or ``"degenerate"`` (:attr:`LoadedPosition.status`).
    reason
        Why, in words.

    The one record of an excluded position: the headline of the loaded analysis
    (:class:`CycleHeadline`), the result model (:class:`fegear.results.Cycle`) and
    ``summary.json`` (``cycle.excluded_positions``) all hold it.
    """

    index: int
    pinion_angle_deg: float
    status: str
    reason: str


@dataclass(frozen=True)
class CycleHeadline:
    """The cycle's headline numbers, each meaning what it says (``docs/architecture.md``: the result
    model).

    A value is None when nothing physical can be reported, with the reason next to it.

    Attributes
    ----------
    n_positions
        Positions of the cycle.
    te_pp_unloaded_arcsec
        Unloaded TE peak-to-peak over the positions where the TCA found contact (None if fewer
        than two).
    te_pp_loaded_arcsec
        Loaded TE peak-to-peak over the usable positions (status ``"ok"``), None if fewer than
        two; ``te_pp_loaded_positions_used`` of them, ``te_pp_loaded_reason`` why None (""
        otherwise).
    excluded_positions
        The positions left out of it, with their reasons.
    contact_ratio_loaded
        Mean number of pairs carrying load over all positions.
    p_max_MPa
        Largest pressure away from the flank edges (:attr:`PairContact.p_interior_MPa`) over the
        usable positions, at ``p_max_position`` on pair ``p_max_pair``; None with
        ``p_max_reason`` when no loaded cell is away from an edge on a resolved patch.
    p_max_edge_MPa
        Largest pressure at a flank edge (singular, grid-dependent) over the usable positions,
        at ``p_max_edge_position`` on pair ``p_max_edge_pair``, where it touches
        ``p_max_edge_edges``; None when no usable position has an edge contact.
    positions_with_edge_contact
        Usable positions with a loaded pair at an edge (with an edge value, or none that the
        fidelity can give: :attr:`PairContact.pressure_reason`).
    """

    n_positions: int
    te_pp_unloaded_arcsec: float | None
    te_pp_loaded_arcsec: float | None
    te_pp_loaded_positions_used: int
    te_pp_loaded_reason: str
    excluded_positions: tuple[Excluded, ...]
    contact_ratio_loaded: float
    p_max_MPa: float | None
    p_max_reason: str
    p_max_position: int | None
    p_max_pair: tuple[int, int] | None
    p_max_edge_MPa: float | None
    p_max_edge_position: int | None
    p_max_edge_pair: tuple[int, int] | None
    p_max_edge_edges: tuple[str, ...]
    positions_with_edge_contact: tuple[int, ...]


def _none_usable(excluded: tuple[Excluded, ...]) -> str:
    """Why no position is usable, counted by status (the reasons are per position)."""
    counts = {s: sum(e.status == s for e in excluded) for s in ("degenerate", "lost")}
    parts = [f"{v} {k}" for k, v in counts.items() if v]
    return f"no usable position ({', '.join(parts)}: see the excluded positions)"


def _why_no_p_max(positions: tuple[LoadedPosition, ...], used: list[int]) -> str:
    """The reason for a null headline p_max (no usable pressure away from the edges)."""
    if not used:
        return _none_usable(
            tuple(
                Excluded(i, math.degrees(p.phi1), p.status, p.status_reason)
                for i, p in enumerate(positions)
            )
        )
    resolved = [q for i in used for q in positions[i].pairs if q.in_contact and q.resolved]
    if resolved:  # none of them has a cell away from the edges
        edges = sorted({e for q in resolved for e in q.edges})
        return (
            "every loaded contact is at a flank edge (" + ", ".join(edges) + "): its pressure "
            "is singular and grid-dependent, see p_max_edge_MPa"
        )
    return "no loaded patch away from the edges is resolved by the contact cells"


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
        That contact zone (:class:`fegear.ltca.zone.ContactZone`), or None.
    models
        The :class:`fegear.ltca.analysis.MemberModels` every position was solved on (those of
        ``zone``): what the displacement fields load, without building them again.
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
    models: Any = None

    @property
    def te_pp_unloaded_arcsec(self) -> float:
        """Raw: over every position (:meth:`headline` for the one to report)."""
        return float(np.ptp(self.te_unloaded_arcsec)) if self.phi1.size else 0.0

    @property
    def te_pp_loaded_arcsec(self) -> float:
        """Raw: over every position, lost and degenerate ones included (:meth:`headline`
        leaves them out)."""
        return float(np.ptp(self.te_loaded_arcsec)) if self.phi1.size else 0.0

    @property
    def contact_ratio_loaded(self) -> float:
        """Mean number of pairs in contact over the cycle (uniformly spaced positions)."""
        return float(np.mean(self.n_in_contact)) if self.phi1.size else 0.0

    @property
    def p_max_MPa(self) -> float:
        """Raw: the largest cell pressure anywhere, edges included (:meth:`headline`)."""
        return max((p.p_max_MPa for p in self.positions), default=0.0)

    def headline(self) -> CycleHeadline:
        """The headline numbers (:class:`CycleHeadline`): TE peak-to-peak over the usable
        positions only, p_max away from the edges, the edge value beside it with the edge
        named."""
        pos = self.positions
        used = [i for i, p in enumerate(pos) if p.status == "ok"]
        excluded = tuple(
            Excluded(i, math.degrees(float(p.phi1)), p.status, p.status_reason)
            for i, p in enumerate(pos)
            if p.status != "ok"
        )
        te_l = None
        reason = ""
        if len(used) >= 2:
            te_l = float(np.ptp(self.te_loaded_arcsec[used]))
        elif not used:
            reason = _none_usable(excluded)
        else:
            reason = f"only one usable position (of {len(pos)})"
        seen = [i for i, p in enumerate(pos) if p.unloaded_contact]
        te_u = float(np.ptp(self.te_unloaded_arcsec[seen])) if len(seen) >= 2 else None
        best = edge = None
        edge_positions = []
        for i in used:
            for q in pos[i].pairs:
                if not q.in_contact:
                    continue
                if q.p_interior_MPa is not None and (best is None or q.p_interior_MPa > best[0]):
                    best = (q.p_interior_MPa, i, (q.k, q.j))
                if q.p_edge_MPa is not None or (q.edges and q.pressure_reason):
                    if not edge_positions or edge_positions[-1] != i:
                        edge_positions.append(i)
                if q.p_edge_MPa is not None:
                    if edge is None or q.p_edge_MPa > edge[0]:
                        edge = (q.p_edge_MPa, i, (q.k, q.j), q.edges)
        return CycleHeadline(
            n_positions=len(pos),
            te_pp_unloaded_arcsec=te_u,
            te_pp_loaded_arcsec=te_l,
            te_pp_loaded_positions_used=len(used),
            te_pp_loaded_reason=reason,
            excluded_positions=excluded,
            contact_ratio_loaded=self.contact_ratio_loaded,
            p_max_MPa=None if best is None else float(best[0]),
            p_max_reason="" if best is not None else _why_no_p_max(pos, used),
            p_max_position=None if best is None else best[1],
            p_max_pair=None if best is None else best[2],
            p_max_edge_MPa=None if edge is None else float(edge[0]),
            p_max_edge_position=None if edge is None else edge[1],
            p_max_edge_pair=None if edge is None else edge[2],
            p_max_edge_edges=() if edge is None else tuple(edge[3]),
            positions_with_edge_contact=tuple(edge_positions),
        )
