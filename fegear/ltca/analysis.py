"""The loaded mesh cycle: TCA gaps + FE compliance of both sectors + torque-balanced contact.

At each mesh position (DESIGN §8):

1. the TCA closes the smallest gap of all pairs (unloaded TE) and gives the coarse separation
   field of every pair that can engage;
2. every pair gets fine contact cells where its separation is below ``g_max``
   (:func:`fegear.ltca.grid.pair_cells`);
3. the compliance of all cells is ``C = C_pinion + C_gear`` with ``C_m = P_mᵀ (K_m⁻¹)_cc P_m``
   on the member's cached operator (the force of a cell acts along ``−n1`` on the pinion and
   ``+n1`` on the gear, ``n1`` the pinion's outward normal); cells of different pairs are coupled
   through the bodies;
4. :func:`fegear.contact.solve_contact` solves ``d = g − θ h + C F ≥ 0, F ≥ 0, F·d = 0`` with
   torque balance ``hᵀF = T2``: ``θ`` is the elastic lag of member 2, and the number of pairs in
   contact is whatever the active set says;
5. ``g_max`` is checked afterwards: a coarse TCA cell left out (separation above ``g_max``) whose
   rigid gap after the lag, ``g − θ h``, is negative could have taken load; ``g_max`` is then
   doubled and the position solved again (the elastic term ``C F`` only opens such gaps further,
   so the rigid test is conservative).

The loaded TE is the unloaded TE minus the lag ``θ`` (arcsec).

The ``hybrid`` fidelity (DESIGN §7) changes step 3 inside each pair. The FE cannot resolve a
patch narrower than its elements (cells finer than the P2 elements make ``PᵀK⁻¹P``
rank-deficient), so, after Vijayakar (1991, IJNME 31, 525), the approach of cell ``i`` is split at
a matching point ``y_i = x_i + d e_i`` a depth ``d`` below it (``e_i`` the inward normal):

    w_i = Q_iᵀ K⁻¹ P F  +  Σ_j [u_hs(x_i; j) − u_hs(y_i; j)] F_j      (for each member)

the FE read at depth (where the coarse mesh no longer has to resolve the pressure's near field)
plus the closed-form compression of the layer ``[0, d]`` of a half-space under uniform pressure
on rectangular cells (Love 1929 for the surface, the Boussinesq integral below it:
:func:`fegear.halfspace.subsurface_influence`); the part of the near field the coarse FE
carries above ``y_i`` is never used, so nothing is counted twice. ``d = min(2h, 0.35 m)`` is tied
to the element size, so the layer shrinks as the FE is refined and the hybrid tends to the pure
FE answer (shown on the Hertz scene: ``tests/test_hybrid.py``). The FE part is symmetrised.
Between pairs (different teeth) the plain ``PᵀK⁻¹P`` coupling is used. The operator of each
member covers the DOFs of the tetrahedra down to ``d`` below its working flanks; a matching point
outside them moves up (``d`` halved), and a cell overhanging the flank edge reads the FE at the
surface. The cells of each pair are refined on a grid turned to its patch's axes
(:func:`_refined_sizes`), starting from the previous position's grid.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fegear.compliance import cross_compliance, find_tets, probe_operator
from fegear.contact import solve_contact
from fegear.errors import InputError
from fegear.geometry.transforms import apply_points, apply_vectors, inverse
from fegear.halfspace import subsurface_influence
from fegear.ltca.grid import PairCells, pair_cells
from fegear.ltca.model import (
    MemberModel,
    build_member_model,
    member_compliance,
    member_load_operator,
)
from fegear.ltca.results import LoadedCycle, LoadedPosition, PairLoad
from fegear.ltca.warm import active_guess, footprint
from fegear.mesh.sector import FINE, sector_mesh
from fegear.patch import measure_patch
from fegear.tca import TCA, TCAOptions
from fegear.tca.cached import cached_tca
from fegear.tca.results import ARCSEC, PositionResult

__all__ = ["LTCAOptions", "MemberModels", "build_models", "solve_position", "run_ltca"]

log = logging.getLogger(__name__)

# fe: the cells are element-sized, the cap only bounds the dense compliance of a huge zone.
_FE_MAX_CELLS = 1500


@dataclass(frozen=True)
class LTCAOptions:
    """Options of the loaded analysis.

    Attributes
    ----------
    n_positions
        Positions per mesh cycle.
    level
        Sector mesh level (0 coarse … 4 fine).
    n_teeth
        Teeth per sector (contact ratio + one neighbour each side; 3 covers contact ratios < 2).
    cell_mm
        Contact cell size; None: the fine element size of the coarser member. Cells much
        smaller than the P2 elements make the FE compliance ``PᵀK⁻¹P`` rank-deficient (more
        cells than surface DOFs under them), so the ``fe`` fidelity cannot resolve patches
        narrower than its elements: that is the ``hybrid`` fidelity's job.
    g_max_mm
        Initial separation cut-off (doubled automatically while too small).
    tca_grid
        Coarse separation grid of the TCA (nu, nv).
    E_MPa, nu
        Material of both members.
    backend
        Sparse direct backend.
    fidelity
        ``"fe"``: the contact grid with the FE compliance (cells one element wide).
        ``"hertz"``: per-pair Hertz laws and lumped FE compliance (:mod:`fegear.ltca.hertz_model`).
        ``"hybrid"``: the FE read at a matching depth ``d`` below every cell plus
        the closed-form half-space compression of the layer above it (Vijayakar 1991; the split
        validated on the Hertz scene, :func:`fegear.scenes.hertz_scene.hybrid_compliance`),
        inside each pair; plain ``PᵀK⁻¹P`` between pairs. The cells are refined below the
        element size until ``n_across`` of them span each loaded patch.
    n_across
        ``hybrid``: cells wanted across each loaded patch in both flank directions.
    max_cells
        ``hybrid``: cells per pair at most (both sizes grow in proportion beyond): caps the
        cost of the dense compliance (n²) where a pair's patch is tiny, i.e. at an edge
        contact, whose pressure is singular and does not converge under refinement anyway
        (measured on the spiral bevel: 3614 cells, 15 s for one solve, without the cap); the
        ``fe`` cells are element-sized (cap 1500). Interior patches take
        200-550 cells at ``n_across = 8``. Measured (hybrid level 0, 25 positions, cap 1500 ->
        600): seed face gear loaded TE within 0.003", load shares within 0.0005, warm positions
        8.8 -> 5.8 s; spiral bevel TE within 0.04", shares within 0.0006, 18.8 -> 11.8 s; only
        the (singular) edge-contact p_max changes.
    depth_elements, depth_max_modules
        ``hybrid``: ``d = min(depth_elements h, depth_max_modules m)`` (``h`` the fine element
        size, ``m`` the module). Measured on the FZG pair: positive definite from d = 1.1 h.
    """

    n_positions: int = 25
    level: int = 0
    n_teeth: int = 3
    cell_mm: float | None = None
    g_max_mm: float = 0.02
    tca_grid: tuple[int, int] = (24, 12)
    E_MPa: float = 206000.0
    nu: float = 0.3
    backend: str = "auto"
    fidelity: str = "fe"
    n_across: int = 8
    max_cells: int = 600
    depth_elements: float = 2.0
    depth_max_modules: float = 0.35

    def __post_init__(self) -> None:
        if self.fidelity not in ("fe", "hertz", "hybrid"):
            raise InputError("fidelity", self.fidelity, "'fe', 'hertz' or 'hybrid'")


@dataclass(frozen=True)
class MemberModels:
    """FE models of both members and the cell size that goes with them."""

    pinion: MemberModel
    gear: MemberModel
    cell_mm: float
    seconds: float
    fidelity: str = "fe"
    depth_mm: float = 0.0
    E: float = 206000.0
    nu: float = 0.3
    n_across: int = 8
    max_cells: int = 600


def build_models(pinion, gear, assembly, options: LTCAOptions) -> MemberModels:
    """Mesh both sectors and compute their compliance operators (cached)."""
    t0 = time.perf_counter()
    sectors = [sector_mesh(m, options.n_teeth, options.level) for m in (pinion, gear)]
    h = max(float(sm.parameters["h_fine_mm"]) for sm in sectors)
    module = min(float(sm.parameters["h_fine_mm"]) / FINE[options.level] for sm in sectors)
    depth = layer = 0.0
    if options.fidelity == "hybrid":
        depth = min(options.depth_elements * h, options.depth_max_modules * module)
        layer = depth
    models = [
        build_member_model(
            member.name, sm, side, options.E_MPa, options.nu, options.backend, layer_mm=layer
        )
        for member, side, sm in (
            (pinion, assembly.side1, sectors[0]),
            (gear, assembly.side2, sectors[1]),
        )
    ]
    cell = options.cell_mm if options.cell_mm is not None else h
    return MemberModels(
        models[0],
        models[1],
        cell,
        time.perf_counter() - t0,
        fidelity=options.fidelity,
        depth_mm=depth,
        E=options.E_MPa,
        nu=options.nu,
        n_across=options.n_across,
        max_cells=options.max_cells,
    )


def _no_contact(pos: PositionResult, reason: str) -> LoadedPosition:
    from fegear.contact import ContactSolution

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
    te = pos.te_arcsec
    return LoadedPosition(
        phi1=pos.phi1,
        te_unloaded_arcsec=te,
        te_loaded_arcsec=te,
        theta=0.0,
        pairs=(),
        cells=(),
        pressure=(),
        solution=empty,
        g_max_mm=0.0,
        warnings=(reason,),
    )


def _excluded_violation(pos: PositionResult, g_max: float, theta: float) -> bool:
    for g in pos.grids:
        out = g.valid & (g.separation > g_max)
        if np.any(g.separation[out] - theta * g.h[out] < 0.0):
            return True
    return False


def _solve_cells(tca, pos, models, torque2_Nmm, cell, g_max, warnings, footprints=None):
    """Cells of every modelled pair within ``g_max`` and their contact solution; ``cell`` maps a
    pair ``(k, j)`` to its cell sizes (key None: the size of the pairs not listed);
    ``footprints`` (:func:`fegear.ltca.warm.footprint` of a neighbouring solution) warm-start
    the active set."""
    cells: list[PairCells] = []
    for gi, g in enumerate(pos.grids):
        if not (models.pinion.has_tooth(g.k) and models.gear.has_tooth(g.j)):
            n = models.pinion.sector.n_teeth
            msg = f"pair ({g.k}, {g.j}) lies outside the {n}-tooth sectors"
            if msg not in warnings:
                warnings.append(msg)
                log.warning(msg)
            continue
        su, sv, angle = cell.get((int(g.k), int(g.j)), cell[None])
        cap = models.max_cells if models.fidelity == "hybrid" else _FE_MAX_CELLS
        c = pair_cells(tca, pos, gi, (su, sv), g_max, max_cells=cap, angle=angle)
        if c is not None:
            cells.append(c)
    if not cells:
        return cells, None
    C = _solve_cells_compliance(tca, pos, models, cells)
    gap = np.concatenate([c.gap for c in cells])
    h = np.concatenate([c.h for c in cells])
    guess = active_guess(tca.asm, pos.phi1, cells, footprints) if footprints else None
    return cells, solve_contact(C, gap, torque2_Nmm, weights=h, active_guess=guess)


def _load_operators(models, M1, M2, cells) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Consistent loads of all cells on both members: along ``−n1`` on the pinion flank, along
    ``+n1`` at the same points moved across the gap onto the gear flank."""
    P1 = sp.hstack(
        [member_load_operator(models.pinion, M1, c.k, c.quad_points, -c.normals) for c in cells]
    ).tocsr()
    P2 = sp.hstack(
        [
            member_load_operator(
                models.gear,
                M2,
                c.j,
                c.quad_points + c.gap[:, None, None] * c.normals[:, None],
                c.normals,
            )
            for c in cells
        ]
    ).tocsr()
    return P1, P2


