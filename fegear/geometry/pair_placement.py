"""Placement of a gear pair in one fixed frame, with installation (assembly) errors.

Every placement of fegear is built here, as 4×4 homogeneous transforms (column vectors, see
:mod:`fegear.geometry.transforms`). A member placement is

.. math::

    M_i(\\varphi_i) = B_i \\; R_z\\big(s_i\\,(\\varphi_i + \\varphi_{i,0})\\big) \\; C_i ,

with ``B_i`` the (error-carrying) placement of the member axis, ``s_i = ±1`` the sense of the
driving rotation about the member ``z`` axis, ``φ_i`` the rotation angle in the driving sense
(rad), ``φ_{i,0}`` the phase (member 2: the reference contact position, see
:func:`fegear.tca.reference_phase`) and ``C_i`` a constant member-frame transform. Tooth ``k``
of a member is tooth 0 turned by ``k·2π/N`` about the member ``z`` axis (``tooth_transform``).

Sign conventions (written once; ``docs/conventions.md``, ``docs/tca/assembly_conventions.png``)
-----------------------------------------------------------------------------------------------
Intersecting axes (face gear, spiral bevel). The axes of the error-free pair intersect at the
crossing point ``O`` (bevel: the pitch-cone apex; face gear: the point of the face-gear axis at the
height ``r_p1`` of the pinion axis). Fixed frame: member-2 axis ``+z`` (face gear) or
``+x`` (bevel mesh frame of :mod:`fegear.geometry.bevel.mesh_frame`), common perpendicular ``y``.

- ``ΔE`` (mm): change of the shortest distance between the axes; the pinion is moved by ``ΔE``
  along ``+y`` (the common perpendicular), so the axes become crossed (hypoid-like offset).
- ``ΔA1`` = ``ΔP`` (mm): pinion moved along its own axis, positive AWAY from ``O``
  (larger mounting distance; for a bevel pinion: along the apex→blank direction).
- ``ΔA2`` = ``ΔG`` (bevel) = ``Δq`` (face gear) (mm): member 2 moved along its own axis, positive
  AWAY from ``O`` (face gear: the face gear moves along ``−z``, away from the pinion axis).
- ``Δγ`` (deg): change of the shaft angle; the pinion axis is turned about the common
  perpendicular through ``O`` so that the angle between the two axes becomes ``γ + Δγ``.

Parallel axes (spur / helical). Fixed frame: pinion axis ``+z`` through the origin, gear axis
through ``(a, 0, 0)``; the plane of the axes is ``xz``; face centre at ``z = 0``.

- ``Δa`` (mm): centre-distance change, gear moved along ``+x``.
- ``f_Σδ`` (mm over the gear face width ``b``): in-plane axis-parallelism deviation
  (ISO 1328-1:1995 §... / ISO/TR 10064-3: "deviation of parallelism of axes in the plane of the
  axes", symbol f_Σδ). The gear axis is turned about ``+y`` through the face centre by
  ``atan(f_Σδ / b)``: the centre distance grows by ``f_Σδ`` from ``z = −b/2`` to ``z = +b/2``.
- ``f_Σβ`` (mm over ``b``): out-of-plane deviation ("in the plane perpendicular to the plane of
  the axes", f_Σβ). The gear axis is turned about ``−x`` through the face centre by
  ``atan(f_Σβ / b)``: the gear axis leans toward ``+y`` at ``z = +b/2``.

Both ISO deviations are given here as lengths over the face width (what the mesh sees), not over
the bearing span L of ISO/TR 10064-3; convert with ``f_b = f_L · b / L``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .bevel.mesh_frame import gear_frame
from .transforms import compose, inverse, rot_axis, rot_x, rot_y, rot_z, translation

__all__ = [
    "InstallationErrors",
    "Assembly",
    "involute_assembly",
    "face_gear_assembly",
    "spiral_bevel_assembly",
    "tooth_transform",
]

Array = NDArray[np.float64]
Kind = Literal["parallel", "intersecting", "crossed"]


def tooth_transform(n_teeth: int, k: ArrayLike) -> Array:
    """Member-frame transform of tooth ``k``: ``rot_z(2πk/N)``, shape ``(..., 4, 4)``."""
    return rot_z(2.0 * np.pi * np.asarray(k, dtype=float) / n_teeth)


@dataclass(frozen=True)
class InstallationErrors:
    """Installation errors (sign conventions in the module docstring).

    Intersecting axes: ``dE_mm`` (ΔE), ``dA1_mm`` (ΔA1 = ΔP), ``dA2_mm`` (ΔA2 = ΔG = Δq),
    ``dgamma_deg`` (Δγ). Parallel axes: ``da_mm`` (Δa), ``f_sigma_delta_mm`` (f_Σδ, in-plane),
    ``f_sigma_beta_mm`` (f_Σβ, out-of-plane), both over the face width. ``dA1_mm``/``dA2_mm``
    also apply to parallel axes (axial shift along ``+z``).
    """

    dE_mm: float = 0.0
    dA1_mm: float = 0.0
    dA2_mm: float = 0.0
    dgamma_deg: float = 0.0
    da_mm: float = 0.0
    f_sigma_delta_mm: float = 0.0
    f_sigma_beta_mm: float = 0.0

    def __post_init__(self) -> None:
        for name in self.__dataclass_fields__:
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InputError(f"errors.{name}", v, "a finite number")
        if abs(self.dgamma_deg) > 10.0:
            raise InputError("errors.dgamma_deg", self.dgamma_deg, "|Δγ| <= 10 deg")

    @property
    def is_zero(self) -> bool:
        return all(getattr(self, n) == 0.0 for n in self.__dataclass_fields__)


@dataclass(frozen=True)
class Assembly:
    """A pair placed in the fixed frame: ``M_i(φ_i) = B_i R_z(s_i (φ_i + phase_i)) C_i``.

    Attributes
    ----------
    kind
        ``"parallel"``, ``"intersecting"`` or ``"crossed"`` (a hypoid: offset axes).
    n1, n2
        Tooth numbers (member 1 pinion, driving; member 2 gear, driven).
    side1, side2
        Flanks of each member that are in contact when member 1 drives.
    base1, base2
        ``(4, 4)`` axis placements ``B_i`` (errors included).
    sense1, sense2
        ``±1``: driving rotation is about ``s_i · z`` of the member frame.
    phase1, phase2
        Phases (rad, driving sense). ``phase2`` is the gear angle of the reference contact at
        ``φ1 = 0`` (see :func:`fegear.tca.reference_phase`).
    const1, const2
        ``(4, 4)`` member-frame transforms applied first (identity unless a family needs one).
    errors
        The installation errors built into ``base1``/``base2``.
    face_width_mm
        Face width used for the parallelism deviations (parallel axes), else 0.
    nominal
        The error-free assembly builder (a callable returning the same assembly without errors);
        used to compute the reference phase.
    """

    kind: Kind
    n1: int
    n2: int
    side1: str
    side2: str
    base1: Array
    base2: Array
    sense1: int
    sense2: int
    phase1: float = 0.0
    phase2: float = 0.0
    const1: Array = field(default_factory=lambda: np.eye(4))
    const2: Array = field(default_factory=lambda: np.eye(4))
    errors: InstallationErrors = field(default_factory=InstallationErrors)
    face_width_mm: float = 0.0
    nominal: Callable[[], Assembly] | None = field(default=None, repr=False, compare=False)

    @property
    def ratio(self) -> float:
        """Nominal ratio ``N1/N2`` (φ2 = ratio · φ1)."""
        return self.n1 / self.n2

    def placement1(self, phi1: ArrayLike) -> Array:
        """``M1(φ1)``: pinion frame → fixed frame, ``(..., 4, 4)``."""
        a = self.sense1 * (np.asarray(phi1, dtype=float) + self.phase1)
        return compose(self.base1, rot_z(a), self.const1)

    def placement2(self, phi2: ArrayLike) -> Array:
        """``M2(φ2)``: gear frame → fixed frame, ``(..., 4, 4)``."""
        a = self.sense2 * (np.asarray(phi2, dtype=float) + self.phase2)
        return compose(self.base2, rot_z(a), self.const2)

    def axis1(self) -> tuple[Array, Array]:
        """Point on and unit direction of the member-1 axis (fixed frame)."""
        return self.base1[:3, 3].copy(), self.base1[:3, 2].copy()

    def axis2(self) -> tuple[Array, Array]:
        """Point on and unit direction of the member-2 axis (fixed frame)."""
        return self.base2[:3, 3].copy(), self.base2[:3, 2].copy()

    def with_phase2(self, phase2: float) -> Assembly:
        return replace(self, phase2=float(phase2))

    def without_errors(self) -> Assembly:
        """The same pair without installation errors (same phases)."""
        if self.nominal is None or self.errors.is_zero:
            return self
        return replace(self.nominal(), phase1=self.phase1, phase2=self.phase2)

    def axes_distance(self) -> float:
        """Shortest distance between the two axes (mm); for parallel axes the distance at z=0."""
        p1, e1 = self.axis1()
        p2, e2 = self.axis2()
        c = np.cross(e1, e2)
        if np.linalg.norm(c) < 1e-12:
            d = p2 - p1
            return float(np.linalg.norm(d - np.dot(d, e1) * e1))
        return float(abs(np.dot(p2 - p1, c)) / np.linalg.norm(c))

    def shaft_angle_deg(self) -> float:
        """Angle between the axes (deg)."""
        e1, e2 = self.axis1()[1], self.axis2()[1]
        return float(np.degrees(np.arccos(np.clip(np.dot(e1, e2), -1.0, 1.0))))


def _about(point: ArrayLike, M: Array) -> Array:
    """``M`` applied about ``point`` (a rigid motion with that fixed point)."""
    p = np.asarray(point, dtype=float)
    return compose(translation(p), M, translation(-p))


def involute_assembly(
    pinion, gear, errors: InstallationErrors | None = None, face_offset_mm: float = 0.0
) -> Assembly:
    """Parallel-axes placement of two external involute members (spur / helical).

    Pinion axis ``+z`` through the origin, turning about ``+z``; gear axis through
    ``(a, 0, 0)`` turning about ``−z`` (both ``"drive"`` flanks in contact, see
    :mod:`fegear.geometry.involute`). ``a`` is the working centre distance of zero backlash,
    ``inv α_w = inv α_t + 2 tan α_n (x1 + x2)/(z1 + z2)`` (ISO 21771 eq. for a_w).
    Geometric phase: pinion tooth 0 on ``+x`` (towards the gear), gear tooth 0 at polar angle
    ``π − π/N2`` about the gear axis (its drive flank faces the space on ``−x``).
    ``face_offset_mm``: design axial offset of the pinion's face centre from the gear's (along
    ``+z``); the parallelism deviations are then given over the width where the faces overlap.
    """
    errors = errors or InstallationErrors()
    d1, d2 = pinion.design, gear.design
    at = pinion.alpha_t
    an = math.radians(d1.pressure_angle_deg)
    inv = math.tan(at) - at
    inv_w = inv + 2 * math.tan(an) * (d1.profile_shift + d2.profile_shift) / (
        d1.n_teeth + d2.n_teeth
    )
    aw = _inv_inverse(inv_w)
    a = (pinion.r_p + gear.r_p) * math.cos(at) / math.cos(aw)
    b1, b2, off = d1.face_width_mm, d2.face_width_mm, float(face_offset_mm)
    b = min(off + b1 / 2, b2 / 2) - max(off - b1 / 2, -b2 / 2) if off else min(b1, b2)
    if b <= 0:
        raise InputError("face_offset_mm", off, f"|offset| < {(b1 + b2) / 2:g} (faces overlap)")
    base1 = translation([0.0, 0.0, errors.dA1_mm + off])
    tilt = compose(
        rot_y(math.atan2(errors.f_sigma_delta_mm, b)),
        rot_x(-math.atan2(errors.f_sigma_beta_mm, b)),
    )
    centre = np.array([a + errors.da_mm, 0.0, 0.0])
    base2 = compose(_about(centre, tilt), translation(centre + [0.0, 0.0, errors.dA2_mm]))

    def nominal() -> Assembly:
        return involute_assembly(pinion, gear, face_offset_mm=off)

    return Assembly(
        kind="parallel",
        n1=d1.n_teeth,
        n2=d2.n_teeth,
        side1="drive",
        side2="drive",
        base1=base1,
        base2=base2,
        sense1=1,
        sense2=-1,
        phase1=0.0,
        phase2=-math.pi + math.pi / d2.n_teeth,
        errors=errors,
        face_width_mm=b,
        nominal=nominal,
    )


def _inv_inverse(y: float) -> float:
    """Solve ``tan α − α = y`` for α (Newton; converges from α = (3y)^(1/3))."""
    a = (3.0 * y) ** (1.0 / 3.0) if y > 0 else 0.0
    for _ in range(50):
        f = math.tan(a) - a - y
        a -= f / math.tan(a) ** 2 if a else 0.0
        if abs(f) < 1e-16:
            break
    return a


def face_gear_assembly(
    face_gear, errors: InstallationErrors | None = None, pinion=None
) -> Assembly:
    """Face gear (member 2, axis ``+z`` of the fixed frame) and its spur pinion (member 1).

    Fixed frame = face-gear frame of :mod:`fegear.geometry.face_gear` (pitch plane ``z = 0``).
    Error-free pinion axis: through ``O = (0, 0, r_p1)`` along ``rot_y(γ) e_z`` (``+x`` for
    γ = 90°); the pinion face centre (its member ``z = 0``) sits at the mean face-gear radius
    ``(L_i + L_o)/2`` along that axis. The pinion turns about its ``+z`` (``sense1 = +1``) and
    drives with its ``"drive"`` flank the face-gear ``"coast"`` flank; the face gear then turns
    about ``+z`` (``sense2 = +1``). Errors as in the module docstring: ΔE along ``+y``, ΔA1 along
    the pinion axis away from ``O``, Δq = ΔA2 along ``−z``, Δγ about ``y`` through ``O``.
    """
    errors = errors or InstallationErrors()
    d = face_gear.design
    pinion = pinion or face_gear.pinion()
    r1 = pinion.r_p
    Lm = 0.5 * (d.inner_radius_mm + d.outer_radius_mm)
    O = np.array([0.0, 0.0, r1])
    g = math.radians(d.shaft_angle_deg + errors.dgamma_deg)
    base1 = compose(
        translation(O + [0.0, errors.dE_mm, 0.0]),
        rot_y(g),
        translation([0.0, 0.0, Lm + errors.dA1_mm]),
    )
    base2 = translation([0.0, 0.0, -errors.dA2_mm])

    def nominal() -> Assembly:
        return face_gear_assembly(face_gear, None, pinion)

    return Assembly(
        kind="intersecting",
        n1=pinion.n_teeth,
        n2=d.n_face_gear,
        side1="drive",
        side2="coast",
        base1=base1,
        base2=base2,
        sense1=1,
        sense2=1,
        phase1=0.0,
        phase2=math.pi / d.n_face_gear,
        errors=errors,
        face_width_mm=0.0,
        nominal=nominal,
    )


def spiral_bevel_assembly(
    pair, side: str = "drive", errors: InstallationErrors | None = None
) -> Assembly:
    """Spiral bevel or hypoid pair in the mesh frame of :mod:`fegear.geometry.bevel.mesh_frame`.

    Pinion pitch apex at the origin, pinion axis ``+z``; the gear axis through its pitch apex
    ``A2`` along ``e2`` (``rot_y(Σ) e_z`` through the origin for intersecting axes); at
    ``φ1 = φ2 = 0`` the mean points of the ``side`` flanks coincide (phase2 = 0 is already the
    reference). The pinion turns about ``σ e_z``, the gear about ``−σ e2`` (σ of the synthesis
    report). Errors, about the crossing point ``O`` of the axes (the point of the pinion axis
    nearest the gear axis): ΔE along the common perpendicular ``d`` from the gear axis to the
    pinion axis (``+y`` for intersecting axes), so that the distance of the axes becomes
    ``E + ΔE``; ΔP along ``+z`` (pinion, away from its apex and ``O``), ΔG along ``+e2`` (gear,
    away from its apex); Δγ: the pinion axis turned about ``e_z × e2`` through ``O`` by ``−Δγ``
    so that the shaft angle becomes ``Σ + Δγ``.
    """
    errors = errors or InstallationErrors()
    r = pair.placements[side]
    blank = pair.blank
    sigma = int(round(r.sigma))
    A2, e2 = blank.gear_axis()
    O = blank.crossing_point()
    axis = np.cross([0.0, 0.0, 1.0], e2)
    d = np.array([0.0, 1.0, 0.0])
    if blank.offset_mm > 0.0:  # from the gear axis's nearest point to O
        foot = A2 + e2 * np.dot(O - A2, e2)
        d = (O - foot) / np.linalg.norm(O - foot)
    base1 = compose(
        translation(errors.dE_mm * d),
        _about(O, rot_axis(axis, -math.radians(errors.dgamma_deg))),
        translation([0.0, 0.0, errors.dA1_mm]),
    )
    base2 = compose(gear_frame(blank), translation([0.0, 0.0, errors.dA2_mm]))

    def nominal() -> Assembly:
        return spiral_bevel_assembly(pair, side, None)

    return Assembly(
        kind="intersecting" if blank.offset_mm == 0.0 else "crossed",
        n1=blank.n1,
        n2=blank.n2,
        side1=side,
        side2=side,
        base1=base1,
        base2=base2,
        sense1=sigma,
        sense2=-sigma,
        phase1=0.0,
        phase2=0.0,
        const1=rot_z(-r.pinion_flank_angle),
        const2=rot_z(-r.gear_flank_angle),
        errors=errors,
        nominal=nominal,
    )


def relative_transform(asm: Assembly, phi1: ArrayLike, phi2: ArrayLike) -> Array:
    """``M2(φ2)⁻¹ M1(φ1)``: pinion frame → gear frame, ``(..., 4, 4)``."""
    return compose(inverse(asm.placement2(phi2)), asm.placement1(phi1))
