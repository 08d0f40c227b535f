"""The ``hertz`` fidelity: multi-pair load sharing with per-pair Hertz laws and lumped compliance.

The seed's multi-pair algorithm (DESIGN §9). At a position, pair ``i`` has, from the TCA, its
smallest separation ``b_i`` (mm, along the pinion normal; 0 for the pair in contact) and the
moment arm ``h_i`` (mm/rad) of its normal about the member-2 axis. A lag ``θ`` of member 2 gives
it the approach ``Δ_i = θ h_i − b_i``; where ``Δ_i > 0`` it carries the force ``F_i`` solving

.. math:: \\delta^H_i(F_i) + c_i F_i = \\Delta_i ,

with ``δ^H`` the local contact law and ``c_i`` the lumped (tooth bending, shear, body) compliance.
Torque balance ``Σ h_i F_i(θ) = T2`` is monotone in ``θ`` and solved by a bracketed root search;
the pairs take load in the order of their separations as ``θ`` grows. Milliseconds per position
once the ``c_i`` are known.

Local law: point contact (the separation's Hessian at the closest point gives ``A <= B`` in the
tangent plane, :func:`fegear.hertz.hertz_law`: ``δ = c F^{2/3}``); when ``A < 1e-6 B`` the
contact is a line of length ``L`` (the extent along the flat direction of the band where the
separation is within 20 µm of its minimum) and Palmgren's line-contact approach for steel,
``δ = 3.84e-5 F^0.9 / L^0.8`` (mm, N; Palmgren 1959, *Ball and Roller Bearing Engineering*;
Harris & Kotzalas 2006), scaled by ``(E*_steel / E*)^0.9``, is used; the line's peak pressure is
Hertz's ``p0 = sqrt(w E* / (π R))`` for the mean line load ``w = F / L`` and ``1/R = 2B``.

Lumped compliance from the FE operators of the sectors, at the pair's closest point: the cells of
the ``fe`` fidelity within the separation ``b_i + δ_ref`` (``δ_ref`` the local approach under the
whole torque on that pair) carry a uniform unit load ``w``; ``c_i = wᵀ C_FE w − wᵀ S w``, the FE
approach minus the half-space approach of the same load (both bodies, :mod:`fegear.halfspace`):
what the FE carries beyond the local contact deformation, which the Hertz law already counts.
At coarse FE levels the FE under-estimates the local deformation, so ``c_i`` is clipped at zero
(and a warning says so).
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq

from fegear.contact import ContactSolution
from fegear.halfspace import layout_influence, tangent_layout
from fegear.hertz import effective_modulus, hertz_law, hertz_line
from fegear.ltca.grid import pair_cells, separation_at, take_cells, tca_edge_names
from fegear.ltca.results import LoadedPosition, PairLoad
from fegear.ltca.zone import left_out_pairs
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


def _hessian(tca: TCA, pos: PositionResult, i: int, step_mm: float):
    """Separation Hessian at pair ``i``'s closest point in the tangent plane (1/mm), its moment
    arm, and the flank coordinates' mm per unit."""
    u0, v0 = pos.pinion_uv[i]
    b = tca.fm1.bounds
    # mm per unit of u and v (finite differences of the pinion flank)
    du_probe = 1e-4 * (b.u_tip - b.u_fillet)
    dv_probe = 1e-4 * (b.v_end - b.v_start)
    uu = np.array([u0, u0 + du_probe, u0])
    vv = np.array([v0, v0, v0 + dv_probe])
    X, N, _, _, _, _ = separation_at(tca, pos.phi1, -pos.te_rad, i, uu, vv)
    lu = np.linalg.norm(X[1] - X[0]) / du_probe
    lv = np.linalg.norm(X[2] - X[0]) / dv_probe
    hu, hv = step_mm / lu, step_mm / lv
    U = u0 + hu * np.array([-1, 0, 1, -1, 0, 1, -1, 0, 1], dtype=float)
    V = v0 + hv * np.array([-1, -1, -1, 0, 0, 0, 1, 1, 1], dtype=float)
    U = np.clip(U, b.u_fillet, b.u_tip)
    V = np.clip(V, b.v_start, b.v_end)
    X, N, s, h, ok, _ = separation_at(tca, pos.phi1, -pos.te_rad, i, U, V)
    if not ok[4] or ok.sum() < 6:  # at a flank edge: keep the points that meet the gear flank
        return None
    # Local coordinates in the tangent plane at the centre (oblique u, v handled exactly).
    d = X - X[4]
    e1 = X[5] - X[3] if ok[5] and ok[3] else (X[5] - X[4] if ok[5] else X[4] - X[3])
    e1 = e1 - (e1 @ N[4]) * N[4]
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(N[4], e1)
    x, y = d[ok] @ e1, d[ok] @ e2
    Vm = np.column_stack([np.ones(x.size), x, y, x * x, x * y, y * y])
    c, *_ = np.linalg.lstsq(Vm, s[ok], rcond=None)
    H = np.array([[2 * c[3], c[4]], [c[4], 2 * c[5]]])
    return H, float(h[4]), (lu, lv)


