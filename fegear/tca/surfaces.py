"""Exact flank evaluators for the TCA: native parameters, flank coordinates, fast closed forms.

The TCA solves many small Newton problems on the exact surfaces. It works through a
:class:`FlankMap`: an exact point/normal evaluator in *native* parameters ``(a, b)`` (those in
which the surface is cheapest to evaluate exactly) and the conversion to the member's *flank
coordinates* ``(u, v)`` (profile × face, with :class:`~fegear.geometry.surface.FlankBoundaries`).

- :class:`GenericFlankMap`: native = flank coordinates, evaluation by the member's own
  ``point_normal`` (the generation engine, exact to the engine tolerance 1e-11 mm). Any family.
- :class:`SpurInvoluteMap`: unmodified spur involute (no crowning, relief, helix): the closed-form
  involute ``P = r_b (e(λ) + ε e'(λ))``, ``λ = ψ_b − ε`` (drive flank; coast mirrored in ``y``),
  native ``(ε = tan α_y, z)``; the rack profile parameter ``u`` is affine in ``ε``
  (``√(r² − r_b²) = r sin α_t + η / sin α_t``, ``η`` the rack height; Litvin & Fuentes 2004
  ch. 10). Agrees with the generated surface to ~1e-12 mm (tested).
- :class:`HelicoidMap`: the modified involute helicoid of a cylindrical member (spur or helical,
  with flank modifications; :mod:`fegear.geometry.cylindrical`), closed form with analytic
  tangents, native = flank coordinates ``(u, z)``; it is the member's own working flank.
- :class:`SpiralBevelMap`: face-milled spiral bevel, native ``(s, θ)`` cutter parameters, ψ from
  the equation of meshing by Newton from a tabulated predictor
  (:class:`~fegear.geometry.bevel.native.NativeFlank`); analytic Jacobian; flank coordinates:
  the fraction of the working height above the fillet-limit curve, and the cone distance.
- :class:`FaceGearMap`: face gear with γ = 90°: Litvin's closed form (Litvin & Fuentes 2004
  §19.3; :func:`fegear.geometry.face_gear.closed_form_point`), native ``(t, ψ)`` = shaper roll and
  shaper angle; flank coordinates: the fraction of the working height between the fillet-limit
  curve and the tip plane, and the radius ``√(x² + y²)``.

Jacobians of the Newton solves are finite differences of these exact evaluators (the residuals
are exact, so the converged points are exact; the Jacobian only sets the convergence rate).

:func:`flank_map` names no family: the member says, in its
:meth:`~fegear.geometry.surface.GeneratedMember.flank_coordinates`, which fast exact evaluator
its surface has (if any); :data:`FAST_FLANK_MAPS` turns the name into one of the maps above. A
member without one (a new family) gets :class:`GenericFlankMap` with no edit here; a fast map for
it is an acceleration, added by registering its class under the name the member gives.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..geometry.surface import FlankBoundaries, GeneratedMember
from .flank_tables import flank_table

__all__ = [
    "FlankMap",
    "GenericFlankMap",
    "SpurInvoluteMap",
    "HelicoidMap",
    "FaceGearMap",
    "SpiralBevelMap",
    "FAST_FLANK_MAPS",
    "flank_map",
]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class FlankMap:
    """Base: native = flank coordinates, evaluation by ``member.point_normal``.

    Attributes
    ----------
    member
        A :class:`~fegear.geometry.surface.GeneratedMember`.
    side
        Flank side.
    bounds
        Working-flank limits in flank coordinates: ``u`` from ``u_fillet`` to ``u_tip``, ``v``
        from ``v_start`` to ``v_end``.
    step
        Finite-difference steps ``(da, db)`` in native parameters.
    """

    member: object
    side: str
    bounds: FlankBoundaries
    step: tuple[float, float] = (1e-6, 1e-6)
    _cache: dict = field(default_factory=dict, repr=False, compare=False, hash=False)

    def native(self, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Native parameters of flank coordinates (broadcast)."""
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        return u.copy(), v.copy()

    def evaluate(self, a: ArrayLike, b: ArrayLike) -> tuple[Array, Array]:
        """Exact points ``(..., 3)`` and outward unit normals in the member frame."""
        return self.member.point_normal(self.side, a, b)

    def native_point(self, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array, Array, Array]:
        """``(a, b, p, n)``: :meth:`native` and :meth:`evaluate` at once (a map whose inversion
        evaluates the flank anyway hands its last evaluation over)."""
        a, b = self.native(u, v)
        p, n = self.evaluate(a, b)
        return a, b, p, n

    def flank(self, a: Array, b: Array, p: Array) -> tuple[Array, Array]:
        """Flank coordinates ``(u, v)`` of native parameters (``p`` their points)."""
        return np.asarray(a, float), np.asarray(b, float)

    def native_box(self) -> tuple[Array, Array]:
        """Lower/upper native bounds of the working flank (used to clamp Newton steps; cached)."""
        box = self._cache.get("box")
        if box is None:
            box = self._cache["box"] = self._native_box()
        return box

    def _native_box(self) -> tuple[Array, Array]:
        bd = self.bounds
        a0, b0 = self.native(np.array([bd.u_fillet, bd.u_tip]), np.array([bd.v_start, bd.v_end]))
        lo = np.array([min(a0), min(b0)])
        hi = np.array([max(a0), max(b0)])
        return lo, hi

    #: :meth:`evaluate` and :meth:`flank` work point by point (closed forms): the points of one
    #: call do not change each other's result, so several sets of points may be evaluated in
    #: one call (:meth:`point_jacobian`); not so for solves that stop when all their points have
    #: converged (the engine's, :class:`GenericFlankMap`; the spiral bevel's ψ).
    pointwise: ClassVar[bool] = False
    #: :meth:`native` works point by point too (an affine map; not the face gear's inversion).
    native_pointwise: ClassVar[bool] = False

    def jacobian(self, a: Array, b: Array, p: Array) -> tuple[Array, Array]:
        """``∂p/∂a``, ``∂p/∂b`` by forward differences ``(..., 3)`` each."""
        ha, hb = self.step
        pa = self.evaluate(a + ha, b)[0]
        pb = self.evaluate(a, b + hb)[0]
        return (pa - p) / ha, (pb - p) / hb

    def point_jacobian(self, a: Array, b: Array) -> tuple[Array, Array, Array, Array]:
        """``(p, n, ∂p/∂a, ∂p/∂b)`` at ``(a, b)`` (same shape): :meth:`evaluate` and
        :meth:`jacobian` at once. A :attr:`pointwise` map with the forward differences of
        :meth:`jacobian` evaluates ``(a, b)``, ``(a + h_a, b)`` and ``(a, b + h_b)`` in one
        call (the same numbers: one call instead of three on the Newton solves' small
        batches)."""
        if self.pointwise and type(self).jacobian is FlankMap.jacobian:
            a, b = np.asarray(a, float), np.asarray(b, float)
            ha, hb = self.step
            ab = np.empty((2, 3) + np.broadcast_shapes(a.shape, b.shape))
            ab[0, 0], ab[0, 1], ab[0, 2] = a, a + ha, a
            ab[1, 0], ab[1, 1], ab[1, 2] = b, b, b + hb
            P, N = self.evaluate(ab[0], ab[1])
            p = P[0]
            return p, N[0], (P[1] - p) / ha, (P[2] - p) / hb
        p, n = self.evaluate(a, b)
        ra, rb = self.jacobian(a, b, p)
        return p, n, ra, rb


