"""Flank surfaces: the common result type of every gear family, and surface curvature.

Conventions (all families)
--------------------------
- Member frame: the rotation axis of the member is the ``z`` axis through the origin; the member
  turns about ``+z``. Lengths in mm, curvatures in 1/mm, angles in rad.
- ``u`` runs across the profile from root to tip, ``v`` along the face (toe→heel, inner→outer,
  or −b/2→+b/2); what they *are* is stated by each family.
- Normals point OUT of the tooth material.
- Principal curvatures are signed so that a convex surface (bending away from its outward normal,
  like a cylinder seen from outside) has POSITIVE curvature: with the outward normal ``n``,
  ``κ = -(r'' · n)`` along a unit-speed curve of the surface (the opposite of do Carmo's sign).

Curvature from the fundamental forms (do Carmo, *Differential Geometry of Curves and Surfaces*,
1976, §3.3; Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2004, ch. 7–8):

    I = [[E, F], [F, G]],  E = r_u·r_u, F = r_u·r_v, G = r_v·r_v
    II = [[L, M], [M, N]], L = -r_uu·n = r_u·n_u, M = -r_uv·n, N = -r_vv·n = r_v·n_v

The shape operator ``S = I⁻¹ II`` has the principal curvatures as eigenvalues. It is evaluated
in an orthonormal tangent basis (e1 = r_u/|r_u|, e2 = n × e1), where with ``A = [e1 e2]ᵀ[r_u r_v]``
it is the symmetric matrix ``A⁻ᵀ II A⁻¹``, so a vectorised symmetric eigensolver gives the
curvatures and orthonormal principal directions.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "Side",
    "FlankBoundaries",
    "FlankSurface",
    "ConeLine",
    "BlankOutline",
    "FlankCoordinates",
    "GeneratedMember",
    "NativeFlankEvaluator",
    "HasNativeFlank",
    "principal_curvatures",
    "curvatures_from_normal_derivatives",
    "finite_difference_curvatures",
    "unit",
]

Side = Literal["drive", "coast"]
Array = NDArray[np.float64]


def unit(v: ArrayLike) -> Array:
    """``v / |v|`` along the last axis."""
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@dataclass(frozen=True)
class FlankBoundaries:
    """Named limits of a flank in its parameter space ``(u, v)``.

    All values are parameter values of the family's ``u`` (across the profile) and ``v`` (along the
    face) axes; ``u_root <= u_fillet <= u_tip`` and ``v_start < v_end``.

    Attributes
    ----------
    u_root
        Root end of the flank (bottom of the fillet; ``== u_fillet`` if no fillet is modelled).
    u_fillet
        Fillet limit: boundary between the fillet and the working (active) surface.
    u_tip
        Tip end of the flank (tip circle / tip plane / face cone).
    v_start, v_end
        Face ends: toe/heel (bevel), inner/outer radius (face gear), ``∓b/2`` (cylindrical).
    u_name, v_name
        What ``u`` and ``v`` are for this family, with units (for messages and plots).
    height
        Optional ``height(u, v) -> h`` (mm, broadcast): the physical profile coordinate of flank
        coordinates (the face gear's height above the pitch plane, the bevel's height above the
        pitch cone). Families whose working surface is bounded by *curves* over the face make
        ``u`` a fraction of the working height, so that ``[u_fillet, u_tip] × [v_start, v_end]``
        is exactly the curved working surface for every consumer; ``height`` gives the curves
        back in physical terms (:meth:`fillet_curve`, :meth:`tip_curve`) for plots and reports.
        None: ``u`` is itself the profile coordinate and the limits are constant (involute).
    height_name
        What ``height`` is, with units.

    Notes
    -----
    Consumers test a point against the working surface with :meth:`contains`, in flank
    coordinates.
    """

    u_root: float
    u_fillet: float
    u_tip: float
    v_start: float
    v_end: float
    u_name: str = "u"
    v_name: str = "v"
    height: Callable[[ArrayLike, ArrayLike], Array] | None = field(default=None, compare=False)
    height_name: str = ""

    def __post_init__(self) -> None:
        if not (self.u_root <= self.u_fillet <= self.u_tip):
            raise ValueError(
                f"FlankBoundaries needs u_root <= u_fillet <= u_tip, got "
                f"{self.u_root}, {self.u_fillet}, {self.u_tip}"
            )
        if not self.v_start < self.v_end:
            raise ValueError(
                f"FlankBoundaries needs v_start < v_end, got {self.v_start}, {self.v_end}"
            )

    def profile(self, u: ArrayLike, v: ArrayLike) -> Array:
        """Physical profile coordinate of flank coordinates (``height`` or ``u`` itself)."""
        if self.height is None:
            return np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))[0].copy()
        return np.asarray(self.height(u, v), float)

    def fillet_curve(self, v: ArrayLike) -> Array:
        """The fillet limit as a curve over the face: profile coordinate at ``u_fillet``."""
        return self.profile(self.u_fillet, v)

    def tip_curve(self, v: ArrayLike) -> Array:
        """The tip limit as a curve over the face: profile coordinate at ``u_tip``."""
        return self.profile(self.u_tip, v)

    def contains(self, u: ArrayLike, v: ArrayLike, tol: float = 1e-9) -> NDArray[np.bool_]:
        """Flank coordinates on the working surface (relative tolerance ``tol`` of the spans)."""
        u, v = np.asarray(u, float), np.asarray(v, float)
        tu = tol * (self.u_tip - self.u_fillet)
        tv = tol * (self.v_end - self.v_start)
        return (
            (u >= self.u_fillet - tu)
            & (u <= self.u_tip + tu)
            & (v >= self.v_start - tv)
            & (v <= self.v_end + tv)
        )


@dataclass(frozen=True)
class FlankSurface:
    """One generated flank sampled on a parameter grid, in the member's own frame (axis = z).

    Attributes
    ----------
    member
        Member name (e.g. ``"pinion"``, ``"gear"``, ``"face_gear"``).
    side
        ``"drive"`` or ``"coast"``.
    u, v
        Parameter axes, shapes ``(nu,)`` and ``(nv,)``; ``u`` root→tip, ``v`` along the face (the
        family states what they are, see ``boundaries.u_name`` / ``v_name``).
    points
        ``(nu, nv, 3)`` mm.
    normals
        ``(nu, nv, 3)`` unit, pointing out of the tooth material.
    kappa
        ``(nu, nv, 2)`` principal curvatures 1/mm, convex positive, descending.
    directions
        ``(nu, nv, 2, 3)`` unit principal directions (tangent, orthogonal to each other).
    meshing_residual
        ``(nu, nv)`` equation-of-meshing residual ``|n·v|/|v|`` (0 for analytic surfaces).
    boundaries
        Named flank limits in ``(u, v)``.
    """

    member: str
    side: Side
    u: Array
    v: Array
    points: Array
    normals: Array
    kappa: Array
    directions: Array
    meshing_residual: Array
    boundaries: FlankBoundaries

    def __post_init__(self) -> None:
        if self.side not in ("drive", "coast"):
            raise ValueError(f"FlankSurface.side must be 'drive' or 'coast', got {self.side!r}")
        nu, nv = np.shape(self.u), np.shape(self.v)
        if len(nu) != 1 or len(nv) != 1:
            raise ValueError("FlankSurface.u and .v must be 1-D")
        g = (nu[0], nv[0])
        expected = {
            "points": g + (3,),
            "normals": g + (3,),
            "kappa": g + (2,),
            "directions": g + (2, 3),
            "meshing_residual": g,
        }
        for name, shape in expected.items():
            got = np.shape(getattr(self, name))
            if got != shape:
                raise ValueError(f"FlankSurface.{name} has shape {got}, expected {shape}")

    @property
    def shape(self) -> tuple[int, int]:
        """Grid shape ``(nu, nv)``."""
        return (len(self.u), len(self.v))


@dataclass(frozen=True)
class ConeLine:
    """A surface of revolution ``h = a + b L`` in a member's cone coordinates ``(L, h)``
    (:class:`BlankOutline`): a cylinder, a plane or a cone about the member axis."""

    a: float
    b: float

    def __call__(self, L: Array | float) -> Array:
        return self.a + self.b * np.asarray(L, dtype=float)


@dataclass(frozen=True)
class BlankOutline:
    """The blank of a member in its meridian plane, and how its flanks sit on it (mm, rad).

    A plain geometric description that any consumer (the sector mesher, the engagement checks,
    plots) reads instead of asking which family a member is.

    Attributes
    ----------
    module
        The member's module (mm): the length scale of its teeth.
    meridian
        ``(2, 2)`` orthogonal ``M`` mapping the member's *cone coordinates* ``(L, h)`` to
        ``(ρ, z)``: ``(ρ, z)ᵀ = M (L, h)ᵀ``. ``L`` runs along the face and is the flank
        coordinate ``v`` (``z`` of a cylindrical gear, the radius of a face gear, the cone
        distance of a bevel gear); ``h`` runs across it (radius, height ``z``, height above the
        pitch cone). The sections ``L = const`` are planes, cylinders or back cones.
    tip, root, bottom
        Tip surface, root surface, and the bottom of the blank (the face the member is held by)
        as :class:`ConeLine` ``h = a + b L``.
    L_start, L_end
        The face: ``L`` of its two ends (toe/heel, inner/outer radius, ``∓b/2``).
    L_range
        A face span a little wider than ``L_start … L_end`` over which the flank and fillet
        surfaces still evaluate (a solid built on it is trimmed back to the face).
    n_sections
        Sections ``L = const`` spread evenly over ``L_range`` through which a surface lofted
        from exact section curves follows the flanks to a few µm.
    u_root, u_fillet, u_tip
        The flank's profile limits in flank coordinates (as :class:`FlankBoundaries`; the same
        numbers for both sides).
    plus_side
        The side (``"drive"``/``"coast"``) facing +θ about the axis, the other faces −θ.
    bottom_name
        Name of the bottom face (``"bore"``, ``"base"``).
    has_fillet
        The fillet is generated (:meth:`GeneratedMember.flank_points` evaluates it for
        ``u_root <= u < u_fillet``).
    n_fillet
        Exact points that represent one tooth-space half of root and fillet in a section.
    """

    module: float
    meridian: Array
    tip: ConeLine
    root: ConeLine
    bottom: ConeLine
    L_start: float
    L_end: float
    L_range: tuple[float, float]
    n_sections: int
    u_root: float
    u_fillet: float
    u_tip: float
    plus_side: Side
    bottom_name: str
    has_fillet: bool
    n_fillet: int = 25


@dataclass(frozen=True)
class FlankCoordinates:
    """How a member's flank is addressed in flank coordinates ``(u, v)``.

    Attributes
    ----------
    bounds
        The working flank: ``u`` from ``u_fillet`` to ``u_tip``, ``v`` over the face.
    step
        Finite-difference steps ``(du, dv)`` suited to the scales of ``u`` and ``v`` (for
        Jacobians and curvatures by differences of :meth:`GeneratedMember.point_normal`).
    fast_evaluator
        Name of a cheaper exact evaluation of the *same* surface that the family offers (a
        closed form, or a native parametrisation): ``"spur_involute"``,
        ``"face_gear_orthogonal"``, ``"spiral_bevel_native"``. Consumers that know the name
        may use it; ``None`` (or a name they do not know): :meth:`GeneratedMember.point_normal`.
    """

    bounds: FlankBoundaries
    step: tuple[float, float]
    fast_evaluator: str | None = None


@runtime_checkable
class GeneratedMember(Protocol):
    """What every gear family implements, and all that the consumers (TCA, mesh) may ask.

    Member frame: rotation axis = ``z`` through the origin; the tooth space / tooth of index 0 is
    placed as the family documents; tooth ``k`` is tooth 0 turned by ``k * tooth_angle`` about z.

    A new family is one class with these members (``family`` a class attribute naming it); no
    consumer names a family. Optional capability: ``native_flank(side)`` (:class:`HasNativeFlank`).
    """

    name: str
    n_teeth: int
    family: str

    @property
    def tooth_angle(self) -> float:
        """Angular pitch ``2π / n_teeth`` (rad)."""
        ...

    @property
    def axis(self) -> Array:
        """Rotation axis in the member frame: always ``[0, 0, 1]``."""
        ...

    def flank(self, side: Side, nu: int = 21, nv: int = 11) -> FlankSurface:
        """The flank of tooth 0 on an ``nu × nv`` grid spanning its boundaries."""
        ...

    def point_normal(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Exact surface points ``(..., 3)`` and outward unit normals at arbitrary ``(u, v)``."""
        ...

    def flank_points(self, side: Side, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """The fastest exact points and normals the family has at flank coordinates ``(u, v)``,
        the fillet (``u < u_fillet``) included: the surfaces of :meth:`point_normal` (to
        ~1e-12 mm), or :meth:`point_normal` itself."""
        ...

    def flank_coordinates(self, side: Side) -> FlankCoordinates:
        """Working-flank bounds, difference steps and fast evaluator of the ``side`` flank."""
        ...

    def blank_outline(self, rim_modules: float = 3.0) -> BlankOutline:
        """The blank's meridian outline; ``rim_modules``: rim below the root (modules) where the
        family's blank is not fixed by its design data."""
        ...


@runtime_checkable
class NativeFlankEvaluator(Protocol):
    """An exact evaluator of a flank in native parameters ``(a, b)`` with exact tangents."""

    def native(self, u: ArrayLike, v: ArrayLike) -> tuple[Array, Array]:
        """Native parameters of flank coordinates."""
        ...

    def evaluate(self, a: ArrayLike, b: ArrayLike, tangents: bool = False) -> tuple[Array, ...]:
        """``(p, n)``, with ``tangents`` also ``(∂p/∂a, ∂p/∂b)``."""
        ...


@runtime_checkable
class HasNativeFlank(Protocol):
    """Optional member capability: :class:`NativeFlankEvaluator` per side (closest points in
    parameters that extend past the flank limits, with exact tangents)."""

    def native_flank(self, side: Side) -> NativeFlankEvaluator: ...


def _symmetric_eig2(S: Array) -> tuple[Array, Array]:
    """Eigen-decomposition of symmetric 2×2 stacks, eigenvalues descending."""
    w, V = np.linalg.eigh(0.5 * (S + np.swapaxes(S, -1, -2)))
    return w[..., ::-1], V[..., :, ::-1]


def _curvatures(r_u: Array, r_v: Array, n: Array, II: Array) -> tuple[Array, Array]:
    """Principal curvatures/directions from tangents, unit normal and II (convex positive)."""
    e1 = unit(r_u)
    e2 = np.cross(n, e1)
    # A maps (du, dv) to components in (e1, e2)
    A = np.empty(r_u.shape[:-1] + (2, 2))
    A[..., 0, 0] = np.sum(e1 * r_u, -1)
    A[..., 0, 1] = np.sum(e1 * r_v, -1)
    A[..., 1, 0] = np.sum(e2 * r_u, -1)
    A[..., 1, 1] = np.sum(e2 * r_v, -1)
    Ainv = np.linalg.inv(A)
    S = np.swapaxes(Ainv, -1, -2) @ II @ Ainv
    k, V = _symmetric_eig2(S)
    d = V[..., 0, :, None] * e1[..., None, :] + V[..., 1, :, None] * e2[..., None, :]
    return k, unit(d)


def principal_curvatures(
    r_u: ArrayLike,
    r_v: ArrayLike,
    r_uu: ArrayLike,
    r_uv: ArrayLike,
    r_vv: ArrayLike,
    n: ArrayLike,
) -> tuple[Array, Array]:
    """Principal curvatures and directions from the first and second fundamental forms.

    Parameters
    ----------
    r_u, r_v, r_uu, r_uv, r_vv
        Partial derivatives of the surface ``r(u, v)``, each ``(..., 3)``.
    n
        Unit normal ``(..., 3)`` pointing out of the material (sets the sign).

    Returns
    -------
    kappa : (..., 2)
        Principal curvatures (1/length), convex positive, descending.
    directions : (..., 2, 3)
        Unit principal directions (tangent to the surface), ``directions[..., i, :]`` for
        ``kappa[..., i]``.

    Notes
    -----
    ``II = -[[r_uu·n, r_uv·n], [r_uv·n, r_vv·n]]``; eigenvalues of ``I⁻¹ II`` (do Carmo 1976 §3.3;
    Litvin & Fuentes 2004 §7.5–7.6).
    """
    r_u, r_v, n = (np.asarray(a, dtype=float) for a in (r_u, r_v, n))
    r_uu, r_uv, r_vv = (np.asarray(a, dtype=float) for a in (r_uu, r_uv, r_vv))
    II = np.empty(r_u.shape[:-1] + (2, 2))
    II[..., 0, 0] = -np.sum(r_uu * n, -1)
    II[..., 0, 1] = II[..., 1, 0] = -np.sum(r_uv * n, -1)
    II[..., 1, 1] = -np.sum(r_vv * n, -1)
    return _curvatures(r_u, r_v, n, II)


def curvatures_from_normal_derivatives(
    r_u: ArrayLike, r_v: ArrayLike, n: ArrayLike, n_u: ArrayLike, n_v: ArrayLike
) -> tuple[Array, Array]:
    """Principal curvatures from first derivatives of the surface and of its unit normal.

    Weingarten: differentiating ``r_u·n = 0`` gives ``-r_uu·n = r_u·n_u``, so
    ``II_ij = r_i · n_j`` (symmetrised). This needs no second derivatives of ``r`` and is what the
    generation engine uses (the normal of an envelope is the transformed tool normal).
    Returns as :func:`principal_curvatures`.
    """
    r_u, r_v, n, n_u, n_v = (np.asarray(a, dtype=float) for a in (r_u, r_v, n, n_u, n_v))
    II = np.empty(r_u.shape[:-1] + (2, 2))
    II[..., 0, 0] = np.sum(r_u * n_u, -1)
    II[..., 0, 1] = II[..., 1, 0] = 0.5 * (np.sum(r_u * n_v, -1) + np.sum(r_v * n_u, -1))
    II[..., 1, 1] = np.sum(r_v * n_v, -1)
    return _curvatures(r_u, r_v, n, II)


def finite_difference_curvatures(
    f: Callable[[Array, Array], Array],
    u: ArrayLike,
    v: ArrayLike,
    h: float | tuple[float, float],
    normals: ArrayLike | None = None,
) -> tuple[Array, Array]:
    """Principal curvatures of a point function by central differences (independent check path).

    Parameters
    ----------
    f
        ``f(u, v) -> (..., 3)`` surface points, vectorised over broadcast arrays.
    u, v
        Parameter values (broadcast together).
    h
        Step (or ``(h_u, h_v)``). Central differences have truncation error O(h²) and round-off
        O(ε|r|/h²) in second derivatives, so pick ``h ≈ (ε|r|)^(1/4)``-ish relative to the scale.
    normals
        Optional outward normals ``(..., 3)`` to orient the FD normal ``r_u × r_v``; without them
        ``r_u × r_v`` is taken as outward.

    Returns
    -------
    As :func:`principal_curvatures`.
    """
    hu, hv = (h, h) if np.isscalar(h) else h
    u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
    p = f(u, v)
    pu1, pu0 = f(u + hu, v), f(u - hu, v)
    pv1, pv0 = f(u, v + hv), f(u, v - hv)
    r_u = (pu1 - pu0) / (2 * hu)
    r_v = (pv1 - pv0) / (2 * hv)
    r_uu = (pu1 - 2 * p + pu0) / hu**2
    r_vv = (pv1 - 2 * p + pv0) / hv**2
    r_uv = (f(u + hu, v + hv) - f(u + hu, v - hv) - f(u - hu, v + hv) + f(u - hu, v - hv)) / (
        4 * hu * hv
    )
    n = unit(np.cross(r_u, r_v))
    if normals is not None:
        s = np.sign(np.sum(n * np.asarray(normals, dtype=float), -1))
        n = n * np.where(s == 0, 1.0, s)[..., None]
    return principal_curvatures(r_u, r_v, r_uu, r_uv, r_vv, n)
