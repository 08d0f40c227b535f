"""The ``hybrid`` fidelity of the loaded analysis: coarse FE + closed-form half-space near field.

The ``hybrid`` fidelity (``docs/fidelity.md``) changes the compliance of the cells inside each pair.
The FE cannot resolve a patch narrower than its elements (cells finer than the P2 elements make
``PᵀK⁻¹P`` rank-deficient), so, after Vijayakar (1991, IJNME 31, 525), the approach of cell ``i`` is
split at a matching point ``y_i = x_i + d e_i`` a depth ``d`` below it (``e_i`` the inward normal):

    w_i = Q_iᵀ K⁻¹ P F  +  Σ_j [u_hs(x_i; j) − u_hs(y_i; j)] F_j      (for each member)

the FE read at depth (where the coarse mesh no longer has to resolve the pressure's near field)
plus the closed-form compression of the layer ``[0, d]`` of a half-space under uniform pressure
on rectangular cells (Love 1929 for the surface, the Boussinesq integral below it:
:func:`fegear.mechanics.halfspace.layout_influence`), each cell laid out in its own tangent
plane (:func:`fegear.mechanics.halfspace.tangent_layout`: on a flank whose metric varies, one
flat map of a grid
turned to the patch misplaces the cells; measured 3-20 % on the layer approach); the part of
the near field the coarse FE carries above ``y_i`` is never used, so nothing is counted twice.
``d = min(2h, 0.35 m)`` is tied to the element size, so the layer shrinks as the FE is refined
and the hybrid tends to the pure FE answer (shown on the Hertz scene: ``tests/test_hybrid.py``).
The FE part is symmetrised.
Between pairs (different teeth) the plain ``PᵀK⁻¹P`` coupling is used. The operator of each
member covers the DOFs of the tetrahedra down to ``d`` below its working flanks; a matching point
outside them moves up (``d`` halved), and a cell overhanging the flank edge reads the FE at the
surface. The cells of each pair are refined on a grid turned to its patch's axes
(:func:`refined_sizes`), starting from the previous position's grid; the cells predicted far
from contact are left out of a solve, and :func:`hybrid_displacement` (the same compliance,
loaded cells × reading cells only) checks that they stay open
(:mod:`fegear.ltca.position`).
"""

from __future__ import annotations

import logging
import math
from dataclasses import replace

import numpy as np
import scipy.sparse as sp

from fegear.geometry.transforms import apply_points, apply_vectors, inverse
from fegear.ltca.model import cell_load_operators
from fegear.mechanics.compliance import SurfacePoints, cross_compliance, find_tets, probe_operator
from fegear.mechanics.halfspace import layout_influence, layout_influences, tangent_layout

__all__ = ["hybrid_compliance", "hybrid_displacement", "refined_sizes"]

log = logging.getLogger(__name__)


def _probe(model, M, x, inward, P, depth: float) -> tuple[sp.csc_matrix, np.ndarray]:
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
        tets, xi = find_tets(model.body.mesh, x0 + d[:, None] * e)
        bad = tets < 0
        bad[~bad] = ~model.layer_tets[tets[~bad]]
        if not bad.any():
            break
        d[bad] *= 0.5
    good = np.flatnonzero(~bad)  # found at their depth d by the last search: not searched again
    loc = SurfacePoints(tets[good], xi[good], np.zeros(good.size))
    Q = probe_operator(model.body, x0[good] + d[good, None] * e[good], e[good], located=loc)
    if bad.any():
        d[bad] = 0.0
        log.debug("%s: %d hybrid cells read at the surface", model.name, int(bad.sum()))
        order = np.concatenate([good, np.flatnonzero(bad)])
        Q = sp.hstack([Q, sp.csc_matrix(P)[:, bad]]).tocsc()[:, np.argsort(order)]
    return sp.csc_matrix(Q), d


