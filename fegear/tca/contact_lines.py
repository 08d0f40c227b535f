r"""Contact lines of a cylindrical (spur or helical) pair and its contact ratios.

Parallel axes, external pair, error-free assembly
(:func:`fegear.geometry.pair_placement.involute_assembly`):
pinion axis ``+z`` through the origin, gear axis through ``(a, 0, 0)``. The unmodified flanks
(involute helicoids, :mod:`fegear.geometry.cylindrical`) touch along straight lines in the
*plane of action*, the plane tangent to both base cylinders,

.. math:: \{X : X \cdot n_{pa} = r_{b1}\}, \qquad
          n_{pa} = (\cos\alpha_{wt}, -\sin\alpha_{wt}, 0), \qquad
          \cos\alpha_{wt} = (r_{b1} + r_{b2})/a

(the sign: the outward normal of the pinion's drive flank points from the base circle to the
point, towards ``+y`` at the pitch point). A helicoid's normals are tangent to its base
cylinder, and a normal lies in the plane of action exactly where the point does: the contact
point of a transverse section ``z`` is the root of ``N_1(u, z) · R_z(−ψ) n_{pa} = 0`` on the
pinion flank (``ψ`` the pinion angle; Newton on the exact normals). Its transverse roll lengths
on the two members add up to the length of the line of action between the base circles,
``L_1 + L_2 = a \sin\alpha_{wt}`` (Litvin & Fuentes 2004 §10.6, §14.5; ISO 21771 §5.4), and the
section is in contact when both lie on their working flanks (form circle to tip circle) and
``z`` on both faces. The contact line of a pair is the interval of ``z`` where its sections are
in contact: it runs across the plane of action at the base helix angle ``β_b``
(``tan β_b = tan β cos α_t``).

Contact ratios (measured here on the members' surfaces, against the closed forms of ISO
21771:2007 §5.4 in :func:`iso_contact_ratios`): the angle ``Δψ`` over which a pair is in contact
(its first to its last contact, by bisection on the contact predicate of its face-end sections)
over the angular pitch ``2π/z_1``:

- ``ε_α`` of the section in the middle of the common face,
- ``ε_β`` the lag of the contact start between the two face ends (``b tan β_b / p_bt``),
- ``ε_γ`` of the whole pair (from its first contact at one face end to its last at the other).

The closed forms assume that the tip circles bound the path of contact (``ε_α`` from the tip
radii); where a form circle bounds it instead the measured ratio is the smaller and
:attr:`ContactRatios.start_limit` / :attr:`end_limit` say so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

__all__ = [
    "ContactLine",
    "ContactRatios",
    "PlaneOfAction",
    "contact_line",
    "contact_ratios",
    "iso_contact_ratios",
    "plane_of_action",
    "section_contact",
]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class PlaneOfAction:
    """The plane of action of an error-free parallel-axes pair (fixed frame, mm, rad).

    Attributes
    ----------
    normal
        ``(3,)`` unit normal ``n_pa``; the plane is ``X · n_pa = r_b1``.
    direction
        ``(3,)`` unit transverse direction of the line of action (the pinion drive flank's
        transverse normal at a contact), from the pinion's base circle towards the gear's.
    alpha_wt
        Working transverse pressure angle.
    centre_distance_mm, length_mm
        Centre distance ``a`` and the length ``a sin α_wt`` between the base-circle tangency
        points.
    face
        ``(z_start, z_end)`` of the common face (fixed frame).
    pinion_offset_mm
        ``z`` of the pinion's face centre in the fixed frame.
    """

    normal: Array
    direction: Array
    alpha_wt: float
    centre_distance_mm: float
    length_mm: float
    face: tuple[float, float]
    pinion_offset_mm: float


def _check(pinion, gear) -> None:
    for m in (pinion, gear):
        if not hasattr(m, "helicoid"):
            raise InputError("pair", type(m).__name__, 'cylindrical members (kind = "cylindrical")')


def plane_of_action(pinion, gear, assembly) -> PlaneOfAction:
    """The :class:`PlaneOfAction` of the pair without its installation errors."""
    _check(pinion, gear)
    asm = assembly.without_errors()
    a = asm.axes_distance()
    aw = math.acos((pinion.r_b + gear.r_b) / a)
    off = float(asm.base1[2, 3])
    b1, b2 = pinion.design.face_width_mm, gear.design.face_width_mm
    face = (max(off - b1 / 2, -b2 / 2), min(off + b1 / 2, b2 / 2))
    return PlaneOfAction(
        normal=np.array([math.cos(aw), -math.sin(aw), 0.0]),
        direction=np.array([math.sin(aw), math.cos(aw), 0.0]),
        alpha_wt=aw,
        centre_distance_mm=a,
        length_mm=a * math.sin(aw),
        face=face,
        pinion_offset_mm=off,
    )


def section_contact(
    pinion, gear, pa: PlaneOfAction, psi: ArrayLike, z: ArrayLike, iterations: int = 8
) -> tuple[Array, Array, Array, NDArray[np.bool_]]:
    """The contact point of pair 0 in the transverse section ``z`` (fixed frame) at pinion angle
    ``psi`` (rad), broadcast: ``(points (..., 3) fixed frame, L1, L2, in_contact)``, ``L_i`` the
    transverse roll lengths (mm) on the two members, ``in_contact`` both on their working
    flanks and ``z`` on both faces. Newton on ``N_1 · R_z(−ψ) n_pa = 0`` along the pinion
    profile (unmodified flank), from the roll length of the plane of action's trace."""
    psi, z = np.broadcast_arrays(np.asarray(psi, dtype=float), np.asarray(z, dtype=float))
    zm = z - pa.pinion_offset_mm  # pinion member frame
    c, s = np.cos(psi), np.sin(psi)
    n = pa.normal
    nm = np.stack([c * n[0] + s * n[1], -s * n[0] + c * n[1], 0.0 * c], -1)  # R_z(−ψ) n_pa
    # start: the involute's normal angle ψ_b − ε + ω(z) + π/2 equals that of the line of action
    tb = math.tan(math.radians(pinion.design.helix_angle_deg))
    eps = pinion._psi_b - tb * zm / pinion.r_p + pa.alpha_wt + psi
    u = pinion.u_of_roll_length(pinion.r_b * eps)
    h = 1e-6
    for _ in range(iterations):
        f = np.sum(pinion.helicoid("drive", u, zm, modified=False)[1] * nm, -1)
        f1 = np.sum(pinion.helicoid("drive", u + h, zm, modified=False)[1] * nm, -1)
        du = -f * h / np.where(f1 != f, f1 - f, 1.0)
        u = u + du
        if np.max(np.abs(du)) < 1e-13:
            break
    X = pinion.helicoid("drive", u, zm, modified=False)[0]
    Xf = np.stack([c * X[..., 0] - s * X[..., 1], s * X[..., 0] + c * X[..., 1], z], -1)
    L1 = pinion.roll_length(u)
    rho2 = np.hypot(Xf[..., 0] - pa.centre_distance_mm, Xf[..., 1])
    L2 = np.sqrt(np.maximum(rho2**2 - gear.r_b**2, 0.0))
    b1 = pinion.boundaries("drive")
    b2 = gear.boundaries("drive")
    u2 = gear.u_of_roll_length(L2)
    tol = 1e-12
    ok = (
        (u >= b1.u_fillet - tol) & (u <= b1.u_tip + tol)
        & (u2 >= b2.u_fillet - tol) & (u2 <= b2.u_tip + tol)
        & (z >= pa.face[0] - tol) & (z <= pa.face[1] + tol)
        & (np.sum(Xf * n, -1) > 0)  # on the drive side of the pinion axis
    )  # fmt: skip
    return Xf, L1, L2, ok


