"""The ``fegear`` command.

``fegear run [CASE] [--level L] [--out DIR] [--study L1,L2,...] [--backend B]`` runs a case and
writes its results; with no CASE it runs the built-in Hertz scene (crowned roller Rx 20 / Ry 100 mm
on a block, 2000 N, steel) at level 3. Bad input ends with a one-line message and exit code 2.
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

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
    r = sub.add_parser("run", help="run a case file (default: the built-in Hertz scene)")
    r.add_argument("case", nargs="?", help="case file (TOML); default: the Hertz scene")
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
        choices=["fe", "hybrid"],
        help="fe: pure FE compliance; hybrid: coarse FE + half-space near field",
    )
    r.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")
    return p


def _run(args: argparse.Namespace) -> int:
    from fegear.case import HertzCase, load_case
    from fegear.convergence import observed_rate
    from fegear.io.hertz_output import write_hertz_outputs
    from fegear.scenes.hertz_scene import CELLS_ACROSS_MINOR, HertzScene, run_level

    if args.case:
        case = load_case(args.case)
    else:
        case = HertzCase(
            name="hertz_scene",
            scene=HertzScene(),
            level=3,
            backend="auto",
            fidelity="fe",
            fe_level=0,
            study_levels=(),
            source="<built-in>",
        )
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
    out = Path(args.out)
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
    except InputError as exc:
        print(f"fegear: error: {exc}", file=sys.stderr)
        return 2
    except FegearError as exc:
        print(f"fegear: failed: {exc}", file=sys.stderr)
        return 1
    return 1


if __name__ == "__main__":
    sys.exit(main())
