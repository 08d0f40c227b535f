"""Ease-off: the separation topography of the mating flanks over the pinion's working flank.

Definition (Stadtfeld, *Handbook of Bevel and Hypoid Gears*, 1993, §2 "ease-off"; Kolivand &
Kahraman, *Mech. Mach. Theory* 44 (2009) 1848, §2.1; the TCA's angular gap of Litvin & Fuentes,
*Gear Geometry and Applied Theory*, 2nd ed. 2004, §9.4): the ease-off at a point ``P`` of the
pinion flank is how far ``P`` lies from the flank *conjugate* to the gear, the envelope of the
gear flank when both members turn in the exact ratio. With the TCA's angular gap
``θ(P; φ1)`` (:mod:`.solve`: the rotation of the gear against its driving sense, a lag, that
brings the gear flank onto the circle of ``P`` about the gear axis, the gear at ``ratio·φ1``)

.. math::  \\theta_e(P) = \\min_{\\varphi_1} \\theta(P; \\varphi_1),
           \\qquad \\frac{\\partial\\theta}{\\partial\\varphi_1}(P; \\varphi_1^*) = 0,

the gap of ``P`` in its *contact position* ``φ1*(P)``, where ``P`` lies on the instantaneous
contact line of the conjugate pair (the stationarity is the equation of meshing
``n · v12 = 0``). ``θ(P; φ1)`` itself depends on ``φ1``: away from its contact position the
point is off the line of action and the gap grows quadratically, so the pinion angle is
eliminated by the minimum. In length along the pinion normal ``ε(P) = θ_e(P) h(P)``, ``h`` the
moment arm of the gear rotation along the normal (mm/rad, as
:func:`fegear.ltca.grid.separation_at` computes it) in the contact position; first order in the
gap (µm gaps over arms of tens of mm: 1e-7 relative).

What it shows: a conjugate pair has ``θ_e ≡ 0``; the unloaded TE at ``φ1`` is
``−min_P θ(P; φ1)``, and the TCA's contact point lies (to second order in the ease-off's slope
across the contact line) on the contact line of ``φ1`` at the minimum of ``θ_e`` along it: the
ease-off's minimum along each contact line is the TE curve, the valley of the ease-off is the
path of contact (the bearing).

The derivative at fixed ``P`` (gear tooth frame: ``Q(φ1)`` the pinion point, the gear flank
turned by ``−s2 θ`` through it, ``N_Q`` its normal there): differentiating
``Q = R_z(−s2 θ) r2(a, b)`` and dotting with ``N_Q`` (the tangent terms drop),

.. math::  \\theta' = -\\frac{N_Q \\cdot Q'}{s_2\\, N_Q \\cdot (e_z \\times Q)}.

``φ1*`` is found per point by a scan over ±3 pinion pitches (the gap's smallest sample), then a
safeguarded secant on ``θ' = 0`` inside the bracket of the neighbouring samples.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..geometry.transforms import apply_points, apply_vectors
from .solve import circle_hit, in_bounds, wrap

__all__ = ["EaseOff", "ease_off", "ease_off_at"]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]

#: the scan of the contact position: ± this many pinion pitches, this many samples
SCAN_PITCHES, SCAN_SAMPLES = 3.0, 37
#: secant iterations on θ' = 0 and the step (rad of φ1) below which a point stops
SECANT_ITER, SECANT_TOL = 30, 1e-10
#: a root: |θ'| below this (rad/rad; θ'' ~ 0.1 on the FZG pair, so 1e-10 rad of φ1 leaves
#: 1e-11, and a secant stopped at the edge of the gear's working flank 1e-3)
DTH_TOL = 1e-8
#: the scan is made on every ``SCAN_EVERY``-th node of the grid in each direction (and the last),
#: its contact positions interpolated to the others (``φ1*`` is smooth over the flank)
SCAN_EVERY = 4
#: the pinion-angle step of the forward difference of Q' (rad; the tooth frames are smooth in
#: φ1: truncation 1e-7 relative, round-off 1e-16 · 100 mm / 1e-7 = 1e-7 mm/rad; a relative
#: error e of θ' moves the root by e θ'/θ'' and θ_e by its square only)
DPHI = 1e-7


@dataclass(frozen=True)
class EaseOff:
    """The ease-off of a pair over the pinion's working flank (module docstring).

    Attributes
    ----------
    u, v
        ``(nu,)``, ``(nv,)`` the grid's pinion flank coordinates (profile from the fillet
        limit to the tip, face; ``flank_coordinates(side).bounds``).
    points
        ``(nu, nv, 3)`` mm, the grid points in the pinion member frame.
    theta_rad
        ``(nu, nv)`` the ease-off in angle ``θ_e`` (a gear lag; NaN where undefined: the
        circle of the point misses the gear's working flank in its contact position).
    phi1_rad
        ``(nu, nv)`` the contact position ``φ1*`` of each point (the TCA's pinion angles).
    h_mm
        ``(nu, nv)`` mm/rad, the moment arm of the gear rotation along the pinion normal there.
    eps_um
        ``(nu, nv)`` µm, ``ε = θ_e h`` less its minimum over the grid (NaN where undefined).
    eps_min_mm
        The minimum of ``θ_e h`` over the grid (mm; the absolute level: the ease-off's
        smallest gap, negative where the pair closes with the gear ahead of its ratio).
    min_uv
        ``(2,)`` the pinion flank coordinates of that minimum (a grid node).
    """

    u: Array
    v: Array
    points: Array
    theta_rad: Array
    phi1_rad: Array
    h_mm: Array
    eps_um: Array
    eps_min_mm: float
    min_uv: Array


def _gap(tca, i: int, P: Array, N: Array, phi: Array, a: Array | None, b: Array | None):
    """Gap, its derivative and arm at pinion points ``P (n, 3)``, normals ``N`` (member frame)
    in the positions ``phi (n,)`` of pair ``i``: ``(θ, θ', h, a, b, ok)``."""
    s2 = tca.asm.sense2
    T = tca._tooth_frames(phi)[:, i]
    Q = apply_points(T, P)
    dQ = (apply_points(tca._tooth_frames(phi + DPHI)[:, i], P) - Q) / DPHI
    NQ1 = apply_vectors(T, N)
    rho, z = np.hypot(Q[:, 0], Q[:, 1]), Q[:, 2]
    if a is None:
        a, b = tca.gear_start(rho, z)
    a2, b2, p2, n2, ok = circle_hit(tca.fm2, None, a, b, rho, z)
    u2, v2 = tca.fm2.flank(a2, b2, p2)
    ok = ok & in_bounds(tca.fm2, u2, v2)
    alpha = wrap(np.arctan2(Q[:, 1], Q[:, 0]) - np.arctan2(p2[:, 1], p2[:, 0]))
    c, s = np.cos(alpha), np.sin(alpha)
    NQ = np.stack([c * n2[:, 0] - s * n2[:, 1], s * n2[:, 0] + c * n2[:, 1], n2[:, 2]], -1)
    ezQ = np.stack([-Q[:, 1], Q[:, 0], np.zeros(len(Q))], -1)
    arm = np.sum(NQ * ezQ, -1)
    th = -s2 * alpha
    dth = -np.sum(NQ * dQ, -1) / (s2 * np.where(np.abs(arm) > 1e-300, arm, 1e-300))
    # a gear rotation θ moves the gear point by −s2 θ e_z × Q: along the pinion normal line
    den = np.sum(NQ1 * NQ, -1)
    h = s2 * arm / np.where(np.abs(den) > 1e-12, den, 1e-12)
    ok = ok & np.isfinite(th) & (np.abs(th) < 0.5 * 2 * np.pi / tca.asm.n2)
    return np.where(ok, th, np.inf), np.where(ok, dth, np.nan), h, a2, b2, ok


def _sub(n: int) -> NDArray[np.int_]:
    """Every :data:`SCAN_EVERY`-th index of ``range(n)`` and the last."""
    return np.unique(np.r_[np.arange(0, n, SCAN_EVERY), n - 1])


def _empty(u: Array, v: Array, points: Array) -> EaseOff:
    nan = np.full(points.shape[:2], np.nan)
    return EaseOff(u, v, points, nan, nan, nan, nan, float("nan"), np.full(2, np.nan))


def _pair(tca, pair: int | None) -> int:
    if pair is not None:
        return pair
    zero = np.flatnonzero((tca.pairs == 0).all(-1))
    return int(zero[0]) if zero.size else 0


def _scan(tca, pair: int, P: Array, N: Array) -> tuple[Array, NDArray[np.bool_], float]:
    """``(φ1, hit, step)``: per point the smallest gap among the scan's pinion angles, moved to
    the vertex of the parabola through it and its neighbours; ``hit``: that sample is interior
    to finite ones (else the contact position is off the gear's working flank or the scan)."""
    pitch = 2 * np.pi / tca.asm.n1
    scan = np.linspace(-SCAN_PITCHES * pitch, SCAN_PITCHES * pitch, SCAN_SAMPLES)
    m, step, ns = len(scan), scan[1] - scan[0], len(P)
    Ps, Ns = np.repeat(P, m, 0), np.repeat(N, m, 0)
    th = _gap(tca, pair, Ps, Ns, np.tile(scan, ns), None, None)[0].reshape(ns, m)
    k = np.argmin(th, -1)
    r = np.arange(ns)
    kk = np.clip(k, 1, m - 2)
    f0, fm, fp = th[r, kk], th[r, kk - 1], th[r, kk + 1]
    hit = (k == kk) & np.isfinite(f0) & np.isfinite(fm) & np.isfinite(fp)
    with np.errstate(invalid="ignore"):
        curv = np.where(hit, fp - 2 * f0 + fm, 0.0)
        off = np.where(curv > 0, 0.5 * (fm - fp) / np.where(curv > 0, curv, 1.0), 0.0)
    return scan[kk] + np.clip(off, -1.0, 1.0) * step, hit, float(step)


def _refine(tca, pair: int, P: Array, N: Array, x0: Array, step: float):
    """Safeguarded secant on ``θ' = 0`` in ``x0 ± 2 step`` (rad of φ1): ``(θ_e, φ1*, h)``,
    NaN where no root lies strictly inside the bracket or the secant stops short of one (the
    gap still falls where the circle leaves the gear's working flank: the contact position is
    off it, or beyond the scan)."""
    lo0, hi0 = x0 - 2 * step, x0 + 2 * step
    f, d, h, a, b, ok = _gap(tca, pair, P, N, x0, None, None)
    xp, dp = x0, d
    x = np.clip(x0 - np.sign(np.nan_to_num(d)) * 0.25 * step, lo0, hi0)
    lo, hi = np.where(d > 0, lo0, x0), np.where(d > 0, x0, hi0)
    f, d, h, a, b, ok = _gap(tca, pair, P, N, x, a, b)
    act = np.ones(len(P), bool)
    for _ in range(SECANT_ITER):
        lo = np.where(d > 0, lo, np.maximum(lo, x))
        hi = np.where(d > 0, np.minimum(hi, x), hi)
        den = d - dp
        with np.errstate(invalid="ignore", divide="ignore"):
            xn = x - d * (x - xp) / np.where(np.abs(den) > 1e-300, den, 1e-300)
        bad = ~np.isfinite(xn) | (xn <= lo) | (xn >= hi)
        xn = np.where(bad, 0.5 * (lo + hi), xn)
        act &= np.abs(xn - x) > SECANT_TOL
        if not act.any():
            break
        idx = np.flatnonzero(act)
        res = _gap(tca, pair, P[idx], N[idx], xn[idx], a[idx], b[idx])
        xp, dp = x.copy(), d.copy()
        x[idx] = xn[idx]
        f[idx], d[idx], h[idx], a[idx], b[idx], ok[idx] = res
    good = (x > lo0 + 1e-6 * step) & (x < hi0 - 1e-6 * step) & (np.abs(d) < DTH_TOL)
    good &= ok & np.isfinite(f) & (h > 0)
    nan = np.nan
    return np.where(good, f, nan), np.where(good, x, nan), np.where(good, h, nan)


def ease_off_at(tca, u: Array, v: Array, pair: int | None = None) -> tuple[Array, Array, Array]:
    """``(θ_e, φ1*, h)`` (rad, rad, mm/rad; shapes of ``u``, ``v``) at pinion flank points
    ``(u, v)``: the ease-off in angle, the contact position and the arm (module docstring),
    each point scanned on its own (:func:`ease_off` scans a sub-grid)."""
    pair = _pair(tca, pair)
    u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
    _, _, P, N = tca.fm1.native_point(u.ravel(), v.ravel())
    x0, hit, step = _scan(tca, pair, P, N)
    th, x, h = _refine(tca, pair, P, N, x0, step)
    th, x, h = (np.where(hit, y, np.nan).reshape(u.shape) for y in (th, x, h))
    return th, x, h


def ease_off(tca, grid: tuple[int, int] = (21, 41), pair: int | None = None) -> EaseOff:
    """The :class:`EaseOff` of the TCA's pair (``tca``: a :class:`~fegear.tca.TCA`, its
    assembly phased; ``pair``: the index into ``tca.pairs``, default the pair in contact at
    ``φ1 = 0``) on a ``grid = (n_profile, n_face)`` node grid over the pinion's working flank.

    Cost: one scan of :data:`SCAN_SAMPLES` pinion angles and about ten secant steps of one
    circle hit per point (warm-started), ~0.3 s for 21 × 41 points on the spiral bevel.
    """
    pair = _pair(tca, pair)
    bd = tca.fm1.bounds
    u = np.linspace(bd.u_fillet, bd.u_tip, grid[0])
    v = np.linspace(bd.v_start, bd.v_end, grid[1])
    U, V = np.meshgrid(u, v, indexing="ij")
    _, _, P, N = tca.fm1.native_point(U.ravel(), V.ravel())
    # the scan on a coarse sub-grid, its contact positions to every node (bilinear in the node
    # indices; a miss takes its nearest hit), then each node refined on its own
    iu, iv = _sub(grid[0]), _sub(grid[1])
    sub = (iu[:, None] * grid[1] + iv[None, :]).ravel()
    xs, hit, step = _scan(tca, pair, P[sub], N[sub])
    if not hit.any():
        log.warning("ease-off: no point of the pinion flank has a contact position")
        return _empty(u, v, P.reshape(U.shape + (3,)))
    if not hit.all():
        from scipy.spatial import cKDTree

        pts = np.stack([iu.repeat(iv.size), np.tile(iv, iu.size)], -1).astype(float)
        xs[~hit] = xs[hit][cKDTree(pts[hit]).query(pts[~hit])[1]]
    from scipy.interpolate import RegularGridInterpolator

    nodes = np.stack([np.arange(grid[0]).repeat(grid[1]), np.tile(np.arange(grid[1]), grid[0])], -1)
    x0 = RegularGridInterpolator((iu, iv), xs.reshape(iu.size, iv.size))(nodes)
    f, x, h = _refine(tca, pair, P, N, x0, step)
    theta, hh = f.reshape(U.shape), h.reshape(U.shape)
    eps = theta * hh
    if not np.isfinite(eps).any():
        log.warning("ease-off: no point of the pinion flank has a contact position")
        return _empty(u, v, P.reshape(U.shape + (3,)))
    j = int(np.nanargmin(eps))
    emin = float(eps.flat[j])
    return EaseOff(
        u=u,
        v=v,
        points=P.reshape(U.shape + (3,)),
        theta_rad=theta,
        phi1_rad=x.reshape(U.shape),
        h_mm=hh,
        eps_um=(eps - emin) * 1e3,
        eps_min_mm=emin,
        min_uv=np.array([U.flat[j], V.flat[j]]),
    )
