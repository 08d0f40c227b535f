"""Sweeps: several gear cases, or one case over a parameter grid, each item a normal run.

A sweep is a list of :class:`SweepItem` (a validated :class:`~fegear.io.gear_case.GearCase` with
a name and the grid values that made it). :func:`run_sweep` runs every item in its own folder
``out/<item>/`` with the outputs of ``fegear run`` (summary.json, VTK + .pvd, PNG), on local
processes (:class:`concurrent.futures.ProcessPoolExecutor`) or on a Dask distributed cluster, and
writes the sweep outputs (:mod:`fegear.sweep.output`: ``sweep.json``, ``comparison.md``,
``te_overlay.png``).

Grid specification (``KEY=START:STOP:N`` or ``KEY=V1,V2,...``): ``KEY`` is a case-file key
``section.key`` (``errors.dgamma_deg``, ``load.torque2_Nm``, ``pair.module_mm``, ...). Every grid
point is written into a copy of the base case's TOML document and validated by the case-file
parser (:func:`fegear.case_files.parse_case`), so a bad key or value is refused exactly as in a case
file, before any work. A load key replaces the case's torque key (a case has exactly one).
Several grid axes make their Cartesian product.

Robustness (one sweep per output folder at a time; a lock file enforces it on POSIX):

- an item is computed into ``out/.<item>.<id>.tmp/``; its marker ``sweep_item.json`` (inputs
  fingerprint, SHA-256 of the item's summary.json) is written last, then the folder is renamed
  into place (atomic on one file system). A folder ``out/<item>/`` is trusted only with a marker
  whose fingerprint matches the item (case data, fidelity, level, fegear version) and a
  summary.json that still has the recorded SHA-256 and parses (:func:`verified_summary`: checked
  when the sweep starts and again when the comparison reads it); otherwise the item is
  recomputed and the folder replaced.
- the comparison's reference item (``--nominal``, else the first item without installation
  errors, else the first item) is fixed by the items, not by which ones finished: if it has no
  valid results the comparison is an error (``SweepResult.comparison_error``, exit code 1),
  never a silent substitute.
- a re-run skips finished items, recomputes the others and removes leftover ``*.tmp`` folders of
  an interrupted run.
- an item that fails is reported with its one-line error and does not stop the others.

Dask: the workers need fegear installed and must see ``out`` and the mesh/operator cache
(:func:`fegear.store.cache.cache_root`: ``$FEGEAR_CACHE``, else the per-user cache folder) at the
same paths as the client (a shared file system; a ``LocalCluster`` trivially does).
"""

from __future__ import annotations

import contextlib
import copy
import functools
import itertools
import logging
import math
import os
import re
import shutil
import time
import tomllib
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from fegear import __version__
from fegear.case_files import load_case, parse_case
from fegear.errors import BackendUnavailable, FegearError, InputError
from fegear.forked import process_count
from fegear.io.gear_case import FIDELITIES, GEAR_KINDS, N_LEVELS, GearCase
from fegear.output.gear_output import write_gear_outputs
from fegear.pipeline.run import check_case, run_gear_case
from fegear.store.cache import cache_root as _cache_root
from fegear.store.cache import content_hash
from fegear.store.files import write_json
from fegear.sweep.local import run_local
from fegear.sweep.marker import MARKER, digest, read_marker, verified_summary
from fegear.sweep.output import comparison_error, write_sweep_json, write_sweep_outputs
from fegear.units import TORQUE_KEYS

__all__ = [
    "GridAxis",
    "SweepItem",
    "ItemResult",
    "SweepResult",
    "parse_grid",
    "build_items",
    "run_item",
    "run_sweep",
    "require_dask",
    "is_done",
    "verified_summary",
    "MARKER",
]

log = logging.getLogger(__name__)

#: Name of the per-item marker file, written last inside the item folder.
_MAX_AXIS = 1000
_MAX_ITEMS = 10000
_NOT_SWEEPABLE = ("case",)  # kind / name / description of the base case stay as they are

Value = int | float | str
Progress = Callable[["ItemResult", int, int], None]


