"""Which teeth the loaded analysis models: the contact zone of a cycle, from the TCA.

The sectors have "enough teeth for every pair that can touch at the highest load plus one
unloaded neighbour on each side", and each is meshed fine on the whole working flank of its
loaded teeth (:func:`fegear.ltca.build_models`; ``docs/ltca/studies.md``: the mesh does not
depend on where the mate sits, so a study over installation errors reuses it). The zone says
how many teeth that is, and where on the flanks the cycle's contact can reach (reported in
``summary.json``, ``cycle.zone``).

**Teeth.** Over the positions of one mesh cycle, a pair ``(k, j)`` can touch where its unloaded
separation is at most ``gap_mm`` (the loaded approach cannot close more). The sector of each member
gets ``n = 2 max(|k|, |j|) + 3`` teeth (at least ``min_teeth``), so every such tooth has a
neighbour on each side and the sector stays symmetric about member tooth 0.

**Which pairs.** ``exact=True``: a pair is in when its separation is within ``gap_mm`` anywhere
(the coarse samples, or its closest point, where the TCA solved it exactly:
:func:`fegear.ltca.grid.near_cells`; a separation valley narrower than a coarse cell can run
between the samples). ``exact=False``: the coarse samples only. The loaded analysis starts from
the sampled zone (a proxy of the reach of the load: on the seed face gear pair (1, 1) comes
within 17.8 µm of contact at its closest point, every sample reads more than 22.9 µm, and the
rated load closes 9.5 µm: modelling it would double the cost of the operators for nothing) and
grows it with the exact rule when a pair left out can close under the solved lag
(:func:`fegear.ltca.cycle.grown_zone`).

**Zone boxes.** On every such tooth, the TCA's coarse separation cells (a regular grid of the pinion
flank coordinates) with separation ``<= gap_mm`` at any position, dilated by one coarse cell in
both directions (the same dilation as the contact grids of :func:`fegear.ltca.grid.pair_cells`),
are the pinion's zone. The gear's zone is the same set carried across the gap: the gear flank
coordinates the TCA found for those cells and their neighbours, rasterised on a grid of the gear
flank of the same resolution and dilated by one cell. Each zone is a union of boxes in the flank
coordinates, one per run of consecutive zone cells along ``v`` (:class:`FlankZone`).

Why it matters (measured before the zone came from the TCA, when every sector had 3 teeth and
only the centre one was fine):

* the loaded TE must repeat one pitch later (the next pair in the same state); on the FZG spur
  pair it jumped by 12.3 / 13.3 arcsec of -53 (24 %) at ``fe`` level 0; now 2.0 arcsec of -57
  (3.5 %; 0.7 arcsec with 7 teeth: the clamped cuts stiffen their neighbours,
  ``tests/test_ltca.py``);
* spiral bevel, ``fe`` level 3: the pairs on the outer teeth were solved with element-sized cells
  over elements four times larger; the compliance of such cells is rank-deficient and the pressure
  collapsed onto single rows of cells (semi-minor axis 0.00-0.02 mm instead of 0.3 mm, p_max
  3000-3959 MPa instead of ~1300 MPa);
* loaded TE peak-to-peak of the spiral bevel 15.4 -> 12.3 arcsec (``hybrid`` level 0), of the
  seed face gear 0.69 -> 0.49 arcsec.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import binary_dilation

from fegear.errors import InputError
from fegear.ltca.grid import near_cells
from fegear.mesh.sector import FlankZone
from fegear.tca.results import PositionResult

__all__ = ["ContactZone", "contact_zone", "left_out_pairs"]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


@dataclass(frozen=True)
class ContactZone:
    """The teeth and flank boxes a cycle's contact can reach.

    Attributes
    ----------
    n_teeth
        Sector teeth for both members.
    pinion, gear
        Zone boxes on each member's working flank (sector tooth numbering).
    pairs
        ``(m, 2)`` int, the pairs ``(k, j)`` that can touch.
    gap_mm
        The separation bound used.
    """

    n_teeth: int
    pinion: tuple[FlankZone, ...]
    gear: tuple[FlankZone, ...]
    pairs: NDArray[np.int64]
    gap_mm: float


def _dilate(mask: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Binary dilation by one cell (3 × 3 neighbourhood)."""
    return binary_dilation(mask, structure=np.ones((3, 3), dtype=bool))


def _boxes(mask: NDArray[np.bool_], u: Array, v: Array, tooth: int, side: str) -> list[FlankZone]:
    """One box per run of consecutive ``True`` cells along ``v`` in each ``u`` row of ``mask``
    (cells centred at ``u``, ``v``; a box spans its cells fully)."""
    du = (u[-1] - u[0]) / max(len(u) - 1, 1)
    dv = (v[-1] - v[0]) / max(len(v) - 1, 1)
    out = []
    for i in range(mask.shape[0]):
        row = np.concatenate([[False], mask[i], [False]]).astype(np.int8)
        starts = np.flatnonzero(np.diff(row) == 1)
        ends = np.flatnonzero(np.diff(row) == -1) - 1
        for s, e in zip(starts, ends, strict=True):
            out.append(
                FlankZone(
                    tooth,
                    side,
                    (float(u[i] - 0.5 * du), float(u[i] + 0.5 * du)),
                    (float(v[s] - 0.5 * dv), float(v[e] + 0.5 * dv)),
                )
            )
    return out


