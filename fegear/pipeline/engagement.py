"""The engagement checks of a gear pair, made before any FE work (:func:`check_engagement`).

Every way the contact can fail is decided here: a tip running into the mate's root and no
contact at any position are refused (:class:`~fegear.errors.InputError` naming the
installation-error fields), contact lost at some positions, a pair that jams and a contact ratio
below 1 become warnings (the installation errors: ``docs/conventions.md``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from fegear.errors import DesignError, InputError
from fegear.geometry.pair_placement import InstallationErrors
from fegear.io.gear_case import GearCase, error_fields
from fegear.pipeline.pair import GearPair, assemble
from fegear.tca.engagement import cached_handover, jamming, tip_root_clearance
from fegear.tca.path import cached_contact_path

__all__ = ["INTERFERENCE_TOL_MM", "Engagement", "check_engagement", "check_clearance"]

Array = NDArray[np.float64]


#: A tip closer than this to the mate's root (mm) is an interference (the clearance is computed
#: to well below a micrometre, :func:`fegear.tca.engagement.tip_root_clearance`).
INTERFERENCE_TOL_MM = 1e-4


@dataclass(frozen=True)
class Engagement:
    """How the flanks engage, checked before the loaded analysis (:func:`check_engagement`).

    Attributes
    ----------
    clearance
        Tip-to-root clearances (:class:`fegear.tca.engagement.Clearance`).
    handover
        Interior contact over the cycle (:class:`fegear.tca.engagement.Handover`).
    path
        One pair's unloaded contact over its whole contact interval
        (:class:`fegear.tca.path.ContactPath`: contact ratio, path length, what ends it), or
        None where no pair has interior contact.
    phi1
        ``(n,)`` rad, the positions of the run.
    has_contact
        ``(n,)`` bool, the unloaded TCA found contact there.
    missed_handover
        The interior contact covers less than the whole cycle (contact ratio below 1) and no
        position of the run falls where it does not: the run's TE peak-to-peak and contact
        ratio do not see the handover.
    errors
        ``[(case-file key, value)]`` of the non-zero installation errors.
    warnings
        Terminal warnings (they change the meaning of a headline).
    """

    clearance: Any
    handover: Any
    phi1: Array
    has_contact: NDArray[np.bool_]
    missed_handover: bool
    errors: tuple[tuple[str, float], ...]
    warnings: tuple[str, ...]
    path: Any = None

    @property
    def contact_ratio_below_one(self) -> float | None:
        """The unloaded contact ratio when it is below 1 (the interior fraction), else None."""
        f = float(self.handover.interior_fraction)
        return f if f < 1.0 else None

    @property
    def lost(self) -> tuple[int, ...]:
        """Positions of the run without unloaded contact."""
        return tuple(int(i) for i in np.flatnonzero(~self.has_contact))


def _fields_text(errors) -> str:
    return ", ".join(f"{k} = {v:g}" for k, v in errors) or "no installation errors"


def check_clearance(case: GearCase, pair: GearPair):
    """Refuse a tip running into the mate's root (:class:`~fegear.errors.InputError` naming the
    installation-error field that causes it and the depth; a :class:`~fegear.errors.DesignError`
    if the error-free pair already interferes)."""
    from dataclasses import replace

    c = tip_root_clearance(pair.pinion, pair.gear, pair.assembly)
    if c.interference_mm <= INTERFERENCE_TOL_MM:
        return c
    who = c.worse
    mate = "gear" if who == "pinion" else "pinion"
    errs = error_fields(case)
    nominal = tip_root_clearance(pair.pinion, pair.gear, assemble(case, pair, InstallationErrors()))
    what = (
        f"tip/root interference: the {who} tip runs {c.interference_mm:.3f} mm into the {mate} "
        f"root; the tip clearance without errors is "
        f"{min(nominal.pinion_tip_mm, nominal.gear_tip_mm):.3f} mm"
    )
    if not errs or nominal.interference_mm > INTERFERENCE_TOL_MM:
        raise DesignError(
            "pair", "tip/root interference", "a pair whose tips clear the roots", what
        )
    culprits = []
    for key, value in errs:
        one = replace(InstallationErrors(), **{key.split(".", 1)[1]: value})
        alone = tip_root_clearance(pair.pinion, pair.gear, assemble(case, pair, one))
        if alone.interference_mm > INTERFERENCE_TOL_MM:
            culprits.append((key, value))
    named = culprits or errs
    field = ", ".join(k for k, _ in named)
    value = named[0][1] if len(named) == 1 else [v for _, v in named]
    raise InputError(
        field, value, "an installation error that keeps the tips out of the roots", what
    )


def _jamming(pair: GearPair, case: GearCase) -> str:
    """The warning of a parallel-axes pair that jams (:func:`fegear.tca.engagement.jamming`),
    else ""."""
    if pair.assembly.kind != "parallel":
        return ""
    j = jamming(pair.pinion, pair.gear, case.errors)
    if j is None:
        return ""
    named = ", ".join(f"{k} = {v:g}" for k, v in j.fields)
    return (
        f"the pair jams ({named}): its teeth are cut without backlash for the centre distance "
        f"{j.working_mm:.4f} mm; at {j.centre_distance_mm:.4f} mm their other flanks would "
        f"overlap by {j.depth_mm:.4f} mm along the line of action; the analysis loads the "
        "working flanks only"
    )


def check_engagement(
    case: GearCase, pair: GearPair, tca, positions, clearance, workers: int | None = None
) -> Engagement:
    """Every way the contact can fail, decided before the loaded analysis.

    ``tca``, ``positions``: the TCA of the run's positions (:func:`fegear.tca.cached.cached_tca`,
    the one the loaded analysis reads back); ``clearance``: the pair's tip/root clearances
    (checked first: an interference is refused before any TCA); ``workers``: processes for the
    TCA positions of the path's ends and the hand-overs (:func:`fegear.tca.parallel.positions`).

    Raises
    ------
    InputError
        No position of the cycle has contact: the flanks do not meet (naming the installation
        errors that separate them).
    """
    errs = tuple(error_fields(case))
    has = np.array([p.has_contact for p in positions], dtype=bool)
    phi1 = np.array([p.phi1 for p in positions], dtype=float)
    n = len(positions)
    if not has.any():
        field = ", ".join(k for k, _ in errs) or "pair"
        value = errs[0][1] if len(errs) == 1 else [v for _, v in errs] if errs else "as designed"
        raise InputError(
            field,
            value,
            "installation errors under which the flanks meet",
            f"no contact anywhere: the flanks do not meet at any of the {n} positions of the "
            f"cycle; the teeth are separated by {_fields_text(errs)}",
        )
    h = cached_handover(pair.pinion, pair.gear, pair.assembly, tca.opt, tca, workers=workers)
    path = cached_contact_path(
        pair.pinion, pair.gear, pair.assembly, tca.opt, tca, positions, workers=workers
    )
    warnings = []
    jam = _jamming(pair, case)
    if jam:
        warnings.append(jam)
    lost = np.flatnonzero(~has)
    if lost.size:
        where = ", ".join(f"{i} (φ1 = {np.degrees(phi1[i]):.3f}°)" for i in lost)
        warnings.append(
            f"contact lost at {lost.size} of {n} positions: {where}; the flanks do not meet "
            f"there ({_fields_text(errs)}); the TE peak-to-peak leaves them out"
        )
    missed = False
    if h.interior_fraction < 1.0:
        pct = 100.0 * (1.0 - h.interior_fraction)
        spans = ", ".join(f"{np.degrees(a):.2f}° to {np.degrees(b):.2f}°" for a, b in h.intervals)
        text = (
            f"unloaded contact ratio {h.interior_fraction:.3f} < 1 ({_fields_text(errs)}): over "
            f"{pct:.1f} % of each mesh cycle (φ1 {spans}) the contact is at a tip or root edge "
            "or lost"
        )
        inside = h.covers(phi1)
        if not inside.any():
            missed = True
            need = int(np.ceil(1.0 / max(1.0 - h.interior_fraction, 1e-9))) + 1
            text += (
                f"; none of the {n} positions falls there, so their TE peak-to-peak and contact "
                f"ratio would not see it: not reported (run with n_positions >= {need})"
            )
        warnings.append(text)
    return Engagement(
        clearance=clearance,
        handover=h,
        phi1=phi1,
        has_contact=has,
        missed_handover=missed,
        errors=errs,
        warnings=tuple(warnings),
        path=path,
    )
