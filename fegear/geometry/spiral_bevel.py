"""Face-milled spiral bevel gears generated on a cradle (DESIGN §4).

Sources: Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed., 2004, ch. 21 "Spiral
bevel gears"; Litvin & Zhang, NASA CR-4342 (1991) "Local synthesis and tooth contact analysis of
face-milled spiral bevel gears"; Argyris, Fuentes & Litvin, CMAME 191 (2002) 1057–1095.

- Gear (member 2): straight-blade head cutter on a cradle, nominal ratio of roll (generating crown
  gear with pitch semi-angle 90° − δ_f2), both flanks with exactly the design spiral angle β and
  pressure angle α at their mean points.
- Pinion (member 1): parabolic blade (profile crowning), its own cutter radius (lengthwise
  crowning), modified roll ``φ1(ψ) = −m_c1 (ψ − C ψ²/2)`` and blank offset, all found by Litvin's
  local synthesis so that the pair has a predesigned parabolic TE of the chosen amplitude, the
  chosen path direction and contact-ellipse length (:mod:`.spiral_bevel_settings`).

Surfaces come from the shared envelope engine :func:`fegear.geometry.generation.generate`
(tool: :class:`~.spiral_bevel_settings.HeadCutter`; motion: cradle chain
:func:`~.spiral_bevel_settings.machine_motion`); its API fits the cradle kinematics directly.

Conventions
-----------
- Member frames: axis z, apex at the origin, the blank on the +z side of the apex; tooth 0 is
  centred at polar angle 0 (its flank mean points at ±half the mean tooth-thickness angle).
- Drive flank = concave gear side (outside blade) / convex pinion side (inside blade); coast =
  convex gear / concave pinion. The gear is right-hand, the pinion left-hand.
- Flank parameters: ``v = L`` the cone distance (mm), toe ``A0 − F`` → heel ``A0``; ``u`` the
  fraction of the working flank height at that L, 0 at the fillet limit (the mate's face cone
  + clearance, the lowest point that can be in contact; the fillet is not modelled) and 1 at the
  face cone. ``(L, h)`` coordinates are defined in :mod:`.spiral_bevel_settings`.
- Mesh frame (:meth:`SpiralBevelPair.mesh_placement`): apex at the origin, pinion axis +z_f,
  gear axis +x_f (Σ = 90°), common pitch generatrix in the x_f z_f plane.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, SolverError
from .generation import Envelope, generate
from .spiral_bevel_settings import (
    ARCSEC,
    MachineSettings,
    SpiralBevelBlank,
    SpiralBevelSettings,
    SynthesisReport,
    SynthesisTargets,
    head_cutter,
    machine_motion,
    mesh_transforms,
    synthesize,
)
from .surface import FlankBoundaries, FlankSurface, Side
from .transforms import apply_points, apply_vectors

__all__ = [
    "SpiralBevelBlank",
    "SynthesisTargets",
    "MachineSettings",
    "SpiralBevelSettings",
    "SynthesisReport",
    "SpiralBevelMember",
    "SpiralBevelPair",
    "FlankEvaluation",
    "NativeFlank",
    "transmission_error",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


@dataclass(frozen=True)
class FlankEvaluation:
    """Exact generated surface at flank parameters ``(u, v)``, member frame; shapes ``(...)``.

    Attributes
    ----------
    points, normals
        ``(..., 3)`` mm and unit outward normals.
    kappa, directions
        ``(..., 2)`` principal curvatures (1/mm, convex positive, descending) and
        ``(..., 2, 3)`` principal directions.
    tool_s, tool_theta, psi
        Blade parameter s (mm), cutter angle θ (rad) and cradle angle ψ (rad) generating the
        point.
    meshing_residual
        ``|n·v|/|v|`` of the equation of meshing at the point.
    """

    points: Array
    normals: Array
    kappa: Array
    directions: Array
    tool_s: Array
    tool_theta: Array
    psi: Array
    meshing_residual: Array


def _cone_coords(p: Array, gamma: float) -> tuple[Array, Array, Array, Array]:
    """``L``, ``h`` of points ``p (..., 3)`` and their gradients ``(..., 3)``."""
    rho = np.hypot(p[..., 0], p[..., 1])
    cg, sg = math.cos(gamma), math.sin(gamma)
    L = p[..., 2] * cg + rho * sg
    h = rho * cg - p[..., 2] * sg
    er = np.stack([p[..., 0] / rho, p[..., 1] / rho, np.zeros_like(rho)], -1)
    ez = np.array([0.0, 0.0, 1.0])
    return L, h, er * sg + ez * cg, er * cg - ez * sg


@dataclass(frozen=True)
class SpiralBevelMember:
    """One member (pinion or gear) of a spiral bevel pair; implements ``GeneratedMember``.

    Build it through :class:`SpiralBevelPair`. ``point_normal``/``evaluate`` solve, for each
    ``(u, v)``, the cutter parameters ``(s, θ)`` whose generated point has cone distance ``v`` and
    height ``h(u, v)`` (2-D Newton on the engine's implicit-function derivatives; the engine
    solves the equation of meshing for ψ inside).
    """

    name: str
    index: int
    n_teeth: int
    blank: SpiralBevelBlank
    drive: MachineSettings
    coast: MachineSettings
    tol_mm: float = 1e-11
    _cache: dict = field(default_factory=dict, repr=False, compare=False, hash=False)

    @property
    def tooth_angle(self) -> float:
        return 2.0 * math.pi / self.n_teeth

    @property
    def axis(self) -> Array:
        return np.array([0.0, 0.0, 1.0])

    @property
    def pitch_angle(self) -> float:
        return self.blank.pitch_angles[self.index - 1]

    def settings(self, side: Side) -> MachineSettings:
        if side not in ("drive", "coast"):
            raise InputError(f"{self.name}.side", side, "'drive' or 'coast'")
        return self.drive if side == "drive" else self.coast

    def boundaries(self) -> FlankBoundaries:
        A0 = self.blank.outer_cone_distance
        return FlankBoundaries(
            u_root=0.0,
            u_fillet=0.0,
            u_tip=1.0,
            v_start=A0 - self.blank.face_width_mm,
            v_end=A0,
            u_name="fraction of the working height: 0 fillet limit, 1 face cone",
            v_name="cone distance L (mm), toe -> heel",
        )

    def height(self, u: ArrayLike, v: ArrayLike) -> Array:
        """Height ``h`` above the pitch cone (mm) of flank parameters ``(u, v)``."""
        h_f, h_a = self.blank.flank_heights(self.index, v)
        return h_f + np.asarray(u, dtype=float) * (h_a - h_f)

    def mean_parameters(self) -> tuple[float, float]:
        """``(u, v)`` of the mean point (pitch cone, mean cone distance)."""
        rm = self.blank.mean_cone_distance
        h_f, h_a = self.blank.flank_heights(self.index, rm)
        return float(-h_f / (h_a - h_f)), rm

    # ------------------------------------------------------------------ evaluation
    def _tools(self, side: Side):
        key = side
        if key not in self._cache:
            ms = self.settings(side)
            self._cache[key] = (head_cutter(ms), machine_motion(ms))
        return self._cache[key]

    def native_flank(self, side: Side) -> NativeFlank:
        """Fast exact evaluator of the ``side`` flank in cutter parameters (built once, cached).

        See :class:`NativeFlank`; building it tabulates the meshing root on a 41 × 41 grid
        (~0.1 s).
        """
        key = ("native", side)
        nf = self._cache.get(key)
        if nf is None:
            self.settings(side)  # validates the side
            nf = self._cache[key] = NativeFlank.build(self, side)
        return nf

    def _solve(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Envelope, Array, Array]:
        tool, mot = self._tools(side)
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        L_t = v
        h_t = self.height(u, v)
        g = self.pitch_angle
        # linear predictor from the mean point (s = θ = ψ = 0 by construction)
        e0 = generate(tool, mot, 0.0, 0.0, 0.0, half_width=0.3)
        L0, h0, gL0, gh0 = _cone_coords(e0.points, g)
        J0 = np.array([[gL0 @ e0.r_u, gL0 @ e0.r_t], [gh0 @ e0.r_u, gh0 @ e0.r_t]], dtype=float)
        d = np.stack([L_t - L0, h_t - h0], -1)
        x = np.einsum("ij,...j->...i", np.linalg.inv(J0), d)
        s, th = x[..., 0], x[..., 1]
        psi = np.zeros_like(s)
        hw = 0.6
        for _ in range(40):
            env = generate(tool, mot, s, th, psi, half_width=hw)
            psi = env.psi
            L, h, gL, gh = _cone_coords(env.points, g)
            F = np.stack([L - L_t, h - h_t], -1)
            err = np.max(np.abs(F)) if F.size else 0.0
            if err < self.tol_mm:
                break
            J = np.empty(F.shape[:-1] + (2, 2))
            J[..., 0, 0] = np.sum(gL * env.r_u, -1)
            J[..., 0, 1] = np.sum(gL * env.r_t, -1)
            J[..., 1, 0] = np.sum(gh * env.r_u, -1)
            J[..., 1, 1] = np.sum(gh * env.r_t, -1)
            dx = np.linalg.solve(J, -F[..., None])[..., 0]
            s = s + dx[..., 0]
            th = th + dx[..., 1]
            hw = 0.15
        else:
            raise SolverError(
                f"spiral bevel {self.name} {side}: flank point solve did not converge "
                f"(max |ΔL|,|Δh| = {err:.2e} mm)"
            )
        return env, s, th

    def evaluate(self, side: Side, u: ArrayLike, v: ArrayLike) -> FlankEvaluation:
        """Points, normals, principal curvatures, tool parameters and residuals at ``(u, v)``."""
        env, s, th = self._solve(side, u, v)
        k, dirs = env.curvatures()
        return FlankEvaluation(
            points=env.points,
            normals=env.normals,
            kappa=k,
            directions=dirs,
            tool_s=s,
            tool_theta=th,
            psi=env.psi,
            meshing_residual=env.residual,
        )

    def point_normal(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Exact points ``(..., 3)`` mm and outward unit normals at ``(u, v)``."""
        env, _, _ = self._solve(side, u, v)
        return env.points, env.normals

    def flank(self, side: Side, nu: int = 21, nv: int = 11) -> FlankSurface:
        """Tooth-0 flank on an ``nu × nv`` grid: u fillet limit → face cone, v toe → heel."""
        if nu < 2 or nv < 2:
            raise InputError(f"{self.name}.flank.nu/nv", (nu, nv), ">= 2 each")
        b = self.boundaries()
        u = np.linspace(b.u_fillet, b.u_tip, nu)
        v = np.linspace(b.v_start, b.v_end, nv)
        ev = self.evaluate(side, u[:, None], v[None, :])
        return FlankSurface(
            member=self.name,
            side=side,
            u=u,
            v=v,
            points=ev.points,
            normals=ev.normals,
            kappa=ev.kappa,
            directions=ev.directions,
            meshing_residual=ev.meshing_residual,
            boundaries=b,
        )


