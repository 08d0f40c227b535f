r"""Closed-form references from the gear standards for cylindrical (spur/helical) pairs.

Nothing here calls the solver: these are the independent numbers the validation page
(``docs/validation.md``) sets the fegear results against. Units: mm, N, MPa, N·mm; stiffness
in N/(mm·µm) as ISO writes it; angles in degrees at the interface, radians inside.

Involute geometry of an external pair (ISO 21771:2007, §4–5)
------------------------------------------------------------
Transverse pressure angle :math:`\tan\alpha_t = \tan\alpha_n / \cos\beta`, base helix angle
:math:`\tan\beta_b = \tan\beta\cos\alpha_n`, reference radius :math:`r = z m_n / (2\cos\beta)`,
base radius :math:`r_b = r\cos\alpha_t`. The working transverse pressure angle of a pair with
profile shifts :math:`x_1, x_2` (zero backlash) solves

.. math:: \operatorname{inv}\alpha_{wt} = \operatorname{inv}\alpha_t
          + 2\,\frac{x_1 + x_2}{z_1 + z_2}\tan\alpha_n, \qquad
          \operatorname{inv}\alpha = \tan\alpha - \alpha,

and the centre distance is :math:`a_w = (r_{b1} + r_{b2})/\cos\alpha_{wt}`. At the pitch point C
the profiles' radii of curvature are :math:`\rho_{Ci} = r_{bi}\tan\alpha_{wt}` (the distances from
C to the tangency points of the line of action on the base circles).

Line Hertz at the pitch point (Johnson 1985, §4.3; ISO 6336-2:2006, §5)
----------------------------------------------------------------------
Two parallel cylinders of radii :math:`\rho_{C1}, \rho_{C2}` under the normal load per unit
length :math:`w = F_{bn}/b` carry the peak pressure

.. math:: p_H = \sqrt{\frac{w E^*}{\pi R}}, \qquad \frac1R = \frac1{\rho_{C1}} + \frac1{\rho_{C2}},
          \qquad \frac1{E^*} = \frac{1-\nu_1^2}{E_1} + \frac{1-\nu_2^2}{E_2},

(:func:`fegear.mechanics.hertz_closed_form.hertz_line`). For a spur pair whose gear carries the
torque :math:`T_2`
alone (single-pair zone) the normal load is :math:`F_{bn} = T_2 / r_{b2}` along the line of
action. ISO 6336-2 writes the same number as the nominal contact stress

.. math:: \sigma_{H0} = Z_H Z_E \sqrt{\frac{F_t}{d_1 b}\,\frac{u + 1}{u}}, \qquad
          Z_H = \sqrt{\frac{2\cos\beta_b\cos\alpha_{wt}}{\cos^2\alpha_t\sin\alpha_{wt}}}, \qquad
          Z_E = \sqrt{\frac{1}{\pi\left(\frac{1-\nu_1^2}{E_1} + \frac{1-\nu_2^2}{E_2}\right)}},

with :math:`F_t = T_2/r_2` the tangential load at the reference circle, :math:`d_1 = 2 r_1`,
:math:`u = z_2/z_1`, and the contact-ratio factor :math:`Z_\varepsilon = 1` (one pair carries
the load at the pitch point; ISO's :math:`Z_\varepsilon < 1` averages over the path of a spur
pair with :math:`\varepsilon_\alpha < 2`). The two forms are algebraically the same (spur:
:func:`iso6336_2_sigma_H0` equals :func:`pitch_point_line_hertz` to round-off).

Single stiffness (ISO 6336-1:2006, §9, Method B; DIN 3990-1:1987, §10)
---------------------------------------------------------------------
The single stiffness :math:`c'` is the load per unit face width along the line of action that
deflects one tooth pair by 1 µm in that direction (bending, shear and contact flattening of both
teeth, and the rim/body under them), at its maximum for a single pair (near the pitch point).
Method B gives the theoretical single stiffness of solid disc gears with the standard basic rack
as a series fitted to Weber/Banaschek's deflections,

.. math:: c'_{th} = \frac1{q'}, \qquad
          q' = C_1 + \frac{C_2}{z_{n1}} + \frac{C_3}{z_{n2}} + C_4 x_1 + C_5\frac{x_1}{z_{n1}}
               + C_6 x_2 + C_7\frac{x_2}{z_{n2}} + C_8 x_1^2 + C_9 x_2^2 \quad
          [\text{mm·µm/N}],

with :math:`C_1 … C_9` = 0.04723, 0.15551, 0.25791, −0.00635, −0.11654, −0.00193, −0.24188,
0.00529, 0.00182 and the virtual tooth numbers :math:`z_n = z/(\cos^2\beta_b\cos\beta)`
(valid for :math:`x_1 \ge x_2`, :math:`-0.5 \le x_1 + x_2 \le 2`, steel on steel, specific load
:math:`F_t K_A / b \ge 100` N/mm). The single stiffness of real gears is then

.. math:: c' = c'_{th}\, C_M\, C_R\, C_B \cos\beta,

:math:`C_M = 0.8` the correction from the theoretical to the measured stiffness of solid disc
gears, :math:`C_R` the gear blank factor (1 for solid discs), and the basic rack factor
:math:`C_B = [1 + 0.5(1.2 - h_{fP}/m_n)][1 - 0.02(20° - \alpha_{Pn})]` (:math:`h_{fP}` the
dedendum of the basic rack, :math:`\alpha_{Pn}` its pressure angle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from fegear.errors import InputError
from fegear.mechanics.hertz_closed_form import effective_modulus, hertz_line

__all__ = [
    "CTH_COEFFICIENTS",
    "PitchPointHertz",
    "SingleStiffness",
    "basic_rack_factor",
    "involute",
    "inverse_involute",
    "iso6336_2_sigma_H0",
    "pitch_point_line_hertz",
    "single_stiffness",
    "theoretical_single_stiffness",
    "virtual_teeth",
    "working_pressure_angle",
]

#: ISO 6336-1:2006 Method B (and DIN 3990-1:1987): coefficients C1 … C9 of the series for the
#: theoretical single stiffness (q' in mm·µm/N).
CTH_COEFFICIENTS: tuple[float, ...] = (
    0.04723,
    0.15551,
    0.25791,
    -0.00635,
    -0.11654,
    -0.00193,
    -0.24188,
    0.00529,
    0.00182,
)
#: ISO 6336-1 Method B: correction from the theoretical to the measured single stiffness.
CM_DEFAULT = 0.8


def _finite(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(name, value, "a finite number") from None
    if not math.isfinite(v):
        raise InputError(name, value, "a finite number")
    return v


def _positive(name: str, value: float) -> float:
    v = _finite(name, value)
    if v <= 0.0:
        raise InputError(name, value, "a finite number > 0")
    return v


def involute(alpha_rad: float) -> float:
    """The involute function ``inv α = tan α − α`` (α in rad, 0 ≤ α < π/2)."""
    return math.tan(alpha_rad) - alpha_rad


def inverse_involute(value: float) -> float:
    """The angle α (rad) with ``inv α = value`` (0 ≤ value < 1.5), by Newton from
    ``α0 = (3 value)^{1/3}`` (the first term of inv α ≈ α³/3); ``d inv α / dα = tan² α``.
    Converges to round-off in a few steps for the pressure angles of gears."""
    v = _finite("value", value)
    if not 0.0 <= v < 1.5:
        raise InputError("value", value, "in [0, 1.5)")
    if v == 0.0:
        return 0.0
    a = (3.0 * v) ** (1.0 / 3.0)
    for _ in range(60):
        step = (involute(a) - v) / math.tan(a) ** 2
        a -= step
        if abs(step) < 1e-16 * max(a, 1.0):
            break
    return a


def working_pressure_angle(
    z1: int, z2: int, x1: float, x2: float, alpha_n_deg: float = 20.0, beta_deg: float = 0.0
) -> float:
    r"""Working transverse pressure angle :math:`\alpha_{wt}` (rad) of an external pair at zero
    backlash (ISO 21771:2007): :math:`\operatorname{inv}\alpha_{wt} = \operatorname{inv}\alpha_t
    + 2\tan\alpha_n (x_1 + x_2)/(z_1 + z_2)`.

    Parameters
    ----------
    z1, z2
        Tooth numbers (external pair, > 0).
    x1, x2
        Profile shift coefficients.
    alpha_n_deg, beta_deg
        Normal pressure angle and reference helix angle (deg).
    """
    if z1 <= 0 or z2 <= 0:
        raise InputError("z", (z1, z2), "positive tooth numbers (external pair)")
    an = math.radians(_positive("alpha_n_deg", alpha_n_deg))
    at = math.atan(math.tan(an) / math.cos(math.radians(_finite("beta_deg", beta_deg))))
    return inverse_involute(involute(at) + 2.0 * math.tan(an) * (x1 + x2) / (z1 + z2))


def virtual_teeth(z: int, beta_deg: float = 0.0, alpha_n_deg: float = 20.0) -> float:
    r"""Virtual tooth number :math:`z_n = z / (\cos^2\beta_b \cos\beta)` (ISO 6336-1 §9),
    :math:`\tan\beta_b = \tan\beta\cos\alpha_n`."""
    b = math.radians(_finite("beta_deg", beta_deg))
    bb = math.atan(math.tan(b) * math.cos(math.radians(alpha_n_deg)))
    return z / (math.cos(bb) ** 2 * math.cos(b))


def theoretical_single_stiffness(
    z1: int, z2: int, x1: float, x2: float, beta_deg: float = 0.0, alpha_n_deg: float = 20.0
) -> float:
    r"""ISO 6336-1:2006 Method B theoretical single stiffness :math:`c'_{th} = 1/q'` of solid disc
    gears (N/(mm·µm)); the series is in the module docstring.

    Parameters
    ----------
    z1, z2
        Tooth numbers of pinion and gear (external pair).
    x1, x2
        Profile shift coefficients of pinion and gear.
    beta_deg, alpha_n_deg
        Reference helix angle and normal pressure angle (deg), for the virtual tooth numbers.

    Returns
    -------
    float
        :math:`c'_{th}` (N/(mm·µm)). FZG type C (16/24, x 0.1817/0.1715, spur): 15.78.
    """
    C = CTH_COEFFICIENTS
    zn1 = virtual_teeth(z1, beta_deg, alpha_n_deg)
    zn2 = virtual_teeth(z2, beta_deg, alpha_n_deg)
    q = (
        C[0]
        + C[1] / zn1
        + C[2] / zn2
        + C[3] * x1
        + C[4] * x1 / zn1
        + C[5] * x2
        + C[6] * x2 / zn2
        + C[7] * x1**2
        + C[8] * x2**2
    )
    return 1.0 / q


def basic_rack_factor(hfP_mn: float = 1.25, alpha_Pn_deg: float = 20.0) -> float:
    r"""ISO 6336-1:2006 basic rack factor :math:`C_B = [1 + 0.5(1.2 - h_{fP}/m_n)]
    [1 - 0.02(20° - \alpha_{Pn})]` (1 for :math:`h_{fP} = 1.2\,m_n`, :math:`\alpha_{Pn} = 20°`).

    Parameters
    ----------
    hfP_mn
        Dedendum of the basic rack over the normal module (fegear's rack cutter: 1.25).
    alpha_Pn_deg
        Pressure angle of the basic rack (deg).
    """
    return (1.0 + 0.5 * (1.2 - _positive("hfP_mn", hfP_mn))) * (
        1.0 - 0.02 * (20.0 - _positive("alpha_Pn_deg", alpha_Pn_deg))
    )


@dataclass(frozen=True)
class SingleStiffness:
    """ISO 6336-1 Method B single stiffness and its factors (N/(mm·µm)).

    Attributes
    ----------
    c_th
        Theoretical single stiffness :math:`c'_{th}` of solid disc gears.
    CM, CR, CB, cos_beta
        Measured-vs-theory correction, gear blank factor, basic rack factor, cos β.
    c_prime
        :math:`c' = c'_{th} C_M C_R C_B \\cos\\beta`.
    """

    c_th: float
    CM: float
    CR: float
    CB: float
    cos_beta: float

    @property
    def c_prime(self) -> float:
        return self.c_th * self.CM * self.CR * self.CB * self.cos_beta


def single_stiffness(
    z1: int,
    z2: int,
    x1: float,
    x2: float,
    beta_deg: float = 0.0,
    alpha_n_deg: float = 20.0,
    hfP_mn: float = 1.25,
    CM: float = CM_DEFAULT,
    CR: float = 1.0,
) -> SingleStiffness:
    """The single stiffness of ISO 6336-1:2006 Method B: :math:`c'_{th}` and the factors of
    :math:`c'` (solid disc gears, ``CR = 1``, unless given).

    Parameters
    ----------
    z1, z2, x1, x2, beta_deg, alpha_n_deg
        As :func:`theoretical_single_stiffness`.
    hfP_mn
        Basic rack dedendum over the module (for ``CB``).
    CM, CR
        Correction factor (ISO: 0.8) and gear blank factor (solid disc: 1).
    """
    return SingleStiffness(
        c_th=theoretical_single_stiffness(z1, z2, x1, x2, beta_deg, alpha_n_deg),
        CM=_positive("CM", CM),
        CR=_positive("CR", CR),
        CB=basic_rack_factor(hfP_mn, alpha_n_deg),
        cos_beta=math.cos(math.radians(beta_deg)),
    )


@dataclass(frozen=True)
class PitchPointHertz:
    """Line Hertz contact of a spur pair at the pitch point under one pair's load.

    Attributes
    ----------
    alpha_w_rad
        Working pressure angle (rad).
    centre_distance_mm
        Working centre distance (mm).
    r_b1_mm, r_b2_mm
        Base radii (mm).
    rho1_mm, rho2_mm
        Profile radii of curvature at the pitch point (mm).
    R_mm
        Relative radius of curvature (mm).
    force_N
        Normal load along the line of action ``T2 / r_b2`` (N).
    load_N_per_mm
        Normal load per unit face width (N/mm).
    E_star_MPa
        Effective modulus (MPa).
    p_H_MPa
        Peak (Hertz) pressure (MPa).
    half_width_mm
        Half-width of the contact strip (mm).
    """

    alpha_w_rad: float
    centre_distance_mm: float
    r_b1_mm: float
    r_b2_mm: float
    rho1_mm: float
    rho2_mm: float
    R_mm: float
    force_N: float
    load_N_per_mm: float
    E_star_MPa: float
    p_H_MPa: float
    half_width_mm: float


def pitch_point_line_hertz(
    z1: int,
    z2: int,
    module_mm: float,
    alpha_deg: float,
    x1: float,
    x2: float,
    face_width_mm: float,
    torque2_Nmm: float,
    E_MPa: float = 206000.0,
    nu: float = 0.3,
) -> PitchPointHertz:
    r"""Line Hertz at the pitch point of a spur pair whose gear carries ``torque2_Nmm`` on one
    tooth pair (module docstring: :math:`\rho_{Ci} = r_{bi}\tan\alpha_w`, :math:`w = T_2/(r_{b2}
    b)`, :math:`p_H = \sqrt{w E^*/(\pi R)}`).

    Parameters
    ----------
    z1, z2
        Tooth numbers of pinion and gear.
    module_mm, alpha_deg
        Module (mm) and pressure angle (deg).
    x1, x2
        Profile shift coefficients.
    face_width_mm
        Common face width (mm): the contact line length.
    torque2_Nmm
        Torque on the gear (N·mm).
    E_MPa, nu
        Material of both members.

    Returns
    -------
    PitchPointHertz
        FZG type C at 200 N·m on the gear: ``p_H_MPa`` 1100.0.
    """
    m = _positive("module_mm", module_mm)
    b = _positive("face_width_mm", face_width_mm)
    T2 = _positive("torque2_Nmm", torque2_Nmm)
    a0 = math.radians(_positive("alpha_deg", alpha_deg))
    aw = working_pressure_angle(z1, z2, x1, x2, alpha_deg)
    rb1, rb2 = 0.5 * z1 * m * math.cos(a0), 0.5 * z2 * m * math.cos(a0)
    rho1, rho2 = rb1 * math.tan(aw), rb2 * math.tan(aw)
    R = rho1 * rho2 / (rho1 + rho2)
    F = T2 / rb2
    Es = effective_modulus(E_MPa, nu, E_MPa, nu)
    line = hertz_line(F / b, R, Es)
    return PitchPointHertz(
        alpha_w_rad=aw,
        centre_distance_mm=(rb1 + rb2) / math.cos(aw),
        r_b1_mm=rb1,
        r_b2_mm=rb2,
        rho1_mm=rho1,
        rho2_mm=rho2,
        R_mm=R,
        force_N=F,
        load_N_per_mm=F / b,
        E_star_MPa=Es,
        p_H_MPa=line.p0_MPa,
        half_width_mm=line.b_mm,
    )


def iso6336_2_sigma_H0(
    z1: int,
    z2: int,
    module_mm: float,
    alpha_deg: float,
    x1: float,
    x2: float,
    face_width_mm: float,
    torque2_Nmm: float,
    E_MPa: float = 206000.0,
    nu: float = 0.3,
) -> float:
    r"""ISO 6336-2:2006 nominal contact stress at the pitch point of a spur pair,
    :math:`\sigma_{H0} = Z_H Z_E \sqrt{F_t (u+1)/(d_1 b u)}` with :math:`Z_\varepsilon = 1`
    (MPa); the same number as :func:`pitch_point_line_hertz` written with ISO's factors.

    Parameters
    ----------
    z1, z2, module_mm, alpha_deg, x1, x2, face_width_mm, torque2_Nmm, E_MPa, nu
        As :func:`pitch_point_line_hertz`.
    """
    m = _positive("module_mm", module_mm)
    a0 = math.radians(_positive("alpha_deg", alpha_deg))
    aw = working_pressure_angle(z1, z2, x1, x2, alpha_deg)
    Ft = _positive("torque2_Nmm", torque2_Nmm) / (0.5 * z2 * m)
    d1 = z1 * m
    u = z2 / z1
    ZH = math.sqrt(2.0 * math.cos(aw) / (math.cos(a0) ** 2 * math.sin(aw)))
    ZE = math.sqrt(1.0 / (math.pi * 2.0 * (1.0 - nu * nu) / _positive("E_MPa", E_MPa)))
    return ZH * ZE * math.sqrt(Ft / (d1 * _positive("face_width_mm", face_width_mm)) * (u + 1) / u)