def hybrid_compliance(tca, pos, models, cells, loads=None) -> np.ndarray:
    """Hybrid compliance: inside each pair, FE at the matching depth + the half-space compression
    of the layer ``[0, d]`` of each member (cells in intrinsic flank coordinates); between pairs
    (different teeth, far apart) the plain surface coupling ``PᵀK⁻¹P``. ``loads``: the cells'
    :func:`~fegear.ltca.model.cell_load_operators` if already made."""
    asm = tca.asm
    M1 = asm.placement1(pos.phi1)
    M2 = asm.placement2(pos.phi2)
    n1 = np.concatenate([c.normals for c in cells])
    x1 = np.concatenate([c.centers for c in cells])
    x2 = x1 + np.concatenate([c.gap[:, None] * c.normals for c in cells])
    P1, P2 = loads if loads is not None else cell_load_operators(models, M1, M2, cells)
    P1, P2 = P1.tocsc(), P2.tocsc()
    Q1, d1 = _probe(models.pinion, M1, x1, -n1, P1, models.depth_mm)
    Q2, d2 = _probe(models.gear, M2, x2, n1, P2, models.depth_mm)
    # Q and P in each operator's DOF basis once (a block of cells reads its columns of them).
    ops = [
        (op, op.project(Q), op.project(P))
        for op, Q, P in ((models.pinion.op, Q1, P1), (models.gear.op, Q2, P2))
    ]
    ends = np.cumsum([0] + [c.n for c in cells])
    blocks = [slice(ends[i], ends[i + 1]) for i in range(len(cells))]
    C = np.zeros((int(ends[-1]), int(ends[-1])))
    # Between pairs: the plain surface coupling of both members (upper blocks, mirrored).
    for ia, sa in enumerate(blocks):
        for sb in blocks[ia + 1 :]:
            C[sa, sb] = sum(
                cross_compliance(op, P[:, sa], P[:, sb], projected=True) for op, _, P in ops
            )
            C[sb, sa] = C[sa, sb].T
    for c, sl in zip(cells, blocks, strict=True):
        S = np.zeros((c.n, c.n))
        for op, Q, P in ops:
            Cf = cross_compliance(op, Q[:, sl], P[:, sl], projected=True)
            S += 0.5 * (Cf + Cf.T)
        lay = tangent_layout(c.centers, c.centers, c.normals, c.edges)
        # the surface and every depth read by more than a quarter of the rows of a member, in
        # one pass over the layout (full: depth -> all rows, shared by both members)
        need = sorted(
            {
                float(dp)
                for dd in (d1[sl], d2[sl])
                for dp in np.unique(dd)
                if dp != 0.0 and np.count_nonzero(dd == dp) > c.n // 4
            }
        )
        s0, *rest = layout_influences(lay, [0.0, *need], models.E, models.nu)
        full = dict(zip(need, rest, strict=True))
        h0 = 0.5 * (s0 + s0.T)  # the same for both members
        sym: dict[float, np.ndarray] = {}  # depth -> sym(sd) when every row is at that depth
        for dd in (d1[sl], d2[sl]):
            S += h0
            for depth in np.unique(dd):
                rows = np.flatnonzero(dd == depth)
                if rows.size == c.n and float(depth) in sym:  # the other member's, again
                    S -= sym[float(depth)]
                    continue
                if rows.size == c.n:  # every row: sd is s0 or the full block, not a copy
                    sd = s0 if depth == 0.0 else full[float(depth)]
                    sym[float(depth)] = 0.5 * (sd + sd.T)
                    S -= sym[float(depth)]
                    continue
                sd = np.zeros((c.n, c.n))
                if depth == 0.0:
                    sd[rows] = s0[rows]
                elif rows.size > c.n // 4:
                    sd[rows] = full[float(depth)][rows]
                else:
                    sd[rows] = layout_influence(lay.rows(rows), float(depth), models.E, models.nu)
                S -= 0.5 * (sd + sd.T)
        C[sl, sl] = S
    return C


def _column(y: np.ndarray) -> sp.csc_matrix:
    """The dense column ``y`` (n, 1) as a sparse one (its non-zero entries, as
    ``sp.csc_matrix(y)`` stores them, without a pass of SciPy's dense conversion)."""
    nz = np.flatnonzero(y[:, 0])
    return sp.csc_matrix((y[nz, 0], nz, np.array([0, nz.size])), shape=y.shape)