@dataclass(frozen=True)
class SpiralBevelPair:
    """A designed spiral bevel pair: blank, targets, settings, synthesis reports, members.

    Use :meth:`design`; to override settings, ``dataclasses.replace`` a
    :class:`MachineSettings` of ``pair.settings`` and pass the new
    :class:`SpiralBevelSettings` to :meth:`design` (the synthesis reports then describe the
    synthesized, not the overridden, settings).
    """

    blank: SpiralBevelBlank
    targets: SynthesisTargets
    settings: SpiralBevelSettings
    reports: dict[str, SynthesisReport]
    pinion: SpiralBevelMember
    gear: SpiralBevelMember

    @classmethod
    def design(
        cls,
        blank: SpiralBevelBlank | None = None,
        targets: SynthesisTargets | None = None,
        settings: SpiralBevelSettings | None = None,
    ) -> SpiralBevelPair:
        """Synthesize the machine settings (unless given) and build both members."""
        blank = blank or SpiralBevelBlank()
        targets = targets or SynthesisTargets()
        synth, reports = synthesize(blank, targets)
        if settings is None:
            settings = synth
            if targets.symmetric_te:
                for side in ("drive", "coast"):
                    settings = _tune_third_order_roll(blank, targets, settings, reports, side)
        return cls._build(blank, targets, settings, reports)

    @classmethod
    def _build(cls, blank, targets, settings, reports) -> SpiralBevelPair:
        pinion = SpiralBevelMember(
            "pinion", 1, blank.n1, blank, settings.pinion_drive, settings.pinion_coast
        )
        gear = SpiralBevelMember(
            "gear", 2, blank.n2, blank, settings.gear_drive, settings.gear_coast
        )
        return cls(blank, targets, settings, reports, pinion, gear)

    def mesh_placement(self, side: Side):
        """``(pinion(φ1), gear(φ2))``: functions of driving-sense angles (rad) → 4×4 member → mesh.

        At ``φ1 = φ2 = 0`` the mean points of the ``side`` flanks of tooth 0 of both members
        coincide on the pitch generatrix with opposite normals (the mean contact position).
        Nominal rotation ``φ2 = (N1/N2) φ1``; the TE is ``φ2 − (N1/N2) φ1`` (DESIGN §3).
        """
        r = self.reports[side]
        pin, gear, _ = mesh_transforms(
            self.blank, side, r.gear_flank_angle, r.pinion_flank_angle, r.sigma
        )
        return pin, gear