# --------------------------------------------------------------------------------------------
# Items
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class GridAxis:
    """One axis of a parameter grid.

    Attributes
    ----------
    key
        Case-file key ``"section.key"``.
    values
        The values, in order.
    spec
        The specification as given (for messages).
    """

    key: str
    values: tuple[Value, ...]
    spec: str

    @property
    def short(self) -> str:
        """The key without its section (``"dgamma_deg"``), used in item names."""
        return self.key.split(".", 1)[1]


@dataclass(frozen=True)
class SweepItem:
    """One run of a sweep.

    Attributes
    ----------
    name
        Item name, also its folder name and the ``case`` of its summary.json.
    case
        The validated case, fidelity and level overrides applied.
    params
        ``{case-file key: value}`` of the grid point (empty for a sweep over case files).
    base
        Name of the base case.
    """

    name: str
    case: GearCase
    params: dict[str, Value] = field(default_factory=dict)
    base: str = ""

    def fingerprint(self) -> str:
        """Hash of everything the item's results depend on (the file it came from excluded)."""
        inputs = self.case.to_dict()
        inputs.pop("source", None)
        return content_hash({"inputs": inputs, "fegear": __version__})


@dataclass(frozen=True)
class ItemResult:
    """What became of one item.

    Attributes
    ----------
    name
        Item name.
    status
        ``"done"`` (computed now), ``"skipped"`` (finished by an earlier run), ``"failed"``.
    seconds
        Wall time of the item (0 when skipped).
    error
        One-line error of a failed item, else ``""``.
    """

    name: str
    status: str
    seconds: float = 0.0
    error: str = ""


@dataclass(frozen=True)
class SweepResult:
    """A finished (or partly failed) sweep.

    Attributes
    ----------
    out
        The sweep folder.
    items
        The items, in sweep order.
    results
        ``{item name: ItemResult}``.
    files
        The sweep outputs written (sweep.json, comparison.md, te_overlay.png).
    seconds
        Wall time of the sweep.
    comparison_error
        Why the comparison could not be made ("" if it was): its reference item has no valid
        results.
    """

    out: Path
    items: tuple[SweepItem, ...]
    results: dict[str, ItemResult]
    files: tuple[Path, ...] = ()
    seconds: float = 0.0
    comparison_error: str = ""

    @property
    def n_failed(self) -> int:
        return sum(r.status == "failed" for r in self.results.values())


def _literal(text: str) -> Value:
    t = text.strip()
    try:
        return int(t)
    except ValueError:
        pass
    try:
        v = float(t)
    except ValueError:
        return t.strip("'\"")
    return v


def _tidy(v: float) -> float:
    """Round linspace noise away (``0.020000000000000004`` → ``0.02``), no ``-0.0``."""
    return float(f"{v:.12g}") + 0.0


def parse_grid(spec: str) -> GridAxis:
    """Parse ``KEY=START:STOP:N`` (``N`` values, ends included) or ``KEY=V1,V2,...``.

    Parameters
    ----------
    spec
        The specification, e.g. ``"errors.dgamma_deg=-0.04:0.04:5"``.

    Raises
    ------
    InputError
        Malformed specification (the key and values are checked by :func:`build_items`).
    """
    fld = "--grid"
    if "=" not in spec:
        raise InputError(fld, spec, "KEY=START:STOP:N or KEY=V1,V2,... (no '=' given)")
    key, _, rhs = spec.partition("=")
    key = key.strip()
    sec, dot, name = key.partition(".")
    if not dot or not sec or not name or "." in name:
        raise InputError(fld, spec, "a case-file key 'section.key' before '=' (errors.dgamma_deg)")
    if sec in _NOT_SWEEPABLE:
        raise InputError(fld, spec, f"a key outside [{sec}] (the case identity is not swept)")
    rhs = rhs.strip()
    if not rhs:
        raise InputError(fld, spec, "values after '=' (START:STOP:N or V1,V2,...)")
    if ":" in rhs:
        parts = rhs.split(":")
        if len(parts) != 3:
            raise InputError(fld, spec, "START:STOP:N (three fields)")
        try:
            start, stop = float(parts[0]), float(parts[1])
        except ValueError as exc:
            raise InputError(fld, spec, "START and STOP numbers") from exc
        try:
            n = int(parts[2])
        except ValueError as exc:
            raise InputError(fld, spec, "N an integer (the number of values)") from exc
        if not (math.isfinite(start) and math.isfinite(stop)):
            raise InputError(fld, spec, "finite START and STOP")
        if not 1 <= n <= _MAX_AXIS or (n == 1 and start != stop):
            raise InputError(fld, spec, f"N in [2, {_MAX_AXIS}] (or 1 with START = STOP)")
        raw = [start + (stop - start) * i / (n - 1) for i in range(n)] if n > 1 else [start]
        values: list[Value] = [_tidy(v) for v in raw]
        ints = all(p.strip().lstrip("+-").isdigit() for p in parts[:2])
        if ints and all(float(v).is_integer() for v in values):
            values = [int(v) for v in values]  # integer keys (n_positions, level) stay integers
    else:
        values = [_literal(v) for v in rhs.split(",")]
        if any(v == "" for v in values):
            raise InputError(fld, spec, "comma-separated values without empty entries")
        if len(values) > _MAX_AXIS:
            raise InputError(fld, spec, f"at most {_MAX_AXIS} values")
    if len(set(map(repr, values))) != len(values):
        raise InputError(fld, spec, "distinct values")
    return GridAxis(key=key, values=tuple(values), spec=spec)