def pair_laws(tca, pos, models, torque2_Nmm, E, nu, only=None):
    """The law of every modelled pair at this position (of the grids ``only``, indices into
    ``pos.grids``, if given), with ``b_i`` and ``h_i``."""
    E_star = effective_modulus(E, nu, E, nu)
    out, warnings = [], []
    for gi, g in enumerate(pos.grids):
        if only is not None and gi not in only:
            continue
        i = int(np.flatnonzero((tca.pairs[:, 0] == g.k) & (tca.pairs[:, 1] == g.j))[0])
        if not (pos.pair_valid[i] and models.pinion.has_tooth(g.k) and models.gear.has_tooth(g.j)):
            continue
        hess = None
        for step in (0.1, 0.03, 0.01):
            hess = _hessian(tca, pos, i, step)
            if hess is not None:
                break
        if hess is None and i == pos.contact_pair and pos.ellipse is not None:
            # at a flank edge the stencil leaves the flank: the TCA's ellipse at the contact
            # point has the same relative curvature (A, B)
            A_e, B_e = pos.ellipse.A, pos.ellipse.B
            hess = (np.diag([2 * A_e, 2 * B_e]), float(_moment_arm(tca, pos, i)), None)
        if hess is None:
            if pos.backlash_mm[i] < 0.05:
                warnings.append(f"pair ({g.k}, {g.j}): no curvature at its closest point: left out")
            continue
        H, h_i, _ = hess
        lam = np.linalg.eigvalsh(H)
        A, B = max(lam[0], 0.0) / 2.0, max(lam[1], 0.0) / 2.0
        b_i = float(pos.backlash_mm[i])
        if B <= 0.0:
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
                if b_i < 0.05:  # only a pair that could be reached matters
                    warnings.append(f"pair ({g.k}, {g.j}): no line length: left out")
                continue
            coeff = 3.84e-5 * (_E_STAR_STEEL / E_star) ** 0.9
            local = PairLaw("line", coeff, length, 0.0, B)
            d_ref = local.approach(torque2_Nmm / h_i)
        line = local.kind == "line"
        g_lim = b_i + (max(d_ref, 1e-4) if line else max(4.0 * d_ref, 0.02))
        c_i, warn = _lumped(tca, pos, gi, models, g_lim, E, nu, line=line)
        if warn:
            warnings.append(f"pair ({g.k}, {g.j}): {warn}")
        local.lumped = c_i
        out.append((g.k, g.j, i, b_i, h_i, local))
    return out, warnings


def _moment_arm(tca, pos, i: int) -> float:
    """Moment arm ``h`` of pair ``i`` at its closest point."""
    u0, v0 = pos.pinion_uv[i]
    _, _, _, h, _, _ = separation_at(tca, pos.phi1, -pos.te_rad, i, np.array([u0]), np.array([v0]))
    return float(h[0])


