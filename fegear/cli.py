"""The ``fegear`` command.

``fegear run [CASE] [--fidelity F] [--level L] [--out DIR]`` runs a case file and writes its
results (summary.json, VTK + .pvd, PNG) into ``DIR`` (default ``./out``), one run per folder
(:mod:`fegear.store.outputs`: an earlier run's files there are replaced, a folder with other
files needs ``--overwrite``). The case kind decides what runs:

- gear pairs (``face_gear``, ``spur``, ``cylindrical``, ``spiral_bevel``, ``hypoid``): the loaded
  TCA (``--fidelity hybrid``, the default, ``fe`` or ``hertz``) or the unloaded TCA
  (``--fidelity tca``);
- ``hertz_scene``: the FE Hertz check (``--fidelity fe | hybrid``, ``--study``, ``--backend``).

With no CASE it runs the built-in seed face-gear case (``cases/face_gear_nominal.toml``: N2 160,
N1 25, m 6.35 mm, 25°, pinion torque 350.14 N·m, hybrid level 0, 25 positions; under a minute
cold on 2 cores, the sector meshes and compliance operators are then cached).

``fegear sweep CASE... [--grid KEY=START:STOP:N]`` runs several cases or a grid
(:mod:`fegear.sweep`); ``fegear cache info | clear [--kind K]`` shows or empties the
mesh/operator cache (:mod:`fegear.store.cache`: the per-user cache folder, or ``$FEGEAR_CACHE``);
``fegear plot FOLDER [--member gear|pinion]`` draws the bearing pattern over the cycle on a
member's flank from a run's flank views. ``fegear export-ccx CASE`` writes the case as CalculiX
decks (:mod:`fegear.export.command`). ``fegear accept CASE [--design D] [--p-max-pct X]
[--te-pp-arcsec X] [--khb X] [--allow-edge] [--out DIR]`` runs a measured case and its design
and prints the checks and the verdict (:mod:`fegear.api.acceptance`); its exit code is the
verdict's: 0 ACCEPT, 3 REJECT, 4 UNDECIDED (1 and 2 as for every command).

The command is a layer over the Python API (:mod:`fegear.api`): ``fegear run`` is
``fegear.run(case, ...)`` then ``result.write(out)``, with the progress and the report printed.

Progress goes to stderr (stages and positions); ``-q`` keeps only warnings and errors. Warnings
that change the meaning of a headline (positions left out of the TE peak-to-peak, a p_max not
reported, a contact ratio below 1, contact lost, ``fe`` cells wider than the patch) are printed
as ``warning: ...`` lines, also with ``-q``. Bad input, including an installation that cannot
mesh (no contact anywhere, tip/root interference) and an output folder that cannot be written,
ends with a one-line message and exit code 2 before the analysis; a failure of the analysis with
exit code 1.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import re
import sys
import time
from pathlib import Path

from fegear import __version__
from fegear.errors import FegearError, InputError
from fegear.export.command import add_parser as add_export
from fegear.export.command import run as export_ccx
from fegear.export.settings import add_parser as add_settings
from fegear.export.settings import run as print_settings
from fegear.forked import process_count
from fegear.store.cache import cache_info, check_cache_root, clear_cache
from fegear.store.files import check_writable_folder, journal
from fegear.store.outputs import MANIFEST, inspect_output_folder, run_files

__all__ = ["main", "parser"]


def parser() -> argparse.ArgumentParser:
    """The command's argument parser (also what checks the command lines of the docs)."""
    return _parser()


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="fegear",
        description="Finite-element loaded tooth contact "
        "analysis. Run a case and write summary.json, VTK and PNG.",
    )
    p.add_argument("--version", action="version", version=f"fegear {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run a case file (default: the seed face-gear case)")
    r.add_argument("case", nargs="?", help="case file (TOML); default: the seed face-gear case")
    r.add_argument("--level", type=int, help="mesh level (0 = coarsest); overrides the case")
    r.add_argument("--out", default="out", help="output folder (default: ./out)")
    r.add_argument("--study", help="comma-separated levels for a mesh-convergence study")
    r.add_argument(
        "--backend",
        choices=["auto", "pardiso", "superlu"],
        help="sparse direct solver; overrides the case",
    )
    r.add_argument(
        "--fidelity",
        help="gear pairs: hybrid (FE + half-space near field, resolves the patch; the default) | "
        "fe (pure FE; its cells are wider than the patch at practical levels) | hertz (per-pair "
        "Hertz + lumped FE compliance) | tca (unloaded, rigid); "
        "Hertz scene: fe | hybrid (coarse FE + half-space near field)",
    )
    r.add_argument(
        "--workers",
        type=int,
        help="gear pairs: processes solving the mesh positions, and with two or more the "
        "pictures drawn beside the VTK files (default: one per core); the result does not "
        "depend on it",
    )
    r.add_argument(
        "--root-stress",
        action="store_true",
        default=None,
        help="gear pairs at fe/hybrid: also the tooth root stress (the sectors remeshed with "
        "refined fillets, one more factorisation per member: minutes and GB on large "
        "sectors); overrides the case's [analysis] root_stress",
    )
    r.add_argument(
        "--recompute",
        action="store_true",
        help="gear pairs: solve the mesh positions again even if the same run (same case, "
        "fidelity, level and code) is in the cache",
    )
    r.add_argument(
        "--overwrite",
        action="store_true",
        help="write into an output folder that holds files fegear did not write (they are "
        "kept); a folder of an earlier fegear run needs no flag (its files are replaced)",
    )
    r.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")
    s = sub.add_parser(
        "sweep",
        help="run several gear cases, or one case over a parameter grid, each in its own folder",
    )
    s.add_argument("case", nargs="+", help="gear case files (TOML)")
    s.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="KEY=START:STOP:N",
        help="a case-file key and its values (KEY=START:STOP:N or KEY=V1,V2,...), e.g. "
        "errors.dgamma_deg=-0.04:0.04:5 or load.torque2_Nm=100:400:4; repeat for a product",
    )
    s.add_argument("--out", default="sweep", help="sweep folder (default: ./sweep)")
    s.add_argument(
        "--fidelity",
        help="hybrid (the default of every case) | fe | hertz | tca (unloaded, rigid); "
        "overrides the cases",
    )
    s.add_argument("--level", type=int, help="mesh level (0 = coarsest); overrides the cases")
    s.add_argument(
        "--workers",
        type=int,
        help="items computed side by side after the first, in processes sharing its models "
        "(default: one per core, $FEGEAR_WORKERS); the results do not depend on it",
    )
    s.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask distributed cluster (e.g. tcp://host:8786) instead of local processes",
    )
    s.add_argument("--nominal", help="reference item of the comparison (default: no errors)")
    s.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")
    c = sub.add_parser(
        "cache",
        help="the mesh/operator cache: where it is and what it holds, or clear it",
        description="The artefact cache (sector meshes, compliance operators, TCA) is in the "
        "per-user cache folder of the platform, or in $FEGEAR_CACHE if set. It keeps itself "
        "within a size cap ($FEGEAR_CACHE_LIMIT, default 10GB; 'none' for no cap) by evicting "
        "its least recently used entries, and verifies every entry it reads (size and "
        "checksum), rebuilding a damaged one.",
    )
    csub = c.add_subparsers(dest="cache_command", required=True)
    csub.add_parser(
        "info", help="where the cache is, its size per kind, its entries and its size cap"
    )
    cc = csub.add_parser("clear", help="delete the cached artefacts (all, or one kind)")
    cc.add_argument("--kind", help="only this kind (a folder name shown by `fegear cache info`)")
    pl = sub.add_parser(
        "plot",
        help="the bearing pattern over the cycle on one member's flank, from a run's folder",
        description="Reads FOLDER/vtk/flank_<member>_*.vtp (fidelity hybrid or fe) and draws the "
        "largest pressure each point of the flank saw over the cycle, with the working-surface "
        "outline, as a PNG.",
    )
    pl.add_argument("folder", help="output folder of `fegear run` (e.g. out)")
    pl.add_argument("--member", choices=["gear", "pinion"], default="gear",
                    help="whose flank (default: gear)")  # fmt: skip
    pl.add_argument("--png", help="the PNG (default: FOLDER/bearing_pattern_<member>_flank.png)")
    pl.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")
    a = sub.add_parser(
        "accept",
        help="is this batch acceptable: a measured case against its design, within tolerances",
        description="Runs a measured case (a case file with a [topography] section) and its "
        "design (the same case without [topography], or --design), compares p_max away from "
        "the edges, the loaded and unloaded TE p-p, KHβ (cylindrical pairs) and edge contact "
        "against the allowed increases, prints the checks and the verdict and writes "
        "acceptance.json. Exit codes: 0 ACCEPT, 3 REJECT, 4 UNDECIDED (a headline not "
        "reported by a run), 2 bad input, 1 the analysis failed.",
    )
    a.add_argument("case", help="the measured case file (TOML, with [topography])")
    a.add_argument("--design", help="the design case file (default: CASE without [topography])")
    a.add_argument(
        "--p-max-pct",
        metavar="X",
        help="allowed increase of p_max away from the edges, %% (default 10)",
    )
    a.add_argument(
        "--te-pp-arcsec",
        metavar="X",
        help="allowed increase of the loaded TE p-p, arcsec (default 1)",
    )
    a.add_argument(
        "--te-pp-pct",
        metavar="X",
        help="allowed increase of the loaded TE p-p, %% (default: not checked)",
    )
    a.add_argument(
        "--te-pp-unloaded-arcsec",
        metavar="X",
        help="allowed increase of the unloaded TE p-p, arcsec (default 1)",
    )
    a.add_argument(
        "--khb", metavar="X", help="allowed increase of KHβ, cylindrical pairs (default 0.1)"
    )
    a.add_argument(
        "--allow-edge",
        action="store_true",
        help="a loaded pair at a flank edge where the design has none does not reject",
    )
    a.add_argument(
        "--fidelity",
        help="hybrid (default: the case's) | fe | hertz | tca (unloaded: "
        "the loaded checks are undecided)",
    )
    a.add_argument("--level", type=int, help="mesh level (0 = coarsest); overrides the cases")
    a.add_argument("--workers", type=int, help="processes solving the mesh positions")
    a.add_argument(
        "--out",
        default="out/acceptance",
        help="folder of acceptance.json (default: ./out/acceptance)",
    )
    a.add_argument("-q", "--quiet", action="store_true", help="only the verdict line")
    add_export(sub)
    add_settings(sub)
    return p