def _read_toml(path: Path) -> dict[str, Any]:
    """The raw TOML document of a case file (the errors are those of :func:`load_case`)."""
    load_case(path)  # every problem of the file itself: one InputError, as for `fegear run`
    return tomllib.loads(Path(path).read_text(encoding="utf-8-sig"))


def _fmt(v: Value) -> str:
    """A value as it appears in an item's name (its folder): a number as ``%g``; text with every
    character outside ``A-Z a-z 0-9 . _ + -`` as ``_`` (a swept file path, e.g. a
    ``topography.pinion_drive`` grid, holds separators)."""
    if isinstance(v, float):
        return f"{v:g}"
    return re.sub(r"[^A-Za-z0-9._+-]", "_", str(v))


def _check_overrides(fidelity: str | None, level: int | None) -> None:
    if fidelity is not None and fidelity not in FIDELITIES:
        raise InputError("--fidelity", fidelity, f"one of {FIDELITIES} for gear pairs")
    if level is not None and not 0 <= level < N_LEVELS:
        raise InputError("--level", level, f"an integer in [0, {N_LEVELS - 1}]")


def _apply(case: GearCase, fidelity: str | None, level: int | None) -> GearCase:
    return replace(
        case,
        fidelity=case.fidelity if fidelity is None else fidelity,
        level=case.level if level is None else level,
    )


def _from_grid(exc: InputError, axes: Sequence[GridAxis]) -> InputError:
    """The parser's error with the grid specification that caused it appended."""
    spec = next(
        (a.spec for a in axes if exc.field == a.key or a.key.startswith(exc.field + ".")), None
    )
    where = f"--grid {spec}" if spec else "from --grid " + " ".join(a.spec for a in axes)
    base = f"{exc.field} = {exc.value!r} is not allowed: must be {exc.allowed}"
    text = str(exc)
    detail = text[len(base) :].strip()[1:-1] if text.startswith(base) else ""
    return type(exc)(exc.field, exc.value, exc.allowed, f"{detail}; {where}" if detail else where)


def require_dask() -> None:
    """Raise :class:`~fegear.errors.BackendUnavailable` unless Dask distributed is importable."""
    try:
        import distributed  # noqa: F401
    except ImportError as exc:
        raise BackendUnavailable(
            "--scheduler needs Dask: pip install 'fegear[dask]' (dask[distributed])"
        ) from exc


