"""Load a case and run it (:func:`load_case`, :func:`run`): the entry points of the Python API
and of ``fegear run``."""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from pathlib import Path

from fegear.api.gear_result import GearResult, gear_result
from fegear.api.hertz_scene_result import HertzResult, run_hertz
from fegear.case_files import load_case as _load_case
from fegear.errors import InputError
from fegear.io.gear_case import ANALYSIS, FIDELITIES, N_LEVELS, GearCase
from fegear.output.gear_output import flank_views
from fegear.pipeline.pair import build_pair
from fegear.pipeline.run import run_gear_case
from fegear.scenes.hertz_case import HertzCase
from fegear.store.cache import cache_root, check_cache_root
from fegear.store.files import clean_stale_temps

__all__ = ["Progress", "load_case", "run"]

log = logging.getLogger(__name__)

#: ``progress(stage, i, n)``: called at the start of each stage (``i = n = None``; gear pairs:
#: ``"geometry"``, ``"tca"`` or ``"models"``, ``"positions"`` (or ``"cached"``: the loaded cycle
#: of the same run read back), ``"displacements"``; the Hertz
#: scene: ``"study"`` with ``i`` of ``n`` levels, ``"run"``) and after each mesh position
#: (``"positions"``, ``i`` of ``n``).
Progress = Callable[[str, "int | None", "int | None"], None]


def load_case(path: str | Path) -> GearCase | HertzCase:
    """Read and validate a case file (TOML).

    Parameters
    ----------
    path
        The case file.

    Returns
    -------
    GearCase or HertzCase
        A gear pair (``kind`` ``"face_gear"``, ``"spur"``, ``"cylindrical"``, ``"spiral_bevel"``,
        ``"hypoid"``) or the Hertz scene (``"hertz_scene"``).

    Raises
    ------
    InputError
        A missing or unreadable file, or any problem of its content, naming the case-file
        field, the value and the allowed range.
    """
    return _load_case(path)


_CLEANED: set[str] = set()


def _clean_cache_temps() -> None:
    """Remove the temporary files that interrupted writes left in the artefact cache
    (:func:`fegear.store.files.clean_stale_temps`: their writer is gone), once per process and
    cache folder."""
    root = cache_root()
    if str(root) in _CLEANED:
        return
    _CLEANED.add(str(root))
    gone = clean_stale_temps(root, recursive=True)
    if gone:
        log.info("removed %d temporary files of interrupted writes from %s", len(gone), root)


def run(
    case: GearCase | HertzCase,
    *,
    fidelity: str | None = None,
    level: int | None = None,
    workers: int | None = None,
    backend: str | None = None,
    root_stress: bool | None = None,
    study: Sequence[int] | None = None,
    progress: Progress | None = None,
    notify: Callable[[str], None] | None = None,
    fields: bool = True,
    reuse: bool = True,
) -> GearResult | HertzResult:
    """Run a case.

    Parameters
    ----------
    case
        From :func:`load_case` (or its ``replace``/``with_errors``).
    fidelity
        Overrides the case's. Gear pairs: ``"hybrid"`` (FE + half-space near field, the
        default of every case), ``"fe"``, ``"hertz"`` (per-pair Hertz + lumped FE compliance),
        ``"tca"`` (unloaded, rigid: TE, contact path, pattern; seconds). Hertz scene: ``"fe"``
        or ``"hybrid"``.
    level
        Mesh level, 0 (coarsest) … 4; overrides the case's.
    workers
        Gear pairs: processes solving the mesh positions (None: ``$FEGEAR_WORKERS``, else one
        per core), and drawing the pictures beside the VTK files in the result's ``write``
        (with two or more); the result does not depend on it. Ignored by the Hertz scene.
    backend
        Sparse direct solver ``"auto"``, ``"pardiso"``, ``"superlu"``; overrides the case's.
    root_stress
        Gear pairs at ``fe``/``hybrid``: compute the tooth root stress (the sectors remeshed
        with refined fillets and solved once more per member: on the seed face gear about
        2 min and 5 GB more, ``benchmarks/results/root_stress_cost.md``); overrides
        ``[analysis] root_stress`` (default False).
    study
        Hertz scene: levels of a mesh-convergence study (overrides ``[study] levels``).
    progress
        ``progress(stage, i, n)`` (:data:`Progress`).
    notify
        Gear pairs: ``notify(text)`` with each warning of the engagement checks as soon as it is
        made, before the loaded analysis (they are in the result's ``warnings`` too; without
        ``notify`` they are logged).
    fields
        Gear pairs at ``fe``/``hybrid``: compute the sectors' displacement fields (the VTK
        files; one sparse factorisation per member and process, then a solve per run). False:
        the numbers only, for a study that reads numbers (every number of the result but the
        ``mesh`` sizes of the fields, which stay empty); :meth:`GearResult.write` then computes
        the fields it writes (the same ones). ``root_stress`` computes them always.
    reuse
        Gear pairs at a loaded fidelity: read the positions (and the fields) of a run made
        before with the same inputs from the cache (``docs/ltca/studies.md``); False: solve
        them again.

    Returns
    -------
    GearResult or HertzResult
        By the kind of the case.

    Raises
    ------
    InputError
        A bad override, design data the geometry refuses, or an installation under which the
        flanks cannot mesh (no contact anywhere, a tip running into the mate's root), each named
        and decided before the FE work; an unusable cache folder (``FEGEAR_CACHE``).
    FegearError
        The analysis failed (mesh, solver).
    """
    check_cache_root()
    _clean_cache_temps()
    if isinstance(case, HertzCase):
        if root_stress:
            raise InputError("root_stress", root_stress, "absent for the Hertz scene (no teeth)")
        return run_hertz(case, fidelity, level, backend, study, progress)
    if not isinstance(case, GearCase):
        raise InputError("case", type(case).__name__, "a case from fegear.load_case")
    from dataclasses import replace

    if study is not None:
        raise InputError("study", study, "absent for a gear case (a Hertz-scene option)")
    if backend is not None:
        ANALYSIS.key("backend").check("backend", backend)  # the case file's rule
        case = replace(case, backend=backend)
    if root_stress is not None:
        if not isinstance(root_stress, bool):
            raise InputError("root_stress", root_stress, "True or False")
        case = replace(case, root_stress=root_stress)
    fid = case.fidelity if fidelity is None else fidelity
    lvl = case.level if level is None else level
    if fid not in FIDELITIES:
        raise InputError("fidelity", fid, "'fe', 'hertz', 'hybrid' or 'tca' for gear pairs")
    if not (isinstance(lvl, int) and not isinstance(lvl, bool) and 0 <= lvl < N_LEVELS):
        raise InputError("level", lvl, f"an integer in [0, {N_LEVELS - 1}]")
    if workers is not None and not (isinstance(workers, int) and workers >= 1):
        raise InputError("workers", workers, "an integer >= 1")
    if not isinstance(reuse, bool):
        raise InputError("reuse", reuse, "True or False")
    pair = build_pair(case)  # bad design data is refused here, before any work
    gear_run = run_gear_case(
        case,
        fidelity=fid,
        level=lvl,
        progress=progress,
        pair=pair,
        workers=workers,
        notify=notify,
        fields=fields,
        reuse=reuse,
    )
    return gear_result(gear_run, flank_views(gear_run), workers)
