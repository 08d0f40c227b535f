"""Newton solves on the exact flanks: circle hits (angular gaps) and normal-line hits (separations).

Angular gap (Litvin & Fuentes 2004 §9.4 TCA, written as a distance problem). Member 2 turns
about its axis; a point ``Q`` (gear-tooth frame, cylindrical ``(ρ, φ, z)`` about the gear axis) is
reached by the gear flank after a rotation ``θ`` iff the flank meets the circle ``(ρ_Q, z_Q)``:

.. math::  \\rho(r_2(a, b)) = \\rho_Q, \\quad z(r_2(a, b)) = z_Q, \\qquad
           \\theta = s_2 \\,(\\varphi(r_2) - \\varphi_Q),

two equations in the two flank parameters (2×2 Newton), then ``θ`` in closed form. ``θ`` is the
rotation of member 2 *against* its driving sense (a lag) that brings the gear flank onto ``Q``;
the smallest ``θ`` over the pinion flank is the rotation that closes the gap (the tangency
conditions of TCA are its stationarity conditions).

Separation along the pinion normal: ``r_2(a, b) = P + s n_1`` (3×3 Newton in ``a, b, s``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..geometry.transforms import apply_points, apply_vectors
from .surfaces import FlankMap

Array = NDArray[np.float64]
#: Newton stops at this residual (mm); the solves converge quadratically to ~1e-12 mm
TOL_MM = 1e-10


def _finite(x: Array) -> Array:
    """``np.nan_to_num(x)`` (NaN → 0, ±inf → ± the largest float): ``x`` itself when it is all
    finite (the usual Newton step), without the per-call cost of ``nan_to_num``."""
    return x if np.isfinite(x).all() else np.nan_to_num(x)


def _map(T: Array | None, p: Array, vec: bool = False) -> Array:
    if T is None:
        return p
    return apply_vectors(T, p) if vec else apply_points(T, p)


def circle_hit(
    fm: FlankMap,
    T: Array | None,
    a: Array,
    b: Array,
    rho_t: Array,
    z_t: Array,
    max_iter: int = 25,
) -> tuple[Array, Array, Array, Array, Array]:
    """Parameters where ``T · r(a, b)`` meets the circles ``(ρ_t, z_t)`` about ``z``.

    Parameters
    ----------
    fm
        Flank evaluator (member frame).
    T
        ``(..., 4, 4)`` member frame → target frame, or None (identity).
    a, b
        ``(...)`` initial native parameters.
    rho_t, z_t
        ``(...)`` target circle radius and height (mm).

    Returns
    -------
    a, b : (...)
        Native parameters of the hit.
    p, n : (..., 3)
        Point and unit normal in the target frame.
    ok : (...) bool
        Converged (residual < ``TOL_MM``).
    """
    shape = np.broadcast_shapes(np.shape(a), np.shape(rho_t), np.shape(z_t))
    a = np.broadcast_to(np.asarray(a, dtype=float), shape).ravel().copy()
    b = np.broadcast_to(np.asarray(b, dtype=float), shape).ravel().copy()
    rho_t = np.broadcast_to(np.asarray(rho_t, dtype=float), shape).ravel()
    z_t = np.broadcast_to(np.asarray(z_t, dtype=float), shape).ravel()
    Tf = None
    if T is not None:
        Tf = np.broadcast_to(T, shape + (4, 4)).reshape(-1, 4, 4)
    lo, hi = fm.native_box()
    span = hi - lo
    lo, hi = lo - 0.5 * span, hi + 0.5 * span
    act = np.arange(a.size)
    prev = np.full(a.size, np.inf)
    # a pointwise map keeps the point and normal of the evaluation at which each point stops
    # (its parameters do not move after it): the final evaluation is made only for the points
    # still moving when the iterations run out
    keep = fm.pointwise
    if keep:
        p_end, n_end = np.empty((a.size, 3)), np.empty((a.size, 3))
    for it in range(max_iter):
        if act.size == 0:
            break
        aa, bb = a[act], b[act]
        Ta = None if Tf is None else Tf[act]
        p0, n0, ra, rb = fm.point_jacobian(aa, bb)
        p = _map(Ta, p0)
        ra, rb = _map(Ta, ra, True), _map(Ta, rb, True)
        rho = np.hypot(p[..., 0], p[..., 1])
        F1, F2 = rho - rho_t[act], p[..., 2] - z_t[act]
        r = np.hypot(F1, F2)
        done = ~(r >= TOL_MM)  # converged (or NaN: give up)
        if it >= 6:  # no intersection (the circle misses the flank): Newton stalls; give up
            done |= r > 0.5 * prev[act]
        prev[act] = r
        er = p[..., :2] / np.maximum(rho, 1e-300)[..., None]
        j11 = np.sum(er * ra[..., :2], -1)
        j12 = np.sum(er * rb[..., :2], -1)
        j21, j22 = ra[..., 2], rb[..., 2]
        det = j11 * j22 - j12 * j21
        det = np.where(np.abs(det) > 1e-300, det, 1e-300)
        da = _finite(-(j22 * F1 - j12 * F2) / det)
        db = _finite(-(j11 * F2 - j21 * F1) / det)
        # trust region: at most a quarter of the working box per step
        sc = np.maximum(
            1.0, np.maximum(np.abs(da) / (0.25 * span[0]), np.abs(db) / (0.25 * span[1]))
        )
        a[act] = np.where(done, aa, np.clip(aa + da / sc, lo[0], hi[0]))
        b[act] = np.where(done, bb, np.clip(bb + db / sc, lo[1], hi[1]))
        if keep:
            p_end[act[done]], n_end[act[done]] = p0[done], n0[done]
        act = act[~done]
    if keep:
        if act.size:
            p_end[act], n_end[act] = fm.evaluate(a[act], b[act])
        p0, n0 = p_end, n_end
    else:
        p0, n0 = fm.evaluate(a, b)
    p, n = _map(Tf, p0), _map(Tf, n0, True)
    res = np.hypot(np.hypot(p[..., 0], p[..., 1]) - rho_t, p[..., 2] - z_t)
    ok = np.isfinite(res) & (res < 1e3 * TOL_MM)
    return (
        a.reshape(shape),
        b.reshape(shape),
        p.reshape(shape + (3,)),
        n.reshape(shape + (3,)),
        ok.reshape(shape),
    )


def line_hit(
    fm: FlankMap, a: Array, b: Array, P: Array, N: Array, max_iter: int = 25
) -> tuple[Array, Array, Array, Array, Array, Array]:
    """Intersection of the lines ``P + s N`` with the flank ``r(a, b)`` (member frame).

    Newton on ``r(a, b) − P − s N = 0`` for all lines at once; a line leaves the iteration
    when its residual is below ``TOL_MM`` (its point and normal are those of that evaluation),
    so the exact flank is evaluated only where it is still needed (measured on the spiral bevel's
    contact grids: 29 % of the lines still iterate after the second step).
    Returns ``a, b, s, p, n, ok`` (the shapes of ``a``); ``s`` (mm) is the separation along
    ``N``.
    """
    shape = np.shape(a)
    a = np.array(a, dtype=float).ravel()
    b = np.array(b, dtype=float).ravel()
    P3, N3 = np.reshape(P, (-1, 3)), np.reshape(N, (-1, 3))
    s = np.zeros(a.shape)
    p, n = np.full(a.shape + (3,), np.nan), np.full(a.shape + (3,), np.nan)
    lo, hi = fm.native_box()
    span = hi - lo
    lo, hi = lo - 0.5 * span, hi + 0.5 * span
    # The lines still iterating, ``act``, and their state (a, b, s, P, N) packed: a line that
    # stops writes its state back once (the same numbers as updating the full arrays in place).
    act = np.arange(a.size)
    ac, bc, sc, Pc, Nc = a, b, s, P3, N3
    for _ in range(max_iter):
        if act.size == 0:
            break
        pa, na, ra, rb = fm.point_jacobian(ac, bc)
        F = pa - Pc - sc[:, None] * Nc
        going = np.linalg.norm(F, axis=-1) >= TOL_MM  # (NaN: stops, and fails the check below)
        stop = ~going
        if stop.any():
            done = act[stop]
            p[done], n[done] = pa[stop], na[stop]
            a[done], b[done], s[done] = ac[stop], bc[stop], sc[stop]
        if not going.any():
            act = act[:0]
            break
        act, Pc, Nc = act[going], Pc[going], Nc[going]
        J = np.stack([ra[going], rb[going], -Nc], -1)
        # tiny Tikhonov term: a stack with one singular Jacobian must not stop the batch
        dx = np.linalg.solve(J + 1e-13 * np.eye(3), -F[going][..., None])[..., 0]
        dx = _finite(dx)
        step = np.maximum(
            1.0,
            np.maximum(
                np.abs(dx[..., 0]) / (0.25 * span[0]), np.abs(dx[..., 1]) / (0.25 * span[1])
            ),
        )
        ac = np.clip(ac[going] + dx[..., 0] / step, lo[0], hi[0])
        bc = np.clip(bc[going] + dx[..., 1] / step, lo[1], hi[1])
        sc = sc[going] + dx[..., 2] / step
    if act.size:  # out of iterations: the points of the last update
        a[act], b[act], s[act] = ac, bc, sc
        p[act], n[act] = fm.evaluate(ac, bc)
    res = np.linalg.norm(p - P3 - s[:, None] * N3, axis=-1)
    ok = np.isfinite(res) & (res < 1e3 * TOL_MM)
    return (
        a.reshape(shape),
        b.reshape(shape),
        s.reshape(shape),
        p.reshape(shape + (3,)),
        n.reshape(shape + (3,)),
        ok.reshape(shape),
    )


def in_bounds(fm: FlankMap, u: Array, v: Array, tol: float = 1e-9) -> Array:
    """Flank coordinates inside the working flank (relative tolerance ``tol`` of the spans;
    :meth:`~fegear.geometry.surface.FlankBoundaries.contains`)."""
    return fm.bounds.contains(u, v, tol)


def wrap(x: Array) -> Array:
    """Angle wrapped into (−π, π]."""
    return np.pi - np.mod(np.pi - x, 2 * np.pi)
