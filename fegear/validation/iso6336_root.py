r"""ISO 6336-3 method B nominal tooth-root stress σF0 and fegear's FE root stress against it.

Reference (ISO 6336-3:2006, clauses 5-7; spur gears, ``β = 0`` so the virtual gear is the gear
itself, ``Yβ = 1``):

.. math::

    \sigma_{F0} = \frac{F_t}{b\, m_n}\, Y_F\, Y_S\, Y_\beta, \qquad
    F_t = \frac{2 T}{d}\ (d = m z \text{ the reference diameter}).

*Critical section (§6.2, the 30° tangent).* With the basic rack's dedendum ``h_fP``, tip radius
``ρ_fP`` and protuberance ``s_pr`` (0 here), for an external gear (``T = π/3``):

.. math::

    E = \frac{\pi}{4} m_n - h_{fP}\tan\alpha_n + \frac{s_{pr}}{\cos\alpha_n}
        - (1-\sin\alpha_n)\frac{\rho_{fP}}{\cos\alpha_n},\quad
    G = \frac{\rho_{fP}}{m_n} - \frac{h_{fP}}{m_n} + x,\quad
    H = \frac{2}{z}\Big(\frac{\pi}{2} - \frac{E}{m_n}\Big) - T,

    \vartheta = \frac{2G}{z}\tan\vartheta - H \ (\text{fixed point from } \vartheta = \pi/6),

    \frac{s_{Fn}}{m_n} = z \sin\Big(\frac{\pi}{3} - \vartheta\Big)
        + \sqrt3\Big(\frac{G}{\cos\vartheta} - \frac{\rho_{fP}}{m_n}\Big),\quad
    \frac{\rho_F}{m_n} = \frac{\rho_{fP}}{m_n}
        + \frac{2G^2}{\cos\vartheta\,(z\cos^2\vartheta - 2G)}.

*Bending moment arm (§6.3, load at the outer point of single tooth contact D).*

.. math::

    \frac{d_{en}}{2} = \sqrt{\Big(\sqrt{r_a^2 - r_b^2} - p_b(\varepsilon_\alpha - 1)\Big)^2
        + r_b^2},
    \quad \alpha_{en} = \arccos\frac{d_b}{d_{en}},\quad
    \gamma_e = \frac{\pi/2 + 2x\tan\alpha_n}{z} + \operatorname{inv}\alpha_n
        - \operatorname{inv}\alpha_{en},\quad \alpha_{Fen} = \alpha_{en} - \gamma_e,

    \frac{h_{Fe}}{m_n} = \frac12\Big[(\cos\gamma_e - \sin\gamma_e\tan\alpha_{Fen})\frac{d_{en}}{m_n}
        - z\cos\Big(\frac{\pi}{3}-\vartheta\Big) - \frac{G}{\cos\vartheta}
        + \frac{\rho_{fP}}{m_n}\Big].

*Factors (§6.1, §7.1).*

.. math::

    Y_F = \frac{6\,(h_{Fe}/m_n)\cos\alpha_{Fen}}{(s_{Fn}/m_n)^2\cos\alpha_n},\qquad
    Y_S = (1.2 + 0.13 L)\, q_s^{1/(1.21 + 2.3/L)},\quad L = \frac{s_{Fn}}{h_{Fe}},\
    q_s = \frac{s_{Fn}}{2\rho_F}.

Every length uses the pair as fegear models it (tip radii of the members, the rack of their
generation), so the reference and the FE see the same teeth. :func:`critical_section_check`
recomputes ``s_Fn``, ``ρ_F`` and ``h_Fe`` from the generated fillet itself (the envelope of the
rack tip circle, :mod:`fegear.geometry.involute`) as a check of the closed forms.

fegear's value (:func:`fe_root_stress`): the loaded analysis at the pinion angle where the
rigid contact of one pair is at the outer point of single contact of the member (D for the pinion,
B for the gear, from the pitch-point angle of :func:`fegear.validation.rows.pitch_point_phi1`
and ``r_b1`` of contact travel per radian), then the stress sectors under its cell forces
(:func:`fegear.io.gear_run.displacements`): the largest maximum principal stress in the tension
fillet of that member's loaded tooth.

``python -m fegear.validation.iso6336_root`` prints the rows.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fegear.errors import FegearError, InputError

__all__ = [
    "RootFactors",
    "root_factors",
    "nominal_root_stress",
    "contact_ratio",
    "FERootStress",
    "single_contact_phi1",
    "fe_root_stress",
    "fzg_reference",
    "rows",
    "COMMAND",
]

#: The command that reproduces the rows.
COMMAND = "python -m fegear.validation.iso6336_root"
TEST = "tests/test_root_stress.py::test_fzg_root_stress_within_15_percent_of_iso"


def _inv(a: float) -> float:
    return math.tan(a) - a


@dataclass(frozen=True)
class RootFactors:
    """ISO 6336-3 method B quantities of one gear (lengths mm, angles rad).

    Attributes
    ----------
    z, mn, x
        Teeth, normal module, profile shift coefficient.
    theta
        Angle ϑ of the 30° tangent iteration.
    sFn, rhoF, hFe
        Critical-section chord, fillet radius there, bending moment arm.
    den, alpha_Fen
        Diameter of the outer point of single contact and the load angle there.
    YF, YS
        Form factor and stress-correction factor.
    """

    z: int
    mn: float
    x: float
    theta: float
    sFn: float
    rhoF: float
    hFe: float
    den: float
    alpha_Fen: float
    YF: float
    YS: float

    @property
    def qs(self) -> float:
        return self.sFn / (2.0 * self.rhoF)


def contact_ratio(ra1: float, rb1: float, ra2: float, rb2: float, a_w: float, pb: float) -> float:
    """Transverse contact ratio of an external spur pair (mm):
    ``ε_α = (√(ra1²−rb1²) + √(ra2²−rb2²) − a_w sin α_w) / p_b``, ``cos α_w = (rb1 + rb2)/a_w``."""
    alpha_w = math.acos((rb1 + rb2) / a_w)
    g = math.sqrt(ra1**2 - rb1**2) + math.sqrt(ra2**2 - rb2**2) - a_w * math.sin(alpha_w)
    return g / pb


def root_factors(
    z: int,
    mn: float,
    alpha_n_deg: float,
    x: float,
    hfP: float,
    rhofP: float,
    ra: float,
    eps_alpha: float,
    spr: float = 0.0,
) -> RootFactors:
    """:class:`RootFactors` of an external spur gear (module docstring).

    Parameters
    ----------
    z, mn, alpha_n_deg, x
        Teeth, module (mm), pressure angle (deg), profile shift coefficient.
    hfP, rhofP, spr
        Basic rack dedendum, tip radius and protuberance (mm).
    ra
        Tip radius of the gear (mm).
    eps_alpha
        Transverse contact ratio of the pair.
    """
    for name, v in (("mn", mn), ("hfP", hfP), ("rhofP", rhofP), ("ra", ra), ("eps", eps_alpha)):
        if not (math.isfinite(v) and v > 0.0):
            raise InputError(name, v, "a finite number > 0")
    if z < 5:
        raise InputError("z", z, "an external gear with at least 5 teeth")
    an = math.radians(alpha_n_deg)
    E = math.pi / 4 * mn - hfP * math.tan(an) + spr / math.cos(an)
    E -= (1.0 - math.sin(an)) * rhofP / math.cos(an)
    G = rhofP / mn - hfP / mn + x
    H = 2.0 / z * (math.pi / 2 - E / mn) - math.pi / 3
    th = math.pi / 6
    for _ in range(200):
        new = 2.0 * G / z * math.tan(th) - H
        if abs(new - th) < 1e-14:
            th = new
            break
        th = new
    else:
        raise FegearError(f"ISO 6336-3 ϑ iteration did not converge (z = {z}, x = {x})")
    sFn = mn * (z * math.sin(math.pi / 3 - th) + math.sqrt(3) * (G / math.cos(th) - rhofP / mn))
    rhoF = mn * (rhofP / mn + 2 * G**2 / (math.cos(th) * (z * math.cos(th) ** 2 - 2 * G)))
    d = mn * z
    rb = 0.5 * d * math.cos(an)
    pb = math.pi * mn * math.cos(an)
    den = 2.0 * math.sqrt((math.sqrt(ra**2 - rb**2) - pb * (eps_alpha - 1.0)) ** 2 + rb**2)
    a_en = math.acos(2 * rb / den)
    ge = (0.5 * math.pi + 2 * x * math.tan(an)) / z + _inv(an) - _inv(a_en)
    a_Fen = a_en - ge
    hFe = (
        0.5
        * mn
        * (
            (math.cos(ge) - math.sin(ge) * math.tan(a_Fen)) * den / mn
            - z * math.cos(math.pi / 3 - th)
            - G / math.cos(th)
            + rhofP / mn
        )
    )
    YF = 6.0 * (hFe / mn) * math.cos(a_Fen) / ((sFn / mn) ** 2 * math.cos(an))
    L = sFn / hFe
    qs = sFn / (2.0 * rhoF)
    YS = (1.2 + 0.13 * L) * qs ** (1.0 / (1.21 + 2.3 / L))
    return RootFactors(z, mn, x, th, sFn, rhoF, hFe, den, a_Fen, YF, YS)


def nominal_root_stress(
    Ft: float, b: float, mn: float, f: RootFactors, Ybeta: float = 1.0
) -> float:
    """``σF0 = Ft/(b mn) YF YS Yβ`` (MPa; ``Ft`` N, ``b``, ``mn`` mm)."""
    return Ft / (b * mn) * f.YF * f.YS * Ybeta


def _design(member):
    d = getattr(member, "design", None)
    if d is None or getattr(d, "helix_angle_deg", 0.0) != 0.0:
        raise InputError("pair", type(member).__name__, "a spur (involute, β = 0) member")
    return d


def fzg_reference(case=None) -> dict[str, tuple[RootFactors, float]]:
    """``{"pinion": (factors, σF0), "gear": (factors, σF0)}`` (MPa) of a spur case (default
    ``cases/fzg_spur.toml``) at its torque: ``Ft = 2 T2 / d2``."""
    from fegear.io.gear_case import build_pair

    case = case or _fzg_case()
    pair = build_pair(case)
    p, g = pair.pinion, pair.gear
    dp, dg = _design(p), _design(g)
    a_w = float(pair.assembly.axes_distance())
    pb = math.pi * dp.module_mm * math.cos(math.radians(dp.pressure_angle_deg))
    eps = contact_ratio(p.r_a, p.r_b, g.r_a, g.r_b, a_w, pb)
    Ft = 2.0 * case.torque2_Nmm / (dg.module_mm * dg.n_teeth)
    out = {}
    for name, m, d in (("pinion", p, dp), ("gear", g, dg)):
        f = root_factors(d.n_teeth, d.module_mm, d.pressure_angle_deg, d.profile_shift,
                         d.dedendum_coeff * d.module_mm, d.rack_tip_radius_coeff * d.module_mm,
                         float(m.r_a), eps)  # fmt: skip
        out[name] = (f, nominal_root_stress(Ft, float(d.face_width_mm), d.module_mm, f))
    return out


def _fzg_case():
    from pathlib import Path

    from fegear.api import load_case

    return load_case(Path(__file__).resolve().parents[2] / "cases" / "fzg_spur.toml")


def single_contact_phi1(pair) -> dict[str, float]:
    """``{"pinion": φ_D, "gear": φ_B}`` (rad): pinion angles at which the rigid contact of one pair
    lies at the outer point of single contact of the pinion (D, ``p_b`` beyond the start of
    contact A) and of the gear (B, ``p_b`` before the end E), from the pitch point angle
    (:func:`fegear.validation.rows.pitch_point_phi1`) and ``r_b1`` of travel per radian; the sense
    of travel is read from the TCA (the pinion contact radius grows towards the pinion tip)."""
    from fegear.geometry.transforms import apply_points, inverse
    from fegear.tca import TCA, TCAOptions, reference_phase
    from fegear.validation.rows import pitch_point_phi1

    p, g, asm = pair.pinion, pair.gear, pair.assembly
    phi_c = pitch_point_phi1(pair)
    a_w = float(asm.axes_distance())
    rb1, rb2 = float(p.r_b), float(g.r_b)
    alpha_w = math.acos((rb1 + rb2) / a_w)
    pb = 2 * math.pi * rb1 / asm.n1
    L_C = rb1 * math.tan(alpha_w)  # from the pinion's base tangent point T1 along the line
    L_A = a_w * math.sin(alpha_w) - math.sqrt(g.r_a**2 - rb2**2)
    L_E = math.sqrt(p.r_a**2 - rb1**2)
    opt = TCAOptions()
    asm = asm.with_phase2(reference_phase(p, g, asm, opt))
    tca = TCA(p, g, asm, opt)
    d = 0.2 * pb / rb1
    radii = []
    for phi in (phi_c - d, phi_c + d):
        pos = tca.positions(np.array([phi]), with_grids=False)[0]
        x = apply_points(inverse(asm.placement1(phi)), np.asarray(pos.points))
        r = np.hypot(x[:, 0], x[:, 1])
        ok = pos.pair_valid & (pos.backlash_mm < 1e-6)
        L = np.sqrt(np.maximum(r[ok] ** 2 - rb1**2, 0.0))
        radii.append(float(L[np.argmin(np.abs(L - L_C))]))
    sense = 1.0 if radii[1] > radii[0] else -1.0
    return {
        "pinion": phi_c + sense * (L_A + pb - L_C) / rb1,
        "gear": phi_c + sense * (L_E - pb - L_C) / rb1,
    }


@dataclass(frozen=True)
class FERootStress:
    """fegear's root stress of one member's loaded tooth at one pinion angle.

    Attributes
    ----------
    member, fidelity, level
        Which member, how it ran.
    phi1_deg
        Pinion angle (deg).
    tooth
        The member tooth read (the most loaded pair's).
    tension_MPa
        Largest maximum principal stress in its tension fillet.
    load_share
        Torque share of that pair.
    fillet_mm
        Fillet element size of the stress sector.
    seconds
        Wall time (analysis and stress solve).
    """

    member: str
    fidelity: str
    level: int
    phi1_deg: float
    tooth: int
    tension_MPa: float
    load_share: float
    fillet_mm: float
    seconds: float


def fe_root_stress(
    fidelity: str = "hybrid",
    level: int = 0,
    case=None,
    fillet_modules: float | None = None,
) -> dict[str, FERootStress]:
    """fegear's root stress of the pinion at φ_D and of the gear at φ_B
    (:func:`single_contact_phi1`): one loaded position each, then the stress sectors."""
    from fegear.io.gear_case import build_pair
    from fegear.io.gear_run import displacements
    from fegear.ltca import LTCAOptions, build_models, run_ltca
    from fegear.tca.results import ARCSEC

    case = case or _fzg_case()
    pair = build_pair(case)
    where = single_contact_phi1(pair)
    opt = LTCAOptions(level=level, fidelity=fidelity, n_teeth=case.n_teeth, E_MPa=case.E_MPa,
                      nu=case.nu, backend=case.backend, workers=1)  # fmt: skip
    out = {}
    for k, name in enumerate(("pinion", "gear")):
        t0 = time.perf_counter()
        models = build_models(pair.pinion, pair.gear, pair.assembly, opt)
        cyc = run_ltca(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, opt,
                       phi1=np.array([where[name]]), models=models)  # fmt: skip
        if cyc.zone is not None and cyc.zone is not models.zone:
            models = build_models(pair.pinion, pair.gear, pair.assembly, opt, zone=cyc.zone)
        asm = pair.assembly.with_phase2(cyc.phase2)
        phi2 = asm.ratio * cyc.phi1 + cyc.te_unloaded_arcsec * ARCSEC
        mf = displacements(pair, asm, models, cyc, phi2, fillet_modules)[k]
        pos = cyc.positions[0]
        q = max(pos.pairs, key=lambda q: q.force_N)
        tooth = q.k if name == "pinion" else q.j
        r = next(r for r in mf.root[0] if r.tooth == tooth)
        out[name] = FERootStress(
            member=name,
            fidelity=fidelity,
            level=level,
            phi1_deg=math.degrees(where[name]),
            tooth=int(tooth),
            tension_MPa=r.tension_MPa,
            load_share=float(q.load_share),
            fillet_mm=float(mf.fillet_mm),
            seconds=time.perf_counter() - t0,
        )
    return out


def rows(levels: tuple[int, ...] = (0, 1), fidelity: str = "hybrid", case=None) -> list:
    """The root-stress rows of ``docs/validation.md`` (:class:`fegear.validation.Row`): per
    member, ISO 6336-3 σF0 at the outer point of single contact against fegear's tension-fillet
    maximum principal stress at ``fidelity`` and each of ``levels``."""
    from fegear.validation import Row, Value

    case = case or _fzg_case()
    ref = fzg_reference(case)
    runs = [fe_root_stress(fidelity, lv, case) for lv in levels]
    T = case.torque2_Nmm / 1000.0
    out = []
    for name, point in (("pinion", "D"), ("gear", "B")):
        f, s0 = ref[name]
        vals = tuple(
            Value(
                fidelity=fidelity,
                level=r[name].level,
                value=r[name].tension_MPa,
                seconds=r[name].seconds,
                note=(
                    f"φ1 = {r[name].phi1_deg:.3f}°, tooth {r[name].tooth:+d}, load share "
                    f"{r[name].load_share:.3f}, fillet elements {r[name].fillet_mm:.3g} mm"
                ),
            )
            for r in runs
        )
        out.append(
            Row(
                key=f"iso6336_3_root_stress_{name}",
                check=(
                    f"FZG type C, {T:g} N·m on the gear: {name} root stress with the load at its "
                    f"outer point of single tooth contact ({point})"
                ),
                quantity=f"{name} σF, largest max principal stress in the tension fillet (MPa)",
                reference=s0,
                reference_text=(
                    f"ISO 6336-3 method B σF0 = Ft/(b mn) YF YS Yβ: YF {f.YF:.3f}, YS {f.YS:.3f} "
                    f"(sFn {f.sFn:.3f} mm, ρF {f.rhoF:.3f} mm, hFe {f.hFe:.3f} mm, 30° tangent), "
                    "Yβ 1"
                ),
                values=vals,
                tolerance="±15 % (ISO's form and stress-correction factors are approximations)",
                command=COMMAND,
                test=TEST,
            )
        )
    return out


def _main() -> None:  # pragma: no cover  (the command of the rows)
    for r in rows():
        print(f"{r.key}: ISO σF0 {r.reference:.1f} MPa ({r.reference_text})")
        for v in r.values:
            print(f"  {v.fidelity} level {v.level}: {v.value:.1f} MPa, ratio "
                  f"{r.ratio(v):.3f} ({v.note}; {v.seconds:.0f} s)")  # fmt: skip


if __name__ == "__main__":  # pragma: no cover
    _main()