#: API argument -> command-line option (the API names its arguments, the command its options)
_OPTIONS = ("fidelity", "level", "workers", "study", "backend")


def _as_option(exc: InputError) -> InputError:
    """An API argument error renamed to the command-line option (``level`` → ``--level``)."""
    if exc.field in _OPTIONS:
        return type(exc)(f"--{exc.field}", exc.value, exc.allowed, exc.detail)
    return exc


def _run(args: argparse.Namespace) -> int:
    # local: the API and the gear case pull scipy and scikit-fem (~2 s); `fegear --help` does not
    from fegear.api import load_case
    from fegear.io.gear_case import GearCase

    if args.case:
        case = load_case(args.case)
    else:
        from fegear.io.seed import seed_case  # local: scipy, as above

        case = seed_case()
    try:
        if isinstance(case, GearCase):
            return _run_gear(args, case)
        return _run_hertz(args, case)
    except InputError as exc:
        raise _as_option(exc) from exc


def _run_gear(args: argparse.Namespace, case) -> int:
    # local: the API and the LTCA pull scipy and scikit-fem (~2 s); `fegear --help` does not
    from fegear.api import run
    from fegear.io.gear_case import UNLOADED
    from fegear.ltca.fidelity import FIDELITIES

    if args.study:
        raise InputError("--study", args.study, "absent for a gear case (a Hertz-scene option)")
    folder = inspect_output_folder(args.out, args.overwrite)  # before any work
    out = folder.path
    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    warned: set[str] = set()

    def warn(text: str) -> None:
        if text not in warned:
            warned.add(text)
            print(f"warning: {text}", file=sys.stderr, flush=True)

    fid = args.fidelity or case.fidelity
    lvl = case.level if args.level is None else args.level
    t_start = time.perf_counter()
    checks = "geometry, assembly and engagement checks (tip clearance, TCA of the positions)"
    kind = FIDELITIES.get(fid)  # None: the unloaded TCA (or a bad name, refused by the run)
    if kind is not None:
        stages = [
            ("geometry", checks),
            ("models", f"{kind.models_text} (cached after the first run)"),
            ("positions", f"mesh positions ({kind.positions_text})"),
        ]
    else:
        stages = [
            ("geometry", "geometry, assembly and tip clearance"),
            ("tca", "unloaded TCA over the cycle and engagement checks"),
        ]
    writing = "writing outputs"
    if kind is not None and kind.cells:  # the fields are computed while the pictures are drawn
        writing = "displacement fields (one sparse solve per member) and outputs"
    stages.append(("writing", writing))
    labels = {s: f"[{i}/{len(stages)}] {text}" for i, (s, text) in enumerate(stages, 1)}
    if kind is not None:  # the loaded cycle of the same run read back (fegear.ltca.cached)
        labels["cached"] = (
            f"[2-3/{len(stages)}] models and mesh positions: the same run is in the cache, "
            "read back (--recompute solves it again)"
        )
    stage_t = {"t": t_start, "started": False}

    def progress(stage: str, i: int | None, n: int | None) -> None:
        if not stage_t["started"]:  # the case is valid and its pair built: say what runs
            stage_t["started"] = True
            say(
                f"fegear {__version__}: case {case.name!r} ({case.source}), {case.kind}, "
                f"T2 {case.torque2_Nm:.1f} N·m, fidelity {fid}"
                + (f", level {lvl}" if fid != UNLOADED else "")
                + f", {case.n_positions} positions, out {out}/"
            )
        now = time.perf_counter()
        if stage == "positions" and i:
            bar = "#" * int(20 * i / n)
            say(f"    position {i:3d}/{n} [{bar:<20s}] {now - stage_t['t']:6.1f} s")
            return
        if stage == "cached":  # the fields of the same run are read back too
            k = len(stages)
            labels["writing"] = f"[{k}/{k}] outputs (the displacement fields read back if cached)"
        say(f"{labels.get(stage, stage)} ...  ({now - t_start:.1f} s elapsed)")
        stage_t["t"] = now

    result = run(
        case,
        fidelity=args.fidelity,
        level=args.level,
        workers=args.workers,
        backend=args.backend,
        root_stress=args.root_stress,
        progress=progress,
        notify=warn,
        fields=False,  # computed by write, beside the pictures (fegear.output.gear_output)
        reuse=not args.recompute,
    )
    progress("writing", None, None)
    paths = result.write(out, overwrite=args.overwrite)
    say(f"    {folder.describe()}")
    c = result.cycle
    if result.fidelity != UNLOADED:
        used = f" over {c.te_pp_loaded_positions_used} of {c.n_positions} positions"
        say(
            f"    TE p-p unloaded {_value(c.te_pp_unloaded_arcsec, '.2f', 'arcsec')}, loaded "
            f"{_value(c.te_pp_loaded_arcsec, '.2f', 'arcsec')}"
            + (used if c.te_pp_loaded_arcsec is not None else "")
            + f"; loaded contact ratio {_value(c.contact_ratio_loaded, '.2f', '')}"
        )
        if c.p_max_MPa is not None:
            k, j = c.p_max_pair
            say(
                f"    p_max {c.p_max_MPa:.0f} MPa away from the flank edges (position "
                f"{c.p_max_position}, pair ({k}, {j}))"
            )
        if c.p_max_edge_MPa is not None:
            k, j = c.p_max_edge_pair
            say(
                f"    edge contact at {len(c.positions_with_edge_contact)} of {c.n_positions} "
                f"positions: up to {c.p_max_edge_MPa:.0f} MPa at the "
                f"{', '.join(c.p_max_edge_edges)} (position {c.p_max_edge_position}, pair ({k}, "
                f"{j})): singular, grid-dependent (cycle.p_max_edge_MPa)"
            )
        elif c.positions_with_edge_contact:
            why = next(
                q.pressure_reason
                for i in c.positions_with_edge_contact
                for q in result.positions[i].pairs
                if q.pressure_reason
            )
            say(
                f"    edge contact at {len(c.positions_with_edge_contact)} of {c.n_positions} "
                f"positions, no pressure there: {why} (positions[i].pairs[j].pressure_reason)"
            )
    else:
        say(f"    unloaded TE p-p {_value(c.te_pp_unloaded_arcsec, '.2f', 'arcsec')} (TCA only)")
    ch = result.checks
    if ch.contact_ratio_unloaded is not None:
        start, end = ch.path_ends
        say(
            f"    unloaded contact ratio {ch.contact_ratio_unloaded:.3f}: one pair's path "
            f"{ch.path_length_mm:.1f} mm on the {result.run.pair.gear.name.replace('_', '-')} "
            f"flank, from {start.replace(':', ' ')} to {end.replace(':', ' ')}"
        )
    for w in result.model.warnings:  # the run's warnings (the solver's notes: below)
        warn(w)
    n_other = sum(bool(p.warnings) for p in result.positions)
    if n_other:
        say(f"    {n_other} positions with solver notes (summary.json: positions[i].warnings)")
    kinds = (
        "summary.json, cycle.pvd, vtk/, *.png"
        if result.fidelity != UNLOADED
        else "summary.json, *.png"
    )
    say(f"wrote {len(paths)} files to {out}/ ({kinds}) in {time.perf_counter() - t_start:.1f} s")
    return 0


