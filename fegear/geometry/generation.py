"""The generation engine: envelope of a tool surface under a one-parameter generating motion.

Theory (Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed., 2004, ch. 6 "Envelope to a
family of surfaces", ch. 8 "Curvatures of generated surfaces"):

- Tool surface ``r_t(u, θ)`` with unit normal ``n_t`` in the tool frame. ``n_t`` must point INTO
  the tool body, i.e. OUT of the tooth material that the tool leaves on the blank.
- Generating motion: a 4×4 transform ``M(ψ)`` from the tool frame to the blank frame, built as a
  chain of factors (:class:`Rotation`, :class:`Translation`, :class:`Fixed`) whose angles/offsets
  are polynomials in ψ (a quadratic term is the "modified roll" of bevel generators).
- Relative velocity of the tool point, seen in the blank frame: ``v = (dM/dψ) r_t``.
- Equation of meshing: ``f(u, θ, ψ) = (R n_t) · v = 0`` with ``R`` the rotation part of ``M``.
- Generated surface: ``r(u, θ) = M(ψ(u, θ)) r_t(u, θ)``; its normal is ``R n_t``.

Curvatures (implicit-function theorem on the envelope mapping): with ``f_ψ ≠ 0``,
``ψ_u = -f_u/f_ψ``, ``ψ_θ = -f_θ/f_ψ``; then ``r_u = R r_t,u + (dM r_t) ψ_u`` and
``n_u = R n_t,u + (dR n_t) ψ_u`` (same for θ), and Weingarten's relation ``II_ij = r_i · n_j``
(see :func:`~fegear.geometry.surface.curvatures_from_normal_derivatives`) gives the principal
curvatures from first derivatives only. ``f_ψ = 0`` marks singular points of the generated surface
(undercut; Litvin & Fuentes 2004 §6.3).

The meshing equation is solved for ψ at every ``(u, θ)`` by a vectorised safeguarded Newton
iteration inside a sign-change bracket (bisection when Newton leaves the bracket), so it always
terminates; the residual ``|n·v|/|v|`` (regularised where v = 0) is reported.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .surface import curvatures_from_normal_derivatives, unit
from .transforms import _rot, translation

__all__ = [
    "ToolSample",
    "ToolSurface",
    "tool_sample",
    "Rotation",
    "Translation",
    "Fixed",
    "Motion",
    "Envelope",
    "generate",
]

log = logging.getLogger(__name__)
#: regularisation of the residual at pure-rolling points (v = 0): |f| / (|v| + 1e-3 |f_ψ|)
_PSI_REG = 1e-3
Array = NDArray[np.float64]


@dataclass(frozen=True)
class ToolSample:
    """Tool surface and first derivatives at parameters ``(u, θ)``, tool frame; each ``(..., 3)``.

    ``n`` is unit and points into the tool body; ``n_u``, ``n_t`` are its derivatives.
    """

    r: Array
    r_u: Array
    r_t: Array
    n: Array
    n_u: Array
    n_t: Array


class ToolSurface(Protocol):
    """A tool: ``evaluate(u, θ) -> ToolSample`` vectorised over broadcast arrays."""

    def evaluate(self, u: Array, theta: Array) -> ToolSample: ...


def tool_sample(
    r: Array, r_u: Array, r_t: Array, r_uu: Array, r_ut: Array, r_tt: Array, sign: ArrayLike
) -> ToolSample:
    """Build a :class:`ToolSample` with ``n = sign · (r_u × r_t)/|r_u × r_t|`` and its derivatives.

    ``d(c/|c|) = (c' − n (n·c'))/|c|`` with ``c_u = r_uu × r_t + r_u × r_ut``.
    """
    c = np.cross(r_u, r_t)
    cn = np.linalg.norm(c, axis=-1, keepdims=True)
    s = np.asarray(sign, dtype=float)[..., None] if np.ndim(sign) else float(sign)
    n = c / cn
    c_u = np.cross(r_uu, r_t) + np.cross(r_u, r_ut)
    c_t = np.cross(r_ut, r_t) + np.cross(r_u, r_tt)
    n_u = (c_u - n * np.sum(n * c_u, -1, keepdims=True)) / cn
    n_t = (c_t - n * np.sum(n * c_t, -1, keepdims=True)) / cn
    return ToolSample(r=r, r_u=r_u, r_t=r_t, n=s * n, n_u=s * n_u, n_t=s * n_t)


@functools.lru_cache(maxsize=256)
def _poly_coeffs(c: tuple[float, ...]) -> tuple[Array, Array, Array]:
    """Coefficients of ``c0 + c1 ψ + c2 ψ² + ...`` and of its first two derivatives (a motion
    keeps its coefficients: derived once, not at every evaluation)."""
    p = np.polynomial.polynomial
    a = np.asarray(c, dtype=float)
    out = (a, p.polyder(a), p.polyder(a, 2))
    for x in out:
        x.setflags(write=False)
    return out


@functools.lru_cache(maxsize=256)
def _poly_floats(c: tuple[float, ...]) -> tuple[tuple[float, ...], ...]:
    """:func:`_poly_coeffs` as tuples of floats (for :func:`_horner`)."""
    return tuple(tuple(float(v) for v in x) for x in _poly_coeffs(c))


def _horner(c: tuple[float, ...], x: Array) -> Array:
    """``np.polynomial.polynomial.polyval(x, c)`` by the same operations, ``c[-1] + 0 x`` then
    ``c[k] + (...) x`` down to ``k = 0`` (the same numbers), without its per-call argument
    conversions (the generation engine evaluates its motions ~10⁴ times per TCA)."""
    v = c[-1] + x * 0
    for ck in c[-2::-1]:
        v = ck + v * x
    return v


def _poly(c: Sequence[float], psi: Array) -> tuple[Array, Array, Array]:
    """Value, first and second derivative of ``c0 + c1 ψ + c2 ψ² + ...``."""
    c0, c1, c2 = _poly_floats(tuple(float(x) for x in c))
    return _horner(c0, psi), _horner(c1, psi), _horner(c2, psi)


@dataclass(frozen=True)
class Rotation:
    """Rotation about coordinate ``axis`` by ``angle(ψ) = Σ coeffs[k] ψ^k`` (rad)."""

    axis: Literal["x", "y", "z"]
    coeffs: tuple[float, ...]

    def matrices(self, psi: Array) -> tuple[Array, Array, Array]:
        i = "xyz".index(self.axis)
        a, a1, a2 = _poly(self.coeffs, psi)
        d1 = _rot(a, i, 1)
        M1 = d1 * a1[..., None, None]
        M2 = _rot(a, i, 2) * (a1**2)[..., None, None] + d1 * a2[..., None, None]
        return _rot(a, i), M1, M2


@dataclass(frozen=True)
class Translation:
    """Translation by ``(Σ coeffs[k] ψ^k) · direction`` (mm)."""

    direction: tuple[float, float, float]
    coeffs: tuple[float, ...]

    def matrices(self, psi: Array) -> tuple[Array, Array, Array]:
        d = np.asarray(self.direction, dtype=float)
        c, c1, c2 = _poly(self.coeffs, psi)
        M = translation(c[..., None] * d)
        M1 = np.zeros(M.shape)
        M2 = np.zeros(M.shape)
        M1[..., :3, 3] = c1[..., None] * d
        M2[..., :3, 3] = c2[..., None] * d
        return M, M1, M2


@dataclass(frozen=True)
class Fixed:
    """A constant 4×4 transform."""

    matrix: Array

    def matrices(self, psi: Array) -> tuple[Array, Array, Array]:
        M = np.broadcast_to(np.asarray(self.matrix, dtype=float), psi.shape + (4, 4))
        Z = np.zeros(M.shape)
        return M, Z, Z


@dataclass(frozen=True)
class Motion:
    """Generating motion ``M(ψ) = F_0(ψ) F_1(ψ) … F_k(ψ)`` from tool frame to blank frame.

    The right-most factor acts first on tool points (column-vector convention).
    """

    factors: tuple[Rotation | Translation | Fixed, ...]

    def matrices(self, psi: ArrayLike) -> tuple[Array, Array, Array]:
        """``M``, ``dM/dψ``, ``d²M/dψ²``, each ``(..., 4, 4)`` (product rule, forward).

        The same products as ``P @ F`` over the stacks, but a product with a constant operand
        (a :class:`Fixed` factor, its zero derivatives, or the partial product before the first
        moving factor) is one matrix product over the whole stack instead of one per point: the
        same BLAS products of the same 4 × 4 blocks, several times faster on long stacks
        (tested bit for bit against the per-point products)."""
        psi = np.asarray(psi, dtype=float)
        if psi.size < _BATCH_MIN:
            P = np.broadcast_to(np.eye(4), psi.shape + (4, 4))
            P1 = np.zeros(P.shape)
            P2 = np.zeros(P.shape)
            for fac in self.factors:
                F, F1, F2 = fac.matrices(psi)
                P, P1, P2 = P @ F, P1 @ F + P @ F1, P2 @ F + 2 * (P1 @ F1) + P @ F2
            return P, P1, P2
        P, P1, P2 = np.eye(4), np.zeros((4, 4)), np.zeros((4, 4))
        for fac in self.factors:
            if isinstance(fac, Fixed):
                F = np.asarray(fac.matrix, dtype=float)
                F1 = F2 = np.zeros((4, 4))
            else:
                F, F1, F2 = fac.matrices(psi)
            P, P1, P2 = (
                _mm(P, F),
                _mm(P1, F) + _mm(P, F1),
                _mm(P2, F) + 2 * _mm(P1, F1) + _mm(P, F2),
            )
        shape = psi.shape + (4, 4)
        return tuple(np.broadcast_to(X, shape) if X.ndim == 2 else X for X in (P, P1, P2))


#: stacks shorter than this take the per-point products (the batched ones cost a few copies)
_BATCH_MIN = 64


def _mm(A: Array, B: Array) -> Array:
    """``A @ B`` for a constant ``(4, 4)`` or a stack ``(..., 4, 4)`` on either side; with one
    constant operand, one product over the stack (``C B_k`` side by side, ``A_k C`` one above
    the other)."""
    if A.ndim == 2 and B.ndim == 2:
        return A @ B
    if A.ndim == 2:
        lead = B.shape[:-2]
        wide = np.ascontiguousarray(np.moveaxis(B.reshape(-1, 4, 4), 0, 1)).reshape(4, -1)
        C = (A @ wide).reshape(4, -1, 4)
        return np.ascontiguousarray(np.moveaxis(C, 1, 0)).reshape(lead + (4, 4))
    if B.ndim == 2:
        A = np.ascontiguousarray(A)
        return (A.reshape(-1, 4) @ B).reshape(A.shape)
    return A @ B


def _mv(M: Array, x: Array, w: float) -> Array:
    """``M [x, w]`` for homogeneous weight ``w`` (1 point, 0 vector); returns ``(..., 3)``."""
    out = np.einsum("...ij,...j->...i", M[..., :3, :3], x)
    return out + M[..., :3, 3] if w else out


@dataclass(frozen=True)
class Envelope:
    """Generated surface at tool parameters ``(u, θ)``, blank frame; arrays ``(...)``/``(..., 3)``.

    Attributes
    ----------
    psi
        Generating-motion parameter solving the equation of meshing.
    points, normals
        Generated points (mm) and unit normals (out of the tooth material).
    r_u, r_t, n_u, n_t
        Derivatives of the generated point and normal w.r.t. the tool parameters (IFT).
    f_psi
        ``∂f/∂ψ`` at the solution (0 at singular points of the generated surface).
    singularity
        ``f_ψ − a f_u − b f_θ`` with ``v = a R r_t,u + b R r_t,θ``: the generated mapping has
        ``r_u × r_θ = (singularity / f_ψ) (R r_t,u × R r_t,θ)``, so a sign change of it marks the
        singular points (line of regression) where undercut begins (Litvin & Fuentes 2004 §6.3).
    residual
        ``|n·v| / (|v| + 10⁻³ |∂(n·v)/∂ψ|)`` at the solution: the sine of the angle between n and
        v, regularised at pure-rolling points (pitch point) where ``v = 0``.
    converged
        Residual below the tolerance.
    """

    psi: Array
    points: Array
    normals: Array
    r_u: Array
    r_t: Array
    n_u: Array
    n_t: Array
    f_psi: Array
    singularity: Array
    residual: Array
    converged: NDArray[np.bool_] = field(repr=False)

    def curvatures(self) -> tuple[Array, Array]:
        """Principal curvatures ``(..., 2)`` (convex positive) and directions ``(..., 2, 3)``."""
        return curvatures_from_normal_derivatives(
            self.r_u, self.r_t, self.normals, self.n_u, self.n_t
        )


def _meshing(tool: ToolSample, motion: Motion, psi: Array) -> tuple[Array, Array, Array]:
    """``f``, ``f_ψ`` and ``|v|`` at ψ."""
    M, M1, M2 = motion.matrices(psi)
    n = _mv(M, tool.n, 0)
    v = _mv(M1, tool.r, 1)
    f = np.sum(n * v, -1)
    f_psi = np.sum(_mv(M1, tool.n, 0) * v, -1) + np.sum(n * _mv(M2, tool.r, 1), -1)
    return f, f_psi, np.linalg.norm(v, axis=-1)


def generate(
    tool: ToolSurface,
    motion: Motion,
    u: ArrayLike,
    theta: ArrayLike,
    psi0: ArrayLike,
    half_width: float = 0.5,
    tol: float = 1e-15,
    max_iter: int = 60,
    n_scan: int = 17,
) -> Envelope:
    """Solve the equation of meshing and return the generated surface at ``(u, θ)``.

    Parameters
    ----------
    tool, motion
        Tool surface (tool frame) and generating motion (tool → blank).
    u, theta
        Tool parameters (broadcast together).
    psi0
        Initial guess of ψ (broadcast); the root nearest to it inside
        ``[psi0 − half_width, psi0 + half_width]`` is taken.
    tol
        Stop when ``|f|/|v| < tol`` or the bracket is below ``1e-15`` rad (times ``max(1, |ψ|)``).
    max_iter, n_scan
        Newton/bisection iteration cap (guarantees termination) and bracket-scan samples.
    """
    u, theta = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(theta, dtype=float))
    ts = tool.evaluate(u, theta)
    psi0 = np.broadcast_to(np.asarray(psi0, dtype=float), u.shape).copy()

    # bracket: scan ±half_width, pick the sign change nearest psi0
    offs = np.linspace(-half_width, half_width, n_scan)
    grid = psi0[..., None] + offs
    if 1 < u.size * n_scan < _BATCH_MIN:
        # a small scan in one evaluation of the motion (the per-point products of
        # Motion.matrices as in one call per scan point, the same numbers): the scan points one
        # set after the other, the tool sample repeated for each
        rep = ToolSample(*(np.tile(np.broadcast_to(z, u.shape + (3,)).reshape(-1, 3), (n_scan, 1))
                           for z in (ts.r, ts.r_u, ts.r_t, ts.n, ts.n_u, ts.n_t)))  # fmt: skip
        f = _meshing(rep, motion, np.moveaxis(grid, -1, 0).reshape(-1))[0]
        fg = np.moveaxis(f.reshape((n_scan,) + u.shape), 0, -1)
    else:
        fg = np.stack([_meshing(ts, motion, grid[..., k])[0] for k in range(n_scan)], -1)
    change = np.signbit(fg[..., :-1]) != np.signbit(fg[..., 1:])
    dist = np.where(change, np.abs(0.5 * (offs[:-1] + offs[1:])), np.inf)
    k = np.argmin(dist, axis=-1)
    has = np.isfinite(np.take_along_axis(dist, k[..., None], -1)[..., 0])
    a = np.where(has, np.take_along_axis(grid, k[..., None], -1)[..., 0], -np.inf)
    b = np.where(has, np.take_along_axis(grid, k[..., None] + 1, -1)[..., 0], np.inf)
    fa = np.where(has, np.take_along_axis(fg, k[..., None], -1)[..., 0], np.nan)
    if not np.all(has):
        log.warning("generate: no sign change of n·v near psi0 at %d points", np.sum(~has))
    # without a bracket, Newton is confined to the scanned window (no sign change: no root)
    a = np.where(has, a, psi0 - half_width)
    b = np.where(has, b, psi0 + half_width)
    x = np.clip(psi0, a, b)
    # A point that has stopped (converged, or bracket closed) keeps its ψ: its f is the same at
    # the next iteration and its bracket only shrinks. So only the points still moving are
    # iterated (a tenth of them after the first step), with the same arithmetic on each.
    x, a, b, fa, has = (np.array(z, dtype=z.dtype).reshape(-1) for z in (x, a, b, fa, has))
    flat = [np.broadcast_to(z, u.shape + (3,)).reshape(-1, 3) for z in (ts.r, ts.r_u, ts.r_t,
            ts.n, ts.n_u, ts.n_t)]  # fmt: skip
    act = np.arange(x.size)
    for _ in range(max_iter):
        tk = ToolSample(*(z[act] for z in flat))
        xk, ak, bk, fak, hk = x[act], a[act], b[act], fa[act], has[act]
        f, fp, vn = _meshing(tk, motion, xk)
        done = np.abs(f) <= tol * (vn + _PSI_REG * np.abs(fp))
        left = hk & (np.signbit(f) == np.signbit(fak))
        ak = np.where(left, xk, ak)
        fak = np.where(left, f, fak)
        bk = np.where(hk & ~left, xk, bk)
        with np.errstate(divide="ignore", invalid="ignore"):
            xn = xk - f / fp
        bad = ~np.isfinite(xn) | (xn <= ak) | (xn >= bk)
        xn = np.where(bad & hk, 0.5 * (ak + bk), xn)
        xn = np.where(bad & ~hk, np.clip(np.nan_to_num(xn), ak, bk), xn)
        small = bk - ak <= 1e-15 * np.maximum(1.0, np.abs(xk))
        stop = done | small
        x[act] = np.where(stop, xk, xn)
        a[act], b[act], fa[act] = ak, bk, fak
        act = act[~stop]
        if act.size == 0:
            break
    return _assemble(ts, motion, x.reshape(u.shape), tol)


def _assemble(ts: ToolSample, motion: Motion, psi: Array, tol: float) -> Envelope:
    """Points, normals and IFT derivatives at the solved ψ."""
    M, M1, M2 = motion.matrices(psi)
    n = _mv(M, ts.n, 0)
    v = _mv(M1, ts.r, 1)
    f = np.sum(n * v, -1)
    vn = np.linalg.norm(v, axis=-1)
    f_psi = np.sum(_mv(M1, ts.n, 0) * v, -1) + np.sum(n * _mv(M2, ts.r, 1), -1)
    f_u = np.sum(_mv(M, ts.n_u, 0) * v, -1) + np.sum(n * _mv(M1, ts.r_u, 0), -1)
    f_t = np.sum(_mv(M, ts.n_t, 0) * v, -1) + np.sum(n * _mv(M1, ts.r_t, 0), -1)
    with np.errstate(divide="ignore", invalid="ignore"):
        psi_u = -f_u / f_psi
        psi_t = -f_t / f_psi
    dRn = _mv(M1, ts.n, 0)
    r_u = _mv(M, ts.r_u, 0) + v * psi_u[..., None]
    r_t = _mv(M, ts.r_t, 0) + v * psi_t[..., None]
    n_u = _mv(M, ts.n_u, 0) + dRn * psi_u[..., None]
    n_t = _mv(M, ts.n_t, 0) + dRn * psi_t[..., None]
    A, B = _mv(M, ts.r_u, 0), _mv(M, ts.r_t, 0)
    gAA, gAB, gBB = np.sum(A * A, -1), np.sum(A * B, -1), np.sum(B * B, -1)
    vA, vB = np.sum(v * A, -1), np.sum(v * B, -1)
    det = gAA * gBB - gAB**2
    with np.errstate(divide="ignore", invalid="ignore"):
        ca = (vA * gBB - vB * gAB) / det
        cb = (vB * gAA - vA * gAB) / det
        den = vn + _PSI_REG * np.abs(f_psi)
        res = np.where(den > 0, np.abs(f) / den, 0.0)
    return Envelope(
        psi=psi,
        points=_mv(M, ts.r, 1),
        normals=unit(n),
        r_u=r_u,
        r_t=r_t,
        n_u=n_u,
        n_t=n_t,
        f_psi=f_psi,
        singularity=f_psi - ca * f_u - cb * f_t,
        residual=res,
        converged=res <= max(tol, 1e-12),
    )
