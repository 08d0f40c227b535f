"""The unloaded path of a line contact, traced in the mid-face transverse section.

A conjugate parallel-axes pair touches along a line across the face; the TCA's contact point of
a position is some point of that line (where its search stopped), so a path through those points
zigzags along the lines and its length grows with the number of positions (ISO/TR 6336-30
example 1: 69.0 mm at 13 positions, 128.9 mm at 25). The path of a line contact is read in one
transverse section, the mid-face one (``v_mid``, the middle of the pinion's face), as a gear
engineer reads the path of contact:

1. at each sample ``ψ`` the pinion point of the section on the contact line is the one whose
   closing rotation ``θ(u, v_mid)`` is least (the TCA's angular gap, :meth:`TCA._theta_pinion`;
   a 1-D search over the pinion's working profile), kept where it ties with the pair's own
   closing rotation within ``tol_rad`` (the section is in contact at ``ψ``);
2. the section's path runs on the gear flank from where the pinion's working profile ends to
   where the gear's does. Both flank parameters are affine in the transverse roll lengths
   (``u`` of the cylindrical members, the rack parameter of the generated involutes) and the
   roll lengths of a contact in one section add up to a constant (the line of action), so
   ``u2 = a + b u1`` exactly: fitted to the samples, it carries the pinion's profile limits to
   the gear flank, and the path's gear parameters are that interval clipped to the gear's;
3. its length is the arc length of the gear flank curve ``v = v_mid`` between the two ends
   (:data:`ARC_POINTS` points: a chord error below 1e-9 mm on a module-8 flank), the same for
   any number of positions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .core import TCA

__all__ = ["ARC_POINTS", "MidFacePath", "line_contact_states", "mid_face_path"]

Array = NDArray[np.float64]
#: Points of the gear flank curve whose polyline gives the path length.
ARC_POINTS = 4001
_GRID = 65  # start grid of the 1-D search over the pinion profile
_HALVINGS = 48


@dataclass(frozen=True)
class MidFacePath:
    """A line contact's path in the mid-face section (module docstring).

    Attributes
    ----------
    phi
        ``(n,)`` rad, pinion angles of pair 0: the samples in contact in the section and the
        two ends, ascending.
    pinion_uv, gear_uv
        ``(n, 2)`` flank coordinates of the section's contact points (``v`` = mid-face).
    length_mm
        Arc length of the path on the gear flank.
    """

    phi: Array
    pinion_uv: Array
    gear_uv: Array
    length_mm: float


def _section_minimum(tca: TCA, T: Array, v: float) -> tuple[Array, Array, Array]:
    """Per frame ``T (n, 4, 4)`` (pair 0): the pinion ``u`` of least closing rotation at
    ``v``, that rotation and the gear's ``(u, v)`` there."""
    b = tca.fm1.bounds
    n = T.shape[0]
    us = np.linspace(b.u_fillet, b.u_tip, _GRID)
    th = tca._theta_pinion(T, np.broadcast_to(us, (n, _GRID)), np.full((n, _GRID), v))[0]
    k = np.argmin(th, axis=1)
    u, f = us[k], th[np.arange(n), k]
    h = np.full(n, (b.u_tip - b.u_fillet) / (_GRID - 1))
    o = np.array([-1.0, -0.5, 0.5, 1.0])
    for _ in range(_HALVINGS):
        cand = np.clip(u[:, None] + o * h[:, None], b.u_fillet, b.u_tip)
        fc = tca._theta_pinion(T, cand, np.full(cand.shape, v))[0]
        j = np.argmin(fc, axis=1)
        fb = fc[np.arange(n), j]
        better = fb < f
        u, f = np.where(better, cand[np.arange(n), j], u), np.where(better, fb, f)
        h = 0.5 * h
    th, _, _, uv2 = tca._theta_pinion(T, u[:, None], np.full((n, 1), v))
    return u, th[:, 0], uv2[:, 0]


def _at_bound(u: Array, lo: float, hi: float) -> tuple[Array, Array]:
    """``u`` at the lower / upper bound (within 1e-7 of the span: the 1-D search ends within
    2⁻⁴⁸ of it where the gap runs into a boundary)."""
    tol = 1e-7 * (hi - lo)
    return u <= lo + tol, u >= hi - tol