def _value(x: float | None, fmt: str, unit: str) -> str:
    """A headline number, or "not reported" (never a 0 standing for nothing)."""
    if x is None:
        return "not reported"
    return f"{format(x, fmt)} {unit}".rstrip()


def _run_hertz(args: argparse.Namespace, case) -> int:
    from fegear.api import run  # local: scipy and scikit-fem (~2 s), as in _run_gear

    study = None
    if args.study:
        try:
            study = tuple(sorted({int(x) for x in args.study.split(",")}))
        except ValueError as exc:
            raise InputError("--study", args.study, "comma-separated integers") from exc
    folder = inspect_output_folder(args.out, args.overwrite)  # before any work
    out = folder.path
    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr))
    fidelity = args.fidelity or case.fidelity
    level = case.level if args.level is None else args.level
    levels = case.study_levels if study is None else study
    clock = {"t": time.perf_counter(), "started": False}

    def progress(stage: str, i: int | None, n: int | None) -> None:
        if not clock["started"]:
            clock["started"] = True
            say(
                f"fegear {__version__}: case {case.name!r} ({case.source}), fidelity "
                f"{fidelity}, level {level}, out {out}/"
            )
        clock["t"] = time.perf_counter()
        if stage == "study":
            say(f"[study {i}/{n}] level {levels[i - 1]} ...")
        else:
            say(f"[run] level {level}: meshes, stiffness, compliance, contact, fields ...")

    res = run(
        case, fidelity=args.fidelity, level=args.level, backend=args.backend, study=study,
        progress=progress,
    )  # fmt: skip
    for r in res.study:
        say(
            f"    level {r.level}: p0 {r.p0_MPa:8.1f} MPa ({r.error('p0'):+.2%})  a "
            f"{r.a_mm:.4f} mm ({r.error('a'):+.2%})  b {r.b_mm:.4f} mm ({r.error('b'):+.2%})  "
            f"DOFs {sum(r.dofs.values())}  {sum(r.seconds.values()):.1f} s"
        )
    if res.rates:
        say("observed rates: " + ", ".join(f"{k} {v:.2f}" for k, v in res.rates.items()))
    for w in res.warnings:
        say(f"warning: {w}")
    say(
        f"    p0 {res.p0_MPa:.1f} MPa (Hertz {res.hertz_p0_MPa:.1f}, {res.errors['p0']:+.2%}), "
        f"a {res.a_mm:.4f} mm ({res.errors['a']:+.2%}), b {res.b_mm:.4f} mm "
        f"({res.errors['b']:+.2%}), {res.level_result.n_active} active cells, "
        f"{time.perf_counter() - clock['t']:.1f} s"
    )
    for p in res.write(out, overwrite=args.overwrite):
        say(f"wrote {p}")
    say(folder.describe())
    return 0