def _contact(pair: SpiralBevelPair, side: Side, phi1: float, x: Array) -> tuple[Array, float]:
    """Contact of tooth 0 of both members at pinion angle φ1 (Gauss-Newton, FD Jacobian).

    Unknowns ``x = (u1, v1, u2, v2, φ2)``; equations ``P(φ1) r1 = G(φ2) r2`` (3) and
    ``P n1 + G n2 = 0`` (3, rank 2): Litvin & Fuentes 2004 §9.4 (TCA).
    """
    pin, gear = pair.mesh_placement(side)
    steps = np.array([1e-6, 1e-5, 1e-6, 1e-5, 1e-9])

    def F(x: Array) -> tuple[Array, Array]:
        X = x[None, :] + np.vstack([np.zeros(5), np.diag(steps)])
        p1, n1 = pair.pinion.point_normal(side, X[:, 0], X[:, 1])
        p2, n2 = pair.gear.point_normal(side, X[:, 2], X[:, 3])
        P, G = pin(phi1), gear(X[:, 4])
        r = np.concatenate(
            [
                apply_points(P, p1) - apply_points(G, p2),
                apply_vectors(P, n1) + apply_vectors(G, n2),
            ],
            -1,
        )
        return r[0], ((r[1:] - r[0]) / steps[:, None]).T

    x = np.array(x, dtype=float)
    for _ in range(30):
        r, J = F(x)
        dx = np.linalg.lstsq(J, -r, rcond=None)[0]
        # damping: keep each step inside a trust region (0.2 of the height, 3 mm, 0.05 rad)
        dx *= min(1.0, 1.0 / max(np.max(np.abs(dx) / [0.2, 3.0, 0.2, 3.0, 0.05]), 1e-300))
        x = x + dx
        if np.max(np.abs(dx[[0, 1, 2, 3]])) < 1e-10 and abs(dx[4]) < 1e-13:
            break
    return x, float(np.max(np.abs(F(x)[0])))