def _solve_cells_compliance(tca, pos, models, cells) -> np.ndarray:
    """``C = C_pinion + C_gear`` of the cells (both flanks, cross-pair coupling included)."""
    if models.fidelity == "hybrid":
        return _hybrid_compliance(tca, pos, models, cells)
    asm = tca.asm
    M1 = asm.placement1(pos.phi1)
    M2 = asm.placement2(pos.phi2)
    P1, P2 = _load_operators(models, M1, M2, cells)
    return member_compliance(models.pinion, P1) + member_compliance(models.gear, P2)


def _hybrid_probe(model, M, x, inward, P, depth: float) -> tuple[sp.csc_matrix, np.ndarray]:
    """Matching-point readings of one member for the FE part of the hybrid compliance,
    ``sym(Qᵀ (K⁻¹)_cc P)``: ``Q`` reads the displacement along the inward normal at ``x + d e``.
    A matching point that would leave the tooth, or fall in a tetrahedron outside the operator's
    layer, moves up by halving ``d``; a cell whose point is still outside after three halvings (a
    cell overhanging the flank edge) reads the FE at the surface, through its own load column
    (``d = 0``: no layer correction).
    Returns ``Q`` (n_dofs × n) and the depths used."""
    Minv = inverse(M)
    e = apply_vectors(Minv, inward)
    x0 = apply_points(Minv, x)
    d = np.full(x0.shape[0], depth)
    for _ in range(4):
        tets, _ = find_tets(model.body.mesh, x0 + d[:, None] * e)
        bad = tets < 0
        bad[~bad] = ~model.layer_tets[tets[~bad]]
        if not bad.any():
            break
        d[bad] *= 0.5
    good = np.flatnonzero(~bad)
    Q = probe_operator(model.body, x0[good] + d[good, None] * e[good], e[good])
    if bad.any():
        d[bad] = 0.0
        log.debug("%s: %d hybrid cells read at the surface", model.name, int(bad.sum()))
        order = np.concatenate([good, np.flatnonzero(bad)])
        Q = sp.hstack([Q, sp.csc_matrix(P)[:, bad]]).tocsc()[:, np.argsort(order)]
    return sp.csc_matrix(Q), d


