"""The ease-off of a run's pair, kept in the artefact cache, and the numbers that describe it.

A run reports the ease-off (:mod:`fegear.tca.ease_off`, ``docs/ease_off.md``) of its pair in
the assembly the analysis phased, on a :data:`GRID` of the pinion's working flank; for measured
flanks (:class:`~fegear.tca.deviation.MeasuredMember`) also the design pair's, on the same grid
and assembly. Both are kept in the artefact cache (kind ``ease_off``, keyed like the TCA: the
members' ``repr`` with their grid hashes, the assembly with its errors and phase, the grid), so a
warm run reads them.

The shape of an ease-off is read by bevel engineers as a few numbers (Stadtfeld, *Handbook of
Bevel and Hypoid Gears*, 1993, §2: length and profile crowning, flank twist; the same terms name
a cylindrical pair's lead and profile modifications). :func:`fit_ease_off` gives them as the
least-squares quadratic

.. math::  \\varepsilon(s, t) \\approx c_0 + c_s s + c_t t + C_p s^2 + C_l t^2 + C_x s t

over the defined nodes, ``s, t ∈ [−1, 1]`` the normalised profile (fillet limit → tip) and face
(start → end) coordinates of the grid. ``C_p`` (profile crowning) and ``C_l`` (lengthwise
crowning) are the rise of the fitted surface at the ends of the profile / face over its tangent
plane at the centre; ``C_x`` (twist, diagonal) is a quarter of
``ε(1, 1) + ε(−1, −1) − ε(1, −1) − ε(−1, 1)``; ``c_s`` and ``c_t`` are half the fitted rise from
one end to the other (a pressure-angle or helix/spiral-angle mismatch). A lead crowning ``C_β``
of a helical pinion gives ``C_l = C_β cos β_b`` (laid along the transverse line of action).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from fegear.store.records import cached_object, registry

from .cached import pair_key
from .core import TCA, TCAOptions
from .deviation import MeasuredMember
from .ease_off import EaseOff, ease_off

__all__ = ["GRID", "EaseOffFit", "PairEaseOff", "fit_ease_off", "pair_ease_off"]

log = logging.getLogger(__name__)

#: the grid of a run's ease-off: profile × face nodes
GRID = (21, 41)
#: the TCA options of the ease-off's TCA object: no search, no separation grid (it only holds
#: the flank maps, the tooth frames and the gear's start values)
OPTIONS = TCAOptions(search_grid=(3, 3), separation_grid=None, edge_samples=3)
#: the fewest defined nodes a fit is made on (six coefficients, a grid of 21 × 41)
MIN_FIT_NODES = 12


@dataclass(frozen=True)
class PairEaseOff:
    """The ease-off of a pair as run, and of its design pair for measured flanks.

    Attributes
    ----------
    ease_off
        The pair as run (measured flanks where the case has them).
    design
        The design pair's on the same grid and assembly (a measured pair), else None.
    """

    ease_off: EaseOff
    design: EaseOff | None

    @property
    def difference_um(self) -> np.ndarray | None:
        """``(nu, nv)`` µm, measured minus design (each ``θ_e h`` less the design's minimum;
        NaN where either is undefined), or None without a design."""
        if self.design is None:
            return None
        e, d = self.ease_off, self.design
        return (e.eps_um - d.eps_um) + (e.eps_min_mm - d.eps_min_mm) * 1e3


class EaseOffFit(NamedTuple):
    """The quadratic fit of an ease-off (module docstring), µm.

    Attributes
    ----------
    offset_um
        ``c_0``: the fitted ε at the flank's centre.
    profile_slope_um, lengthwise_slope_um
        ``c_s``, ``c_t``: half the fitted rise from the fillet limit to the tip, from the face's
        start to its end.
    profile_crowning_um, lengthwise_crowning_um
        ``C_p``, ``C_l``.
    twist_um
        ``C_x``.
    rms_um
        Root mean square of the fit's residual over the defined nodes (what the quadratic does
        not hold: reliefs, a bias that is not bilinear, a grid's bumps).
    nodes
        How many defined nodes it was fitted on.
    """

    offset_um: float
    profile_slope_um: float
    lengthwise_slope_um: float
    profile_crowning_um: float
    lengthwise_crowning_um: float
    twist_um: float
    rms_um: float
    nodes: int


def fit_ease_off(e: EaseOff) -> EaseOffFit | None:
    """The :class:`EaseOffFit` of ``e`` over its defined nodes (least squares, module
    docstring), or None with fewer than :data:`MIN_FIT_NODES` of them."""
    s = 2 * (e.u - 0.5 * (e.u[0] + e.u[-1])) / (e.u[-1] - e.u[0])
    t = 2 * (e.v - 0.5 * (e.v[0] + e.v[-1])) / (e.v[-1] - e.v[0])
    S, T = np.meshgrid(s, t, indexing="ij")
    ok = np.isfinite(e.eps_um)
    if ok.sum() < MIN_FIT_NODES:
        return None
    s, t, y = S[ok], T[ok], e.eps_um[ok]
    A = np.stack([np.ones_like(s), s, t, s * s, t * t, s * t], -1)
    c, *_ = np.linalg.lstsq(A, y, rcond=None)
    rms = float(np.sqrt(np.mean((A @ c - y) ** 2)))
    return EaseOffFit(*(float(x) for x in c), rms, int(ok.sum()))


_CLASSES = registry(EaseOff, PairEaseOff)


def pair_ease_off(pinion, gear, assembly, grid: tuple[int, int] = GRID) -> PairEaseOff:
    """The :class:`PairEaseOff` of ``pinion`` and ``gear`` in ``assembly`` (phased, with its
    errors) on ``grid``, from the cache when made before (module docstring)."""
    params = {**pair_key(pinion, gear, assembly, OPTIONS), "grid": list(grid)}

    def make() -> PairEaseOff:
        e = ease_off(TCA(pinion, gear, assembly, OPTIONS), grid)
        design = None
        if isinstance(pinion, MeasuredMember) or isinstance(gear, MeasuredMember):
            base = [m.base if isinstance(m, MeasuredMember) else m for m in (pinion, gear)]
            design = ease_off(TCA(base[0], base[1], assembly, OPTIONS), grid)
        return PairEaseOff(e, design)

    return cached_object("ease_off", params, make, _CLASSES)[0]
