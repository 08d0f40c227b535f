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

fegear's value (:func:`fe_root_stress`): the largest maximum principal stress in the tension
fillet of the member's tooth with the load at its *loaded* outer point of single contact. At the
rigid one (D for the pinion, B for the gear, from the pitch-point angle of
:func:`fegear.validation.rows.pitch_point_phi1` and ``r_b1`` of contact travel per radian) the
FZG pair, which has no tip relief, already shares the load with the next pair (0.59 of the
torque on the pair: the teeth bend); the tooth carries the whole load highest on its flank a
little before, where its root stress peaks. ISO's σF0 is the stress of that load case (the whole
load at the outer point of single contact), so fegear's value is the peak over positions stepping
back from the rigid point, from the stress sectors under the solved cell forces
(:func:`fegear.pipeline.fields.displacements`). Measured (hybrid, 200 N·m): level 0 pinion 178.0 /
183.1 MPa (0.972), gear 169.0 / 177.7 MPa (0.951); level 1 178.6 (0.975) and 168.8 (0.950).

``python -m fegear.validation.iso6336_root`` prints the rows.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fegear.api import load_case
from fegear.errors import FegearError, InputError
from fegear.geometry.transforms import apply_points, inverse
from fegear.ltca import LTCAOptions, build_models, run_ltca
from fegear.pipeline.fields import displacements
from fegear.pipeline.pair import build_pair
from fegear.tca import TCA, TCAOptions, reference_phase
from fegear.tca.results import ARCSEC
from fegear.validation import Row, Value
from fegear.validation.rows import pitch_point_phi1