def _hybrid_compliance(tca, pos, models, cells) -> np.ndarray:
    """Hybrid compliance: inside each pair, FE at the matching depth + the half-space compression
    of the layer ``[0, d]`` of each member (cells in intrinsic flank coordinates); between pairs
    (different teeth, far apart) the plain surface coupling ``PᵀK⁻¹P``."""
    asm = tca.asm
    M1 = asm.placement1(pos.phi1)
    M2 = asm.placement2(pos.phi2)
    n1 = np.concatenate([c.normals for c in cells])
    x1 = np.concatenate([c.centers for c in cells])
    x2 = x1 + np.concatenate([c.gap[:, None] * c.normals for c in cells])
    P1, P2 = _load_operators(models, M1, M2, cells)
    P1, P2 = P1.tocsc(), P2.tocsc()
    Q1, d1 = _hybrid_probe(models.pinion, M1, x1, -n1, P1, models.depth_mm)
    Q2, d2 = _hybrid_probe(models.gear, M2, x2, n1, P2, models.depth_mm)
    ops = ((models.pinion.op, Q1, P1), (models.gear.op, Q2, P2))
    ends = np.cumsum([0] + [c.n for c in cells])
    blocks = [slice(ends[i], ends[i + 1]) for i in range(len(cells))]
    C = np.zeros((int(ends[-1]), int(ends[-1])))
    # Between pairs: the plain surface coupling of both members (upper blocks, mirrored).
    for ia, sa in enumerate(blocks):
        for sb in blocks[ia + 1 :]:
            C[sa, sb] = sum(cross_compliance(op, P[:, sa], P[:, sb]) for op, _, P in ops)
            C[sb, sa] = C[sa, sb].T
    for c, sl in zip(cells, blocks, strict=True):
        S = np.zeros((c.n, c.n))
        for op, Q, P in ops:
            Cf = cross_compliance(op, Q[:, sl], P[:, sl])
            S += 0.5 * (Cf + Cf.T)
        s0 = subsurface_influence(c.local, 0.0, c.local, c.half_widths, models.E, models.nu)
        full: dict[float, np.ndarray] = {}  # depth -> all rows (shared by both members)
        for dd in (d1[sl], d2[sl]):
            S += 0.5 * (s0 + s0.T)
            for depth in np.unique(dd):
                rows = np.flatnonzero(dd == depth)
                sd = np.zeros((c.n, c.n))
                if depth == 0.0:
                    sd[rows] = s0[rows]
                elif rows.size > c.n // 4:
                    if float(depth) not in full:
                        full[float(depth)] = subsurface_influence(
                            c.local, float(depth), c.local, c.half_widths, models.E, models.nu
                        )
                    sd[rows] = full[float(depth)][rows]
                else:
                    sd[rows] = subsurface_influence(
                        c.local[rows], float(depth), c.local, c.half_widths, models.E, models.nu
                    )
                S -= 0.5 * (sd + sd.T)
        C[sl, sl] = S
    return C


