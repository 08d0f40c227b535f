"""Cylindrical (spur and helical) members with the flank modifications engineers specify.

A :class:`CylindricalMember` is the rack-generated involute member of
:mod:`fegear.geometry.involute` (same frames, flank parameters ``(u, v = z)``, generated
trochoidal fillet, tip and root) whose *working flank* is the exact involute helicoid plus the
flank modifications, in closed form.

Involute helicoid (Litvin & Fuentes 2004 §10.3, §14.3; ISO 21771 §4). Transverse section
``z`` of the ``"drive"`` flank of tooth 0 at roll parameter ``ε = tan α_y`` (``α_y`` the
transverse pressure angle at the point)::

    P(ε, z) = R_z(ω(z)) · r_b (e(λ) + ε e'(λ)) + z e_z,   λ = ψ_b − ε,   ω(z) = −z tan β / r

with ``e(λ) = (cos λ, sin λ, 0)``, ``e'(λ) = (−sin λ, cos λ, 0)``, ``r_b`` the base radius,
``r = m_n z/(2 cos β)`` the reference radius, ``β`` the signed helix angle of
:class:`~fegear.geometry.involute.InvoluteDesign` (``β > 0``: left hand, the tooth trace turns
towards −θ with increasing ``z``; ``β < 0``: right hand) and
``ψ_b = (π/2 + 2 x tan α_n)/z + inv α_t`` the half tooth angle at the base circle. The
``"coast"`` flank is the mirror image ``y → −y`` of the section, turned by the same ``ω(z)``.
The rack profile parameter ``u`` is affine in the transverse roll length ``L = r_b ε``:
``L = r sin α_t + (h + x m_n)/sin α_t`` for the rack datum height ``h`` of the straight flank
that generates the point (the contact lies on the transverse line of action at ``η/sin α_t``
from the pitch point, ``η = h + x m_n``).

Flank modifications (ISO 21771:2007 §7; ISO 1328-1 measures them the same way). A modification
``δ(L, z)`` (mm, positive: material removed) moves the point against the outward transverse
normal ``n_t = R_z(ω) e'(λ)``, i.e. along the transverse line of action::

    X(ε, z) = P(ε, z) − δ(r_b ε, z) n_t(ε, z)

so ``δ`` is the deviation measured in the transverse section along the line of action, as on a
gear-measuring machine's profile and helix charts; along the 3-D flank normal it is
``δ cos β_b``. It is the sum of (``L`` transverse roll length, ``z`` axial position from the
face centre, ``b`` the face width, ``k`` = 1 linear or 2 parabolic):

- profile crowning ``C_α (2 (L − L_m)/L_w)²`` over the working profile ``L_f … L_a`` (form
  circle of the generation to the tip; ``L_m`` its middle, ``L_w`` its length);
- tip relief ``C_a ((L − L_Ca)/(L_a − L_Ca))^k`` above its start ``L_Ca``, root relief
  ``C_f ((L_Cf − L)/(L_Cf − L_f))^k`` below its start ``L_Cf`` (a start is given as a diameter
  ``d`` — ``L = √(d²/4 − r_b²)`` — or as a roll angle ``ξ`` in degrees — ``L = r_b ξ``);
- lead crowning ``C_β (2 z/b)²``;
- helix slope deviation ``f_Hβ z/b`` (positive: material removed towards the ``+z`` face end,
  added towards ``−z``; a helix slope of ``f_Hβ`` over the face on one member turns its contact
  lines in the plane of action as an axis inclination ``f_Σβ = f_Hβ`` would);
- end relief ``C_e ((|z| − (b/2 − l_e))/l_e)^k`` over a length ``l_e`` at both face ends.

The normal of ``X`` is ``X_ε × X_z`` (exact: ``δ`` and its first derivatives enter). The
fillet (``u < u_fillet``) is the generated fillet of the unmodified rack: the modifications
are those of a finished (ground) flank, which end at the form circle; where a modification
is not zero there (profile crowning, root relief, lead modifications) the flank stands back from
the fillet by that amount, as on a ground gear.

The sector meshes of a member are made of its unmodified solid (:meth:`CylindricalMember.
mesh_member`): modifications of some µm change neither the stiffness nor a mesh of elements
of tenths of a millimetre, and the gaps of the contact come from the exact modified surfaces.
A study of modifications therefore reads its meshes and compliance operators from the cache.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import DesignError, InputError
from .involute import InvoluteDesign, InvoluteMember
from .surface import FlankCoordinates, FlankSurface, Side, finite_difference_curvatures

__all__ = [
    "CylindricalMember",
    "FlankModifications",
    "RELIEF_SHAPES",
    "cylindrical_member",
    "signed_helix_deg",
]

Array = NDArray[np.float64]

#: Shapes of the tip, root and end reliefs: exponent ``k`` of ``((x − x_s)/l)^k``.
RELIEF_SHAPES = {"linear": 1, "parabolic": 2}


@dataclass(frozen=True)
class FlankModifications:
    """The flank modifications of one member (mm, transverse, positive = material removed; see
    the module docstring for the formulas).

    Attributes
    ----------
    lead_crowning_mm
        ``C_β``: removed at both face ends.
    helix_slope_mm
        ``f_Hβ``: helix slope deviation over the face width (signed).
    end_relief_mm, end_relief_length_mm, end_relief_shape
        ``C_e`` at both face ends over ``l_e`` (``0 < l_e <= b/2``), ``"linear"`` or
        ``"parabolic"``.
    profile_crowning_mm
        ``C_α``: removed at the form circle and at the tip.
    tip_relief_mm, tip_relief_shape
        ``C_a`` at the tip circle.
    tip_relief_start_diameter_mm, tip_relief_start_roll_deg
        Where the tip relief starts: a diameter or a roll angle (at most one; neither: at the
        radius 60 % of the way from the reference to the tip radius).
    root_relief_mm, root_relief_shape
        ``C_f`` at the form circle.
    root_relief_start_diameter_mm, root_relief_start_roll_deg
        Where the root relief starts (neither: at the radius 60 % of the way from the reference
        to the form radius).
    """

    lead_crowning_mm: float = 0.0
    helix_slope_mm: float = 0.0
    end_relief_mm: float = 0.0
    end_relief_length_mm: float | None = None
    end_relief_shape: str = "linear"
    profile_crowning_mm: float = 0.0
    tip_relief_mm: float = 0.0
    tip_relief_shape: str = "linear"
    tip_relief_start_diameter_mm: float | None = None
    tip_relief_start_roll_deg: float | None = None
    root_relief_mm: float = 0.0
    root_relief_shape: str = "linear"
    root_relief_start_diameter_mm: float | None = None
    root_relief_start_roll_deg: float | None = None

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name.endswith("_shape"):
                if v not in RELIEF_SHAPES:
                    raise InputError(f.name, v, "'linear' or 'parabolic'")
                continue
            if v is None:
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InputError(f.name, v, "a finite number")
            if f.name != "helix_slope_mm" and v < 0:
                raise InputError(f.name, v, ">= 0")
        for which in ("tip", "root"):
            d = getattr(self, f"{which}_relief_start_diameter_mm")
            r = getattr(self, f"{which}_relief_start_roll_deg")
            if d is not None and r is not None:
                raise InputError(
                    f"{which}_relief_start_roll_deg",
                    r,
                    f"absent when {which}_relief_start_diameter_mm is given (one start only)",
                )
        if self.end_relief_mm > 0 and self.end_relief_length_mm is None:
            raise InputError("end_relief_length_mm", None, "> 0 when end_relief_mm > 0")

    @property
    def is_zero(self) -> bool:
        """No modification at all."""
        return not any(
            getattr(self, n)
            for n in (
                "lead_crowning_mm",
                "helix_slope_mm",
                "end_relief_mm",
                "profile_crowning_mm",
                "tip_relief_mm",
                "root_relief_mm",
            )
        )

    @property
    def lead_only(self) -> bool:
        """Only modifications along the face (the profile is the involute)."""
        return not (self.profile_crowning_mm or self.tip_relief_mm or self.root_relief_mm)


@dataclass(frozen=True)
class _Profile:
    """Roll lengths (mm) of the working profile and of the relief starts of one member."""

    L_form: float
    L_tip: float
    L_tip_relief: float
    L_root_relief: float


@dataclass(frozen=True)
class CylindricalMember(InvoluteMember):
    """A spur/helical involute member with flank modifications (see the module docstring).

    ``design`` carries the basic geometry (its rack modifications must be 0: the modifications
    are ``mods``, defined on the flank); ``mods`` the :class:`FlankModifications`.

    Raises
    ------
    InputError
        A modification out of range (naming the :class:`FlankModifications` field): a relief
        start outside the working profile, a root relief starting above the tip relief, an end
        relief longer than half the face.
    """

    mods: FlankModifications = field(default_factory=FlankModifications)

    def __post_init__(self) -> None:
        d = self.design
        for f in ("profile_crowning_mm", "lead_crowning_mm", "tip_relief_mm"):
            if getattr(d, f):
                raise InputError(f, getattr(d, f), "0 in the design (give it in mods)")
        p, m = self._profile, self.mods
        for which, L in (("tip", p.L_tip_relief), ("root", p.L_root_relief)):
            if getattr(m, f"{which}_relief_mm") and not p.L_form < L < p.L_tip:
                key = f"{which}_relief_start_" + (
                    "roll_deg"
                    if getattr(m, f"{which}_relief_start_roll_deg") is not None
                    else "diameter_mm"
                )
                given = getattr(m, key)
                lo = 2 * math.hypot(self.r_b, p.L_form)
                hi = 2 * self.r_a
                if key.endswith("roll_deg"):
                    lo, hi = math.degrees(p.L_form / self.r_b), math.degrees(p.L_tip / self.r_b)
                raise DesignError(
                    key, given, f"in ({lo:.4f}, {hi:.4f}) (the working profile of {self.name})"
                )
        if (m.tip_relief_mm and m.root_relief_mm) and p.L_root_relief > p.L_tip_relief:
            raise DesignError(
                "root_relief_start_diameter_mm"
                if m.root_relief_start_roll_deg is None
                else "root_relief_start_roll_deg",
                m.root_relief_start_diameter_mm or m.root_relief_start_roll_deg,
                "below the start of the tip relief",
            )
        b = d.face_width_mm
        if m.end_relief_length_mm is not None and not 0 < m.end_relief_length_mm <= b / 2:
            raise DesignError(
                "end_relief_length_mm", m.end_relief_length_mm, f"in (0, {b / 2:g}] (half the face)"
            )

    # ------------------------------------------------------------------ profile
    @cached_property
    def _roll_affine(self) -> tuple[float, float]:
        """``(k, L0)``: transverse roll length ``L = L0 + k u`` of the working flank."""
        d = self.design
        rack = self.rack("drive")
        at = self.alpha_t
        h = np.array([0.0, 1.0])
        u = rack.u_of_height(h)
        L = self.r_p * math.sin(at) + (h + d.profile_shift * d.module_mm) / math.sin(at)
        k = float((L[1] - L[0]) / (u[1] - u[0]))
        return k, float(L[0] - k * u[0])

    def roll_length(self, u: ArrayLike) -> Array:
        """Transverse roll length ``L = √(r_y² − r_b²)`` (mm) of working-flank parameter ``u``."""
        k, L0 = self._roll_affine
        return L0 + k * np.asarray(u, dtype=float)

    def u_of_roll_length(self, L: ArrayLike) -> Array:
        """Inverse of :meth:`roll_length`."""
        k, L0 = self._roll_affine
        return (np.asarray(L, dtype=float) - L0) / k

    @cached_property
    def _profile(self) -> _Profile:
        bd = self.boundaries("drive")
        L_f, L_a = (float(x) for x in self.roll_length([bd.u_fillet, bd.u_tip]))
        m, rb = self.mods, self.r_b

        def start(which: str, default_radius: float) -> float:
            d = getattr(m, f"{which}_relief_start_diameter_mm")
            xi = getattr(m, f"{which}_relief_start_roll_deg")
            if xi is not None:
                return rb * math.radians(xi)
            r = default_radius if d is None else 0.5 * d
            return math.sqrt(max(r * r - rb * rb, 0.0))

        r_form = math.hypot(rb, L_f)
        return _Profile(
            L_form=L_f,
            L_tip=L_a,
            L_tip_relief=start("tip", self.r_p + 0.6 * (self.r_a - self.r_p)),
            L_root_relief=start("root", self.r_p - 0.6 * (self.r_p - r_form)),
        )

    @property
    def form_radius(self) -> float:
        """Radius of the form circle (where the generated fillet meets the involute), mm."""
        return math.hypot(self.r_b, self._profile.L_form)

    # ------------------------------------------------------------------ modification
    def modification(self, L: ArrayLike, z: ArrayLike) -> tuple[Array, Array, Array]:
        """``δ(L, z)`` (mm, positive: material removed) and ``∂δ/∂L``, ``∂δ/∂z`` at transverse
        roll length ``L`` and axial position ``z`` (member frame, face centre ``z = 0``)."""
        L, z = np.broadcast_arrays(np.asarray(L, dtype=float), np.asarray(z, dtype=float))
        m, p = self.mods, self._profile
        d = np.zeros(L.shape)
        dL = np.zeros(L.shape)
        dz = np.zeros(L.shape)
        if m.profile_crowning_mm:
            Lm, Lw = 0.5 * (p.L_form + p.L_tip), p.L_tip - p.L_form
            d += m.profile_crowning_mm * (2 * (L - Lm) / Lw) ** 2
            dL += m.profile_crowning_mm * 8 * (L - Lm) / Lw**2
        for C, k, s, span, sign in (
            (m.tip_relief_mm, RELIEF_SHAPES[m.tip_relief_shape], L - p.L_tip_relief,
             p.L_tip - p.L_tip_relief, 1.0),
            (m.root_relief_mm, RELIEF_SHAPES[m.root_relief_shape], p.L_root_relief - L,
             p.L_root_relief - p.L_form, -1.0),
        ):  # fmt: skip
            if C:
                w = np.maximum(s, 0.0) / span
                d += C * w**k
                dL += sign * C * k * w ** (k - 1) / span * (s > 0)
        b = self.design.face_width_mm
        if m.lead_crowning_mm:
            d += m.lead_crowning_mm * (2 * z / b) ** 2
            dz += m.lead_crowning_mm * 8 * z / b**2
        if m.helix_slope_mm:
            d += m.helix_slope_mm * z / b
            dz += m.helix_slope_mm / b
        if m.end_relief_mm:
            le = float(m.end_relief_length_mm)  # type: ignore[arg-type]
            k = RELIEF_SHAPES[m.end_relief_shape]
            s = np.abs(z) - (0.5 * b - le)
            w = np.maximum(s, 0.0) / le
            d += m.end_relief_mm * w**k
            dz += np.sign(z) * m.end_relief_mm * k * w ** (k - 1) / le * (s > 0)
        return d, dL, dz

    # ------------------------------------------------------------------ surface
    @cached_property
    def _psi_b(self) -> float:
        d = self.design
        return (
            (math.pi / 2 + 2 * d.profile_shift * math.tan(math.radians(d.pressure_angle_deg)))
            / d.n_teeth
            + math.tan(self.alpha_t)
            - self.alpha_t
        )

    def helicoid(
        self, side: Side, u: ArrayLike, v: ArrayLike, modified: bool = True
    ) -> tuple[Array, Array, Array, Array]:
        """Closed-form working flank at ``(u, v)`` (any ``u``: the involute helicoid continued):
        points, outward unit normals and the tangents ``∂X/∂u``, ``∂X/∂v``, each ``(..., 3)``;
        ``modified`` False: the involute helicoid without the modifications.

        In the unrotated section ``Xs = r_b (e + ε e') − δ e'`` (``de/dε = −e'``,
        ``de'/dε = e``): ``Xs_ε = (r_b ε − δ) e − r_b δ_L e'``; then
        ``X = R(ω) Xs + z e_z``, ``X_ε = R Xs_ε``, ``X_z = ω' R J Xs − δ_z R e' + e_z``
        (``J`` the quarter turn about z) and the normal ``X_ε × X_z``."""
        u, z = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        rb, k = self.r_b, self._roll_affine[0]
        L = self.roll_length(u)
        eps = L / rb
        lam = self._psi_b - eps
        c, s = np.cos(lam), np.sin(lam)
        sg = 1.0 if side == "drive" else -1.0  # coast: the section mirrored in y
        # e = (c, sg s), e' = (−s, sg c)
        if modified and not self.mods.is_zero:
            dl, dL, dz = self.modification(L, z)
        else:
            dl = dL = dz = None
        a = rb * eps if dl is None else rb * eps - dl
        xs, ys = rb * c - a * s, sg * (rb * s + a * c)  # r_b e + (r_b ε − δ) e'
        ex, ey = a * c, sg * a * s  # Xs_ε (before the δ_L term)
        if dL is not None:
            ex, ey = ex + rb * dL * s, ey - sg * rb * dL * c
        tb = math.tan(math.radians(self.design.helix_angle_deg))
        w1 = -tb / self.r_p  # dω/dz
        shape = u.shape + (3,)
        X, Xe, Xz, nt = (np.empty(shape) for _ in range(4))
        if w1 == 0.0:
            co, so = 1.0, 0.0
        else:
            om = w1 * z
            co, so = np.cos(om), np.sin(om)
        X[..., 0], X[..., 1], X[..., 2] = co * xs - so * ys, so * xs + co * ys, z
        Xe[..., 0], Xe[..., 1], Xe[..., 2] = co * ex - so * ey, so * ex + co * ey, 0.0
        nx, ny = -co * s - so * sg * c, -so * s + co * sg * c  # R e'
        nt[..., 0], nt[..., 1], nt[..., 2] = nx, ny, 0.0
        # ω' R J Xs = ω' J X (rotations about z commute)
        zx, zy = -w1 * X[..., 1], w1 * X[..., 0]
        if dz is not None:
            zx, zy = zx - dz * nx, zy - dz * ny
        Xz[..., 0], Xz[..., 1], Xz[..., 2] = zx, zy, 1.0
        N = np.cross(Xe, Xz)
        N /= np.linalg.norm(N, axis=-1, keepdims=True)
        N *= np.sign(np.sum(N * nt, -1))[..., None]
        Xe *= k / rb
        return X, N, Xe, Xz

    def point_normal(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Exact points ``(..., 3)`` and outward unit normals: the modified helicoid on the
        working flank (``u >= u_fillet``), the generated fillet below it."""
        u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
        p, n = self.helicoid(side, u, v)[:2]
        fil = u < self.rack(side).u_fillet
        if np.any(fil):
            pf, nf = super().point_normal(side, u[fil], v[fil])
            p[fil], n[fil] = pf, nf
        return p, n

    def flank_points(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Exact points and normals, fillet included (:meth:`point_normal`)."""
        return self.point_normal(side, u, v)

    def flank_coordinates(self, side: Side) -> FlankCoordinates:
        """Working flank of ``side``; fast evaluator ``"involute_helicoid"``: :meth:`helicoid`
        (the working flank continued past its limits, analytic tangents)."""
        return FlankCoordinates(self.boundaries(side), (1e-5, 1e-5), "involute_helicoid")

    def mesh_member(self) -> InvoluteMember:
        """The unmodified member whose solid the sector meshes are made of (see the module
        docstring)."""
        return InvoluteMember(self.design, self.name)

    def flank(
        self, side: Side, nu: int = 21, nv: int = 11, include_fillet: bool = True
    ) -> FlankSurface:
        """Flank of tooth 0 on an ``nu × nv`` grid (as :meth:`InvoluteMember.flank`); the
        curvatures of the working rows by central differences of the closed form (steps
        1e-3 mm: truncation ~1e-8 1/mm)."""
        base = super().flank(side, nu, nv, include_fillet)
        U, V = np.meshgrid(base.u, base.v, indexing="ij")
        work = U >= base.boundaries.u_fillet
        P, N = self.point_normal(side, U, V)
        kappa, dirs = base.kappa.copy(), base.directions.copy()
        if np.any(work):
            k, dd = finite_difference_curvatures(
                lambda a, b: self.helicoid(side, a, b)[0], U[work], V[work], 1e-3, N[work]
            )
            kappa[work], dirs[work] = k, dd
        resid = np.where(work, 0.0, base.meshing_residual)
        return FlankSurface(
            member=self.name, side=side, u=base.u, v=base.v, points=P, normals=N, kappa=kappa,
            directions=dirs, meshing_residual=resid, boundaries=base.boundaries,
        )  # fmt: skip

    # ------------------------------------------------------------------ data
    @property
    def hand(self) -> str:
        """``"right"``, ``"left"`` or ``"spur"``."""
        b = self.design.helix_angle_deg
        return "spur" if b == 0 else ("left" if b > 0 else "right")

    @property
    def beta_b(self) -> float:
        """Base helix angle ``|β_b|`` (rad): ``tan β_b = tan |β| cos α_t``."""
        return math.atan(abs(math.tan(math.radians(self.design.helix_angle_deg))) *
                         math.cos(self.alpha_t))  # fmt: skip


def signed_helix_deg(helix_angle_deg: float, hand: str) -> float:
    """The signed helix angle of :class:`~fegear.geometry.involute.InvoluteDesign` for a
    helix angle ``>= 0`` and a hand (``"right"``: ``−β``, ``"left"``: ``+β``)."""
    if hand not in ("right", "left"):
        raise InputError("hand", hand, "'right' or 'left'")
    return -abs(helix_angle_deg) if hand == "right" else abs(helix_angle_deg)


def cylindrical_member(
    name: str, design: InvoluteDesign, mods: FlankModifications | None = None
) -> CylindricalMember:
    """A :class:`CylindricalMember` (the design validated first, then the modifications)."""
    return CylindricalMember(design, name, mods or FlankModifications())
