"""The Python API: load a case, change it, run it, read and write its results.

::

    import fegear

    case = fegear.load_case("cases/face_gear_nominal.toml")
    result = fegear.run(case.with_errors(dgamma_deg=0.02), fidelity="tca")
    print(result.cycle.te_pp_unloaded_arcsec, result.pattern["gear"].face_mm)
    result.write("out/dgamma")          # the files of `fegear run`

A case is frozen: :meth:`~fegear.io.gear_case.GearCase.replace` and
:meth:`~fegear.io.gear_case.GearCase.with_errors` return a new case validated exactly like a case
file (a bad field raises the :class:`~fegear.errors.InputError` the case file would).
:func:`run` returns a :class:`GearResult` (gear pairs) or a :class:`HertzResult` (the Hertz
scene): typed, frozen, with the numbers of ``summary.json`` — a gear result hands out the result
model (:mod:`fegear.results`) that ``summary.json`` is written from — and ``write(folder)``,
which writes the files ``fegear run`` writes (the command is a layer over this module). Units
are in the names (mm, N, MPa, N·m, arcsec, deg).

For scripts that compare runs (one per installation error, say): :func:`table` (a text table of
the headline numbers and the pattern shift), :func:`plot_te` and :func:`plot_patterns`. Is a
measured batch acceptable: :func:`accept` (a measured run against its design, within the user's
:class:`Tolerances`).
"""

from fegear.api.acceptance import Check, Tolerances, Verdict, accept
from fegear.api.compare import plot_patterns, plot_te, table
from fegear.api.gear_result import GearResult
from fegear.api.hertz_scene_result import HertzResult
from fegear.api.runner import Progress, load_case, run
from fegear.api.settings import machine_sheet, machine_tables
from fegear.results.model import Checks, Cycle, Excluded, PairLoad, Position

__all__ = [
    "Check",
    "Checks",
    "Cycle",
    "Excluded",
    "GearResult",
    "HertzResult",
    "PairLoad",
    "Position",
    "Progress",
    "Tolerances",
    "Verdict",
    "accept",
    "load_case",
    "machine_sheet",
    "machine_tables",
    "plot_patterns",
    "plot_te",
    "run",
    "table",
]