def _refined_sizes(cells, sol, cell, n_across, remake=False):
    """Per-pair cell grids ``(s_ξ, s_η, angle)`` for the ``hybrid`` refinement, or None if the
    grids are fine enough.

    The loaded patch of every pair is measured on its current grid by the force-weighted second
    moments of the loaded cells (intrinsic cell coordinates): the eigenvectors give the major
    direction ``M`` (minor ``m``), the eigenvalues ``λ`` the semi-axes ``sqrt(5 (λ + span²/12))``
    (the Hertz pressure ``p0 sqrt(1 - x²/a² - y²/b²)`` has ``∫x² p / ∫p = a²/5``; a cell
    spreads its force over its span). A cell of sizes
    ``s = (s_ξ, s_η)`` spans ``|m|·s`` across the patch and ``|M|·s`` along it; the pair is
    accepted when ``2b`` holds ``0.75 n_across`` such spans and ``2a`` as many, otherwise its
    next grid is turned to the patch axes (``η`` along ``M``: the thin, long patches of gears are
    oblique to the flank grid, and an unaligned grid fine enough across them has ``(a/b)²``
    times more cells) with ``s = (2b, 2a) / (1.25 n_across)``, never coarser than the element-size
    cells. A grid whose cells are less than 0.4 times the area of those (too fine, or turned
    away from the patch: a pair's grid starts from the previous position's, where its patch may
    have been much smaller) is re-made the same way. Aiming above the target lets the next grid
    pass, as a coarse grid over-estimates the patch. Each pair gets its own grid: a small patch
    (an edge contact carrying little load) does not refine its neighbour. ``remake``: every
    loaded pair gets the grid made for its patch, accepted or not (the start of the next
    position); pairs without load are left out (they start from the default cells).
    """
    start, new, refine = 0, {None: cell[None]}, False
    base = cell[None][0]
    for c in cells:
        F = sol.force[start : start + c.n]
        start += c.n
        key = (c.k, c.j)
        now = cell.get(key, cell[None])
        if not np.any(F > 0):
            continue
        w = F / F.sum()
        x = c.local - w @ c.local
        lam, vec = np.linalg.eigh((x * w[:, None]).T @ x)
        M = vec[:, 1]
        size = np.asarray(now[:2])
        span_b, span_a = np.abs(M[::-1]) @ size, np.abs(M) @ size
        # Each cell smears its force over its span (variance span²/12): a patch one cell wide
        # measures at least that width.
        b2 = 2.0 * np.sqrt(5.0 * (max(lam[0], 0.0) + span_b**2 / 12.0))
        a2 = 2.0 * np.sqrt(5.0 * (max(lam[1], 0.0) + span_a**2 / 12.0))
        ideal = (min(base, b2 / (1.25 * n_across)), min(base, a2 / (1.25 * n_across)))
        fine = b2 >= 0.75 * n_across * span_b and a2 >= 0.75 * n_across * span_a
        wasteful = size[0] * size[1] < 0.4 * ideal[0] * ideal[1]
        if fine and not wasteful and not remake:
            new[key] = now
            continue
        refine = True
        turn = math.atan2(M[1], M[0]) - 0.5 * math.pi  # η onto the major axis
        new[key] = (*ideal, math.remainder(now[2] + turn, math.pi))
    return new if refine else None