@dataclass(frozen=True)
class ContactLine:
    """The contact line of one pair at one position (fixed frame).

    Attributes
    ----------
    z_start, z_end
        The ``z`` interval of the line (``z_start > z_end``: no contact).
    start, end
        ``(3,)`` its end points (mm).
    length_mm
        Its length (0 without contact).
    """

    z_start: float
    z_end: float
    start: Array
    end: Array
    length_mm: float

    @property
    def in_contact(self) -> bool:
        return self.length_mm > 0.0


def contact_line(pinion, gear, assembly, psi: float, n: int = 401) -> ContactLine:
    """The contact line of pair 0 at pinion angle ``psi`` (rad): the sections of the common
    face in contact (``n`` samples, the ends refined by bisection to 1e-12 mm)."""
    pa = plane_of_action(pinion, gear, assembly)
    z = np.linspace(*pa.face, n)
    ok = section_contact(pinion, gear, pa, psi, z)[3]
    if not ok.any():
        zero = np.zeros(3)
        return ContactLine(math.inf, -math.inf, zero, zero, 0.0)
    i0, i1 = np.flatnonzero(ok)[[0, -1]]

    def edge(inside: float, outside: float) -> float:
        for _ in range(60):
            mid = 0.5 * (inside + outside)
            if section_contact(pinion, gear, pa, psi, mid)[3]:
                inside = mid
            else:
                outside = mid
            if abs(outside - inside) < 1e-12:
                break
        return inside

    z0 = z[i0] if i0 == 0 else edge(z[i0], z[i0 - 1])
    z1 = z[i1] if i1 == n - 1 else edge(z[i1], z[i1 + 1])
    P = section_contact(pinion, gear, pa, psi, np.array([z0, z1]))[0]
    return ContactLine(float(z0), float(z1), P[0], P[1], float(np.linalg.norm(P[1] - P[0])))


