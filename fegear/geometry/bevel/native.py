"""Fast exact evaluation of a generated bevel flank and fillet in their cutter parameters.

The envelope engine (:func:`fegear.geometry.generation.generate`) solves the equation of meshing
by bracketing at every call; a member evaluated at tens of thousands of points (TCA, meshes,
contact grids) needs it faster. :class:`NativeFlank` and :class:`NativeFillet` predict the root
from a spline tabulated once and finish it by Newton: the same surface to round-off.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import SolverError
from ..generation import Fixed, Rotation, Translation, generate
from ..surface import Side

if TYPE_CHECKING:  # the member builds its evaluators (no import at run time)
    from .member import SpiralBevelMember

__all__ = ["NativeFlank", "NativeFillet", "cone_coords"]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


def cone_coords(p: Array, gamma: float) -> tuple[Array, Array, Array, Array]:
    """``L``, ``h`` of member-frame points ``p (..., 3)`` on a cone of pitch angle ``gamma``
    (:mod:`.blank`) and their gradients ``(..., 3)``."""
    rho = np.hypot(p[..., 0], p[..., 1])
    cg, sg = math.cos(gamma), math.sin(gamma)
    L = p[..., 2] * cg + rho * sg
    h = rho * cg - p[..., 2] * sg
    er = np.stack([p[..., 0] / rho, p[..., 1] / rho, np.zeros_like(rho)], -1)
    ez = np.array([0.0, 0.0, 1.0])
    return L, h, er * sg + ez * cg, er * cg - ez * sg


# --------------------------------------------------------------------------------------------
# fast exact evaluation in the native (cutter) parameters
# --------------------------------------------------------------------------------------------
def _horner(c: tuple[float, ...], x: Array) -> Array:
    out = np.full(np.shape(x), c[-1] if c else 0.0)
    for a in reversed(c[:-1]):
        out = out * x + a
    return out


@dataclass(frozen=True)
class _Step:
    """One compiled factor of the generating motion: ``kind`` "R" (rotation about coordinate
    axis ``axis`` by the polynomial ``c0``), "T" (translation ``c0 · d``) or "F" (constant
    ``(R, t)``); ``c1``, ``c2`` are the coefficient tuples of the first and second derivative."""

    kind: str
    axis: int = 2
    c0: tuple[float, ...] = ()
    c1: tuple[float, ...] = ()
    c2: tuple[float, ...] = ()
    Rt: Array | None = None
    t: Array | None = None
    d: Array | None = None


def _compile(factors) -> tuple[_Step, ...]:
    """Compile a :class:`~fegear.geometry.generation.Motion` chain (constant factors merged)."""

    def der(c: tuple[float, ...]) -> tuple[float, ...]:
        return tuple(k * c[k] for k in range(1, len(c)))

    mats: list = []
    for f in factors:
        if isinstance(f, Fixed):
            m = np.asarray(f.matrix, dtype=float)
            if mats and isinstance(mats[-1], np.ndarray):
                mats[-1] = mats[-1] @ m
            else:
                mats.append(m)
        else:
            mats.append(f)
    out = []
    for f in mats:
        if isinstance(f, np.ndarray):
            out.append(_Step("F", Rt=np.ascontiguousarray(f[:3, :3].T), t=f[:3, 3].copy()))
        elif isinstance(f, Rotation):
            c = tuple(float(x) for x in f.coeffs)
            out.append(_Step("R", "xyz".index(f.axis), c, der(c), der(der(c))))
        elif isinstance(f, Translation):
            c = tuple(float(x) for x in f.coeffs)
            d = np.asarray(f.direction, dtype=float)
            out.append(_Step("T", 2, c, der(c), der(der(c)), d=d))
        else:  # pragma: no cover - Motion only holds these three
            raise TypeError(type(f))
    return tuple(out)


def _apply_step(st: _Step, psi: Array, x: list[Array], w: float) -> list[Array]:
    """Apply one factor ``F(ψ)`` to ``x = [x, x', x'', ...]`` (ψ-derivatives, product rule).

    ``(Fx)' = F'x + Fx'``, ``(Fx)'' = F''x + 2F'x' + Fx''``; for a rotation by ``a(ψ)`` about a
    coordinate axis ``e``: ``F'y = a' e × (Fy)``, ``F''y = a'' e × (Fy) + a'² e × (e × (Fy))``:
    elementwise operations only. ``w``: homogeneous weight (1 point, 0 vector).
    """
    order = len(x) - 1
    if st.kind == "F":
        out = [np.dot(xk, st.Rt) for xk in x]
        if w:
            out[0] = out[0] + st.t
        return out
    if st.kind == "T":
        cs = (st.c0, st.c1, st.c2)
        return [x[k] + (w * _horner(cs[k], psi))[..., None] * st.d for k in range(order + 1)]
    j, k = [(1, 2), (2, 0), (0, 1)][st.axis]
    a = _horner(st.c0, psi)
    c, s = np.cos(a), np.sin(a)

    def rot(y: Array) -> Array:
        z = y.copy()
        z[..., j] = c * y[..., j] - s * y[..., k]
        z[..., k] = s * y[..., j] + c * y[..., k]
        return z

    def cross_e(y: Array) -> Array:  # e_axis × y
        z = np.zeros_like(y)
        z[..., j] = -y[..., k]
        z[..., k] = y[..., j]
        return z

    R0 = rot(x[0])
    out = [R0]
    if order >= 1:
        a1 = _horner(st.c1, psi)[..., None]
        eR0 = cross_e(R0)
        R1 = rot(x[1])
        out.append(a1 * eR0 + R1)
        if order >= 2:
            a2 = _horner(st.c2, psi)[..., None]
            out.append(a2 * eR0 + a1**2 * cross_e(eR0) + 2.0 * a1 * cross_e(R1) + rot(x[2]))
    return out


@dataclass(frozen=True)
class _NativeEnvelope:
    """Exact, fast evaluation of the envelope of one cutter surface of revolution in its native
    parameters ``(a, θ)`` (profile parameter, cutter angle): the shared part of
    :class:`NativeFlank` (blade) and :class:`NativeFillet` (edge radius).

    The generated surface is ``r(a, θ) = M(ψ(a, θ)) r_t(a, θ)`` with ``ψ`` the root of the
    equation of meshing ``f = (M n_t) · (M' r_t) = 0`` (Litvin & Fuentes 2004 §6.1). Instead of
    the bracketing solve of :func:`~fegear.geometry.generation.generate` at every call, ``ψ`` is
    predicted by a bicubic spline tabulated once (by the engine) over the surface and a margin
    around it, then corrected by Newton on the meshing equation,

    .. math::  \\psi \\leftarrow \\psi - f / f_\\psi, \\qquad
               f_\\psi = (M' n_t)\\cdot(M' r_t) + (M n_t)\\cdot(M'' r_t),

    until ``|Δψ| < 1e-14`` rad (quadratic convergence: 2 steps from the spline's ~1e-8 rad).
    The motion is applied factor by factor to the tool vectors (elementwise rotations, no 4×4
    products), with the ψ-derivatives propagated by the product rule. The result is the exact
    envelope (the engine's root, to round-off: ~1e-13 mm, tested), NOT an interpolant; the
    spline only supplies the Newton start. Tangents follow from the implicit-function theorem:
    ``ψ_a = −f_a/f_ψ``, ``r_a = M r_{t,a} + (M' r_t) ψ_a`` (same for θ).

    Tool: a surface of revolution with profile ``(ρ(a), z(a))`` (``tool.profile``), so
    ``r_t = (ρ cos θ, ρ sin θ, z)`` and ``n_t = σ (−z' cos θ, −z' sin θ, ρ') / √(ρ'² + z'²)`` in
    closed form (``σ = tool.sign``).
    """

    member: SpiralBevelMember
    side: Side
    tool: object
    steps: tuple[_Step, ...]
    spline: object
    inverse: tuple[object, object]
    box: tuple[Array, Array]

    @staticmethod
    def _psi_table(member: SpiralBevelMember, side: Side, tool, lo: Array, hi: Array,
                   margin: tuple[float, float], n_grid: int):  # fmt: skip
        """Bicubic spline of the meshing root ψ over ``(a, θ)`` in ``[lo, hi]`` widened by
        ``margin`` times its span on each side (``n_grid²`` engine roots)."""
        from scipy.interpolate import RectBivariateSpline

        mot = member._tools(side)[1]
        span = hi - lo
        glo, ghi = lo - np.multiply(margin, span), hi + np.multiply(margin, span)
        gs = np.linspace(glo[0], ghi[0], n_grid)
        gt = np.linspace(glo[1], ghi[1], n_grid)
        S, T = np.meshgrid(gs, gt, indexing="ij")
        # the far corners of the margin may have no root (the engine warns): expected here
        glog = logging.getLogger(generate.__module__)
        level = glog.level
        glog.setLevel(max(level, logging.ERROR))
        try:
            env = generate(tool, mot, S, T, member.reference(side)[2], half_width=0.6)
        finally:
            glog.setLevel(level)
        ok = env.residual < 1e-9
        if not ok.all():
            log.debug("%s %s native table: %d of %d margin points without a root (filled)",
                      member.name, side, int(np.sum(~ok)), ok.size)  # fmt: skip
        if ok.mean() < 0.9:
            raise SolverError(
                f"spiral bevel {member.name} {side}: meshing equation has no root on "
                f"{int(np.sum(~ok))} of {ok.size} points of the native grid"
            )
        psi = env.psi
        if not ok.all():
            # far corners of the margin without a root: fill from a cubic fit (the table is only
            # a predictor; Newton decides)
            x, y = (S - S.mean()) / np.ptp(S), (T - T.mean()) / np.ptp(T)
            D = np.stack([x**i * y**j for i in range(4) for j in range(4 - i)], -1)
            c = np.linalg.lstsq(D[ok], psi[ok], rcond=None)[0]
            psi = np.where(ok, psi, D @ c)
        return RectBivariateSpline(gs, gt, psi, kx=3, ky=3)

    # ---------------------------------------------------------------- evaluation
    def _tool(self, s: Array, th: Array, derivs: bool) -> tuple[Array, ...]:
        """Tool point, normal (into the tool) and, with ``derivs``, their a/θ-derivatives.

        Same surface as ``tool.evaluate``, closed form for a surface of revolution.
        """
        t = self.tool
        sg = t.sign
        rho, z, rho1, z1, rho2, z2 = t.profile(s)
        wn = np.hypot(rho1, z1)
        # n = sg (r_s × r_θ)/|·| = sg (−z' cos θ, −z' sin θ, ρ')/|(ρ', z')|   (ρ > 0)
        Nr, Nz = -sg * z1 / wn, sg * rho1 / wn
        c, si = np.cos(th), np.sin(th)
        r = np.stack([rho * c, rho * si, z], -1)
        n = np.stack([Nr * c, Nr * si, Nz], -1)
        if not derivs:
            return r, n
        # d/ds of the unit profile normal: (q' − N (N·q'))/|q|, q = sg (−z', ρ')
        qr, qz = -sg * z2, sg * rho2
        dot = Nr * qr + Nz * qz
        Nr1, Nz1 = (qr - Nr * dot) / wn, (qz - Nz * dot) / wn
        zero = np.zeros_like(rho)
        r_s = np.stack([rho1 * c, rho1 * si, z1], -1)
        r_t = np.stack([-rho * si, rho * c, zero], -1)
        n_s = np.stack([Nr1 * c, Nr1 * si, Nz1], -1)
        n_t = np.stack([-Nr * si, Nr * c, zero], -1)
        return r, n, r_s, r_t, n_s, n_t

    def _chain(self, psi: Array, x: Array, w: float, order: int) -> list[Array]:
        xs = [x] + [np.zeros_like(x) for _ in range(order)]
        for st in reversed(self.steps):
            xs = _apply_step(st, psi, xs, w)
        return xs

    def _solve_psi(self, s: Array, th: Array, tr: Array, tn: Array, max_iter: int = 8):
        """Newton on the meshing equation from the spline; returns ψ and the chains at ψ."""
        psi = self.spline.ev(s, th)
        for _ in range(max_iter):
            r = self._chain(psi, tr, 1.0, 2)
            n = self._chain(psi, tn, 0.0, 1)
            f = np.sum(n[0] * r[1], -1)
            fp = np.sum(n[1] * r[1], -1) + np.sum(n[0] * r[2], -1)
            d = f / fp
            # converged: the chains at ψ are the result (the last step, < 1e-14 rad, would move
            # the point by < 1e-12 mm)
            if not np.any(np.abs(d) >= 1e-14):  # also stops on NaN
                break
            psi = psi - d
        return psi, r, n, fp

    def evaluate(self, s: ArrayLike, th: ArrayLike, tangents: bool = False) -> tuple[Array, ...]:
        """Points ``(..., 3)`` and unit normals; with ``tangents`` also ``r_a``, ``r_θ``."""
        s, th = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(th, dtype=float))
        shape = s.shape
        s, th = s.ravel(), th.ravel()
        tl = self._tool(s, th, tangents)
        psi, r, n, fp = self._solve_psi(s, th, tl[0], tl[1])
        out = [r[0], n[0]]
        if tangents:
            for ru, nu in ((tl[2], tl[4]), (tl[3], tl[5])):
                Ru = self._chain(psi, ru, 0.0, 1)
                Nu = self._chain(psi, nu, 0.0, 0)[0]
                fu = np.sum(Nu * r[1], -1) + np.sum(n[0] * Ru[1], -1)
                out.append(Ru[0] - r[1] * (fu / fp)[..., None])
        return tuple(o.reshape(shape + (3,)) for o in out)

    def psi(self, s: ArrayLike, th: ArrayLike) -> Array:
        """Root ψ (rad) of the equation of meshing at ``(a, θ)``."""
        s, th = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(th, dtype=float))
        tl = self._tool(s.ravel(), th.ravel(), False)
        return self._solve_psi(s.ravel(), th.ravel(), *tl)[0].reshape(s.shape)

    def meshing_residual(self, s: ArrayLike, th: ArrayLike) -> Array:
        """``|n·v|/|v|`` of the equation of meshing at ``(a, θ)`` (a check of the solve)."""
        s, th = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(th, dtype=float))
        tl = self._tool(s.ravel(), th.ravel(), False)
        _, r, n, _ = self._solve_psi(s.ravel(), th.ravel(), *tl)
        res = np.abs(np.sum(n[0] * r[1], -1)) / np.linalg.norm(r[1], axis=-1)
        return res.reshape(s.shape)


@dataclass(frozen=True)
class NativeFlank(_NativeEnvelope):
    """Exact, fast evaluation of one generated bevel flank (the blade envelope) in its cutter
    parameters ``(s, θ)`` (:class:`_NativeEnvelope`; tool:
    :class:`~.cutter.HeadCutter`).

    The ψ table covers the working flank and a margin of 0.75 of its span around it (41 × 41
    engine roots, ~0.1 s). Flank coordinates (:class:`SpiralBevelMember`): ``v = L`` (cone
    distance), ``u`` the fraction of the working height ``(h − h_fl(L))/(h_a(L) − h_fl(L))``
    above the fillet limit; ``(u, v) → (s, θ)`` by 2-D Newton on ``(L, h)`` with the analytic
    tangents from a bicubic predictor.

    Build with :meth:`SpiralBevelMember.native_flank`.
    """

    @classmethod
    def build(cls, member: SpiralBevelMember, side: Side, n_grid: int = 41) -> NativeFlank:
        """Tabulate ψ on an ``n_grid²`` grid of ``(s, θ)`` covering the flank ± 0.75 its span."""
        from scipy.interpolate import RectBivariateSpline

        tool, mot = member._tools(side)
        b = member.boundaries()
        uu = np.linspace(b.u_fillet, b.u_tip, 9)
        vv = np.linspace(b.v_start, b.v_end, 9)
        _, s0, t0 = member._solve(side, uu[:, None], vv[None, :])
        inv = (RectBivariateSpline(uu, vv, s0), RectBivariateSpline(uu, vv, t0))
        lo = np.array([s0.min(), t0.min()])
        hi = np.array([s0.max(), t0.max()])
        spl = cls._psi_table(member, side, tool, lo, hi, (0.75, 0.75), n_grid)
        return cls(member, side, tool, _compile(mot.factors), spl, inv, (lo, hi))

    # ---------------------------------------------------------------- flank coordinates
    def flank(self, p: Array) -> tuple[Array, Array]:
        """Flank coordinates ``(u, v)`` of member-frame points ``p (..., 3)`` of the working
        surface (``u < 0`` for points below the fillet limit; not the fillet's own ``u``)."""
        L, h, _, _ = cone_coords(p, self.member.pitch_angle)
        return self.member.working_u(h, L, self.side), L

    def native(self, u: ArrayLike, v: ArrayLike, tol: float = 1e-11) -> tuple[Array, Array]:
        """``(s, θ)`` of flank coordinates (2-D Newton on ``(L, h)``, analytic tangents)."""
        return self.native_evaluation(u, v, tol)[:2]

    def native_evaluation(self, u: ArrayLike, v: ArrayLike, tol: float = 1e-11):
        """:meth:`native` and :meth:`evaluate` at the result: ``(s, θ, p, n)``, the Newton's
        last evaluation, at the converged ``(s, θ)``."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        m = self.member
        h_fl = m.fillet_height(v, self.side)
        L_t, h_t = v, h_fl + u * (m.blank.flank_heights(m.index, v)[1] - h_fl)
        s = self.inverse[0].ev(u, v)
        th = self.inverse[1].ev(u, v)
        g = m.pitch_angle
        err = np.inf
        for _ in range(30):
            p, n, rs, rt = self.evaluate(s, th, tangents=True)
            L, h, gL, gh = cone_coords(p, g)
            F1, F2 = L - L_t, h - h_t
            err = float(np.max(np.abs(np.stack([F1, F2])))) if F1.size else 0.0
            if not err >= tol:
                break
            j11, j12 = np.sum(gL * rs, -1), np.sum(gL * rt, -1)
            j21, j22 = np.sum(gh * rs, -1), np.sum(gh * rt, -1)
            det = j11 * j22 - j12 * j21
            s = s - (j22 * F1 - j12 * F2) / det
            th = th - (j11 * F2 - j21 * F1) / det
        else:
            raise SolverError(
                f"spiral bevel {m.name} {self.side}: (u, v) -> (s, theta) did not converge "
                f"(max |dL|,|dh| = {err:.2e} mm)"
            )
        if not np.isfinite(err):
            raise SolverError(f"spiral bevel {m.name} {self.side}: (u, v) -> (s, theta) NaN")
        return s, th, p, n


@dataclass(frozen=True)
class NativeFillet(_NativeEnvelope):
    """Exact, fast evaluation of one generated fillet (the envelope of the blade's edge radius,
    :class:`~.cutter.EdgeRadius`) in its native parameters ``(ϑ, θ)``
    (:class:`_NativeEnvelope`).

    Fillet coordinates ``u ∈ [−1, 0]`` (−1 on the root cone, 0 on the fillet limit), ``v = L``:
    ``ϑ = (1 + u) ϑ_b`` and θ by Newton on the cone distance, ``∂L/∂θ = ∇L · r_θ`` (analytic
    IFT tangent), from a bicubic predictor. The ψ table covers the fillet with margins of 0.25
    (in ϑ: the arc is continued past its ends only a little) and 0.75 (in θ) of its spans.

    Build with :meth:`SpiralBevelMember.native_fillet`.
    """

    @classmethod
    def build(cls, member: SpiralBevelMember, side: Side, n_grid: int = 33) -> NativeFillet:
        """Tabulate ψ on an ``n_grid²`` grid of ``(ϑ, θ)`` (exact fillet on 9 × 9 ``(u, v)``)."""
        from scipy.interpolate import RectBivariateSpline

        tool = member.edge_tool(side)
        b = member.boundaries()
        uu = np.linspace(b.u_root, b.u_fillet, 9)
        vv = np.linspace(b.v_start, b.v_end, 9)
        _, w0, t0 = member._fillet_solve(side, uu[:, None], vv[None, :])
        inv = (RectBivariateSpline(uu, vv, w0), RectBivariateSpline(uu, vv, t0))
        lo = np.array([w0.min(), t0.min()])
        hi = np.array([w0.max(), t0.max()])
        spl = cls._psi_table(member, side, tool, lo, hi, (0.25, 0.75), n_grid)
        steps = _compile(member._tools(side)[1].factors)
        return cls(member, side, tool, steps, spl, inv, (lo, hi))

    def native(self, u: ArrayLike, v: ArrayLike, tol: float = 1e-11) -> tuple[Array, Array]:
        """``(ϑ, θ)`` of fillet coordinates ``(u ∈ [−1, 0], v = L)``."""
        return self.native_evaluation(u, v, tol)[:2]

    def native_evaluation(self, u: ArrayLike, v: ArrayLike, tol: float = 1e-11):
        """``(ϑ, θ, p, n)``: :meth:`native` and the evaluation at the converged parameters."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        m = self.member
        w = (1.0 + u) * self.tool.theta_blade
        th = self.inverse[1].ev(u, v)
        g = m.pitch_angle
        err = np.inf
        for _ in range(30):
            p, n, _, rt = self.evaluate(w, th, tangents=True)
            L, _, gL, _ = cone_coords(p, g)
            F = L - v
            err = float(np.max(np.abs(F))) if F.size else 0.0
            if not err >= tol:
                break
            th = th - F / np.sum(gL * rt, -1)
        else:
            raise SolverError(
                f"spiral bevel {m.name} {self.side}: fillet (u, v) -> (ϑ, θ) did not converge "
                f"(max |dL| = {err:.2e} mm)"
            )
        if not np.isfinite(err):
            raise SolverError(f"spiral bevel {m.name} {self.side}: fillet (u, v) -> (ϑ, θ) NaN")
        return w, th, p, n
