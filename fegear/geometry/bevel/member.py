"""One member of a face-milled bevel pair: its generated flanks, fillets and their limits.

The flanks come from the shared envelope engine :func:`fegear.geometry.generation.generate`
(tool: :class:`~.cutter.HeadCutter`; motion: the cradle chain :func:`~.machine.machine_motion`
of the flank's :class:`~.machine.MachineSettings`); the member finds, for flank coordinates
``(u, v)``, the cutter parameters that generate the point there.

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
  coordinates are defined in :mod:`.blank`.

Cutter tip, fillet limit and fillet (Litvin & Fuentes 2004 §21.2; Litvin & Zhang 1991;
Argyris, Fuentes & Litvin 2002 §2)
-------------------------------------------------------------------------------------------
The blade of each flank's head cutter ends in an edge radius ``ρ_f``
(:class:`~.cutter.EdgeRadius`, :func:`~.cutter.blade_tip`):
an arc tangent to the blade at ``s = s_b`` and to the cutter's point plane, the plane normal to
the cutter axis that touches the blank's root cone (:func:`~.machine.point_plane`;
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
"""

from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from ...errors import DesignError, InputError, SolverError
from ..generation import Envelope, generate
from ..surface import BlankOutline, ConeLine, FlankBoundaries, FlankCoordinates, FlankSurface, Side
from .blank import BevelBlank
from .cutter import EdgeRadius, blade_tip
from .machine import MachineSettings, blank_placement, head_cutter, machine_motion, point_plane
from .native import NativeFillet, NativeFlank, cone_coords
from .tabulated import FlankTableRecord, TabulatedFlank, flank_record, from_record, tabulate

