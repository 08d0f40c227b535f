"""Face-milled spiral bevel gears generated on a cradle (``docs/reference_pairs.md``).

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
  fraction of the working flank height at that L, 0 on the fillet limit ``h_fl(L)`` (where the
  blade meets its edge radius: a curve over the face, :meth:`SpiralBevelMember.fillet_height`)
  and 1 on the face cone; ``u ∈ [−1, 0)`` is the generated fillet (the envelope of the blade's
  edge radius, a torus of the cutter), ``−1`` where it touches the root cone. ``(L, h)``
  coordinates are defined in :mod:`.spiral_bevel_settings`.

Cutter tip, fillet limit and fillet (Litvin & Fuentes 2004 §21.2; Litvin & Zhang 1991;
Argyris, Fuentes & Litvin 2002 §2)
-------------------------------------------------------------------------------------------
The blade of each flank's head cutter ends in an edge radius ``ρ_f``
(:class:`~.spiral_bevel_settings.EdgeRadius`, :func:`~.spiral_bevel_settings.blade_tip`):
an arc tangent to the blade at ``s = s_b`` and to the cutter's point plane, the plane normal to
the cutter axis that touches the blank's root cone (:func:`~.spiral_bevel_settings.point_plane`;
under the cradle motion it turns in itself and, with the blank's roll, sweeps exactly the root
cone). The blade and the arc share the circle ``s = s_b`` of the tool and its normal, so their
envelopes under the same generating motion ``M(ψ)`` share the curve it generates: the *fillet
limit*, the points of the blade envelope with ``s = s_b``. At cone distance ``L`` it is found by
Newton on the cutter angle ``θ`` (``∂L/∂θ = ∇L · r_θ`` with the engine's implicit-function
tangent ``r_θ``); its height ``h_fl(L)`` is tabulated once per flank as a cubic spline (nodes
0.5 mm apart, 1e-10 mm from the exact curve, tested). Below it the flank is the envelope of the
torus: at fillet coordinate ``u`` the arc angle is ``ϑ = (1 + u) ϑ_b`` (``ϑ = 0`` on the point
plane, ``ϑ_b`` at the blade) and ``θ`` solves ``L(θ) = L`` the same way; ``ϑ = 0`` generates
the root cone (the point plane's own envelope), tangentially.
- Mesh frame (:meth:`SpiralBevelPair.mesh_placement`): apex at the origin, pinion axis +z_f,
  gear axis +x_f (Σ = 90°), common pitch generatrix in the x_f z_f plane.
"""

from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass, field, fields, replace
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from ..errors import DesignError, InputError, SolverError
from .generation import Envelope, Fixed, Rotation, Translation, generate
from .spiral_bevel_settings import (
    ARCSEC,
    EdgeRadius,
    MachineSettings,
    SpiralBevelBlank,
    SpiralBevelSettings,
    SynthesisReport,
    SynthesisTargets,
    blade_tip,
    head_cutter,
    machine_motion,
    mesh_transforms,
    point_plane,
    synthesize,
)
from .surface import BlankOutline, ConeLine, FlankBoundaries, FlankCoordinates, FlankSurface, Side
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
    "FilletLimit",
    "NativeFlank",
    "NativeFillet",
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
        Blade parameter s (mm; on the fillet, ``u < 0``: the edge-radius angle ϑ, rad), cutter
        angle θ (rad) and cradle angle ψ (rad) generating the point.
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
class FilletLimit:
    """The fillet limit of one flank at cone distances ``L``; arrays ``(...)``/``(..., 3)``.

    Attributes
    ----------
    theta, psi
        Cutter angle and cradle angle (rad) generating the point from the blade's end ``s_b``.
    points, normals
        Member frame (mm) and outward unit normals of the blade envelope.
    height
        ``h`` above the pitch cone (mm).
    """

    theta: Array
    psi: Array
    points: Array
    normals: Array
    height: Array


