"""``fegear settings``: the machine settings of a bevel case as a summary sheet's tables.

``fegear settings CASE [--units mm|in] [--out FILE]`` prints (or writes) the ``[machine.*]``
tables (:mod:`fegear.io.machine_table`) of the settings that cut the case's flanks: the
synthesized ones, or the case's own. Pasted into a case file they give the same flanks: a
starting point for settings of one's own, or the settings to hand to the gear cutter.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["add_parser", "run"]


def add_parser(sub) -> None:
    """The ``settings`` subcommand on the CLI's subparsers ``sub``."""
    e = sub.add_parser(
        "settings",
        help="print a bevel case's machine settings as [machine] tables (mm/deg or inch/deg-min)",
        description="Prints the machine settings that cut the flanks of a bevel case, "
        "synthesized or given, as the [machine.<flank>] tables of a case file.",
    )
    e.add_argument("case", help="case file (TOML) of kind spiral_bevel")
    e.add_argument("--units", default="mm", choices=("mm", "in"),
                   help="mm and decimal degrees (default), or inches, degrees-minutes")  # fmt: skip
    e.add_argument("--out", help="write to this file (default: standard output)")


def run(args: argparse.Namespace) -> int:
    """Run the subcommand; the exit code."""
    # local: the API pulls the geometry and scipy (~1 s); the `fegear` command builds its
    # parser from this module
    from fegear.api import load_case, machine_sheet

    text = machine_sheet(load_case(args.case), args.units)
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
        print(f"wrote {args.out}", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0