def _cache(args: argparse.Namespace) -> int:
    if args.cache_command == "clear":
        gone = clear_cache(args.kind)
        if not gone.exists:
            print(f"fegear cache: {gone.root} does not exist (nothing to clear)")
            return 0
        what = f"kind {args.kind!r}" if args.kind else "all kinds"
        print(
            f"fegear cache: removed {gone.files} files ({_size(gone.bytes)}) of {what} from "
            f"{gone.root}"
        )
        return 0
    info = cache_info()
    where = "FEGEAR_CACHE" if info.source == "FEGEAR_CACHE" else "the per-user cache folder"
    print(f"fegear cache: {info.root} ({where})")
    if not info.exists:
        print("  empty (the folder is made by the first run)")
        return 0
    if not info.is_cache:
        print("  warning: this folder is not a fegear cache (no fegear CACHEDIR.TAG)")
    width = max([len(k.kind) for k in info.kinds] + [5])
    for k in info.kinds:
        print(f"  {k.kind:<{width}}  {k.entries:5d} entries  {k.files:6d} files  "
              f"{_size(k.bytes):>10}")  # fmt: skip
    print(f"  {'total':<{width}}  {info.entries:5d} entries  {info.files:6d} files  "
          f"{_size(info.bytes):>10}")  # fmt: skip
    cap = "none" if info.limit == float("inf") else _size(int(info.limit))
    share = "" if info.limit == float("inf") else f" ({100 * info.bytes / info.limit:.0f} % used)"
    print(
        f"  size cap {cap}{share}: the least recently used entries are evicted beyond it "
        "(FEGEAR_CACHE_LIMIT, e.g. 20GB or none)"
    )
    legacy = Path.cwd() / "meshes" / "cache"
    if legacy.is_dir() and legacy.resolve() != info.root.resolve():
        print(
            f"  note: {legacy} is the cache of an older fegear, no longer used: delete it, or "
            "reuse it with FEGEAR_CACHE"
        )
    return 0