__all__ = [
    "CriticalSection",
    "RootFactors",
    "critical_section_check",
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


@dataclass(frozen=True)
class CriticalSection:
    """The 30° tangent section measured on a generated tooth (mm).

    Attributes
    ----------
    sFn
        Chord between the points of the two fillets whose tangent makes 30° with the tooth
        centre line.
    rhoF
        Radius of curvature of the fillet there (mean of both sides).
    hFe
        Distance along the centre line from that chord to the point where the load line
        through the profile point at ``den/2`` (normal to the involute, tangent to the base
        circle) crosses the centre line.
    """

    sFn: float
    rhoF: float
    hFe: float


def critical_section_check(member, den: float, n: int = 4001) -> CriticalSection:
    """:class:`CriticalSection` of tooth 0 of an involute spur ``member`` measured on its
    generated transverse profile (fillet: the envelope of the rack tip circle; flank: the
    involute), independently of the ISO 6336-3 closed forms: ``n`` exact points of each side's
    fillet at mid-face, tangent angles and curvature from their finite differences
    (``np.gradient``, second order), the 30° points by linear interpolation; ``den`` (mm) the
    diameter of the load point."""
    b = member.boundaries("drive")
    u = np.linspace(b.u_root, b.u_fillet, n)
    pts = {}
    for side in ("drive", "coast"):
        bs = member.boundaries(side)
        us = np.linspace(bs.u_root, bs.u_fillet, n)
        P, _ = member.point_normal(side, us, np.zeros_like(us))
        pts[side] = P[:, :2]
    # tooth centre line: the bisector of the two flanks (symmetric tooth)
    mid = pts["drive"][-1] + pts["coast"][-1]
    axis = mid / np.linalg.norm(mid)
    perp = np.array([-axis[1], axis[0]])
    found = {}
    for side, P in pts.items():
        d = np.gradient(P, u, axis=0)
        dd = np.gradient(d, u, axis=0)
        tang = d / np.linalg.norm(d, axis=1, keepdims=True)
        ang = np.degrees(np.arccos(np.abs(tang @ axis)))  # angle to the centre line
        i = int(np.flatnonzero(np.diff(np.sign(ang - 30.0)))[0])
        w = (30.0 - ang[i]) / (ang[i + 1] - ang[i])
        x = P[i] + w * (P[i + 1] - P[i])
        kap = np.abs(d[:, 0] * dd[:, 1] - d[:, 1] * dd[:, 0]) / np.linalg.norm(d, axis=1) ** 3
        found[side] = (x, 1.0 / ((1 - w) * kap[i] + w * kap[i + 1]))
    (xd, rd), (xc, rc) = found["drive"], found["coast"]
    sFn = float(abs((xd - xc) @ perp))
    h_chord = float(0.5 * (xd + xc) @ axis)
    # load point: the drive flank at radius den/2; load line along the involute normal
    rb = float(member.r_b)
    r = 0.5 * den
    bd = member.boundaries("drive")
    uu = np.linspace(bd.u_fillet, bd.u_tip, 4001)
    F, N = member.point_normal("drive", uu, np.zeros_like(uu))
    j = int(np.argmin(np.abs(np.hypot(F[:, 0], F[:, 1]) - r)))
    p0, nrm = F[j, :2], N[j, :2]
    # p0 + t nrm on the centre line: (p0 + t nrm) · perp = 0
    t = -(p0 @ perp) / (nrm @ perp)
    h_load = float((p0 + t * nrm) @ axis)
    if not rb < r:
        raise InputError("den", den, f"above the base diameter {2 * rb:.3f} mm")
    return CriticalSection(sFn=sFn, rhoF=0.5 * (rd + rc), hFe=h_load - h_chord)


def _design(member):
    d = getattr(member, "design", None)
    if d is None or getattr(d, "helix_angle_deg", 0.0) != 0.0:
        raise InputError("pair", type(member).__name__, "a spur (involute, β = 0) member")
    return d


def fzg_reference(case=None) -> dict[str, tuple[RootFactors, float]]:
    """``{"pinion": (factors, σF0), "gear": (factors, σF0)}`` (MPa) of a spur case (default
    ``cases/fzg_spur.toml``) at its torque: ``Ft = 2 T2 / d2``."""
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

    return load_case(Path(__file__).resolve().parents[2] / "cases" / "fzg_spur.toml")


def single_contact_phi1(pair) -> dict[str, float]:
    """``{"pitch": φ_C, "pinion": φ_D, "gear": φ_B}`` (rad): pinion angles at which the rigid
    contact of one pair lies at the outer point of single contact of the pinion (D, ``p_b``
    beyond the start of
    contact A) and of the gear (B, ``p_b`` before the end E), from the pitch point angle
    (:func:`fegear.validation.rows.pitch_point_phi1`) and ``r_b1`` of travel per radian; the sense
    of travel is read from the TCA (the pinion contact radius grows towards the pinion tip)."""
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
        "pitch": phi_c,
        "pinion": phi_c + sense * (L_A + pb - L_C) / rb1,
        "gear": phi_c + sense * (L_E - pb - L_C) / rb1,
    }


@dataclass(frozen=True)
class FERootStress:
    """fegear's root stress of one member's tooth with the load at its outer point of single
    contact.

    Under load the next pair takes over before the rigid transfer point (the teeth bend; the
    FZG pair has no tip relief): at the rigid φ_D the pair carries about 0.6 of the torque. The
    loaded outer point of single contact is where the tooth carries the whole load highest on
    its flank, i.e. where its root stress peaks; it is found on ``n_window`` positions stepping
    ``step_deg`` back from the rigid point (the peak is the largest of them).

    Attributes
    ----------
    member, fidelity, level
        Which member, how it ran.
    tooth
        The member tooth read (the pair in single contact at the start of the window).
    phi1_deg
        Pinion angle of the peak (deg).
    tension_MPa
        Largest maximum principal stress in its tension fillet there.
    load_share
        Torque share of the pair there.
    rigid_phi1_deg, rigid_tension_MPa, rigid_load_share
        The same at the rigid outer point of single contact.
    fillet_mm
        Fillet element size of the stress sector.
    seconds
        Wall time of the analysis and the stress solves (both members).
    """

    member: str
    fidelity: str
    level: int
    tooth: int
    phi1_deg: float
    tension_MPa: float
    load_share: float
    rigid_phi1_deg: float
    rigid_tension_MPa: float
    rigid_load_share: float
    fillet_mm: float
    seconds: float


