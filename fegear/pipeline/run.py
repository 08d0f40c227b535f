"""Run a gear-pair case: geometry → assembly → (TCA | loaded TCA) → displacement fields.

:func:`run_gear_case` is what ``fegear run`` calls for a gear case; it returns a
:class:`GearRun` that :func:`fegear.output.gear_output.write_gear_outputs` turns into files.
The library logs; the caller gets progress through an optional callback
``progress(stage, i, n)`` (``i``/``n`` are the position counters of the position stage and
``None`` otherwise; stage ``"cached"`` instead of ``"models"`` and ``"positions"`` when the
loaded cycle of the same run is read from the cache, :mod:`fegear.ltca.cached`).

Fidelities available for gear pairs (``docs/fidelity.md``):

- ``"fe"``: :func:`fegear.ltca.run_ltca` (FE sector compliance, torque-balanced contact);
  then, per member, the displacement ``u = K⁻¹ P F`` of every position in ONE factorisation
  (:func:`fegear.pipeline.fields.displacements`).
- ``"tca"``: the rigid, unloaded TCA (:func:`fegear.tca.run_tca`): unloaded TE, contact path,
  unloaded bearing pattern. No FE, no loaded results.
- ``"hybrid"`` (the default of every gear case) and ``"hertz"``: as ``"fe"`` with the compliance
  of :mod:`fegear.ltca.hybrid` or the per-pair Hertz laws of :mod:`fegear.ltca.hertz_fidelity`.

Before any FE work, :func:`fegear.pipeline.engagement.check_engagement` decides every way the
contact can fail. What the run reports (the headlines over the usable positions, the warnings)
is built from the :class:`GearRun` by :func:`fegear.results.build_result`.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from fegear.errors import InputError
from fegear.geometry.pair_placement import Assembly
from fegear.io.gear_case import FIDELITIES, N_LEVELS, UNLOADED, GearCase
from fegear.ltca import LTCAOptions, build_models, run_ltca
from fegear.ltca.cached import cached_cycle, cycle_params
from fegear.ltca.cycle import cycle_tca
from fegear.ltca.fidelity import Fidelity, fidelity_of
from fegear.ltca.results import LoadedCycle
from fegear.pipeline.engagement import Engagement, check_clearance, check_engagement
from fegear.pipeline.fields import FIELD_CLASSES, MemberField, displacements
from fegear.pipeline.pair import GearPair, build_pair
from fegear.store.cache import CacheUse, record_cache_use
from fegear.store.records import cached_object
from fegear.tca import TCAOptions
from fegear.tca.cached import cached_tca
from fegear.tca.cycle import cycle_result
from fegear.tca.ease_off_pair import PairEaseOff, pair_ease_off
from fegear.tca.ellipse import EllipseAt, ellipses
from fegear.tca.results import ARCSEC, CycleResult

__all__ = ["GearRun", "check_case", "run_gear_case"]

log = logging.getLogger(__name__)

Array = NDArray[np.float64]
Progress = Callable[[str, "int | None", "int | None"], None]


@dataclass(frozen=True)
class GearRun:
    """Everything a gear-case run produced (input of the writers).

    Attributes
    ----------
    case
        The case as run (fidelity and level overrides applied).
    pair
        Members and the assembly with the installation errors.
    assembly
        The assembly with the reference gear phase (the one the analysis used).
    cycle
        :class:`~fegear.ltca.LoadedCycle` (loaded fidelities), else None.
    tca
        :class:`~fegear.tca.CycleResult` (fidelity ``"tca"``), else None.
    members
        The two :class:`MemberField` (fidelities ``"fe"`` and ``"hybrid"``), else empty; empty
        too where the run was asked for its numbers only (``fields=False``:
        :attr:`fields_pending`, :func:`with_fields` adds them).
    seconds
        Wall time per stage.
    engagement
        What :func:`check_engagement` found before the analysis.
    cache
        The artefact-cache lookups of the run (:class:`fegear.store.cache.CacheUse`: what was
        read, what was built), or None.
    ellipses
        Per position the contact ellipses of the unloaded TCA
        (:class:`fegear.tca.ellipse.EllipseAt`, None without contact; Hertz at the case's load
        on one pair).
    cycle_key
        The cache key of the loaded cycle (:mod:`fegear.ltca.cached`; "" for none): what its
        displacement fields are cached under.
    ease_off
        The ease-off of the pair in :attr:`assembly` (and of its design pair for measured
        flanks; :mod:`fegear.tca.ease_off_pair`), or None.
    """

    case: GearCase
    pair: GearPair
    assembly: Assembly
    cycle: LoadedCycle | None = None
    tca: CycleResult | None = None
    members: tuple[MemberField, ...] = ()
    seconds: dict[str, float] = field(default_factory=dict)
    engagement: Engagement | None = None
    cache: CacheUse | None = None
    ellipses: tuple[EllipseAt | None, ...] = ()
    cycle_key: str = ""
    ease_off: PairEaseOff | None = None

    @property
    def fidelity(self) -> str:
        return self.case.fidelity

    @property
    def kind(self) -> Fidelity | None:
        """The loaded :class:`~fegear.ltca.fidelity.Fidelity` of the run (None: unloaded TCA)."""
        return None if self.fidelity == UNLOADED else fidelity_of(self.fidelity)

    @property
    def fields_pending(self) -> bool:
        """A loaded run with cell loads whose displacement fields were not computed
        (:func:`run_gear_case` with ``fields=False``; :func:`with_fields` computes them)."""
        return (
            self.cycle is not None
            and self.kind is not None
            and self.kind.cells
            and not self.members
        )

    @property
    def phi2(self) -> Array:
        """``(n,)`` rad, gear angle of the TCA-closed position (``ratio φ1 + TE_unloaded``)."""
        c = self.cycle if self.cycle is not None else self.tca
        te = c.te_unloaded_arcsec if self.cycle is not None else c.te_arcsec
        return self.assembly.ratio * np.asarray(c.phi1) + np.asarray(te) * ARCSEC


def _override(case: GearCase, fidelity: str | None, level: int | None) -> GearCase:
    from dataclasses import replace

    if fidelity is not None and fidelity not in FIDELITIES:
        raise InputError("--fidelity", fidelity, f"one of {FIDELITIES} for gear pairs")
    if level is not None and not 0 <= level < N_LEVELS:
        raise InputError("--level", level, f"an integer in [0, {N_LEVELS - 1}]")
    return replace(
        case,
        fidelity=fidelity if fidelity is not None else case.fidelity,
        level=level if level is not None else case.level,
    )


def run_gear_case(
    case: GearCase,
    fidelity: str | None = None,
    level: int | None = None,
    progress: Progress | None = None,
    pair: GearPair | None = None,
    workers: int | None = None,
    notify: Callable[[str], None] | None = None,
    fields: bool = True,
    reuse: bool = True,
) -> GearRun:
    """Run a gear case at its (or the given) fidelity and level.

    Parameters
    ----------
    case
        A validated :class:`~fegear.io.gear_case.GearCase`.
    fidelity, level
        Overrides of ``[analysis] fidelity`` and ``level``.
    progress
        ``progress(stage, i, n)``: called at the start of each stage (``i = n = None``) and after
        each mesh position (``stage = "positions"``).
    pair
        The pair of the case if already built (:func:`~fegear.pipeline.pair.build_pair`, which
        is where bad design data is refused).
    workers
        Processes for the mesh positions (:mod:`fegear.ltca.cycle`); None: one per core. A
        sweep, which runs its items in parallel already, passes 1.
    notify
        ``notify(text)``: called with each warning of the engagement checks as soon as they
        are made, before the loaded analysis (they are in ``GearRun.engagement`` too).
    fields
        Compute the displacement fields of the sectors (the VTK files, the stresses; one sparse
        factorisation per member and process, then one solve per member and run). False: the
        numbers only (every number of ``summary.json`` but the ``mesh`` sizes of the fields);
        :func:`with_fields` adds them later. The root stress (``case.root_stress``) is always
        computed: it is a number of the run.
    reuse
        Read the loaded cycle (every position) and its displacement fields from the cache when
        the same run was made before (:mod:`fegear.ltca.cached`: keyed on the pair, the
        installation, the torque, the options and the code); False: solve them again (the
        cache is neither read nor written for them).

    Raises
    ------
    InputError
        Bad overrides or design data; an installation under which the flanks cannot mesh: no
        contact at any position (naming the installation errors), or a tip running into the
        mate's root (naming the error and the depth). Both are decided before any FE work.
    """
    from dataclasses import replace

    with record_cache_use() as used:
        run = _run_gear_case(case, fidelity, level, progress, pair, workers, notify, fields, reuse)
    return replace(run, cache=used())


def with_fields(run: GearRun, progress: Progress | None = None) -> GearRun:
    """``run`` with its displacement fields (:func:`fegear.pipeline.fields.displacements`) if
    they are pending (:attr:`GearRun.fields_pending`), else ``run`` itself: a new run, its
    ``seconds`` and ``cache`` counting the fields' work too. What ``fields=True`` would have
    computed, with the same models and loads: the same fields."""
    from dataclasses import replace

    if not run.fields_pending:
        return run
    say = progress or (lambda stage, i, n: None)
    t0 = time.perf_counter()
    say("displacements", None, None)
    with record_cache_use() as used:
        members = _member_fields(run)
    seconds = {**run.seconds, "displacements": time.perf_counter() - t0}
    cache = used() if run.cache is None else run.cache.joined(used())
    return replace(run, members=members, seconds=seconds, cache=cache)


def _member_fields(run: GearRun) -> tuple[MemberField, ...]:
    """The displacement fields of a loaded run (:func:`fegear.pipeline.fields.displacements`),
    from the cache when its cycle's fields were computed before (``member_fields``, keyed on
    the cycle's key, the root-stress switch and the solver backend); a cycle read from the
    cache has no models: they are built (read from the cache) only when the fields are not."""
    c = run.case

    def compute() -> tuple[MemberField, ...]:
        models = run.cycle.models
        if models is None:  # the cycle came from the cache: its models, on its zone
            opt = _ltca_options(c, None)
            p = run.pair
            models = build_models(p.pinion, p.gear, p.assembly, opt, zone=run.cycle.zone)
        return displacements(run.pair, run.assembly, models, run.cycle, run.phi2,
                             root_stress=c.root_stress, backend=c.backend)  # fmt: skip

    if not run.cycle_key:
        return compute()
    params = {"cycle": run.cycle_key, "root_stress": c.root_stress, "backend": c.backend}
    members, _ = cached_object("member_fields", params, compute, FIELD_CLASSES)
    return tuple(members)


def _ltca_options(case: GearCase, workers: int | None) -> LTCAOptions:
    """The :class:`~fegear.ltca.analysis.LTCAOptions` of a case."""
    return LTCAOptions(
        n_positions=case.n_positions,
        level=case.level,
        n_teeth=case.n_teeth,
        E_MPa=case.E_MPa,
        nu=case.nu,
        backend=case.backend,
        fidelity=case.fidelity,
        workers=workers,
        **case.contact.as_dict(),
    )


def _ellipses(case: GearCase, tca, positions) -> tuple:
    """The contact ellipses of the TCA positions at the case's load (:mod:`fegear.tca.ellipse`)."""
    T1 = case.pinion_torque_Nm
    return ellipses(positions, tca.asm.axis1(), T1, tca.opt.paint_mm, case.E_MPa, case.nu)