def solve_position(
    tca: TCA,
    pos: PositionResult,
    models: MemberModels,
    torque2_Nmm: float,
    g_max_mm: float,
    previous: LoadedPosition | None = None,
) -> LoadedPosition:
    """Loaded contact at one TCA position (see the module docstring).

    ``previous`` (``hybrid``): the solution at the neighbouring position; its refined cell grids
    and ``g_max`` start this one (the patches move little from one position to the next, so the
    first solve is usually already fine enough: one or two solves instead of three or four).
    """
    if not pos.has_contact:
        return _no_contact(pos, "no contact: the flanks do not meet at this position")
    warnings: list[str] = []
    # Pass 1: cells of the default size (or the previous position's grids); g_max doubled until
    # no left-out cell could touch.
    g_max = g_max_mm
    cell = {None: (models.cell_mm, models.cell_mm, 0.0)}
    if models.fidelity == "hybrid" and previous is not None and previous.cells:
        g_max = previous.g_max_mm
        for c in previous.cells:
            cell[(c.k, c.j)] = (float(c.cell_mm[0]), float(c.cell_mm[1]), c.angle)
        # Grids made for the previous position's measured patches (not merely accepted for
        # them): a grid drifting with a growing or shrinking patch would cross the acceptance
        # bounds and cost a second solve (measured on the seed face gear: 39 -> 34 solves).
        made = _refined_sizes(previous.cells, previous.solution, cell, models.n_across, True)
        cell = made if made is not None else cell
    fps = None
    if previous is not None and previous.cells:
        fps = footprint(tca.asm, previous.phi1, previous.cells, previous.solution.active)
    for _attempt in range(8):
        cells, sol = _solve_cells(tca, pos, models, torque2_Nmm, cell, g_max, warnings, fps)
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
    for _ in range(3 if models.fidelity == "hybrid" else 0):
        sizes = _refined_sizes(cells, sol, cell, models.n_across)
        if sizes is None:
            break
        h_all = np.concatenate([c.h for c in cells])
        g_ref = max(1.5 * sol.theta * float(h_all.max()), 1e-6)
        fps = footprint(tca.asm, pos.phi1, cells, sol.active)
        cells2, sol2 = _solve_cells(tca, pos, models, torque2_Nmm, sizes, g_ref, warnings, fps)
        if sol2 is None or _excluded_violation(pos, g_ref, sol2.theta):
            break
        cells, sol, g_max, cell = cells2, sol2, g_ref, sizes
    # Per-pair results.
    loads, pressures = [], []
    start = 0
    for c in cells:
        F = sol.force[start : start + c.n]
        act = sol.active[start : start + c.n]
        start += c.n
        p = F / c.area
        pressures.append(p)
        f_tot = float(F.sum())
        if f_tot > 0.0:
            pm = measure_patch(c.local, F, c.area)
            centroid = (F @ c.centers) / f_tot
            semi = (pm.semi_major, pm.semi_minor)
            if 2.0 * pm.semi_minor < 4.0 * float(c.cell_mm.min()):
                msg = (
                    f"pair ({c.k}, {c.j}) at phi1 = {np.degrees(pos.phi1):.3f} deg: contact "
                    f"grid too coarse for the patch: "
                    f"{2 * pm.semi_minor / c.cell_mm.min():.1f} cells across the minor axis"
                )
                warnings.append(msg)
            p_peak = pm.p_peak
        else:
            centroid, semi, p_peak = np.zeros(3), (0.0, 0.0), 0.0
        loads.append(
            PairLoad(
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
            )
        )
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
    )


