"""Is this batch acceptable? A measured run against its design run (:func:`accept`).

A measured case (a case file with a ``[topography]`` section, ``docs/measured_flanks.md``) is
run beside its design (by default the same case without the grids,
``case.replace(topography={})``), and the headlines of the two runs are compared against the
user's :class:`Tolerances`:

- ``p_max``: the largest pressure away from the flank edges (``cycle.p_max_MPa``), relative
  increase in %;
- ``TE p-p loaded``: ``cycle.te_pp_loaded_arcsec``, increase in arcsec (and, if asked, in %);
- ``TE p-p unloaded``: ``cycle.te_pp_unloaded_arcsec``, increase in arcsec;
- ``KHβ`` (cylindrical pairs): ``cylindrical.load.k_h_beta``, increase of the factor;
- ``edge contact``: a pair at a flank edge carrying load (``positions[i].pairs[j].edge_contact``)
  where the design's same pair at the same position has none.

Each :class:`Check` holds the measured and design values, the difference, the limit and its
status: ``"pass"``, ``"fail"``, or ``"undecided"`` when a value is null in either run (with the
run's reason: never a pass). The :class:`Verdict` is ``"reject"`` when a check fails,
``"undecided"`` when none fails but one is undecided, else ``"accept"``. The limits are
one-sided: a batch better than its design passes.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

from fegear.api.gear_result import GearResult
from fegear.api.runner import run
from fegear.errors import InputError
from fegear.io.gear_case import GearCase
from fegear.store.files import write_json

__all__ = ["ACCEPT", "REJECT", "UNDECIDED", "Check", "Tolerances", "Verdict", "accept"]

log = logging.getLogger(__name__)

ACCEPT, REJECT, UNDECIDED = "accept", "reject", "undecided"
PASS, FAIL = "pass", "fail"

#: ``progress(which, case)``: called before each run, ``which`` ``"measured"`` or ``"design"``
AcceptProgress = Callable[[str, GearCase], None]


@dataclass(frozen=True)
class Tolerances:
    """What a batch may differ from its design; each limit an allowed **increase** (a decrease
    always passes). None: the check is not made.

    The defaults are a starting point, not a standard: the limits are the user's to set (a
    customer's band, the margin of the design's safety factors).

    Attributes
    ----------
    p_max_pct
        Relative increase of p_max away from the flank edges, % (default 10: the contact stress
        enters the pitting life with a high power, so a 10 % rise already costs much of it).
    te_pp_loaded_arcsec
        Increase of the loaded TE peak-to-peak, arcsec (default 1.0).
    te_pp_loaded_pct
        Relative increase of the loaded TE peak-to-peak, % (default None: not checked).
    te_pp_unloaded_arcsec
        Increase of the unloaded TE peak-to-peak, arcsec (default 1.0).
    k_h_beta
        Increase of the face load factor KHβ (cylindrical pairs; default 0.1).
    edge_contact_allowed
        False (default): a loaded pair at a flank edge where the design's has none rejects.
    """

    p_max_pct: float | None = 10.0
    te_pp_loaded_arcsec: float | None = 1.0
    te_pp_loaded_pct: float | None = None
    te_pp_unloaded_arcsec: float | None = 1.0
    k_h_beta: float | None = 0.1
    edge_contact_allowed: bool = False

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "edge_contact_allowed":
                if not isinstance(v, bool):
                    raise InputError(f.name, v, "True or False")
                continue
            ok = isinstance(v, (int, float)) and not isinstance(v, bool)
            if v is not None and not (ok and math.isfinite(v) and v >= 0):
                raise InputError(f.name, v, "a finite number >= 0 (an allowed increase), or None")


@dataclass(frozen=True)
class Check:
    """One compared headline.

    Attributes
    ----------
    name
        ``"p_max"``, ``"te_pp_loaded"``, ``"te_pp_loaded_pct"``, ``"te_pp_unloaded"``,
        ``"k_h_beta"``, ``"edge_contact"``.
    label
        What it is, with its unit (the table's first column).
    measured, design
        The two runs' values (None: not reported; edge contact: the loaded pairs at an edge).
    difference
        Measured against design in the limit's unit (%, arcsec, the factor, new edge pairs).
    limit
        The allowed increase (None: edge contact allowed).
    unit
        The difference's and the limit's unit (``"%"``, ``"arcsec"``, ``""``, ``"pairs"``).
    status
        ``"pass"``, ``"fail"`` or ``"undecided"``.
    reason
        Why it is undecided (the run's reason), or what the failure is (edge contact: where).
    """

    name: str
    label: str
    measured: float | None
    design: float | None
    difference: float | None
    limit: float | None
    unit: str
    status: str
    reason: str = ""


@dataclass(frozen=True)
class Verdict:
    """The answer to "is this batch acceptable".

    Attributes
    ----------
    verdict
        ``"accept"``, ``"reject"`` (a check failed) or ``"undecided"`` (none failed, one could
        not be decided).
    checks
        The :class:`Check` of each limit set.
    tolerances
        The limits applied.
    measured, design
        The two runs (:class:`~fegear.api.GearResult`).
    """

    verdict: str
    checks: tuple[Check, ...]
    tolerances: Tolerances
    measured: GearResult = field(repr=False, compare=False)
    design: GearResult = field(repr=False, compare=False)

    @property
    def failing(self) -> tuple[Check, ...]:
        """The checks that failed."""
        return tuple(c for c in self.checks if c.status == FAIL)

    @property
    def undecided(self) -> tuple[Check, ...]:
        """The checks that could not be decided."""
        return tuple(c for c in self.checks if c.status == UNDECIDED)

    @property
    def line(self) -> str:
        """The verdict line: ``ACCEPT``, ``REJECT: <failing checks>`` or ``UNDECIDED: <checks
        and their reasons>``."""
        if self.verdict == REJECT:
            return "REJECT: " + "; ".join(_failure(c) for c in self.failing)
        if self.verdict == UNDECIDED:
            return "UNDECIDED: " + "; ".join(f"{SHORT[c.name]} ({c.reason})"
                                             for c in self.undecided)  # fmt: skip
        return "ACCEPT: every check within its limit"

    def table(self) -> str:
        """The checks as a text table (Markdown) under a line naming the runs, and the verdict
        line."""
        m, d = self.measured, self.design
        head = (
            f"{m.case.name} ({_where(m.case.source)}) against its design {d.case.name} "
            f"({_where(d.case.source)}"
            f"{', without [topography]' if not d.case.topography else ''}): "
            f"{m.fidelity}" + (f" level {m.level}" if m.level is not None else "")
            + f", {m.cycle.n_positions} positions"
        )  # fmt: skip
        rows = [head, "", "| check | measured | design | difference | limit | result |",
                "|---|---|---|---|---|---|"]  # fmt: skip
        for c in self.checks:
            rows.append(
                f"| {c.label} | {_num(c.measured, c)} | {_num(c.design, c)} | {_diff(c)} | "
                f"{_limit(c)} | {c.status.upper() if c.status == FAIL else c.status} |"
            )
        notes = [f"- {c.label}: {c.reason}" for c in self.checks if c.reason]
        return "\n".join(rows + ([""] + notes if notes else []) + ["", self.line])

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (``acceptance.json``)."""

        def run(r: GearResult) -> dict[str, Any]:
            return {"case": r.case.name, "source": str(r.case.source),
                    "topography": {k: {"file": " + ".join(map(str, g.files)), "sha256": g.sha256}
                                   for k, g in r.case.topography.items()}, "fidelity": r.fidelity,
                    "level": r.level, "n_positions": r.cycle.n_positions}  # fmt: skip

        return {
            "verdict": self.verdict,
            "line": self.line,
            "failing": [c.name for c in self.failing],
            "undecided": [c.name for c in self.undecided],
            "checks": [asdict(c) for c in self.checks],
            "tolerances": asdict(self.tolerances),
            "measured": run(self.measured),
            "design": run(self.design),
        }

    def write(self, folder: str | Path) -> Path:
        """Write ``acceptance.json`` into ``folder`` (made if missing), atomically; its path."""
        return write_json(Path(folder) / "acceptance.json", self.as_dict())


def _where(source: object) -> str:
    """A case's file relative to the working folder when it is under it (the table's head)."""
    try:
        return str(Path(str(source)).resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(source)


#: the checks' names in the verdict line
SHORT = {"p_max": "p_max", "te_pp_loaded": "TE p-p loaded", "te_pp_loaded_pct": "TE p-p loaded",
         "te_pp_unloaded": "TE p-p unloaded", "k_h_beta": "KHβ",
         "edge_contact": "edge contact"}  # fmt: skip


def _failure(c: Check) -> str:
    if c.name == "edge_contact":
        return c.reason
    return f"{SHORT[c.name]} {_diff(c)} > {_limit(c)}"


def _fmt(c: Check) -> str:
    return {"p_max": ".0f", "k_h_beta": ".3f", "edge_contact": ".0f"}.get(c.name, ".2f")


def _num(x: float | None, c: Check) -> str:
    return "—" if x is None else format(x, _fmt(c))


def _diff(c: Check) -> str:
    if c.difference is None:
        return "—"
    if c.name == "edge_contact":
        return f"{c.difference:.0f} new"
    spec = "+.1f" if c.unit == "%" else ("+.3f" if c.name == "k_h_beta" else "+.2f")
    return f"{format(c.difference, spec)}{' ' + c.unit if c.unit else ''}"


def _limit(c: Check) -> str:
    if c.name == "edge_contact":
        return "allowed" if c.limit is None else "none new"
    spec = "+.1f" if c.unit == "%" else ("+.3f" if c.name == "k_h_beta" else "+.2f")
    return f"{format(c.limit, spec)}{' ' + c.unit if c.unit else ''}"


def _increase(name, label, unit, m, d, m_why, d_why, limit, relative=False) -> Check:
    """A one-sided check of ``m`` against ``d``: undecided when either is None."""
    if m is None or d is None:
        why = "; ".join(
            f"{w} run: {r or 'not reported'}"
            for w, x, r in (("measured", m, m_why), ("design", d, d_why))
            if x is None
        )
        if m is None and d is None and m_why == d_why:
            why = f"both runs: {m_why or 'not reported'}"
        return Check(name, label, m, d, None, limit, unit, UNDECIDED, why)
    if relative:
        if d <= 0:
            return Check(name, label, m, d, None, limit, unit, UNDECIDED,
                         "the design's value is 0: no relative change")  # fmt: skip
        diff = 100.0 * (m - d) / d
    else:
        diff = m - d
    return Check(name, label, m, d, diff, limit, unit, PASS if diff <= limit else FAIL)


def _edge_pairs(r: GearResult) -> dict[tuple[int, int, int], tuple[str, ...]]:
    """``{(position, pinion tooth, gear tooth): edges}`` of the pairs at a flank edge that carry
    load."""
    return {
        (p.index, q.pinion_tooth, q.gear_tooth): q.edges
        for p in r.positions
        for q in p.pairs
        if q.edge_contact and q.in_contact and (q.load_share or 0.0) > 0.0
    }


def _edge_check(m: GearResult, d: GearResult, allowed: bool) -> Check:
    label = "edge contact (loaded pairs at an edge)"
    limit = None if allowed else 0.0
    if any(all(p.te_loaded_arcsec is None for p in r.positions) for r in (m, d)):
        return Check("edge_contact", label, None, None, None, limit, "pairs", UNDECIDED,
                     f"both runs: no loaded contact (fidelity {m.fidelity})")  # fmt: skip
    em, ed = _edge_pairs(m), _edge_pairs(d)
    new = {k: e for k, e in em.items() if k not in ed}
    status = FAIL if new and not allowed else PASS
    where = ", ".join(f"position {i} pair ({a}, {b}) at the {' and '.join(e)}"
                      for (i, a, b), e in sorted(new.items()))  # fmt: skip
    reason = f"new edge contact: {where}" if new else ""
    return Check("edge_contact", label, float(len(em)), float(len(ed)), float(len(new)), limit,
                 "pairs", status, reason)  # fmt: skip


def _k_h_beta(r: GearResult) -> tuple[float | None, str]:
    load = (r.model.cylindrical or {}).get("load") or {}
    k = load.get("k_h_beta")
    if k is None:
        why = load.get("reason") or (r.model.cylindrical or {}).get("reason") or ""
        if r.fidelity == "tca":
            why = why or "unloaded TCA only (fidelity tca)"
        return None, why
    return float(k), ""


def compare(measured: GearResult, design: GearResult, tolerances: Tolerances) -> Verdict:
    """The :class:`Verdict` of two runs of the same pair (their positions the same)."""
    t = tolerances
    cm, cd = measured.cycle, design.cycle
    checks: list[Check] = []
    if t.p_max_pct is not None:
        checks.append(_increase("p_max", "p_max away from the edges (MPa)", "%", cm.p_max_MPa,
                                cd.p_max_MPa, cm.p_max_reason, cd.p_max_reason, t.p_max_pct,
                                relative=True))  # fmt: skip
    te = ("TE p-p loaded (arcsec)", cm.te_pp_loaded_arcsec, cd.te_pp_loaded_arcsec,
          cm.te_pp_loaded_reason, cd.te_pp_loaded_reason)  # fmt: skip
    if t.te_pp_loaded_arcsec is not None:
        checks.append(_increase("te_pp_loaded", te[0], "arcsec", *te[1:], t.te_pp_loaded_arcsec))
    if t.te_pp_loaded_pct is not None:
        checks.append(_increase("te_pp_loaded_pct", "TE p-p loaded, relative", "%", *te[1:],
                                t.te_pp_loaded_pct, relative=True))  # fmt: skip
    if t.te_pp_unloaded_arcsec is not None:
        checks.append(_increase("te_pp_unloaded", "TE p-p unloaded (arcsec)", "arcsec",
                                cm.te_pp_unloaded_arcsec, cd.te_pp_unloaded_arcsec,
                                cm.te_pp_unloaded_reason, cd.te_pp_unloaded_reason,
                                t.te_pp_unloaded_arcsec))  # fmt: skip
    if t.k_h_beta is not None and measured.case.kind == "cylindrical":
        (km, wm), (kd, wd) = _k_h_beta(measured), _k_h_beta(design)
        checks.append(_increase("k_h_beta", "KHβ", "", km, kd, wm, wd, t.k_h_beta))
    checks.append(_edge_check(measured, design, t.edge_contact_allowed))
    for c in checks:
        if c.name.startswith("te_pp_loaded") and c.status != UNDECIDED:
            used = (cm.te_pp_loaded_positions_used, cd.te_pp_loaded_positions_used)
            if used[0] != used[1]:
                checks[checks.index(c)] = Check(**{**asdict(c), "reason": (
                    f"over {used[0]} positions measured, {used[1]} design (cycle."
                    "excluded_positions)")})  # fmt: skip
    status = {c.status for c in checks}
    verdict = REJECT if FAIL in status else UNDECIDED if UNDECIDED in status else ACCEPT
    return Verdict(verdict, tuple(checks), t, measured, design)


def accept(
    measured_case: GearCase,
    tolerances: Tolerances | None = None,
    design_case: GearCase | None = None,
    *,
    fidelity: str | None = None,
    level: int | None = None,
    workers: int | None = None,
    progress: AcceptProgress | None = None,
) -> Verdict:
    """Run a measured case and its design and compare their headlines.

    Parameters
    ----------
    measured_case
        A gear case with measured flanks (a ``[topography]`` section).
    tolerances
        The limits (default :class:`Tolerances`: its documented defaults).
    design_case
        The design (default: ``measured_case.replace(topography={})``, the same pair with the
        generated flanks). The same kind of pair with the same number of positions.
    fidelity, level, workers
        As :func:`fegear.run`, for both runs (default: the measured case's fidelity and level).
    progress
        ``progress(which, case)`` before each run (``"measured"``, then ``"design"``).

    Returns
    -------
    Verdict

    Raises
    ------
    InputError
        Not a gear case; no design to compare with (a case without ``[topography]`` and no
        ``design_case``); a design of another kind of pair or other positions; bad tolerances
        or run options.
    """
    tol = Tolerances() if tolerances is None else tolerances
    if not isinstance(tol, Tolerances):
        raise InputError("tolerances", type(tol).__name__, "a fegear.Tolerances")
    if not isinstance(measured_case, GearCase):
        raise InputError("case", type(measured_case).__name__, "a gear case (not the Hertz scene)")
    if design_case is None:
        if not measured_case.topography:
            raise InputError("design_case", None, "a design case for a case without "
                             "[topography]", "it would be compared with itself")  # fmt: skip
        design_case = measured_case.replace(topography={})
    if not isinstance(design_case, GearCase) or design_case.kind != measured_case.kind:
        got = getattr(design_case, "kind", type(design_case).__name__)
        raise InputError("design_case", got, f"a {measured_case.kind} case (the measured pair's)")
    if design_case.n_positions != measured_case.n_positions:
        raise InputError("design_case", design_case.n_positions,
                         f"{measured_case.n_positions} positions (the measured case's)",
                         "[analysis] n_positions: the two runs are compared position by "
                         "position")  # fmt: skip
    fid = measured_case.fidelity if fidelity is None else fidelity
    lvl = measured_case.level if level is None else level
    results = {}
    for which, case in (("measured", measured_case), ("design", design_case)):
        if progress is not None:
            progress(which, case)
        results[which] = run(case, fidelity=fid, level=lvl, workers=workers, fields=False)
    m, d = results["measured"], results["design"]
    pairs = zip(m.positions, d.positions, strict=True)
    if any(abs(p.pinion_angle_deg - q.pinion_angle_deg) > 1e-9 for p, q in pairs):
        raise InputError("design_case", design_case.name, "the measured case's mesh positions",
                         "its pinion angles differ: the cycles are compared position by "
                         "position")  # fmt: skip
    verdict = compare(m, d, tol)
    log.info("acceptance of %s: %s", measured_case.name, verdict.line)
    return verdict