def _size(n: int) -> str:
    for unit, k in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= k:
            return f"{n / k:.1f} {unit}"
    return f"{n} B"


def _plot(args: argparse.Namespace) -> int:
    import json

    # local: the flank view and its VTP reader pull scipy and scikit-fem (~2 s)
    from fegear.output.flank_view import plot_flank_pattern
    from fegear.output.flank_vtp import read_flank_vtp

    folder = Path(args.folder)
    listed = run_files(folder)  # the files of the folder's run, never a stale one of another
    if listed is None and (folder / MANIFEST).is_file():
        raise InputError(
            "FOLDER", str(folder), "the output folder of a finished `fegear run`",
            "its run did not finish (no summary.json): run it again",
        )  # fmt: skip
    if listed is None:  # a folder written before manifests: what is there
        files = sorted((folder / "vtk").glob(f"flank_{args.member}_*.vtp"))
    else:
        pattern = re.compile(rf"^vtk/flank_{args.member}_[0-9]+\.vtp$")
        files = sorted(folder / f for f in listed if pattern.match(f))
    if not files:
        raise InputError(
            "FOLDER",
            str(folder),
            "an output folder of `fegear run` at fidelity hybrid or fe",
            f"no vtk/flank_{args.member}_*.vtp in it",
        )
    png = Path(args.png) if args.png else folder / f"bearing_pattern_{args.member}_flank.png"
    if png.parent != Path("") and png.parent.exists() and not png.parent.is_dir():
        raise InputError("--png", str(png), "a file in a folder")
    frame, patches = None, []
    for f in files:
        frame, patch, _ = read_flank_vtp(f)
        patches.append(patch)
    title, p_max = folder.name, None
    try:
        doc = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
        title = f"{doc['case']}: {doc['fidelity']} level {doc['level']}"
        p_max = doc["cycle"].get("p_max_MPa")
    except (OSError, ValueError, KeyError):
        pass
    manifest = folder / MANIFEST
    # the PNG joins the run's outputs in the folder (the next run there replaces it too)
    with journal(folder, manifest) if manifest.is_file() else contextlib.nullcontext():
        path = plot_flank_pattern(frame, patches, png, title, p_max)
    if not args.quiet:
        print(f"wrote {path} (the bearing pattern over {len(files)} positions)", file=sys.stderr)
    return 0