__all__ = ["FlankEvaluation", "FilletLimit", "SpiralBevelMember"]

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
    blank: BevelBlank
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
        return self.blank.pitch_angle(self.index)

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
        A0 = self.blank.outer_cone_distance(self.index)
        return FlankBoundaries(
            u_root=-1.0,
            u_fillet=0.0,
            u_tip=1.0,
            v_start=A0 - self.blank.face_width(self.index),
            v_end=A0,
            u_name="fraction of the working height: 0 fillet limit, 1 face cone (-1 root cone)",
            v_name="cone distance L (mm), toe -> heel",
            height=functools.partial(self.height, side=self.settings(side).side),
            height_name="height h above the pitch cone (mm)",
        )

    # ------------------------------------------------------------------ cutter tip and limits
    def edge_tool(self, side: Side) -> EdgeRadius:
        """The edge radius of the ``side`` blade, placed on the point plane that cuts this
        member's root cone (:func:`~.machine.blade_tip`, cached)."""
        key = ("edge", side)
        if key not in self._cache:
            ms = self.settings(side)
            cutter = self._tools(side)[0]
            zp = ms.point_plane_mm
            if zp is None:
                zp = point_plane(self.blank, self.index, ms)
            self._cache[key] = blade_tip(cutter, ms.edge_radius_mm, zp)
        return self._cache[key]

    def root_cone_line(self) -> tuple[float, float]:
        """``(a, b)`` of the member's root cone ``h_R(L) = a + b L`` in its ``(L, h)`` plane.

        The blank's (:meth:`~.blank.SpiralBevelBlank.root_cone_line`) where the settings put
        the point plane on it (synthesized settings), else the cone the cutters' point plane
        sweeps: at ψ = 0 the plane ``z_m = z_p`` of the machine is ``n·X = c`` in the member
        frame (``n`` the third row of the blank placement's rotation); turned about the member
        axis its envelope in the axial half-plane is the line ``n_ρ ρ + n_z z = c``,
        ``n_ρ = |(n_x, n_y)|`` (the side :func:`~.machine.point_plane` touches), i.e. in
        ``(L, h)``: ``a = c / (n_ρ cos γ − n_z sin γ)``,
        ``b = −(n_ρ sin γ + n_z cos γ) / (n_ρ cos γ − n_z sin γ)``.

        Raises :class:`~fegear.errors.DesignError` if the two sides' settings sweep root cones
        more than 1 µm apart over the face (one root cone per member is modelled).
        """
        key = "root_cone"
        if key not in self._cache:
            ms = {side: self.settings(side) for side in ("drive", "coast")}
            if all(m.point_plane_mm is None for m in ms.values()):
                self._cache[key] = self.blank.root_cone_line(self.index)
            else:
                lines = {side: _swept_root(m, self.pitch_angle) for side, m in ms.items()}
                A0, F = (
                    self.blank.outer_cone_distance(self.index),
                    self.blank.face_width(self.index),
                )
                L = np.array([A0 - F, A0])
                (a1, b1), (a2, b2) = lines["drive"], lines["coast"]
                gap = float(np.max(np.abs((a1 + b1 * L) - (a2 + b2 * L))))
                if gap > 1e-3:
                    raise DesignError(
                        f"machine.{self.name}_coast.machine_root_angle",
                        ms["coast"].machine_root_angle_deg,
                        f"the root cone of machine.{self.name}_drive",
                        f"the two sides of the {self.name} cut root cones {gap:.4f} mm apart "
                        "(one root cone per member is modelled)",
                    )  # fmt: skip
                self._cache[key] = lines["drive"]
        return self._cache[key]

    def root_cone_height(self, L: ArrayLike) -> Array:
        """Height ``h_R(L)`` (mm) of the member's root cone (:meth:`root_cone_line`)."""
        a, b = self.root_cone_line()
        return a + b * np.asarray(L, float)

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
            Lp, _, gL, _ = cone_coords(env.points, g)
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

    def reference(self, side: Side) -> tuple[float, float, float]:
        """Cutter parameters ``(s, θ, ψ)`` that generate the mean point of the ``side`` flank
        (cone distance ``Rm``, on the pitch cone ``h = 0``): the start of every solve.

        Synthesized settings are fitted through the mean point, so it is ``(0, 0, 0)`` (taken
        as it is when that point is within 1e-9 mm of the mean point). Other settings (a summary
        sheet's): the nearest generated point over a grid of blade heights, cutter angles and
        cradle angles, then Newton on ``(L, h)`` (:meth:`_newton`). Cached.

        Raises :class:`~fegear.errors.DesignError` naming the flank's settings when no point
        of the generated flank comes within 1e-9 mm of the mean point.
        """
        key = ("reference", side)
        if key not in self._cache:
            self._cache[key] = self._find_reference(side)
        return self._cache[key]

    def _find_reference(self, side: Side) -> tuple[float, float, float]:
        tool, mot = self._tools(side)
        g, rm = self.pitch_angle, self.blank.mean_cone_distance(self.index)
        glog = logging.getLogger(generate.__module__)
        level = glog.level
        glog.setLevel(max(level, logging.ERROR))  # (0, 0, 0) may generate nothing: then search
        try:
            e0 = generate(tool, mot, 0.0, 0.0, 0.0, half_width=0.3)
        finally:
            glog.setLevel(level)
        L0, h0, _, _ = cone_coords(e0.points, g)
        if bool(e0.residual < 1e-9) and math.hypot(L0 - rm, h0) < 1e-9:
            return 0.0, 0.0, 0.0
        depth = self.blank.addendum(self.index) + self.blank.dedendum(self.index)
        S, T, P = np.meshgrid(
            np.linspace(-depth, 2.0 * depth, 7), np.linspace(-1.2, 1.2, 49),
            np.linspace(-1.0, 1.0, 9), indexing="ij",
        )  # fmt: skip
        glog = logging.getLogger(generate.__module__)
        level = glog.level
        glog.setLevel(max(level, logging.ERROR))  # most of the wide grid has no root: expected
        try:
            env = generate(tool, mot, S, T, P, half_width=0.125)
        finally:
            glog.setLevel(level)
        L, h, _, _ = cone_coords(env.points, g)
        miss = np.where(env.residual < 1e-9, np.hypot(L - rm, h), np.inf)
        k = np.unravel_index(int(np.argmin(miss)), miss.shape)
        who = f"machine.{self.name}_{side}"
        if not np.isfinite(miss[k]):
            raise DesignError(who, "these settings", "settings that cut this flank",
                              "the cutter generates no flank near the blank")  # fmt: skip
        s0, th0, psi0 = float(S[k]), float(T[k]), float(env.psi[k])
        try:
            env, s1, t1 = self._newton(side, np.array(rm), np.array(0.0), s0, th0, psi0)
        except SolverError as exc:
            raise DesignError(
                who, "these settings", "settings that cut this flank through its mean point",
                f"the generated flank comes no nearer than {miss[k]:.3f} mm to the mean point "
                f"(L = {rm:.3f} mm on the pitch cone): {exc}",
            ) from exc  # fmt: skip
        return float(s1), float(t1), float(env.psi)

    def _theta_predictor(self, side: Side, s: Array, L: Array) -> Array:
        """Linear predictor of θ at blade parameter ``s`` and cone distance ``L`` from the mean
        point (:meth:`reference`)."""
        tool, mot = self._tools(side)
        s0, t0, p0 = self.reference(side)
        e0 = generate(tool, mot, s0, t0, p0, half_width=0.3)
        L0, _, gL0, _ = cone_coords(e0.points, self.pitch_angle)
        ds = np.asarray(s, float) - s0
        return t0 + (np.asarray(L, float) - L0 - (gL0 @ e0.r_u) * ds) / (gL0 @ e0.r_t)

    def fillet_limit(self, side: Side, L: ArrayLike, tol: float = 1e-12) -> FilletLimit:
        """The exact fillet limit at cone distances ``L`` (mm): the point of the blade
        envelope generated by the blade's end ``s = s_b`` (where the edge radius begins), by
        Newton on the cutter angle (:meth:`_theta_solve`, ``tol`` mm)."""
        L = np.asarray(L, float)
        sb = np.full(L.shape, self.edge_tool(side).s_blade)
        th0 = self._theta_predictor(side, sb, L)
        psi0 = np.full(L.shape, self.reference(side)[2])
        env, th = self._theta_solve(side, self._tools(side)[0], sb, L, th0, psi0, tol)
        h = cone_coords(env.points, self.pitch_angle)[1]
        return FilletLimit(th, env.psi, env.points, env.normals, h)

    def _limit_table(self, side: Side) -> tuple[CubicSpline, CubicSpline, CubicSpline]:
        """Cubic splines over the cone distance of the fillet-limit height ``h_fl(L)``, its
        cutter angle ``θ_fl(L)`` and generating angle ``ψ_fl(L)``: 0.5 mm apart from 0.4 F
        inside the toe to 0.2 F past the heel (the sector loft reaches 0.04 F past both ends).
        The curve is smooth and nearly straight: the spline is within ~1e-10 mm of the exact
        limit (tested)."""
        key = ("limit", side)
        if key not in self._cache:
            A0, F = self.blank.outer_cone_distance(self.index), self.blank.face_width(self.index)
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
            h[f] = cone_coords(p, self.pitch_angle)[1]
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
        rm = self.blank.mean_cone_distance(self.index)
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
            A0, F = self.blank.outer_cone_distance(self.index), self.blank.face_width(self.index)
            L = np.linspace(A0 - F, A0, n_L)
            phi = {}
            for side in ("drive", "coast"):
                p = self._fillet_solve(side, -np.ones_like(L), L)[0].points  # engine: 9 points
                phi[side] = np.arctan2(p[:, 1], p[:, 0])
            plus, minus = ("drive", "coast")
            if phi["drive"][0] < phi["coast"][0]:
                plus, minus = minus, plus
            g = self.pitch_angle
            rho_root = L * math.sin(g) + self.root_cone_height(L) * math.cos(g)
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
            h0 = float(self.fillet_height(self.blank.mean_cone_distance(self.index), side))
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
            cb = math.cos(self.blank.spiral_angle(self.index))
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
            A0, F = self.blank.outer_cone_distance(self.index), self.blank.face_width(self.index)
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
                    f"{self.blank.field_prefix}.face_width_mm", self.blank.face_width(self.index),
                    f"<= {self.blank.outer_cone_distance(self.index) - L0:.2f} mm", where,
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

    def tabulated_flank(self, side: Side) -> NativeFlank:
        """:meth:`native_flank` tabulated once (built once, cached): the same flank to
        :data:`~.tabulated.TABLE_TOL_MM`, ~8× cheaper per call of a few points
        (:class:`~.tabulated.TabulatedFlank`; the exact evaluator if no table meets the
        tolerance)."""
        key = ("tabulated", side)
        tf = self._cache.get(key)
        if tf is None:
            tf = self._cache[key] = tabulate(self.native_flank(side))
        return tf

    def tabulated_record(self, side: Side) -> FlankTableRecord | None:
        """:meth:`tabulated_flank` as plain arrays (:func:`~.tabulated.flank_record`), or None
        where no table met the tolerance (the exact evaluator is used)."""
        tf = self.tabulated_flank(side)
        if not isinstance(tf, TabulatedFlank):
            return None
        return flank_record(tf, self.native_flank(side))

    def adopt_tabulated(self, side: Side, record: FlankTableRecord) -> NativeFlank:
        """:meth:`tabulated_flank` from ``record`` (:meth:`tabulated_record` of the same member,
        e.g. read back from a cache) instead of building it; the exact evaluator with it. A
        member that has built its own keeps it."""
        key = ("tabulated", side)
        if key not in self._cache:
            tab, native = from_record(self, side, record)
            self._cache.setdefault(("native", side), native)
            self._cache[key] = tab
        return self._cache[key]

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
        A0 = bl.outer_cone_distance(i)
        F = bl.face_width(i)
        root = ConeLine(*self.root_cone_line())
        tip = ConeLine(*bl.face_cone_line(i))
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
        cutter parameters ``(s, θ)`` for the target ``(L, h)`` (:meth:`_newton`), from the mean
        point's parameters (:meth:`reference`)."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        return self._newton(side, v, self.height(u, v, side), *self.reference(side))

    def _newton(
        self, side: Side, L_t: Array, h_t: Array, s0: float, t0: float, p0: float
    ) -> tuple[Envelope, Array, Array]:
        """Blade envelope points at cone coordinates ``(L_t, h_t)``: linear predictor from the
        envelope at ``(s0, θ0, ψ0)``, then Newton on ``(s, θ)`` with the engine's tangents."""
        tool, mot = self._tools(side)
        g = self.pitch_angle
        e0 = generate(tool, mot, s0, t0, p0, half_width=0.3)
        L0, h0, gL0, gh0 = cone_coords(e0.points, g)
        J0 = np.array([[gL0 @ e0.r_u, gL0 @ e0.r_t], [gh0 @ e0.r_u, gh0 @ e0.r_t]], dtype=float)
        d = np.stack([L_t - L0, h_t - h0], -1)
        x = np.einsum("ij,...j->...i", np.linalg.inv(J0), d)
        s, th = s0 + x[..., 0], t0 + x[..., 1]
        psi = np.full_like(s, p0)
        hw = 0.6
        for _ in range(40):
            env = generate(tool, mot, s, th, psi, half_width=hw)
            psi = env.psi
            L, h, gL, gh = cone_coords(env.points, g)
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


def _swept_root(ms: MachineSettings, gamma: float) -> tuple[float, float]:
    """``(a, b)`` of the cone ``h = a + b L`` that the point plane of ``ms`` sweeps on a member
    of pitch angle ``gamma`` (:meth:`SpiralBevelMember.root_cone_line`)."""
    B = blank_placement(ms)
    n = B[2, :3]
    c = ms.ref_height_mm + ms.point_plane_mm - B[2, 3]
    n_rho, n_z = math.hypot(n[0], n[1]), n[2]
    cg, sg = math.cos(gamma), math.sin(gamma)
    den = n_rho * cg - n_z * sg
    return c / den, -(n_rho * sg + n_z * cg) / den