def transmission_error(
    pair: SpiralBevelPair, side: Side, phi1: ArrayLike, substeps: int = 2
) -> tuple[Array, Array, Array]:
    """Unloaded TE of the mean tooth pair (tooth 0 of both members), rad, DESIGN §3 sign.

    Rigid TCA by continuation from the mean contact position (φ1 = φ2 = 0); only this one tooth
    pair is considered (no edge contact, no neighbouring pairs): the full TCA is fegear.tca.

    Returns
    -------
    te : (n,)
        ``φ2 − (N1/N2) φ1`` (rad).
    params : (n, 5)
        ``(u1, v1, u2, v2, φ2)`` of the contact point.
    residual : (n,)
        Max abs residual of the contact equations (mm / unit normals).
    """
    phi1 = np.atleast_1d(np.asarray(phi1, dtype=float))
    u1, v1 = pair.pinion.mean_parameters()
    u2, v2 = pair.gear.mean_parameters()
    x0 = np.array([u1, v1, u2, v2, 0.0])
    X = np.empty((phi1.size, 5))
    res = np.empty(phi1.size)
    m21 = pair.blank.m21
    for k, target in enumerate(phi1):
        x = x0.copy()
        for a in np.linspace(0.0, target, substeps + 1)[1:]:
            x[4] = m21 * a + (x[4] - m21 * (a - target / substeps))  # keep the TE guess
            x, r = _contact(pair, side, float(a), x)
        X[k], res[k] = x, r if target != 0 else _contact(pair, side, 0.0, x0)[1]
    return X[:, 4] - m21 * phi1, X, res


