"""``fegear export-ccx``: a case as CalculiX decks, optionally run and read back.

``fegear export-ccx CASE [--positions I,J | --phi1-deg A,B] [--element-mm H] [--reach-mm R]
[--level L] [--out DIR] [--run] [--threads N]`` writes ``DIR/<job>.inp`` (and its record
``<job>.json``) per deck; with ``--run`` it runs ``ccx`` on each (one at a time) and prints the
load shares, p_max, patch semi-axes and TE read back (``<job>.result.json``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys

from fegear.errors import InputError
from fegear.export import export_ccx, find_ccx, position_angle, read_results, run_ccx

__all__ = ["add_parser", "run"]


def add_parser(sub) -> None:
    """The ``export-ccx`` subcommand on the CLI's subparsers ``sub``."""
    e = sub.add_parser(
        "export-ccx",
        help="write a case as CalculiX/Abaqus decks (.inp), optionally run ccx and read back",
        description="Writes the Hertz scene, or a gear pair at chosen positions, as ready-to-run "
        "CalculiX decks: C3D10 sectors refined around the contact, material, supports, torque, "
        "penalty contact pairs and output requests (docs/calculix.md).",
    )
    e.add_argument("case", help="case file (TOML): a gear pair or the Hertz scene")
    e.add_argument("--positions", help="gear pairs: comma-separated indices of the case's "
                   "cycle (the positions of `fegear run`, 0..n_positions-1)")  # fmt: skip
    e.add_argument("--phi1-deg", help="gear pairs: comma-separated pinion angles (deg)")
    e.add_argument("--element-mm", type=float, help="contact element size in mm (default: "
                   "0.5 for gears; the Hertz scene: twice the cell size of --level)")  # fmt: skip
    e.add_argument("--reach-mm", type=float, help="gear pairs: pairs within this separation "
                   "get contact pairs and refined elements (default 0.03)")  # fmt: skip
    e.add_argument("--level", type=int, help="gear pairs: sector mesh level away from the "
                   "contact (default: the case's); the Hertz scene: the level whose element size "
                   "the contact gets (default 1: 0.24 mm, ~2.5 min of ccx on 2 cores)")  # fmt: skip
    e.add_argument("--patch-mm", type=float, help="gear pairs: element size in mm along each "
                   "pair's contact patch (the flank strip where the TCA separation is below "
                   "--patch-gap-mm), coarse elsewhere (default: none, the reach's boxes at "
                   "--element-mm)")  # fmt: skip
    e.add_argument("--patch-gap-mm", type=float, help="gear pairs: the separation that bounds "
                   "the patch strips of --patch-mm (default 0.01)")  # fmt: skip
    e.add_argument("--out", default="ccx", help="output folder (default: ./ccx)")
    e.add_argument("--run", action="store_true", help="run ccx on each deck and read it back")
    e.add_argument("--threads", type=int, default=1, help="OMP_NUM_THREADS of ccx (default 1)")
    e.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")


def _floats(text: str, option: str) -> list[float]:
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError as exc:
        raise InputError(option, text, "comma-separated numbers") from exc


def run(args: argparse.Namespace) -> int:
    """Run the subcommand; the exit code."""
    # local: the API and the Hertz case pull scipy and scikit-fem (~2 s); the `fegear` command
    # builds its parser from this module
    from fegear.api import load_case
    from fegear.scenes.hertz_case import HertzCase

    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    case = load_case(args.case)
    phi1: list[float] = []
    if args.positions and args.phi1_deg:
        raise InputError("--positions", args.positions, "either --positions or --phi1-deg")
    if args.positions:
        phi1 = [position_angle(case, int(x)) for x in _floats(args.positions, "--positions")]
    elif args.phi1_deg:
        phi1 = [math.radians(x) for x in _floats(args.phi1_deg, "--phi1-deg")]
    elif not isinstance(case, HertzCase):
        raise InputError("--positions", None, "positions of the gear pair (or --phi1-deg)")
    if args.run:
        find_ccx()  # a missing ccx is said before any meshing
    paths = export_ccx(case, args.out, args.element_mm, phi1, args.reach_mm, args.level,
                       args.patch_mm, args.patch_gap_mm)  # fmt: skip
    for p in paths:
        rec = json.loads(p.with_suffix(".json").read_text(encoding="utf-8"))
        say(f"wrote {p} ({rec['n_nodes']} nodes, {rec['n_elements']} C3D10, "
            f"{len(rec['pairs'])} contact pair(s))")  # fmt: skip
    if not args.run:
        say(f"run: cd {args.out} && ccx -i <job>   (OMP_NUM_THREADS sets its threads)")
        return 0
    code = 0
    for p in paths:
        say(f"ccx -i {p.stem} ({args.threads} thread(s)) ...")
        r = run_ccx(p, threads=args.threads)
        if r.returncode != 0:
            print(f"fegear: failed: ccx exit {r.returncode} on {p} (see {p.stem}.log)",
                  file=sys.stderr)  # fmt: skip
            code = 1
            continue
        res = read_results(p)
        doc = {**res.to_dict(), "ccx_seconds": r.seconds, "ccx_peak_MB": r.peak_MB,
               "threads": r.threads}  # fmt: skip
        p.with_name(p.stem + ".result.json").write_text(json.dumps(doc, indent=1), "utf-8")
        say(f"    {r.seconds:.1f} s, {r.peak_MB:.0f} MB; balance {res.balance:.6f}")
        for q in res.pairs:
            say(f"    pair ({q.k}, {q.j}): share {q.load_share:.4f}, force {q.normal_force_N:.1f}"
                f" N, p_max {q.p_max_MPa:.0f} MPa (recovered {q.p_peak_MPa:.0f}), semi-axes "
                f"{q.semi_major_mm:.3f} x {q.semi_minor_mm:.3f} mm")  # fmt: skip
            if q.ip_force_N is not None and q.normal_force_N > 0:
                say(f"      pressure integral / contact force {q.ip_force_N / q.normal_force_N:.5f}"
                    f" ({q.n_points} integration points, contact area "
                    f"{q.contact_area_mm2:.4g} mm2); CalculiX's nodal pressures integrate to "
                    f"{q.nodal_force_N / q.normal_force_N:.3f} x the force")  # fmt: skip
        if res.te_loaded_arcsec is not None:
            say(f"    TE unloaded {res.te_unloaded_arcsec:.2f}, loaded {res.te_loaded_arcsec:.2f}"
                f" arcsec (lag {res.theta_rad:.4g} rad)")  # fmt: skip
        if res.approach_mm is not None:
            say(f"    axle approach {1000 * res.approach_mm:.3f} um")
        for w in res.warnings:
            print(f"warning: {w}", file=sys.stderr)
    return code
