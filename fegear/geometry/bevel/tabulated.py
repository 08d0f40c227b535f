"""A generated bevel flank tabulated once in its cutter parameters: the exact surface to ~1e-12 mm.

The exact evaluator (:class:`~.native.NativeFlank`) solves the equation of meshing at every
point (a Newton on ψ through the machine's motion chain): ~0.3-0.6 ms per call of a few points,
and the TCA's and the contact grids' Newton solves make tens of thousands of such calls per
cycle. The flank is smooth in ``(s, θ)`` (blade parameter, cutter angle), so its points and
unit normals are tabulated on a uniform ``n × n`` grid over the working box and a margin around
it (the box within which the solves clamp their steps) and interpolated by tensor-product
quintic splines (:class:`scipy.interpolate.RectBivariateSpline`, ``k = 5``; de Boor 2001,
ch. XVII). The interpolation error of a spline of degree ``k`` is ``O(h^{k+1})`` in the grid
step ``h`` (de Boor 2001, ch. XII): on the reference 12/36 spiral bevel and the 10/41 hypoid,
201 × 201 nodes over twice the working box give ≤ 1e-11 mm on the points and ≤ 3e-14 on the
normals against the exact evaluator (``docs/geometry/tabulated_flank.md``), two orders below
the TCA's Newton tolerance (1e-10 mm). Tangents are the spline's own derivatives.

Every table measures its error at build time, against the exact flank at points between its
nodes (:attr:`TabulatedFlank.error_mm`); a table that misses :data:`TABLE_TOL_MM` is refined,
and a flank that cannot be tabulated to it keeps its exact evaluator
(:func:`tabulate`). Points outside the table are evaluated exactly.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import SolverError
from .native import NativeFlank, _compile

__all__ = ["FlankTableRecord", "TabulatedFlank", "TABLE_TOL_MM", "flank_record", "from_record",
           "tabulate"]  # fmt: skip

log = logging.getLogger(__name__)
Array = NDArray[np.float64]

#: largest distance (mm) between the tabulated and the exact flank accepted at build time; the
#: TCA's Newton solves stop at 1e-10 mm (``fegear.tca.solve.TOL_MM``): a table ten times below
#: it does not move a contact point beyond the solves' own resolution
TABLE_TOL_MM = 1e-11
#: the working box (the flank's range of (s, θ)) and a quarter of its span around it: every point
#: of the working flank lies there; the table must meet TABLE_TOL_MM there
NEAR = 0.25
#: further out only trial steps of the Newton solves go, and points that stop there are off the
#: working flank by more than a quarter span (no contact): 1e-9 mm (2.6 % of the points the
#: spiral bevel's ΔE run evaluates)
FAR_TOL_MM = 1e-9
#: the table covers the working box widened by this fraction of its span on each side: the TCA's
#: solves clamp their steps half a span beyond the box (``fegear.tca.solve``); 6 % of their
#: calls on the spiral bevel reach past a quarter span
MARGIN = 0.5
#: nodes per direction tried in turn until :data:`TABLE_TOL_MM` and :data:`FAR_TOL_MM` hold
NODES = (201, 281)
#: spline degree (quintic: error O(h⁶))
DEGREE = 5


@dataclass(frozen=True)
class TabulatedFlank(NativeFlank):
    """:class:`~.native.NativeFlank` whose :meth:`evaluate` interpolates a table of the exact
    flank (points and unit normals, quintic tensor-product splines in ``(s, θ)``).

    Attributes (beyond :class:`~.native.NativeFlank`'s)
    ----------
    coef
        ``(n_s, n_θ, 6)`` B-spline coefficients of the point's ``x, y, z`` (mm) and the normal's
        components (one set of knots for all six).
    axes
        ``((s₀, h_s), (θ₀, h_θ))``: the coefficient of index ``i`` belongs to the uniform
        B-spline starting at ``s₀ + i h_s`` (likewise in θ).
    table_box
        ``(lo, hi)`` of the tabulated ``(s, θ)``; outside it :meth:`evaluate` is exact.
    error_mm
        Largest distance of the tabulated points from the exact flank measured at build time
        (at the centres of a sample of grid cells)
        within :data:`NEAR` spans of the working box, mm.
    normal_error
        Largest difference of the unit normals there.
    far_error_mm
        Largest distance further out (where only the Newton solves' trial steps go), mm.
    """

    coef: Array
    axes: tuple[tuple[float, float], tuple[float, float]]
    table_box: tuple[Array, Array]
    error_mm: float = np.nan
    normal_error: float = np.nan
    far_error_mm: float = np.nan

    def evaluate(self, s: ArrayLike, th: ArrayLike, tangents: bool = False) -> tuple[Array, ...]:
        """Points ``(..., 3)`` and unit normals; with ``tangents`` also ``r_s``, ``r_θ`` (the
        derivatives of the point splines). Points outside :attr:`table_box`: exact."""
        s, th = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(th, dtype=float))
        shape = s.shape
        s, th = s.ravel(), th.ravel()
        lo, hi = self.table_box
        inside = (s >= lo[0]) & (s <= hi[0]) & (th >= lo[1]) & (th <= hi[1])
        if inside.all():
            out = self._interpolate(s, th, tangents)
        else:
            out = [np.empty((s.size, 3)) for _ in range(4 if tangents else 2)]
            far = ~inside
            if inside.any():
                near = self._interpolate(s[inside], th[inside], tangents)
                for o, x in zip(out, near, strict=True):
                    o[inside] = x
            exact = NativeFlank.evaluate(self, s[far], th[far], tangents)
            for o, x in zip(out, exact, strict=True):
                o[far] = x
        return tuple(o.reshape(shape + (3,)) for o in out)

    def _interpolate(self, s: Array, th: Array, tangents: bool) -> list[Array]:
        """The splines at ``(s, θ)`` inside :attr:`table_box`: points, unit normals and, with
        ``tangents``, the points' ``s``- and ``θ``-derivatives (lists of ``(n, 3)``)."""
        (s0, hs), (t0, ht) = self.axes
        i, bs, dbs = _basis((s - s0) / hs)
        j, bt, dbt = _basis((th - t0) / ht)
        # the 6 x 6 coefficients of every point, all six components: (n, 36, 6), contracted
        # with the products of the basis functions (one batched product for all that is asked)
        nt = self.coef.shape[1]
        flat = (i[:, :, None] * nt + j[:, None, :]).reshape(len(s), 36)
        C = np.take(self.coef.reshape(-1, 6), flat, axis=0)
        # (one product for the values, one for the tangents: a point is the same number
        # whether its tangents are asked or not)
        v = ((bs[:, :, None] * bt[:, None, :]).reshape(len(s), 1, 36) @ C)[:, 0]
        p = v[:, :3]
        n = v[:, 3:] / np.linalg.norm(v[:, 3:], axis=-1)[:, None]
        out = [p, n]
        if tangents:
            ws = dbs[:, :, None] * bt[:, None, :] / hs
            wt = bs[:, :, None] * dbt[:, None, :] / ht
            W = np.stack([ws, wt], 1).reshape(len(s), 2, 36)
            D = W @ C[..., :3]
            out += [D[:, 0], D[:, 1]]
        return out


def _cardinal_matrix() -> tuple[Array, Array]:
    """Power-basis coefficients of the uniform quintic B-spline's six pieces: the basis
    functions nonzero on a knot interval at the local coordinate ``t ∈ [0, 1)`` are
    ``[1, t, …, t⁵] @ M`` (columns: the first to the last of the six), and their derivatives
    ``[1, t, …, t⁴] @ D``. ``N₅`` on knots ``0 … 6`` (de Boor 2001, ch. IX), fitted exactly
    (a polynomial of degree 5 through 6 of its values)."""
    from scipy.interpolate import BSpline

    b = BSpline.basis_element(np.arange(7.0), extrapolate=False)
    t = np.linspace(0.0, 1.0, 6, endpoint=False) + 1.0 / 12.0
    V = np.vander(t, 6, increasing=True)
    M = np.stack([np.linalg.solve(V, b(t + 5 - r)) for r in range(6)], -1)
    D = M[1:] * np.arange(1, 6)[:, None]
    return M, D


_M, _D = _cardinal_matrix()


def _basis(x: Array) -> tuple[Array, Array, Array]:
    """Coefficient indices ``(n, 6)``, basis values ``(n, 6)`` and their derivatives (per knot
    spacing) at ``x`` = position in knot spacings from the first uniform knot."""
    m = np.floor(x)
    t = x - m
    T = t[:, None] ** np.arange(6)
    idx = m.astype(np.intp)[:, None] + np.arange(6)
    return idx, T @ _M, T[:, :5] @ _D


def _table(nf: NativeFlank, n: int) -> TabulatedFlank | None:
    """``nf`` tabulated on ``n × n`` nodes, its error measured at cell centres (None if the
    exact flank is not finite on every node).

    The splines interpolate the nodes with not-a-knot end conditions
    (:class:`~scipy.interpolate.RectBivariateSpline`); their knots are uniform except within
    eight nodes of an end, so the table is used only inside those (``table_box``), where every
    basis function is the uniform quintic B-spline (:func:`_basis`).
    """
    from scipy.interpolate import RectBivariateSpline

    lo, hi = nf.box
    span = hi - lo
    tlo, thi = lo - MARGIN * span, hi + MARGIN * span
    h = (thi - tlo) / (n - 17)
    gs = tlo[0] + h[0] * np.arange(-8, n - 8)
    gt = tlo[1] + h[1] * np.arange(-8, n - 8)
    P, N = NativeFlank.evaluate(nf, *np.meshgrid(gs, gt, indexing="ij"))
    if not (np.isfinite(P).all() and np.isfinite(N).all()):
        return None
    coef = np.empty((n, n, 6))
    for k, X in enumerate((P[..., 0], P[..., 1], P[..., 2], N[..., 0], N[..., 1], N[..., 2])):
        tx, ty, c = RectBivariateSpline(gs, gt, X, kx=DEGREE, ky=DEGREE).tck[:3]
        coef[..., k] = c.reshape(n, n)
    # the coefficient of index i belongs to the B-spline on knots tx[i .. i + 6]; the interior
    # knots are the nodes gs[3:-3] (tx[6] = gs[3]), so it starts at gs[i − 3]; on the interval
    # starting at gs[m + 2] the nonzero ones are m … m + 5 (:func:`_basis`)
    axes = ((float(gs[2]), float(h[0])), (float(gt[2]), float(h[1])))
    tab = TabulatedFlank(*_fields(nf), coef, axes, (tlo, thi))
    # the error between the nodes: the centres of every 4th cell of the table (where an
    # interpolant is furthest from its data)
    cs = tlo[0] + h[0] * (np.arange(0, n - 17, 4) + 0.5)
    ct = tlo[1] + h[1] * (np.arange(0, n - 17, 4) + 0.5)
    S, T = (x.ravel() for x in np.meshgrid(cs, ct, indexing="ij"))
    Pe, Ne = NativeFlank.evaluate(nf, S, T)
    Pt, Nt = tab._interpolate(S, T, False)
    dp = np.linalg.norm(Pt - Pe, axis=-1)
    dn = np.linalg.norm(Nt - Ne, axis=-1)
    # how far beyond the working box, in spans (0 inside it)
    beyond = np.maximum(
        np.maximum(lo - np.stack([S, T], -1), np.stack([S, T], -1) - hi) / span, 0
    ).max(-1)
    near = beyond <= NEAR
    return TabulatedFlank(
        *_fields(nf), coef, axes, (tlo, thi), float(dp[near].max()), float(dn[near].max()),
        float(dp[~near].max()) if (~near).any() else 0.0,
    )  # fmt: skip


def _with_inverse(tab: TabulatedFlank, n: int = 33) -> TabulatedFlank:
    """``tab`` with a finer predictor of its inversion ``(u, v) → (s, θ)``
    (:meth:`~.native.NativeFlank.native_evaluation`): quintic splines through ``n × n`` points
    of the working flank (where the 9 × 9 bicubic predictor it is built with was fitted), each
    inverted by that Newton on the table. The Newton then starts within ~1e-9 mm of the root and
    needs one step where it needed two; it ends at the same tolerance, so the result does not
    depend on the predictor beyond it. ``tab`` unchanged if an inversion fails (logged)."""
    from scipy.interpolate import RectBivariateSpline

    b = tab.member.boundaries()
    uu = np.linspace(b.u_fillet, b.u_tip, n)
    vv = np.linspace(b.v_start, b.v_end, n)
    try:
        s, th = tab.native(*np.meshgrid(uu, vv, indexing="ij"))
    except SolverError as e:  # pragma: no cover - the working flank inverts on every pair seen
        log.info("%s %s: finer inverse predictor not built (%s)", tab.member.name, tab.side, e)
        return tab
    k = DEGREE
    inverse = (
        RectBivariateSpline(uu, vv, s, kx=k, ky=k),
        RectBivariateSpline(uu, vv, th, kx=k, ky=k),
    )
    return replace(tab, inverse=inverse)


def _fields(nf: NativeFlank) -> tuple:
    return (nf.member, nf.side, nf.tool, nf.steps, nf.spline, nf.inverse, nf.box)


def tabulate(nf: NativeFlank) -> NativeFlank:
    """``nf`` tabulated (:class:`TabulatedFlank`) to :data:`TABLE_TOL_MM`, or ``nf`` itself when
    no table of :data:`NODES` meets it (logged)."""
    err = np.inf
    for n in NODES:
        tab = _table(nf, n)
        if tab is None:
            break
        err = tab.error_mm
        if err <= TABLE_TOL_MM and tab.far_error_mm <= FAR_TOL_MM:
            tab = _with_inverse(tab)
            log.debug("%s %s flank tabulated on %d x %d nodes: %.1e mm, normals %.1e",
                      nf.member.name, nf.side, n, n, err, tab.normal_error)  # fmt: skip
            return tab
    log.info("%s %s flank not tabulated (error %.1e mm > %.0e mm): exact evaluation",
             nf.member.name, nf.side, err, TABLE_TOL_MM)  # fmt: skip
    return nf


# ------------------------------------------------------------------ a table as plain data


@dataclass(frozen=True)
class FlankTableRecord:
    """What a :class:`TabulatedFlank` is made of beyond its member, as plain arrays (for a cache
    on disk: :func:`flank_record`, :func:`from_record`). A spline is its knots, coefficients and
    degrees ``(tx, ty, c, kx, ky)`` (:class:`scipy.interpolate.RectBivariateSpline`'s ``tck``).

    Attributes
    ----------
    psi, inverse9, inverse
        The ψ table of the exact evaluator (:meth:`NativeFlank.build`), the exact evaluator's
        9 × 9 inverse predictor (``(s, θ)`` splines) and the table's finer one.
    box
        ``(lo, hi)`` the working box in ``(s, θ)``.
    coef, axes, table_box, error_mm, normal_error, far_error_mm
        As :class:`TabulatedFlank`.
    """

    psi: tuple
    inverse9: tuple[tuple, tuple]
    inverse: tuple[tuple, tuple]
    box: tuple[Array, Array]
    coef: Array
    axes: tuple[tuple[float, float], tuple[float, float]]
    table_box: tuple[Array, Array]
    error_mm: float
    normal_error: float
    far_error_mm: float


def _tck(spline) -> tuple:
    tx, ty, c = spline.tck
    kx, ky = spline.degrees
    return (np.asarray(tx), np.asarray(ty), np.asarray(c), int(kx), int(ky))


def _spline(tck: tuple):
    """The :class:`~scipy.interpolate.RectBivariateSpline` of ``tck = (tx, ty, c, kx, ky)``:
    the same object the fit made (its evaluation reads ``tck`` and ``degrees`` only)."""
    from scipy.interpolate import RectBivariateSpline

    tx, ty, c, kx, ky = tck
    spline = RectBivariateSpline.__new__(RectBivariateSpline)
    spline.tck = (np.asarray(tx), np.asarray(ty), np.asarray(c))
    spline.degrees = (int(kx), int(ky))
    return spline


def flank_record(tab: TabulatedFlank, native: NativeFlank) -> FlankTableRecord:
    """``tab`` (and ``native``, the exact evaluator it was made from) as a
    :class:`FlankTableRecord`."""
    return FlankTableRecord(
        psi=_tck(tab.spline),
        inverse9=(_tck(native.inverse[0]), _tck(native.inverse[1])),
        inverse=(_tck(tab.inverse[0]), _tck(tab.inverse[1])),
        box=tab.box,
        coef=tab.coef,
        axes=tab.axes,
        table_box=tab.table_box,
        error_mm=tab.error_mm,
        normal_error=tab.normal_error,
        far_error_mm=tab.far_error_mm,
    )


def from_record(member, side, rec: FlankTableRecord) -> tuple[TabulatedFlank, NativeFlank]:
    """The table and its exact evaluator of ``member``'s ``side`` flank from ``rec``
    (:func:`flank_record` of the same member and side): equal to the ones built, bit for bit
    (the tool and motion are the member's own, the arrays the ones stored)."""
    tool, mot = member._tools(side)
    steps = _compile(mot.factors)
    psi = _spline(rec.psi)
    native = NativeFlank(member, side, tool, steps, psi, tuple(map(_spline, rec.inverse9)),
                         rec.box)  # fmt: skip
    tab = TabulatedFlank(
        member, side, tool, steps, psi, tuple(map(_spline, rec.inverse)), rec.box, rec.coef,
        rec.axes, rec.table_box, rec.error_mm, rec.normal_error, rec.far_error_mm,
    )  # fmt: skip
    return tab, native