def build_items(
    cases: Sequence[str | Path],
    grid: Sequence[str | GridAxis] = (),
    fidelity: str | None = None,
    level: int | None = None,
) -> tuple[SweepItem, ...]:
    """The items of a sweep: every case × every point of the grid.

    Parameters
    ----------
    cases
        Case files (TOML) of gear pairs.
    grid
        Grid axes (:class:`GridAxis` or their specification strings); their product is applied
        to every case.
    fidelity, level
        Overrides of the cases' ``[analysis]`` values.

    Returns
    -------
    tuple of SweepItem
        In order: cases, then the grid points (the last axis varying fastest).

    Raises
    ------
    InputError
        A bad case file, grid specification, key or value (named as in the case file, with the
        grid specification it came from), duplicate item names, or bad overrides.
    """
    _check_overrides(fidelity, level)
    if not cases:
        raise InputError("CASE", "none", "at least one case file")
    axes = [g if isinstance(g, GridAxis) else parse_grid(g) for g in grid]
    keys = [a.key for a in axes]
    if len(set(keys)) != len(keys):
        dup = next(k for k in keys if keys.count(k) > 1)
        raise InputError("--grid", dup, "each key at most once")
    n_points = math.prod(len(a.values) for a in axes) if axes else 1
    if n_points * len(cases) > _MAX_ITEMS:
        raise InputError("--grid", f"{n_points * len(cases)} items", f"at most {_MAX_ITEMS}")
    items: list[SweepItem] = []
    for path in cases:
        data = _read_toml(Path(path))
        kind = data.get("case", {}).get("kind")
        if kind not in GEAR_KINDS:
            raise InputError("case.kind", kind, f"a gear pair, one of {GEAR_KINDS}", str(path))
        base = parse_case(data, source=str(path))
        if not axes:
            items.append(SweepItem(base.name, _apply(base, fidelity, level), {}, base.name))
            continue
        for point in itertools.product(*(a.values for a in axes)):
            doc = copy.deepcopy(data)
            params = dict(zip(keys, point, strict=True))
            name = base.name + "".join(
                f"__{a.short}={_fmt(v)}" for a, v in zip(axes, point, strict=True)
            )
            for a, v in zip(axes, point, strict=True):
                sec, key = a.key.split(".", 1)
                table = doc.setdefault(sec, {})
                if not isinstance(table, dict):
                    raise InputError(sec, table, f"a TOML table [{sec}]", f"--grid {a.spec}")
                if sec == "load" and key in TORQUE_KEYS:
                    for other in TORQUE_KEYS:  # the swept torque replaces the case's torque
                        table.pop(other, None)
                table[key] = v
            doc["case"]["name"] = name
            try:
                case = parse_case(doc, source=str(path))
            except InputError as exc:
                raise _from_grid(exc, axes) from exc
            items.append(SweepItem(name, _apply(case, fidelity, level), params, base.name))
    names = [it.name for it in items]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise InputError("CASE", dup, "distinct case names (each item needs its own folder)")
    return tuple(items)


# --------------------------------------------------------------------------------------------
# One item (runs in a worker process or on a Dask worker)
# --------------------------------------------------------------------------------------------


def is_done(folder: Path, item: SweepItem) -> bool:
    """Whether ``folder`` holds the finished, complete results of ``item``: a marker with its
    fingerprint and a summary.json that is the one the marker vouches for
    (:func:`verified_summary`)."""
    m = read_marker(folder)
    return (
        m is not None
        and m.get("fingerprint") == item.fingerprint()
        and verified_summary(folder) is not None
    )


def _rmtree(path: Path) -> None:
    shutil.rmtree(path, ignore_errors=True)


def _commit(tmp: Path, final: Path, item: SweepItem) -> None:
    """Rename the finished ``tmp`` folder to ``final`` (replacing a stale ``final``)."""
    try:
        os.rename(tmp, final)  # atomic; fails if ``final`` exists and is not empty
        return
    except OSError:
        if not final.exists():
            raise
    if is_done(final, item):  # the same item finished elsewhere meanwhile (a Dask retry)
        _rmtree(tmp)
        return
    trash = final.with_name(f".{final.name}.{uuid.uuid4().hex[:8]}.old.tmp")
    os.rename(final, trash)
    os.rename(tmp, final)
    _rmtree(trash)


def _one_line(exc: BaseException) -> str:
    msg = " ".join(str(exc).split()) or type(exc).__name__
    if isinstance(exc, FegearError):
        return msg
    return f"{type(exc).__name__}: {msg}"


