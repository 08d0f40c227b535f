"""Local synthesis of a face-milled bevel pair: the machine settings from the design targets.

Nobody types machine settings for a design: :func:`synthesize` computes all four flanks'
settings from the blank (:class:`~.blank.SpiralBevelBlank`) and the design targets
(:class:`SynthesisTargets`): the gear flanks with exactly the design spiral and pressure angle at
their mean points, the pinion flanks for a predesigned parabolic transmission error of a chosen
amplitude, path direction and contact-ellipse length (Litvin & Zhang, NASA CR-4342, 1991;
Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed., 2004, ch. 9 and 21; Argyris,
Fuentes & Litvin, CMAME 191 (2002) 1057–1095).


"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import fsolve

from ...errors import DesignError, InputError, SolverError
from ..generation import generate
from ..surface import unit
from ..transforms import apply_points, apply_vectors
from .blank import ARCSEC
from .machine import MachineSettings, SpiralBevelSettings, fit_cutter, head_cutter, machine_motion
from .mesh_frame import gear_flank_design, mesh_transforms

__all__ = ["SynthesisTargets", "SynthesisReport", "synthesize"]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


@dataclass(frozen=True)
class SynthesisTargets:
    """Design targets of the local synthesis (Litvin & Zhang 1991).

    Parameters
    ----------
    te_amplitude_arcsec
        Predesigned parabolic TE amplitude over one mesh cycle (> 0, ≤ 60).
    path_angle_drive_deg, path_angle_coast_deg
        Direction η of the contact path on the gear flank at its mean point, measured from the
        tooth trace (toe → heel) towards the tip, in (−90, 90). The relative curvature along the
        path is ``((ω12 × n)·t)²/c`` (see :func:`_relative_curvature`), which vanishes for one
        direction (η ≈ +15° drive, −15° coast for the reference pair, where the path speed
        λ → ∞); the defaults −8° / +8° give a longitudinal path travelling ≈ 16 mm per mesh
        cycle on the 25.4 mm face (Argyris et al. 2002 prefer longitudinal paths with a
        predesigned parabolic TE).
    ellipse_major_axis_mm
        Major axis 2a of the instantaneous contact ellipse at the paint thickness (> 0).
        Default 6.0 mm (about 0.8 of the mean working depth measured along the flank, so that
        the ellipse, whose major axis runs across the profile for a longitudinal path, fits).
    paint_thickness_mm
        Elastic approach / marking-compound thickness δ, default 0.00632 mm.
    pinion_parabola_per_mm
        Parabolic blade coefficient ``a_c`` of the pinion blade (profile crowning), ≥ 0:
        the blade deviates by ``a_c s²`` (mm) from the straight blade at distance s from the
        mean-point height. Default 0.002 1/mm (order of magnitude of Argyris et al. 2002).
    symmetric_te
        Tune the third-order roll coefficient D of each pinion side by a rigid TCA of the mean
        tooth pair so that TE(−π/N1) = TE(+π/N1): local synthesis fixes the TE only to second
        order at the mean point, and the third-order term otherwise tilts the parabola (about
        ±3 arcsec for the reference pair). Costs ~10 s.
    """

    te_amplitude_arcsec: float = 8.0
    path_angle_drive_deg: float = -8.0
    path_angle_coast_deg: float = 8.0
    ellipse_major_axis_mm: float = 6.0
    paint_thickness_mm: float = 0.00632
    pinion_parabola_per_mm: float = 0.002
    symmetric_te: bool = True

    def __post_init__(self) -> None:
        if not 0.0 < self.te_amplitude_arcsec <= 60.0:
            raise InputError(
                "spiral_bevel.te_amplitude_arcsec", self.te_amplitude_arcsec, "in (0, 60]"
            )
        for name in ("path_angle_drive_deg", "path_angle_coast_deg"):
            v = getattr(self, name)
            if not -90.0 < v < 90.0:
                raise InputError(f"spiral_bevel.{name}", v, "in (-90, 90)")
        for name in ("ellipse_major_axis_mm", "paint_thickness_mm"):
            v = getattr(self, name)
            if not np.isfinite(v) or v <= 0:
                raise InputError(f"spiral_bevel.{name}", v, "> 0")
        if not 0.0 <= self.pinion_parabola_per_mm <= 0.05:
            raise InputError(
                "spiral_bevel.pinion_parabola_per_mm", self.pinion_parabola_per_mm, "in [0, 0.05]"
            )


# --------------------------------------------------------------------------------------------
# local synthesis
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SynthesisReport:
    """What the local synthesis aimed at and reached for one side (mesh frame, mean position).

    Attributes
    ----------
    side
        ``"drive"`` or ``"coast"``.
    sigma
        Sense of pinion rotation (+1: about +z_f) for this side to drive.
    m21_prime
        dm21/dφ1 giving the predesigned parabolic TE.
    point, normal
        Mean contact point (mm) and common normal (out of the gear tooth), mesh frame.
    path_direction
        Unit tangent t of the designed path on the gear at M.
    path_speed_mm_per_rad
        λ: speed of the contact point along t per rad of pinion rotation.
    relative_curvature
        ``A = S2 − S1`` (1/mm) in the tangent basis ``(t, n × t)``.
    target_pinion_shape, achieved_pinion_shape
        Pinion shape operator w.r.t. its outward normal, basis ``(t, n × t)`` (1/mm).
    gear_flank_angle, pinion_flank_angle
        Polar angles (rad) of the mean points of this side's gear and pinion flanks in their
        member frames (half tooth-thickness angles with the flank's sign).
    residual
        Final residuals of the settings equations (scaled meshing, curvature × Rm).
    """

    side: str
    sigma: float
    m21_prime: float
    point: Array
    normal: Array
    path_direction: Array
    path_speed_mm_per_rad: float
    relative_curvature: Array
    target_pinion_shape: Array
    achieved_pinion_shape: Array
    gear_flank_angle: float
    pinion_flank_angle: float
    residual: Array = field(repr=False)


def _shape_operator(env, basis: Array) -> Array:
    """Shape operator ``dn = S dr`` of an envelope point in the orthonormal tangent ``basis``."""
    S = basis @ _shape_operator_3d(env) @ basis.T
    return 0.5 * (S + S.T)


def _shape_operator_3d(env) -> Array:
    """``(3, 3)`` shape operator ``dn = S dr`` of an envelope point on its tangent plane."""
    R = np.stack([env.r_u, env.r_t], -1)  # (3, 2)
    N = np.stack([env.n_u, env.n_t], -1)
    return N @ np.linalg.pinv(R)


def _relative_curvature(
    blank, targets: SynthesisTargets, M: Array, n: Array, t_gear: Array, sigma: float,
    S2: Array, sigma_side: str,
) -> tuple[Array, Array, float, float]:  # fmt: skip
    """Litvin's local synthesis at the mean point: path tangent t, relative curvature A
    (basis ``(t, n × t)``), path speed λ, m'21 (mesh frame, module doc).

    Kinematics: ``ω1 = σ e_z`` (pinion axis through the origin), ``ω2 = −σ m21 e2`` about the gear
    axis through ``A2``, ``ω̇12 = σ m'21 e2``; ``v12 = ω1 × M − ω2 × (M − A2)`` (0 for
    intersecting axes, in the tangent plane along the tooth trace for a hypoid). ``S2``: the
    gear's ``(3, 3)`` shape operator at M (w.r.t. ``n``). With ``v_r2 = λ t``:

    * the meshing equation differentiated along the path gives λ:
      ``λ [(S2 t)·v12 + n·(ω12 × t)] + (ω2 × n)·v12 + n·(ω12 × (ω2 × (M − A2)))
      + n·(ω̇12 × (M − A2)) = 0``;
    * the normals' rates on both members, ``v_r1 = v_r2 − v12``, give
      ``A v_r1 = ω12 × n − S2 v12`` for ``A = S2 − S1``: two of its three entries, in the basis
      ``(ê, n × ê)``, ``ê = v_r1/|v_r1|``; the third from the contact ellipse,
      ``λ_min(A) = 2δ/a²``.

    For ``v12 = 0`` this is ``A t = (ω12 × n)/λ`` (Litvin & Zhang 1991).
    """
    N1 = blank.n1
    mp = -2.0 * targets.te_amplitude_arcsec * ARCSEC * (N1 / math.pi) ** 2
    A2, e2 = blank.gear_axis()
    r2 = M - A2
    w1 = sigma * np.array([0.0, 0.0, 1.0])
    w2 = -sigma * blank.m21 * e2
    w12 = w1 - w2
    dw12 = sigma * mp * e2  # −d(ω2)/dt
    v12 = np.cross(w1, M) - np.cross(w2, r2)
    field_name = "path_angle_drive_deg" if sigma_side == "drive" else "path_angle_coast_deg"
    eta_deg = getattr(targets, field_name)
    eta = math.radians(eta_deg)
    e_tr = unit(t_gear - n * np.dot(t_gear, n))
    e_pr = np.cross(n, e_tr)
    if np.dot(e_pr, _pitch_normal_mesh(M, A2, e2)) < 0:
        e_pr = -e_pr
    t = math.cos(eta) * e_tr + math.sin(eta) * e_pr
    q = np.cross(n, t)
    c = (
        np.dot(np.cross(w2, n), v12)
        + np.dot(n, np.cross(dw12, r2))
        + np.dot(n, np.cross(w12, np.cross(w2, r2)))
    )
    den = np.dot(S2 @ t, v12) + np.dot(n, np.cross(w12, t))
    if abs(den) < 1e-12:
        raise DesignError(f"{blank.field_prefix}.{field_name}", eta_deg, "another value")
    lam = -c / den
    x = lam * t - v12  # v_r1
    xn = float(np.linalg.norm(x))
    e = x / xn
    b = (np.cross(w12, n) - S2 @ v12) / xn
    p, r = np.dot(b, e), np.dot(b, np.cross(n, e))
    a = 0.5 * targets.ellipse_major_axis_mm
    k = 2.0 * targets.paint_thickness_mm / a**2
    if p <= k:
        raise DesignError(
            f"{blank.field_prefix}.{field_name}",
            eta_deg,
            "a path direction with a positive relative curvature along it",
            f"relative normal curvature along the path {p:.3e} 1/mm <= {k:.3e} needed by the "
            f"ellipse; change the path angle or the TE amplitude",
        )
    mu = k + r**2 / (p - k)
    f = np.cross(n, e)
    Q = np.array([[np.dot(t, e), np.dot(t, f)], [np.dot(q, e), np.dot(q, f)]])
    A = Q @ np.array([[p, r], [r, mu]]) @ Q.T
    return np.stack([t, q]), 0.5 * (A + A.T), float(lam), mp


def _pitch_normal_mesh(M: Array, A2: Array, e2: Array) -> Array:
    """Outward normal of the gear pitch cone at M (mesh frame): away from the gear axis
    (through the gear apex ``A2`` along ``e2``)."""
    r = M - A2
    radial = r - e2 * np.dot(r, e2)
    return unit(radial - r * np.dot(radial, r) / np.dot(r, r))


def synthesize(
    blank, targets: SynthesisTargets
) -> tuple[SpiralBevelSettings, dict[str, SynthesisReport]]:
    """Compute all machine settings from the blank and the targets (module doc).

    Returns the settings and, per side, the :class:`SynthesisReport`.
    Raises :class:`DesignError` if the synthesis has no solution.
    """
    g1, g2 = blank.pitch_angle(1), blank.pitch_angle(2)
    d1, d2 = blank.dedendum_angle(1), blank.dedendum_angle(2)
    gm1, gm2 = g1 - d1, g2 - d2
    mc1, mc2 = math.cos(d1) / math.sin(g1), math.cos(d2) / math.sin(g2)
    out: dict[str, MachineSettings] = {}
    reports: dict[str, SynthesisReport] = {}
    for side in ("drive", "coast"):
        # ---- gear flank: design normal at its mean point, cutter fitted, nominal roll
        M2, n2, t2, th2 = gear_flank_design(blank, side)
        blade2 = "outside" if side == "drive" else "inside"
        gs = fit_cutter("gear", side, blade2, M2, n2, blank.cutter_radius_mm, 0.0, gm2,
                        math.pi - th2, mc2, edge_radius=blank.edge_radius)  # fmt: skip
        out[f"gear_{side}"] = gs
        env2 = generate(head_cutter(gs), machine_motion(gs), 0.0, 0.0, 0.0, half_width=0.2)
        # ---- into the mesh frame
        # the placement at φ = 0 does not depend on the rotation sense (1.0 here)
        _, gear_f, e2 = mesh_transforms(blank, side, th2, 0.0, 1.0)
        G = gear_f(0.0)
        M = apply_points(G, M2)
        n = apply_vectors(G, n2)
        t_g = apply_vectors(G, t2)
        if not np.allclose(apply_points(G, env2.points), M, atol=1e-8):
            raise SolverError(f"spiral bevel gear {side}: the mean point is not generated")
        # driving sense: the pinion pushes the gear along -n; gear must turn with its torque
        A2 = blank.gear_axis()[0]
        sigma = float(np.sign(np.dot(np.cross(M - A2, n), e2)))
        if np.dot(np.cross(M, n), [0, 0, 1]) * sigma >= 0:
            log.warning("spiral bevel %s: pinion and gear torque senses disagree", side)
        env2_f = _rotate_env(env2, G[:3, :3])
        S2_3 = _shape_operator_3d(env2_f)
        basis, A, lam, mp = _relative_curvature(blank, targets, M, n, t_g, sigma, S2_3, side)
        S2 = _shape_operator(env2_f, basis)
        S_p_target = A - S2  # pinion, w.r.t. its outward normal −n
        # ---- pinion flank: pinion frame = mesh frame at φ1 = 0 (M at polar angle 0)
        blade1 = "inside" if side == "drive" else "outside"
        bpin = basis  # pinion frame == mesh frame here

        def settings1(x, side=side, blade1=blade1, M=M, n=n):
            rc, m, C, E = x
            return fit_cutter("pinion", side, blade1, M, -n, rc, targets.pinion_parabola_per_mm,
                              gm1, math.pi, m, C, E, edge_radius=blank.edge_radius)  # fmt: skip

        def residual(x, M=M, bpin=bpin, S_p_target=S_p_target, settings1=settings1):
            ms = settings1(x)
            mot = machine_motion(ms)
            tool = head_cutter(ms)
            ts = tool.evaluate(np.zeros(()), np.zeros(()))
            Mm, M1m, _ = mot.matrices(np.zeros(()))
            v = M1m[:3, :3] @ ts.r + M1m[:3, 3]
            nn = Mm[:3, :3] @ ts.n
            f = float(np.dot(nn, v)) / np.linalg.norm(M)
            env = generate(tool, mot, 0.0, 0.0, 0.0, half_width=0.1)
            S = _shape_operator(env, bpin)
            d = (S - S_p_target) * blank.mean_cone_distance(1)
            return np.array([f * 10.0, d[0, 0], d[0, 1], d[1, 1]])

        x0 = np.array([blank.cutter_radius_mm, mc1, 0.0, 0.0])
        x, info, ier, msg = fsolve(residual, x0, full_output=True, xtol=1e-12)
        res = residual(x)
        if ier != 1 or np.max(np.abs(res)) > 1e-7:
            raise DesignError(
                "spiral_bevel.synthesis_targets",
                targets,
                "targets the pinion settings can reach",
                f"local synthesis of the {side} side did not converge ({msg.strip()}); "
                f"residual {np.max(np.abs(res)):.2e}",
            )
        _check_reachable(side, x, blank, mc1, targets)
        ps = settings1(x)
        env1 = generate(head_cutter(ps), machine_motion(ps), 0.0, 0.0, 0.0, half_width=0.1)
        S_ach = _shape_operator(env1, bpin)
        # place the pinion flank at its half tooth angle (flank faces +θ or −θ)
        e_th = np.array([0.0, 1.0, 0.0])
        s_face = float(np.sign(np.dot(-n, e_th)))
        delta = s_face * blank.half_tooth_angle(1)
        ps = replace(ps, blank_phase_deg=ps.blank_phase_deg - math.degrees(delta))
        out[f"pinion_{side}"] = ps
        reports[side] = SynthesisReport(
            side=side,
            sigma=sigma,
            m21_prime=mp,
            point=M,
            normal=n,
            path_direction=basis[0],
            path_speed_mm_per_rad=lam,
            relative_curvature=A,
            target_pinion_shape=S_p_target,
            achieved_pinion_shape=S_ach,
            gear_flank_angle=th2,
            pinion_flank_angle=delta,
            residual=res,
        )
        log.info(
            "spiral bevel %s: r_c1 = %.3f mm, m_c1 = %.6f, C = %.5f, E_m1 = %.4f mm, "
            "lambda = %.2f mm/rad, residual %.1e",
            side, x[0], x[1], x[2], x[3], lam, np.max(np.abs(res)),
        )  # fmt: skip
    return SpiralBevelSettings(**out), reports


#: The pinion settings a local synthesis may end at, against the blank: the cutter radius within
#: this factor of the gear's, the ratio of roll of the nominal ``cos δ1 / sin γ1`` (the pinion's
#: rolling cone on the cradle) and the blank offset within the pinion's mean cone distance. The
#: reference pairs end at 0.90-0.94 of the cutter radius, 0.91-1.34 of the roll, blank offsets of
#: 0.10-0.35 of the cone distance; beyond the bounds the equations have a root that is no machine
#: setup (a 10/41 hypoid's blank: ratio of roll 153, blank offset 3.8 m, residual 1e-12).
REACH_FACTOR = 2.0


def _check_reachable(side: str, x: Array, blank, mc1: float, targets) -> None:
    """Refuse pinion settings ``x = (r_c1, m_c1, C, E_m1)`` outside :data:`REACH_FACTOR`'s
    bounds (a root of the synthesis equations that no generator cuts), naming them."""
    rc, m, _, E = (float(v) for v in x)
    r0, rm1 = float(blank.cutter_radius_mm), float(blank.mean_cone_distance(1))
    bad = []
    if not r0 / REACH_FACTOR <= rc <= r0 * REACH_FACTOR:
        bad.append(f"cutter radius {rc:.4g} mm (gear's {r0:.4g} mm)")
    if not mc1 / REACH_FACTOR <= m <= mc1 * REACH_FACTOR:
        bad.append(f"ratio of roll {m:.4g} (rolling cone's {mc1:.4g})")
    if abs(E) > rm1:
        bad.append(f"blank offset {E:.4g} mm (mean cone distance {rm1:.4g} mm)")
    if bad:
        raise DesignError(
            "spiral_bevel.synthesis_targets",
            targets,
            "targets the pinion settings can reach",
            f"local synthesis of the {side} side ended at settings no generator cuts: "
            + ", ".join(bad)
            + f" (bounds: within {REACH_FACTOR:g}x, the offset within the cone distance)",
        )


@dataclass(frozen=True)
class _Env:
    points: Array
    normals: Array
    r_u: Array
    r_t: Array
    n_u: Array
    n_t: Array


def _rotate_env(env, R: Array) -> _Env:
    return _Env(*(a @ R.T for a in (env.points, env.normals, env.r_u, env.r_t, env.n_u, env.n_t)))