class GenericFlankMap(FlankMap):
    """Any member through its ``point_normal`` (exact, slower)."""


@dataclass(frozen=True)
class SpurInvoluteMap(FlankMap):
    """Closed-form unmodified spur involute; native ``(ε, z)`` with ``ε = tan α_y``."""

    pointwise: ClassVar[bool] = True
    native_pointwise: ClassVar[bool] = True

    def _coef(self) -> tuple[float, float, float, float]:
        c = self._cache.get("coef")
        if c is None:
            m = self.member
            d = m.design
            at = m.alpha_t
            rack = m.rack(self.side)
            # ε(u) affine: sample two heights on the straight rack flank
            h = np.array([0.0, 1.0])
            u = rack.u_of_height(h)
            eps = (m.r_p * np.sin(at) + (h + d.profile_shift * d.module_mm) / np.sin(at)) / m.r_b
            k = (eps[1] - eps[0]) / (u[1] - u[0])
            e0 = eps[0] - k * u[0]
            psi_b = (
                np.pi / (2 * d.n_teeth)
                + 2 * d.profile_shift * np.tan(np.radians(d.pressure_angle_deg)) / d.n_teeth
                + np.tan(at)
                - at
            )
            c = (float(k), float(e0), float(psi_b), float(m.r_b))
            self._cache["coef"] = c
        return c

    def native(self, u, v):
        k, e0, _, _ = self._coef()
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        return e0 + k * u, v.copy()

    def flank(self, a, b, p):
        k, e0, _, _ = self._coef()
        return (np.asarray(a, float) - e0) / k, np.asarray(b, float)

    def evaluate(self, a, b):
        _, _, psi_b, rb = self._coef()
        eps, z = np.asarray(a, float), np.asarray(b, float)
        if eps.shape != z.shape:
            eps, z = np.broadcast_arrays(eps, z)
        lam = psi_b - eps
        c, s = np.cos(lam), np.sin(lam)
        sg = 1.0 if self.side == "drive" else -1.0
        # filled in place (no stacks of the coordinate arrays)
        p = np.empty(eps.shape + (3,))
        p[..., 0] = rb * (c - eps * s)
        p[..., 1] = sg * rb * (s + eps * c)
        p[..., 2] = z
        n = np.empty(eps.shape + (3,))
        n[..., 0] = -s
        n[..., 1] = sg * c
        n[..., 2] = 0.0
        return p, n


