"""The Python API: load a case, change it, run it, read and write its results.

::

    import fegear

    case = fegear.load_case("cases/face_gear_nominal.toml")
    result = fegear.run(case.with_errors(dgamma_deg=0.02), fidelity="tca")
    print(result.cycle.te_pp_unloaded_arcsec, result.pattern["gear"].face_mm)
    result.write("out/dgamma")          # the files of `fegear run`

A case is frozen: :meth:`~fegear.io.gear_case.GearCase.replace` and
:meth:`~fegear.io.gear_case.GearCase.with_errors` return a new case validated exactly like a case
file (a bad field raises the :class:`~fegear.errors.InputError` the case file would).
:func:`run` returns a :class:`GearResult` (gear pairs) or a :class:`HertzResult` (the Hertz
scene): typed, frozen, with the numbers of ``summary.json`` — the same values, built from the
same document — and ``write(folder)``, which writes the files ``fegear run`` writes (the command
is a layer over this module). Units are in the names (mm, N, MPa, N·m, arcsec, deg).

For scripts that compare runs (one per installation error, say): :func:`table` (a text table of
the headline numbers and the pattern shift), :func:`plot_te` and :func:`plot_patterns`.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fegear.case import HertzCase
from fegear.case import load_case as _load_case
from fegear.errors import InputError
from fegear.io.gear_case import ANALYSIS, FIDELITIES, N_LEVELS, GearCase
from fegear.output.flank_view import PatternCentre

__all__ = [
    "Checks",
    "Cycle",
    "Excluded",
    "GearResult",
    "HertzResult",
    "PairLoad",
    "Position",
    "Progress",
    "load_case",
    "plot_patterns",
    "plot_te",
    "run",
    "table",
]

log = logging.getLogger(__name__)

#: ``progress(stage, i, n)``: called at the start of each stage (``i = n = None``; gear pairs:
#: ``"geometry"``, ``"tca"`` or ``"models"``, ``"positions"``, ``"displacements"``; the Hertz
#: scene: ``"study"`` with ``i`` of ``n`` levels, ``"run"``) and after each mesh position
#: (``"positions"``, ``i`` of ``n``).
Progress = Callable[[str, "int | None", "int | None"], None]


def load_case(path: str | Path) -> GearCase | HertzCase:
    """Read and validate a case file (TOML).

    Parameters
    ----------
    path
        The case file.

    Returns
    -------
    GearCase or HertzCase
        A gear pair (``kind`` ``"face_gear"``, ``"spur"``, ``"spiral_bevel"``) or the Hertz
        scene (``"hertz_scene"``).

    Raises
    ------
    InputError
        A missing or unreadable file, or any problem of its content, naming the case-file
        field, the value and the allowed range.
    """
    return _load_case(path)


# --------------------------------------------------------------------------------------------
# Gear results
# --------------------------------------------------------------------------------------------


def _opt_float(x: Any) -> float | None:
    return None if x is None else float(x)


def _tuple_or_none(x: Any) -> tuple | None:
    return None if x is None else tuple(x)


@dataclass(frozen=True)
class PairLoad:
    """One tooth pair at one position (``summary.json``: ``positions[i].pairs[j]``).

    Attributes
    ----------
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
    pressure_reason
        Why a loaded pair has no pressure ("" when it has one): ``hertz`` at a flank edge.
    semi_major_mm, semi_minor_mm
        Equivalent-ellipse semi-axes of the loaded patch (mm).
    edge_contact
        The contact touches a boundary of a working flank; ``edges`` names them.
    contact_point_mm
        ``(x, y, z)`` force centroid (TCA: contact point) in the fixed frame (mm), None when not
        in contact.
    backlash_mm
        Fidelity ``tca``: the pair's separation along the pinion normal (mm); else None.
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

    @classmethod
    def _from(cls, q: Mapping[str, Any]) -> PairLoad:
        edges = q.get("edges")
        if edges is None:  # tca: one string "pinion:tip,gear:v_start"
            edges = [e for e in str(q.get("edge", "")).split(",") if e]
        return cls(
            pinion_tooth=int(q["pinion_tooth"]),
            gear_tooth=int(q["gear_tooth"]),
            in_contact=bool(q["in_contact"]),
            force_N=_opt_float(q.get("force_N")),
            torque_Nm=_opt_float(q.get("torque_Nm")),
            load_share=_opt_float(q.get("load_share")),
            p_max_MPa=_opt_float(q.get("p_max_MPa")),
            p_interior_MPa=_opt_float(q.get("p_interior_MPa")),
            p_edge_MPa=_opt_float(q.get("p_edge_MPa")),
            semi_major_mm=_opt_float(q.get("semi_major_mm")),
            semi_minor_mm=_opt_float(q.get("semi_minor_mm")),
            edge_contact=bool(q.get("edge_contact", False)),
            edges=tuple(edges),
            contact_point_mm=_tuple_or_none(q.get("contact_point_mm")),
            backlash_mm=_opt_float(q.get("backlash_mm")),
            pressure_reason=str(q.get("pressure_reason", "")),
        )


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

    @classmethod
    def _from(cls, p: Mapping[str, Any]) -> Position:
        pairs = tuple(PairLoad._from(q) for q in p["pairs"])
        if "status" in p:
            status, why = str(p["status"]), str(p.get("status_reason", ""))
        else:  # tca
            ok = bool(p.get("has_contact", True))
            status, why = ("ok", "") if ok else ("lost", "the flanks do not meet (unloaded TCA)")
        return cls(
            index=int(p["index"]),
            pinion_angle_deg=float(p["pinion_angle_deg"]),
            gear_angle_deg=float(p["gear_angle_deg"]),
            te_unloaded_arcsec=float(p["te_unloaded_arcsec"]),
            te_loaded_arcsec=_opt_float(p.get("te_loaded_arcsec")),
            n_pairs_in_contact=int(p.get("n_pairs_in_contact", sum(q.in_contact for q in pairs))),
            status=status,
            status_reason=why,
            p_max_MPa=_opt_float(p.get("p_max_MPa")),
            pairs=pairs,
        )