def _loaded_checks(case: GearCase, pair: GearPair, clearance, opt: LTCAOptions):
    """``(tca, positions, engagement)``: the TCA of a loaded run's positions
    (:func:`fegear.ltca.cycle.cycle_tca`) and the engagement checks on them, both kept in the
    cache."""
    tca, positions, _ = cycle_tca(pair.pinion, pair.gear, pair.assembly, opt)
    eng = check_engagement(case, pair, tca, positions, clearance, opt.workers)
    return tca, positions, eng


def check_case(case: GearCase, workers: int | None = 1) -> Engagement | None:
    """What :func:`run_gear_case` decides about ``case`` before any FE work: the pair built,
    the tip clearance checked and, for a loaded fidelity, the TCA of the positions and the
    engagement checks (:func:`fegear.pipeline.engagement.check_engagement`); returns their
    :class:`~fegear.pipeline.engagement.Engagement` (None for the ``tca`` fidelity, whose run
    is this work).

    The TCA and the checks are kept in the artefact cache, so a run of the same case
    afterwards reads them (a sweep prepares its later items this way while its first item
    builds the models: :mod:`fegear.sweep.run`).

    Raises
    ------
    InputError
        As :func:`run_gear_case`: bad design data, or an installation under which the flanks
        cannot mesh.
    """
    pair = build_pair(case)
    clearance = check_clearance(case, pair)
    if case.fidelity == UNLOADED:
        return None
    return _loaded_checks(case, pair, clearance, _ltca_options(case, workers))[2]