def _tune_third_order_roll(blank, targets, settings, reports, side) -> SpiralBevelSettings:
    """Third-order roll D of the pinion so that TE(+π/N1) = TE(−π/N1) (secant; g is ~linear)."""
    key = f"pinion_{side}"
    base = settings.get("pinion", side)
    ends = np.array([-math.pi / blank.n1, math.pi / blank.n1])

    def g(D: float) -> float:
        st = replace(settings, **{key: replace(base, modified_roll_third=D)})
        pair = SpiralBevelPair._build(blank, targets, st, reports)
        te, _, _ = transmission_error(pair, side, ends)
        return float(te[1] - te[0])

    D0, D1 = 0.0, 0.05
    g0, g1 = g(D0), g(D1)
    for _ in range(4):
        if g1 == g0:
            break
        D0, D1, g0 = D1, D1 - g1 * (D1 - D0) / (g1 - g0), g1
        g1 = g(D1)
        if abs(g1) < 1e-3 * targets.te_amplitude_arcsec * ARCSEC:
            break
    log.info("spiral bevel %s: third-order roll D = %.5f, TE asymmetry %.2e rad", side, D1, g1)
    return replace(settings, **{key: replace(base, modified_roll_third=D1)})


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
    from .generation import Fixed, Rotation, Translation

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
class NativeFlank:
    """Exact, fast evaluation of one generated bevel flank in its cutter parameters ``(s, θ)``.

    The generated surface is ``r(s, θ) = M(ψ(s, θ)) r_t(s, θ)`` with ``ψ`` the root of the
    equation of meshing ``f = (M n_t) · (M' r_t) = 0`` (Litvin & Fuentes 2004 §6.1). Instead of
    the bracketing solve of :func:`~fegear.geometry.generation.generate` at every call, ``ψ`` is
    predicted by a bicubic spline tabulated once (by the engine) over the working flank and a
    margin of 0.75 of its span around it, then corrected by Newton on the meshing equation,

    .. math::  \\psi \\leftarrow \\psi - f / f_\\psi, \\qquad
               f_\\psi = (M' n_t)\\cdot(M' r_t) + (M n_t)\\cdot(M'' r_t),

    until ``|Δψ| < 1e-14`` rad (quadratic convergence: 2 steps from the spline's ~1e-8 rad).
    The motion is applied factor by factor to the tool vectors (elementwise rotations, no 4×4
    products), with the ψ-derivatives propagated by the product rule. The result is the exact
    envelope (the engine's root, to round-off: ~1e-13 mm, tested), NOT an interpolant; the
    spline only supplies the Newton start. Tangents follow from the implicit-function theorem:
    ``ψ_s = −f_s/f_ψ``, ``r_s = M r_{t,s} + (M' r_t) ψ_s`` (same for θ).

    Tool (head cutter, :class:`~.spiral_bevel_settings.HeadCutter`): a surface of revolution
    with blade profile ``(ρ(s), z(s))``, so ``r_t = (ρ cos θ, ρ sin θ, z)`` and
    ``n_t = ± (−z' cos θ, −z' sin θ, ρ') / √(ρ'² + z'²)`` in closed form.

    Flank coordinates (:class:`SpiralBevelMember`): ``v = L`` (cone distance), ``u`` the fraction
    of the working height ``(h − h_f(L))/(h_a(L) − h_f(L))``; ``(u, v) → (s, θ)`` by 2-D Newton
    on ``(L, h)`` with the analytic tangents from a bicubic predictor.

    Build with :meth:`SpiralBevelMember.native_flank`.
    """

    member: SpiralBevelMember
    side: Side
    tool: object
    steps: tuple[_Step, ...]
    spline: object
    inverse: tuple[object, object]
    box: tuple[Array, Array]

    # ---------------------------------------------------------------- construction
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
        span = hi - lo
        glo, ghi = lo - 0.75 * span, hi + 0.75 * span
        gs = np.linspace(glo[0], ghi[0], n_grid)
        gt = np.linspace(glo[1], ghi[1], n_grid)
        S, T = np.meshgrid(gs, gt, indexing="ij")
        # the far corners of the margin may have no root (the engine warns): expected here
        glog = logging.getLogger(generate.__module__)
        level = glog.level
        glog.setLevel(max(level, logging.ERROR))
        try:
            env = generate(tool, mot, S, T, 0.0, half_width=0.6)
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
        spl = RectBivariateSpline(gs, gt, psi, kx=3, ky=3)
        return cls(member, side, tool, _compile(mot.factors), spl, inv, (lo, hi))

    # ---------------------------------------------------------------- evaluation
    def _tool(self, s: Array, th: Array, derivs: bool) -> tuple[Array, ...]:
        """Head-cutter point, normal (into the tool) and, with ``derivs``, their s/θ-derivatives.

        Same surface as :meth:`HeadCutter.evaluate`, closed form for a surface of revolution.
        """
        t = self.tool
        sa, ca = math.sin(t.blade_angle), math.cos(t.blade_angle)
        sg = 1.0 if t.outside else -1.0
        d_r, d_z, n_r, n_z, a = sg * sa, ca, -sg * ca, sa, t.parabola
        rho = t.radius + s * d_r - a * s**2 * n_r
        z = s * d_z - a * s**2 * n_z
        rho1, z1 = d_r - 2 * a * s * n_r, d_z - 2 * a * s * n_z
        wn = np.hypot(rho1, z1)
        # n = sg (r_s × r_θ)/|·| = sg (−z' cos θ, −z' sin θ, ρ')/|(ρ', z')|   (ρ > 0)
        Nr, Nz = -sg * z1 / wn, sg * rho1 / wn
        c, si = np.cos(th), np.sin(th)
        r = np.stack([rho * c, rho * si, z], -1)
        n = np.stack([Nr * c, Nr * si, Nz], -1)
        if not derivs:
            return r, n
        rho2, z2 = -2 * a * n_r, -2 * a * n_z
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
        """Points ``(..., 3)`` and unit normals; with ``tangents`` also ``r_s``, ``r_θ``."""
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
        """Root ψ (rad) of the equation of meshing at ``(s, θ)``."""
        s, th = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(th, dtype=float))
        tl = self._tool(s.ravel(), th.ravel(), False)
        return self._solve_psi(s.ravel(), th.ravel(), *tl)[0].reshape(s.shape)

    def meshing_residual(self, s: ArrayLike, th: ArrayLike) -> Array:
        """``|n·v|/|v|`` of the equation of meshing at ``(s, θ)`` (a check of the solve)."""
        s, th = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(th, dtype=float))
        tl = self._tool(s.ravel(), th.ravel(), False)
        _, r, n, _ = self._solve_psi(s.ravel(), th.ravel(), *tl)
        res = np.abs(np.sum(n[0] * r[1], -1)) / np.linalg.norm(r[1], axis=-1)
        return res.reshape(s.shape)

    # ---------------------------------------------------------------- flank coordinates
    def flank(self, p: Array) -> tuple[Array, Array]:
        """Flank coordinates ``(u, v)`` of member-frame points ``p (..., 3)``."""
        L, h, _, _ = _cone_coords(p, self.member.pitch_angle)
        h_f, h_a = self.member.blank.flank_heights(self.member.index, L)
        return (h - h_f) / (h_a - h_f), L

    def native(self, u: ArrayLike, v: ArrayLike, tol: float = 1e-11) -> tuple[Array, Array]:
        """``(s, θ)`` of flank coordinates (2-D Newton on ``(L, h)``, analytic tangents)."""
        return self.native_evaluation(u, v, tol)[:2]

    def native_evaluation(self, u: ArrayLike, v: ArrayLike, tol: float = 1e-11):
        """:meth:`native` and :meth:`evaluate` at the result: ``(s, θ, p, n)``, the Newton's
        last evaluation, at the converged ``(s, θ)``."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        m = self.member
        L_t, h_t = v, m.height(u, v)
        s = self.inverse[0].ev(u, v)
        th = self.inverse[1].ev(u, v)
        g = m.pitch_angle
        err = np.inf
        for _ in range(30):
            p, n, rs, rt = self.evaluate(s, th, tangents=True)
            L, h, gL, gh = _cone_coords(p, g)
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