def line_contact_states(
    tca: TCA, phi: Array, uv1: Array, tol_rad: float
) -> tuple[NDArray[np.bool_], list[str]]:
    """Whether pair 0 carries its line contact with its working flanks at ``phi (n,)``, and if
    not, the edge it is on.

    The TCA's point of a line contact lies anywhere on the line, so its edge tags say where that
    point is, not whether the line still has a part inside both working flanks: near the end of
    a helical pair's interval the line runs from a tip to a face-end corner, and the point may
    be at either end (ISO/TR 6336-30 example 1 at a 40 mm face: contact ratios 1.9828, 1.9828,
    1.9829 and another end edge from 9, 13 and 25 positions). A line's last part in contact is
    at a face end, so the pair is in contact while one of the sections at the face ends or at
    mid-face has its least closing rotation tied with the pair's (within ``tol_rad``) at a point
    inside both working profiles. Otherwise the edge is the profile limit that section's search
    ran into (``"pinion:tip"``, ``"gear:root"``, ...), or ``"transfer"``.
    """
    b1, b2 = tca.fm1.bounds, tca.fm2.bounds
    i0 = int(np.flatnonzero((tca.pairs[:, 0] == 0) & (tca.pairs[:, 1] == 0))[0])
    T = tca._tooth_frames(np.asarray(phi, dtype=float))[:, i0]
    own = tca._theta_pinion(T, uv1[:, :1], uv1[:, 1:])[0][:, 0]
    n = T.shape[0]
    inside = np.zeros(n, dtype=bool)
    edge = [""] * n
    for v in (b1.v_start, b1.v_end, 0.5 * (b1.v_start + b1.v_end)):
        u1, th, uv2 = _section_minimum(tca, T, v)
        r1, t1 = _at_bound(u1, b1.u_fillet, b1.u_tip)
        r2, t2 = _at_bound(uv2[:, 0], b2.u_fillet, b2.u_tip)
        tied = np.isfinite(th) & (th <= own + tol_rad)
        inside |= tied & ~(r1 | t1 | r2 | t2)
        names = (("pinion:root", r1), ("pinion:tip", t1), ("gear:root", r2), ("gear:tip", t2))
        for k in range(n):
            if not edge[k]:
                edge[k] = ",".join(t for t, on in names if on[k])
    return inside, [("" if ok else (e or "transfer")) for ok, e in zip(inside, edge, strict=True)]


def mid_face_path(tca: TCA, phi: Array, uv1: Array, tol_rad: float) -> MidFacePath | None:
    """The :class:`MidFacePath` of pair 0 from its samples at ``phi (n,)`` (rad) with the
    TCA's contact points ``uv1 (n, 2)`` on the pinion flank; None when fewer than two samples
    touch in the mid-face section."""
    b1, b2 = tca.fm1.bounds, tca.fm2.bounds
    v = 0.5 * (b1.v_start + b1.v_end)
    i0 = int(np.flatnonzero((tca.pairs[:, 0] == 0) & (tca.pairs[:, 1] == 0))[0])
    T = tca._tooth_frames(np.asarray(phi, dtype=float))[:, i0]
    own = tca._theta_pinion(T, uv1[:, :1], uv1[:, 1:])[0][:, 0]
    u1, th, uv2 = _section_minimum(tca, T, v)
    on = np.isfinite(th) & (th <= own + tol_rad)
    if on.sum() < 2:
        return None
    # u2 = a + b u1 and ψ = c + d u1 in the section (affine in the roll lengths: exact)
    bu, au = np.polyfit(u1[on], uv2[on, 0], 1)
    dpsi, cpsi = np.polyfit(u1[on], np.asarray(phi)[on], 1)
    ends1 = np.array([b1.u_fillet, b1.u_tip])
    ends2 = np.clip(au + bu * ends1, b2.u_fillet, b2.u_tip)
    ends1 = (ends2 - au) / bu
    psi_end = cpsi + dpsi * ends1
    order = np.argsort(psi_end)
    ps = np.concatenate([psi_end[order[:1]], np.asarray(phi)[on], psi_end[order[1:]]])
    p1 = np.concatenate([ends1[order[:1]], u1[on], ends1[order[1:]]])
    p2 = np.concatenate([ends2[order[:1]], uv2[on, 0], ends2[order[1:]]])
    s = np.argsort(ps)
    ps, p1, p2 = ps[s], p1[s], p2[s]
    v2 = float(np.median(uv2[on, 1]))  # the same axial section on the gear's flank
    ua = np.linspace(ends2.min(), ends2.max(), ARC_POINTS)
    g = tca.fm2.evaluate(*tca.fm2.native(ua, np.full(ua.shape, v2)))[0]
    length = float(np.linalg.norm(np.diff(g, axis=0), axis=1).sum())
    return MidFacePath(
        ps,
        np.stack([p1, np.full(ps.shape, v)], -1),
        np.stack([p2, np.full(ps.shape, v2)], -1),
        length,
    )