def _ease_off(pair: GearPair, asm: Assembly, seconds: dict[str, float]) -> PairEaseOff:
    """The ease-off of ``pair`` in ``asm`` (:func:`fegear.tca.ease_off_pair.pair_ease_off`,
    from the cache when made before), its wall time put in ``seconds``."""
    t0 = time.perf_counter()
    e = pair_ease_off(pair.pinion, pair.gear, asm)
    seconds["ease_off"] = time.perf_counter() - t0
    return e


def _run_gear_case(case, fidelity, level, progress, pair, workers, notify, fields, reuse):
    case = _override(case, fidelity, level)
    say = progress or (lambda stage, i, n: None)
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    say("geometry", None, None)
    pair = pair if pair is not None else build_pair(case)
    clearance = check_clearance(case, pair)  # interference: refused before any TCA
    seconds["geometry"] = time.perf_counter() - t0

    if case.fidelity == UNLOADED:
        t0 = time.perf_counter()
        say("tca", None, None)
        opt = TCAOptions(n_positions=case.n_positions, E_MPa=case.E_MPa, nu=case.nu,
                         pinion_torque_Nm=case.pinion_torque_Nm)  # fmt: skip
        n = case.n_positions
        phi1 = -np.pi / pair.assembly.n1 + 2 * np.pi / pair.assembly.n1 * np.arange(n) / n
        tca, positions, _ = cached_tca(pair.pinion, pair.gear, pair.assembly, opt, phi1, workers)
        eng = check_engagement(case, pair, tca, positions, clearance, workers)
        for w in eng.warnings:
            (notify or log.warning)(w)
        r = cycle_result(list(positions), opt.paint_mm, tca)
        ell = _ellipses(case, tca, positions)
        seconds["tca"] = time.perf_counter() - t0
        return GearRun(
            case=case, pair=pair, assembly=tca.asm, tca=r, seconds=seconds, engagement=eng,
            ellipses=ell, ease_off=_ease_off(pair, tca.asm, seconds),
        )  # fmt: skip

    opt = _ltca_options(case, workers)
    t0 = time.perf_counter()
    tca, positions, eng = _loaded_checks(case, pair, clearance, opt)  # before the FE work
    ell = _ellipses(case, tca, positions)
    for w in eng.warnings:
        (notify or log.warning)(w)
    seconds["checks"] = time.perf_counter() - t0

    def solve() -> LoadedCycle:
        t0 = time.perf_counter()
        say("models", None, None)
        models = build_models(pair.pinion, pair.gear, pair.assembly, opt)
        seconds["models"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        say("positions", 0, case.n_positions)
        cycle = run_ltca(
            pair.pinion,
            pair.gear,
            pair.assembly,
            case.torque2_Nmm,
            opt,
            models=models,
            progress=lambda i, n: say("positions", i, n),
        )
        seconds["positions"] = time.perf_counter() - t0
        return cycle

    params = cycle_params(pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, opt)
    cycle, key, hit = cached_cycle(params, solve, reuse)
    if hit:  # every position read back: no models, no solve
        seconds["cycle_read"] = cycle.seconds["read"]
        say("cached", None, None)
    asm = pair.assembly.with_phase2(cycle.phase2)  # the phase run_ltca closed the pair with
    eo = _ease_off(pair, asm, seconds)
    run = GearRun(case=case, pair=pair, assembly=asm, cycle=cycle, seconds=seconds, engagement=eng,
                  ellipses=ell, cycle_key=key if reuse else "", ease_off=eo)  # fmt: skip
    if fields or case.root_stress:  # else the numbers only: the fields when written
        return with_fields(run, say)
    return run
