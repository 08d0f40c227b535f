"""Outputs of a gear-case run (the result model: ``docs/architecture.md``): ``summary.json``, VTK
time series, PNGs.

Files written to the output folder (each one atomically: complete or absent):

- ``summary.json`` — inputs, per position (pinion angle, unloaded/loaded TE, status, pairs with
  force, load share, p_max, patch axes, contact point in the fixed frame, edge flag and edges),
  cycle values, solver residuals, timings, versions, units. Headlines mean what they say
  (:func:`fegear.results.build_result`): ``cycle.te_pp_loaded_arcsec`` over the usable positions
  only (``te_pp_loaded_positions_used``; ``excluded_positions`` with their reasons: contact
  lost, or degenerate: a loaded patch the cells do not resolve), ``cycle.p_max_MPa`` the largest
  pressure away from the flank edges, ``cycle.p_max_edge_MPa`` the edge value beside it
  (``p_max_edge_at``: position, pair, edges named), and ``null`` with a ``*_reason`` where
  nothing physical can be reported, never 0. ``pattern`` (per member: the bearing pattern's
  centre and extent on its flank, :class:`fegear.output.flank_view.PatternCentre`) and ``cache``
  (the cache folder, the artefacts read from it and those built). The engagement checks made
  before the analysis:
  ``cycle.tip_clearance_mm``, ``cycle.unloaded_interior_contact_fraction`` (the contact ratio
  when below 1), ``cycle.positions_without_unloaded_contact``; one pair's unloaded contact over
  its whole contact interval (:func:`fegear.tca.path.contact_path`):
  ``cycle.contact_ratio_unloaded`` (the interval over the angular pitch),
  ``cycle.path_length_mm`` (on the gear flank), ``cycle.path_length_in_space_mm``,
  ``cycle.path_ends`` (what ends it: ``"gear:tip"``, ``"pinion:tip"``, ``"transfer"``, …),
  ``cycle.path_pinion_angles_deg``. The unloaded contact ellipses (every fidelity,
  :mod:`fegear.tca.ellipse`): ``positions[i].contact_ellipse`` (the TCA's pair in contact: its
  principal relative curvatures and directions, Litvin's ellipse for the paint thickness, the
  Hertz ellipse of that pair carrying the whole load; null without contact) and
  ``cycle.contact_ellipses`` (their ranges over the cycle). Keys other tools rely on:
  ``cycle.te_pp_unloaded_arcsec``, ``cycle.te_pp_loaded_arcsec``,
  ``cycle.contact_ratio_loaded``, ``cycle.p_max_MPa``, ``positions[i].pinion_angle_deg``,
  ``positions[i].te_loaded_arcsec``, ``positions[i].pairs[j].load_share``,
  ``positions[i].pairs[j].p_max_MPa``, ``positions[i].pairs[j].contact_point_mm``,
  ``positions[i].pairs[j].edge_contact``, ``cycle.contact_zone`` (``sector_teeth``, ``pairs``,
  ``gap_mm``: what the sectors modelled). (Fidelity ``tca``: the loaded values are ``null``.)
  Root stress (fidelities ``fe`` and ``hybrid``, from the stress sectors under the cell forces,
  :mod:`fegear.fem.stress`): ``positions[i].members[k]`` (``name``, ``root_stress_MPa``: per
  tooth that can touch ``tooth``, ``loaded``, ``tension_max_principal`` (largest σ1 in the
  fillet on the loaded-flank side), ``compression_min_principal`` (smallest σ3 on the other
  side), ``von_mises_max``, each with ``*_at``: ``point_mm`` in the member frame,
  ``radius_mm``, ``axial_mm``; ``stress_equilibrium``: reaction against load, relative);
  ``cycle.root_stress_max_MPa`` (per member the extremes over the loaded teeth and positions,
  where), ``cycle.root_stress_fillet_mm`` (``cycle.root_stress_notes``: why coarser than
  0.1 m), ``cycle.root_stress_max_equilibrium_residual``
  (``null`` with ``cycle.root_stress_reason`` at ``hertz``).
- ``vtk/pinion_<i>.vtu``, ``vtk/gear_<i>.vtu`` (fidelity ``fe``) — the sector of each member
  in its assembled position at position ``i`` (fixed frame, mm; the gear at its unloaded
  TCA-closed angle ``ratio·φ1 + TE_unloaded``, the elastic lag is not added), linear tets, with
  point data ``displacement_mm`` (fixed-frame components of ``u = K⁻¹ P F``; *Warp By Vector*),
  ``pressure_MPa`` (the pressure of the contact cell over each working-flank vertex, raised to
  that of the loaded cells whose nearest vertex it is, else 0: a display of the patch on the
  element mesh; the exact field is in the contact cells) and
  ``in_contact`` (1 on loaded flank vertices), ``max_principal_stress_MPa``,
  ``min_principal_stress_MPa``, ``von_mises_MPa`` (the recovered vertex stresses; the sectors
  are the stress sectors, fillets refined).
- ``vtk/contact_cells_<i>.vtu`` — the contact cells of all pairs as quads on the pinion flank
  (fixed frame) with cell data ``force_N``, ``pressure_MPa``, ``area_mm2`` (so that
  ``Σ pressure·area = Σ force``), ``gap_mm``, ``active``, ``edge``, ``pair``,
  ``pinion_tooth``, ``gear_tooth``: the exact solver output. A position without contact has an
  empty file (VTK/ParaView/pyvista read it; meshio 5.3 cannot read an empty VTU).
- ``vtk/flank_pinion_<i>.vtp``, ``vtk/flank_gear_<i>.vtp`` (fidelities ``fe`` and ``hybrid``)
  — the flank views (:mod:`fegear.output.flank_view`): the loaded contact cells of each member on
  its own working flank in flank coordinates, ``x`` the face coordinate and ``y`` the profile
  coordinate (mm; for the face gear the radius and the height above the pitch plane), cell data
  ``pressure_MPa``, ``force_N``, ``tooth``, ``pair``, ``edge``, with the working-surface
  outline (a line, ``outline`` = 1). All teeth share the flank; the bearing pattern of one
  position is what the flank shows, the cycle plays the patch across it.
- ``cycle.pvd`` — the collection: **time = pinion angle φ1 in degrees** (said in a comment of
  the file and in the field data ``pinion_angle_deg`` of every file of the series, the
  ``.vtp`` also in ``time_unit``); parts 0 pinion, 1 gear, 2 contact cells, 3 pinion flank view,
  4 gear flank view; open it in ParaView and press play.
- PNGs: ``te.png`` (unloaded and loaded TE), ``load_share.png``, ``p_max.png``,
  ``bearing_pattern.png`` (union of the loaded cells on the pinion flank, coloured by the largest
  pressure seen over the cycle), ``root_stress.png`` (per member, the root stress of one tooth
  over its passage through the mesh). Fidelity ``tca``: ``te.png`` and ``bearing_pattern.png``
  (unloaded, paint thickness).
- ``ease_off.png``, ``ease_off.vts``, ``ease_off.json`` (every fidelity) — the ease-off of the
  pair over the pinion flank (:mod:`fegear.output.ease_off_output`, ``docs/ease_off.md``): its
  grid is in ``ease_off.json``, the numbers that describe it in ``summary.json``'s ``ease_off``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fegear.forked import apart, process_count
from fegear.output.cylindrical_output import plot_line_load
from fegear.output.ease_off_output import write_ease_off
from fegear.output.flank_view import (
    FlankFrame,
    FlankPatch,
    PatternCentre,
    flank_frames,
    flank_patches,
    pattern_centre,
)
from fegear.output.gear_plots import loaded_plots, tca_plots
from fegear.output.picture_cache import keep_pictures, kept_pictures, picture_params
from fegear.output.vtk import write_gear_vtk, write_pvd
from fegear.pipeline.run import GearRun, with_fields
from fegear.results.build import build_result
from fegear.results.cylindrical import is_cylindrical
from fegear.results.model import GearRunResult
from fegear.results.summary import summary_document
from fegear.store.files import write_json

__all__ = ["FlankViews", "flank_views", "gear_summary", "write_gear_outputs", "write_pvd"]


@dataclass(frozen=True)
class FlankViews:
    """The flank views of a run (:mod:`fegear.output.flank_view`), computed once for the files,
    the summary and the pictures.

    Attributes
    ----------
    frames
        ``{member: FlankFrame}``.
    patches
        Per position ``{member: FlankPatch}`` (empty for the fidelities without contact cells).
    pattern
        ``{member: PatternCentre}``.
    """

    frames: dict[str, FlankFrame]
    patches: tuple[dict[str, FlankPatch], ...]
    pattern: dict[str, PatternCentre]


def flank_views(run: GearRun) -> FlankViews:
    """The :class:`FlankViews` of a run."""
    frames = flank_frames(run)
    patches = tuple(flank_patches(run, frames=frames)) if run.cycle is not None else ()
    return FlankViews(frames, patches, pattern_centre(run, frames, list(patches)))


def gear_summary(
    run: GearRun, files: list[str] | None = None, views: FlankViews | None = None
) -> dict[str, Any]:
    """The ``summary.json`` document of a gear run (``views``: its flank views, which give
    ``pattern``; without them ``pattern`` is null): :func:`fegear.results.build_result` written
    by :func:`fegear.results.summary_document`."""
    return summary_document(build_result(run, views.pattern if views else None), files)


def write_gear_outputs(
    out: Path,
    run: GearRun,
    views: FlankViews | None = None,
    result: GearRunResult | None = None,
    workers: int | None = 1,
) -> list[Path]:
    """Write every output of a gear run into ``out`` (atomically); returns the paths.

    ``views``: the run's flank views (:func:`flank_views`), computed if not given; ``result``:
    its result model (:func:`fegear.results.build_result`, with the views' pattern), built if
    not given. ``workers``: the processes the run may use (None: as the positions,
    ``$FEGEAR_WORKERS``, else one per core); with two or more, the pictures of a loaded run
    are drawn in a second process while the VTK files are written (:func:`fegear.forked.apart`),
    except while the fields of a run without root stress are to come (their two solves already
    use two cores);
    a run whose pictures are in the cache (the same run drawn before) has them copied
    (:mod:`fegear.output.picture_cache`).
    A run whose displacement fields are pending (``run.fields_pending``) gets them here
    (:func:`fegear.pipeline.run.with_fields`) while the pictures are drawn (they show no
    field), and ``result`` is then built from the run with its fields.
    """

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    views = views if views is not None else flank_views(run)
    pending = run.fields_pending
    result = result if result is not None and not pending else build_result(run, views.pattern)
    paths: list[Path] = []
    if run.cycle is not None:
        keep = picture_params(run, result)
        kept = kept_pictures(out, keep)  # the same run drawn before: its pictures copied
        # A second process for the pictures, unless the fields to come are the vertex
        # displacements only: their two members' solves run side by side on two threads
        # (fegear.pipeline.fields.displacements), and a forked process then cost more than it
        # gained (seed face gear, warm: write stage 1.45 s wall and 1.8 s CPU drawn here, 1.54 s
        # and 2.6 s forked; the fork's copy-on-write pages nearly double the drawing's CPU).
        solves_side_by_side = pending and not run.case.root_stress
        fork = process_count(workers, 2) > 1 and kept is None and not solves_side_by_side

        # the line-load chart of a cylindrical pair (the cycle's) and the ease-off (the pair's
        # in its assembly, which the cycle key holds) are drawn and kept with the pictures: a
        # warm run copies them
        def draw(r=run, res=result) -> list[Path]:
            line = [plot_line_load(out, r)] if is_cylindrical(r) else []
            return loaded_plots(out, r, res) + line + write_ease_off(out, r)

        plots = apart(draw, fork)
        if pending:  # the fields while the pictures are drawn, then the model with them
            run = with_fields(run)
            result = build_result(run, views.pattern)
        paths += write_gear_vtk(out, run, views)
        if kept is None:
            kept = plots()
            keep_pictures(keep, kept)
        paths += kept
    else:
        paths += tca_plots(out, run)
        paths += write_ease_off(out, run)
    files = [str(p.relative_to(out)) for p in paths] + ["summary.json"]
    # the summary last: its presence says the run is complete
    paths.append(write_json(out / "summary.json", summary_document(result, files)))
    return paths
