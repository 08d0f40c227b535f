r"""Closed-form Hertz contact: the baseline the FE contact engine must converge to.

Units: mm, N, MPa (N/mm²), radians.

Geometry
--------
Near the first point of contact the separation (gap) between two smooth surfaces is the quadratic
form

.. math:: h(x, y) = A x^2 + B y^2, \qquad 0 < A \le B,

in the principal axes of the *relative* curvature (Johnson 1985, §4.1). For two bodies with signed
principal curvatures :math:`(\kappa_{1I}, \kappa_{1II})`, :math:`(\kappa_{2I}, \kappa_{2II})`
(convex positive) whose first principal directions make the angle :math:`\omega`

.. math::

    A + B &= \tfrac12(\kappa_{1I} + \kappa_{1II} + \kappa_{2I} + \kappa_{2II}), \\
    B - A &= \tfrac12\sqrt{g_1^2 + g_2^2 + 2 g_1 g_2 \cos 2\omega},
        \qquad g_i = \kappa_{iI} - \kappa_{iII}.

Elliptical point contact (Hertz 1882; Johnson 1985, §4.2)
---------------------------------------------------------
Pressure :math:`p = p_0\sqrt{1 - x^2/a^2 - y^2/b^2}` on the ellipse with semi-axes
:math:`a \ge b` (``a`` along the direction of the smaller coefficient ``A``), total load
:math:`P = \tfrac23\pi a b p_0`. With :math:`e = \sqrt{1 - b^2/a^2}` and the complete elliptic
integrals :math:`K(e), E(e)` of modulus ``e`` (Johnson 1985, eq. 4.39)

.. math::

    A = \frac{p_0}{E^*}\frac{b}{e^2 a^2}\,[K(e) - E(e)], \qquad
    B = \frac{p_0}{E^*}\frac{b}{e^2 a^2}\,\Big[\frac{a^2}{b^2}E(e) - K(e)\Big], \qquad
    \delta = \frac{p_0}{E^*}\, b\, K(e),

where :math:`\delta` is the total approach of distant points of the two bodies and
:math:`1/E^* = (1-\nu_1^2)/E_1 + (1-\nu_2^2)/E_2`. Harris & Kotzalas (Rolling Bearing Analysis,
5th ed., 2006, ch. 6) give the same relations in their own notation.

Numerics
--------
``K - E`` cancels as :math:`e \to 0` (near-circular contact) and ``m = e^2 \to 1`` loses the small
complementary parameter :math:`1 - m = (b/a)^2` for very elongated contact. Both are avoided by
writing the relations with Carlson's symmetric integrals (DLMF §19.25(i), eq. 19.25.1):

.. math::

    K = R_F(0, k'^2, 1), \quad K - E = \tfrac{e^2}{3} R_D(0, k'^2, 1), \quad
    E - k'^2 K = \tfrac{e^2 k'^2}{3} R_D(0, 1, k'^2), \qquad k' = b/a,

which, with the homogeneity of :math:`R_F, R_D` and :math:`P = \frac23\pi a b p_0`, turns
Johnson's eq. 4.39 into the symmetric, cancellation-free form

.. math::

    A = \frac{P\,R_D(0, b^2, a^2)}{2\pi E^*}, \qquad
    B = \frac{P\,R_D(0, a^2, b^2)}{2\pi E^*}, \qquad
    \delta = \frac{3P\,R_F(0, a^2, b^2)}{2\pi E^*}.

Hence the axis ratio :math:`k' = b/a` solves :math:`R_D(0, 1, k'^2) / R_D(0, k'^2, 1) = B/A`
(a monotone function of :math:`k'`, equal to 1 at :math:`k' = 1`), solved by bracketed ``brentq``
on :math:`\ln k'`; then :math:`a^3 = P R_D(0, k'^2, 1) / (2\pi E^* A)`, :math:`b = k' a` and
:math:`\delta = 3 P R_F(0, k'^2, 1)/(2\pi E^* a)`. The complementary parameter :math:`k'^2` is the
argument itself, so nothing cancels as :math:`m \to 1` (this plays the role of
``scipy.special.ellipkm1``). For :math:`A = B` this is exactly the sphere:
:math:`R_D(0,1,1) = 3\pi/4` gives :math:`a^3 = 3PR/(4E^*)` with :math:`1/R = A + B = 2A`,
:math:`p_0 = 3P/(2\pi a^2)`, :math:`\delta = a^2/R`.

Force–approach law: :math:`\delta = c\,P^{2/3}` with :math:`c` depending on ``A, B, E*`` only, so
:math:`P = (\delta/c)^{3/2}` (see :class:`HertzLaw`).

Paint thickness / approach conventions
--------------------------------------
Litvin (Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed. 2004, section on the
instantaneous contact ellipse) takes the "elastic approach" :math:`\delta` as a known constant —
in practice the thickness of the marking compound, customarily 0.00025 in ≈ 6.3 µm — and defines
the instantaneous contact ellipse purely geometrically as the level curve :math:`h = \delta` of
the gap: :math:`a = \sqrt{\delta/A}`, :math:`b = \sqrt{\delta/B}` (no elasticity, no load). That is
:func:`paint_ellipse`, the convention to use for an unloaded bearing pattern comparable with Litvin.
:func:`hertz_ellipse_for_approach` is the *elastic* Hertz ellipse whose total approach is
:math:`\delta`; it is smaller (by exactly :math:`\sqrt2` in both axes for a sphere, because the
bodies also deform outside the contact).

Line contact (Johnson 1985, ch. 4, two-dimensional contact of cylinders)
-----------------------------------------------------------------------
Load per unit length ``w``, relative radius :math:`1/R = 1/R_1 + 1/R_2`: half-width
:math:`b = \sqrt{4 w R/(\pi E^*)}`, :math:`p_0 = 2w/(\pi b) = \sqrt{w E^*/(\pi R)}`. No approach is
given: in plane strain the approach is defined only relative to a chosen datum (it grows with the
logarithm of the body size), and finite-length roller formulas (e.g. Lundberg's) are not
implemented here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq
from scipy.special import elliprd, elliprf

from fegear.errors import InputError, SolverError

__all__ = [
    "HertzPoint",
    "HertzLine",
    "HertzLaw",
    "RelativeCurvature",
    "ContactEllipse",
    "effective_modulus",
    "relative_curvature",
    "hertz_law",
    "hertz_point",
    "hertz_point_radii",
    "hertz_force_for_approach",
    "hertz_ellipse_for_approach",
    "paint_ellipse",
    "hertz_pressure",
    "hertz_line",
]

#: Smallest axis ratio b/a searched for (B/A up to ~1e297); below it B/A would overflow R_D.
_MIN_AXIS_RATIO = 1e-150


# --------------------------------------------------------------------------------------------
# validation helpers
# --------------------------------------------------------------------------------------------


def _real(field: str, value: object, allowed: str) -> float:
    """``float(value)`` if it is a finite real number, else :class:`InputError`."""
    if isinstance(value, bool):
        raise InputError(field, value, allowed, "not a number")
    try:
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(field, value, allowed, "not a number") from None
    if not math.isfinite(x):
        raise InputError(field, value, allowed, "not finite")
    return x


def _positive(field: str, value: object) -> float:
    x = _real(field, value, "a finite number > 0")
    if x <= 0.0:
        raise InputError(field, value, "a finite number > 0")
    return x


def _poisson(field: str, value: object) -> float:
    allowed = "a finite number in (-1, 0.5)"
    x = _real(field, value, allowed)
    if not -1.0 < x < 0.5:
        raise InputError(field, value, allowed)
    return x


def _wrap_half_turn(angle: float) -> float:
    """Axis angle (defined modulo π) wrapped into (−π/2, π/2]."""
    w = math.remainder(angle, math.pi)  # in [-π/2, π/2]
    return math.pi / 2 if w <= -math.pi / 2 else w


# --------------------------------------------------------------------------------------------
# results
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class HertzPoint:
    """Hertz elliptical point contact.

    Attributes
    ----------
    force_N
        Normal load P.
    p0_MPa
        Maximum (central) pressure, ``3 P / (2 π a b)``.
    a_mm, b_mm
        Semi-major and semi-minor axes, ``a >= b``; ``a`` lies along the direction of ``A``.
    approach_mm
        Total rigid approach δ of distant points of the two bodies (both deformations).
    A, B
        Relative-curvature coefficients (1/mm) of the gap ``h = A x² + B y²``, sorted
        ``0 < A <= B`` (x along the major axis).
    E_star_MPa
        Effective modulus ``E*``.
    major_axis_rad
        Angle of the major axis in the caller's frame, in (−π/2, π/2], or ``None`` when no
        directions were given.
    """

    force_N: float
    p0_MPa: float
    a_mm: float
    b_mm: float
    approach_mm: float
    A: float
    B: float
    E_star_MPa: float
    major_axis_rad: float | None = None

    @property
    def axis_ratio(self) -> float:
        """``b / a`` in (0, 1]."""
        return self.b_mm / self.a_mm

    @property
    def eccentricity(self) -> float:
        """``e = sqrt(1 - (b/a)²)``."""
        k = self.axis_ratio
        return math.sqrt((1.0 - k) * (1.0 + k))

    @property
    def area_mm2(self) -> float:
        """Contact area ``π a b``."""
        return math.pi * self.a_mm * self.b_mm

    @property
    def mean_pressure_MPa(self) -> float:
        """``P / (π a b) = (2/3) p0``."""
        return self.force_N / self.area_mm2

    def pressure(self, x: ArrayLike, y: ArrayLike) -> NDArray[np.float64]:
        """Pressure at ``(x, y)`` in the ellipse axes (x along the major axis); see
        :func:`hertz_pressure`."""
        return hertz_pressure(x, y, self.p0_MPa, self.a_mm, self.b_mm)


@dataclass(frozen=True)
class HertzLine:
    """Hertz line (two-dimensional) contact of parallel cylinders, per unit length.

    Attributes
    ----------
    load_N_per_mm
        Load per unit length ``w``.
    p0_MPa
        Maximum pressure ``2 w / (π b)``.
    b_mm
        Half-width of the contact strip.
    R_mm
        Relative radius, ``1/R = 1/R1 + 1/R2`` (gap ``h = y² / (2R)``).
    E_star_MPa
        Effective modulus ``E*``.
    """

    load_N_per_mm: float
    p0_MPa: float
    b_mm: float
    R_mm: float
    E_star_MPa: float

    def pressure(self, y: ArrayLike) -> NDArray[np.float64]:
        """``p0 sqrt(1 - y²/b²)``, 0 outside the strip (``y`` across the line)."""
        y = np.asarray(y, dtype=float)
        return self.p0_MPa * np.sqrt(np.clip(1.0 - (y / self.b_mm) ** 2, 0.0, None))


class RelativeCurvature(NamedTuple):
    """Relative-curvature coefficients of the gap ``h = A x² + B y²``.

    ``A <= B``; ``major_axis_rad`` is the angle from body 1's first principal direction to the
    direction of ``A`` (the major axis of any contact ellipse), in (−π/2, π/2]; it is arbitrary
    (returned as 0) when ``A == B``.
    """

    A: float
    B: float
    major_axis_rad: float


class ContactEllipse(NamedTuple):
    """A purely geometric ellipse: semi-axes ``a_mm >= b_mm`` and major-axis angle (or None)."""

    a_mm: float
    b_mm: float
    major_axis_rad: float | None


# --------------------------------------------------------------------------------------------
# material and geometry
# --------------------------------------------------------------------------------------------


def effective_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    r"""Effective (contact) modulus :math:`E^*`, :math:`1/E^* = (1-\nu_1^2)/E_1 + (1-\nu_2^2)/E_2`.

    Parameters
    ----------
    E1, E2
        Young's moduli (MPa), > 0.
    nu1, nu2
        Poisson's ratios, in (−1, 0.5).

    Returns
    -------
    float
        ``E*`` in MPa (Johnson 1985, ch. 4). Steel on steel, E = 206 000 MPa,
        ν = 0.3: ``E* = 206000 / (2 · 0.91) ≈ 113 187 MPa``.
    """
    e1 = _positive("E1", E1)
    e2 = _positive("E2", E2)
    n1 = _poisson("nu1", nu1)
    n2 = _poisson("nu2", nu2)
    return 1.0 / ((1.0 - n1 * n1) / e1 + (1.0 - n2 * n2) / e2)


def relative_curvature(
    k1: tuple[float, float], k2: tuple[float, float], omega: float
) -> RelativeCurvature:
    r"""Relative-curvature coefficients ``A <= B`` from the principal curvatures of two bodies.

    Parameters
    ----------
    k1, k2
        Signed principal curvatures ``(κ_I, κ_II)`` (1/mm) of bodies 1 and 2 at the contact point,
        each measured with the body's own outward normal: convex positive, concave negative,
        flat 0.
    omega
        Angle (rad) from body 1's first principal direction to body 2's first principal direction,
        in the common tangent plane, positive counter-clockwise about body 1's outward normal
        (``A``, ``B`` depend only on ``cos 2ω``; the sign matters for ``major_axis_rad``, which is
        measured the same way from body 1's first principal direction).

    Returns
    -------
    RelativeCurvature
        ``(A, B, major_axis_rad)``, with (Johnson 1985, §4.1; Litvin & Fuentes 2004 give the same
        with their sign convention for κ₂)

        .. math::

            A + B = \tfrac12 \textstyle\sum\kappa, \qquad
            B - A = \tfrac12 G, \qquad
            G = \sqrt{g_1^2 + g_2^2 + 2 g_1 g_2 \cos 2\omega}, \quad g_i = \kappa_{iI}-\kappa_{iII}.

        The gap is the sum of the two bodies' second-order heights,
        :math:`h = \tfrac12 \mathbf{x}^T(\mathbf{K}_1 + \mathbf{K}_2)\mathbf{x}`, so ``A, B`` are
        the eigenvalues of :math:`\tfrac12(\mathbf{K}_1 + \mathbf{K}_2)`; its deviatoric part is
        :math:`\tfrac14 G` times a reflection at angle :math:`2\psi`,
        :math:`G e^{2i\psi} = g_1 + g_2 e^{2i\omega}`; ``B`` lies along :math:`\psi` and the
        major axis (``A``) along :math:`\psi + \pi/2`. ``A`` is computed as
        :math:`AB/B` with :math:`AB = \tfrac14[(\kappa_{1I}+\kappa_{2I})(\kappa_{1II}+\kappa_{2II})
        + g_1 g_2 \sin^2\omega]` to avoid the cancellation of ``(Σκ − G)/4`` when ``A << B``.

    Raises
    ------
    InputError
        Non-finite input, or ``A <= 0``: conformal or line contact (the gap does not grow in
        every direction), which is not Hertzian point contact. Field ``"A"``.
    """
    if len(k1) != 2:
        raise InputError("k1", k1, "a pair (k_I, k_II) of curvatures (1/mm)")
    if len(k2) != 2:
        raise InputError("k2", k2, "a pair (k_I, k_II) of curvatures (1/mm)")
    k1I = _real("k1[0]", k1[0], "a finite curvature (1/mm)")
    k1II = _real("k1[1]", k1[1], "a finite curvature (1/mm)")
    k2I = _real("k2[0]", k2[0], "a finite curvature (1/mm)")
    k2II = _real("k2[1]", k2[1], "a finite curvature (1/mm)")
    w = _real("omega", omega, "a finite angle (rad)")

    g1 = k1I - k1II
    g2 = k2I - k2II
    s = k1I + k1II + k2I + k2II
    c2w, s2w = math.cos(2.0 * w), math.sin(2.0 * w)
    # G e^{2iψ} = g1 + g2 e^{2iω}
    gx = g1 + g2 * c2w
    gy = g2 * s2w
    G = math.hypot(gx, gy)
    B = 0.25 * (s + G)
    ab = 0.25 * ((k1I + k2I) * (k1II + k2II) + g1 * g2 * math.sin(w) ** 2)
    if G == 0.0:
        A = B  # round: exactly equal, so hertz_point takes the exact sphere branch
    else:
        A = min(ab / B, B) if B > 0.0 else 0.25 * (s - G)
    if not A > 0.0:
        raise InputError(
            "A",
            A,
            "> 0",
            "relative curvature not positive in every direction: conformal or line contact is "
            "not Hertzian point contact",
        )
    major = 0.0 if G == 0.0 else _wrap_half_turn(0.5 * math.atan2(gy, gx) + 0.5 * math.pi)
    return RelativeCurvature(A=A, B=B, major_axis_rad=major)


# --------------------------------------------------------------------------------------------
# point contact
# --------------------------------------------------------------------------------------------


def _ratio_function(t: float, log_r: float) -> float:
    """ln(R_D(0,1,k²)/R_D(0,k²,1)) − ln(B/A) at k = exp(t); decreasing in t."""
    k2 = math.exp(2.0 * t)
    return math.log(float(elliprd(0.0, 1.0, k2))) - math.log(float(elliprd(0.0, k2, 1.0))) - log_r


def _axis_ratio(r: float) -> float:
    """Axis ratio ``k = b/a`` in (0, 1] of the Hertz ellipse for ``r = B/A >= 1``.

    Solves ``R_D(0, 1, k²) / R_D(0, k², 1) = r`` by ``brentq`` on ``t = ln k`` in a bracket
    ``[t_lo, 0]``; exactly 1 for ``r == 1``.
    """
    if r == 1.0:
        return 1.0
    log_r = math.log(r)
    # For small k, r(k) ≈ 1/(k² (ln(4/k) − 1)) <= 1/k² (k < 0.54), so k = 1/sqrt(r) lies on the
    # 'too round' side; step down until the sign changes.
    k_lo = min(0.5, 1.0 / math.sqrt(r))
    while _ratio_function(math.log(k_lo), log_r) <= 0.0:
        if k_lo <= _MIN_AXIS_RATIO:
            raise InputError("B/A", r, "<= 1e297", "contact too elongated for point contact")
        k_lo = max(k_lo * 1e-2, _MIN_AXIS_RATIO)
    t, info = brentq(
        _ratio_function,
        math.log(k_lo),
        0.0,
        args=(log_r,),
        xtol=1e-300,
        rtol=4.0 * np.finfo(float).eps,
        maxiter=200,
        full_output=True,
        disp=False,
    )
    if not info.converged:  # pragma: no cover - brentq on a bracket always converges
        raise SolverError(f"Hertz axis ratio for B/A = {r!r} did not converge: {info.flag}")
    return math.exp(t)


@dataclass(frozen=True)
class HertzLaw:
    r"""The Hertz force–approach law of one contact, :math:`\delta = c\,P^{2/3}`.

    Built by :func:`hertz_law` once per (A, B, E*), then evaluated cheaply many times (e.g. by a
    per-pair load-sharing model).

    With :math:`k = b/a` fixed by ``B/A``: :math:`a = s P^{1/3}`,
    :math:`s^3 = R_D(0, k^2, 1)/(2\pi E^* A)`, and
    :math:`\delta = 3 P R_F(0, k^2, 1)/(2\pi E^* a) = c P^{2/3}`,
    :math:`c = 3 R_F(0, k^2, 1)/(2\pi E^* s)`.

    Attributes
    ----------
    A, B
        Sorted relative-curvature coefficients (1/mm), ``0 < A <= B``.
    E_star_MPa
        Effective modulus.
    axis_ratio
        ``k = b/a`` of every contact ellipse of this law.
    size_coeff
        ``s`` (mm/N^(1/3)): ``a = s P^(1/3)``.
    compliance_coeff
        ``c`` (mm/N^(2/3)): ``δ = c P^(2/3)``.
    """

    A: float
    B: float
    E_star_MPa: float
    axis_ratio: float
    size_coeff: float
    compliance_coeff: float

    def approach(self, force_N: ArrayLike) -> NDArray[np.float64] | float:
        """Total approach ``δ = c P^(2/3)`` (mm); forces <= 0 give 0."""
        f = np.maximum(np.asarray(force_N, dtype=float), 0.0)
        out = self.compliance_coeff * np.cbrt(f) ** 2
        return float(out) if out.ndim == 0 else out

    def force(self, approach_mm: ArrayLike) -> NDArray[np.float64] | float:
        """Force ``P = (δ/c)^(3/2)`` (N); approaches <= 0 (no contact) give 0."""
        d = np.maximum(np.asarray(approach_mm, dtype=float), 0.0)
        out = (d / self.compliance_coeff) ** 1.5
        return float(out) if out.ndim == 0 else out

    def stiffness(self, approach_mm: ArrayLike) -> NDArray[np.float64] | float:
        """Tangent stiffness ``dP/dδ = (3/2) δ^(1/2) / c^(3/2)`` (N/mm); 0 for δ <= 0."""
        d = np.maximum(np.asarray(approach_mm, dtype=float), 0.0)
        out = 1.5 * np.sqrt(d) / self.compliance_coeff**1.5
        return float(out) if out.ndim == 0 else out

    def point(self, force_N: float, major_axis_rad: float | None = None) -> HertzPoint:
        """The full contact for load ``force_N`` (> 0)."""
        P = _positive("force_N", force_N)
        a = self.size_coeff * math.cbrt(P)
        b = self.axis_ratio * a
        return HertzPoint(
            force_N=P,
            p0_MPa=1.5 * P / (math.pi * a * b),
            a_mm=a,
            b_mm=b,
            approach_mm=self.compliance_coeff * math.cbrt(P) ** 2,
            A=self.A,
            B=self.B,
            E_star_MPa=self.E_star_MPa,
            major_axis_rad=major_axis_rad,
        )


def _sorted_coefficients(
    A: float, B: float, x_axis_rad: float | None
) -> tuple[float, float, float | None]:
    """Validate, sort ``A <= B`` and return the major-axis angle (x axis, or y if ``A > B``)."""
    detail = "the gap must grow in every direction (Hertz point contact); line contact: hertz_line"
    a_ = _real("A", A, "a finite number > 0")
    b_ = _real("B", B, "a finite number > 0")
    if a_ <= 0.0:
        raise InputError("A", A, "a finite number > 0", detail)
    if b_ <= 0.0:
        raise InputError("B", B, "a finite number > 0", detail)
    major = None
    if x_axis_rad is not None:
        x0 = _real("x_axis_rad", x_axis_rad, "a finite angle (rad)")
        major = _wrap_half_turn(x0 if a_ <= b_ else x0 + 0.5 * math.pi)
    return min(a_, b_), max(a_, b_), major


def hertz_law(A: float, B: float, E_star: float) -> HertzLaw:
    r"""The force–approach law :math:`\delta = c P^{2/3}` and ellipse shape for given ``A, B, E*``.

    Parameters
    ----------
    A, B
        Relative-curvature coefficients (1/mm) of the gap ``h = A x² + B y²``, any order, > 0.
    E_star
        Effective modulus (MPa), > 0.

    Returns
    -------
    HertzLaw
        With ``A <= B`` sorted. See the module docstring for the formulas (Johnson 1985 eq. 4.39
        in Carlson form).
    """
    A_, B_, _ = _sorted_coefficients(A, B, None)
    Es = _positive("E_star", E_star)
    k = _axis_ratio(B_ / A_)
    k2 = k * k
    s = math.cbrt(float(elliprd(0.0, k2, 1.0)) / (2.0 * math.pi * Es * A_))
    c = 3.0 * float(elliprf(0.0, k2, 1.0)) / (2.0 * math.pi * Es * s)
    return HertzLaw(A=A_, B=B_, E_star_MPa=Es, axis_ratio=k, size_coeff=s, compliance_coeff=c)


def hertz_point(
    force_N: float, A: float, B: float, E_star: float, x_axis_rad: float | None = None
) -> HertzPoint:
    r"""Hertz elliptical point contact for a given load.

    Parameters
    ----------
    force_N
        Normal load P (N), finite and > 0.
    A, B
        Relative-curvature coefficients (1/mm) of the gap ``h = A x² + B y²`` (any order), > 0.
        For a sphere of radius R on a flat, ``A = B = 1/(2R)``.
    E_star
        Effective modulus (MPa), see :func:`effective_modulus`.
    x_axis_rad
        Optional angle of the x axis (the direction of ``A`` as given) in the caller's frame; the
        result's ``major_axis_rad`` is this angle, or this + π/2 if ``A > B``.

    Returns
    -------
    HertzPoint
        Solution of Johnson (1985) §4.2 eqs. 4.39–4.41 (Hertz 1882):

        .. math::

            \frac{B}{A} = \frac{(a/b)^2 E(e) - K(e)}{K(e) - E(e)}, \quad
            A = \frac{3P}{2\pi E^* a^3}\frac{K(e)-E(e)}{e^2}, \quad
            \delta = \frac{3 P K(e)}{2\pi E^* a}, \quad p_0 = \frac{3P}{2\pi a b},

        evaluated in the cancellation-free Carlson form of the module docstring. ``A = B`` gives
        exactly the sphere: :math:`a = (3PR/4E^*)^{1/3}`, :math:`1/R = A + B`,
        :math:`\delta = a^2/R`.

    Raises
    ------
    InputError
        ``force_N``, ``A``, ``B`` or ``E_star`` not finite and > 0.
    """
    P = _positive("force_N", force_N)
    _, _, major = _sorted_coefficients(A, B, x_axis_rad)
    return hertz_law(A, B, E_star).point(P, major)


def _radius(field: str, value: float | None) -> float:
    """Curvature 1/R of a radius (None = flat)."""
    if value is None:
        return 0.0
    return 1.0 / _positive(field, value)


def hertz_point_radii(
    force_N: float,
    radii1: tuple[float | None, float | None] | None,
    radii2: tuple[float | None, float | None] | None,
    E1: float,
    nu1: float,
    E2: float,
    nu2: float,
) -> HertzPoint:
    r"""Hertz point contact of two convex bodies with aligned principal axes.

    Parameters
    ----------
    force_N
        Normal load (N), > 0.
    radii1, radii2
        Principal radii ``(Rx, Ry)`` (mm) of each body along the common x and y axes; ``None``
        for a flat direction, or ``None`` for a whole flat body. Radii must be > 0 (convex); use
        :func:`relative_curvature` for concave or rotated surfaces.
    E1, nu1, E2, nu2
        Elastic constants of the bodies.

    Returns
    -------
    HertzPoint
        With :math:`A_x = \tfrac12(1/R_{1x} + 1/R_{2x})`, :math:`B_y = \tfrac12(1/R_{1y} +
        1/R_{2y})` and ``major_axis_rad`` 0 (major axis along x) or π/2 (along y). Example: a
        crowned roller ``(20, 100)`` on a flat block has ``A_x = 1/40``, ``B_y = 1/200``, so the
        major axis runs along y.

    Raises
    ------
    InputError
        Any radius <= 0 (field ``radii1.Rx`` etc.), bad material, bad force, or both bodies flat
        in one direction (line contact, field ``A`` or ``B``).
    """
    P = _positive("force_N", force_N)
    r1 = (None, None) if radii1 is None else radii1
    r2 = (None, None) if radii2 is None else radii2
    if len(r1) != 2:
        raise InputError("radii1", radii1, "(Rx, Ry) or None")
    if len(r2) != 2:
        raise InputError("radii2", radii2, "(Rx, Ry) or None")
    cx = _radius("radii1.Rx", r1[0]) + _radius("radii2.Rx", r2[0])
    cy = _radius("radii1.Ry", r1[1]) + _radius("radii2.Ry", r2[1])
    Es = effective_modulus(E1, nu1, E2, nu2)
    return hertz_point(P, 0.5 * cx, 0.5 * cy, Es, x_axis_rad=0.0)


def hertz_force_for_approach(approach_mm: float, A: float, B: float, E_star: float) -> float:
    r"""Load P whose Hertz approach is ``approach_mm``: :math:`P = (\delta/c)^{3/2}`.

    The exact inverse of ``hertz_point(P, A, B, E_star).approach_mm`` (same law, same
    coefficient ``c``; see :class:`HertzLaw`).

    Raises
    ------
    InputError
        ``approach_mm`` not finite and > 0, or bad ``A``, ``B``, ``E_star``.
    """
    d = _positive("approach_mm", approach_mm)
    return float(hertz_law(A, B, E_star).force(d))


def hertz_ellipse_for_approach(
    approach_mm: float, A: float, B: float, E_star: float, x_axis_rad: float | None = None
) -> HertzPoint:
    """The elastic Hertz contact whose total approach is ``approach_mm``.

    This is *not* Litvin's paint-thickness ellipse (that one is :func:`paint_ellipse`, the level
    curve ``h = δ`` of the rigid gap); the elastic ellipse is smaller because part of the approach
    is taken up by deformation outside the contact (``sqrt(2)`` smaller for a sphere). The load
    that produces the approach is in ``force_N``.

    Raises
    ------
    InputError
        ``approach_mm`` not finite and > 0, or bad ``A``, ``B``, ``E_star``.
    """
    d = _positive("approach_mm", approach_mm)
    _, _, major = _sorted_coefficients(A, B, x_axis_rad)
    law = hertz_law(A, B, E_star)
    return law.point(float(law.force(d)), major)


def paint_ellipse(
    approach_mm: float, A: float, B: float, x_axis_rad: float | None = None
) -> ContactEllipse:
    r"""Litvin's instantaneous contact ellipse for a paint (marking compound) thickness δ.

    Litvin & Fuentes (2004), instantaneous contact ellipse: with the elastic approach δ taken as
    the paint thickness (customarily 0.00025 in ≈ 6.3 µm), the contact ellipse is where the rigid
    gap is below δ:
    :math:`A x^2 + B y^2 = \delta`, so :math:`a = \sqrt{\delta/A}`, :math:`b = \sqrt{\delta/B}`.
    Purely geometric (no load, no material); use it for unloaded bearing patterns comparable with
    Litvin's. For the elastic ellipse of a given approach see :func:`hertz_ellipse_for_approach`.

    Raises
    ------
    InputError
        ``approach_mm``, ``A`` or ``B`` not finite and > 0.
    """
    d = _positive("approach_mm", approach_mm)
    A_, B_, major = _sorted_coefficients(A, B, x_axis_rad)
    return ContactEllipse(a_mm=math.sqrt(d / A_), b_mm=math.sqrt(d / B_), major_axis_rad=major)


def hertz_pressure(
    x: ArrayLike, y: ArrayLike, p0: float, a: float, b: float
) -> NDArray[np.float64]:
    r"""Hertz elliptical pressure :math:`p_0\sqrt{1 - x^2/a^2 - y^2/b^2}`, 0 outside the ellipse.

    Parameters
    ----------
    x, y
        Coordinates (mm) in the ellipse axes (x along semi-axis ``a``); any broadcastable shapes.
    p0
        Peak pressure (MPa), >= 0.
    a, b
        Semi-axes (mm), > 0 (either may be the larger).

    Returns
    -------
    ndarray
        Pressure (MPa), shape ``broadcast(x, y)``. Integrates to ``(2/3) π a b p0``.
    """
    p0_ = _real("p0", p0, "a finite number >= 0")
    if p0_ < 0.0:
        raise InputError("p0", p0, "a finite number >= 0")
    a_ = _positive("a", a)
    b_ = _positive("b", b)
    xa = np.asarray(x, dtype=float) / a_
    yb = np.asarray(y, dtype=float) / b_
    return p0_ * np.sqrt(np.clip(1.0 - xa * xa - yb * yb, 0.0, None))


# --------------------------------------------------------------------------------------------
# line contact
# --------------------------------------------------------------------------------------------


def hertz_line(load_N_per_mm: float, R_mm: float, E_star: float) -> HertzLine:
    r"""Hertz line contact of parallel cylinders (Johnson 1985, ch. 4, 2D contact of cylinders).

    Parameters
    ----------
    load_N_per_mm
        Load per unit length ``w`` (N/mm), > 0.
    R_mm
        Relative radius (mm), :math:`1/R = 1/R_1 + 1/R_2` (``R = R1`` on a flat); > 0.
    E_star
        Effective modulus (MPa), > 0.

    Returns
    -------
    HertzLine
        :math:`b = \sqrt{4 w R/(\pi E^*)}`, :math:`p_0 = 2w/(\pi b)`. No approach (see the module
        docstring).
    """
    w = _positive("load_N_per_mm", load_N_per_mm)
    R = _positive("R_mm", R_mm)
    Es = _positive("E_star", E_star)
    b = math.sqrt(4.0 * w * R / (math.pi * Es))
    return HertzLine(load_N_per_mm=w, p0_MPa=2.0 * w / (math.pi * b), b_mm=b, R_mm=R, E_star_MPa=Es)
