"""The ``hertz`` fidelity: multi-pair load sharing with per-pair Hertz laws and lumped compliance.

The seed's multi-pair algorithm (``docs/fidelity.md``). At a position, pair ``i`` has, from the TCA,
its smallest separation ``b_i`` (mm, along the pinion normal; 0 for the pair in contact) and the
moment arm ``h_i`` (mm/rad) of its normal about the member-2 axis. A lag ``θ`` of member 2 gives it
the approach ``Δ_i = θ h_i − b_i``; where ``Δ_i > 0`` it carries the force ``F_i`` solving

.. math:: \\delta^H_i(F_i) + c_i F_i = \\Delta_i ,

with ``δ^H`` the local contact law and ``c_i`` the lumped (tooth bending, shear, body) compliance.
Torque balance ``Σ h_i F_i(θ) = T2`` is monotone in ``θ`` and solved by a bracketed root search;
the pairs take load in the order of their separations as ``θ`` grows. Milliseconds per position
once the ``c_i`` are known.

Local law: point contact (the relative curvature of the flanks at the closest point gives
``A <= B``, :func:`_relative_curvature`, :func:`fegear.mechanics.hertz_closed_form.hertz_law`: ``δ
= c F^{2/3}``); when
``A < 1e-6 B`` the contact is a line of length ``L`` (the extent along the flat direction of the
band where the separation is within 20 µm of its minimum) and Palmgren's line-contact approach
for steel, ``δ = 3.84e-5 F^0.9 / L^0.8`` (mm, N; Palmgren 1959, *Ball and Roller Bearing
Engineering*; Harris & Kotzalas 2006), scaled by ``(E*_steel / E*)^0.9``, is used; the line's
peak pressure is Hertz's ``p0 = sqrt(w E* / (π R))`` for the mean line load ``w = F / L`` and
``1/R = 2B``.

Lumped compliance from the FE operators of the sectors, at the pair's closest point: a unit load
``w`` on contact cells near it, ``c_i = wᵀ C_FE w − wᵀ S w``, the FE approach minus the half-space
approach of the same load (both bodies, :mod:`fegear.mechanics.halfspace`): what the FE carries
beyond
the local contact deformation, which the Hertz law already counts. For a line contact ``w`` is
uniform on the ``fe`` cells of the band within ``b_i + δ_ref`` (``δ_ref`` the local approach
under the whole torque on that pair). For a point contact it is a smooth bump on cells of a
quarter element, ``w ∝ (1 − r²/R²) · min(1, d/ρ)`` within ``R = 2.5`` elements of the closest
point (a patch the FE resolves), faded out over ``ρ`` = one element from the boundaries of both
working flanks (``d`` the distance to the nearest, :func:`_unit_load`): the load then moves
continuously as the contact approaches, runs along and leaves a flank edge (a uniform load on
the element-sized cells within ``R`` changed by a whole cell there, and the lumped compliance of
the seed face gear's entering pair stepped by 4.5 % when its closest point left the gear's tip).
At coarse FE levels the FE under-estimates the local deformation, so ``c_i`` is clipped at zero
(and a warning says so).

A pair whose closest point lies on a flank edge is an edge contact: the law of the flanks'
curvatures there gives its force (continuous with the interior), but its pressure is the edge's
(singular), which no closed form gives: its pressures are None with the reason
(:attr:`fegear.ltca.results.PairContact.pressure_reason`). A pair within reach of contact that gets
no law (no curvature, a relative curvature that is not positive, no line length) makes the
position degenerate if the lag closes it (its load would be missing from the balance).
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq

from fegear.geometry.pair_placement import tooth_transform
from fegear.geometry.surface import finite_difference_curvatures
from fegear.geometry.transforms import apply_vectors, compose
from fegear.ltca.grid import pair_cells, separation_at, take_cells, tca_edge_names
from fegear.ltca.model import cell_load_operators
from fegear.ltca.results import LoadedPosition, PairContact
from fegear.ltca.zone import left_out_pairs
from fegear.mechanics.contact import ContactSolution
from fegear.mechanics.halfspace import layout_influence, tangent_layout
from fegear.mechanics.hertz_closed_form import effective_modulus, hertz_law, hertz_line
from fegear.tca.core import TCA
from fegear.tca.results import ARCSEC, PositionResult

__all__ = ["PairLaw", "pair_laws", "solve_position_hertz"]

log = logging.getLogger(__name__)
_E_STAR_STEEL = 206000.0 / (2.0 * (1.0 - 0.3**2))
_EPS = float(np.finfo(float).eps)


class PairLaw:
    """Force–approach law of one pair: ``δ(F) = δ_H(F) + c F`` (mm, N)."""

    def __init__(
        self, kind: str, coeff: float, length: float, lumped: float, B: float, law=None
    ) -> None:
        self.kind, self.coeff, self.length, self.lumped = kind, coeff, length, lumped
        self.B, self.law = B, law

    def approach(self, F: float) -> float:
        if F <= 0.0:
            return 0.0
        if self.kind == "point":
            local = self.coeff * F ** (2.0 / 3.0)
        else:
            local = self.coeff * F**0.9 / self.length**0.8
        return local + self.lumped * F

    def force(self, delta: float) -> float:
        """Inverse of :meth:`approach` (monotone), by a bracketed root search."""
        if delta <= 0.0:
            return 0.0
        hi = 1.0
        while self.approach(hi) < delta:
            hi *= 4.0
        # relative tolerance: the force of a tiny approach is tiny (an absolute 1e-14 hi was
        # a visible part of it at 1e-6 N·m)
        return brentq(lambda f: self.approach(f) - delta, 0.0, hi, xtol=1e-300, rtol=4.0 * _EPS)


def _relative_curvature(tca: TCA, pos: PositionResult, i: int, native=None):
    """``(A, B)`` (1/mm, ``A <= B``) of pair ``i`` at its closest point: the relative curvature of
    the two flanks there, from each flank's principal curvatures and directions (central
    differences of the exact flank maps; the curvature tensors of both surfaces, each
    ``Σ κ_k d_k d_kᵀ`` in the fixed frame, summed and halved in the tangent plane of the pinion
    normal, as :meth:`fegear.tca.TCA` computes the contact ellipse; Litvin & Fuentes 2004,
    *Gear Geometry and Applied Theory*, §9.3), or None if a flank cannot be evaluated there.

    This is the Hessian of the separation at the closest point divided by two, which the law
    needs, without sampling the separation around the point: a stencil of separations leaves
    the mate's working flank when the closest point is on an edge of it (its normal lines miss
    the flank beyond the edge), and a one-sided fit there gave a negative curvature, a line law
    and a TE step at the handover; or, with the centre itself off the flank, no law at all and
    the pair dropped (the seed face gear, Δγ = +0.02°, moderate load, φ1 = −3.744°: the other
    pair took 100 % of the load). The flank maps are evaluated a few finite-difference steps
    inside their native parameter box, which extends beyond the working flank: the curvature at
    an edge is the flank's own, continuous with the interior."""
    a = tca.asm
    k, j = (int(x) for x in tca.pairs[i])
    frames = (
        compose(a.placement1(pos.phi1), tooth_transform(a.n1, k)),
        compose(a.placement2(pos.phi2), tooth_transform(a.n2, j)),
    )
    K, n1 = [], None
    native = native if native is not None else _natives(tca, pos, [i])[i]
    for fm, (pa, pb), M in zip((tca.fm1, tca.fm2), native, frames, strict=True):
        h = (50 * fm.step[0], 50 * fm.step[1])  # as the TCA's ellipse: 0.01 mm, 1e-3 rad
        lo, hi = fm.native_box()
        pa = float(np.clip(pa, lo[0] + h[0], hi[0] - h[0]))
        pb = float(np.clip(pb, lo[1] + h[1], hi[1] - h[1]))
        nrm = fm.evaluate(pa, pb)[1]
        kappa, d = finite_difference_curvatures(
            lambda x, y, fm=fm: fm.evaluate(x, y)[0], pa, pb, h, nrm
        )
        if not (np.all(np.isfinite(kappa)) and np.all(np.isfinite(d))):
            return None
        d = apply_vectors(M, d)
        K.append(kappa[0] * np.outer(d[0], d[0]) + kappa[1] * np.outer(d[1], d[1]))
        if n1 is None:
            n1 = apply_vectors(M, np.asarray(nrm, dtype=float))
            n1 = n1 / np.linalg.norm(n1)
    e1 = np.cross(n1, [0.0, 0.0, 1.0]) if abs(n1[2]) < 0.9 else np.cross(n1, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    E = np.stack([e1, np.cross(n1, e1)], -1)
    S = 0.5 * E.T @ (K[0] + K[1]) @ E
    w = np.linalg.eigvalsh(0.5 * (S + S.T))
    if not np.all(np.isfinite(w)):
        return None
    return float(w[0]), float(w[1])


def _natives(tca: TCA, pos: PositionResult, idx) -> dict:
    """Native flank parameters of the closest points of pairs ``idx``: ``{i: ((a1, b1), (a2,
    b2))}`` on the pinion and the gear, each flank's inversion made once for all of them (the
    face gear's is an envelope solve: one call costs as much as several points)."""
    idx = list(idx)
    out: dict = {i: [] for i in idx}
    for fm, uv in ((tca.fm1, pos.pinion_uv), (tca.fm2, pos.gear_uv)):
        a, b = fm.native(uv[idx, 0], uv[idx, 1])
        for i, x, y in zip(idx, np.atleast_1d(a), np.atleast_1d(b), strict=True):
            out[i].append((float(x), float(y)))
    return out


def _arm(tca, pos, i: int) -> float:
    """Moment arm ``h`` (mm/rad) of pair ``i``'s normal about the member-2 axis at its closest
    point; where the normal line there misses the mate's working flank (a closest point on its
    edge), the TCA's lever of the pair, ``backlash_mm / backlash_rad``."""
    h = _moment_arm(tca, pos, i)
    if np.isfinite(h) and h > 0.0:
        return h
    if pos.backlash_rad[i] > 0.0 and pos.backlash_mm[i] > 0.0:
        return float(pos.backlash_mm[i] / pos.backlash_rad[i])
    return float("nan")


def pair_laws(tca, pos, models, torque2_Nmm, E, nu, only=None):
    """The law of every modelled pair at this position (of the grids ``only``, indices into
    ``pos.grids``, if given), with ``b_i`` and ``h_i``: ``(laws, warnings, lawless)``.

    ``lawless``: ``(k, j, i, why)`` of the pairs within 0.05 mm of contact that get no law (no
    curvature or moment arm at the closest point, a relative curvature that is not positive, a
    line contact without length); :func:`solve_position_hertz` flags the position when the lag
    closes one of them (it would carry load the law cannot give)."""
    E_star = effective_modulus(E, nu, E, nu)
    out, warnings, lawless = [], [], []
    todo = []
    for gi, g in enumerate(pos.grids):
        if only is not None and gi not in only:
            continue
        i = int(np.flatnonzero((tca.pairs[:, 0] == g.k) & (tca.pairs[:, 1] == g.j))[0])
        if pos.pair_valid[i] and models.pinion.has_tooth(g.k) and models.gear.has_tooth(g.j):
            todo.append((gi, g, i))
    natives = _natives(tca, pos, [i for _, _, i in todo]) if todo else {}
    for gi, g, i in todo:
        curv = _relative_curvature(tca, pos, i, natives[i])
        h_i = _arm(tca, pos, i)
        near = pos.backlash_mm[i] < 0.05  # only a pair that could be reached matters
        if curv is None or not np.isfinite(h_i):
            if near:
                lawless.append((int(g.k), int(g.j), i, "no curvature or moment arm"))
            continue
        A, B = max(curv[0], 0.0), max(curv[1], 0.0)
        b_i = float(pos.backlash_mm[i])
        if B <= 0.0:
            if near:
                lawless.append((int(g.k), int(g.j), i, "no positive relative curvature"))
            continue
        if A >= 1e-6 * B:  # elongated point contacts (face gear: A/B ~ 1e-3) stay points
            law = hertz_law(A, B, E_star)
            local = PairLaw("point", law.compliance_coeff, 0.0, 0.0, B, law)
            d_ref = local.approach(torque2_Nmm / h_i)
        else:
            # line contact: its length is the extent, along the flat direction, of the band of
            # cells within 20 µm of the closest separation (cells of an eighth of the element
            # size: the length is then known to 1/8 element, not to a whole cell)
            cells = pair_cells(tca, pos, gi, models.cell_mm / 8.0, b_i + 0.02)
            length = 0.0
            if cells is not None:
                e = (
                    np.array([1.0, 0.0])
                    if np.ptp(cells.local[:, 0]) > np.ptp(cells.local[:, 1])
                    else np.array([0.0, 1.0])
                )
                proj = cells.local @ e
                length = float(np.ptp(proj) + np.mean(cells.cell_mm))
            if length <= 0.0:
                if near:
                    lawless.append((int(g.k), int(g.j), i, "no line length"))
                continue
            coeff = 3.84e-5 * (_E_STAR_STEEL / E_star) ** 0.9
            local = PairLaw("line", coeff, length, 0.0, B)
            d_ref = local.approach(torque2_Nmm / h_i)
        line = local.kind == "line"
        g_lim = b_i + (max(d_ref, 1e-4) if line else max(4.0 * d_ref, 0.02))
        c_i, warn = _lumped(tca, pos, gi, models, g_lim, E, nu, line=line, b_i=b_i)
        if warn:
            warnings.append(f"pair ({g.k}, {g.j}): {warn}")
        local.lumped = c_i
        out.append((g.k, g.j, i, b_i, h_i, local))
    return out, warnings, lawless


def _moment_arm(tca, pos, i: int) -> float:
    """Moment arm ``h`` of pair ``i`` at its closest point."""
    u0, v0 = pos.pinion_uv[i]
    _, _, _, h, _, _ = separation_at(tca, pos.phi1, -pos.te_rad, i, np.array([u0]), np.array([v0]))
    return float(h[0])


def _lumped(tca, pos, gi, models, g_lim, E, nu, line: bool = False, b_i=0.0):
    """``c = wᵀ C_FE w − wᵀ S w``, ``w`` the unit load of a line contact (uniform on the fe cells
    within separation ``g_lim``) or of a point contact (:func:`_unit_load`): see the module."""
    g = pos.grids[gi]
    i = int(np.flatnonzero((tca.pairs[:, 0] == g.k) & (tca.pairs[:, 1] == g.j))[0])
    if line:
        cells = None
        for grow in (1.0, 4.0, 16.0, 64.0):  # the coarse TCA grid may straddle a thin band
            cells = pair_cells(tca, pos, gi, models.cell_mm, g_lim * grow)
            if cells is not None:
                break
        weight = None if cells is None else np.ones(cells.n)
    else:
        cells, weight = _unit_load(tca, pos, gi, i, models.cell_mm, g_lim, b_i)
    if cells is None:
        return 0.0, "no contact cells at the closest point: lumped compliance 0"
    # the compliance operators cover the working flanks of the teeth in the sectors' contact
    # zone only (fegear.ltca.model): a pair at the zone's fringe keeps the cells they cover
    covered = _covered(tca, pos, models, cells)
    note = ""
    if not covered.all():
        if not covered.any():
            return 0.0, "closest point outside the sectors' contact zone: lumped compliance 0"
        note = (
            f"{int((~covered).sum())} of {cells.n} unit-load cells outside the sectors' contact "
            "zone: left out of the lumped compliance"
        )
        cells, weight = take_cells(cells, np.flatnonzero(covered)), weight[covered]
    if not weight.sum() > 0.0:
        return 0.0, "no unit load inside the flanks at the closest point: lumped compliance 0"
    C = models.kind.compliance(tca, pos, models, [cells])
    w = weight / weight.sum()
    lay = tangent_layout(cells.centers, cells.centers, cells.normals, cells.edges)
    S = 2.0 * layout_influence(lay, 0.0, E, nu)
    c = float(w @ C @ w - w @ S @ w)
    if c < 0.0:
        clip = f"FE stiffer than the half-space at this level (c = {c:.3g} mm/N): clipped to 0"
        return 0.0, "; ".join(filter(None, (note, clip)))
    return c, note


#: Unit load of the lumped compliance at a point contact: its radius and the length over which it
#: fades out towards a flank boundary, in elements; the cells, in elements (_unit_load).
_LOAD_RADIUS, _LOAD_FADE, _LOAD_CELL = 2.5, 0.25, 0.25


def _unit_load(tca, pos, gi, i, h_mm, g_lim, b_i):
    """``(cells, weight)``: the cells and the (unnormalised) unit load of a point contact's
    lumped compliance (the module docstring), or ``(None, None)`` if no cell is near.

    The load lies where the pair can touch, on cells of ``_LOAD_CELL · h`` within
    ``R = _LOAD_RADIUS · h`` of pair ``i``'s closest point whose separation is below ``g_lim``
    (``b_i``: the closest point's), and fades out to
    zero over ``ρ = _LOAD_FADE · h`` towards each of those limits and towards the boundaries of
    both working flanks:

    ``w = area · t((R − r)/ρ) · t(d/ρ) · t((g_lim − s) / (0.25 (g_lim − b_i)))``,
    ``t(x) = min(1, max(0, x))``,

    ``r`` the distance to the closest point, ``d`` to the nearest flank boundary, ``s`` the
    cell's separation. A cell then enters or leaves the load with zero weight as the contact
    moves from one position to the next (a hard cut by any of these limits changed the load by
    whole cells); the cells :func:`fegear.ltca.grid.pair_cells` leaves out beyond ``g_lim``
    would have none."""
    R, rho = _LOAD_RADIUS * h_mm, _LOAD_FADE * h_mm
    origin = np.asarray(pos.points[i], dtype=float)
    cells = None
    for grow in (1.0, 4.0, 16.0, 64.0):  # the coarse TCA grid may straddle a thin band
        cells = pair_cells(tca, pos, gi, _LOAD_CELL * h_mm, g_lim * grow, max_cells=4000)
        if cells is not None and np.any(np.linalg.norm(cells.centers - origin, axis=1) < R):
            break
    if cells is None:
        return None, None
    r = np.linalg.norm(cells.centers - origin, axis=1)
    keep = (r < R) & (cells.gap < g_lim)  # (a widened band: the cells within g_lim)
    if not keep.any():  # a valley narrower than the cells: the nearest one
        keep = r <= r.min()
    cells, r = take_cells(cells, np.flatnonzero(keep)), r[keep]
    d = _boundary_distance(tca, pos, i, cells)
    band = max(0.25 * (g_lim - b_i), 1e-12)
    t = lambda x: np.clip(x, 0.0, 1.0)  # noqa: E731
    w = cells.area * t((R - r) / rho) * t(d / rho) * t((g_lim - cells.gap) / band)
    if not w.sum() > 0.0:  # on a boundary only: the cells as they are
        w = cells.area.copy()
    return cells, w


def _boundary_distance(tca, pos, i, cells) -> np.ndarray:
    """``(n,)`` mm: distance of each cell centre to the nearest boundary of the pinion's working
    flank (its ``(u, v)``) or of the gear's (the gear-flank point its normal line meets), each
    parameter scaled by its flank's mm per unit there (:func:`_metric`)."""
    U, V = cells.uv[:, 0], cells.uv[:, 1]
    X, N, sep, _, ok, guv = separation_at(tca, pos.phi1, -pos.te_rad, i, U, V)
    out = np.full(cells.n, np.inf)
    gear_points = X + sep[:, None] * N  # where the normal lines meet the gear's flank
    for fm, uv, P, at in (
        (tca.fm1, cells.uv, X, pos.pinion_uv[i]),
        (tca.fm2, guv, gear_points, pos.gear_uv[i]),
    ):
        b = fm.bounds
        lu, lv = _metric(uv[ok], P[ok], fm, at)
        d = np.minimum.reduce(
            [
                (uv[:, 0] - b.u_fillet) * lu,
                (b.u_tip - uv[:, 0]) * lu,
                (uv[:, 1] - b.v_start) * lv,
                (b.v_end - uv[:, 1]) * lv,
            ]
        )
        out = np.minimum(out, d)
    return np.where(ok, np.maximum(out, 0.0), 0.0)


def _metric(uv: np.ndarray, P: np.ndarray, fm, at) -> tuple[float, float]:
    """mm per unit of a flank's ``u`` and ``v`` near the cells: the columns of the least-squares
    linear map from the cells' flank parameters ``uv`` ``(n, 2)`` to their points ``P``
    ``(n, 3)`` (the cells span a few mm: the flank's metric is constant there to a fraction of
    a per cent). With fewer than three cells, or cells on a line, forward differences of the
    flank map at ``at`` (1e-4 of the flank's extent, towards its inside)."""
    if uv.shape[0] >= 3:
        A = np.column_stack([np.ones(uv.shape[0]), uv - uv.mean(axis=0)])
        if np.linalg.matrix_rank(A) == 3:
            J = np.linalg.lstsq(A, P, rcond=None)[0][1:]
            return float(np.linalg.norm(J[0])), float(np.linalg.norm(J[1]))
    b = fm.bounds
    u, v = float(at[0]), float(at[1])
    du, dv = 1e-4 * (b.u_tip - b.u_fillet), 1e-4 * (b.v_end - b.v_start)
    du = du if u + du <= b.u_tip else -du
    dv = dv if v + dv <= b.v_end else -dv
    _, _, Q, _ = fm.native_point(np.array([u, u + du, u]), np.array([v, v, v + dv]))
    lu = float(np.linalg.norm(Q[1] - Q[0]) / abs(du))
    return lu, float(np.linalg.norm(Q[2] - Q[0]) / abs(dv))


def _covered(tca, pos, models, cells) -> np.ndarray:
    """``(n,)`` bool: the cells whose consistent loads lie on DOFs both members' compliance
    operators cover (their load DOFs, or constrained DOFs)."""
    M1, M2 = tca.asm.placement1(pos.phi1), tca.asm.placement2(pos.phi2)
    ok = np.ones(cells.n, dtype=bool)
    loads = cell_load_operators(models, M1, M2, [cells])
    for model, P in zip((models.pinion, models.gear), loads, strict=True):
        outside = np.ones(P.shape[0])
        outside[model.op.load_support] = 0.0
        ok &= (abs(sp.csr_matrix(P)).T @ outside) == 0.0
    return ok


def _backlash(tca, pos, g) -> float:
    """mm, separation at the closest point of the pair of grid ``g`` (inf if not valid)."""
    i = int(np.flatnonzero((tca.pairs[:, 0] == g.k) & (tca.pairs[:, 1] == g.j))[0])
    return float(pos.backlash_mm[i]) if pos.pair_valid[i] else np.inf


def _closes(tca, pos, g, theta: float) -> bool:
    """Whether the lag ``theta`` closes the pair of grid ``g`` at its closest point."""
    i = int(np.flatnonzero((tca.pairs[:, 0] == g.k) & (tca.pairs[:, 1] == g.j))[0])
    return bool(pos.pair_valid[i] and pos.backlash_rad[i] < theta)


def _lag(laws, torque2_Nmm: float) -> float:
    """The lag ``θ`` (rad) at which the pairs' forces balance the torque."""
    hvec = np.array([h for (_, _, _, _, h, _) in laws])

    def residual(theta: float) -> float:
        forces = np.array([law.force(theta * h - b) for (_, _, _, b, h, law) in laws])
        return float(hvec @ forces) - torque2_Nmm

    hi = max(1e-9, min(b / h for (_, _, _, b, h, _) in laws) + 1e-7)
    while residual(hi) < 0.0:
        hi *= 2.0
    # relative tolerance only: an absolute one (1e-16 rad, once) is a large part of the lag at
    # a tiny torque (1e-6 N·m on FZG: lag ~1e-10 rad, the shares summed to 1 + 6.9e-6)
    return float(brentq(residual, 0.0, hi, xtol=1e-300, rtol=4.0 * _EPS))


def _lost(pos: PositionResult, reason: str) -> LoadedPosition:
    return LoadedPosition.lost(pos.phi1, pos.te_arcsec, bool(pos.has_contact), reason)


def solve_position_hertz(tca, pos, models, torque2_Nmm, E=206000.0, nu=0.3) -> LoadedPosition:
    """Load sharing at one position with the ``hertz`` fidelity (see the module docstring)."""
    if not pos.has_contact:
        return _lost(pos, "no contact: the flanks do not meet at this position")
    # Pairs farther from contact than the sectors' contact zone reaches get their law only if the
    # solved lag closes them: the compliance operators cover the flanks of the zone's teeth only
    # (fegear.ltca.model), and a law's lumped compliance reads the FE at the pair's
    # closest point (FZG: pairs 2.8 and 6.4 mm from contact at their tips).
    reach = float(models.zone.gap_mm) if models.zone is not None else np.inf
    near = {gi for gi, g in enumerate(pos.grids) if _backlash(tca, pos, g) <= reach}
    laws, warnings, lawless = pair_laws(tca, pos, models, torque2_Nmm, E, nu, only=near)
    if not laws:
        return _lost(pos, "no pair with a Hertz law at this position")
    far = [gi for gi in range(len(pos.grids)) if gi not in near]
    while True:
        theta = _lag(laws, torque2_Nmm)
        closing = [gi for gi in far if _closes(tca, pos, pos.grids[gi], theta)]
        if not closing:
            break
        more, notes, none = pair_laws(tca, pos, models, torque2_Nmm, E, nu, only=set(closing))
        laws += more
        warnings += notes
        lawless += none
        far = [gi for gi in far if gi not in closing]
    hvec = np.array([h for (_, _, _, _, h, _) in laws])
    F = np.array([law.force(theta * h - b) for (_, _, _, b, h, law) in laws])
    eq = abs(hvec @ F - torque2_Nmm) / torque2_Nmm
    loads = []
    E_star = effective_modulus(E, nu, E, nu)
    b1, b2 = tca.fm1.bounds, tca.fm2.bounds
    for (k, j, i, _b, h, law), f in zip(laws, F, strict=True):
        if f > 0.0 and law.kind == "point":
            hp = law.law.point(f)
            p0, a, bb = hp.p0_MPa, hp.a_mm, hp.b_mm
        elif f > 0.0:
            # line contact: Hertz line p0 and half-width for the mean line load, 1/R = 2B
            hl = hertz_line(f / law.length, 1.0 / (2.0 * law.B), E_star)
            p0, a, bb = hl.p0_MPa, 0.5 * law.length, hl.b_mm
        else:
            p0, a, bb = 0.0, 0.0, 0.0
        # The closest point on a flank boundary makes the pair an edge contact: its force comes
        # from the law of the flanks' curvatures there, but its pressure is the edge's
        # (singular), which no closed form gives; the Hertz p0 of the continued flanks is not
        # it (25-288 MPa at the seed face gear's edges, below the interior values, where
        # hybrid reads 1400-2950 MPa): the pair's pressures are None, with the reason. Except a
        # line contact whose closest point is at a face end only: its p0 is that of the mean
        # line load along the whole face, an interior value (the face-end peak is not modelled
        # by this fidelity; FZG with a 0.01 mm axis tilt: the closest point of every line moves
        # to a face end).
        tags = [t for t in pos.edge[i].split(",") if t]
        face_ends = all(t.endswith((":v_start", ":v_end")) for t in tags)
        at_edge = bool(tags) and not (law.kind == "line" and face_ends)
        edges = tca_edge_names(pos.edge[i], b1, b2) if f > 0.0 else ()
        why = ""
        if f > 0.0 and at_edge:
            why = (
                f"hertz: the closest point is on the flank edge ({', '.join(edges)}): the "
                "pressure there is the edge's, singular, which a closed-form law does not give "
                "(fe or hybrid resolve the patch)"
            )
        p_val = float(p0) if not why else float("nan")
        loads.append(
            PairContact(
                k=k,
                j=j,
                force_N=float(f),
                torque_Nmm=float(h * f),
                load_share=float(h * f / torque2_Nmm),
                p_max_MPa=p_val,
                p_peak_MPa=p_val,
                semi_major_mm=float(a),
                semi_minor_mm=float(bb),
                n_active=0,
                edge_contact=bool(pos.edge[i]) and bool(f > 0.0),
                contact_point=pos.points[i].copy(),
                edges=edges,
                p_interior_MPa=float(p0) if f > 0.0 and not at_edge else None,
                p_edge_MPa=None,
                pressure_reason=why,
            )
        )
    sol = ContactSolution(
        force=F,
        gap=np.zeros_like(F),
        active=F > 0.0,
        theta=float(theta),
        iterations=0,
        equilibrium_residual=float(eq),
        complementarity_residual=0.0,
        max_penetration=0.0,
        min_active_force=float(F[F > 0].min()) if np.any(F > 0) else 0.0,
    )
    left = left_out_pairs(pos, models, float(theta), warnings)
    te_l = pos.te_arcsec - theta / ARCSEC
    status, reason = "ok", ""
    closed = [(k, j, why) for k, j, i, why in lawless if pos.backlash_rad[i] < theta]
    if closed:
        status = "degenerate"
        reason = f"phi1 = {np.degrees(pos.phi1):.3f} deg: " + "; ".join(
            f"pair ({k}, {j}) closes under the lag but has no Hertz law ({why}): its load is "
            "missing from the balance"
            for k, j, why in closed
        )
        warnings.append(reason)
    return LoadedPosition(
        phi1=pos.phi1,
        te_unloaded_arcsec=pos.te_arcsec,
        te_loaded_arcsec=te_l,
        theta=float(theta),
        pairs=tuple(loads),
        cells=(),
        pressure=(),
        solution=sol,
        g_max_mm=0.0,
        warnings=tuple(warnings),
        left_out=left,
        status=status,
        status_reason=reason,
    )