@dataclass(frozen=True)
class HelicoidMap(FlankMap):
    """Modified involute helicoid of a cylindrical member (:mod:`fegear.geometry.cylindrical`),
    closed form, continued past the working flank (the Newton solves step over its limits);
    native = flank coordinates ``(u, z)``."""

    def evaluate(self, a, b):
        return self.member.helicoid(self.side, a, b)[:2]

    def jacobian(self, a, b, p):
        _, _, pu, pv = self.member.helicoid(self.side, a, b)
        return pu, pv

    def point_jacobian(self, a, b):
        # the closed form gives the tangents with the point: one evaluation
        return self.member.helicoid(self.side, a, b)


@dataclass(frozen=True)
class FaceGearMap(FlankMap):
    """Closed-form face gear (γ = 90°); native ``(t, ψ)`` shaper roll and shaper angle."""

    pointwise: ClassVar[bool] = True

    def _consts(self):
        c = self._cache.get("consts")
        if c is None:
            d = self.member.design
            sg = -1.0 if self.side == "drive" else 1.0
            ns, n2, m = d.n_shaper, d.n_face_gear, d.module_mm
            al = np.radians(d.pressure_angle_deg)
            c = (sg, ns, n2, 0.5 * ns * m * np.cos(al), 0.5 * ns * m, ns / n2, al)
            self._cache["consts"] = c
        return c

    def _terms(self):
        """The constant terms of :meth:`evaluate`, each computed as there (left to right):
        ``π/(2 N_s) + tan α − α``, ``−σ r_b``, ``σ π / N_2``."""
        k = self._cache.get("terms")
        if k is None:
            sg, ns, n2, rb, rps, q, al = self._consts()
            k = (np.pi / (2 * ns) + np.tan(al) - al, -sg * rb, sg * np.pi / n2)
            self._cache["terms"] = k
        return k

    def _roll(self, t: Array) -> tuple[Array, Array, Array, Array]:
        """The shaper involute at roll ``t``: point ``(x_s, y_s)`` and normal."""
        sg, _, _, rb, _, _, _ = self._consts()
        be = self._terms()[0] - t
        cb, sb = np.cos(be), np.sin(be)
        return rb * (cb - t * sb), sg * rb * (sb + t * cb), sb, -sg * cb

    def _turn(self, psi: Array) -> tuple[Array, Array, Array, Array]:
        """``cos``, ``sin`` of the shaper angle ``ψ`` and of the face gear's ``q ψ + σ π / N_2``."""
        q = self._consts()[5]
        c = q * psi + self._terms()[2]
        return np.cos(psi), np.sin(psi), np.cos(c), np.sin(c)

    def _point(self, roll, turn) -> tuple[Array, Array]:
        """The face gear point and normal of the shaper point ``roll`` turned by ``turn``: the
        shaper point turned by ψ about the shaper axis, ``X = u_s`` from the meshing condition,
        then the face gear's turn (filled in place, no stacks of the coordinate arrays)."""
        _, _, _, _, rps, q, _ = self._consts()
        xs, ys, nxs, nys = roll
        cp, sp, cc, sc = turn
        yr = xs * sp + ys * cp
        xr = xs * cp - ys * sp
        ny = nxs * sp + nys * cp
        nx = nxs * cp - nys * sp
        X = self._terms()[1] / (q * ny)
        p = np.empty(np.shape(X) + (3,))
        p[..., 0] = X * cc + yr * sc
        p[..., 1] = -X * sc + yr * cc
        p[..., 2] = rps - xr
        n = np.empty(p.shape)
        n[..., 0] = ny * sc
        n[..., 1] = ny * cc
        n[..., 2] = -nx
        return p, n

    def evaluate(self, a, b):
        t, psi = np.asarray(a, float), np.asarray(b, float)
        if t.shape != psi.shape:
            t, psi = np.broadcast_arrays(t, psi)
        return self._point(self._roll(t), self._turn(psi))

    def point_jacobian(self, a, b):
        # the forward differences' points (t + h_t, ψ) and (t, ψ + h_ψ) share the roll or the
        # turn of (t, ψ): 2 of each instead of 3 (the same numbers as 3 evaluations)
        t, psi = np.asarray(a, float), np.asarray(b, float)
        if t.shape != psi.shape:
            t, psi = np.broadcast_arrays(t, psi)
        ht, hp = self.step
        tt, pp = np.empty((2,) + t.shape), np.empty((2,) + t.shape)
        tt[0], tt[1] = t, t + ht
        pp[0], pp[1] = psi, psi + hp
        sel_t, sel_p = [0, 1, 0], [0, 0, 1]
        roll = tuple(x[sel_t] for x in self._roll(tt))
        turn = tuple(x[sel_p] for x in self._turn(pp))
        P, N = self._point(roll, turn)
        p = P[0]
        return p, N[0], (P[1] - p) / ht, (P[2] - p) / hp

    def flank(self, a, b, p):
        rho = np.hypot(p[..., 0], p[..., 1])
        return self.member.working_u(p[..., 2], rho, self.side), rho

    def native(self, u, v):
        m = self.member
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        env, t, _ = m._solve(self.side, m.height(u, v, self.side), v)
        return np.asarray(t, float), np.asarray(env.psi, float)

    def _native_box(self):
        # the working surface is curved in (t, ψ) too: sample its whole boundary
        bd = self.bounds
        s = np.linspace(0.0, 1.0, 9)
        U = np.concatenate([np.full(9, bd.u_fillet), np.full(9, bd.u_tip), s, s])
        V = np.concatenate([s, s, np.zeros(9), np.ones(9)]) * (bd.v_end - bd.v_start)
        a, b = self.native(U, bd.v_start + V)
        return np.array([a.min(), b.min()]), np.array([a.max(), b.max()])