def _interval(pinion, gear, pa: PlaneOfAction, z: float) -> tuple[float, float]:
    """``(ψ_in, ψ_out)``: the pinion angles bounding the contact of pair 0's section ``z``
    (scan over ± 3 pitches, ends by bisection to 1e-14 rad)."""
    tau = 2 * math.pi / pinion.n_teeth
    psi = np.linspace(-3 * tau, 3 * tau, 1201)
    ok = section_contact(pinion, gear, pa, psi, z)[3]
    if not ok.any():
        raise InputError("pair", "no contact", "a pair whose flanks meet in the section")
    i0, i1 = np.flatnonzero(ok)[[0, -1]]
    if i0 == 0 or i1 == len(psi) - 1:
        raise InputError("pair", "contact over the whole scan", "a contact ratio below 6")

    def edge(inside: float, outside: float) -> float:
        for _ in range(80):
            mid = 0.5 * (inside + outside)
            if section_contact(pinion, gear, pa, mid, z)[3]:
                inside = mid
            else:
                outside = mid
            if abs(outside - inside) < 1e-14:
                break
        return 0.5 * (inside + outside)

    return edge(psi[i0], psi[i0 - 1]), edge(psi[i1], psi[i1 + 1])


@dataclass(frozen=True)
class ContactRatios:
    """Contact ratios measured on the members' flanks (see the module docstring).

    Attributes
    ----------
    eps_alpha, eps_beta, eps_gamma
        Transverse, overlap and total contact ratio.
    path_mm
        Length of the path of contact in the middle section (``ε_α p_bt``).
    start_limit, end_limit
        What bounds that path where it starts and ends: ``"gear tip"`` or ``"pinion form
        circle"``; ``"pinion tip"`` or ``"gear form circle"``.
    """

    eps_alpha: float
    eps_beta: float
    eps_gamma: float
    path_mm: float
    start_limit: str
    end_limit: str

    def as_dict(self) -> dict[str, object]:
        return {
            "eps_alpha": self.eps_alpha,
            "eps_beta": self.eps_beta,
            "eps_gamma": self.eps_gamma,
            "path_of_contact_mm": self.path_mm,
            "path_start_limit": self.start_limit,
            "path_end_limit": self.end_limit,
        }


def contact_ratios(pinion, gear, assembly) -> ContactRatios:
    """The :class:`ContactRatios` of a cylindrical pair (error-free assembly)."""
    pa = plane_of_action(pinion, gear, assembly)
    z0, z1 = pa.face
    k = pinion.n_teeth / (2 * math.pi)
    a_in, a_out = _interval(pinion, gear, pa, 0.5 * (z0 + z1))
    s_in, s_out = _interval(pinion, gear, pa, z0)
    e_in, e_out = _interval(pinion, gear, pa, z1)
    eps_a = (a_out - a_in) * k
    eps_b = abs(s_in - e_in) * k
    eps_g = (max(s_out, e_out) - min(s_in, e_in)) * k
    zm = 0.5 * (z0 + z1)
    L1 = section_contact(pinion, gear, pa, np.array([a_in, a_out]), zm)[1]
    b1, b2 = pinion.boundaries("drive"), gear.boundaries("drive")
    L1_form, L1_tip = (float(x) for x in pinion.roll_length([b1.u_fillet, b1.u_tip]))
    L2_form, L2_tip = (float(x) for x in gear.roll_length([b2.u_fillet, b2.u_tip]))
    g = pa.length_mm
    start = "gear tip" if g - L2_tip >= L1_form else "pinion form circle"
    end = "pinion tip" if L1_tip <= g - L2_form else "gear form circle"
    return ContactRatios(eps_a, eps_b, eps_g, float(L1[1] - L1[0]), start, end)


def iso_contact_ratios(pinion, gear, assembly) -> tuple[float, float, float]:
    r"""``(ε_α, ε_β, ε_γ)`` in closed form (ISO 21771:2007 §5.4):

    .. math:: \varepsilon_\alpha = \frac{\sqrt{r_{a1}^2 - r_{b1}^2} + \sqrt{r_{a2}^2 - r_{b2}^2}
              - a \sin\alpha_{wt}}{p_{bt}}, \qquad
              \varepsilon_\beta = \frac{b \sin\beta}{\pi m_n}, \qquad
              \varepsilon_\gamma = \varepsilon_\alpha + \varepsilon_\beta,

    ``p_bt = 2π r_b1 / z_1`` the transverse base pitch, ``b`` the common face width. Assumes
    that the tip circles bound the path of contact (see :func:`contact_ratios`)."""
    pa = plane_of_action(pinion, gear, assembly)
    pbt = 2 * math.pi * pinion.r_b / pinion.n_teeth
    ea = (
        math.sqrt(pinion.r_a**2 - pinion.r_b**2)
        + math.sqrt(gear.r_a**2 - gear.r_b**2)
        - pa.length_mm
    ) / pbt
    d = pinion.design
    eb = (
        (pa.face[1] - pa.face[0])
        * abs(math.sin(math.radians(d.helix_angle_deg)))
        / (math.pi * d.module_mm)
    )
    return ea, eb, ea + eb
