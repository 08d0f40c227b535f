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
