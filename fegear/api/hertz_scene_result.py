"""The result of a Hertz-scene run in Python (:class:`HertzResult`): the FE contact of a
crowned roller on a block against Hertz, and its files on request."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fegear.errors import InputError
from fegear.io.gear_case import ANALYSIS
from fegear.mechanics.convergence import observed_rate
from fegear.output.hertz_scene_output import write_hertz_outputs
from fegear.results.hertz_scene import HertzSceneResult, build_hertz_result
from fegear.scenes.hertz_case import HertzCase
from fegear.scenes.hertz_scene import CELLS_ACROSS_MINOR, run_level
from fegear.store.outputs import inspect_output_folder, output_run

__all__ = ["HertzResult", "run_hertz"]


@dataclass(frozen=True)
class HertzResult:
    """A Hertz-scene run: the FE contact of a crowned roller on a block against Hertz.

    Attributes
    ----------
    case
        The case.
    fidelity, level
        How it ran.
    p0_MPa, a_mm, b_mm, approach_mm
        Peak pressure (MPa), patch semi-axes and rigid approach (mm) of the FE contact.
    hertz_p0_MPa, hertz_a_mm, hertz_b_mm
        The closed-form Hertz values.
    errors
        ``{"p0", "a", "b", "approach"}``: relative errors against Hertz.
    study
        The levels of a convergence study (:class:`fegear.scenes.hertz_scene.HertzLevelResult`).
    rates
        Observed convergence rates of the study (``{"p0", "a", "b"}``).
    warnings
        Warnings of the run.
    level_result
        The run's :class:`~fegear.scenes.hertz_scene.HertzLevelResult` (fields, cells).
    model
        The result model (:class:`~fegear.results.hertz_scene.HertzSceneResult`): what
        ``summary.json`` holds; the numbers above are its.
    """

    case: HertzCase
    fidelity: str
    level: int
    p0_MPa: float
    a_mm: float
    b_mm: float
    approach_mm: float
    hertz_p0_MPa: float
    hertz_a_mm: float
    hertz_b_mm: float
    errors: Mapping[str, float]
    study: tuple[Any, ...] = field(repr=False)
    rates: Mapping[str, float] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    level_result: Any = field(default=None, repr=False, compare=False)
    model: HertzSceneResult | None = field(default=None, repr=False)

    def write(self, folder: str | Path, overwrite: bool = False) -> tuple[Path, ...]:
        """Write the files of ``fegear run`` for the scene into ``folder`` (``summary.json``,
        ``block.vtu``, ``roller.vtu``, ``contact_cells.vtu``, ``pressure_map.png``,
        ``convergence.png`` with a study): one run per folder, as :meth:`GearResult.write`.
        Returns the paths."""
        with output_run(inspect_output_folder(folder, overwrite, "folder")) as out:
            return tuple(write_hertz_outputs(out, self.model, self.level_result))


def run_hertz(
    case: HertzCase,
    fidelity: str | None,
    level: int | None,
    backend: str | None,
    study: Sequence[int] | None,
    progress=None,
) -> HertzResult:
    """Run the Hertz scene (:func:`fegear.api.run` with a
    :class:`~fegear.scenes.hertz_case.HertzCase`)."""
    n = len(CELLS_ACROSS_MINOR)
    if backend is not None:
        ANALYSIS.key("backend").check("backend", backend)  # the case file's rule
    if fidelity not in (None, "fe", "hybrid"):
        raise InputError("fidelity", fidelity, "'fe' or 'hybrid' for the Hertz scene")
    level = case.level if level is None else level
    if not (isinstance(level, int) and 0 <= level < n):
        raise InputError("level", level, f"an integer in [0, {n - 1}]")
    levels = case.study_levels if study is None else tuple(sorted(set(study)))
    for lv in levels:
        if not (isinstance(lv, int) and 0 <= lv < n):
            raise InputError("study", lv, f"levels in [0, {n - 1}]")
    fidelity = fidelity or case.fidelity
    kw = {"backend": backend or case.backend, "fidelity": fidelity, "fe_level": case.fe_level}
    say = progress or (lambda stage, i, k: None)
    rows = []
    for i, lv in enumerate(levels):
        say("study", i + 1, len(levels))
        rows.append(run_level(case.scene, lv, **kw))
    rates: dict[str, float] = {}
    if len(rows) >= 2:
        h = [r.cell_size_mm for r in rows]
        for key in ("p0", "a", "b"):
            try:
                rates[key] = observed_rate(h, [r.error(key) for r in rows])
            except InputError:
                pass
    say("run", None, None)
    res = run_level(case.scene, level, with_fields=True, **kw)  # logs its warnings
    model = build_hertz_result(case.name, case.scene, res, rows, rates)
    return HertzResult(
        case=case,
        fidelity=model.fidelity,
        level=model.inputs.level,
        p0_MPa=model.result.p0_MPa,
        a_mm=model.result.a_mm,
        b_mm=model.result.b_mm,
        approach_mm=model.result.approach_mm,
        hertz_p0_MPa=model.hertz.p0_MPa,
        hertz_a_mm=model.hertz.a_mm,
        hertz_b_mm=model.hertz.b_mm,
        errors=dict(model.errors),
        study=tuple(rows),
        rates=dict(model.convergence_rate),
        warnings=model.result.warnings,
        level_result=res,
        model=model,
    )
