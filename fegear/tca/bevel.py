"""Spiral bevel TCA studies: the designed TE parabola, the path direction, installation errors.

The TCA itself is the general one (:func:`~fegear.tca.cycle.run_tca` with
:class:`~fegear.tca.surfaces.SpiralBevelMap` flanks); this module only reads its results in the
terms of bevel practice:

- **Pattern centre**: the mean of the contact path on the gear flank over one mesh cycle, in cone
  distance ``L`` (mm, toe → heel) and height ``h`` above the pitch cone (mm, root → top); its
  change under an error is the "pattern shift" (toward heel: ``ΔL > 0``; toward top: ``Δh > 0``).
- **TE parabola**: a quadratic ``TE(φ1) = c0 + c1 φ1 + c2 φ1²`` fitted to the TE curve of the
  mean pair (pair ``m = 0``) over the cycle; its vertex ``φ* = −c1/(2 c2)`` and height
  ``TE(φ*)`` (the shift of the parabola), its amplitude ``−c2 (π/N1)²``.
- **First-order TE shift** (envelope theorem): a small rigid displacement of the pinion relative
  to the gear that moves the pinion contact point ``M`` by ``δr`` changes the gap at ``M`` along
  the gear normal ``n`` (out of the gear tooth) by ``δr · n``; a lag ``θ`` of the gear closes it
  by ``θ h`` with ``h = (σ e2 × (M − A2)) · n`` (gear rotation axis ``−σ e2`` through the gear
  apex ``A2`` in its driving sense), so ``ΔTE = −θ = −(δr · n)/h`` at ``φ1 = 0`` to first order,
  whatever the contact point shift (the gap is stationary at the contact point). ``δr`` is the
  displacement of the pinion relative to the gear at ``M`` that the assembly's error transforms
  make (:func:`fegear.geometry.pair_placement.spiral_bevel_assembly`): for intersecting axes
  ``ΔE e_y`` (ΔE), ``ΔP e_z`` (ΔP), ``−ΔG e2`` (ΔG, the gear moves), ``(−Δγ e_y) × M`` (Δγ,
  pinion axis turned about ``e_y`` through the apex by ``−Δγ``), to first order.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..geometry.pair_placement import InstallationErrors, spiral_bevel_assembly
from ..geometry.transforms import apply_points, inverse
from .core import TCAOptions
from .cycle import run_tca
from .results import ARCSEC, CycleResult

__all__ = [
    "ErrorEffect",
    "te_parabola",
    "pattern_centre",
    "first_order_te_shift",
    "error_effects",
    "path_angle_on_gear",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


@dataclass(frozen=True)
class ErrorEffect:
    """How one set of installation errors changes the unloaded TCA of a spiral bevel pair.

    Attributes
    ----------
    label
        Name of the case (e.g. ``"ΔE=+0.05 mm"``).
    errors
        The installation errors.
    has_contact
        Every position of the cycle has contact (otherwise the other fields are 0).
    dL_mm, dh_mm
        Shift of the pattern centre on the gear flank relative to the error-free pair: along the
        face (``> 0`` toward the heel) and in height (``> 0`` toward the top), mm.
    te_pp_arcsec
        Peak-to-peak unloaded TE over the cycle.
    vertex_deg, vertex_te_arcsec
        Vertex of the mean pair's TE parabola: pinion angle (deg) and TE (arcsec).
    amplitude_arcsec
        Parabola amplitude ``−c2 (π/N1)²`` (the designed value for the error-free pair).
    te0_arcsec
        Mean pair's TE at ``φ1 = 0``.
    te0_first_order_arcsec
        Its first-order prediction (module docstring).
    edge_positions
        Positions whose contact point is on a flank boundary.
    """

    label: str
    errors: InstallationErrors
    has_contact: bool
    dL_mm: float
    dh_mm: float
    te_pp_arcsec: float
    vertex_deg: float
    vertex_te_arcsec: float
    amplitude_arcsec: float
    te0_arcsec: float
    te0_first_order_arcsec: float
    edge_positions: int


def te_parabola(r: CycleResult, n1: int) -> tuple[float, float, float, float]:
    """Quadratic fit of the TE curve of the mean pair ``m = 0`` over ``|φ1| <= 1.3 π/N1``.

    Returns ``(vertex φ* rad, TE(φ*) arcsec, amplitude arcsec, rms fit residual arcsec)``.
    """
    k = _row_m0(r)
    m = r.pair_valid[:, k] & (np.abs(r.phi1) <= 1.3 * math.pi / n1)
    if m.sum() < 4:
        return 0.0, 0.0, 0.0, 0.0
    x, y = r.phi1[m], r.pair_te_arcsec[m, k]
    c2, c1, c0 = np.polyfit(x, y, 2)
    res = float(np.sqrt(np.mean((np.polyval([c2, c1, c0], x) - y) ** 2)))
    xv = -c1 / (2 * c2) if c2 != 0 else 0.0
    return float(xv), float(np.polyval([c2, c1, c0], xv)), float(-c2 * (math.pi / n1) ** 2), res


def _row_m0(r: CycleResult) -> int:
    """Row of the mean pair ``m = 0`` (tooth indices ``(0, 0)``) in ``r.pairs``."""
    return int(np.nonzero((r.pairs[:, 0] == 0) & (r.pairs[:, 1] == 0))[0][0])


def pattern_centre(r: CycleResult, gear, n1: int, side: str = "drive") -> tuple[float, float]:
    """Mean ``(L, h)`` (mm) of the gear contact path over the positions with ``|φ1| < π/N1``
    (``h`` from the ``side`` flank's coordinates: ``u`` is measured from its own fillet limit)."""
    m = r.has_contact & (np.abs(r.phi1) < math.pi / n1 - 1e-12)
    u, v = r.gear_uv[m, 0], r.gear_uv[m, 1]
    return float(np.mean(v)), float(np.mean(gear.height(u, v, side)))


def first_order_te_shift(pair, side: str, errors: InstallationErrors) -> float:
    """First-order TE change (arcsec) at ``φ1 = 0`` caused by ``errors`` (module docstring)."""
    rep = pair.reports[side]
    M, n, sigma = np.asarray(rep.point), np.asarray(rep.normal), rep.sigma
    A2, e2 = pair.blank.gear_axis()
    a0, a1 = spiral_bevel_assembly(pair, side), spiral_bevel_assembly(pair, side, errors)
    move1 = apply_points(a1.base1 @ inverse(a0.base1), M)  # the pinion's point M, moved
    move2 = apply_points(a1.base2 @ inverse(a0.base2), M)  # the gear's point M, moved
    dr = move1 - move2
    h = float(np.dot(np.cross(sigma * e2, M - A2), n))
    return float(-np.dot(dr, n) / h / ARCSEC)


def cycle_angles(n1: int, n: int, margin: float = 0.0) -> Array:
    """``n`` pinion angles over ``[−(1+margin) π/N1, (1+margin) π/N1]`` (rad)."""
    a = (1.0 + margin) * math.pi / n1
    return np.linspace(-a, a, n)


def error_effects(
    pair,
    cases: dict[str, InstallationErrors],
    side: str = "drive",
    options: TCAOptions | None = None,
    n_positions: int = 13,
) -> tuple[CycleResult, dict[str, ErrorEffect], dict[str, CycleResult]]:
    """Run the error-free pair and each case over one cycle; return the reference and effects.

    ``options`` default: no separation grids (only the path and TE are needed).
    """
    opt = options or TCAOptions(separation_grid=None)
    n1 = pair.blank.n1
    phi = cycle_angles(n1, n_positions)
    ref = run_tca(pair.pinion, pair.gear, spiral_bevel_assembly(pair, side), opt, phi1=phi)
    L0, h0 = pattern_centre(ref, pair.gear, n1, side)
    out: dict[str, ErrorEffect] = {}
    runs: dict[str, CycleResult] = {}
    for label, e in cases.items():
        r = run_tca(pair.pinion, pair.gear, spiral_bevel_assembly(pair, side, e), opt, phi1=phi)
        runs[label] = r
        k0 = _row_m0(r)
        i0 = int(np.argmin(np.abs(r.phi1)))
        if not r.has_contact.all():
            out[label] = ErrorEffect(label, e, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                                     first_order_te_shift(pair, side, e), 0)  # fmt: skip
            continue
        L, h = pattern_centre(r, pair.gear, n1, side)
        xv, tv, amp, _ = te_parabola(r, n1)
        out[label] = ErrorEffect(
            label=label,
            errors=e,
            has_contact=True,
            dL_mm=L - L0,
            dh_mm=h - h0,
            te_pp_arcsec=r.te_peak_to_peak_arcsec,
            vertex_deg=math.degrees(xv),
            vertex_te_arcsec=tv,
            amplitude_arcsec=amp,
            te0_arcsec=float(r.pair_te_arcsec[i0, k0]) if r.pair_valid[i0, k0] else 0.0,
            te0_first_order_arcsec=first_order_te_shift(pair, side, e),
            edge_positions=int(r.edge.sum()),
        )
        log.info("%s: dL %+.3f mm, dh %+.3f mm, TE p-p %.2f\", vertex %+.2f deg %+.2f\"",
                 label, L - L0, h - h0, r.te_peak_to_peak_arcsec, math.degrees(xv), tv)  # fmt: skip
    return ref, out, runs


def path_angle_on_gear(pair, side: str = "drive", dphi: float = 0.02) -> tuple[float, float]:
    """Measured and designed path angle η (deg) on the gear flank at the mean contact point.

    The TCA contact points of the error-free mean pair at ``φ1 = ±dphi`` are taken to the gear
    member frame and back to the mesh frame at ``φ2 = 0``; their chord ``d`` (a central
    difference, O(dphi²)) is the path tangent there. With the designed tangent ``t`` and normal
    ``n`` of the synthesis report and ``w`` the in-plane unit vector ⟂ ``t`` toward the tip (the
    projection of the gear pitch-cone normal), ``η_measured = η_design + atan2(d·w, d·t)``
    (η is measured from the tooth trace toward the tip, :class:`SynthesisTargets`; the path is a
    line, so the difference is taken modulo 180°).
    """
    asm = spiral_bevel_assembly(pair, side)
    opt = TCAOptions(separation_grid=None, pair_offsets=(0,))
    r = run_tca(pair.pinion, pair.gear, asm, opt, phi1=np.array([-dphi, dphi]))
    G0 = asm.placement2(0.0)
    pts = [
        apply_points(G0 @ inverse(asm.placement2(p.phi2)), p.points[p.contact_pair])
        for p in r.positions
    ]
    d = pts[1] - pts[0]
    rep = pair.reports[side]
    M, t, n = (np.asarray(x, dtype=float) for x in (rep.point, rep.path_direction, rep.normal))
    A2, e2 = pair.blank.gear_axis()
    r2 = M - A2
    radial = r2 - e2 * np.dot(r2, e2)
    ep = radial - r2 * np.dot(radial, r2) / np.dot(r2, r2)  # gear pitch-cone normal (toward tip)
    w = np.cross(n, t)
    w = w if np.dot(w, ep) > 0 else -w
    tgt = pair.targets
    eta = tgt.path_angle_drive_deg if side == "drive" else tgt.path_angle_coast_deg
    # a path is a line: its direction is defined modulo 180° (the coast path runs heel → toe)
    delta = math.degrees(math.atan2(np.dot(d, w), np.dot(d, t)))
    delta = (delta + 90.0) % 180.0 - 90.0
    return eta + delta, eta