@dataclass(frozen=True)
class Excluded:
    """A position left out of the headline TE peak-to-peak (``cycle.excluded_positions``).

    Attributes
    ----------
    index, pinion_angle_deg
        Which position.
    status, reason
        ``"lost"`` or ``"degenerate"``, and why.
    """

    index: int
    pinion_angle_deg: float
    status: str
    reason: str


@dataclass(frozen=True)
class Cycle:
    """The cycle's headline numbers, as ``summary.json`` reports them (``cycle``).

    Each means what it says; a value that nothing physical can give is None and its
    ``*_reason`` says why (never a 0 standing for nothing).

    Attributes
    ----------
    n_positions
        Positions over one mesh cycle (2π/N1 of the pinion).
    torque2_Nm
        Resisting torque on member 2 (N·m).
    te_pp_unloaded_arcsec, te_pp_unloaded_reason
        Unloaded TE peak-to-peak (arcsec) over the positions with contact.
    te_pp_loaded_arcsec, te_pp_loaded_reason, te_pp_loaded_positions_used
        Loaded TE peak-to-peak (arcsec) over the usable positions (how many).
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
        ``summary.json``'s ``cycle.root_stress_max_MPa``: per member the largest tension-fillet
        maximum principal stress, the most compressive compression-fillet minimum principal
        stress and the largest von Mises stress of the loaded teeth over the cycle, with where
        (fidelities ``fe``, ``hybrid``); None and the reason otherwise.
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
    root_stress_max_MPa: Mapping[str, Any] | None = None
    root_stress_reason: str = ""

    @classmethod
    def _from(cls, c: Mapping[str, Any]) -> Cycle:
        at = c.get("p_max_at") or {}
        edge = c.get("p_max_edge_at") or {}
        return cls(
            n_positions=int(c["n_positions"]),
            torque2_Nm=float(c["torque2_Nm"]),
            te_pp_unloaded_arcsec=_opt_float(c.get("te_pp_unloaded_arcsec")),
            te_pp_unloaded_reason=str(c.get("te_pp_unloaded_reason", "")),
            te_pp_loaded_arcsec=_opt_float(c.get("te_pp_loaded_arcsec")),
            te_pp_loaded_reason=str(c.get("te_pp_loaded_reason", "")),
            te_pp_loaded_positions_used=c.get("te_pp_loaded_positions_used"),
            excluded_positions=tuple(
                Excluded(int(e["index"]), float(e["pinion_angle_deg"]), e["status"], e["reason"])
                for e in c.get("excluded_positions", ())
            ),
            contact_ratio_loaded=_opt_float(c.get("contact_ratio_loaded")),
            contact_ratio_reason=str(c.get("contact_ratio_reason", "")),
            p_max_MPa=_opt_float(c.get("p_max_MPa")),
            p_max_reason=str(c.get("p_max_reason", "")),
            p_max_position=at.get("position"),
            p_max_pair=_tuple_or_none(at.get("pair")),
            p_max_edge_MPa=_opt_float(c.get("p_max_edge_MPa")),
            p_max_edge_position=edge.get("position"),
            p_max_edge_pair=_tuple_or_none(edge.get("pair")),
            p_max_edge_edges=tuple(edge.get("edges", ())),
            positions_with_edge_contact=tuple(c.get("positions_with_edge_contact", ())),
            max_equilibrium_residual=_opt_float(c.get("max_equilibrium_residual")),
            hertz_p0_max_MPa=_opt_float(c.get("hertz_p0_max_MPa")),
            root_stress_max_MPa=c.get("root_stress_max_MPa"),
            root_stress_reason=str(c.get("root_stress_reason", "")),
        )


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

    @classmethod
    def _from(cls, c: Mapping[str, Any]) -> Checks:
        tip = c.get("tip_clearance_mm") or {}
        return cls(
            pinion_tip_clearance_mm=_opt_float(tip.get("pinion_tip")),
            gear_tip_clearance_mm=_opt_float(tip.get("gear_tip")),
            unloaded_interior_contact_fraction=_opt_float(
                c.get("unloaded_interior_contact_fraction")
            ),
            contact_ratio_unloaded_below_1=_opt_float(c.get("contact_ratio_unloaded_below_1")),
            handover_missed_by_positions=bool(c.get("handover_missed_by_positions", False)),
            positions_without_unloaded_contact=tuple(
                c.get("positions_without_unloaded_contact", ())
            ),
            contact_ratio_unloaded=_opt_float(c.get("contact_ratio_unloaded")),
            path_length_mm=_opt_float(c.get("path_length_mm")),
            path_length_in_space_mm=_opt_float(c.get("path_length_in_space_mm")),
            path_ends=_tuple_or_none(c.get("path_ends")),
            path_reason=str(c.get("path_reason", "")),
        )


@dataclass(frozen=True)
class GearResult:
    """A gear-pair run: the numbers of ``summary.json``, typed, and the files on request.

    Attributes
    ----------
    case
        The case as run (fidelity and level applied).
    fidelity
        ``"hybrid"``, ``"fe"``, ``"hertz"`` or ``"tca"``.
    level
        Sector mesh level (None at fidelity ``tca``).
    cycle
        The headline numbers (:class:`Cycle`).
    checks
        The engagement checks (:class:`Checks`).
    positions
        Per position (:class:`Position`), each with its pairs (:class:`PairLoad`).
    pattern
        ``{"pinion": PatternCentre, "gear": PatternCentre}``: where the bearing pattern is on
        each member's flank (:class:`fegear.output.flank_view.PatternCentre`, flank coordinates in
        mm: ``face_mm`` along the face, ``profile_mm`` up the profile).
    warnings
        Warnings that change the meaning of a headline (and the solver's notes).
    seconds
        Wall time per stage (s).
    cache
        What the run read from the artefact cache and what it built
        (:class:`fegear.store.cache.CacheUse`).
    summary
        The ``summary.json`` document (without its ``files`` list, which :meth:`write` fills).
    run
        The full run (:class:`fegear.pipeline.run.GearRun`: contact cells, pressure fields,
        displacement fields) for what the typed fields do not hold.
    """

    case: GearCase
    fidelity: str
    level: int | None
    cycle: Cycle
    checks: Checks
    positions: tuple[Position, ...]
    pattern: Mapping[str, PatternCentre]
    warnings: tuple[str, ...]
    seconds: Mapping[str, float]
    cache: Any
    summary: Mapping[str, Any] = field(repr=False, compare=False)
    run: Any = field(repr=False, compare=False)
    _views: Any = field(default=None, repr=False, compare=False)

    @property
    def pinion_angle_deg(self) -> np.ndarray:
        """``(n,)`` pinion angles of the positions (deg)."""
        return np.array([p.pinion_angle_deg for p in self.positions])

    @property
    def te_unloaded_arcsec(self) -> np.ndarray:
        """``(n,)`` unloaded TE (arcsec)."""
        return np.array([p.te_unloaded_arcsec for p in self.positions])

    @property
    def te_loaded_arcsec(self) -> np.ndarray:
        """``(n,)`` loaded TE (arcsec; NaN at fidelity ``tca``)."""
        return np.array(
            [np.nan if p.te_loaded_arcsec is None else p.te_loaded_arcsec for p in self.positions]
        )

    def write(self, folder: str | Path, overwrite: bool = False) -> tuple[Path, ...]:
        """Write the files of ``fegear run`` into ``folder`` (made if missing): ``summary.json``,
        ``cycle.pvd`` with ``vtk/`` (sectors, contact cells, flank views), the PNGs; each file
        atomically, ``summary.json`` last. The folder holds one run
        (:mod:`fegear.store.outputs`): the files of an earlier run written there are removed
        first, and a folder with files fegear did not write is refused unless ``overwrite``
        (then its other files are kept). Returns the paths.

        Raises
        ------
        InputError
            ``folder`` cannot be written (a file, or no permission), or holds other files and
            ``overwrite`` is False.
        """
        from fegear.output.gear_output import write_gear_outputs
        from fegear.store.outputs import inspect_output_folder, output_run

        with output_run(inspect_output_folder(folder, overwrite, "folder")) as out:
            return tuple(write_gear_outputs(out, self.run, self._views))

    def root_stress(self, member: str, what: str = "tension") -> dict[int, np.ndarray]:
        """Root stress of each tooth of ``member`` (``"pinion"``/``"gear"``) that can touch:
        ``{tooth: (n_positions,) MPa}``, ``what`` one of ``"tension"`` (largest maximum
        principal stress in the fillet on the loaded-flank side), ``"compression"`` (smallest
        minimum principal stress on the other side), ``"von_mises"`` (NaN without contact;
        :mod:`fegear.fem.stress`).

        Raises
        ------
        InputError
            A bad ``member`` or ``what``, or a fidelity without stress sectors (``tca``,
            ``hertz``).
        """
        fields = {"tension": "tension_MPa", "compression": "compression_MPa",
                  "von_mises": "von_mises_MPa"}  # fmt: skip
        if what not in fields:
            raise InputError("what", what, f"one of {sorted(fields)}")
        mf = next((m for m in self.run.members if m.name == member), None)
        if member not in ("pinion", "gear"):
            raise InputError("member", member, "'pinion' or 'gear'")
        if mf is None or not mf.root:
            raise InputError("fidelity", self.fidelity, "'hybrid' or 'fe' (cell loads on the FE)")
        return {t: mf.root_series(t, fields[what]) for t in mf.root_teeth}

    def plot_pattern(self, path: str | Path, member: str = "gear") -> Path:
        """The bearing pattern over the cycle on one member's flank as a PNG: the largest
        pressure each point of the flank saw (loaded fidelities), with the working-surface
        outline; ``member`` ``"gear"`` or ``"pinion"``.

        Raises
        ------
        InputError
            A bad ``member``, or a fidelity without contact cells (``tca``, ``hertz``: use
            :func:`plot_patterns` for the contact path).
        """
        from fegear.output.flank_view import plot_flank_pattern

        if member not in ("pinion", "gear"):
            raise InputError("member", member, "'pinion' or 'gear'")
        if not self._views.patches or (self.run.kind is not None and not self.run.kind.cells):
            raise InputError(
                "fidelity", self.fidelity, "'hybrid' or 'fe' (a fidelity with contact cells)"
            )
        return plot_flank_pattern(
            self._views.frames[member],
            [p[member] for p in self._views.patches],
            Path(path),
            f"{self.case.name}: {self.fidelity} level {self.level}",
            self.cycle.p_max_MPa,
        )


def _gear_result(run, views) -> GearResult:
    from fegear.output.gear_output import gear_summary

    doc = gear_summary(run, None, views)
    doc.pop("files", None)
    return GearResult(
        case=run.case,
        fidelity=doc["fidelity"],
        level=doc["level"],
        cycle=Cycle._from(doc["cycle"]),
        checks=Checks._from(doc["cycle"]),
        positions=tuple(Position._from(p) for p in doc["positions"]),
        pattern=dict(views.pattern),
        warnings=tuple(doc["warnings"]),
        seconds=dict(doc["timings_s"]),
        cache=run.cache,
        summary=doc,
        run=run,
        _views=views,
    )


# --------------------------------------------------------------------------------------------
# Hertz scene
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class HertzResult:
    """A Hertz-scene run: the FE contact of a crowned roller on a block against Hertz.

    Attributes
    ----------
    case
        The case.
    fidelity, level
        How it ran.
    p0_MPa, a_mm, b_mm, approach_mm
        Peak pressure (MPa), patch semi-axes and rigid approach (mm) of the FE contact.
    hertz_p0_MPa, hertz_a_mm, hertz_b_mm
        The closed-form Hertz values.
    errors
        ``{"p0", "a", "b", "approach"}``: relative errors against Hertz.
    study
        The levels of a convergence study (:class:`fegear.scenes.hertz_scene.HertzLevelResult`).
    rates
        Observed convergence rates of the study (``{"p0", "a", "b"}``).
    warnings
        Warnings of the run.
    level_result
        The run's :class:`~fegear.scenes.hertz_scene.HertzLevelResult` (fields, cells).
    """

    case: HertzCase
    fidelity: str
    level: int
    p0_MPa: float
    a_mm: float
    b_mm: float
    approach_mm: float
    hertz_p0_MPa: float
    hertz_a_mm: float
    hertz_b_mm: float
    errors: Mapping[str, float]
    study: tuple[Any, ...] = field(repr=False)
    rates: Mapping[str, float] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    level_result: Any = field(default=None, repr=False, compare=False)

    def write(self, folder: str | Path, overwrite: bool = False) -> tuple[Path, ...]:
        """Write the files of ``fegear run`` for the scene into ``folder`` (``summary.json``,
        ``block.vtu``, ``roller.vtu``, ``contact_cells.vtu``, ``pressure_map.png``,
        ``convergence.png`` with a study): one run per folder, as :meth:`GearResult.write`.
        Returns the paths."""
        from fegear.output.hertz_output import write_hertz_outputs
        from fegear.store.outputs import inspect_output_folder, output_run

        with output_run(inspect_output_folder(folder, overwrite, "folder")) as out:
            return tuple(
                write_hertz_outputs(
                    out,
                    self.case.name,
                    self.case.scene,
                    self.level_result,
                    list(self.study) or None,
                    dict(self.rates),
                )
            )


def _run_hertz(
    case: HertzCase,
    fidelity: str | None,
    level: int | None,
    backend: str | None,
    study: Sequence[int] | None,
    progress: Progress | None,
) -> HertzResult:
    from fegear.convergence import observed_rate
    from fegear.scenes.hertz_scene import CELLS_ACROSS_MINOR, run_level

    n = len(CELLS_ACROSS_MINOR)
    if backend is not None:
        ANALYSIS.key("backend").check("backend", backend)  # the case file's rule
    if fidelity not in (None, "fe", "hybrid"):
        raise InputError("fidelity", fidelity, "'fe' or 'hybrid' for the Hertz scene")
    level = case.level if level is None else level
    if not (isinstance(level, int) and 0 <= level < n):
        raise InputError("level", level, f"an integer in [0, {n - 1}]")
    levels = case.study_levels if study is None else tuple(sorted(set(study)))
    for lv in levels:
        if not (isinstance(lv, int) and 0 <= lv < n):
            raise InputError("study", lv, f"levels in [0, {n - 1}]")
    fidelity = fidelity or case.fidelity
    kw = {"backend": backend or case.backend, "fidelity": fidelity, "fe_level": case.fe_level}
    say = progress or (lambda stage, i, k: None)
    rows = []
    for i, lv in enumerate(levels):
        say("study", i + 1, len(levels))
        rows.append(run_level(case.scene, lv, **kw))
    rates: dict[str, float] = {}
    if len(rows) >= 2:
        h = [r.cell_size_mm for r in rows]
        for key in ("p0", "a", "b"):
            try:
                rates[key] = observed_rate(h, [r.error(key) for r in rows])
            except InputError:
                pass
    say("run", None, None)
    res = run_level(case.scene, level, with_fields=True, **kw)  # logs its warnings
    return HertzResult(
        case=case,
        fidelity=fidelity,
        level=level,
        p0_MPa=res.p0_MPa,
        a_mm=res.a_mm,
        b_mm=res.b_mm,
        approach_mm=res.approach_mm,
        hertz_p0_MPa=res.hertz.p0_MPa,
        hertz_a_mm=res.hertz.a_mm,
        hertz_b_mm=res.hertz.b_mm,
        errors={k: res.error(k) for k in ("p0", "a", "b", "approach")},
        study=tuple(rows),
        rates=rates,
        warnings=tuple(res.warnings),
        level_result=res,
    )


# --------------------------------------------------------------------------------------------
# run
# --------------------------------------------------------------------------------------------


_CLEANED: set[str] = set()


def _clean_cache_temps() -> None:
    """Remove the temporary files that interrupted writes left in the artefact cache
    (:func:`fegear.store.files.clean_stale_temps`: their writer is gone), once per process and
    cache folder."""
    from fegear.store.cache import cache_root
    from fegear.store.files import clean_stale_temps

    root = cache_root()
    if str(root) in _CLEANED:
        return
    _CLEANED.add(str(root))
    gone = clean_stale_temps(root, recursive=True)
    if gone:
        log.info("removed %d temporary files of interrupted writes from %s", len(gone), root)


def run(
    case: GearCase | HertzCase,
    *,
    fidelity: str | None = None,
    level: int | None = None,
    workers: int | None = None,
    backend: str | None = None,
    root_stress: bool | None = None,
    study: Sequence[int] | None = None,
    progress: Progress | None = None,
    notify: Callable[[str], None] | None = None,
) -> GearResult | HertzResult:
    """Run a case.

    Parameters
    ----------
    case
        From :func:`load_case` (or its ``replace``/``with_errors``).
    fidelity
        Overrides the case's. Gear pairs: ``"hybrid"`` (FE + half-space near field, the
        default of every case), ``"fe"``, ``"hertz"`` (per-pair Hertz + lumped FE compliance),
        ``"tca"`` (unloaded, rigid: TE, contact path, pattern; seconds). Hertz scene: ``"fe"``
        or ``"hybrid"``.
    level
        Mesh level, 0 (coarsest) … 4; overrides the case's.
    workers
        Gear pairs: processes solving the mesh positions (None: ``$FEGEAR_WORKERS``, else one
        per core); the result does not depend on it. Ignored by the Hertz scene.
    backend
        Sparse direct solver ``"auto"``, ``"pardiso"``, ``"superlu"``; overrides the case's.
    root_stress
        Gear pairs at ``fe``/``hybrid``: compute the tooth root stress (the sectors remeshed
        with refined fillets and solved once more per member: on the seed face gear about
        1-2 min and 8 GB more); overrides ``[analysis] root_stress`` (default False).
    study
        Hertz scene: levels of a mesh-convergence study (overrides ``[study] levels``).
    progress
        ``progress(stage, i, n)`` (:data:`Progress`).
    notify
        Gear pairs: ``notify(text)`` with each warning of the engagement checks as soon as it is
        made, before the loaded analysis (they are in the result's ``warnings`` too; without
        ``notify`` they are logged).

    Returns
    -------
    GearResult or HertzResult
        By the kind of the case.

    Raises
    ------
    InputError
        A bad override, design data the geometry refuses, or an installation under which the
        flanks cannot mesh (no contact anywhere, a tip running into the mate's root), each named
        and decided before the FE work; an unusable cache folder (``FEGEAR_CACHE``).
    FegearError
        The analysis failed (mesh, solver).
    """
    from fegear.store.cache import check_cache_root

    check_cache_root()
    _clean_cache_temps()
    if isinstance(case, HertzCase):
        if root_stress:
            raise InputError("root_stress", root_stress, "absent for the Hertz scene (no teeth)")
        return _run_hertz(case, fidelity, level, backend, study, progress)
    if not isinstance(case, GearCase):
        raise InputError("case", type(case).__name__, "a case from fegear.load_case")
    from dataclasses import replace

    from fegear.output.gear_output import flank_views
    from fegear.pipeline.pair import build_pair
    from fegear.pipeline.run import run_gear_case

    if study is not None:
        raise InputError("study", study, "absent for a gear case (a Hertz-scene option)")
    if backend is not None:
        ANALYSIS.key("backend").check("backend", backend)  # the case file's rule
        case = replace(case, backend=backend)
    if root_stress is not None:
        if not isinstance(root_stress, bool):
            raise InputError("root_stress", root_stress, "True or False")
        case = replace(case, root_stress=root_stress)
    fid = case.fidelity if fidelity is None else fidelity
    lvl = case.level if level is None else level
    if fid not in FIDELITIES:
        raise InputError("fidelity", fid, "'fe', 'hertz', 'hybrid' or 'tca' for gear pairs")
    if not (isinstance(lvl, int) and not isinstance(lvl, bool) and 0 <= lvl < N_LEVELS):
        raise InputError("level", lvl, f"an integer in [0, {N_LEVELS - 1}]")
    if workers is not None and not (isinstance(workers, int) and workers >= 1):
        raise InputError("workers", workers, "an integer >= 1")
    pair = build_pair(case)  # bad design data is refused here, before any work
    gear_run = run_gear_case(
        case,
        fidelity=fid,
        level=lvl,
        progress=progress,
        pair=pair,
        workers=workers,
        notify=notify,
    )
    return _gear_result(gear_run, flank_views(gear_run))


# --------------------------------------------------------------------------------------------
# Comparing runs
# --------------------------------------------------------------------------------------------


def _fmt(x: float | None, spec: str) -> str:
    return "—" if x is None or not math.isfinite(x) else format(x, spec)


def table(
    results: Mapping[str, GearResult], reference: str | None = None, member: str = "gear"
) -> str:
    """A text table of runs side by side: TE peak-to-peak, contact ratio, p_max and where the
    bearing pattern is on ``member``'s flank, with its shift against ``reference``.

    Parameters
    ----------
    results
        ``{label: result}``, in the order of the rows.
    reference
        Label of the reference row of the shifts (default: the first result without
        installation errors, else the first).
    member
        ``"gear"`` or ``"pinion"``: whose flank the pattern is measured on.

    Returns
    -------
    str
        The table (Markdown): ``TE p-p`` unloaded / loaded (arcsec), the unloaded contact ratio
        of one pair's path and the loaded contact ratio, p_max away from the edges (MPa), the
        pattern centre ``face`` and ``profile`` (mm, :class:`~fegear.output.flank_view.FlankFrame`)
        and their shifts ``Δface``, ``Δprofile`` against the reference ("—": not reported).
    """
    from fegear.io.gear_case import error_fields

    if not results:
        raise InputError("results", "{}", "at least one result")
    if member not in ("pinion", "gear"):
        raise InputError("member", member, "'pinion' or 'gear'")
    labels = list(results)
    if reference is None:
        reference = next((k for k in labels if not error_fields(results[k].case)), labels[0])
    if reference not in results:
        raise InputError("reference", reference, f"one of the labels {labels}")
    ref = results[reference].pattern[member]
    first = results[labels[0]].pattern[member]
    head = (
        "| case | TE p-p unloaded (arcsec) | TE p-p loaded (arcsec) | contact ratio unloaded | "
        "contact ratio loaded | p_max (MPa) | face (mm) | profile (mm) | Δface (mm) | "
        "Δprofile (mm) |"
    )
    rows = [
        f"{member} flank: face = {first.face_name}; profile = {first.profile_name}; "
        f"pattern centre by {first.weighting}; shifts against {reference!r}",
        "",
        head,
        "|" + "---|" * 10,
    ]
    for label, r in results.items():
        c, pc = r.cycle, r.pattern[member]
        dface = dprof = None
        if pc.face_mm is not None and ref.face_mm is not None:
            dface, dprof = pc.face_mm - ref.face_mm, pc.profile_mm - ref.profile_mm
        rows.append(
            f"| {label} | {_fmt(c.te_pp_unloaded_arcsec, '.2f')} | "
            f"{_fmt(c.te_pp_loaded_arcsec, '.2f')} | "
            f"{_fmt(r.checks.contact_ratio_unloaded, '.3f')} | "
            f"{_fmt(c.contact_ratio_loaded, '.2f')} | {_fmt(c.p_max_MPa, '.0f')} | "
            f"{_fmt(pc.face_mm, '.2f')} | {_fmt(pc.profile_mm, '.3f')} | {_fmt(dface, '+.2f')} | "
            f"{_fmt(dprof, '+.3f')} |"
        )
    return "\n".join(rows)


def _savefig(fig, path: str | Path) -> Path:
    import matplotlib.pyplot as plt

    from fegear.store.files import atomic_write

    fig.tight_layout()
    out = atomic_write(Path(path), lambda q: fig.savefig(q, format="png", dpi=110))
    plt.close(fig)
    return out


def plot_te(results: Mapping[str, GearResult], path: str | Path, title: str = "") -> Path:
    """The TE curves of several runs on one figure (unloaded dashed, loaded solid), PNG.

    Parameters
    ----------
    results
        ``{label: result}``.
    path
        The PNG (its folder is made if missing).
    title
        Figure title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for i, (label, r) in enumerate(results.items()):
        color = f"C{i % 10}"
        ax.plot(r.pinion_angle_deg, r.te_unloaded_arcsec, "--", color=color, lw=1,
                label=f"{label} unloaded")  # fmt: skip
        if np.isfinite(r.te_loaded_arcsec).any():
            ax.plot(r.pinion_angle_deg, r.te_loaded_arcsec, "-", color=color, lw=1.5,
                    label=f"{label} loaded")  # fmt: skip
    ax.set_xlabel("pinion angle φ1 (deg)")
    ax.set_ylabel("TE (arcsec; negative: the gear lags)")
    ax.set_title(title or "transmission error over one mesh cycle", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return _savefig(fig, path)


def plot_patterns(
    results: Mapping[str, GearResult], path: str | Path, member: str = "gear", title: str = ""
) -> Path:
    """Where the contact is on one member's flank for several runs, on one figure (PNG):
    the unloaded contact path (fidelity ``tca``) or the loaded cells' force centroids per
    position (loaded fidelities), the pattern centre (+) and the working-surface outline.

    Parameters
    ----------
    results
        ``{label: result}`` (runs of the same pair).
    path
        The PNG (its folder is made if missing).
    member
        ``"gear"`` or ``"pinion"``.
    title
        Figure title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if member not in ("pinion", "gear"):
        raise InputError("member", member, "'pinion' or 'gear'")
    fig, ax = plt.subplots(figsize=(8, 4.2))
    frame = None
    for i, (label, r) in enumerate(results.items()):
        color = f"C{i % 10}"
        v = r._views
        frame = v.frames[member]
        if r.run.cycle is None:
            t = r.run.tca
            uv = (t.pinion_uv if member == "pinion" else t.gear_uv)[t.has_contact]
            xy = frame.coordinates(uv[:, 0], uv[:, 1])
            ax.plot(xy[:, 0], xy[:, 1], "-o", ms=3, color=color, lw=1, label=label)
        else:
            pts = [
                (p[member].force_N @ p[member].centres) / p[member].force_N.sum()
                for p in v.patches
                if p[member].force_N.size
            ]
            if pts:
                xy = np.array(pts)
                ax.plot(xy[:, 0], xy[:, 1], "o", ms=3, color=color, label=label)
        pc = r.pattern[member]
        if pc.face_mm is not None:
            ax.plot([pc.face_mm], [pc.profile_mm], "+", ms=14, mew=2, color=color)
    if frame is not None:
        o = frame.outline
        ax.plot(o[:, 0], o[:, 1], "k-", lw=1)
        a, b = frame.face_ends
        ax.set_xlabel(f"{frame.face_name}  ({a} → {b})" if a else frame.face_name)
        ax.set_ylabel(frame.profile_name)
    ax.set_title(title or f"contact on the {member} flank (+: pattern centre)", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return _savefig(fig, path)
