r"""Contact ellipses along the unloaded TCA path, for every gear family.

At the contact point of a position the TCA measures the principal curvatures of both flanks on
the exact surfaces (:func:`contact_curvature`); this module turns them into what an engineer reads
(:class:`EllipseAt`, one per position, by :func:`ellipses`):

- the **principal relative curvatures** ``k_a <= k_b`` (1/mm) and their directions,
- Litvin's **instantaneous contact ellipse** for an elastic approach ``δ`` (the paint thickness),
- the **Hertz ellipse** (a, b, p0) of one pair carrying the whole load
  (:func:`fegear.mechanics.hertz_closed_form.hertz_point`).

Geometry (Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed. 2004, the chapter
"Mating Surfaces: Curvature Relations, Contact Ellipse"). At the contact point ``M`` both flanks
touch the common tangent plane; ``n`` is the pinion's outward unit normal. In tangent-plane
coordinates ``x = (ξ, η)`` each flank lies ``z_i = ½ xᵀ K_i x`` away from the plane, ``K_i`` its
curvature tensor with its *own* outward normal (convex positive; the gear's outward normal is
``−n``), so the separation of the flanks along ``n`` is

.. math::

    h(\xi, \eta) = z_1 + z_2 = \tfrac12 x^T (K_1 + K_2)\, x
                 = \tfrac12 (k_a \xi^2 + k_b \eta^2)

in the principal axes of the relative curvature tensor ``K_1 + K_2``, whose eigenvalues
``k_a <= k_b`` are Litvin's principal (induced normal) relative curvatures. (Litvin measures the
second surface's curvatures with the first surface's normal, so his ``k = κ^{(1)} − κ^{(2)}`` is
this sum; Johnson's ``h = A ξ² + B η²`` of :mod:`fegear.mechanics.hertz_closed_form` has ``A =
k_a/2``, ``B = k_b/2``.)

Instantaneous contact ellipse: the flanks pressed together by an approach ``δ`` overlap where
``h <= δ``; its boundary ``h = δ`` is the ellipse

.. math::

    \frac{\xi^2}{a^2} + \frac{\eta^2}{b^2} = 1, \qquad
    a = \sqrt{2\delta / k_a} = \sqrt{\delta / A}, \qquad
    b = \sqrt{2\delta / k_b} = \sqrt{\delta / B},

Litvin's ``a = |2δ/k_a|^{1/2}``, ``b = |2δ/k_b|^{1/2}``
(:func:`fegear.mechanics.hertz_closed_form.paint_ellipse`).
The major axis lies along ``ξ``, the direction of the smaller curvature; the axis ratio
``a/b = sqrt(k_b/k_a)`` does not depend on ``δ``. ``δ`` is a chosen constant (customarily the
paint thickness 0.00632 mm), not the elastic approach of a load: the Hertz ellipse of a load is
smaller and more elongated (:func:`fegear.mechanics.hertz_closed_form.hertz_point`; Johnson 1985
§4.2).

Hertz at the case's load: the pinion torque ``T1`` carried by this one pair, normal force
``F = T1 / |(e_1 × (M − O_1)) · n|`` (``O_1``, ``e_1`` a point on and the direction of the
pinion axis: the moment arm of the normal about it), ``E*`` of the two materials.

Line contact (an unmodified spur or helical pair): ``k_a = 0`` along the contact line (below
``1e-9 k_b`` here), no ellipse: ``a`` and the Hertz ellipse are ``None`` with a reason; ``b`` is
the half-width of the paint strip ``sqrt(2δ/k_b)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.surface import finite_difference_curvatures
from ..geometry.transforms import apply_vectors
from ..mechanics.hertz_closed_form import HertzPoint, effective_modulus, hertz_point, paint_ellipse
from ..units import NMM_PER_NM

__all__ = [
    "LINE_CONTACT_RATIO",
    "ContactCurvature",
    "EllipseAt",
    "contact_curvature",
    "cycle_record",
    "ellipse_at",
    "ellipses",
    "normal_force",
    "outline",
    "record",
]

Array = NDArray[np.float64]
#: ``k_a <= LINE_CONTACT_RATIO · k_b``: line contact (conjugate flanks), no ellipse
LINE_CONTACT_RATIO = 1e-9
#: relative step of the flank tangents ``∂X/∂u``, ``∂X/∂v`` (of the working-flank span)
_TANGENT_STEP = 1e-5


@dataclass(frozen=True)
class ContactCurvature:
    """The curvatures at the contact point of a pair, fixed frame.

    Attributes
    ----------
    normal
        ``(3,)`` pinion outward unit normal ``n``.
    e1
        ``(3,)`` the unit vector of the tangent plane the relative tensor was diagonalised from
        (``n × e_z``, or ``n × e_x`` when ``n`` is near ``e_z``); ``e2 = n × e1``.
    A, B
        ``k_a/2 <= k_b/2`` (1/mm): Johnson's coefficients of the gap ``A ξ² + B η²``.
    major_axis
        ``(3,)`` unit direction ``ξ`` of ``k_a`` (the major axis of any ellipse).
    pinion_k, gear_k
        ``(2,)`` principal curvatures of each flank (1/mm, convex positive with the flank's own
        outward normal, descending).
    pinion_dirs, gear_dirs
        ``(2, 3)`` their unit directions.
    pinion_tangents, gear_tangents
        ``(3, 2)`` mm per unit, ``∂X/∂u`` and ``∂X/∂v`` of each member's flank coordinates at the
        contact point (central differences of the exact flank): the map from flank coordinates to
        the tangent plane, used to draw an ellipse on a flank (:func:`outline`).
    """

    normal: Array
    e1: Array
    A: float
    B: float
    major_axis: Array
    pinion_k: Array
    gear_k: Array
    pinion_dirs: Array
    gear_dirs: Array
    pinion_tangents: Array
    gear_tangents: Array

    @property
    def k(self) -> tuple[float, float]:
        """Principal relative curvatures ``(k_a, k_b) = (2A, 2B)`` (1/mm)."""
        return 2.0 * self.A, 2.0 * self.B

    @property
    def minor_axis(self) -> Array:
        """``(3,)`` unit direction ``η = n × ξ`` of ``k_b``."""
        return np.cross(self.normal, self.major_axis)

    @property
    def line_contact(self) -> bool:
        """``k_a <= 1e-9 k_b`` (or ``k_b <= 0``): conjugate flanks touching along a line."""
        return not self.A > LINE_CONTACT_RATIO * max(self.B, 1e-300) or not self.B > 0


def _tangent_points(fm, uv: Array) -> tuple[Array, Array, tuple[float, float]]:
    """``(U, V, h)``: the four flank coordinates ``(u ± h_u, v)``, ``(u, v ± h_v)`` of the
    central differences of :func:`_flank_tangents` at ``uv``, kept inside the working flank."""
    bd = fm.bounds
    h = (_TANGENT_STEP * (bd.u_tip - bd.u_fillet), _TANGENT_STEP * (bd.v_end - bd.v_start))
    u = float(np.clip(uv[0], bd.u_fillet + h[0], bd.u_tip - h[0]))
    v = float(np.clip(uv[1], bd.v_start + h[1], bd.v_end - h[1]))
    return np.array([u + h[0], u - h[0], u, u]), np.array([v, v, v + h[1], v - h[1]]), h


def _flank_tangents(fm, ab: tuple[Array, Array], h: tuple[float, float], M: Array) -> Array:
    """``(3, 2)``: ``∂X/∂u``, ``∂X/∂v`` of flank ``fm`` by central differences over the
    native coordinates ``ab`` of :func:`_tangent_points` (steps ``h``), in the fixed frame
    (``M`` the member's placement)."""
    p = fm.evaluate(*ab)[0]
    t = np.stack([(p[0] - p[1]) / (2 * h[0]), (p[2] - p[3]) / (2 * h[1])], -1)  # (3, 2)
    return apply_vectors(M, t.T).T


def contact_curvature(
    fm1, fm2, M1: Array, M2: Array, uv1: Array, uv2: Array, n1: Array
) -> ContactCurvature:
    """The curvatures of a pair at its contact point (the TCA's ellipse step).

    Parameters
    ----------
    fm1, fm2
        :class:`~fegear.tca.surfaces.FlankMap` of the pinion and gear flanks.
    M1, M2
        ``(4, 4)`` placements of the pinion tooth and the gear tooth (member → fixed frame) at the
        closed position.
    uv1, uv2
        ``(2,)`` flank coordinates of the contact point on each flank.
    n1
        ``(3,)`` pinion outward unit normal there (fixed frame).

    Each flank's principal curvatures are central differences of its exact surface in its native
    parameters (steps 50 × the map's Newton steps, kept 50 steps inside the working flank);
    the relative tensor ``½(K_1 + K_2)`` is diagonalised in the tangent plane of ``n1`` (module
    docstring). Measured on the seed face gear against a quadratic fit of the exact separation
    field around the contact point (2-8 mm across): ``A`` within 2e-4 … 3e-3, ``B`` within 1e-3.
    """
    K = []
    out = {}
    for name, fm, uv, M in (("pinion", fm1, uv1, M1), ("gear", fm2, uv2, M2)):
        # the contact point and the tangents' four points in one native solve (an envelope
        # solve of the face gear costs about the same for one point as for five)
        U, V, ht = _tangent_points(fm, np.asarray(uv, dtype=float))
        A, B = fm.native(np.concatenate([[uv[0]], U]), np.concatenate([[uv[1]], V]))
        pa, pb = A[0], B[0]
        nrm = fm.evaluate(pa, pb)[1]
        h = (50 * fm.step[0], 50 * fm.step[1])
        lo, hi = fm.native_box()
        pa = float(np.clip(pa, lo[0] + h[0], hi[0] - h[0]))
        pb = float(np.clip(pb, lo[1] + h[1], hi[1] - h[1]))
        k, d = finite_difference_curvatures(
            lambda x, y, fm=fm: fm.evaluate(x, y)[0], pa, pb, h, nrm
        )
        d = apply_vectors(M, d)
        K.append(k[0] * np.outer(d[0], d[0]) + k[1] * np.outer(d[1], d[1]))
        out[f"{name}_k"] = np.asarray(k, dtype=float)
        out[f"{name}_dirs"] = np.asarray(d, dtype=float)
        out[f"{name}_tangents"] = _flank_tangents(fm, (A[1:], B[1:]), ht, M)
    n1 = np.asarray(n1, dtype=float)
    e1 = np.cross(n1, [0.0, 0.0, 1.0]) if abs(n1[2]) < 0.9 else np.cross(n1, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    E = np.stack([e1, np.cross(n1, e1)], -1)
    S = 0.5 * E.T @ (K[0] + K[1]) @ E
    w, V = np.linalg.eigh(0.5 * (S + S.T))
    return ContactCurvature(
        normal=n1,
        e1=e1,
        A=float(w[0]),
        B=float(w[1]),
        major_axis=E @ V[:, 0],
        **out,
    )


def normal_force(pinion_torque_Nm: float, point: Array, normal: Array, axis1) -> float:
    """``F = 1000 T1 / |(e_1 × (M − O_1)) · n|`` (N): the normal force by which one pair carries
    the pinion torque ``T1`` (N·m) at ``point`` (mm) with ``normal``; ``axis1 = (O_1, e_1)``."""
    o1, e = axis1
    arm = abs(float(np.dot(np.cross(e, np.asarray(point) - o1), normal)))
    return NMM_PER_NM * pinion_torque_Nm / arm  # N·mm over mm


@dataclass(frozen=True)
class EllipseAt:
    """The contact ellipses at one TCA position (its pair in contact).

    Attributes
    ----------
    position
        Index of the position; ``phi1`` its pinion angle (rad).
    pair
        ``(k, j)`` pinion and gear tooth of the pair in contact.
    point
        ``(3,)`` mm, the contact point (fixed frame).
    pinion_uv, gear_uv
        ``(2,)`` its flank coordinates on each member.
    curvature
        :class:`ContactCurvature` there.
    line_contact
        ``k_a <= 1e-9 k_b``: no ellipse (``paint_a_mm``, ``hertz`` None, ``hertz_reason`` says).
    delta_mm
        The approach ``δ`` of the instantaneous ellipse (the paint thickness).
    paint_a_mm, paint_b_mm
        Its semi-axes ``sqrt(2δ/k_a)`` (None for a line contact), ``sqrt(2δ/k_b)``.
    pinion_torque_Nm, force_N
        The load and the normal force of one pair carrying it (0 without a load).
    hertz
        :class:`~fegear.mechanics.hertz_closed_form.HertzPoint` of ``force_N``, or None
        (``hertz_reason``).
    major_to_face_deg
        ``{"pinion": deg, "gear": deg}``: angle of the major axis from each flank's face
        direction (``∂X/∂v`` in the tangent plane) toward its tip (``∂X/∂u``), in (−90, 90].
    """

    position: int
    phi1: float
    pair: tuple[int, int]
    point: Array
    pinion_uv: Array
    gear_uv: Array
    curvature: ContactCurvature
    line_contact: bool
    delta_mm: float
    paint_a_mm: float | None
    paint_b_mm: float
    pinion_torque_Nm: float
    force_N: float
    hertz: HertzPoint | None
    hertz_reason: str
    major_to_face_deg: dict[str, float]

    @property
    def paint_axis_ratio(self) -> float | None:
        """``a/b = sqrt(k_b/k_a)`` of the instantaneous ellipse (None for a line contact)."""
        return None if self.paint_a_mm is None else self.paint_a_mm / self.paint_b_mm


def _major_to_face(c: ContactCurvature, tangents: Array) -> float:
    n = c.normal
    tv = tangents[:, 1] - np.dot(tangents[:, 1], n) * n
    tv /= np.linalg.norm(tv)
    tu = np.cross(n, tv)
    if np.dot(tu, tangents[:, 0]) < 0:  # toward the tip (increasing u)
        tu = -tu
    ang = math.degrees(math.atan2(float(np.dot(c.major_axis, tu)), float(np.dot(c.major_axis, tv))))
    ang = (ang + 90.0) % 180.0 - 90.0  # an axis: modulo 180°, in [−90, 90)
    return 90.0 if ang == -90.0 else ang


def ellipse_at(
    position: int,
    phi1: float,
    pair: tuple[int, int],
    point: Array,
    uv: tuple[Array, Array],
    curvature: ContactCurvature,
    delta_mm: float,
    pinion_torque_Nm: float | None,
    axis1,
    E_star_MPa: float,
) -> EllipseAt:
    """The ellipses of one position (module docstring): ``point`` and its flank coordinates
    ``uv = (pinion_uv, gear_uv)``, ``axis1 = (O_1, e_1)`` of the pinion.

    Raises
    ------
    InputError
        ``delta_mm`` not > 0, ``pinion_torque_Nm`` not None and not > 0.
    """
    if not delta_mm > 0:
        raise InputError("paint_thickness_mm", delta_mm, "> 0")
    if pinion_torque_Nm is not None and not pinion_torque_Nm > 0:
        raise InputError("pinion_torque_Nm", pinion_torque_Nm, "> 0 or None")
    c = curvature
    line = c.line_contact
    angles = {
        "pinion": _major_to_face(c, c.pinion_tangents),
        "gear": _major_to_face(c, c.gear_tangents),
    }
    force = 0.0
    if pinion_torque_Nm:
        force = normal_force(pinion_torque_Nm, point, c.normal, axis1)
    where = dict(
        position=position,
        phi1=float(phi1),
        pair=pair,
        point=np.asarray(point, dtype=float),
        pinion_uv=np.asarray(uv[0], dtype=float),
        gear_uv=np.asarray(uv[1], dtype=float),
        curvature=c,
        delta_mm=delta_mm,
        pinion_torque_Nm=pinion_torque_Nm or 0.0,
        force_N=force,
        major_to_face_deg=angles,
    )
    if line:
        return EllipseAt(
            **where,
            line_contact=True,
            paint_a_mm=None,
            paint_b_mm=math.sqrt(delta_mm / c.B) if c.B > 0 else 0.0,
            hertz=None,
            hertz_reason="line contact (k_a = 0 along the contact line): no Hertz ellipse",
        )
    pe = paint_ellipse(delta_mm, c.A, c.B)
    hz, why = None, "no load given"
    if pinion_torque_Nm:
        hz, why = hertz_point(force, c.A, c.B, E_star_MPa), ""
    return EllipseAt(
        **where,
        line_contact=False,
        paint_a_mm=pe.a_mm,
        paint_b_mm=pe.b_mm,
        hertz=hz,
        hertz_reason=why,
    )


def ellipses(
    positions,
    axis1,
    pinion_torque_Nm: float | None,
    delta_mm: float = 0.00632,
    E_MPa: float = 206000.0,
    nu: float = 0.3,
) -> tuple[EllipseAt | None, ...]:
    """:class:`EllipseAt` of every TCA position (None where it has no contact).

    Parameters
    ----------
    positions
        :class:`~fegear.tca.results.PositionResult` sequence (their ``ellipse.curvature``).
    axis1
        ``(O_1, e_1)`` of the pinion axis (:meth:`fegear.geometry.pair_placement.Assembly.axis1`).
    pinion_torque_Nm
        The load of the Hertz ellipses (one pair carrying it), or None.
    delta_mm
        The approach of the instantaneous ellipse (paint thickness).
    E_MPa, nu
        Material of both members.
    """
    Es = effective_modulus(E_MPa, nu, E_MPa, nu)
    out: list[EllipseAt | None] = []
    for i, p in enumerate(positions):
        e = p.ellipse
        if not p.has_contact or e is None or e.curvature is None:
            out.append(None)
            continue
        cp = p.contact_pair
        pair = (int(p.pairs[cp, 0]), int(p.pairs[cp, 1]))
        out.append(
            ellipse_at(
                i,
                p.phi1,
                pair,
                p.points[cp],
                (p.pinion_uv[cp], p.gear_uv[cp]),
                e.curvature,
                delta_mm,
                pinion_torque_Nm,
                axis1,
                Es,
            )  # fmt: skip
        )
    return tuple(out)


def outline(
    e: EllipseAt,
    member: str,
    which: str = "paint",
    n: int = 73,
    axes: tuple[float, float] | None = None,
) -> Array | None:
    """``(n, 2)`` flank coordinates ``(u, v)`` of an ellipse's boundary on ``member``'s flank.

    ``which``: ``"paint"`` (the instantaneous ellipse) or ``"hertz"``; ``axes``: other semi-axes
    ``(a, b)`` (mm) drawn along the same principal directions instead (e.g. a published ellipse
    at this contact point). The tangent-plane ellipse
    ``a cos t ξ + b sin t η`` is taken to flank coordinates through the pseudo-inverse of the
    flank tangents at the contact point (first order: exact for the plane, within the flank's
    second-order height over the ellipse elsewhere). None where there is no such ellipse.
    """
    if axes is not None:
        a, b = axes
    elif which == "paint":
        if e.paint_a_mm is None:
            return None
        a, b = e.paint_a_mm, e.paint_b_mm
    elif which == "hertz":
        if e.hertz is None:
            return None
        a, b = e.hertz.a_mm, e.hertz.b_mm
    else:
        raise InputError("which", which, '"paint" or "hertz"')
    c = e.curvature
    T, uv0 = (
        (c.pinion_tangents, e.pinion_uv) if member == "pinion" else (c.gear_tangents, e.gear_uv)
    )
    t = np.linspace(0.0, 2 * np.pi, n)
    w = a * np.cos(t)[:, None] * c.major_axis + b * np.sin(t)[:, None] * c.minor_axis  # (n, 3)
    d = np.linalg.lstsq(T, w.T, rcond=None)[0].T  # (n, 2)
    return uv0 + d


def _fl(x: float | None) -> float | None:
    return None if x is None else float(x)


def record(e: EllipseAt | None) -> dict[str, object] | None:
    """``summary.json``'s ``positions[i].contact_ellipse``: the ellipses of one position as plain
    data (mm, 1/mm, N, MPa, deg; vectors in the fixed frame), or None without contact."""
    if e is None:
        return None
    c = e.curvature
    hz = e.hertz
    return {
        "pair": list(e.pair),
        "point_mm": [float(x) for x in e.point],
        "normal": [float(x) for x in c.normal],
        "line_contact": bool(e.line_contact),
        "principal_relative_curvatures_per_mm": [float(x) for x in c.k],
        "principal_directions": [
            [float(x) for x in c.major_axis],
            [float(x) for x in c.minor_axis],
        ],  # fmt: skip
        "pinion_principal_curvatures_per_mm": [float(x) for x in c.pinion_k],
        "gear_principal_curvatures_per_mm": [float(x) for x in c.gear_k],
        "major_axis_to_face_deg": {k: float(v) for k, v in e.major_to_face_deg.items()},
        "paint": {
            "delta_mm": float(e.delta_mm),
            "a_mm": _fl(e.paint_a_mm),
            "b_mm": float(e.paint_b_mm),
            "axis_ratio": _fl(e.paint_axis_ratio),
        },
        "hertz": None
        if hz is None
        else {
            "pinion_torque_Nm": float(e.pinion_torque_Nm),
            "force_N": float(e.force_N),
            "a_mm": float(hz.a_mm),
            "b_mm": float(hz.b_mm),
            "p0_MPa": float(hz.p0_MPa),
            "approach_mm": float(hz.approach_mm),
        },
        "hertz_reason": e.hertz_reason,
    }


def cycle_record(es, delta_mm: float, pinion_torque_Nm: float | None) -> dict[str, object]:
    """``summary.json``'s ``cycle.contact_ellipses``: the ranges ``[min, max]`` over the positions
    of the instantaneous ellipse (``paint_*``) and of the Hertz ellipse of one pair carrying the
    whole load (``hertz_*``), null with ``reason`` where there is none (no contact, line
    contact)."""
    pts = [e for e in es if e is not None]
    point = [e for e in pts if not e.line_contact]
    hz = [e for e in point if e.hertz is not None]

    def rng(vals):
        return [float(min(vals)), float(max(vals))] if vals else None

    reason = ""
    if not pts:
        reason = "no position has contact"
    elif not point:
        reason = "line contact at every position (conjugate flanks): no ellipse"
    return {
        "paint_thickness_mm": float(delta_mm),
        "pinion_torque_Nm": _fl(pinion_torque_Nm),
        "positions_with_ellipse": [e.position for e in point],
        "line_contact_positions": [e.position for e in pts if e.line_contact],
        "principal_relative_curvature_a_per_mm": rng([e.curvature.k[0] for e in point]),
        "principal_relative_curvature_b_per_mm": rng([e.curvature.k[1] for e in pts]),
        "paint_a_mm": rng([e.paint_a_mm for e in point]),
        "paint_b_mm": rng([e.paint_b_mm for e in point]),
        "paint_axis_ratio": rng([e.paint_axis_ratio for e in point]),
        "hertz_a_mm": rng([e.hertz.a_mm for e in hz]),
        "hertz_b_mm": rng([e.hertz.b_mm for e in hz]),
        "hertz_p0_MPa": rng([e.hertz.p0_MPa for e in hz]),
        "reason": reason,
    }