@dataclass(frozen=True)
class SpiralBevelMap(FlankMap):
    """Face-milled spiral bevel member; native ``(s, θ)`` = blade parameter and cutter angle.

    Evaluation by :class:`~fegear.geometry.bevel.tabulated.TabulatedFlank`: the exact envelope
    (:class:`~fegear.geometry.bevel.native.NativeFlank`, ψ from the equation of meshing by
    Newton) tabulated once on a quintic spline, within ``TABLE_TOL_MM`` = 1e-11 mm of it (its
    error measured when built, tested), exact outside the table. The Jacobian is the spline's
    derivative, not a finite difference. Flank coordinates ``(u, v)``: the fraction of the working
    height between this side's fillet-limit curve (where the blade meets its edge radius) and the
    face cone, and the cone distance ``L`` (mm); a point below the fillet limit has ``u < 0`` and is
    outside the working surface (the fillet itself is not a contact surface of the TCA).
    """

    #: the tabulated flank's evaluation is point by point (an interpolant)
    pointwise: ClassVar[bool] = True

    def _nf(self):
        nf = self._cache.get("nf")
        if nf is None:
            nf = self._cache["nf"] = flank_table(self.member, self.side)
        return nf

    def evaluate(self, a, b):
        return self._nf().evaluate(a, b)[:2]

    def jacobian(self, a, b, p):
        _, _, rs, rt = self._nf().evaluate(a, b, tangents=True)
        return rs, rt

    def point_jacobian(self, a, b):
        # the tangents come with the point (the splines' derivatives): one evaluation
        return self._nf().evaluate(a, b, tangents=True)

    def flank(self, a, b, p):
        return self._nf().flank(p)

    def native(self, u, v):
        return self._nf().native(u, v)

    def native_point(self, u, v):
        # the (u, v) -> (s, θ) Newton ends on an evaluation at the converged (s, θ): 1 of the
        # ~4 evaluations of a grid point saved
        return self._nf().native_evaluation(u, v)

    def _native_box(self):
        lo, hi = self._nf().box
        return lo.copy(), hi.copy()