def run_ltca(
    pinion,
    gear,
    assembly,
    torque2_Nmm: float,
    options: LTCAOptions | None = None,
    phi1: np.ndarray | None = None,
    models: MemberModels | None = None,
    progress=None,
) -> LoadedCycle:
    """Loaded tooth contact analysis over one mesh cycle (or at the pinion angles ``phi1``).

    Parameters
    ----------
    pinion, gear
        Generated members.
    assembly
        The assembled pair (:mod:`fegear.assembly`), with its installation errors.
    torque2_Nmm
        Resisting torque on member 2 (N·mm, > 0).
    options
        :class:`LTCAOptions`.
    phi1
        Pinion angles (rad); default ``n_positions`` over one cycle ``[−π/N1, π/N1)``.
    models
        Pre-built member models (to reuse over several torques).
    progress
        Optional callable ``progress(i, n)`` called after each position.
    """
    if not (np.isfinite(torque2_Nmm) and torque2_Nmm > 0):
        raise InputError("torque2_Nmm", torque2_Nmm, "a finite number > 0")
    opt = options or LTCAOptions()
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    tca_opt = TCAOptions(
        n_positions=opt.n_positions, separation_grid=opt.tca_grid, E_MPa=opt.E_MPa, nu=opt.nu
    )
    if phi1 is None:
        n = opt.n_positions
        phi1 = -np.pi / assembly.n1 + 2 * np.pi / assembly.n1 * np.arange(n) / n
    phi1 = np.atleast_1d(np.asarray(phi1, dtype=float))
    tca, tca_pos, _ = cached_tca(pinion, gear, assembly, tca_opt, phi1)
    asm = tca.asm
    seconds["tca"] = time.perf_counter() - t0
    if models is None:
        models = build_models(pinion, gear, asm, opt)
    seconds["models"] = models.seconds
    t0 = time.perf_counter()
    out = []
    for i, pos in enumerate(tca_pos):
        if opt.fidelity == "hertz":
            from fegear.ltca.hertz_model import solve_position_hertz

            out.append(solve_position_hertz(tca, pos, models, torque2_Nmm, opt.E_MPa, opt.nu))
        else:
            prev = out[-1] if out else None
            out.append(solve_position(tca, pos, models, torque2_Nmm, opt.g_max_mm, prev))
        if progress is not None:
            progress(i + 1, len(tca_pos))
    seconds["positions"] = time.perf_counter() - t0
    return LoadedCycle(
        positions=tuple(out),
        torque2_Nmm=float(torque2_Nmm),
        phi1=phi1,
        te_unloaded_arcsec=np.array([p.te_unloaded_arcsec for p in out]),
        te_loaded_arcsec=np.array([p.te_loaded_arcsec for p in out]),
        n_in_contact=np.array([p.n_pairs_in_contact for p in out], dtype=int),
        fidelity=opt.fidelity,
        level=opt.level,
        seconds=seconds,
        phase2=float(asm.phase2),
    )
