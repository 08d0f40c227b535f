"""Typed TCA results (frozen dataclasses; arrays with shapes and units documented).

Sign conventions: ``docs/conventions.md``. ``θ`` is a rotation of member 2 AGAINST its driving sense
(a lag, rad) — the unknown of :mod:`fegear.mechanics.contact` — and the unloaded TE is ``−θ*`` with
``θ*`` the
rotation that closes the smallest gap over all pairs, relative to the reference position (the
error-free pair in contact at ``φ1 = 0``). No array holds NaN: entries without meaning are 0 and
masked by a boolean array next to them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..mechanics.hertz_closed_form import HertzPoint
from ..store import records
from .ellipse import ContactCurvature

__all__ = [
    "SeparationGrid",
    "ContactEllipseAt",
    "PositionResult",
    "CycleResult",
    "ARCSEC",
    "RECORD_CLASSES",
]

Array = NDArray[np.float64]
#: one arcsecond in rad
ARCSEC = np.pi / (180.0 * 3600.0)


@dataclass(frozen=True)
class SeparationGrid:
    """The separation field of one tooth pair at one position: the LTCA contact grid.

    Cells are centred on a regular grid of the pinion flank coordinates; after the rigid closing
    rotation ``θ*`` of member 2, the gap of cell ``i`` after a further lag ``θ`` of member 2 is
    ``separation_i − θ h_i`` to first order (the form ``d = g − θ h + C F`` of
    :func:`fegear.mechanics.contact.solve_contact`).

    Attributes
    ----------
    k, j
        Pinion and gear tooth index of the pair.
    u, v
        ``(nu,)``, ``(nv,)`` pinion flank coordinates of the cell centres.
    points
        ``(nu, nv, 3)`` mm, cell centres on the pinion flank, fixed frame.
    normals
        ``(nu, nv, 3)`` unit pinion outward normals, fixed frame.
    separation
        ``(nu, nv)`` mm, distance along the pinion normal from the pinion flank to the gear flank
        at the closed position (``>= 0`` up to the solve tolerance, 1e-10 mm).
    h
        ``(nu, nv)`` mm/rad, ``−∂separation/∂θ``: the moment arm of the normal about the member-2
        axis, ``h = −(ṗ2 · n2)/(n1 · n2)``, ``ṗ2 = ∂p2/∂θ`` (exact for non-collinear normals).
    area
        ``(nu, nv)`` mm², ``|r_u × r_v| Δu Δv`` of each cell.
    gear_uv
        ``(nu, nv, 2)`` gear flank coordinates where the pinion normal meets the gear flank.
    valid
        ``(nu, nv)`` the normal meets the working gear flank (other cells: separation 0, unused).
    """

    k: int
    j: int
    u: Array
    v: Array
    points: Array
    normals: Array
    separation: Array
    h: Array
    area: Array
    gear_uv: Array
    valid: NDArray[np.bool_]

    def contact_cells(self) -> tuple[Array, Array, Array, Array, Array]:
        """Valid cells flattened: ``points (m, 3)``, ``normals (m, 3)``, ``g (m,)``, ``h (m,)``,
        ``area (m,)`` — ready for :func:`fegear.mechanics.contact.solve_contact`
        (``weights = h``)."""
        m = self.valid
        return self.points[m], self.normals[m], self.separation[m], self.h[m], self.area[m]


@dataclass(frozen=True)
class ContactEllipseAt:
    """Contact ellipse at the contact point of a position.

    Attributes
    ----------
    A, B
        Relative-curvature coefficients (1/mm) of the gap ``A x² + B y²`` (``A <= B``).
    major_axis
        ``(3,)`` unit direction of the major axis (fixed frame).
    paint_a_mm, paint_b_mm
        Litvin's instantaneous ellipse for the paint thickness
        (:func:`fegear.mechanics.hertz_closed_form.paint_ellipse`).
    hertz
        Elastic Hertz contact for the given load
        (:func:`fegear.mechanics.hertz_closed_form.hertz_point`) or None.
    force_N
        Normal force used for ``hertz`` (pinion torque / moment arm of the normal), 0 if none.
    line_contact
        ``A <= 1e-9 B`` (conjugate line contact): no ellipse; semi-axes are 0.
    curvature
        The curvatures at the contact point (:class:`~fegear.tca.ellipse.ContactCurvature`:
        both flanks', the relative ones, the normal, the flank tangents), from which
        :func:`fegear.tca.ellipse.ellipses` derives the ellipses at any load.
    """

    A: float
    B: float
    major_axis: Array
    paint_a_mm: float
    paint_b_mm: float
    hertz: HertzPoint | None
    force_N: float
    line_contact: bool
    curvature: ContactCurvature | None = None


@dataclass(frozen=True)
class PositionResult:
    """TCA at one mesh position; ``P`` candidate pairs.

    Attributes
    ----------
    phi1
        Pinion angle (rad, driving sense).
    phi2
        Closed gear angle ``(N1/N2) φ1 + TE`` (rad, driving sense); nominal if no contact.
    has_contact
        False when no pair can close (errors too large, flanks do not meet).
    te_rad
        Unloaded TE ``−θ*`` (rad); 0 when ``has_contact`` is False.
    pairs
        ``(P, 2)`` int, tooth indices ``(k, j)``.
    pair_valid
        ``(P,)`` bool, the pair's flanks can meet.
    pair_te_rad
        ``(P,)`` the TE this pair alone would give (``−θ_pair``).
    backlash_rad, backlash_mm
        ``(P,)`` angular gap ``θ_pair − θ*`` and separation along the pinion normal at the pair's
        closest point (mm) at the closed position; 0 for the pair in contact.
    pinion_uv, gear_uv
        ``(P, 2)`` flank coordinates of each pair's closest point (contact point of the pair in
        contact).
    points
        ``(P, 3)`` mm, those points in the fixed frame.
    edge
        ``(P,)`` str, "" or the boundaries touched, e.g. ``"pinion:v_end"``, ``"gear:tip"``.
    contact_pair
        Index into ``pairs`` of the pair in contact (-1 if none).
    ellipse
        Ellipse at the contact point, or None.
    grids
        One :class:`SeparationGrid` per valid pair, or empty.
    """

    phi1: float
    phi2: float
    has_contact: bool
    te_rad: float
    pairs: NDArray[np.int_]
    pair_valid: NDArray[np.bool_]
    pair_te_rad: Array
    backlash_rad: Array
    backlash_mm: Array
    pinion_uv: Array
    gear_uv: Array
    points: Array
    edge: tuple[str, ...]
    contact_pair: int
    ellipse: ContactEllipseAt | None
    grids: tuple[SeparationGrid, ...]

    @property
    def te_arcsec(self) -> float:
        return self.te_rad / ARCSEC


@dataclass(frozen=True)
class CycleResult:
    """TCA over a mesh cycle (``n`` positions, ``P`` pairs).

    Attributes
    ----------
    positions
        Per-position results.
    phi1
        ``(n,)`` rad.
    te_arcsec
        ``(n,)`` unloaded TE, 0 where ``has_contact`` is False.
    has_contact
        ``(n,)`` bool.
    pair_te_arcsec, pair_valid
        ``(n, P)`` each pair's TE curve and its mask.
    backlash_mm
        ``(n, P)`` separations of the pairs (0 for the pair in contact).
    contact_pair
        ``(n,)`` int, pair in contact (-1 none).
    pinion_uv, gear_uv
        ``(n, 2)`` contact path in flank coordinates of the pinion and gear.
    edge
        ``(n,)`` bool, the contact point lies on a flank boundary.
    paint_axes_mm, hertz_axes_mm
        ``(n, 2)`` semi-axes (a, b) of the paint and load ellipses (0 if none / line contact).
    hertz_p0_MPa
        ``(n,)`` Hertz peak pressure (0 if no load given).
    transfer_points
        ``(m, 2)`` ``(φ1 rad, TE arcsec)`` where the contact passes from one pair to the next
        (intersection of the two pairs' TE curves, linear interpolation between positions).
    pattern_pinion
        ``(nu, nv)`` bool on the separation-grid cells: the unloaded bearing pattern (union over
        positions and pairs of the cells with separation ≤ paint thickness).
    pattern_gear_uv
        ``(m, 2)`` gear flank coordinates of those cells.
    grid_u, grid_v
        Axes of ``pattern_pinion``.
    pairs
        ``(P, 2)`` tooth indices.
    paint_mm
        Paint thickness used.
    """

    positions: tuple[PositionResult, ...]
    phi1: Array
    te_arcsec: Array
    has_contact: NDArray[np.bool_]
    pair_te_arcsec: Array
    pair_valid: NDArray[np.bool_]
    backlash_mm: Array
    contact_pair: NDArray[np.int_]
    pinion_uv: Array
    gear_uv: Array
    edge: NDArray[np.bool_]
    paint_axes_mm: Array
    hertz_axes_mm: Array
    hertz_p0_MPa: Array
    transfer_points: Array
    pattern_pinion: NDArray[np.bool_]
    pattern_gear_uv: Array
    grid_u: Array
    grid_v: Array
    pairs: NDArray[np.int_]
    paint_mm: float

    @property
    def te_peak_to_peak_arcsec(self) -> float:
        te = self.te_arcsec[self.has_contact]
        return float(te.max() - te.min()) if te.size else 0.0


# ------------------------------------------------------------------ plain-data records
#: The classes a TCA cache record holds (:mod:`fegear.store.records`, :mod:`fegear.tca.cached`).
RECORD_CLASSES = records.registry(
    PositionResult, SeparationGrid, ContactEllipseAt, ContactCurvature, HertzPoint
)
