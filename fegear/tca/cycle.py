"""The mesh-cycle driver: reference phase, positions over a cycle, transfer points, pattern."""

from __future__ import annotations

import logging

import numpy as np
from numpy.typing import NDArray

from ..geometry.pair_placement import Assembly
from .core import TCA, TCAOptions
from .results import ARCSEC, CycleResult, PositionResult

__all__ = ["reference_phase", "run_tca", "cycle_result", "contact_interval"]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


def reference_phase(pinion, gear, assembly: Assembly, options: TCAOptions | None = None) -> float:
    """``phase2`` (rad) of the reference position: the ERROR-FREE pair in contact at ``φ1 = 0``.

    The TE of any assembly built with this phase is measured from the error-free contact
    position (``docs/conventions.md``: ``φ2⁰`` is the gear angle of that contact at ``φ1⁰ = 0``), so
    an error-free conjugate pair has TE 0 and an error shows as the change it causes.
    """
    nom = assembly.without_errors()
    opt = options or TCAOptions()
    from dataclasses import replace

    opt = replace(opt, separation_grid=None, pinion_torque_Nm=None)
    phase = nom.phase2
    for _ in range(3):  # the closing rotation is exact; a second pass only checks it
        r = TCA(pinion, gear, nom.with_phase2(phase), opt).positions(np.array([0.0]), False)[0]
        if not r.has_contact:
            log.warning("reference_phase: the error-free pair has no contact at phi1 = 0")
            return phase
        phase += r.te_rad
        if abs(r.te_rad) < 1e-13:
            break
    return float(phase)


def run_tca(
    pinion,
    gear,
    assembly: Assembly,
    options: TCAOptions | None = None,
    phi1: Array | None = None,
    calibrate: bool = True,
) -> CycleResult:
    """Unloaded TCA over one mesh cycle (or at the given pinion angles ``phi1``, rad).

    With ``calibrate`` the gear phase is first set by :func:`reference_phase` (TE relative to
    the error-free contact at ``φ1 = 0``).
    """
    opt = options or TCAOptions()
    if calibrate:
        assembly = assembly.with_phase2(reference_phase(pinion, gear, assembly, opt))
    if phi1 is None:
        n1 = assembly.n1
        phi1 = -np.pi / n1 + 2 * np.pi / n1 * np.arange(opt.n_positions) / opt.n_positions
    tca = TCA(pinion, gear, assembly, opt)
    pos = tca.positions(np.asarray(phi1, dtype=float))
    return cycle_result(pos, opt.paint_mm, tca)


def _transfer_points(phi: Array, pte: Array, valid: NDArray[np.bool_], cp: Array) -> Array:
    out = []
    for i in range(len(phi) - 1):
        a, b = cp[i], cp[i + 1]
        if a < 0 or b < 0 or a == b or not (valid[i, [a, b]].all() and valid[i + 1, [a, b]].all()):
            continue
        d0 = pte[i, a] - pte[i, b]
        d1 = pte[i + 1, a] - pte[i + 1, b]
        s = d0 / (d0 - d1) if d0 != d1 else 0.5
        s = min(max(s, 0.0), 1.0)
        out.append(
            (phi[i] + s * (phi[i + 1] - phi[i]), pte[i, a] + s * (pte[i + 1, a] - pte[i, a]))
        )
    return np.array(out, dtype=float).reshape(-1, 2)