def hybrid_displacement(tca, pos, models, loaded, loads, forces, readers) -> np.ndarray:
    """Approach ``(C F)_i`` (mm, both members) of the cells ``readers`` under the forces
    ``forces`` (N, ``(Σ n,)``) on the cells ``loaded`` (their load operators ``loads``, as
    :func:`~fegear.ltca.model.cell_load_operators` returns them), with the compliance of
    :func:`hybrid_compliance` read without its symmetrisation: inside a pair the FE at the
    matching depth below each reader plus the layer compression, between pairs ``PᵀK⁻¹P``.
    ``loaded[p]`` and ``readers[p]`` are cells of the same pair ``p`` (``readers[p]`` may be
    empty).

    The cost is that of the loaded × reader entries only (no square compliance; one read of
    each member's operator): it checks a solution on the cells it left out
    (:func:`fegear.ltca.position.solve_position`).
    """
    asm = tca.asm
    M1 = asm.placement1(pos.phi1)
    M2 = asm.placement2(pos.phi2)
    have = [c for c in readers if c.n]
    # The readers' surface readings (between pairs, and for a matching point that falls outside
    # the layer) at their centres: a point reading, not the 2 x 2-point average of their load
    # columns (the displacement field is smooth across a cell; 4x fewer points to locate).
    R1, R2 = cell_load_operators(
        models, M1, M2, [replace(c, quad_points=c.centers[:, None, :]) for c in have]
    )
    n1 = np.concatenate([c.normals for c in have])
    x1 = np.concatenate([c.centers for c in have])
    x2 = x1 + np.concatenate([c.gap[:, None] * c.normals for c in have])
    R1, R2 = R1.tocsc(), R2.tocsc()
    Q1, d1 = _probe(models.pinion, M1, x1, -n1, R1, models.depth_mm)
    Q2, d2 = _probe(models.gear, M2, x2, n1, R2, models.depth_mm)
    ends_l = np.cumsum([0] + [c.n for c in loaded])
    ends_r = np.cumsum([0] + [c.n for c in readers])
    F = np.asarray(forces, dtype=float)
    # Per pair p: the load of its own cells (read at depth by Q) and that of the other pairs
    # (read at the surface by R), each read only by p's readers: the operator's entries between
    # p's readers and those loads only (a layer under one tooth is never read under another's).
    own = np.zeros((F.size, len(loaded)))
    for p in range(len(loaded)):
        own[ends_l[p] : ends_l[p + 1], p] = F[ends_l[p] : ends_l[p + 1]]
    other = F[:, None] - own
    u = np.zeros(int(ends_r[-1]))
    for op, Q, R, P in ((models.pinion.op, Q1, R1, loads[0]), (models.gear.op, Q2, R2, loads[1])):
        Q, R = op.project(Q), op.project(R)  # once for all pairs' readers
        at = 0
        for p, c in enumerate(readers):
            if c.n == 0:
                continue
            sub = slice(at, at + c.n)
            at += c.n
            w = np.zeros(c.n)
            for M, f in ((Q, own[:, p]), (R, other[:, p])):
                if f.any():
                    load = op.project(_column(P @ f[:, None]))
                    w += cross_compliance(op, M[:, sub], load, projected=True)[:, 0]
            u[ends_r[p] : ends_r[p + 1]] += w
    # The layer compression of each member from the pair's own loaded cells.
    at = 0
    for p, (cl, cr) in enumerate(zip(loaded, readers, strict=True)):
        if cr.n == 0:
            continue
        rows, sub = np.arange(ends_r[p], ends_r[p + 1]), slice(at, at + cr.n)
        at += cr.n
        if cl.n == 0:
            continue
        fl = F[ends_l[p] : ends_l[p + 1]]
        lay = tangent_layout(cr.centers, cl.centers, cl.normals, cl.edges)
        # the surface and every matching depth of the readers (both members), in one pass
        need = sorted({float(dp) for dp in np.unique(np.concatenate([d1[sub], d2[sub]]))} - {0.0})
        s0, *rest = (m @ fl for m in layout_influences(lay, [0.0, *need], models.E, models.nu))
        done = dict(zip(need, rest, strict=True))  # depth -> reading of every reader
        for dd in (d1[sub], d2[sub]):
            for depth in np.unique(dd):
                if depth == 0.0:
                    continue  # read at the surface: no layer
                k = np.flatnonzero(dd == depth)
                u[rows[k]] += s0[k] - done[float(depth)][k]
    return u


#: A pair carrying less than this share of the torque does not drive the refinement.
MIN_REFINE_SHARE = 0.01


