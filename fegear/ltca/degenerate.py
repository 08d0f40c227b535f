"""When a loaded position is degenerate: one rule for every fidelity and load.

**The rule** (docs/ltca/degenerate.md). A position is *degenerate* when the loaded pairs whose
patch its contact cells do not resolve carry together at least
:data:`~fegear.ltca.results.DEGENERATE_SHARE` (1 %) of the torque. A patch is resolved when its
minor axis spans at least :data:`~fegear.ltca.results.MIN_CELLS_ACROSS` (2) cells (a patch on
one row of cells spans 0).
A degenerate position is left out of the cycle's TE peak-to-peak and p_max.

**Why the share.** The cells of an unresolved patch are wider than the contact: its pressures
are cell averages and its compliance is that of the cells, not of the contact, so the pair's
force is wrong by up to its own size. The pairs of a position share the lag ``θ`` like parallel
springs: a pair of share ``s`` whose force is in error by ``ΔF`` moves the torque balance, hence
the lag, by ``Δθ/θ ≈ ΔF h / T ≤ s``. Pairs the cells do not resolve with shares ``s_i`` leave
the loaded TE uncertain by at most ``Σ s_i θ``; the rule keeps that bound below 1 % of the
elastic lag whatever the load, the cell size or how far from resolved the patch is (0.9 or 0.0
cells across: the bound is the same). Measured on the seed face gear at ``hybrid`` level 0
(light, moderate, heavy and nominal loads, the entering or leaving pair at a flank edge with
0.4-1.3 % of the torque and 0.0-1.4 cells across): refining those pairs until they are resolved
moves their shares by 2-43 % of themselves and the loaded TE by 0.0002-0.008″, 0.01-0.2 % of
the lag (``benchmarks/bench_degenerate.py``; docs/ltca/degenerate.md).

``hertz`` has no cells: its pairs are always resolved (closed-form laws).
"""

from __future__ import annotations

import numpy as np

from fegear.ltca.results import DEGENERATE_SHARE, MIN_CELLS_ACROSS, PairContact

__all__ = ["position_status", "unresolved_share"]


def unresolved_share(pairs: tuple[PairContact, ...] | list[PairContact]) -> float:
    """The share of the torque carried by the loaded pairs the cells do not resolve."""
    return float(sum(q.load_share for q in pairs if q.in_contact and not q.resolved))


def position_status(phi1: float, theta: float, pairs, cell_mm) -> tuple[str, str]:
    """``("ok", "")`` or ``("degenerate", why)`` by the module's rule.

    Parameters
    ----------
    phi1, theta
        The position's pinion angle and elastic lag (rad).
    pairs
        Its :class:`~fegear.ltca.results.PairContact` s.
    cell_mm
        Per pair, the smallest cell size (mm; for the reason).
    """
    share = unresolved_share(pairs)
    if share < DEGENERATE_SHARE:
        return "ok", ""
    parts = []
    for q, size in zip(pairs, cell_mm, strict=True):
        if q.in_contact and not q.resolved:
            parts.append(
                f"pair ({q.k}, {q.j}) carries {100 * q.load_share:.3g} % of the torque on "
                f"{q.n_active} cell{'s' if q.n_active != 1 else ''} of {size:.3g} mm, "
                f"{q.cells_across:.1f} across its patch (2b = {2 * q.semi_minor_mm:.3g} mm; "
                f"at least {MIN_CELLS_ACROSS:g} needed)"
            )
    lag = theta / np.radians(1.0 / 3600.0)
    return "degenerate", (
        f"phi1 = {np.degrees(phi1):.3f} deg: " + "; ".join(parts) + f": the patches the cells "
        f"do not resolve carry {100 * share:.3g} % of the torque (at least "
        f"{100 * DEGENERATE_SHARE:g} % makes a position degenerate), so the loaded TE here is "
        f"uncertain by up to {abs(share * lag):.3g}″ ({100 * share:.3g} % of the {abs(lag):.3g}″ "
        "lag)"
    )
