"""The loaded contact at one mesh position: TCA gaps + the compliance of the fidelity + a
torque-balanced contact solve (:func:`solve_position`; the formulation:
``docs/ltca/contact_formulation.md``).

At each mesh position:

1. the TCA closes the smallest gap of all pairs (unloaded TE) and gives the coarse separation
   field of every pair that can engage;
2. every pair gets fine contact cells where its separation is below ``g_max``
   (:func:`fegear.ltca.grid.pair_cells`);
3. the compliance of all cells is ``C = C_pinion + C_gear`` with ``C_m = P_mᵀ (K_m⁻¹)_cc P_m``
   on the member's cached operator (the force of a cell acts along ``−n1`` on the pinion and
   ``+n1`` on the gear, ``n1`` the pinion's outward normal); cells of different pairs are coupled
   through the bodies;
4. :func:`fegear.mechanics.contact.solve_contact` solves ``d = g − θ h + C F ≥ 0, F ≥ 0, F·d = 0``
with
   torque balance ``hᵀF = T2``: ``θ`` is the elastic lag of member 2, and the number of pairs in
   contact is whatever the active set says;
5. ``g_max`` is checked afterwards: a coarse TCA cell left out (separation above ``g_max``) whose
   rigid gap after the lag, ``g − θ h``, is negative could have taken load; ``g_max`` is then
   doubled and the position solved again (the elastic term ``C F`` only opens such gaps further,
   so the rigid test is conservative).

The loaded TE is the unloaded TE minus the lag ``θ`` (arcsec).

``hybrid`` solves most positions from their predecessor's solution, and uses it once more: the
cells whose loaded gap, predicted from that solution's approach field ``g − d``, exceeds
``trim θ h_max`` are left out of the solve (:func:`fegear.ltca.warm.likely_cells`). The contact
problem restricted to cells that hold its active set has the same solution, so the trimmed
solve is accepted only if the ring of left-out cells around the kept ones stays open under it
(their loaded gap computed from the active cells' forces, :func:`_trim_holds`); otherwise the
position is solved on all cells (what it saves: ``benchmarks/results/contact_options.md``).

The ``hybrid`` fidelity changes step 3 inside each pair: see :mod:`fegear.ltca.hybrid`; the
compliance comes from the models' fidelity (``models.kind``, :mod:`fegear.ltca.fidelity`, whose
``solve_position`` calls this one). :func:`fegear.ltca.cycle.run_ltca` runs the positions of a
cycle.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import numpy as np

from fegear.ltca.degenerate import position_status
from fegear.ltca.edges import edge_split
from fegear.ltca.grid import PairCells, missing_pairs, pair_cells, take_cells
from fegear.ltca.hybrid import hybrid_displacement, refined_sizes
from fegear.ltca.model import (
    cell_load_operators,
)
from fegear.ltca.results import (
    MIN_CELLS_ACROSS,
    LoadedPosition,
    PairContact,
)
from fegear.ltca.warm import active_guess, footprint, likely_cells, ring_cells
from fegear.ltca.zone import left_out_pairs
from fegear.mechanics.contact import solve_contact
from fegear.mechanics.patch import measure_patch
from fegear.tca import TCA
from fegear.tca.results import ARCSEC, PositionResult

if TYPE_CHECKING:  # analysis builds the models and imports the fidelities, which import this
    from fegear.ltca.analysis import MemberModels

__all__ = ["solve_position"]

log = logging.getLogger(__name__)

#: ``hybrid`` cell trimming: a trimmed solve is accepted when the loaded gap of the ring of cells
#: left out around the kept ones stays above this fraction of the rigid approach ``θ h_max``
#: (measured with ``trim = 0.3``: the closest left-out cell stayed 1.4 µm = 0.16 θ h_max open on
#: the seed face gear, 5.2 µm on the spiral bevel).
_TRIM_MARGIN = 0.05


def _no_contact(pos: PositionResult, reason: str) -> LoadedPosition:
    """The TCA position ``pos`` as a position that carries no load (``reason``: why)."""
    return LoadedPosition.lost(pos.phi1, pos.te_arcsec, bool(pos.has_contact), reason)


#: The start of a position's warning that ``max_cells`` made a pair's cells coarser than asked.
CAPPED = "max_cells:"
#: A pair's cells at least this many times the area asked are reported (:data:`CAPPED`): within
#: it the cells across a patch are fewer by under √2, inside the margin the refinement aims
#: with (``n_across / 1.25`` cells: :func:`fegear.ltca.hybrid.refined_sizes`); the default
#: ``max_cells`` caps the line contacts of FZG by 1.2-1.4 in area.
CAP_AREA_RATIO = 2.0


def _excluded_violation(pos: PositionResult, g_max: float, theta: float) -> bool:
    """Could a point left out (separation above ``g_max``) close under the lag ``θ``? Only if
    its rigid gap ``g − θ h`` is negative (the elastic term ``C F`` opens it further). Tested
    on the coarse TCA grid points and on every pair's closest point, where the separation is
    exact (a narrow valley can run between the coarse points: :func:`near_cells`)."""
    for g in pos.grids:
        out = g.valid & (g.separation > g_max)
        if np.any(g.separation[out] - theta * g.h[out] < 0.0):
            return True
    out = pos.pair_valid & (pos.backlash_mm > g_max)
    return bool(np.any(pos.backlash_rad[out] < theta))


def _solve_cells(tca, pos, models, torque2_Nmm, cell, g_max, warnings, footprints=None):
    """Cells of every modelled pair within ``g_max`` and their contact solution; ``cell`` maps a
    pair ``(k, j)`` to its cell sizes (key None: the size of the pairs not listed);
    ``footprints`` (:func:`fegear.ltca.warm.footprint` of a neighbouring solution) warm-start
    the active set and, for ``hybrid``, trim the cells predicted far from contact
    (:func:`fegear.ltca.warm.likely_cells`; if a cell left out closes under the solution on the
    kept ones, :func:`_trim_holds`, the position is solved again on all of them). Returns
    ``(cells, solution, h_max)``, ``h_max`` the largest moment arm of all the cells within
    ``g_max`` (trimmed or not: it sets the next ``g_max``)."""
    cells: list[PairCells] = []
    for gi, g in enumerate(pos.grids):
        if not (models.pinion.has_tooth(g.k) and models.gear.has_tooth(g.j)):
            continue  # outside the zone: left_out_pairs reports it if the lag closes it
        su, sv, angle = cell.get((int(g.k), int(g.j)), cell[None])
        cap = models.kind.max_cells(models)
        c = pair_cells(tca, pos, gi, (su, sv), g_max, max_cells=cap, angle=angle)
        if c is not None:
            cells.append(c)
    if not cells:
        return cells, None, 0.0
    h_max = max(float(c.h.max()) for c in cells)
    if footprints and models.kind.trims:
        keep = likely_cells(tca.asm, pos.phi1, cells, footprints, models.trim)
        if any(k is not None for k in keep):
            kept = [c if k is None else take_cells(c, k) for c, k in zip(cells, keep, strict=True)]
            M1, M2 = tca.asm.placement1(pos.phi1), tca.asm.placement2(pos.phi2)
            loads = cell_load_operators(models, M1, M2, kept)
            sol = _solve_on(tca, pos, models, torque2_Nmm, kept, footprints, loads)
            margin = _TRIM_MARGIN * sol.theta * h_max
            if _trim_holds(tca, pos, models, cells, keep, kept, loads, sol, margin):
                return kept, sol, h_max
            log.info(
                "phi1 = %.4f: a cell left out of the solve closes; solved on all cells", pos.phi1
            )
    return cells, _solve_on(tca, pos, models, torque2_Nmm, cells, footprints), h_max


def _trim_holds(tca, pos, models, cells, keep, kept, loads, sol, margin) -> bool:
    """Whether the cells left out of a trimmed solve stay open: the loaded gap
    ``d = g − θ h + C F`` of the ring of left-out cells around each pair's kept cells
    (:func:`fegear.ltca.warm.ring_cells`) is computed from the forces of the active cells
    (:func:`fegear.ltca.hybrid.hybrid_displacement`) and must stay above ``margin`` (mm).

    The loaded gap grows away from a patch (the separation grows quadratically, the displacement
    varies slowly), so a closed cell farther out than the ring would need a second contact
    region on the same pair that the prediction missed. ``keep``: per pair of ``cells``, the kept
    indices (None: all); ``kept``: those cells, ``loads`` their load operators; ``sol``: the
    solution on them.
    """
    readers = [
        take_cells(c, ring_cells(c, k) if k is not None else np.zeros(0, dtype=int))
        for c, k in zip(cells, keep, strict=True)
    ]
    if sum(r.n for r in readers) == 0:
        return True
    u = hybrid_displacement(tca, pos, models, kept, loads, sol.force, readers)
    g = np.concatenate([r.gap for r in readers])
    h = np.concatenate([r.h for r in readers])
    return bool(np.min(g - sol.theta * h + u) >= margin)


def _solve_on(tca, pos, models, torque2_Nmm, cells, footprints, loads=None):
    """The contact solution on ``cells`` (warm-started from ``footprints``; ``loads``: their
    load operators if already made)."""
    C = _solve_cells_compliance(tca, pos, models, cells, loads)
    gap = np.concatenate([c.gap for c in cells])
    h = np.concatenate([c.h for c in cells])
    guess = active_guess(tca.asm, pos.phi1, cells, footprints) if footprints else None
    return solve_contact(C, gap, torque2_Nmm, weights=h, active_guess=guess)


def _solve_cells_compliance(tca, pos, models, cells, loads=None) -> np.ndarray:
    """``C = C_pinion + C_gear`` of the cells (both flanks, cross-pair coupling included), as
    the fidelity computes it (:meth:`fegear.ltca.fidelity.Fidelity.compliance`)."""
    return models.kind.compliance(tca, pos, models, cells, loads)


def solve_position(
    tca: TCA,
    pos: PositionResult,
    models: MemberModels,
    torque2_Nmm: float,
    g_max_mm: float,
    previous: LoadedPosition | None = None,
) -> LoadedPosition:
    """Loaded contact at one TCA position (see the module docstring).

    ``previous``: the solution at the neighbouring position. Every fidelity starts the contact
    solver from its active set (:mod:`fegear.ltca.warm`; the answer does not depend on it);
    ``hybrid`` also starts from its refined cell grids and ``g_max`` (the patches move little
    from one position to the next: one or two solves instead of three or four).
    """
    if not pos.has_contact:
        return _no_contact(pos, "no contact: the flanks do not meet at this position")
    warnings: list[str] = []
    # Pass 1: cells of the default size (or the previous position's grids); g_max doubled until
    # no left-out cell could touch.
    g_max = g_max_mm
    cell = {None: (models.cell_mm, models.cell_mm, 0.0)}
    if models.kind.warm_grids and previous is not None and previous.cells:
        g_max = previous.g_max_mm
        for c in previous.cells:
            cell[(c.k, c.j)] = (float(c.cell_mm[0]), float(c.cell_mm[1]), c.angle)
        # Grids made for the previous position's measured patches (not merely accepted for
        # them): a grid drifting with a growing or shrinking patch would cross the acceptance
        # bounds and cost a second solve (measured on the seed face gear: 39 -> 34 solves).
        made = refined_sizes(
            previous.cells, previous.solution, cell, models.n_across, True, n_along=models.n_along
        )
        cell = made if made is not None else cell
    fps = None
    if previous is not None and previous.cells:
        fps = footprint(tca.asm, previous.phi1, previous.cells, previous.solution)
    for _attempt in range(8):
        cells, sol, h_max = _solve_cells(tca, pos, models, torque2_Nmm, cell, g_max, warnings, fps)
        if sol is None and g_max < g_max_mm:  # the previous position's g_max was too small
            g_max = g_max_mm
            continue
        if sol is None:
            edge = pos.edge[pos.contact_pair] if pos.contact_pair >= 0 else ""
            why = (
                f"the unloaded contact is an edge contact ({edge}) that the contact cells on the "
                "pinion flank do not represent; no load is carried at this position"
                if edge
                else f"no contact cell within g_max = {g_max:.3g} mm"
            )
            return _no_contact(pos, why)
        if not _excluded_violation(pos, g_max, sol.theta):
            break
        g_max *= 2.0
        log.info("phi1 = %.4f: g_max raised to %.4g mm", pos.phi1, g_max)
    else:
        warnings.append(f"g_max did not settle (last {g_max:.3g} mm)")

    # hybrid: refine the cells until every loaded patch has n_across cells across it in both
    # flank directions; the zone shrinks to where the rigid approach theta h can close it.
    def modelled(k: int, j: int) -> bool:
        return models.pinion.has_tooth(k) and models.gear.has_tooth(j)

    for _ in range(models.kind.refine_rounds):
        lost = missing_pairs(pos, cells, g_max, modelled)
        sizes = refined_sizes(
            cells, sol, cell, models.n_across, missing=lost, n_along=models.n_along
        )
        if sizes is None:
            break
        g_ref = max(1.5 * sol.theta * h_max, 1e-6)
        fps = footprint(tca.asm, pos.phi1, cells, sol)
        cells2, sol2, h2 = _solve_cells(tca, pos, models, torque2_Nmm, sizes, g_ref, warnings, fps)
        if sol2 is None or _excluded_violation(pos, g_ref, sol2.theta):
            break
        cells, sol, g_max, cell, h_max = cells2, sol2, g_ref, sizes, h2
    cap = models.kind.max_cells(models)
    for c in cells:
        asked = cell.get((c.k, c.j), cell[None])
        if c.cell_mm[0] * c.cell_mm[1] > CAP_AREA_RATIO * asked[0] * asked[1]:
            warnings.append(
                f"{CAPPED} pair ({c.k}, {c.j}) at phi1 = {np.degrees(pos.phi1):.3f} deg: cells "
                f"of {c.cell_mm[0]:.3g} x {c.cell_mm[1]:.3g} mm where {asked[0]:.3g} x "
                f"{asked[1]:.3g} mm were asked: the pair's zone holds more than max_cells = "
                f"{cap} of them"
            )
    for k, j in missing_pairs(pos, cells, g_max, modelled):
        ip = int(np.flatnonzero((pos.pairs[:, 0] == k) & (pos.pairs[:, 1] == j))[0])
        warnings.append(
            f"pair ({k}, {j}) at phi1 = {np.degrees(pos.phi1):.3f} deg: its closest point is "
            f"{1000 * pos.backlash_mm[ip]:.1f} um from contact (edge: {pos.edge[ip] or 'none'}) "
            "but no contact cell represents it; it carries no load here"
        )
    # Per-pair results.
    loads, pressures = [], []
    start = 0
    b1, b2 = tca.fm1.bounds, tca.fm2.bounds
    for c in cells:
        F = sol.force[start : start + c.n]
        act = sol.active[start : start + c.n]
        start += c.n
        p = F / c.area
        pressures.append(p)
        f_tot = float(F.sum())
        edges, p_int, p_edge, across = (), None, None, 0.0
        if f_tot > 0.0:
            pm = measure_patch(c.local, F, c.area)
            centroid = (F @ c.centers) / f_tot
            semi = (pm.semi_major, pm.semi_minor)
            across = 2.0 * pm.semi_minor / float(c.cell_mm.min())
            if across < 4.0:
                msg = (
                    f"pair ({c.k}, {c.j}) at phi1 = {np.degrees(pos.phi1):.3f} deg: contact "
                    f"grid too coarse for the patch: {across:.1f} cells across the minor axis"
                )
                warnings.append(msg)
            p_peak = pm.p_peak
            edges, p_int, p_edge = edge_split(c, act, p, pm.semi_minor, b1, b2)
            if across < MIN_CELLS_ACROSS:
                p_int = None  # a cell average over an unresolved patch is not a pressure
        else:
            centroid, semi, p_peak = np.zeros(3), (0.0, 0.0), 0.0
        loads.append(
            PairContact(
                k=c.k,
                j=c.j,
                force_N=f_tot,
                torque_Nmm=float(c.h @ F),
                load_share=float(c.h @ F) / torque2_Nmm,
                p_max_MPa=float(p.max()),
                p_peak_MPa=float(p_peak),
                semi_major_mm=semi[0],
                semi_minor_mm=semi[1],
                n_active=int(act.sum()),
                edge_contact=bool(np.any(act & c.boundary)),
                contact_point=centroid,
                edges=edges,
                p_interior_MPa=p_int,
                p_edge_MPa=p_edge,
                cells_across=float(across),
                resolved=bool(across >= MIN_CELLS_ACROSS),
            )
        )
    status, reason = position_status(
        pos.phi1, sol.theta, loads, [float(c.cell_mm.min()) for c in cells]
    )
    left = left_out_pairs(pos, models, sol.theta, warnings)
    te_l = pos.te_arcsec - sol.theta / ARCSEC
    return LoadedPosition(
        phi1=pos.phi1,
        te_unloaded_arcsec=pos.te_arcsec,
        te_loaded_arcsec=te_l,
        theta=sol.theta,
        pairs=tuple(loads),
        cells=tuple(cells),
        pressure=tuple(pressures),
        solution=sol,
        g_max_mm=g_max,
        warnings=tuple(warnings),
        left_out=left,
        status=status,
        status_reason=reason,
    )