def run_item(
    item: SweepItem,
    out: str | Path,
    cache_root: str | None = None,
    position_workers: int | None = 1,
) -> ItemResult:
    """Run one item into ``out/<item.name>/`` atomically (the worker's entry point).

    Never raises for a failure of the analysis: the result carries the one-line error. An item
    already finished (:func:`is_done`) is skipped.

    Parameters
    ----------
    item
        The item.
    out
        The sweep folder (absolute on a cluster).
    cache_root
        Mesh/operator cache folder (``$FEGEAR_CACHE``) to use in this worker.
    position_workers
        Processes for the item's mesh positions (:mod:`fegear.ltca.cycle`) and, with two or
        more, its pictures drawn beside its VTK files: the cores left to each item by the
        sweep's own workers (1 on a Dask cluster; None: ``$FEGEAR_WORKERS``
        or one per core).
    """
    out = Path(out)
    final = out / item.name
    if is_done(final, item):
        return ItemResult(item.name, "skipped")
    if cache_root:
        os.environ["FEGEAR_CACHE"] = cache_root
    t0 = time.perf_counter()
    tmp = out / f".{item.name}.{uuid.uuid4().hex[:8]}.tmp"
    try:
        tmp.mkdir(parents=True)
        run = run_gear_case(item.case, workers=position_workers, fields=False)
        # the fields and VTK files here while the pictures are drawn in a forked process
        write_gear_outputs(tmp, run, workers=position_workers)
        seconds = time.perf_counter() - t0
        write_json(
            tmp / MARKER,
            {
                "name": item.name,
                "base_case": item.base,
                "params": item.params,
                "fingerprint": item.fingerprint(),
                "summary_sha256": digest(tmp / "summary.json"),
                "fegear": __version__,
                "seconds": seconds,
                "finished_unix": time.time(),
            },
        )  # the marker last: a folder with it is complete
        _commit(tmp, final, item)
    except Exception as exc:  # noqa: BLE001  (one item's failure never stops the sweep)
        _rmtree(tmp)
        log.warning("item %s failed: %s", item.name, _one_line(exc))
        return ItemResult(item.name, "failed", time.perf_counter() - t0, _one_line(exc))
    log.info("item %s done in %.1f s", item.name, seconds)
    return ItemResult(item.name, "done", seconds)


# --------------------------------------------------------------------------------------------
# The sweep
# --------------------------------------------------------------------------------------------


@contextlib.contextmanager
def _lock(out: Path) -> Iterator[None]:
    """An exclusive lock on ``out`` (POSIX ``flock``; released when the process dies)."""
    try:
        import fcntl
    except ImportError:  # Windows: no lock
        yield
        return
    with open(out / ".sweep.lock", "w") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError as exc:
            raise FegearError(f"another sweep is writing to {out}/ (lock .sweep.lock)") from exc
        except OSError as exc:  # a file system without locks (some network mounts)
            log.warning("cannot lock %s (%s): running unlocked", out, exc)
            yield
            return
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def _clean_tmp(out: Path) -> list[str]:
    """Remove the ``.*.tmp`` folders of an interrupted run, and the temporary files of its
    interrupted atomic writes (``.sweep.<random>.json`` and the like, left when the run was
    killed between writing and renaming; the caller holds the sweep's lock, so no writer is
    alive); returns their names."""
    gone = []
    for p in out.glob(".*.tmp"):
        if p.is_dir():
            _rmtree(p)
            gone.append(p.name)
    for p in out.glob(".*.*"):
        if p.is_file() and p.name != ".sweep.lock":
            p.unlink()
            gone.append(p.name)
    return gone


def _dask_client(address: str):
    require_dask()
    from distributed import Client

    try:
        return Client(address, timeout=15, set_as_default=False)
    except Exception as exc:  # noqa: BLE001  (OSError, TimeoutError, bad address)
        raise FegearError(
            f"cannot reach the Dask scheduler at {address!r}: {_one_line(exc)}"
        ) from exc