FAST_FLANK_MAPS: dict[str, tuple[type[FlankMap], tuple[float, float]]] = {
    "spur_involute": (SpurInvoluteMap, (1e-7, 1e-5)),
    # 50 steps (the ellipse's curvatures) = 1e-3 mm
    "involute_helicoid": (HelicoidMap, (2e-5, 2e-5)),
    "face_gear_orthogonal": (FaceGearMap, (1e-7, 1e-8)),
    # steps of the finite-difference curvatures (ellipse): 50 steps = 0.01 mm, 1e-3 rad
    "spiral_bevel_native": (SpiralBevelMap, (2e-4, 2e-5)),
}
"""Fast exact flank maps by the name a member's ``flank_coordinates(side).fast_evaluator``
gives: the map class and its finite-difference steps in its native parameters."""


def flank_map(member: GeneratedMember, side: str, generic: bool = False) -> FlankMap:
    """The fastest exact :class:`FlankMap` for ``member``/``side`` (``generic`` forces the engine).

    Working-flank bounds (``member.flank_coordinates(side).bounds``): ``u`` from the fillet
    limit to the tip, ``v`` over the face. The fast map is the one :data:`FAST_FLANK_MAPS`
    registers under the member's ``fast_evaluator``; otherwise, or with ``generic``,
    :class:`GenericFlankMap` with the member's steps. A member with measured flanks
    (:class:`fegear.tca.deviation.MeasuredMember`) gives its own map (``measured_flank_map``:
    this map of its generated member, deviated by the topography).
    """
    measured = getattr(member, "measured_flank_map", None)
    if measured is not None:
        return measured(side, generic)
    fc = member.flank_coordinates(side)
    fast = None if generic or fc.fast_evaluator is None else FAST_FLANK_MAPS.get(fc.fast_evaluator)
    if fast is not None:
        cls, step = fast
        return cls(member, side, fc.bounds, step)
    return GenericFlankMap(member, side, fc.bounds, fc.step)