def cycle_result(pos: list[PositionResult], paint_mm: float, tca: TCA | None = None) -> CycleResult:
    """Assemble a :class:`CycleResult` from per-position results."""
    phi = np.array([p.phi1 for p in pos])
    has = np.array([p.has_contact for p in pos])
    cp = np.array([p.contact_pair for p in pos])
    pte = np.array([p.pair_te_rad for p in pos]) / ARCSEC
    pv = np.array([p.pair_valid for p in pos])
    rows = np.arange(len(pos))
    cpc = np.maximum(cp, 0)
    uv1 = np.array([p.pinion_uv for p in pos])[rows, cpc] * has[:, None]
    uv2 = np.array([p.gear_uv for p in pos])[rows, cpc] * has[:, None]
    edge = np.array([bool(p.edge[p.contact_pair]) if p.has_contact else False for p in pos])
    paint = np.zeros((len(pos), 2))
    hz = np.zeros((len(pos), 2))
    p0 = np.zeros(len(pos))
    for i, p in enumerate(pos):
        e = p.ellipse
        if e is not None and not e.line_contact:
            paint[i] = (e.paint_a_mm, e.paint_b_mm)
            if e.hertz is not None:
                hz[i] = (e.hertz.a_mm, e.hertz.b_mm)
                p0[i] = e.hertz.p0_MPa
    if tca is not None and tca.opt.separation_grid is not None:
        gu, gv = tca.cell_uv
    else:
        gu, gv = np.zeros(0), np.zeros(0)
    pat = np.zeros((len(gu), len(gv)), dtype=bool)
    guv = []
    for p in pos:
        for g in p.grids:
            m = g.valid & (g.separation <= paint_mm)
            pat |= m
            guv.append(g.gear_uv[m])
    return CycleResult(
        positions=tuple(pos),
        phi1=phi,
        te_arcsec=np.array([p.te_rad for p in pos]) / ARCSEC,
        has_contact=has,
        pair_te_arcsec=pte,
        pair_valid=pv,
        backlash_mm=np.array([p.backlash_mm for p in pos]),
        contact_pair=cp,
        pinion_uv=uv1,
        gear_uv=uv2,
        edge=edge,
        paint_axes_mm=paint,
        hertz_axes_mm=hz,
        hertz_p0_MPa=p0,
        transfer_points=_transfer_points(phi, pte, pv, cp),
        pattern_pinion=pat,
        pattern_gear_uv=np.concatenate(guv) if guv else np.zeros((0, 2)),
        grid_u=gu,
        grid_v=gv,
        pairs=pos[0].pairs if pos else np.zeros((0, 2), int),
        paint_mm=paint_mm,
    )


def contact_interval(
    pinion, gear, assembly: Assembly, options: TCAOptions | None = None, iters: int = 26
) -> tuple[float, float]:
    """Pinion angles ``(φ_start, φ_end)`` (rad) bounding the interior contact of pair ``m = 0``.

    Pair 0 alone is analysed (``assembly`` should carry the reference phase); a position counts
    as contact when the pair's closing rotation is within 1e-9 rad of the reference and its
    contact point is on neither the tip nor the root boundary of either flank. Both ends are found
    by bisection on that predicate (``iters`` halvings of an eighth of a cycle: ~1e-9 rad). The
    contact ratio of a conjugate pair is ``(φ_end − φ_start) N1 / 2π``.
    """
    from dataclasses import replace

    opt = replace(
        options or TCAOptions(), pair_offsets=(0,), separation_grid=None, pinion_torque_Nm=None
    )
    tca = TCA(pinion, gear, assembly, opt)

    def inside(phi: float) -> bool:
        r = tca.positions(np.array([phi]), False)[0]
        if not r.has_contact or r.pair_te_rad[0] < -1e-9:
            return False
        return not any(t in r.edge[0] for t in ("tip", "root"))

    cyc = 2 * np.pi / assembly.n1
    ends = []
    for sgn in (-1.0, 1.0):
        a, step = 0.0, cyc / 8
        if not inside(a):
            raise ValueError("pair 0 is not in interior contact at phi1 = 0")
        b = a + sgn * step
        n = 0
        while inside(b) and n < 24:
            a, b, n = b, b + sgn * step, n + 1
        for _ in range(iters):
            c = 0.5 * (a + b)
            a, b = (c, b) if inside(c) else (a, c)
        ends.append(0.5 * (a + b))
    return ends[0], ends[1]
