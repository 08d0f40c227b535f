"""The ``fegear`` command.

``fegear run [CASE] [--fidelity F] [--level L] [--out DIR]`` runs a case file and writes its
results (summary.json, VTK + .pvd, PNG) into ``DIR`` (default ``./out``). The case kind decides
what runs:

- gear pairs (``face_gear``, ``spur``, ``spiral_bevel``): the loaded TCA (``--fidelity hybrid``,
  the default, ``fe`` or ``hertz``) or the unloaded TCA (``--fidelity tca``);
- ``hertz_scene``: the FE Hertz check (``--fidelity fe | hybrid``, ``--study``, ``--backend``).

With no CASE it runs the built-in seed face-gear case (``cases/face_gear_nominal.toml``: N2 160,
N1 25, m 6.35 mm, 25°, pinion torque 350.14 N·m, hybrid level 0, 25 positions; under a minute
cold on 2 cores, the sector meshes and compliance operators are then cached).

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
import logging
import os
import sys
import time

from fegear import __version__
from fegear.errors import FegearError, InputError

__all__ = ["main"]


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
        help="gear pairs: processes solving the mesh positions (default: one per core); the "
        "result does not depend on it",
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
    s.add_argument("--fidelity", help="hybrid | fe | hertz | tca; overrides the cases")
    s.add_argument("--level", type=int, help="mesh level (0 = coarsest); overrides the cases")
    s.add_argument("--workers", type=int, default=1, help="local worker processes (default 1)")
    s.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask distributed cluster (e.g. tcp://host:8786) instead of local processes",
    )
    s.add_argument("--nominal", help="reference item of the comparison (default: no errors)")
    s.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")
    return p


def _run(args: argparse.Namespace) -> int:
    from fegear.case import load_case
    from fegear.io.gear_case import GearCase

    if args.case:
        case = load_case(args.case)
    else:
        from fegear.io.seed import seed_case

        case = seed_case()
    if isinstance(case, GearCase):
        return _run_gear(args, case)
    return _run_hertz(args, case)


def _run_gear(args: argparse.Namespace, case) -> int:
    from dataclasses import replace

    from fegear.io.files import check_writable_folder
    from fegear.io.gear_case import build_pair
    from fegear.io.gear_output import write_gear_outputs
    from fegear.io.gear_run import report, run_gear_case

    if args.study:
        raise InputError("--study", args.study, "absent for a gear case (a Hertz-scene option)")
    if args.backend:
        case = replace(case, backend=args.backend)
    out = check_writable_folder(args.out)  # before any work
    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    warned: set[str] = set()

    def warn(text: str) -> None:
        if text not in warned:
            warned.add(text)
            print(f"warning: {text}", file=sys.stderr, flush=True)

    fid = args.fidelity or case.fidelity
    lvl = case.level if args.level is None else args.level
    if fid not in ("fe", "hertz", "hybrid", "tca"):
        raise InputError("--fidelity", fid, "'fe', 'hertz', 'hybrid' or 'tca' for gear pairs")
    if not 0 <= lvl <= 4:
        raise InputError("--level", lvl, "an integer in [0, 4]")
    if args.workers is not None and args.workers < 1:
        raise InputError("--workers", args.workers, "an integer >= 1")
    t_start = time.perf_counter()
    pair = build_pair(case)  # bad design data is refused here, before any output
    say(
        f"fegear {__version__}: case {case.name!r} ({case.source}), {case.kind}, "
        f"T2 {case.torque2_Nmm / 1000:.1f} N·m, fidelity {fid}"
        + (f", level {lvl}" if fid != "tca" else "")
        + f", {case.n_positions} positions, out {out}/"
    )
    stage_t = {"t": t_start}
    checks = "geometry, assembly and engagement checks (tip clearance, TCA of the positions)"
    if fid in ("fe", "hybrid"):
        layer = " and their layer below the flanks" if fid == "hybrid" else ""
        labels = {
            "geometry": f"[1/5] {checks}",
            "models": f"[2/5] sector meshes and compliance operators{layer} (cached after the "
            "first run)",
            "positions": "[3/5] mesh positions (TCA + contact)",
            "displacements": "[4/5] displacement fields (one sparse solve per member)",
            "writing": "[5/5] writing outputs",
        }
    elif fid == "hertz":
        labels = {
            "geometry": f"[1/4] {checks}",
            "models": "[2/4] sector meshes and compliance operators (cached after the first run)",
            "positions": "[3/4] mesh positions (TCA + Hertz laws)",
            "writing": "[4/4] writing outputs",
        }
    else:
        labels = {
            "geometry": "[1/3] geometry, assembly and tip clearance",
            "tca": "[2/3] unloaded TCA over the cycle and engagement checks",
            "writing": "[3/3] writing outputs",
        }

    def progress(stage: str, i: int | None, n: int | None) -> None:
        now = time.perf_counter()
        if stage == "positions" and i:
            bar = "#" * int(20 * i / n)
            say(f"    position {i:3d}/{n} [{bar:<20s}] {now - stage_t['t']:6.1f} s")
            return
        say(f"{labels.get(stage, stage)} ...  ({now - t_start:.1f} s elapsed)")
        stage_t["t"] = now

    run = run_gear_case(
        case,
        fidelity=args.fidelity,
        level=args.level,
        progress=progress,
        pair=pair,
        workers=args.workers,
        notify=warn,
    )
    progress("writing", None, None)
    paths = write_gear_outputs(out, run)
    rep = report(run)
    if run.cycle is not None:
        used = f" over {rep.positions_used} of {rep.n_positions} positions"
        say(
            f"    TE p-p unloaded {_value(rep.te_pp_unloaded_arcsec, '.2f', 'arcsec')}, loaded "
            f"{_value(rep.te_pp_loaded_arcsec, '.2f', 'arcsec')}"
            + (used if rep.te_pp_loaded_arcsec is not None else "")
            + f"; loaded contact ratio {_value(rep.contact_ratio_loaded, '.2f', '')}"
        )
        if rep.p_max_MPa is not None:
            k, j = rep.p_max_pair
            say(
                f"    p_max {rep.p_max_MPa:.0f} MPa away from the flank edges (position "
                f"{rep.p_max_position}, pair ({k}, {j}))"
            )
        if rep.p_max_edge_MPa is not None:
            k, j = rep.p_max_edge_pair
            say(
                f"    edge contact at {len(rep.edge_positions)} of {rep.n_positions} positions: "
                f"up to {rep.p_max_edge_MPa:.0f} MPa at the {', '.join(rep.p_max_edge_edges)} "
                f"(position {rep.p_max_edge_position}, pair ({k}, {j})): singular, "
                "grid-dependent (cycle.p_max_edge_MPa)"
            )
    else:
        say(f"    unloaded TE p-p {_value(rep.te_pp_unloaded_arcsec, '.2f', 'arcsec')} (TCA only)")
    cp = run.engagement.path if run.engagement is not None else None
    if cp is not None:
        say(
            f"    unloaded contact ratio {cp.contact_ratio:.3f}: one pair's path "
            f"{cp.length_mm:.1f} mm on the {run.pair.gear.name.replace('_', '-')} flank, from "
            f"{cp.start_limit.replace(':', ' ')} to {cp.end_limit.replace(':', ' ')}"
        )
    for w in rep.warnings:
        warn(w)
    n_other = sum(bool(p.warnings) for p in run.cycle.positions) if run.cycle is not None else 0
    if n_other:
        say(f"    {n_other} positions with solver notes (summary.json: positions[i].warnings)")
    kinds = (
        "summary.json, cycle.pvd, vtk/, *.png" if run.cycle is not None else "summary.json, *.png"
    )
    say(f"wrote {len(paths)} files to {out}/ ({kinds}) in {time.perf_counter() - t_start:.1f} s")
    return 0


def _value(x: float | None, fmt: str, unit: str) -> str:
    """A headline number, or "not reported" (never a 0 standing for nothing)."""
    if x is None:
        return "not reported"
    return f"{format(x, fmt)} {unit}".rstrip()


def _run_hertz(args: argparse.Namespace, case) -> int:
    from fegear.convergence import observed_rate
    from fegear.io.files import check_writable_folder
    from fegear.io.hertz_output import write_hertz_outputs
    from fegear.scenes.hertz_scene import CELLS_ACROSS_MINOR, run_level

    if args.backend not in (None, "auto", "pardiso", "superlu"):
        raise InputError("--backend", args.backend, "'auto', 'pardiso' or 'superlu'")
    if args.fidelity not in (None, "fe", "hybrid"):
        raise InputError("--fidelity", args.fidelity, "'fe' or 'hybrid' for the Hertz scene")
    level = case.level if args.level is None else args.level
    if not 0 <= level < len(CELLS_ACROSS_MINOR):
        raise InputError("--level", level, f"an integer in [0, {len(CELLS_ACROSS_MINOR) - 1}]")
    backend = args.backend or case.backend
    fidelity = args.fidelity or case.fidelity
    kw = {"backend": backend, "fidelity": fidelity, "fe_level": case.fe_level}
    study_levels = case.study_levels
    if args.study:
        try:
            study_levels = tuple(sorted({int(x) for x in args.study.split(",")}))
        except ValueError as exc:
            raise InputError("--study", args.study, "comma-separated integers") from exc
    out = check_writable_folder(args.out)  # before any work
    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr))
    say(
        f"fegear {__version__}: case {case.name!r} ({case.source}), fidelity {fidelity}, "
        f"level {level}, out {out}/"
    )
    study = []
    for i, lv in enumerate(study_levels):
        t0 = time.perf_counter()
        say(f"[study {i + 1}/{len(study_levels)}] level {lv} ...")
        res = run_level(case.scene, lv, **kw)
        say(
            f"    p0 {res.p0_MPa:8.1f} MPa ({res.error('p0'):+.2%})  a {res.a_mm:.4f} mm "
            f"({res.error('a'):+.2%})  b {res.b_mm:.4f} mm ({res.error('b'):+.2%})  "
            f"DOFs {sum(res.dofs.values())}  {time.perf_counter() - t0:.1f} s"
        )
        study.append(res)
    rate = {}
    if len(study) >= 2:
        h = [r.cell_size_mm for r in study]
        for key in ("p0", "a", "b"):
            try:
                rate[key] = observed_rate(h, [r.error(key) for r in study])
            except InputError:
                pass
        say("observed rates: " + ", ".join(f"{k} {v:.2f}" for k, v in rate.items()))
    say(f"[run] level {level}: meshes, stiffness, compliance, contact, fields ...")
    t0 = time.perf_counter()
    res = run_level(case.scene, level, with_fields=True, **kw)
    for w in res.warnings:
        say(f"warning: {w}")
    say(
        f"    p0 {res.p0_MPa:.1f} MPa (Hertz {res.hertz.p0_MPa:.1f}, {res.error('p0'):+.2%}), "
        f"a {res.a_mm:.4f} mm ({res.error('a'):+.2%}), b {res.b_mm:.4f} mm "
        f"({res.error('b'):+.2%}), {res.n_active} active cells, "
        f"{time.perf_counter() - t0:.1f} s"
    )
    paths = write_hertz_outputs(out, case.name, case.scene, res, study or None, rate)
    for p in paths:
        say(f"wrote {p}")
    return 0


def _sweep(args: argparse.Namespace) -> int:
    from fegear.io.files import check_writable_folder
    from fegear.sweep import build_items, require_dask, run_sweep

    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    t_start = time.perf_counter()
    check_writable_folder(args.out)
    items = build_items(args.case, args.grid, fidelity=args.fidelity, level=args.level)
    if args.workers < 1:
        raise InputError("--workers", args.workers, "an integer >= 1")
    names = [it.name for it in items]
    if args.nominal is not None and args.nominal not in names:
        raise InputError("--nominal", args.nominal, f"one of the item names {names}")
    if args.scheduler:
        require_dask()  # a one-line error before any output
    where = (
        f"Dask scheduler {args.scheduler}"
        if args.scheduler
        else f"{args.workers} local worker{'s' if args.workers > 1 else ''}"
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
        workers=args.workers,
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


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit code (0 ok, 2 bad input, 1 other failure)."""
    args = _parser().parse_args(argv)
    logging.basicConfig(
        level=logging.WARNING if args.quiet else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        if args.command == "run":
            return _run(args)
        if args.command == "sweep":
            return _sweep(args)
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