def fe_root_stress(
    fidelity: str = "hybrid",
    level: int = 0,
    case=None,
    fillet_modules: float | None = None,
    n_window: int = 9,
    step_deg: float = 0.25,
):
    """fegear's root stress of the pinion near φ_D and of the gear near φ_B
    (:func:`single_contact_phi1`, :class:`FERootStress`): one loaded analysis over both windows,
    then one stress solve per member. Returns ``({"pinion": …, "gear": …}, run)`` with
    ``run = (pair, asm, models, cycle, phi2)``."""
    t0 = time.perf_counter()
    case = case or _fzg_case()
    pair = build_pair(case)
    where = single_contact_phi1(pair)
    phi_c = where["pitch"]
    steps = np.radians(step_deg) * np.arange(n_window)
    windows = {}
    for name in ("pinion", "gear"):
        phi = where[name]
        inward = 1.0 if phi_c > phi else -1.0  # towards the pitch point
        windows[name] = phi + inward * steps[::-1]  # innermost first, the rigid point last
    phi1 = np.concatenate([windows["pinion"], windows["gear"]])
    opt = LTCAOptions(level=level, fidelity=fidelity, n_teeth=case.n_teeth, E_MPa=case.E_MPa,
                      nu=case.nu, backend=case.backend, workers=1)  # fmt: skip
    models = build_models(pair.pinion, pair.gear, pair.assembly, opt)
    cyc = run_ltca(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, opt, phi1=phi1,
                   models=models)  # fmt: skip
    if cyc.zone is not None and cyc.zone is not models.zone:
        models = build_models(pair.pinion, pair.gear, pair.assembly, opt, zone=cyc.zone)
    asm = pair.assembly.with_phase2(cyc.phase2)
    phi2 = asm.ratio * cyc.phi1 + cyc.te_unloaded_arcsec * ARCSEC
    fields = displacements(pair, asm, models, cyc, phi2, fillet_modules)
    out = {}
    for k, name in enumerate(("pinion", "gear")):
        mf = fields[k]
        idx = np.arange(n_window) + k * n_window
        first = cyc.positions[idx[0]]
        q0 = max(first.pairs, key=lambda q: q.force_N)
        tooth = int(q0.k if name == "pinion" else q0.j)

        def share(i: int, name=name, tooth=tooth) -> float:
            qs = [q for q in cyc.positions[i].pairs if (q.k if name == "pinion" else q.j) == tooth]
            return float(qs[0].load_share) if qs else 0.0

        s = mf.root_series(tooth)[idx]
        best = int(idx[int(np.nanargmax(s))])
        last = int(idx[-1])
        out[name] = FERootStress(
            member=name,
            fidelity=fidelity,
            level=level,
            tooth=tooth,
            phi1_deg=math.degrees(cyc.phi1[best]),
            tension_MPa=float(np.nanmax(s)),
            load_share=share(best),
            rigid_phi1_deg=math.degrees(cyc.phi1[last]),
            rigid_tension_MPa=float(s[-1]),
            rigid_load_share=share(last),
            fillet_mm=float(mf.fillet_mm),
            seconds=time.perf_counter() - t0,
        )
    return out, (pair, asm, models, cyc, phi2)


def rows(levels: tuple[int, ...] = (0, 1), fidelity: str = "hybrid", case=None) -> list:
    """The root-stress rows of ``docs/validation.md`` (:class:`fegear.validation.Row`): per
    member, ISO 6336-3 σF0 at the outer point of single contact against fegear's tension-fillet
    maximum principal stress at ``fidelity`` and each of ``levels``."""
    case = case or _fzg_case()
    ref = fzg_reference(case)
    runs = [fe_root_stress(fidelity, lv, case)[0] for lv in levels]
    T = case.torque2_Nm
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
                    f"loaded outer point of single contact φ1 = {r[name].phi1_deg:.2f}° (share "
                    f"{r[name].load_share:.3f}); at the rigid one ({r[name].rigid_phi1_deg:.2f}°, "
                    f"share {r[name].rigid_load_share:.3f}) {r[name].rigid_tension_MPa:.1f} MPa; "
                    f"fillet elements {r[name].fillet_mm:.3g} mm"
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
