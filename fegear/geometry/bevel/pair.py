"""A designed face-milled bevel pair: blank, targets, settings and the two members.

:meth:`SpiralBevelPair.design` synthesizes the machine settings (:mod:`.synthesis`) unless they
are given, builds both members (:mod:`.member`), chooses the blade edge radius where the blank
leaves it open and refuses an edge radius or a tooth that cannot be cut. The rigid TCA of the
mean tooth pair here (:func:`transmission_error`) serves the synthesis (the third-order roll);
the full TCA is :mod:`fegear.tca`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import DesignError, InputError, SolverError
from ..generation import generate
from ..surface import Side
from ..transforms import apply_points, apply_vectors
from .blank import ARCSEC, BevelBlank, SpiralBevelBlank
from .hypoid import HypoidBlank
from .machine import MachineSettings, SpiralBevelSettings, mirrored
from .member import SpiralBevelMember
from .mesh_frame import mesh_transforms
from .native import NativeFlank, cone_coords
from .synthesis import SynthesisReport, SynthesisTargets, synthesize

__all__ = ["SpiralBevelPair", "transmission_error"]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


@dataclass(frozen=True)
class FlankPlacement:
    """Where the ``side`` flanks of tooth 0 sit in the mesh position ``φ1 = φ2 = 0``.

    Attributes
    ----------
    side
        ``"drive"`` or ``"coast"``.
    sigma
        Sense of pinion rotation (+1: about ``+z`` of the mesh frame) for this side to drive.
    gear_flank_angle, pinion_flank_angle
        Polar angles (rad) of the mean points of the gear and pinion flanks in their member
        frames; each member is turned so that its mean point is at the pitch point ``P``.
    """

    side: str
    sigma: float
    gear_flank_angle: float
    pinion_flank_angle: float


@dataclass(frozen=True)
class SpiralBevelPair:
    """A bevel pair: blank, targets, settings, synthesis reports, placements, members.

    Use :meth:`design` (settings synthesized from the targets); to override settings,
    ``dataclasses.replace`` a :class:`MachineSettings` of ``pair.settings`` and pass the new
    :class:`SpiralBevelSettings` to :meth:`design` (the synthesis reports then describe the
    synthesized, not the overridden, settings). Settings from a summary sheet:
    :meth:`from_settings` (no synthesis: ``reports`` is empty).
    """

    blank: BevelBlank
    targets: SynthesisTargets
    settings: SpiralBevelSettings
    reports: dict[str, SynthesisReport]
    pinion: SpiralBevelMember
    gear: SpiralBevelMember
    placements: dict[str, FlankPlacement]

    @classmethod
    def design(
        cls,
        blank: BevelBlank | None = None,
        targets: SynthesisTargets | None = None,
        settings: SpiralBevelSettings | None = None,
        native_tune: bool = True,
    ) -> SpiralBevelPair:
        """Synthesize the machine settings (unless given) and build both members; choose the
        blade edge radius if the blank leaves it open (:func:`_default_edge_radius`); refuse an
        edge radius whose fillets do not fit (:meth:`SpiralBevelMember.check_fillets`). A
        left-hand gear is the mirror image of the right-hand pair (:meth:`mirrored`).

        ``native_tune``: tune the third-order roll on the native rigid contact
        (:func:`_tune_third_order_roll`, the default), ~4× faster than on the envelope engine
        (``False``); the two D agree to ~2e-10 relative (``benchmarks/results/bevel_design.md``):
        the same pair to the solves' tolerances, though not the same bits (the sector meshes
        follow D's last digits: 3206 or 3210 tetrahedra on the reference pair for a change of
        1e-13)."""
        blank = blank or SpiralBevelBlank()
        targets = targets or SynthesisTargets()
        if blank.hand == "left":
            right = replace(blank, hand="right")
            given = None if settings is None else _mirror_settings(settings)
            return cls.design(right, targets, given, native_tune).mirrored(blank)
        synth, reports = synthesize(blank, targets)
        synth_final = None
        pool: dict = {}  # the members built so far, by their settings (:func:`_members`)
        if settings is None:
            settings = synth
            if targets.symmetric_te:
                for side in ("drive", "coast"):
                    settings = _tune_third_order_roll(
                        blank, targets, settings, reports, side, pool, native_tune
                    )
            synth_final = settings
        pair = cls._build(blank, targets, settings, reports, pool)
        if blank.edge_radius_mm is None and settings is synth_final:
            rho = _default_edge_radius(pair, pool=pool)
            if rho != blank.edge_radius:
                pair = cls._build(blank, targets, _with_edge_radius(settings, rho), reports, pool)
        for m in (pair.pinion, pair.gear):
            m.check_fillets()  # the edge radius fits (DesignError naming it otherwise)
            m.check_tooth()  # neither pointed nor undercut (DesignError naming the field)
        return pair

    @classmethod
    def from_settings(
        cls, blank: BevelBlank, settings: SpiralBevelSettings, check: bool = True
    ) -> SpiralBevelPair:
        """The pair whose flanks the given machine settings cut (no synthesis): each member's
        flanks on the blank, the placement of each side found from the flanks' mean points
        (:func:`flank_placement`); with ``check``, the edge radii and the teeth checked as in
        :meth:`design`.

        Raises :class:`~fegear.errors.DesignError` naming the flank's settings when they do not
        cut a flank through the mean point, a fillet that fits, or a tooth that is neither
        pointed nor undercut.
        """
        pinion, gear = _members(blank, settings)
        placements = {side: flank_placement(blank, pinion, gear, side) for side in SIDES}
        pair = cls(blank, SynthesisTargets(), settings, {}, pinion, gear, placements)
        if check:
            for m in (pair.pinion, pair.gear):
                try:
                    m.check_fillets()
                    m.check_tooth()
                except (DesignError, SolverError) as exc:
                    raise DesignError(
                        f"machine.{m.name}_drive / machine.{m.name}_coast", "these settings",
                        f"settings that cut a {m.name} tooth (fillets that fit in the tooth "
                        "space, neither pointed nor undercut)", str(exc),
                    ) from exc  # fmt: skip
        return pair

    @classmethod
    def _build(cls, blank, targets, settings, reports, pool=None) -> SpiralBevelPair:
        pinion, gear = _members(blank, settings, pool)
        placements = {
            side: FlankPlacement(side, r.sigma, r.gear_flank_angle, r.pinion_flank_angle)
            for side, r in reports.items()
        }
        return cls(blank, targets, settings, reports, pinion, gear, placements)

    def mirrored(self, blank) -> SpiralBevelPair:
        """The mirror image of the pair (``y → −y`` in the mesh frame and in every member
        frame) on ``blank`` (the same blank of the other hand): settings mirrored
        (:func:`~.machine.mirrored`), each side's pinion turning the other way (σ → −σ), flank
        angles, points, normals and path directions mirrored; the relative curvatures and shape
        operators in the basis ``(t, n × t)`` change the sign of their off-diagonal entry
        (``n × t`` of mirrored vectors is minus the mirrored ``n × t``)."""
        Y = np.array([1.0, -1.0, 1.0])
        flip = np.array([[1.0, -1.0], [-1.0, 1.0]])
        reports = {
            side: replace(
                r,
                sigma=-r.sigma,
                point=r.point * Y,
                normal=r.normal * Y,
                path_direction=r.path_direction * Y,
                relative_curvature=r.relative_curvature * flip,
                target_pinion_shape=r.target_pinion_shape * flip,
                achieved_pinion_shape=r.achieved_pinion_shape * flip,
                gear_flank_angle=-r.gear_flank_angle,
                pinion_flank_angle=-r.pinion_flank_angle,
            )  # fmt: skip
            for side, r in self.reports.items()
        }
        settings = _mirror_settings(self.settings)
        pinion, gear = _members(blank, settings)
        placements = {
            side: FlankPlacement(side, -r.sigma, -r.gear_flank_angle, -r.pinion_flank_angle)
            for side, r in self.placements.items()
        }
        return type(self)(blank, self.targets, settings, reports, pinion, gear, placements)

    def record(self) -> dict[str, Any]:
        """The pair as plain data (JSON-ready: numbers, strings, lists): blank, targets, machine
        settings and synthesis reports. :meth:`from_record` rebuilds the same pair (the members
        are built from the settings; floats survive JSON exactly), so a synthesis can be cached
        without pickling code objects."""
        return {
            "format": _RECORD_FORMAT,
            "blank_kind": self.blank.field_prefix,
            "blank": _blank_record(self.blank),
            "targets": _plain_fields(self.targets),
            "settings": {
                k: _plain_fields(getattr(self.settings, k))
                for k in ("gear_drive", "gear_coast", "pinion_drive", "pinion_coast")
            },
            "reports": {side: _plain_fields(r) for side, r in self.reports.items()},
            "placements": {side: _plain_fields(r) for side, r in self.placements.items()},
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
        blank = _blank_from_record(rec.get("blank_kind", "spiral_bevel"), rec["blank"])
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
        if reports:
            return cls._build(blank, targets, settings, reports)
        pinion, gear = _members(blank, settings)
        placements = {side: FlankPlacement(**r) for side, r in rec["placements"].items()}
        return cls(blank, targets, settings, {}, pinion, gear, placements)

    def mesh_placement(self, side: Side):
        """``(pinion(φ1), gear(φ2))``: functions of driving-sense angles (rad) → 4×4 member → mesh.

        At ``φ1 = φ2 = 0`` the mean points of the ``side`` flanks of tooth 0 of both members
        coincide on the pitch generatrix with opposite normals (the mean contact position).
        Nominal rotation ``φ2 = (N1/N2) φ1``; the TE is ``φ2 − (N1/N2) φ1``
        (``docs/conventions.md``).
        """
        r = self.placements[side]
        pin, gear, _ = mesh_transforms(
            self.blank, side, r.gear_flank_angle, r.pinion_flank_angle, r.sigma
        )
        return pin, gear


_RECORD_FORMAT = "fegear.spiral_bevel_pair/1"
SIDES = ("drive", "coast")


def _mirror_settings(settings: SpiralBevelSettings) -> SpiralBevelSettings:
    return SpiralBevelSettings(**{f: mirrored(getattr(settings, f)) for f in _FLANKS})


_FLANKS = ("gear_drive", "gear_coast", "pinion_drive", "pinion_coast")


def _members(
    blank, settings: SpiralBevelSettings, pool: dict | None = None
) -> tuple[SpiralBevelMember, SpiralBevelMember]:
    """The pinion and the gear of ``settings`` on ``blank``. With ``pool`` (a dict kept by
    :meth:`SpiralBevelPair.design` over one design), a member of the same blank and settings
    built before is taken from it, with what it has cached (limit tables, native evaluators:
    functions of its fields alone): the third-order roll's trials share the gear, the tuned
    pair its pinion with the last trial."""
    out = []
    for name, i, n, drive, coast in (
        ("pinion", 1, blank.n1, settings.pinion_drive, settings.pinion_coast),
        ("gear", 2, blank.n2, settings.gear_drive, settings.gear_coast),
    ):
        key = (name, id(blank), drive, coast)
        m = None if pool is None else pool.get(key)
        if m is None or m.blank is not blank:
            m = SpiralBevelMember(name, i, n, blank, drive, coast)
            if pool is not None:
                pool[key] = m
        out.append(m)
    return out[0], out[1]


def flank_placement(
    blank, pinion: SpiralBevelMember, gear: SpiralBevelMember, side: Side
) -> FlankPlacement:
    """The placement of the ``side`` flanks from their generated mean points: the polar angles
    of both members' mean points (:meth:`~.member.SpiralBevelMember.reference`) and the
    pinion's sense of rotation from the gear's normal there, ``σ = sign(((P − A2) × n) · e2)``
    (the pinion pushes the gear along ``−n``; the gear turns with that torque about ``−σ e2``).
    """
    ang = []
    for m in (gear, pinion):
        tool, mot = m._tools(side)
        env = generate(tool, mot, *m.reference(side), half_width=0.3)
        ang.append(float(math.atan2(env.points[1], env.points[0])))
        if m is gear:
            n_gear = env.normals
    th2, d1 = ang
    _, gear_f, e2 = mesh_transforms(blank, side, th2, d1, 1.0)
    G = gear_f(0.0)
    A2 = blank.gear_axis()[0]
    n = apply_vectors(G, n_gear)
    sigma = float(np.sign(np.dot(np.cross(blank.pitch_point() - A2, n), e2)))
    return FlankPlacement(side, sigma, th2, d1)


def _blank_record(blank) -> dict[str, Any]:
    """A blank's input fields as plain data (a hypoid blank's own record)."""
    if isinstance(blank, HypoidBlank):
        return blank.record()
    return _plain_fields(blank)


def _blank_from_record(kind: str, rec: dict[str, Any]):
    """The blank of :func:`_blank_record` (``kind``: the blank's ``field_prefix``)."""
    if kind == HypoidBlank.field_prefix:
        return HypoidBlank.from_record(rec)
    if kind != SpiralBevelBlank.field_prefix:
        raise InputError("bevel record blank_kind", kind, "'spiral_bevel' or 'hypoid'")
    return SpiralBevelBlank(**rec)


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


def _default_edge_radius(pair: SpiralBevelPair, keep: float = 0.2, pool=None) -> float:
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
    half = SpiralBevelPair._build(pair.blank, pair.targets, st, pair.reports, pool)
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
    """Contact of tooth 0 of both members at pinion angle φ1: :class:`_MeshContact` from flank
    coordinates ``x = (u1, v1, u2, v2, φ2)`` (the start) to flank coordinates (the contact)."""
    mc = _MeshContact.of(pair, side)
    y, r = mc.solve(phi1, mc.native(x))
    return mc.flank(y), r


def _contact_engine(
    pair: SpiralBevelPair, side: Side, phi1: float, x: Array, residual: bool = True
) -> tuple[Array, float]:
    """:func:`_contact` through the envelope engine (``point_normal``) with a finite-difference
    Jacobian in flank coordinates: the reference the native solve is tested against.

    Unknowns ``x = (u1, v1, u2, v2, φ2)``; equations ``P(φ1) r1 = G(φ2) r2`` (3) and
    ``P n1 + G n2 = 0`` (3, rank 2): Litvin & Fuentes 2004 §9.4 (TCA). Without ``residual``
    the residual at the contact is not evaluated (NaN; the contact is the same).
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
    for _ in range(_MAX_ITER):
        r, J = F(x)
        dx = np.linalg.lstsq(J, -r, rcond=None)[0]
        dx *= min(1.0, 1.0 / max(np.max(np.abs(dx) / _TRUST), 1e-300))
        x = x + dx
        if np.max(np.abs(dx[:4])) < _TOL_UV and abs(dx[4]) < _TOL_PHI:
            break
    return x, float(np.max(np.abs(F(x)[0]))) if residual else math.nan


#: Newton of the rigid contact: iterations, trust region of a step in flank coordinates
#: ``(u1, v1, u2, v2, φ2)`` (0.2 of the working height, 3 mm, 0.05 rad), convergence (the last
#: step below 1e-10 in ``u`` and ``v`` (mm), 1e-13 rad in ``φ2``)
_MAX_ITER = 30
_TRUST = np.array([0.2, 3.0, 0.2, 3.0, 0.05])
_TOL_UV, _TOL_PHI = 1e-10, 1e-13
#: ψ table of a trial pinion's native flank (:func:`_tune_third_order_roll`; 41 by default)
_TRIAL_GRID = 21


@dataclass(frozen=True)
class _MeshContact:
    """The rigid contact of tooth 0 of both members of one side, solved in the members' native
    cutter parameters.

    Unknowns ``y = (s1, θ1, s2, θ2, φ2)`` (blade parameter and cutter angle of each flank,
    :class:`~.native.NativeFlank`; gear angle); equations (Litvin & Fuentes 2004 §9.4, TCA)

    .. math::  P(φ_1)\\, r_1(s_1, θ_1) − G(φ_2)\\, r_2(s_2, θ_2) = 0, \\qquad
               P(φ_1)\\, n_1 + G(φ_2)\\, n_2 = 0

    (6 equations, rank 5), least-squares Newton. The flanks are evaluated by the members' fast
    exact evaluators (:meth:`~.member.SpiralBevelMember.native_flank`: the engine's surface to
    ~1e-13 mm), whose points and analytic tangents ``r_s``, ``r_θ`` give the position rows of the
    Jacobian; the normal rows' ``n_s``, ``n_θ`` are forward differences of the exact normals
    (steps ``1e-6`` mm, ``1e-8`` rad); the gear turns about ``ω = −σ e2`` through ``A2``
    (:func:`~.mesh_frame.mesh_transforms`), so ``∂(G r_2)/∂φ_2 = ω × (G r_2 − A_2)`` and
    ``∂(G n_2)/∂φ_2 = ω × G n_2``. The residuals are exact, so the Jacobian only sets the rate:
    the converged contact is the engine solve's (:func:`_contact_engine`) to round-off.

    Damping and convergence mean what they mean in flank coordinates ``(u, v)``
    (:data:`_TRUST`, :data:`_TOL_UV`, :data:`_TOL_PHI`): each native step is mapped to its
    ``(Δu, Δv)`` by the linearization ``∂(u, v)/∂(s, θ)`` at the iterate (``v = L``,
    ``u = (h − h_fl(L))/(h_a(L) − h_fl(L))``, :meth:`~.member.SpiralBevelMember.working_u`).
    """

    pair: SpiralBevelPair
    side: Side
    nf: tuple[Any, Any]
    P: Any
    G: Any
    omega: Array
    A2: Array

    @classmethod
    def of(cls, pair: SpiralBevelPair, side: Side, pinion_grid: int | None = None) -> _MeshContact:
        """The contact problem of ``side``: the members' native flanks
        (:meth:`~.member.SpiralBevelMember.native_flank`, built or cached). ``pinion_grid``: a
        pinion without a native flank of its own yet gets one with an ``pinion_grid²`` ψ table
        instead, not cached (the third-order roll's trial pinions, each used for one TE: a
        coarser Newton start, the same surface; :meth:`~.native.NativeFlank.build`)."""
        pin, gear = pair.mesh_placement(side)
        A2, e2 = pair.blank.gear_axis()
        omega = -pair.placements[side].sigma * np.asarray(e2, float)
        m1 = pair.pinion
        if pinion_grid is None or ("native", side) in m1._cache:
            nf1 = m1.native_flank(side)
        else:
            nf1 = NativeFlank.build(m1, side, n_grid=pinion_grid)
        nf = (nf1, pair.gear.native_flank(side))
        return cls(pair, side, nf, pin, gear, omega, np.asarray(A2, float))

    def native(self, x: ArrayLike) -> Array:
        """``y = (s1, θ1, s2, θ2, φ2)`` of flank coordinates ``x = (u1, v1, u2, v2, φ2)``."""
        x = np.asarray(x, float)
        y = x.copy()
        for k, nf in enumerate(self.nf):
            s, th = nf.native(x[2 * k], x[2 * k + 1])
            y[2 * k], y[2 * k + 1] = float(s), float(th)
        return y

    def flank(self, y: Array) -> Array:
        """``x = (u1, v1, u2, v2, φ2)`` of native ``y``."""
        x = np.array(y, dtype=float)
        for k, nf in enumerate(self.nf):
            p = nf.evaluate(y[2 * k], y[2 * k + 1])[0]
            u, v = nf.flank(p)
            x[2 * k], x[2 * k + 1] = float(u), float(v)
        return x

    def _uv_rates(self, k: int, p: Array, rs: Array, rt: Array) -> Array:
        """``∂(u, v)/∂(s, θ)`` (2×2) of member ``k``'s flank at point ``p`` with tangents."""
        nf = self.nf[k]
        m = nf.member
        L, h, gL, gh = cone_coords(p, m.pitch_angle)
        eps = 1e-4  # mm: central difference of the fillet-limit spline and the face cone
        uL = m.working_u(h, np.array([L + eps, L - eps]), self.side)
        du_dL = float(uL[0] - uL[1]) / (2.0 * eps)
        du_dh = float(m.working_u(h + 1.0, L, self.side) - m.working_u(h, L, self.side))
        dL = np.array([gL @ rs, gL @ rt])
        dh = np.array([gh @ rs, gh @ rt])
        return np.array([du_dL * dL + du_dh * dh, dL])

    def _members(self, y: Array, jac: bool):
        """Mesh-frame points, normals (and their native derivatives) of both flanks at ``y``."""
        hs, ht = 1e-6, 1e-8
        out = []
        for k in range(2):
            s, th = y[2 * k], y[2 * k + 1]
            if not jac:
                p, n = self.nf[k].evaluate(s, th)
                out.append((p, n))
                continue
            S = np.array([s, s + hs, s])
            Th = np.array([th, th, th + ht])
            p, n, rs, rt = self.nf[k].evaluate(S, Th, tangents=True)
            out.append((p[0], n[0], rs[0], rt[0], (n[1] - n[0]) / hs, (n[2] - n[0]) / ht))
        return out

    def residual(self, phi1: float, y: Array) -> Array:
        """The 6 contact equations at ``y`` (mm, unit normals)."""
        (p1, n1), (p2, n2) = self._members(y, False)
        P, G = self.P(phi1), self.G(y[4])
        return np.concatenate(
            [
                apply_points(P, p1) - apply_points(G, p2),
                apply_vectors(P, n1) + apply_vectors(G, n2),
            ]
        )

    def linearize(self, phi1: float, y: Array) -> tuple[Array, Array, Array]:
        """``(r, J, R)`` at native ``y``: the 6 residuals, their Jacobian ``∂r/∂y`` (6×5) and
        the map ``R`` (5×5) of a native step to its step in flank coordinates ``(u, v)``."""
        P, G = self.P(phi1), self.G(y[4])
        RP, RG = P[:3, :3], G[:3, :3]
        (p1, n1, r1s, r1t, n1s, n1t), (p2, n2, r2s, r2t, n2s, n2t) = self._members(y, True)
        q2, m2 = apply_points(G, p2), apply_vectors(G, n2)
        r = np.concatenate([apply_points(P, p1) - q2, apply_vectors(P, n1) + m2])
        J = np.empty((6, 5))
        J[:3, 0], J[:3, 1] = RP @ r1s, RP @ r1t
        J[:3, 2], J[:3, 3] = -(RG @ r2s), -(RG @ r2t)
        J[:3, 4] = -np.cross(self.omega, q2 - self.A2)
        J[3:, 0], J[3:, 1] = RP @ n1s, RP @ n1t
        J[3:, 2], J[3:, 3] = RG @ n2s, RG @ n2t
        J[3:, 4] = np.cross(self.omega, m2)
        R = np.zeros((5, 5))
        R[:2, :2] = self._uv_rates(0, p1, r1s, r1t)
        R[2:4, 2:4] = self._uv_rates(1, p2, r2s, r2t)
        R[4, 4] = 1.0
        return r, J, R

    def solve(self, phi1: float, y: Array) -> tuple[Array, float]:
        """Contact at pinion angle ``phi1`` from native ``y``: the contact ``y`` and the max abs
        residual of the equations there (mm / unit normals)."""
        y = np.array(y, dtype=float)
        for _ in range(_MAX_ITER):
            r, J, R = self.linearize(phi1, y)
            dy = np.linalg.lstsq(J, -r, rcond=None)[0]
            # the step in flank coordinates: damping (trust region) and convergence as in (u, v)
            dx = R @ dy
            damp = min(1.0, 1.0 / max(np.max(np.abs(dx) / _TRUST), 1e-300))
            y = y + dy * damp
            if np.max(np.abs(dx[:4] * damp)) < _TOL_UV and abs(dx[4] * damp) < _TOL_PHI:
                break
        return y, float(np.max(np.abs(self.residual(phi1, y))))


def transmission_error(
    pair: SpiralBevelPair, side: Side, phi1: ArrayLike, substeps: int = 2, engine: bool = False
) -> tuple[Array, Array, Array]:
    """Unloaded TE of the mean tooth pair (tooth 0 of both members), rad, sign of
    ``docs/conventions.md``.

    Rigid TCA by continuation from the mean contact position (φ1 = φ2 = 0); only this one tooth
    pair is considered (no edge contact, no neighbouring pairs): the full TCA is fegear.tca.
    The contact equations are solved in the flanks' native cutter parameters with their fast
    exact evaluators (:class:`_MeshContact`); ``engine`` solves them in flank coordinates
    through the envelope engine instead (:func:`_contact_engine`: the same contact to
    round-off, ~50× slower; kept as the reference).

    Returns
    -------
    te : (n,)
        ``φ2 − (N1/N2) φ1`` (rad).
    params : (n, 5)
        ``(u1, v1, u2, v2, φ2)`` of the contact point.
    residual : (n,)
        Max abs residual of the contact equations (mm / unit normals).
    """
    mc = None if engine else _MeshContact.of(pair, side)
    return _transmission_error(pair, side, phi1, substeps, mc)


def _transmission_error(
    pair: SpiralBevelPair,
    side: Side,
    phi1: ArrayLike,
    substeps: int,
    mc: _MeshContact | None,
    residual: bool = True,
) -> tuple[Array, Array, Array]:
    """:func:`transmission_error` solved by ``mc`` (None: the engine; there, without
    ``residual``, the residuals are not evaluated: NaN, the TE and the contacts the same)."""
    phi1 = np.atleast_1d(np.asarray(phi1, dtype=float))
    u1, v1 = pair.pinion.mean_parameters(side)
    u2, v2 = pair.gear.mean_parameters(side)
    x0 = np.array([u1, v1, u2, v2, 0.0])
    if mc is None:
        to_native, to_flank = (lambda x: x), (lambda x: x)  # noqa: E731

        def contact(a: float, x: Array) -> tuple[Array, float]:
            return _contact_engine(pair, side, a, x, residual)
    else:
        to_native, to_flank, contact = mc.native, mc.flank, mc.solve
    y0 = to_native(x0)
    X = np.empty((phi1.size, 5))
    res = np.empty(phi1.size)
    m21 = pair.blank.m21
    for k, target in enumerate(phi1):
        y = y0.copy()
        for a in np.linspace(0.0, target, substeps + 1)[1:]:
            y[4] = m21 * a + (y[4] - m21 * (a - target / substeps))  # keep the TE guess
            y, r = contact(float(a), y)
        if target == 0 and (residual or mc is not None):
            r = contact(0.0, y0)[1]
        X[k], res[k] = to_flank(y), r
    return X[:, 4] - m21 * phi1, X, res


def _tune_third_order_roll(
    blank, targets, settings, reports, side, pool: dict | None = None, native: bool = False
) -> SpiralBevelSettings:
    """Third-order roll D of the pinion so that TE(+π/N1) = TE(−π/N1) (secant; g is ~linear).

    The trials' pairs are built through ``pool`` (:func:`_members`): one gear for all. The TE
    of a trial: by the engine (:func:`_contact_engine`, no residuals: the D of every release so
    far, bit for bit), or with ``native`` by the native contact (:class:`_MeshContact`; each
    trial pinion's native flank with a ``_TRIAL_GRID²`` ψ table, :meth:`_MeshContact.of`):
    ~4× faster, the same D to ~2e-10 relative (12/36 spiral bevel and 10/41 hypoid:
    ``benchmarks/bench_bevel_design.py``)."""
    key = f"pinion_{side}"
    base = settings.get("pinion", side)
    ends = np.array([-math.pi / blank.n1, math.pi / blank.n1])

    def g(D: float) -> float:
        st = replace(settings, **{key: replace(base, modified_roll_third=D)})
        pair = SpiralBevelPair._build(blank, targets, st, reports, pool)
        if native:
            mc = _MeshContact.of(pair, side, pinion_grid=_TRIAL_GRID)
            te = _transmission_error(pair, side, ends, 2, mc)[0]
        else:
            te = _transmission_error(pair, side, ends, 2, None, residual=False)[0]
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