def run_sweep(
    items: Sequence[SweepItem],
    out: str | Path,
    workers: int | None = None,
    scheduler: str | None = None,
    nominal: str | None = None,
    progress: Progress | None = None,
) -> SweepResult:
    """Run the items (skipping finished ones) and write the sweep outputs.

    Parameters
    ----------
    items
        From :func:`build_items`.
    out
        Sweep folder; item ``k`` goes to ``out/<name>/``.
    workers
        Items computed side by side on this machine (ignored with ``scheduler``): all items
        run in one worker process that keeps the models, the first alone on every core, the
        others ``workers`` at a time in processes forked from it (:mod:`fegear.sweep.local`);
        None: ``$FEGEAR_WORKERS``, else one per core. The items' results do not depend on it.
    scheduler
        Address of a Dask distributed scheduler (``tcp://host:8786``); Dask is imported only
        then.
    nominal
        Name of the reference item of the comparison (default: the first item without
        installation errors, else the first item).
    progress
        ``progress(result, k, n)`` after each item (``k`` = items finished so far).

    Raises
    ------
    InputError
        Bad ``workers`` or ``nominal``.
    BackendUnavailable
        ``scheduler`` given without Dask installed.
    FegearError
        The scheduler cannot be reached, or another sweep holds the folder.
    """
    items = tuple(items)
    if workers is not None and not (isinstance(workers, int) and workers >= 1):
        raise InputError("--workers", workers, "an integer >= 1")
    workers = process_count(workers, max(len(items) - 1, 1))
    names = [it.name for it in items]
    if nominal is not None and nominal not in names:
        raise InputError("--nominal", nominal, f"one of the item names {names}")
    out = Path(out).resolve()
    out.mkdir(parents=True, exist_ok=True)

    # the workers (local processes or Dask) must use this process's cache, wherever they run
    cache_root = str(_cache_root().resolve())
    say = progress or (lambda r, k, n: None)
    t0 = time.perf_counter()
    results: dict[str, ItemResult] = {}
    meta = {"workers": workers, "scheduler": scheduler, "nominal": nominal}
    with _lock(out):
        gone = _clean_tmp(out)
        if gone:
            log.info("removed %d unfinished item folder(s) of an earlier run: %s", len(gone), gone)
        todo = []
        for it in items:
            if is_done(out / it.name, it):
                results[it.name] = ItemResult(it.name, "skipped")
                say(results[it.name], len(results), len(items))
            else:
                todo.append(it)
        write_sweep_json(out, items, results, meta)
        if todo:
            for r in _execute(todo, out, workers, scheduler, cache_root):
                results[r.name] = r
                say(r, len(results), len(items))
                write_sweep_json(out, items, results, meta)
        files = write_sweep_outputs(out, items, results, meta)
        cmp_error = comparison_error(out, items, results, meta)
    return SweepResult(
        out, items, results, tuple(files), time.perf_counter() - t0, comparison_error=cmp_error
    )


def _execute(
    todo: list[SweepItem], out: Path, workers: int, scheduler: str | None, cache_root: str
) -> Iterator[ItemResult]:
    """Yield the result of each item as it finishes."""
    if scheduler is not None:
        client = _dask_client(scheduler)
        try:
            from distributed import as_completed as dask_completed

            futs = {
                client.submit(
                    run_item, it, str(out), cache_root, key=f"fegear-{it.name}-{uuid.uuid4().hex}",
                    pure=False,
                ): it
                for it in todo
            }  # fmt: skip
            for fut in dask_completed(list(futs), loop=client.loop):
                it = futs[fut]
                try:
                    yield fut.result()
                except Exception as exc:  # noqa: BLE001  (worker lost, unpicklable, ...)
                    yield ItemResult(it.name, "failed", 0.0, f"Dask: {_one_line(exc)}")
        finally:
            client.close()
        return
    # one warm worker: the first item alone (the models), the others `workers` at a time
    yield from run_local(
        todo,
        functools.partial(_run_one, str(out), cache_root),
        workers,
        _worker_failed,
        functools.partial(_prepare, cache_root),
    )


def _run_one(out: str, cache_root: str, item: SweepItem, processes: int | None) -> ItemResult:
    """:func:`run_item` as :func:`fegear.sweep.local.run_local` calls it."""
    return run_item(item, out, cache_root, processes)


def _prepare(cache_root: str, item: SweepItem) -> None:
    """An item's checks before its run (:func:`fegear.pipeline.run.check_case`), kept in the
    cache at ``cache_root``."""
    os.environ["FEGEAR_CACHE"] = cache_root
    check_case(item.case, workers=1)


def _worker_failed(item: SweepItem, exc: BaseException) -> ItemResult:
    return ItemResult(item.name, "failed", 0.0, f"worker: {_one_line(exc)}")