def refined_sizes(cells, sol, cell, n_across, remake=False, missing=(), n_along=None):
    """Per-pair cell grids ``(s_ξ, s_η, angle)`` for the ``hybrid`` refinement, or None if the
    grids are fine enough.

    The loaded patch of every pair is measured on its current grid by the force-weighted second
    moments of the loaded cells (intrinsic cell coordinates): the eigenvectors give the major
    direction ``M`` (minor ``m``), the eigenvalues ``λ`` the semi-axes ``sqrt(5 (λ + span²/12))``
    (the Hertz pressure ``p0 sqrt(1 - x²/a² - y²/b²)`` has ``∫x² p / ∫p = a²/5``; a cell
    spreads its force over its span). A cell of sizes
    ``s = (s_ξ, s_η)`` spans ``|m|·s`` across the patch and ``|M|·s`` along it; the pair is
    accepted when ``2b`` holds ``0.75 n_across`` such spans and ``2a`` holds ``0.75 n_along``
    (default ``n_across``), otherwise its next grid is turned to the patch axes (``η`` along
    ``M``: the thin, long patches of gears are oblique to the flank grid, and an unaligned grid
    fine enough across them has ``(a/b)²`` times more cells) with
    ``s = (2b / n_across, 2a / n_along) / 1.25``, never coarser than the element-size cells. A
    grid whose cells are less than 0.4 times the area of those (too fine, or turned away from
    the patch: a pair's grid starts from the previous position's, where its patch may
    have been much smaller) is re-made the same way. Aiming above the target lets the next grid
    pass, as a coarse grid over-estimates the patch. Each pair gets its own grid: a small patch
    (an edge contact carrying little load) does not refine its neighbour. ``remake``: every
    loaded pair gets the grid made for its patch, accepted or not (the start of the next
    position); pairs without load are left out (they start from the default cells). A pair
    carrying less than ``MIN_REFINE_SHARE`` of the torque keeps its grid: it is an edge contact
    starting or ending, whose patch shrinks with every refinement (measured on the seed face
    gear: a pair with 0.3 % of the torque cost two extra solves of ~1050 cells at one position).
    ``missing``: pairs ``(k, j)`` whose closest point is within the cell bound but which got no
    cell at all on their grid (a separation valley at a flank edge, narrower than the cells
    around it: :func:`fegear.ltca.grid.missing_pairs`); they are treated as idle pairs (below).
    """
    n_along = n_across if n_along is None else n_along
    start, new, refine = 0, {None: cell[None]}, False
    base = cell[None][0]
    idle, heaviest = [], None
    torque = float(np.concatenate([c.h for c in cells]) @ sol.force)
    for c in cells:
        F = sol.force[start : start + c.n]
        start += c.n
        key = (c.k, c.j)
        now = cell.get(key, cell[None])
        if not np.any(F > 0):
            idle.append((key, now))
            continue
        if float(c.h @ F) < MIN_REFINE_SHARE * torque:
            new[key] = now
            continue
        if heaviest is None or F.sum() > heaviest[0]:
            heaviest = (float(F.sum()), key)
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
        ideal = (min(base, b2 / (1.25 * n_across)), min(base, a2 / (1.25 * n_along)))
        fine = b2 >= 0.75 * n_across * span_b and a2 >= 0.75 * n_along * span_a
        wasteful = size[0] * size[1] < 0.4 * ideal[0] * ideal[1]
        if fine and not wasteful and not remake:
            new[key] = now
            continue
        refine = True
        turn = math.atan2(M[1], M[0]) - 0.5 * math.pi  # η onto the major axis
        new[key] = (*ideal, math.remainder(now[2] + turn, math.pi))
    # A pair in the zone that took no load on cells much coarser than a loaded pair's may only
    # have missed its contact: its separation valley (as narrow as the patches) can fall between
    # the centres of coarse cells (measured on the seed face gear: a 2.9 mm cell read 0.019 mm
    # where the valley is 0.0033 mm deep, and the pair, which carries 25 % of the torque, was
    # lost). It gets the grid of the pair carrying the most load (not the finest grid: that is
    # usually an edge contact's, and spread over an idle pair's whole zone it made 47 million
    # cells on the face gear at level 1).
    idle += [(key, cell.get(key, cell[None])) for key in missing if key not in new]
    if idle and heaviest is not None:
        ref = new[heaviest[1]]
        for key, now in idle:
            if now[0] * now[1] > 4.0 * ref[0] * ref[1]:
                new[key], refine = ref, True
            else:
                new[key] = now
    return new if refine else None