def _sweep(args: argparse.Namespace) -> int:
    from fegear.sweep import build_items, require_dask, run_sweep  # local: scipy, scikit-fem

    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    t_start = time.perf_counter()
    check_writable_folder(args.out)
    items = build_items(args.case, args.grid, fidelity=args.fidelity, level=args.level)
    if args.workers is not None and args.workers < 1:
        raise InputError("--workers", args.workers, "an integer >= 1")
    workers = process_count(args.workers, max(len(items) - 1, 1))
    names = [it.name for it in items]
    if args.nominal is not None and args.nominal not in names:
        raise InputError("--nominal", args.nominal, f"one of the item names {names}")
    if args.scheduler:
        require_dask()  # a one-line error before any output
    where = (
        f"Dask scheduler {args.scheduler}"
        if args.scheduler
        else f"{workers} item{'s' if workers > 1 else ''} at a time"
    )
    grid = "".join(f" × {g}" for g in args.grid)
    say(
        f"fegear {__version__}: sweep of {len(items)} items ({', '.join(args.case)}{grid}), "
        f"{where}, out {args.out}/"
    )
    width = len(str(len(items)))

    def progress(r, k: int, n: int) -> None:
        head = f"[{k:{width}d}/{n}] {r.name}"
        if r.status == "skipped":
            say(f"{head}  skipped (done)")
        elif r.status == "failed":
            say(f"{head}  failed: {r.error}")
        else:
            say(f"{head}  done in {r.seconds:.1f} s")

    res = run_sweep(
        items,
        args.out,
        workers=workers,
        scheduler=args.scheduler,
        nominal=args.nominal,
        progress=progress,
    )
    counts = {s: sum(r.status == s for r in res.results.values()) for s in ("done", "skipped")}
    say(
        f"wrote {', '.join(p.name for p in res.files)} to {args.out}/: "
        f"{counts['done']} computed, {counts['skipped']} skipped (done), {res.n_failed} failed "
        f"in {time.perf_counter() - t_start:.1f} s"
    )
    if not args.quiet:
        print((res.out / "comparison.md").read_text(encoding="utf-8"), end="")
    if res.comparison_error:
        print(f"fegear: failed: {res.comparison_error}", file=sys.stderr)
        return 1
    return 1 if res.n_failed else 0


