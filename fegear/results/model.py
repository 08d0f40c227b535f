"""The result model of a gear run: typed, frozen, units in the names.

One model, built once from a run (:func:`fegear.results.build.build_result`), read by every
writer (``summary.json``: :func:`fegear.results.summary.summary_document`; the PNG titles; the
command line's report) and by the Python API (:class:`fegear.api.GearResult`). A saved
``summary.json`` loads back into the same model (:func:`fegear.results.summary.load_result`).

Names are those of ``summary.json`` (``positions[i]``, ``positions[i].pairs[j]``, ``cycle``):
a field of the model and the key that holds it in the file have one name. Units are in the
names: mm, N, N·m, MPa, deg, arcsec (the conventions: ``docs/conventions.md``). A headline that
nothing physical can give is None, with a ``*_reason`` beside it saying why (never a 0 standing
for nothing).

The typed fields are the numbers a user reads and compares; the records that only some runs
have and that are read as a whole (the contact ellipses, the TE harmonics, the root-stress
rows, the solver residuals of each position, the cylindrical section, the validity checks) are
kept as their JSON-ready mappings (``Mapping[str, Any]``: the keys of ``summary.json``, plain
floats, ints, strings, lists; ``docs/cli/README.md`` documents them).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from fegear.ltca.results import Excluded

__all__ = [
    "Checks",
    "Cycle",
    "Excluded",
    "GearRunResult",
    "PairLoad",
    "PatternCentre",
    "Position",
    "TCA_LOST",
]

Json = Mapping[str, Any]

#: Why a position of the unloaded TCA without contact is ``"lost"`` (a loaded position gives
#: its own reason).
TCA_LOST = "the flanks do not meet (unloaded TCA)"


@dataclass(frozen=True)
class PairLoad:
    """One tooth pair at one position (``summary.json``: ``positions[i].pairs[j]``).

    Attributes
    ----------
    index
        The pair's index at its position (``j``).
    pinion_tooth, gear_tooth
        The teeth of the pair (tooth 0 is the reference pair of the cycle).
    in_contact
        The pair carries load (fidelity ``tca``: it is the pair in unloaded contact).
    force_N
        Normal force (N); None at fidelity ``tca``.
    torque_Nm
        Its torque on member 2 (N·m); None at fidelity ``tca``.
    load_share
        Torque fraction (the shares of a position sum to 1); None at fidelity ``tca``.
    p_max_MPa
        Largest cell pressure of the pair (MPa), edges included; None at fidelity ``tca`` and
        where the fidelity gives no pressure (``pressure_reason``).
    p_interior_MPa, p_edge_MPa
        Largest pressure away from the flank edges and at them (singular); None where there is
        none.
    semi_major_mm, semi_minor_mm
        Equivalent-ellipse semi-axes of the loaded patch (mm); None at fidelity ``tca``.
    edge_contact
        The contact touches a boundary of a working flank; ``edges`` names them.
    edges
        The flank boundaries touched (loaded: ``"pinion tip"``, …; fidelity ``tca``:
        ``"pinion:tip"``, …, ``summary.json``'s comma-separated ``edge``).
    contact_point_mm
        ``(x, y, z)`` force centroid (TCA: contact point) in the fixed frame (mm), None when not
        in contact.
    backlash_mm
        Fidelity ``tca``: the pair's separation along the pinion normal (mm); else None.
    pressure_reason
        Why a loaded pair has no pressure ("" when it has one): ``hertz`` at a flank edge.
    p_peak_MPa
        Recovered peak pressure of the patch (MPa; :func:`fegear.mechanics.patch.measure_patch`);
        None at fidelity ``tca`` and where the fidelity gives no pressure.
    n_active_cells
        Contact cells in contact; None at fidelity ``tca``.
    cells_across_patch
        Contact cells across the patch's minor axis (None: the closed-form ``hertz`` fidelity,
        and fidelity ``tca``).
    resolved
        The cells resolve the patch (at least ``fegear.ltca.results.MIN_CELLS_ACROSS`` across
        it); None at fidelity ``tca``.
    """

    pinion_tooth: int
    gear_tooth: int
    in_contact: bool
    force_N: float | None
    torque_Nm: float | None
    load_share: float | None
    p_max_MPa: float | None
    p_interior_MPa: float | None
    p_edge_MPa: float | None
    semi_major_mm: float | None
    semi_minor_mm: float | None
    edge_contact: bool
    edges: tuple[str, ...]
    contact_point_mm: tuple[float, float, float] | None
    backlash_mm: float | None = None
    pressure_reason: str = ""
    index: int = 0
    p_peak_MPa: float | None = None
    n_active_cells: int | None = None
    cells_across_patch: float | None = None
    resolved: bool | None = None


@dataclass(frozen=True)
class Position:
    """One mesh position (``summary.json``: ``positions[i]``).

    Attributes
    ----------
    index
        Position index.
    pinion_angle_deg, gear_angle_deg
        Pinion angle φ1 and the gear's TCA-closed angle (deg).
    te_unloaded_arcsec, te_loaded_arcsec
        Transmission error (arcsec; negative: the gear lags); the loaded one None at fidelity
        ``tca``.
    n_pairs_in_contact
        Pairs carrying load (fidelity ``tca``: 1 with contact, else 0).
    status, status_reason
        ``"ok"``; ``"lost"`` (no contact), ``"degenerate"`` (a loaded patch the cells do not
        resolve): such positions are left out of the headline TE peak-to-peak.
    p_max_MPa
        Largest cell pressure of the position (MPa); None at fidelity ``tca``.
    pairs
        The modelled tooth pairs.
    unloaded_contact
        The unloaded TCA found contact here (fidelity ``tca``: ``summary.json``'s
        ``has_contact``).
    te_loaded_urad
        Loaded TE (µrad); None at fidelity ``tca``.
    elastic_lag_arcsec
        Elastic lag of member 2 (arcsec, positive against its driving sense; the loaded TE is
        the unloaded TE minus it); None at fidelity ``tca``.
    total_force_N
        Sum of the cell forces (N); None at fidelity ``tca``.
    solver
        The contact solver's iterations and residuals (mm, N), ``n_cells``, ``g_max_mm``; None
        at fidelity ``tca``.
    warnings
        The solver's notes at this position.
    members
        Per member the root stress of every tooth that can touch and the equilibrium of its
        stress solve (``summary.json``: ``positions[i].members``; empty without stress
        sectors).
    contact_ellipse
        The unloaded contact ellipse of the TCA's pair in contact (:mod:`fegear.tca.ellipse`);
        None without contact.
    """

    index: int
    pinion_angle_deg: float
    gear_angle_deg: float
    te_unloaded_arcsec: float
    te_loaded_arcsec: float | None
    n_pairs_in_contact: int
    status: str
    status_reason: str
    p_max_MPa: float | None
    pairs: tuple[PairLoad, ...]
    unloaded_contact: bool = True
    te_loaded_urad: float | None = None
    elastic_lag_arcsec: float | None = None
    total_force_N: float | None = None
    solver: Json | None = None
    warnings: tuple[str, ...] = ()
    members: tuple[Json, ...] = ()
    contact_ellipse: Json | None = None


@dataclass(frozen=True)
class Cycle:
    """The cycle's headline numbers (``summary.json``: ``cycle``).

    Each means what it says; a value that nothing physical can give is None and its
    ``*_reason`` says why (never a 0 standing for nothing). The loaded headlines are over the
    usable positions only (status ``"ok"``), p_max away from the flank edges.

    Attributes
    ----------
    n_positions
        Positions over one mesh cycle (2π/N1 of the pinion).
    torque2_Nm
        Resisting torque on member 2 (N·m).
    te_pp_unloaded_arcsec, te_pp_unloaded_reason
        Unloaded TE peak-to-peak (arcsec) over the positions with contact.
    te_pp_loaded_arcsec, te_pp_loaded_reason, te_pp_loaded_positions_used
        Loaded TE peak-to-peak (arcsec) over the usable positions (how many; None at fidelity
        ``tca``).
    excluded_positions
        The positions left out of it, with the reasons.
    contact_ratio_loaded, contact_ratio_reason
        Mean number of loaded pairs.
    p_max_MPa, p_max_reason, p_max_position, p_max_pair
        Largest pressure away from the flank edges (MPa), where (position, ``(pinion tooth,
        gear tooth)``).
    p_max_edge_MPa, p_max_edge_position, p_max_edge_pair, p_max_edge_edges
        Largest pressure at a flank edge (singular, grid-dependent), where, which edges.
    positions_with_edge_contact
        Usable positions with a loaded pair at an edge.
    max_equilibrium_residual
        Largest relative torque-balance residual of the contact solves (loaded fidelities).
    hertz_p0_max_MPa
        Fidelity ``tca``: the largest Hertz pressure of the unloaded contact points under the
        case's torque (MPa).
    root_stress_max_MPa, root_stress_reason
        Per member the largest tension-fillet maximum principal stress, the most compressive
        compression-fillet minimum principal stress and the largest von Mises stress of the
        loaded teeth over the cycle, with where (fidelities ``fe``, ``hybrid`` with the root
        stress asked for); None and the reason otherwise.
    max_pairs_in_contact, positions_without_contact
        Most loaded pairs at one position; positions where no pair carries load (fidelity
        ``tca``: without unloaded contact).
    max_complementarity_residual, max_penetration_mm
        The contact solves' largest complementarity residual and penetration (mm).
    root_stress_fillet_mm, root_stress_notes, root_stress_max_equilibrium_residual
        Per member the fillet element size of the stress sectors (mm), why coarser than asked,
        and the largest relative reaction residual of their solves.
    paint_thickness_mm
        Fidelity ``tca``: the paint thickness of the unloaded bearing pattern (mm).
    contact_ellipses
        The ranges of the unloaded contact ellipses over the cycle (:mod:`fegear.tca.ellipse`).
    te_harmonics
        The first mesh orders of the loaded and unloaded TE (loaded fidelities).
    contact_zone
        What the sectors modelled (``sector_teeth``, ``pairs``, ``gap_mm``), or None.
    """

    n_positions: int
    torque2_Nm: float
    te_pp_unloaded_arcsec: float | None
    te_pp_unloaded_reason: str
    te_pp_loaded_arcsec: float | None
    te_pp_loaded_reason: str
    te_pp_loaded_positions_used: int | None
    excluded_positions: tuple[Excluded, ...]
    contact_ratio_loaded: float | None
    contact_ratio_reason: str
    p_max_MPa: float | None
    p_max_reason: str
    p_max_position: int | None
    p_max_pair: tuple[int, int] | None
    p_max_edge_MPa: float | None
    p_max_edge_position: int | None
    p_max_edge_pair: tuple[int, int] | None
    p_max_edge_edges: tuple[str, ...]
    positions_with_edge_contact: tuple[int, ...]
    max_equilibrium_residual: float | None
    hertz_p0_max_MPa: float | None = None
    root_stress_max_MPa: Json | None = None
    root_stress_reason: str = ""
    max_pairs_in_contact: int | None = None
    positions_without_contact: int = 0
    max_complementarity_residual: float | None = None
    max_penetration_mm: float | None = None
    root_stress_fillet_mm: Json | None = None
    root_stress_notes: tuple[str, ...] = ()
    root_stress_max_equilibrium_residual: float | None = None
    paint_thickness_mm: float | None = None
    contact_ellipses: Json | None = None
    te_harmonics: Json | None = None
    contact_zone: Json | None = None


@dataclass(frozen=True)
class Checks:
    """The engagement checks made before the loaded analysis (``summary.json``: ``cycle``).

    Attributes
    ----------
    pinion_tip_clearance_mm, gear_tip_clearance_mm
        Tip-to-root clearance of each member's tip (mm; an interference is refused before).
    unloaded_interior_contact_fraction
        Part of the cycle with contact inside both working surfaces (1: all of it).
    contact_ratio_unloaded_below_1
        The unloaded contact ratio when below 1, else None.
    handover_missed_by_positions
        The positions miss the handover of such a contact ratio (the TE peak-to-peak and the
        contact ratio are then not reported).
    positions_without_unloaded_contact
        Positions where the flanks do not meet.
    contact_ratio_unloaded, path_length_mm, path_length_in_space_mm, path_ends
        One pair's unloaded contact over its whole contact interval: the interval over the
        angular pitch, the path length on the gear flank and in space (mm), what ends it
        (``"gear:tip"``, ``"pinion:tip"``, …). None with ``path_reason`` where no pair has
        interior contact.
    path_pinion_angles_deg
        The pinion angles (deg) where that pair's contact starts and ends; None with
        ``path_reason``.
    """

    pinion_tip_clearance_mm: float | None
    gear_tip_clearance_mm: float | None
    unloaded_interior_contact_fraction: float | None
    contact_ratio_unloaded_below_1: float | None
    handover_missed_by_positions: bool
    positions_without_unloaded_contact: tuple[int, ...]
    contact_ratio_unloaded: float | None
    path_length_mm: float | None
    path_length_in_space_mm: float | None
    path_ends: tuple[str, str] | None
    path_reason: str = ""
    path_pinion_angles_deg: tuple[float, float] | None = None


@dataclass(frozen=True)
class PatternCentre:
    """Where the bearing pattern is on one member's flank over the cycle (``summary.json``:
    ``pattern.<member>``; computed by :func:`fegear.output.flank_view.pattern_centre`).

    Attributes
    ----------
    member
        ``"pinion"`` or ``"gear"``.
    face_mm, profile_mm
        Centre ``(face, profile)`` (mm; :class:`fegear.output.flank_view.FlankFrame`): the
        force-weighted centroid of the loaded cells over all positions (loaded fidelities), or
        the mean of the unloaded contact points over the positions with contact, of every pair
        within the paint thickness (6.32 µm: where two pairs close together, both) (fidelity
        ``tca``). None with ``reason`` when there is none.
    face_range_mm, profile_range_mm
        ``(min, max)`` of the loaded cells (or of the path): the extent of the pattern.
    face_name, profile_name
        What the coordinates are.
    weighting
        ``"cell force"`` or ``"unloaded contact path"``.
    reason
        Why there is no centre ("" when there is).
    """

    member: str
    face_mm: float | None
    profile_mm: float | None
    face_range_mm: tuple[float, float] | None
    profile_range_mm: tuple[float, float] | None
    face_name: str
    profile_name: str
    weighting: str
    reason: str = ""

    def as_dict(self) -> dict[str, object]:
        """JSON-ready (``summary.json``: ``pattern``)."""
        return {
            "face_mm": self.face_mm,
            "profile_mm": self.profile_mm,
            "face_range_mm": None if self.face_range_mm is None else list(self.face_range_mm),
            "profile_range_mm": (
                None if self.profile_range_mm is None else list(self.profile_range_mm)
            ),
            "face": self.face_name,
            "profile": self.profile_name,
            "weighting": self.weighting,
            "reason": self.reason,
        }


@dataclass(frozen=True)
class GearRunResult:
    """Everything a gear run reports (``summary.json`` without its ``files`` list).

    Attributes
    ----------
    case_name, kind
        The case's name and pair kind (``summary.json``: ``case``, ``kind``).
    fidelity
        ``"hybrid"``, ``"fe"``, ``"hertz"`` or ``"tca"``.
    level
        Sector mesh level (None at fidelity ``tca``).
    inputs
        The case as run (``summary.json``: ``inputs``, the case file's sections).
    cycle
        The headline numbers.
    checks
        The engagement checks made before the analysis (None for a run without them).
    positions
        Per position, each with its pairs.
    pattern
        ``{"pinion": PatternCentre, "gear": PatternCentre}``, or None when not computed.
    warnings
        Warnings that change the meaning of a headline, then the solver's notes.
    seconds
        Wall time per stage (s; ``summary.json``: ``timings_s``).
    mesh
        Per member the stress sector's size and solver (fidelities with cells), or None.
    validity
        The checks of the model's validity range (loaded fidelities), or None.
    cylindrical
        The cylindrical pair's section (contact ratios, load distribution), or None.
    ease_off
        The numbers that describe the pair's ease-off (:mod:`fegear.results.ease_off`), or
        None.
    cache
        The artefact-cache lookups of the run (folder, artefacts read and built), or None.
    versions
        Python and package versions of the run.
    """

    case_name: str
    kind: str
    fidelity: str
    level: int | None
    inputs: Json
    cycle: Cycle
    checks: Checks | None
    positions: tuple[Position, ...]
    pattern: Mapping[str, PatternCentre] | None
    warnings: tuple[str, ...]
    seconds: Mapping[str, float]
    mesh: Json | None = None
    validity: Json | None = None
    cylindrical: Json | None = None
    ease_off: Json | None = None
    cache: Json | None = None
    versions: Mapping[str, str] = field(default_factory=dict)

    @property
    def loaded(self) -> bool:
        """A loaded run (every fidelity but the unloaded ``tca``)."""
        return self.fidelity != "tca"
