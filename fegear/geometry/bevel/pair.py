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
    ) -> SpiralBevelPair:
        """Synthesize the machine settings (unless given) and build both members; choose the
        blade edge radius if the blank leaves it open (:func:`_default_edge_radius`); refuse an
        edge radius whose fillets do not fit (:meth:`SpiralBevelMember.check_fillets`). A
        left-hand gear is the mirror image of the right-hand pair (:meth:`mirrored`)."""
        blank = blank or SpiralBevelBlank()
        targets = targets or SynthesisTargets()
        if blank.hand == "left":
            right = replace(blank, hand="right")
            given = None if settings is None else _mirror_settings(settings)
            return cls.design(right, targets, given).mirrored(blank)
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
    def _build(cls, blank, targets, settings, reports) -> SpiralBevelPair:
        pinion, gear = _members(blank, settings)
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


def _members(blank, settings: SpiralBevelSettings) -> tuple[SpiralBevelMember, SpiralBevelMember]:
    pinion = SpiralBevelMember(
        "pinion", 1, blank.n1, blank, settings.pinion_drive, settings.pinion_coast
    )
    gear = SpiralBevelMember("gear", 2, blank.n2, blank, settings.gear_drive, settings.gear_coast)
    return pinion, gear


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