#: ``fegear accept`` option -> :class:`fegear.api.Tolerances` field
_TOLERANCES = {
    "--p-max-pct": "p_max_pct",
    "--te-pp-arcsec": "te_pp_loaded_arcsec",
    "--te-pp-pct": "te_pp_loaded_pct",
    "--te-pp-unloaded-arcsec": "te_pp_unloaded_arcsec",
    "--khb": "k_h_beta",
}
#: the exit codes of ``fegear accept`` by verdict (1 and 2 keep their meaning: failure, input)
ACCEPT_EXIT = {"accept": 0, "reject": 3, "undecided": 4}


def _accept(args: argparse.Namespace) -> int:
    import math

    # local: the API and the LTCA pull scipy and scikit-fem (~2 s); `fegear --help` does not
    from fegear.api import Tolerances, accept, load_case

    given = {}
    for option, name in _TOLERANCES.items():
        text = getattr(args, option[2:].replace("-", "_"))
        if text is None:
            continue
        try:
            x = float(text)
        except ValueError:
            x = math.nan
        if not (math.isfinite(x) and x >= 0):
            raise InputError(option, text, "a finite number >= 0 (an allowed increase)")
        given[name] = x
    tol = Tolerances(**given, edge_contact_allowed=args.allow_edge)
    check_writable_folder(args.out)
    measured = load_case(args.case)
    design = None if args.design is None else load_case(args.design)
    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    t_start = time.perf_counter()

    def progress(which: str, case) -> None:
        k = 1 if which == "measured" else 2
        say(f"[{k}/2] {which}: {case.name} ({case.source}) ...  "
            f"({time.perf_counter() - t_start:.1f} s elapsed)")  # fmt: skip

    try:
        verdict = accept(measured, tol, design, fidelity=args.fidelity, level=args.level,
                         workers=args.workers, progress=progress)  # fmt: skip
    except InputError as exc:  # the API's argument names -> the command's
        names = {"design_case": "--design", "case": "CASE"}
        if exc.field in names:
            raise type(exc)(names[exc.field], exc.value, exc.allowed, exc.detail) from exc
        raise _as_option(exc) from exc
    path = verdict.write(args.out)
    say(f"wrote {path} in {time.perf_counter() - t_start:.1f} s")
    print(verdict.line if args.quiet else verdict.table())
    return ACCEPT_EXIT[verdict.verdict]


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit code (0 ok, 2 bad input, 1 other failure)."""
    args = _parser().parse_args(argv)
    logging.basicConfig(
        level=logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        if args.command in ("run", "sweep", "export-ccx", "settings", "accept"):
            check_cache_root()  # an unusable FEGEAR_CACHE is refused before any work
        if args.command == "run":
            return _run(args)
        if args.command == "sweep":
            return _sweep(args)
        if args.command == "cache":
            return _cache(args)
        if args.command == "accept":
            return _accept(args)
        if args.command == "plot":
            return _plot(args)
        if args.command == "export-ccx":
            return export_ccx(args)
        if args.command == "settings":
            return print_settings(args)
    except InputError as exc:
        print(f"fegear: error: {exc}", file=sys.stderr)
        return 2
    except FegearError as exc:
        print(f"fegear: failed: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("fegear: interrupted (files already written are complete)", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001  (third-party failures, e.g. gmsh: one line, exit 1)
        if os.environ.get("FEGEAR_DEBUG"):
            raise
        msg = " ".join(str(exc).split()) or type(exc).__name__
        print(
            f"fegear: failed: {type(exc).__name__}: {msg} (FEGEAR_DEBUG=1 for the traceback)",
            file=sys.stderr,
        )
        return 1
    return 1


if __name__ == "__main__":
    sys.exit(main())
