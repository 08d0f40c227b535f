"""Unloaded multi-pair TCA over the mesh cycle (``docs/tca/README.md``).

For each position ``φ1`` and each candidate pair (pinion tooth ``k``, gear tooth ``j``) the
*angular gap* ``θ(u1, v1)`` (:mod:`.solve`) is computed on a grid of the pinion flank, its minimum
is refined on the exact surfaces (a box-constrained quadratic-model pattern search: 3×3 stencil,
least-squares quadratic, Newton step, stencil shrink), and the gear flank EDGES (tip and face ends)
are searched against the pinion surface as well (edge contact of the gear), so that contact on any
flank boundary is found. The pair's closing rotation is the smaller of the two; the unloaded TE is
``−min over pairs`` (``docs/conventions.md``: ``Δφ2 = φ2 − (N1/N2) φ1``, negative = the gear lags).
Then the separation field along the pinion normal (the LTCA contact grid), the contact ellipse
(paint thickness and Hertz, :mod:`fegear.mechanics.hertz_closed_form`) and the edge flags follow.

Pairs: ``m ∈ pair_offsets`` gives pinion tooth ``k = −s1 m`` and gear tooth ``j = −s2 m``
(``s_i`` the driving senses), so ``m = 0`` is in contact at ``φ1 = 0`` and ``m = +1`` is the next
pair to come into mesh.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline, LinearNDInterpolator
from scipy.spatial import cKDTree

from ..errors import InputError
from ..geometry.pair_placement import Assembly, tooth_transform
from ..geometry.transforms import apply_points, apply_vectors, compose, inverse
from ..mechanics.hertz_closed_form import effective_modulus, hertz_point, paint_ellipse
from .ellipse import contact_curvature, normal_force
from .results import ContactEllipseAt, PositionResult, SeparationGrid
from .solve import circle_hit, in_bounds, line_hit, wrap
from .surfaces import FlankMap, flank_map

__all__ = ["TCAOptions", "TCA", "TIE_RAD"]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]
_INF = np.inf
#: Pairs whose closing rotations agree within this (rad) touch at once (conjugate pairs: the
#: face gear's, exactly): the Newton solves stop at ``TOL_MM`` = 1e-10 mm, over a lever of 10 mm
#: or more 1e-11 rad. The pair reported in contact among them is chosen by a rule (an interior
#: contact before an edge contact, then the largest Hertz p0, then the first of
#: ``pair_offsets``: :meth:`TCA._contact_pair`), not by round-off.
TIE_RAD = 1e-11


@dataclass(frozen=True)
class TCAOptions:
    """Options of the TCA.

    Attributes
    ----------
    n_positions
        Positions per mesh cycle ``2π/N1`` (>= 2), ``φ1`` in ``[−π/N1, π/N1)``.
    pair_offsets
        Candidate pairs ``m`` (see module docstring).
    search_grid
        ``(nu, nv)`` pinion-flank grid of the angular-gap search.
    separation_grid
        ``(nu, nv)`` cells of the separation field (None: not computed).
    edge_samples
        Samples per gear edge in the edge search.
    refine_iter
        Iterations of the 2-D refinement (stencil shrinks by 0.3 each time).
    paint_mm
        Paint thickness of the unloaded ellipse and pattern (6.32 µm ≈ 0.00025 in, customary).
    pinion_torque_Nm
        Pinion torque of the Hertz ellipse (rigid TCA: the whole load on the pair in contact).
    E_MPa, nu
        Material of both members.
    edge_tol
        A contact point closer than ``edge_tol`` (relative to the span) to a boundary is an edge
        contact.
    """

    n_positions: int = 25
    pair_offsets: tuple[int, ...] = (-1, 0, 1)
    search_grid: tuple[int, int] = (15, 9)
    separation_grid: tuple[int, int] | None = (15, 9)
    edge_samples: int = 25
    refine_iter: int = 30
    paint_mm: float = 0.00632
    pinion_torque_Nm: float | None = None
    E_MPa: float = 206000.0
    nu: float = 0.3
    edge_tol: float = 1e-6

    def __post_init__(self) -> None:
        if self.n_positions < 2:
            raise InputError("n_positions", self.n_positions, ">= 2")
        if min(self.search_grid) < 3:
            raise InputError("search_grid", self.search_grid, "(nu, nv) each >= 3")
        if self.paint_mm <= 0:
            raise InputError("paint_mm", self.paint_mm, "> 0")
        if self.pinion_torque_Nm is not None and not self.pinion_torque_Nm > 0:
            raise InputError("pinion_torque_Nm", self.pinion_torque_Nm, "> 0 or None")


def _cell_grid(bd, n: tuple[int, int]) -> tuple[Array, Array]:
    nu, nv = n
    du, dv = (bd.u_tip - bd.u_fillet) / nu, (bd.v_end - bd.v_start) / nv
    return bd.u_fillet + du * (np.arange(nu) + 0.5), bd.v_start + dv * (np.arange(nv) + 0.5)


_INTERPOLATORS: dict[bytes, LinearNDInterpolator] = {}


def _sample_interpolator(points: Array, a: Array, b: Array) -> LinearNDInterpolator:
    """Linear interpolation of ``(a, b)`` over the 2-D ``points``, one per set of samples and
    process (every TCA of the same gear flank, whatever its assembly, has the same samples).

    The barycentric transforms of the triangles (one small LAPACK solve each, made on the first
    interpolation) are made here on one BLAS thread: with OpenBLAS's thread pool they took
    0.7-12 s instead of 3 ms on a 2-core machine with other processes running (measured: the
    first ``gear_start`` of the seed face gear's TCA)."""
    from hashlib import sha1

    from scipy.spatial import Delaunay
    from threadpoolctl import threadpool_limits

    key = sha1(b"".join(np.ascontiguousarray(x).tobytes() for x in (points, a, b))).digest()
    interp = _INTERPOLATORS.get(key)
    if interp is None:
        with threadpool_limits(1, user_api="blas"):
            tri = Delaunay(points)
            _ = tri.transform  # the per-triangle solves, now
        interp = LinearNDInterpolator(tri, np.stack([a, b], -1))
        _INTERPOLATORS[key] = interp
    return interp


class TCA:
    """TCA of one assembled pair: precomputes what does not depend on the position.

    Parameters
    ----------
    pinion, gear
        :class:`~fegear.geometry.surface.GeneratedMember` of member 1 and 2.
    assembly
        Placement (:mod:`fegear.geometry.pair_placement`); its ``side1``/``side2`` select the
        flanks.
    options
        :class:`TCAOptions`.
    maps
        Optional ``(FlankMap, FlankMap)`` overriding :func:`.surfaces.flank_map`.
    """

    def __init__(
        self,
        pinion,
        gear,
        assembly: Assembly,
        options: TCAOptions | None = None,
        maps: tuple[FlankMap, FlankMap] | None = None,
    ) -> None:
        self.opt = options or TCAOptions()
        self.asm = assembly
        self.pinion, self.gear = pinion, gear
        self.fm1, self.fm2 = maps or (
            flank_map(pinion, assembly.side1),
            flank_map(gear, assembly.side2),
        )
        o = self.opt
        m = np.asarray(o.pair_offsets, dtype=int)
        self.pairs = np.stack([-assembly.sense1 * m, -assembly.sense2 * m], -1)
        # pinion search grid (flank coordinates, node grid including the boundaries)
        b1, b2 = self.fm1.bounds, self.fm2.bounds
        nu, nv = o.search_grid
        U, V = np.meshgrid(
            np.linspace(b1.u_fillet, b1.u_tip, nu),
            np.linspace(b1.v_start, b1.v_end, nv),
            indexing="ij",
        )
        self.su, self.sv = U.ravel(), V.ravel()
        self.sa, self.sb = self.fm1.native(self.su, self.sv)
        self.sP, self.sN = self.fm1.evaluate(self.sa, self.sb)
        self.step1 = np.array(
            [(b1.u_tip - b1.u_fillet) / (nu - 1), (b1.v_end - b1.v_start) / (nv - 1)]
        )
        # gear grid for the initial guesses (nearest neighbour in (ρ, z))
        g = 21
        U2, V2 = np.meshgrid(
            np.linspace(b2.u_fillet, b2.u_tip, g),
            np.linspace(b2.v_start, b2.v_end, g),
            indexing="ij",
        )
        self.ga, self.gb = (x.ravel() for x in self.fm2.native(U2, V2))
        gp = self.fm2.evaluate(self.ga, self.gb)[0]
        self._gscale = 1.0
        self.gtree = cKDTree(np.stack([np.hypot(gp[:, 0], gp[:, 1]), gp[:, 2]], -1))
        # gear edges: tip, v_start, v_end; cubic splines of the native parameters over t in [0, 1]
        ne = o.edge_samples
        t = np.linspace(0.0, 1.0, ne)
        eu = [np.full(ne, b2.u_tip), b2.u_fillet + t * (b2.u_tip - b2.u_fillet)]
        eu.append(eu[1])
        ev = [
            b2.v_start + t * (b2.v_end - b2.v_start),
            np.full(ne, b2.v_start),
            np.full(ne, b2.v_end),
        ]
        self.edge_names = ("tip", "v_start", "v_end")
        self.edges = []
        for u_, v_ in zip(eu, ev, strict=True):
            a_, b_ = self.fm2.native(u_, v_)
            self.edges.append((CubicSpline(t, a_), CubicSpline(t, b_)))
        self.et = t
        # separation-grid cells (pinion flank, member frame): independent of the position
        if o.separation_grid is not None:
            cu, cv = _cell_grid(b1, o.separation_grid)
            CU, CV = np.meshgrid(cu, cv, indexing="ij")
            ca, cb = self.fm1.native(CU, CV)
            self.cell_uv = (cu, cv)
            self.cP, self.cN = self.fm1.evaluate(ca, cb)
            du, dv = 1e-4 * (b1.u_tip - b1.u_fillet), 1e-4 * (b1.v_end - b1.v_start)
            pu = self.fm1.evaluate(*self.fm1.native(CU + du, CV))[0]
            pv = self.fm1.evaluate(*self.fm1.native(CU, CV + dv))[0]
            jac = np.linalg.norm(np.cross((pu - self.cP) / du, (pv - self.cP) / dv), axis=-1)
            self.cA = jac * (cu[1] - cu[0]) * (cv[1] - cv[0])
        self.Es = effective_modulus(o.E_MPa, o.nu, o.E_MPa, o.nu)

    # ------------------------------------------------------------------ cache support
    #: Constructor attributes of :meth:`state_record`: arrays and numbers kept as they are.
    _STATE_DATA = (
        "pairs", "su", "sv", "sa", "sb", "sP", "sN", "step1", "ga", "gb", "_gscale", "et",
        "edge_names", "cell_uv", "cP", "cN", "cA", "Es",
    )  # fmt: skip
    #: Attributes rebuilt by :meth:`from_state_record` from its arguments (or on first use).
    _STATE_REBUILT = ("opt", "asm", "pinion", "gear", "fm1", "fm2", "_gear_interp")

    def state_record(self) -> dict[str, object]:
        """What the constructor precomputed, as plain data (arrays, numbers, strings, tuples):
        with :meth:`from_state_record` the on-disk TCA cache (:mod:`fegear.tca.cached`) skips
        the flank-map evaluations of the constructor (0.4 s on the face gear, whose flank is an
        envelope solved point by point) without pickling objects.

        The members, options, assembly and flank maps are not in it (the caller gives them
        back); the gear-sample tree is its points (the tree is rebuilt from them, as the
        constructor builds it); each gear-edge spline is its breakpoints and coefficients.

        Raises
        ------
        TypeError
            An attribute without a record form (a new constructor attribute must be added to
            :attr:`_STATE_DATA` or rebuilt by :meth:`from_state_record`).
        """
        unknown = set(self.__dict__) - set(self._STATE_DATA) - set(self._STATE_REBUILT)
        unknown -= {"gtree", "edges"}
        if unknown:
            raise TypeError(f"TCA.state_record: no record form for {sorted(unknown)}")
        out: dict[str, object] = {
            k: self.__dict__[k] for k in self._STATE_DATA if k in self.__dict__
        }
        out["gtree"] = np.asarray(self.gtree.data)
        out["edges"] = [
            [{"x": s.x, "c": s.c, "extrapolate": bool(s.extrapolate), "axis": int(s.axis)}
             for s in edge]
            for edge in self.edges
        ]  # fmt: skip
        return out

    @classmethod
    def from_state_record(
        cls, state: dict[str, object], pinion, gear, assembly: Assembly, options: TCAOptions
    ) -> TCA:
        """A TCA from :meth:`state_record` of one built on ``pinion``, ``gear`` (same sides) and
        ``options``, placed by ``assembly``: the same object as the constructor's (flank maps
        made again by :func:`.surfaces.flank_map`, which evaluates nothing)."""
        tca = cls.__new__(cls)
        tca.opt = options
        tca.asm = assembly
        tca.pinion, tca.gear = pinion, gear
        tca.fm1, tca.fm2 = flank_map(pinion, assembly.side1), flank_map(gear, assembly.side2)
        for k in cls._STATE_DATA:
            if k in state:
                setattr(tca, k, state[k])
        tca.gtree = cKDTree(state["gtree"])
        tca.edges = [
            tuple(
                CubicSpline.construct_fast(s["c"], s["x"], s["extrapolate"], s["axis"])
                for s in edge
            )
            for edge in state["edges"]
        ]
        return tca

    @cached_property
    def _gear_interp(self) -> LinearNDInterpolator:
        """The gear's native parameters over ``(ρ, z)``, linear on the Delaunay triangulation of
        its flank samples (:func:`_sample_interpolator`: built once per process and gear flank,
        ~ms)."""
        return _sample_interpolator(np.asarray(self.gtree.data), self.ga, self.gb)

    def gear_start(self, rho: Array, z: Array) -> tuple[Array, Array]:
        """Start values of the gear's native parameters for the Newton solves on its flank
        (:func:`~fegear.tca.solve.line_hit`, :func:`~fegear.tca.solve.circle_hit`) at points of
        radius ``rho`` and height ``z`` (gear member frame, any shape): linear interpolation of
        the 21 × 21 flank samples over ``(ρ, z)``, the nearest sample outside their hull.
        Measured on the spiral bevel's contact grids (warm cycle): after the second Newton step
        of ``line_hit`` 71 % of the lines have converged instead of 13 % from the nearest
        sample, and the third evaluation of the exact flank is made only for the others (one
        process: line_hit 3.45-3.67 → 3.13-3.35 s).
        """
        rho, z = np.asarray(rho), np.asarray(z)
        rz = np.empty(np.broadcast_shapes(rho.shape, z.shape) + (2,))
        rz[..., 0], rz[..., 1] = rho, z
        ab = self._gear_interp(rz)
        out = ~np.isfinite(ab).all(axis=-1)
        if out.any():
            idx = self.gtree.query(rz[out])[1]
            ab[out] = np.stack([self.ga[idx], self.gb[idx]], -1)
        return ab[..., 0], ab[..., 1]

    # ------------------------------------------------------------------ transforms
    def _tooth_frames(self, phi1: Array, theta: Array | None = None) -> Array:
        """``(n, P, 4, 4)`` pinion tooth k frame → gear tooth j frame (gear at ``φ2n − θ``)."""
        a = self.asm
        phi2 = a.ratio * phi1 if theta is None else a.ratio * phi1 - theta
        M1 = a.placement1(phi1)[:, None]
        M2i = inverse(a.placement2(phi2))[:, None]
        Tk = tooth_transform(a.n1, self.pairs[:, 0])[None]
        Tj = inverse(tooth_transform(a.n2, self.pairs[:, 1]))[None]
        return compose(Tj, M2i, M1, Tk)

    # ------------------------------------------------------------------ angular gaps
    def _theta_pinion(
        self, T: Array, u: Array, v: Array, a: Array | None = None, b: Array | None = None
    ):
        """Angular gap at pinion flank points ``(u, v)`` (shape ``(C, m)``; ``T (C, 4, 4)``)."""
        a1, b1 = self.fm1.native(u, v)
        P, N = self.fm1.evaluate(a1, b1)
        Q = apply_points(T[:, None], P)
        rho, z = np.hypot(Q[..., 0], Q[..., 1]), Q[..., 2]
        if a is None:
            a, b = self.gear_start(rho, z)
        a2, b2, p2, _, ok = circle_hit(self.fm2, None, a, b, rho, z)
        u2, v2 = self.fm2.flank(a2, b2, p2)
        ok = ok & in_bounds(self.fm2, u2, v2) & in_bounds(self.fm1, u, v)
        th = self.asm.sense2 * wrap(
            np.arctan2(p2[..., 1], p2[..., 0]) - np.arctan2(Q[..., 1], Q[..., 0])
        )
        return np.where(ok, th, _INF), a2, b2, np.stack([u2, v2], -1)

    def _edge_native(self, e: Array, t: Array) -> tuple[Array, Array]:
        a = np.empty(t.shape)
        b = np.empty(t.shape)
        for i, (sa, sb) in enumerate(self.edges):
            m = e == i
            a[m], b[m] = sa(t[m]), sb(t[m])
        return a, b

    def _search_rz(self, T: Array) -> tuple[Array, Array]:
        """``(ρ, z)``, each ``(C, g)``: the pinion search-grid points in the gear tooth frames
        ``T (C, 4, 4)`` (the start points of :meth:`_theta_edge`; one per set of frames)."""
        Pg = apply_points(T[:, None], self.sP[None])  # (C, g, 3)
        return np.hypot(Pg[..., 0], Pg[..., 1]), Pg[..., 2]

    def _theta_edge(self, T: Array, e: Array, t: Array, rz: tuple[Array, Array] | None = None):
        """Angular gap of gear edge points (edge ``e``, parameter ``t``; shape ``(C, m)``);
        ``rz``: :meth:`_search_rz` of ``T`` when the caller has it (the edge search evaluates
        the same frames 20 times)."""
        a2, b2 = self._edge_native(e, t)
        R = self.fm2.evaluate(a2, b2)[0]
        rho, z = np.hypot(R[..., 0], R[..., 1]), R[..., 2]
        rg, zg = self._search_rz(T) if rz is None else rz
        d = (rg[:, None, :] - rho[..., None]) ** 2 + (zg[:, None, :] - z[..., None]) ** 2
        idx = np.argmin(d, axis=-1)
        a1, b1 = self.sa[idx], self.sb[idx]
        a1, b1, p, _, ok = circle_hit(self.fm1, T[:, None], a1, b1, rho, z)
        P1 = self.fm1.evaluate(a1, b1)[0]
        u1, v1 = self.fm1.flank(a1, b1, P1)
        ok = ok & in_bounds(self.fm1, u1, v1)
        th = self.asm.sense2 * wrap(
            np.arctan2(R[..., 1], R[..., 0]) - np.arctan2(p[..., 1], p[..., 0])
        )
        u2, v2 = self.fm2.flank(a2, b2, R)
        return np.where(ok, th, _INF), np.stack([u1, v1], -1), np.stack([u2, v2], -1)

    # ------------------------------------------------------------------ minimisation
    def _refine_pinion(self, T: Array, x: Array, f: Array) -> tuple[Array, Array]:
        """Box-constrained minimisation of θ over the pinion flank from ``x (C, 2)``."""
        bd = self.fm1.bounds
        lo = np.array([bd.u_fillet, bd.v_start])
        hi = np.array([bd.u_tip, bd.v_end])
        h = np.broadcast_to(self.step1, x.shape).copy()
        hmin = 1e-10 * (hi - lo)
        o = np.array([(i, j) for i in (-1, 0, 1) for j in (-1, 0, 1)], float)  # (9, 2)
        ring = np.array([0, 1, 2, 3, 5, 6, 7, 8])  # the stencil without its centre (o[4] = 0)
        # θ at a pinion point is a function of the point alone when the pinion's native
        # parameters and points and the gear's points are computed point by point (each point's
        # circle Newton stops on its own): then the gap at the centre is f, as it was found
        fm1, fm2 = self.fm1, self.fm2
        centre_known = fm1.pointwise and fm1.native_pointwise and fm2.pointwise
        act = np.arange(len(x))
        for _ in range(self.opt.refine_iter):
            act = act[np.any(h[act] > hmin, -1)]
            if act.size == 0:
                break
            xa, fa, ha, Ta = x[act], f[act], h[act], T[act]
            pts = np.clip(xa[:, None, :] + o[None] * ha[:, None, :], lo, hi)  # (c, 9, 2)
            if centre_known:
                # the centre is the current point, whose gap f is known (θ is a function of
                # the point alone): not evaluated again
                fs = np.empty(pts.shape[:2])
                fs[:, ring] = self._theta_pinion(Ta, pts[:, ring, 0], pts[:, ring, 1])[0]
                fs[:, 4] = fa
            else:
                fs = self._theta_pinion(Ta, pts[..., 0], pts[..., 1])[0]
            # least-squares quadratic model in normalised offsets, Newton step (<= 4 steps)
            s = (pts - xa[:, None, :]) / ha[:, None, :]
            D = np.stack([np.ones_like(s[..., 0]), s[..., 0], s[..., 1], s[..., 0] ** 2,
                          s[..., 0] * s[..., 1], s[..., 1] ** 2], -1)  # fmt: skip
            fin = np.isfinite(fs)
            W = fin.astype(float)
            fz = np.where(fin, fs - np.where(np.isfinite(fa), fa, 0.0)[:, None], 0.0)
            A = np.einsum("cki,ck,ckj->cij", D, W, D) + 1e-12 * np.eye(6)
            rhs = np.einsum("cki,ck,ck->ci", D, W, fz)
            c = np.linalg.solve(A, rhs[..., None])[..., 0]
            g = c[:, 1:3]
            H = np.stack([np.stack([2 * c[:, 3], c[:, 4]], -1),
                          np.stack([c[:, 4], 2 * c[:, 5]], -1)], -2)  # fmt: skip
            ev = np.linalg.eigvalsh(H)
            H = H + np.maximum(0.0, 1e-3 * np.abs(ev[:, 1:]) - ev[:, :1])[:, :, None] * np.eye(2)
            step = -np.linalg.solve(H + 1e-300 * np.eye(2), g[..., None])[..., 0]
            step = np.nan_to_num(step)
            step = step / np.maximum(1.0, np.abs(step).max(-1, keepdims=True) / 4.0)
            good = fin.sum(-1) >= 6
            xn = np.clip(xa + np.where(good[:, None], step, 0.0) * ha, lo, hi)
            fn = self._theta_pinion(Ta, xn[:, None, 0], xn[:, None, 1])[0][:, 0]
            cand = np.concatenate([fs, fn[:, None]], -1)
            cx = np.concatenate([pts, xn[:, None]], 1)
            k = np.argmin(cand, -1)
            r = np.arange(len(k))
            better = cand[r, k] < fa
            xb = np.where(better[:, None], cx[r, k], xa)
            moved = np.abs((xb - xa) / ha).max(-1)
            # keep the stencil while the minimum is travelling, shrink it once it is bracketed
            ha = ha * np.where(moved >= 0.99, 1.0, np.maximum(0.3 * moved, 0.05))[:, None]
            x[act], f[act], h[act] = xb, np.where(better, cand[r, k], fa), ha
        return x, f

    def _centre_line_contact(self, T: Array, x: Array, f: Array, tol: float = 1e-12) -> Array:
        """Line contact (θ flat along ``v`` within ``tol`` rad): report the centre of the line.

        Samples ``v`` at the refined ``u``; where several samples tie with the minimum the
        contact point is moved to the middle of the tied range (if that point ties too).
        """
        bd = self.fm1.bounds
        vs = np.linspace(bd.v_start, bd.v_end, 9)
        fs = self._theta_pinion(T, np.repeat(x[:, :1], 9, 1), np.broadcast_to(vs, (len(x), 9)))[0]
        tied = fs <= f[:, None] + tol
        n = tied.sum(-1)
        vlo = np.where(tied, vs, np.inf).min(-1)
        vhi = np.where(tied, vs, -np.inf).max(-1)
        vm = np.where(
            n >= 2, 0.5 * (np.where(n >= 2, vlo, 0.0) + np.where(n >= 2, vhi, 0.0)), x[:, 1]
        )
        fm = self._theta_pinion(T, x[:, :1], vm[:, None])[0][:, 0]
        ok = (n >= 2) & (fm <= f + tol)
        return np.where(ok[:, None], np.stack([x[:, 0], vm], -1), x)

    def _refine_edge(
        self, T: Array, e: Array, t: Array, f: Array, rz: tuple[Array, Array] | None = None
    ) -> tuple[Array, Array]:
        h = np.full(t.shape, 1.0 / (len(self.et) - 1))
        o = np.array([-1.0, -0.5, 0.5, 1.0])
        rz = self._search_rz(T) if rz is None else rz
        for _ in range(18):
            tt = np.clip(t[:, None] + o * h[:, None], 0.0, 1.0)
            fs = self._theta_edge(T, np.broadcast_to(e[:, None], tt.shape), tt, rz)[0]
            k = np.argmin(fs, -1)
            fb = fs[np.arange(len(k)), k]
            better = fb < f
            t = np.where(better, tt[np.arange(len(k)), k], t)
            f = np.where(better, fb, f)
            h = h * 0.5
        return t, f

    # ------------------------------------------------------------------ positions
    def positions(
        self, phi1: Array, with_grids: bool = True, ellipses: bool = True
    ) -> list[PositionResult]:
        """TCA at the pinion angles ``phi1 (n,)`` (rad); ``with_grids``: the separation grids
        of the pairs; ``ellipses``: the contact ellipse at the contact point (curvatures by
        finite differences of the exact flanks: ~60 % of a position's time on the face gear;
        the searches for the ends of the path and the hand-overs do without)."""
        phi1 = np.atleast_1d(np.asarray(phi1, dtype=float))
        n, P = len(phi1), len(self.pairs)
        T = self._tooth_frames(phi1).reshape(n * P, 4, 4)
        C = n * P
        # 1. pinion grid search + refinement
        th = self._theta_pinion(
            T,
            np.broadcast_to(self.su, (C, self.su.size)),
            np.broadcast_to(self.sv, (C, self.sv.size)),
        )[0]
        k = np.argmin(th, -1)
        x0 = np.stack([self.su[k], self.sv[k]], -1)
        xp, fp = self._refine_pinion(T, x0, th[np.arange(C), k])
        xp = self._centre_line_contact(T, xp, fp)
        # 2. gear edges
        ne = len(self.et)
        e_all = np.repeat(np.arange(len(self.edges)), ne)
        t_all = np.tile(self.et, len(self.edges))
        rz = self._search_rz(T)
        te = self._theta_edge(
            T,
            np.broadcast_to(e_all, (C, e_all.size)),
            np.broadcast_to(t_all, (C, t_all.size)),
            rz,
        )[0]
        ke = np.argmin(te, -1)
        ee, tb = e_all[ke], t_all[ke]
        tb, fe = self._refine_edge(T, ee, tb, te[np.arange(C), ke], rz)
        use_edge = fe < fp - 1e-13
        theta = np.minimum(fp, fe).reshape(n, P)
        # contact points of each pair
        _, _, _, uv2p = self._theta_pinion(T, xp[:, None, 0], xp[:, None, 1])
        _, uv1e, uv2e = self._theta_edge(T, ee[:, None], tb[:, None], rz)
        uv1 = np.where(use_edge[:, None], uv1e[:, 0], xp).reshape(n, P, 2)
        uv2 = np.where(use_edge[:, None], uv2e[:, 0], uv2p[:, 0]).reshape(n, P, 2)
        gear_edge = np.where(use_edge, ee, -1).reshape(n, P)
        out = []
        for i in range(n):
            out.append(
                self._position(
                    phi1[i], theta[i], uv1[i], uv2[i], gear_edge[i], with_grids, ellipses
                )
            )
        return out

    def _edges_of(self, uv1: Array, uv2: Array, gear_edge: int) -> str:
        tags = []
        for name, fm, uv in (("pinion", self.fm1, uv1), ("gear", self.fm2, uv2)):
            bd = fm.bounds
            tu, tv = (
                self.opt.edge_tol * (bd.u_tip - bd.u_fillet),
                self.opt.edge_tol * (bd.v_end - bd.v_start),
            )
            for tag, dist in (
                ("root", uv[0] - bd.u_fillet),
                ("tip", bd.u_tip - uv[0]),
                ("v_start", uv[1] - bd.v_start),
                ("v_end", bd.v_end - uv[1]),
            ):
                tol = tu if tag in ("root", "tip") else tv
                if dist <= tol:
                    tags.append(f"{name}:{tag}")
        if gear_edge >= 0 and f"gear:{self.edge_names[gear_edge]}" not in tags:
            tags.append(f"gear:{self.edge_names[gear_edge]}")
        return ",".join(tags)

    def _position(
        self, phi1, theta, uv1, uv2, gear_edge, with_grids, ellipses=True
    ) -> PositionResult:
        a = self.asm
        valid = np.isfinite(theta)
        # a closing rotation beyond half a gear pitch is not a contact of these flanks
        valid &= np.abs(np.where(valid, theta, 0.0)) < 0.5 * 2 * np.pi / a.n2
        has = bool(valid.any())
        ts = float(np.min(theta[valid])) if has else 0.0
        edges = tuple(
            self._edges_of(uv1[i], uv2[i], gear_edge[i]) if valid[i] else ""
            for i in range(len(theta))
        )
        Ph = a.placement1(phi1)
        Tk = tooth_transform(a.n1, self.pairs[:, 0])
        a1, b1 = self.fm1.native(uv1[:, 0], uv1[:, 1])
        P1, N1 = self.fm1.evaluate(a1, b1)
        M1k = compose(Ph[None], Tk)
        X = apply_points(M1k, P1)
        cp, ell = -1, None
        if has:
            cp, ell = self._contact_pair(
                phi1, ts, theta, valid, edges, uv1, uv2, X, M1k, N1, ellipses
            )
        Tc = self._tooth_frames(np.array([phi1]), np.array([ts]))[0]
        # separation at each pair's closest point (closed position)
        Q, NQ = apply_points(Tc, P1), apply_vectors(Tc, N1)
        a2, b2 = self.gear_start(np.hypot(Q[:, 0], Q[:, 1]), Q[:, 2])
        _, _, s, _, _, ok = line_hit(self.fm2, a2, b2, Q, NQ)
        back_mm = np.where(valid & ok, np.maximum(s, 0.0), 0.0)
        back_rad = np.where(valid, theta - ts, 0.0)
        if cp >= 0:
            back_mm[cp], back_rad[cp] = 0.0, 0.0
        grids = (
            self._grids(phi1, ts, valid)
            if (with_grids and has and self.opt.separation_grid)
            else ()
        )
        return PositionResult(
            phi1=float(phi1),
            phi2=float(a.ratio * phi1 - ts),
            has_contact=has,
            te_rad=-ts,
            pairs=self.pairs.copy(),
            pair_valid=valid,
            pair_te_rad=np.where(valid, -theta, 0.0),
            backlash_rad=back_rad,
            backlash_mm=back_mm,
            pinion_uv=np.where(valid[:, None], uv1, 0.0),
            gear_uv=np.where(valid[:, None], uv2, 0.0),
            points=np.where(valid[:, None], X, 0.0),
            edge=edges,
            contact_pair=cp,
            ellipse=ell,
            grids=grids,
        )

    def _contact_pair(self, phi1, ts, theta, valid, edges, uv1, uv2, X, M1k, N1, ellipses=True):
        """``(index, ellipse)`` of the pair reported in contact: the smallest closing rotation,
        and among pairs tied with it within :data:`TIE_RAD` (they touch at once) the one a rule
        picks, not round-off: interior contacts before edge contacts, then the largest Hertz
        ``p0`` with the whole load (the severe one, as the rigid TCA's Hertz reads a pair), then
        the first of ``pair_offsets``. Without ``ellipses`` (the searches of the path's ends
        and the hand-overs, which read the edge tags only) the ``p0`` step is skipped and the
        ellipse is None."""
        tied = np.flatnonzero(valid & (np.where(valid, theta, _INF) <= ts + TIE_RAD))
        pool = [int(i) for i in tied if edges[i] == ""] or [int(i) for i in tied]

        def ellipse(i: int) -> ContactEllipseAt:
            n = apply_vectors(M1k[i], N1[i])
            return self._ellipse(phi1, ts, i, uv1[i], uv2[i], X[i], n)

        if not ellipses:
            return pool[0], None
        if len(pool) == 1 or not self.opt.pinion_torque_Nm:
            # without a torque no ellipse has a Hertz p0 (all −1 below): the first of the pool,
            # whose ellipse alone is computed (the loaded cycle's TCA: 13 of its 38 on the face
            # gear were for the other pairs of a tie)
            return pool[0], ellipse(pool[0])
        ells = [ellipse(i) for i in pool]
        p0 = [e.hertz.p0_MPa if e.hertz is not None else -1.0 for e in ells]
        k = int(np.argmax(p0))  # the first of the largest
        return pool[k], ells[k]

    def _grids(self, phi1: float, ts: float, valid: Array) -> tuple[SeparationGrid, ...]:
        a = self.asm
        Tc = self._tooth_frames(np.array([phi1]), np.array([ts]))[0]
        M1 = a.placement1(phi1)
        out = []
        idx = np.nonzero(valid)[0]
        QN = [(apply_points(Tc[i], self.cP), apply_vectors(Tc[i], self.cN)) for i in idx]
        if self.fm2.pointwise and len(idx) > 1:
            # one Newton solve for the lines of all the pairs (each line iterates on its own:
            # the same numbers as a solve per pair, with a pointwise flank map)
            Q, NQ = np.stack([q for q, _ in QN]), np.stack([nq for _, nq in QN])
            a2, b2 = self.gear_start(np.hypot(Q[..., 0], Q[..., 1]), Q[..., 2])
            hit = line_hit(self.fm2, a2, b2, Q, NQ)
            hits = [tuple(x[m] for x in hit) for m in range(len(idx))]
        else:
            hits = []
            for Q, NQ in QN:
                a2, b2 = self.gear_start(np.hypot(Q[..., 0], Q[..., 1]), Q[..., 2])
                hits.append(line_hit(self.fm2, a2, b2, Q, NQ))
        for i, (_, NQ), (a2, b2, s, p2, n2, ok) in zip(idx, QN, hits, strict=True):
            u2, v2 = self.fm2.flank(a2, b2, p2)
            ok = ok & in_bounds(self.fm2, u2, v2)
            pdot = -a.sense2 * np.stack([-p2[..., 1], p2[..., 0], np.zeros_like(s)], -1)
            den = np.sum(NQ * n2, -1)
            h = -np.sum(pdot * n2, -1) / np.where(np.abs(den) > 1e-12, den, -1e-12)
            ok = ok & (h > 0)
            Mk = compose(M1, tooth_transform(a.n1, self.pairs[i, 0]))
            out.append(
                SeparationGrid(
                    k=int(self.pairs[i, 0]),
                    j=int(self.pairs[i, 1]),
                    u=self.cell_uv[0],
                    v=self.cell_uv[1],
                    points=apply_points(Mk, self.cP),
                    normals=apply_vectors(Mk, self.cN),
                    separation=np.where(ok, s, 0.0),
                    h=np.where(ok, h, 0.0),
                    area=self.cA,
                    gear_uv=np.where(ok[..., None], np.stack([u2, v2], -1), 0.0),
                    valid=ok,
                )
            )
        return tuple(out)

    def _ellipse(self, phi1, ts, cp, uv1, uv2, X, n1) -> ContactEllipseAt:
        """The ellipse at the contact point of pair ``cp`` (:mod:`.ellipse`)."""
        a = self.asm
        M1 = compose(a.placement1(phi1), tooth_transform(a.n1, self.pairs[cp, 0]))
        M2 = compose(a.placement2(a.ratio * phi1 - ts), tooth_transform(a.n2, self.pairs[cp, 1]))
        c = contact_curvature(self.fm1, self.fm2, M1, M2, uv1, uv2, n1)
        A, B, major = c.A, c.B, c.major_axis
        if c.line_contact:
            return ContactEllipseAt(
                max(A, 0.0), max(B, 0.0), major, 0.0, 0.0, None, 0.0, True, curvature=c
            )
        pe = paint_ellipse(self.opt.paint_mm, A, B)
        hz, F = None, 0.0
        if self.opt.pinion_torque_Nm:
            F = normal_force(self.opt.pinion_torque_Nm, X, n1, a.axis1())
            hz = hertz_point(F, A, B, self.Es)
        return ContactEllipseAt(A, B, major, pe.a_mm, pe.b_mm, hz, F, False, curvature=c)