def _lumped(tca, pos, gi, models, g_lim, E, nu, line: bool = False):
    """``c = wᵀ C_FE w − wᵀ S w`` on the fe cells within separation ``g_lim`` (see module)."""

    cells = None
    for grow in (1.0, 4.0, 16.0, 64.0):  # the coarse TCA grid may straddle a thin band
        cells = pair_cells(tca, pos, gi, models.cell_mm, g_lim * grow)
        if cells is not None:
            break
    if cells is None:
        return 0.0, "no FE cells at the closest point: lumped compliance 0"
    # the unit load: along the whole band for a line contact; for a point contact on the cells
    # within 2.5 cells of the pair's closest point, a patch the FE resolves (a single coarse cell
    # would be under-resolved and the FE stiffer than the half-space). Only those cells enter
    # wᵀ C w (C is pairwise): the others are left out before C is made.
    i = int(np.flatnonzero((tca.pairs[:, 0] == cells.k) & (tca.pairs[:, 1] == cells.j))[0])
    r = np.linalg.norm(cells.centers - pos.points[i], axis=1)
    near = np.ones(cells.n, dtype=bool) if line else r <= 2.5 * float(np.max(cells.cell_mm))
    if not near.any():
        near = r <= r.min() + 1e-12
    cells = take_cells(cells, np.flatnonzero(near))
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
        cells = take_cells(cells, np.flatnonzero(covered))
    C = models.kind.compliance(tca, pos, models, [cells])
    w = np.full(cells.n, 1.0 / cells.n)
    lay = tangent_layout(cells.centers, cells.centers, cells.normals, cells.edges)
    S = 2.0 * layout_influence(lay, 0.0, E, nu)
    c = float(w @ C @ w - w @ S @ w)
    if c < 0.0:
        clip = f"FE stiffer than the half-space at this level (c = {c:.3g} mm/N): clipped to 0"
        return 0.0, "; ".join(filter(None, (note, clip)))
    return c, note


def _covered(tca, pos, models, cells) -> np.ndarray:
    """``(n,)`` bool: the cells whose consistent loads lie on DOFs both members' compliance
    operators cover (their load DOFs, or constrained DOFs)."""
    from fegear.ltca.model import cell_load_operators

    M1, M2 = tca.asm.placement1(pos.phi1), tca.asm.placement2(pos.phi2)
    ok = np.ones(cells.n, dtype=bool)
    loads = cell_load_operators(models, M1, M2, [cells])
    for model, P in zip((models.pinion, models.gear), loads, strict=True):
        outside = np.ones(P.shape[0])
        outside[np.union1d(model.op.cols, model.op.fixed)] = 0.0
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
    laws, warnings = pair_laws(tca, pos, models, torque2_Nmm, E, nu, only=near)
    if not laws:
        return _lost(pos, "no pair with a Hertz law at this position")
    far = [gi for gi in range(len(pos.grids)) if gi not in near]
    while True:
        theta = _lag(laws, torque2_Nmm)
        closing = [gi for gi in far if _closes(tca, pos, pos.grids[gi], theta)]
        if not closing:
            break
        more, notes = pair_laws(tca, pos, models, torque2_Nmm, E, nu, only=set(closing))
        laws += more
        warnings += notes
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
        # The closest point on a flank boundary makes the pair an edge contact, whose Hertz p0
        # is not the pressure there (singular). Except a line contact whose closest point is at
        # a face end only: its p0 is that of the mean line load along the whole face, an interior
        # value (the face-end peak is not modelled by this fidelity; FZG with a 0.01 mm axis
        # tilt: the closest point of every line moves to a face end).
        tags = [t for t in pos.edge[i].split(",") if t]
        face_ends = all(t.endswith((":v_start", ":v_end")) for t in tags)
        at_edge = bool(tags) and not (law.kind == "line" and face_ends)
        loads.append(
            PairLoad(
                k=k,
                j=j,
                force_N=float(f),
                torque_Nmm=float(h * f),
                load_share=float(h * f / torque2_Nmm),
                p_max_MPa=float(p0),
                p_peak_MPa=float(p0),
                semi_major_mm=float(a),
                semi_minor_mm=float(bb),
                n_active=0,
                edge_contact=bool(pos.edge[i]) and bool(f > 0.0),
                contact_point=pos.points[i].copy(),
                edges=tca_edge_names(pos.edge[i], b1, b2) if f > 0.0 else (),
                p_interior_MPa=float(p0) if f > 0.0 and not at_edge else None,
                p_edge_MPa=float(p0) if f > 0.0 and at_edge else None,
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
    )