def _clip(z: FlankZone, bounds) -> FlankZone:
    u = (max(z.u[0], bounds.u_fillet), min(z.u[1], bounds.u_tip))
    v = (max(z.v[0], bounds.v_start), min(z.v[1], bounds.v_end))
    return FlankZone(z.tooth, z.side, u, v)


def contact_zone(
    positions: tuple[PositionResult, ...] | list[PositionResult],
    bounds1,
    bounds2,
    side1: str,
    side2: str,
    gap_mm: float,
    n_teeth: int | None = None,
    min_teeth: int = 3,
    exact: bool = True,
) -> ContactZone:
    """The contact zone of a cycle (see the module docstring).

    Parameters
    ----------
    positions
        TCA positions with separation grids (:meth:`fegear.tca.TCA.positions`).
    bounds1, bounds2
        Working-flank limits (``u_fillet, u_tip, v_start, v_end``) of the pinion and the gear.
    side1, side2
        Working flank sides.
    gap_mm
        Separation bound (mm).
    n_teeth
        Sector teeth; None: from the pairs that can touch. Pairs outside a given count get no
        zone (the loaded analysis reports them).
    min_teeth
        Fewest teeth of an automatic count.
    exact
        Pairs and cells within ``gap_mm`` at their exact closest points too, not only at the
        coarse samples (see the module docstring).
    """
    grids = [g for p in positions for g in p.grids]
    if not grids:
        raise InputError("positions", "without separation grids", "TCA positions with grids")
    # (grid, its near cells): the coarse samples within gap_mm and, if exact, the cell of the
    # pair's closest point (a narrow valley can run between the samples: near_cells).
    nears = [
        (g, near_cells(p, i, gap_mm) if exact else g.valid & (g.separation <= gap_mm))
        for p in positions
        for i, g in enumerate(p.grids)
    ]
    near_pairs = sorted({(int(g.k), int(g.j)) for g, near in nears if np.any(near)})
    reach = max((max(abs(k), abs(j)) for k, j in near_pairs), default=0)
    n = n_teeth if n_teeth is not None else max(min_teeth, 2 * reach + 3)
    c = n // 2
    z1: list[FlankZone] = []
    z2: list[FlankZone] = []
    for k, j in near_pairs:
        if not (0 <= k + c < n and 0 <= j + c < n):
            continue
        gs = [(g, near) for g, near in nears if (g.k, g.j) == (k, j)]
        u, v = gs[0][0].u, gs[0][0].v
        m1 = np.zeros(gs[0][0].valid.shape, dtype=bool)
        nu2, nv2 = m1.shape
        u2 = np.linspace(bounds2.u_fillet, bounds2.u_tip, nu2 + 1)
        v2 = np.linspace(bounds2.v_start, bounds2.v_end, nv2 + 1)
        m2 = np.zeros((nu2, nv2), dtype=bool)
        for g, near in gs:
            m1 |= near
            # gear points of the near cells and their neighbours, rasterised on the gear grid
            around = _dilate(near) & g.valid
            gu, gv = g.gear_uv[around].T
            iu = np.clip(np.searchsorted(u2, gu) - 1, 0, nu2 - 1)
            iv = np.clip(np.searchsorted(v2, gv) - 1, 0, nv2 - 1)
            m2[iu, iv] = True
        z1 += [_clip(z, bounds1) for z in _boxes(_dilate(m1), u, v, k + c, side1)]
        cu2, cv2 = 0.5 * (u2[1:] + u2[:-1]), 0.5 * (v2[1:] + v2[:-1])
        z2 += [_clip(z, bounds2) for z in _boxes(_dilate(m2), cu2, cv2, j + c, side2)]
    log.info(
        "contact zone: pairs %s within %.3f mm, %d-tooth sectors, %d + %d zone boxes",
        near_pairs,
        gap_mm,
        n,
        len(z1),
        len(z2),
    )
    return ContactZone(
        n_teeth=n,
        pinion=tuple(z1),
        gear=tuple(z2),
        pairs=np.array(near_pairs, dtype=np.int64).reshape(-1, 2),
        gap_mm=float(gap_mm),
    )


def left_out_pairs(
    pos: PositionResult, models, theta: float, warnings: list[str] | None = None
) -> tuple[tuple[int, int], ...]:
    """The pairs outside the modelled teeth that the lag ``θ`` (rad) closes at ``pos``.

    A pair closes under the rigid rotation ``θ`` of member 2 where its angular gap
    ``backlash_rad`` (exact, at its closest point) is below ``θ``; the elastic deformation only
    opens it further. ``models`` has ``pinion.has_tooth(k)`` and ``gear.has_tooth(j)``
    (:class:`fegear.ltca.analysis.MemberModels`). Each pair found is appended to ``warnings``
    (and logged); :func:`fegear.ltca.cycle.grown_zone` rebuilds the sectors to hold it.
    """
    out = tuple(
        (int(k), int(j))
        for (k, j), ok, b in zip(pos.pairs, pos.pair_valid, pos.backlash_rad, strict=True)
        if ok
        and b < theta
        and not (models.pinion.has_tooth(int(k)) and models.gear.has_tooth(int(j)))
    )
    for k, j in out:
        msg = (
            f"pair ({k}, {j}) closes under the loaded lag but lies outside the contact zone of "
            f"the {models.pinion.sector.n_teeth}-tooth sectors: not modelled"
        )
        if warnings is not None and msg not in warnings:
            warnings.append(msg)
            log.warning("phi1 = %.4f: %s", pos.phi1, msg)
    return out