@dataclass(frozen=True)
class SpiralBevelMember:
    """One member (pinion or gear) of a spiral bevel pair; implements ``GeneratedMember``.

    Build it through :class:`SpiralBevelPair`. ``point_normal``/``evaluate`` solve, for each
    working ``(u >= 0, v)``, the blade parameters ``(s, θ)`` whose generated point has cone
    distance ``v`` and height ``h(u, v)`` (2-D Newton on the engine's implicit-function
    derivatives; the engine solves the equation of meshing for ψ inside); for ``u < 0`` the
    edge-radius angle ``ϑ = (1 + u) ϑ_b`` and the θ giving cone distance ``v`` (the fillet).
    """

    name: str
    index: int
    n_teeth: int
    blank: SpiralBevelBlank
    drive: MachineSettings
    coast: MachineSettings
    tol_mm: float = 1e-11
    _cache: dict = field(default_factory=dict, repr=False, compare=False, hash=False)
    family: ClassVar[str] = "spiral_bevel"

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

    def boundaries(self, side: Side = "drive") -> FlankBoundaries:
        """Flank coordinates: ``v`` the cone distance ``L`` (mm), toe → heel; ``u`` the fraction
        of the working height at that L, 0 on the fillet limit ``h_fl(L)`` (a curve over the
        face, :meth:`fillet_height`), 1 on the face cone; ``u ∈ [−1, 0)`` the generated fillet
        (−1 on the root cone). The working surface is exactly ``[0, 1] × [toe, heel]`` for every
        consumer; ``height`` gives the curves back in mm for ``side`` (the limits are the same
        numbers for both sides, the curves they stand for are each side's own)."""
        A0 = self.blank.outer_cone_distance
        return FlankBoundaries(
            u_root=-1.0,
            u_fillet=0.0,
            u_tip=1.0,
            v_start=A0 - self.blank.face_width_mm,
            v_end=A0,
            u_name="fraction of the working height: 0 fillet limit, 1 face cone (-1 root cone)",
            v_name="cone distance L (mm), toe -> heel",
            height=functools.partial(self.height, side=self.settings(side).side),
            height_name="height h above the pitch cone (mm)",
        )

    # ------------------------------------------------------------------ cutter tip and limits
    def edge_tool(self, side: Side) -> EdgeRadius:
        """The edge radius of the ``side`` blade, placed on the point plane that cuts this
        member's root cone (:func:`~.spiral_bevel_settings.blade_tip`, cached)."""
        key = ("edge", side)
        if key not in self._cache:
            ms = self.settings(side)
            cutter = self._tools(side)[0]
            zp = point_plane(self.blank, self.index, ms)
            self._cache[key] = blade_tip(cutter, ms.edge_radius_mm, zp)
        return self._cache[key]

    def _theta_solve(
        self, side: Side, tool, w: Array, L: Array, theta0: Array, psi0: Array,
        tol: float = 1e-12,
    ) -> tuple[Envelope, Array]:  # fmt: skip
        """Envelope of ``tool`` at profile parameter ``w`` and the cutter angle θ whose
        generated point has cone distance ``L``: Newton on θ with ``∂L/∂θ = ∇L · r_θ`` (the
        engine's implicit-function tangent), ψ continued from ``psi0``; stops at ``tol`` mm."""
        mot = self._tools(side)[1]
        g = self.pitch_angle
        w, L, th, psi = (np.array(a, dtype=float) for a in np.broadcast_arrays(w, L, theta0, psi0))
        hw, err = 0.6, np.inf
        for _ in range(40):
            env = generate(tool, mot, w, th, psi, half_width=hw)
            Lp, _, gL, _ = _cone_coords(env.points, g)
            F = Lp - L
            err = float(np.max(np.abs(F))) if F.size else 0.0
            if err < tol:
                return env, th
            th = th - np.clip(F / np.sum(gL * env.r_t, -1), -0.05, 0.05)
            psi, hw = env.psi, 0.15
        raise SolverError(
            f"spiral bevel {self.name} {side}: cone distance not reached on the cutter's "
            f"{type(tool).__name__} (max |dL| = {err:.2e} mm)"
        )

    def _theta_predictor(self, side: Side, s: Array, L: Array) -> Array:
        """Linear predictor of θ at blade parameter ``s`` and cone distance ``L`` from the mean
        point (``s = θ = ψ = 0``)."""
        tool, mot = self._tools(side)
        e0 = generate(tool, mot, 0.0, 0.0, 0.0, half_width=0.3)
        L0, _, gL0, _ = _cone_coords(e0.points, self.pitch_angle)
        return (np.asarray(L, float) - L0 - (gL0 @ e0.r_u) * np.asarray(s, float)) / (gL0 @ e0.r_t)

    def fillet_limit(self, side: Side, L: ArrayLike, tol: float = 1e-12) -> FilletLimit:
        """The exact fillet limit at cone distances ``L`` (mm): the point of the blade
        envelope generated by the blade's end ``s = s_b`` (where the edge radius begins), by
        Newton on the cutter angle (:meth:`_theta_solve`, ``tol`` mm)."""
        L = np.asarray(L, float)
        sb = np.full(L.shape, self.edge_tool(side).s_blade)
        th0 = self._theta_predictor(side, sb, L)
        env, th = self._theta_solve(side, self._tools(side)[0], sb, L, th0, np.zeros(L.shape), tol)
        h = _cone_coords(env.points, self.pitch_angle)[1]
        return FilletLimit(th, env.psi, env.points, env.normals, h)

    def _limit_table(self, side: Side) -> tuple[CubicSpline, CubicSpline, CubicSpline]:
        """Cubic splines over the cone distance of the fillet-limit height ``h_fl(L)``, its
        cutter angle ``θ_fl(L)`` and generating angle ``ψ_fl(L)``: 0.5 mm apart from 0.4 F
        inside the toe to 0.2 F past the heel (the sector loft reaches 0.04 F past both ends).
        The curve is smooth and nearly straight: the spline is within ~1e-10 mm of the exact
        limit (tested)."""
        key = ("limit", side)
        if key not in self._cache:
            A0, F = self.blank.outer_cone_distance, self.blank.face_width_mm
            n = int(math.ceil(1.6 * F / 0.5)) + 1
            L = np.linspace(A0 - 1.4 * F, A0 + 0.2 * F, n)
            lim = self.fillet_limit(side, L)
            self._cache[key] = (
                CubicSpline(L, lim.height),
                CubicSpline(L, lim.theta),
                CubicSpline(L, lim.psi),
            )
        return self._cache[key]

    def fillet_height(self, L: ArrayLike, side: Side = "drive") -> Array:
        """Height ``h_fl`` (mm, above the pitch cone) of the fillet limit at cone distances
        ``L``: the lower limit of the working surface, a curve over the face."""
        return self._limit_table(side)[0](np.asarray(L, float))

    def height(self, u: ArrayLike, v: ArrayLike, side: Side = "drive") -> Array:
        """Height ``h`` above the pitch cone (mm) of flank coordinates ``(u, v)``:
        ``h_fl + u (h_a − h_fl)`` on the working surface, the generated fillet's below."""
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        h_fl = self.fillet_height(v, side)
        h_a = self.blank.flank_heights(self.index, v)[1]
        h = h_fl + np.maximum(u, 0.0) * (h_a - h_fl)
        f = u < 0
        if np.any(f):
            h = np.array(h, dtype=float)
            p = self.native_fillet(side).evaluate(*self.native_fillet(side).native(u[f], v[f]))[0]
            h[f] = _cone_coords(p, self.pitch_angle)[1]
        return h

    def working_u(self, h: ArrayLike, L: ArrayLike, side: Side = "drive") -> Array:
        """Flank coordinate ``u`` of the working-surface point at height ``h`` and cone distance
        ``L``: ``(h − h_fl(L)) / (h_a(L) − h_fl(L))``."""
        L = np.asarray(L, float)
        h_fl = self.fillet_height(L, side)
        h_a = self.blank.flank_heights(self.index, L)[1]
        return (np.asarray(h, float) - h_fl) / (h_a - h_fl)

    def mean_parameters(self, side: Side = "drive") -> tuple[float, float]:
        """``(u, v)`` of the mean point of the ``side`` flank (pitch cone, mean cone distance)."""
        rm = self.blank.mean_cone_distance
        return float(self.working_u(0.0, rm, side)), rm

    def _fillet_solve(self, side: Side, u: Array, L: Array) -> tuple[Envelope, Array, Array]:
        """Exact fillet points (engine) at fillet coordinates ``u ∈ [−1, 0]``, cone distances
        ``L``: the envelope of the edge radius at ``ϑ = (1 + u) ϑ_b`` (:meth:`_theta_solve`,
        from the fillet limit's θ and ψ). Returns the envelope, ``ϑ`` and ``θ``."""
        tool = self.edge_tool(side)
        u, L = np.broadcast_arrays(np.asarray(u, float), np.asarray(L, float))
        w = (1.0 + u) * tool.theta_blade
        _, s_th, s_psi = self._limit_table(side)
        env, th = self._theta_solve(side, tool, w, L, s_th(L), s_psi(L))
        return env, w, th

    def root_land(self, n_L: int = 9) -> tuple[Array, Array]:
        """``(L, land)``: ``n_L`` cone distances toe → heel (mm) and the root land there (mm):
        the arc of the root circle between the bottoms (``u = −1``, on the root cone) of the two
        fillets of a tooth space (the ``+θ`` flank of a tooth and the ``−θ`` flank of the next).
        Negative where the fillets overlap. Cached."""
        key = ("root_land", n_L)
        if key not in self._cache:
            A0, F = self.blank.outer_cone_distance, self.blank.face_width_mm
            L = np.linspace(A0 - F, A0, n_L)
            phi = {}
            for side in ("drive", "coast"):
                p = self._fillet_solve(side, -np.ones_like(L), L)[0].points  # engine: 9 points
                phi[side] = np.arctan2(p[:, 1], p[:, 0])
            plus, minus = ("drive", "coast")
            if phi["drive"][0] < phi["coast"][0]:
                plus, minus = minus, plus
            g = self.pitch_angle
            rho_root = L * math.sin(g) + self.blank.root_height(self.index, L) * math.cos(g)
            self._cache[key] = (L, (phi[minus] + self.tooth_angle - phi[plus]) * rho_root)
        return self._cache[key]

    def check_fillets(self) -> None:
        """Refuse an edge radius the blades cannot carry.

        (1) The fillet limit must lie below the mean contact point (``h_fl(R_m) < 0``; else the
        designed contact is on the fillet). (2) The fillets of the two flanks of a tooth space
        must not overlap: the :meth:`root_land` must stay positive from toe to heel. Each edge
        radius takes about ``ρ_f (1 − sin α)/cos α`` of the root (normal section) from its
        blade's sharp corner; with a larger radius than the point width of the space carries,
        the second fillet would cut into the first and neither would be the envelope modelled.

        Raises :class:`~fegear.errors.DesignError` naming ``spiral_bevel.edge_radius_mm``.
        """
        rf = {s: self.settings(s).edge_radius_mm for s in ("drive", "coast")}
        rho_f = max(rf.values())
        for side in ("drive", "coast"):
            h0 = float(self.fillet_height(self.blank.mean_cone_distance, side))
            if h0 >= 0.0:
                raise DesignError(
                    "spiral_bevel.edge_radius_mm", rf[side], "an edge radius below the pitch cone",
                    f"{self.name} {side}: the fillet limit is {h0:.3f} mm above the mean point",
                )  # fmt: skip
        L, land = self.root_land()
        k = int(np.argmin(land))
        if land[k] <= 0.0:
            # about: the land shrinks by Σ ρ_f (1 − sin α)/cos α (normal section) / cos β
            al = [math.radians(self.settings(s).blade_angle_deg) for s in rf]
            take = sum((1 - math.sin(a)) / math.cos(a) for a in al)
            cb = math.cos(math.radians(self.blank.spiral_angle_deg))
            est = rho_f + land[k] * cb / take
            raise DesignError(
                "spiral_bevel.edge_radius_mm", rho_f, "an edge radius whose fillets fit in a "
                "tooth space (what the blade points can carry)",
                f"{self.name}: the fillets of a tooth space overlap by {-land[k]:.3f} mm at "
                f"L = {L[k]:.2f} mm; about {max(est, 0.0):.2f} mm fits",
            )  # fmt: skip

    def tooth_limits(self, n_L: int = 9, n_u: int = 7) -> tuple[Array, Array, Array]:
        """``(L, top_land, singular)``: ``n_L`` cone distances toe → heel (mm), the top land
        there (mm: the arc of the tip between the drive and the coast flank of one tooth,
        negative where the flanks cross below the tip: a pointed tooth), and per side the
        smallest ``|singularity|`` over the working surface relative to its largest, with the
        sign it has where it changes sign (a zero crossing of the engine's singularity function
        ``f_ψ − c_a f_u − c_b f_t``, :class:`~fegear.geometry.generation.Envelope`, is a
        singular line of the generated surface: undercut, Litvin & Fuentes 2004 §6.3). Sampled
        on ``n_u × n_L`` working-surface points per side; the tooth's sign is that of its
        thickness at the fillet limit. Cached."""
        key = ("tooth_limits", n_L, n_u)
        if key not in self._cache:
            A0, F = self.blank.outer_cone_distance, self.blank.face_width_mm
            L = np.linspace(A0 - F, A0, n_L)
            U, V = np.meshgrid(np.linspace(0.0, 1.0, n_u), L, indexing="ij")
            ang, sing = {}, []
            for side in ("drive", "coast"):
                env = self._solve(side, U, V)[0]
                ang[side] = np.arctan2(env.points[..., 1], env.points[..., 0])
                f = env.singularity
                crosses = bool(np.any(f > 0) and np.any(f < 0))
                sing.append(-1.0 if crosses else float(np.abs(f).min() / np.abs(f).max()))
            rho = np.hypot(env.points[-1, :, 0], env.points[-1, :, 1])
            w = np.angle(np.exp(1j * (ang["drive"] - ang["coast"])))
            land = np.sign(w[0]) * w[-1] * rho
            self._cache[key] = (L, land, np.array(sing))
        return self._cache[key]

    def check_tooth(self) -> None:
        """Refuse a pointed or undercut tooth (:meth:`tooth_limits`), naming the field.

        Pointed: the top land vanishes somewhere from toe to heel. If it is positive at the heel
        and vanishes toward the toe, a narrower face keeps it (``face_width_mm <= A0 − L0``,
        ``L0`` where the land crosses zero, linear between the samples); else the member needs
        more teeth (thicker teeth at the same depth). Undercut: a singular line crosses the
        working surface; the member needs more teeth.

        Raises :class:`~fegear.errors.DesignError` naming ``spiral_bevel.face_width_mm``, or
        the member's tooth count (``spiral_bevel.n1`` / ``n2``).
        """
        L, land, sing = self.tooth_limits()
        teeth = f"spiral_bevel.n{self.index}"
        if np.any(land <= 0.0):
            k = int(np.argmin(land))
            where = (
                f"the {self.name}'s top land vanishes (pointed tooth): {land[k]:.3f} mm at "
                f"cone distance {L[k]:.2f} mm (toe {L[0]:.2f}, heel {L[-1]:.2f} mm)"
            )
            if land[-1] > 0.0:
                j = int(np.flatnonzero(land <= 0.0).max())
                L0 = L[j] + (L[j + 1] - L[j]) * (0.0 - land[j]) / (land[j + 1] - land[j])
                raise DesignError(
                    "spiral_bevel.face_width_mm", self.blank.face_width_mm,
                    f"<= {self.blank.outer_cone_distance - L0:.2f} mm", where,
                )  # fmt: skip
            raise DesignError(teeth, self.n_teeth, "more teeth (a thicker tooth)", where)
        if np.any(sing < 0.0):
            raise DesignError(
                teeth, self.n_teeth, "more teeth (a tooth without undercut)",
                f"the {self.name}'s generated flank has singular points on its working surface "
                "(undercut)",
            )  # fmt: skip

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

    def native_fillet(self, side: Side) -> NativeFillet:
        """Fast exact evaluator of the ``side`` fillet in the edge-radius parameters ``(ϑ, θ)``
        (built once, cached; :class:`NativeFillet`)."""
        key = ("native_fillet", side)
        nf = self._cache.get(key)
        if nf is None:
            self.settings(side)  # validates the side
            nf = self._cache[key] = NativeFillet.build(self, side)
        return nf

    def flank_points(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Exact points and normals at flank coordinates ``(u, v)`` through the fast native
        evaluators (:meth:`native_flank` for ``u >= 0``, :meth:`native_fillet` below): the same
        surfaces as :meth:`point_normal` to ~1e-12 mm, ~100× faster."""
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        f = u < 0
        p, n = np.empty(u.shape + (3,)), np.empty(u.shape + (3,))
        for mask, nf in ((~f, self.native_flank), (f, self.native_fillet)):
            if mask.any():
                e = nf(side)
                p[mask], n[mask] = e.evaluate(*e.native(u[mask], v[mask]))
        return p, n

    def flank_coordinates(self, side: Side) -> FlankCoordinates:
        """Working flank of ``side`` (:meth:`boundaries`); fast evaluator
        ``"spiral_bevel_native"``: :meth:`native_flank`."""
        return FlankCoordinates(self.boundaries(side), (1e-6, 1e-5), "spiral_bevel_native")

    def blank_outline(self, rim_modules: float = 3.0) -> BlankOutline:
        """Cone coordinates ``(L, h)``: cone distance and height above the pitch cone; root and
        face cones of the blank (Gleason taper), a rim of ``rim_modules · m`` below the root cone
        (its bottom cone is the ``bore``); the face toe → heel, 9 sections; the plus side from
        the polar angles of the two sides' mean points."""
        bl = self.blank
        i = self.index
        m = bl.module_mm
        gam = self.pitch_angle
        A0 = bl.outer_cone_distance
        F = bl.face_width_mm
        ded = bl.dedenda[i - 1]
        td = math.tan(bl.dedendum_angles[i - 1])
        tj = math.tan(bl.dedendum_angles[1 if i == 1 else 0])
        root = ConeLine(-ded + A0 * td, -td)
        tip = ConeLine(bl.addenda[i - 1] - A0 * tj, tj)
        bot = ConeLine(root.a - rim_modules * m, root.b)
        # plus side: the side whose mean point has the larger polar angle (one exact envelope
        # point per side, 15 ms; building a side's native evaluator for it took 0.8 s, for the
        # unloaded side on every warm run)
        ang = {}
        for s in ("drive", "coast"):
            um, vm = self.mean_parameters(s)
            p = self.point_normal(s, np.array([um]), np.array([vm]))[0][0]
            ang[s] = math.atan2(p[1], p[0])
        plus: Side = "drive" if ang["drive"] > ang["coast"] else "coast"
        bd = self.boundaries()
        sg, cg = math.sin(gam), math.cos(gam)
        # root + fillet of a space half (~1.5 mm) through 13 exact points: fillet nodes within
        # 2e-5 of the element size (25 points: 3e-6, but OCC's intersection of the lofted
        # sector with its envelope took 1.8x as long: 6.9 s instead of 3.8 s, 5-tooth pinion)
        return BlankOutline(
            module=m, meridian=np.array([[sg, cg], [cg, -sg]]), tip=tip, root=root, bottom=bot,
            L_start=A0 - F, L_end=A0, L_range=(A0 - F - 0.04 * F, A0 + 0.04 * F), n_sections=9,
            u_root=bd.u_root, u_fillet=bd.u_fillet, u_tip=bd.u_tip, plus_side=plus,
            bottom_name="bore", has_fillet=True, n_fillet=13,
        )  # fmt: skip

    def _solve(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Envelope, Array, Array]:
        """Blade envelope at working flank coordinates ``(u >= 0, v)``: 2-D Newton on the
        cutter parameters ``(s, θ)`` for the target ``(L, h)``."""
        tool, mot = self._tools(side)
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        L_t = v
        h_t = self.height(u, v, side)
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
        """Points, normals, principal curvatures, tool parameters and residuals at ``(u, v)``
        (the blade envelope for ``u >= 0``, the edge-radius envelope, the fillet, below)."""
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        f = u < 0
        parts = []
        if (~f).any():
            parts.append((~f, *self._solve(side, u[~f], v[~f])))
        if f.any():
            parts.append((f, *self._fillet_solve(side, u[f], v[f])))
        shapes = {"points": (3,), "normals": (3,), "kappa": (2,), "directions": (2, 3),
                  "tool_s": (), "tool_theta": (), "psi": (), "meshing_residual": ()}  # fmt: skip
        out = {k: np.empty(u.shape + sh) for k, sh in shapes.items()}
        for mask, env, a, th in parts:
            k, dirs = env.curvatures()
            vals = {"points": env.points, "normals": env.normals, "kappa": k, "directions": dirs,
                    "tool_s": a, "tool_theta": th, "psi": env.psi,
                    "meshing_residual": env.residual}  # fmt: skip
            for name, val in vals.items():
                out[name][mask] = val
        return FlankEvaluation(**out)

    def point_normal(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Exact points ``(..., 3)`` mm and outward unit normals at ``(u, v)`` (the engine):
        the blade envelope for ``u >= 0``, the generated fillet for ``u < 0``."""
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        f = u < 0
        if not f.any():
            env, _, _ = self._solve(side, u, v)
            return env.points, env.normals
        p, n = np.empty(u.shape + (3,)), np.empty(u.shape + (3,))
        if (~f).any():
            env = self._solve(side, u[~f], v[~f])[0]
            p[~f], n[~f] = env.points, env.normals
        env = self._fillet_solve(side, u[f], v[f])[0]
        p[f], n[f] = env.points, env.normals
        return p, n

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
        """Synthesize the machine settings (unless given) and build both members; choose the
        blade edge radius if the blank leaves it open (:func:`_default_edge_radius`); refuse an
        edge radius whose fillets do not fit (:meth:`SpiralBevelMember.check_fillets`)."""
        blank = blank or SpiralBevelBlank()
        targets = targets or SynthesisTargets()
        synth, reports = synthesize(blank, targets)
        synth_final = None
        if settings is None:
            settings = synth
            if targets.symmetric_te:
                for side in ("drive", "coast"):
                    settings = _tune_third_order_roll(blank, targets, settings, reports, side)
            synth_final = settings
        pair = cls._build(blank, targets, settings, reports)
        if blank.edge_radius_mm is None and settings is synth_final:
            rho = _default_edge_radius(pair)
            if rho != blank.edge_radius:
                pair = cls._build(blank, targets, _with_edge_radius(settings, rho), reports)
        for m in (pair.pinion, pair.gear):
            m.check_fillets()  # the edge radius fits (DesignError naming it otherwise)
            m.check_tooth()  # neither pointed nor undercut (DesignError naming the field)
        return pair

    @classmethod
    def _build(cls, blank, targets, settings, reports) -> SpiralBevelPair:
        pinion = SpiralBevelMember(
            "pinion", 1, blank.n1, blank, settings.pinion_drive, settings.pinion_coast
        )
        gear = SpiralBevelMember(
            "gear", 2, blank.n2, blank, settings.gear_drive, settings.gear_coast
        )
        return cls(blank, targets, settings, reports, pinion, gear)

    def record(self) -> dict[str, Any]:
        """The pair as plain data (JSON-ready: numbers, strings, lists): blank, targets, machine
        settings and synthesis reports. :meth:`from_record` rebuilds the same pair (the members
        are built from the settings; floats survive JSON exactly), so a synthesis can be cached
        without pickling code objects."""
        return {
            "format": _RECORD_FORMAT,
            "blank": _plain_fields(self.blank),
            "targets": _plain_fields(self.targets),
            "settings": {
                k: _plain_fields(getattr(self.settings, k))
                for k in ("gear_drive", "gear_coast", "pinion_drive", "pinion_coast")
            },
            "reports": {side: _plain_fields(r) for side, r in self.reports.items()},
        }

    @classmethod
    def from_record(cls, rec: dict[str, Any]) -> SpiralBevelPair:
        """The pair of a :meth:`record`.

        Raises
        ------
        InputError
            A record of another format.
        """
        if rec.get("format") != _RECORD_FORMAT:
            raise InputError("spiral_bevel record format", rec.get("format"), _RECORD_FORMAT)
        blank = SpiralBevelBlank(**rec["blank"])
        targets = SynthesisTargets(**rec["targets"])
        settings = SpiralBevelSettings(
            **{k: MachineSettings(**v) for k, v in rec["settings"].items()}
        )
        reports = {
            side: SynthesisReport(
                **{k: np.asarray(v, float) if isinstance(v, list) else v for k, v in r.items()}
            )
            for side, r in rec["reports"].items()
        }
        return cls._build(blank, targets, settings, reports)

    def mesh_placement(self, side: Side):
        """``(pinion(φ1), gear(φ2))``: functions of driving-sense angles (rad) → 4×4 member → mesh.

        At ``φ1 = φ2 = 0`` the mean points of the ``side`` flanks of tooth 0 of both members
        coincide on the pitch generatrix with opposite normals (the mean contact position).
        Nominal rotation ``φ2 = (N1/N2) φ1``; the TE is ``φ2 − (N1/N2) φ1``
        (``docs/conventions.md``).
        """
        r = self.reports[side]
        pin, gear, _ = mesh_transforms(
            self.blank, side, r.gear_flank_angle, r.pinion_flank_angle, r.sigma
        )
        return pin, gear


_RECORD_FORMAT = "fegear.spiral_bevel_pair/1"


def _plain_fields(obj: Any) -> dict[str, Any]:
    """A frozen dataclass of numbers, strings and arrays as a JSON-ready dict (arrays → lists,
    numpy scalars → Python numbers)."""
    out = {}
    for f in fields(obj):
        v = getattr(obj, f.name)
        if isinstance(v, np.ndarray):
            v = v.tolist()
        elif isinstance(v, np.generic):
            v = v.item()
        out[f.name] = v
    return out


def _with_edge_radius(settings: SpiralBevelSettings, rho: float) -> SpiralBevelSettings:
    """``settings`` with every blade's edge radius set to ``rho`` (mm)."""
    return SpiralBevelSettings(
        **{
            k: replace(settings.get(*k.split("_")), edge_radius_mm=float(rho))
            for k in ("gear_drive", "gear_coast", "pinion_drive", "pinion_coast")
        }
    )


def _default_edge_radius(pair: SpiralBevelPair, keep: float = 0.2) -> float:
    """The default blade edge radius (mm): ``0.25 m``, or ``(1 − keep)`` of the largest radius
    the tooth spaces carry where that is smaller.

    The root land of a tooth space (:meth:`SpiralBevelMember.root_land`) falls linearly with
    the edge radius, ``land(ρ) = W − K ρ`` (each edge radius takes ``ρ (1 − sin α)/cos α`` of the
    root in the normal section; measured linear to 1e-4 mm over 0.4 … 1.24 mm), with ``W`` the
    point width the sharp blades would leave. From the lands at the trial ``ρ_0 = 0.25 m`` (the
    pair as synthesized) and at ``ρ_0/2``: ``K``, ``W`` and the largest radius
    ``ρ_max = min W/K`` over both members and the face; the default keeps ``keep`` of the point
    width as root land: ``ρ = min(ρ_0, (1 − keep) ρ_max)``.
    """
    r0 = pair.blank.edge_radius
    st = _with_edge_radius(pair.settings, 0.5 * r0)
    half = SpiralBevelPair._build(pair.blank, pair.targets, st, pair.reports)
    rho_max, where = math.inf, ""
    for m0, m1 in ((pair.pinion, half.pinion), (pair.gear, half.gear)):
        L, l0 = m0.root_land()
        l1 = m1.root_land()[1]
        K = (l1 - l0) / (0.5 * r0)
        W = l0 + K * r0
        k = int(np.argmin(W / K))
        if W[k] / K[k] < rho_max:
            rho_max, where = float(W[k] / K[k]), f"{m0.name} at L = {L[k]:.2f} mm, W {W[k]:.3f} mm"
    rho = min(r0, (1.0 - keep) * rho_max)
    log.info("spiral bevel: blade edge radius %.4f mm (the tooth spaces carry %.4f mm: %s)",
             rho, rho_max, where)  # fmt: skip
    return rho


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
    """Unloaded TE of the mean tooth pair (tooth 0 of both members), rad, sign of
    ``docs/conventions.md``.

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
    u1, v1 = pair.pinion.mean_parameters(side)
    u2, v2 = pair.gear.mean_parameters(side)
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
    :class:`~.spiral_bevel_settings.HeadCutter`).

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
        L, h, _, _ = _cone_coords(p, self.member.pitch_angle)
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


@dataclass(frozen=True)
class NativeFillet(_NativeEnvelope):
    """Exact, fast evaluation of one generated fillet (the envelope of the blade's edge radius,
    :class:`~.spiral_bevel_settings.EdgeRadius`) in its native parameters ``(ϑ, θ)``
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
            L, _, gL, _ = _cone_coords(p, g)
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
