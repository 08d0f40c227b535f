"""The result of a gear-pair run in Python (:class:`GearResult`): the result model
(:mod:`fegear.results`), typed, with the files of ``fegear run`` on request."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from fegear.errors import InputError
from fegear.io.gear_case import GearCase
from fegear.output.flank_view import plot_flank_pattern
from fegear.output.gear_output import write_gear_outputs
from fegear.results.build import build_result
from fegear.results.model import Checks, Cycle, GearRunResult, PatternCentre, Position
from fegear.results.summary import summary_document, summary_warnings
from fegear.store.outputs import inspect_output_folder, output_run

if TYPE_CHECKING:  # the run and its flank views: the pipeline and the writers, loaded on use
    from fegear.output.gear_output import FlankViews
    from fegear.pipeline.run import GearRun
    from fegear.store.cache import CacheUse

__all__ = ["GearResult", "gear_result"]


@dataclass(frozen=True)
class GearResult:
    """A gear-pair run: the numbers of ``summary.json``, typed, and the files on request.

    Attributes
    ----------
    case
        The case as run (fidelity and level applied).
    fidelity
        ``"hybrid"``, ``"fe"``, ``"hertz"`` or ``"tca"``.
    level
        Sector mesh level (None at fidelity ``tca``).
    cycle
        The headline numbers (:class:`Cycle`).
    checks
        The engagement checks (:class:`Checks`).
    positions
        Per position (:class:`Position`), each with its pairs (:class:`PairLoad`).
    pattern
        ``{"pinion": PatternCentre, "gear": PatternCentre}``: where the bearing pattern is on
        each member's flank (:class:`fegear.output.flank_view.PatternCentre`, flank coordinates in
        mm: ``face_mm`` along the face, ``profile_mm`` up the profile).
    warnings
        Warnings that change the meaning of a headline (and the solver's notes).
    seconds
        Wall time per stage (s).
    cache
        What the run read from the artefact cache and what it built
        (:class:`fegear.store.cache.CacheUse`).
    model
        The result model all of these come from (:class:`fegear.results.GearRunResult`): what
        ``summary.json`` holds, typed; ``summary`` is its JSON document.
    run
        The full run (:class:`fegear.pipeline.run.GearRun`: contact cells, pressure fields,
        and the displacement fields unless the run was made with ``fields=False``) for what
        the typed fields do not hold.
    """

    case: GearCase
    fidelity: str
    level: int | None
    cycle: Cycle
    checks: Checks
    positions: tuple[Position, ...]
    pattern: Mapping[str, PatternCentre]
    warnings: tuple[str, ...]
    seconds: Mapping[str, float]
    cache: CacheUse | None
    model: GearRunResult = field(repr=False, compare=False)
    run: GearRun = field(repr=False, compare=False)
    _views: FlankViews | None = field(default=None, repr=False, compare=False)
    _workers: int | None = field(default=1, repr=False, compare=False)

    @property
    def summary(self) -> dict[str, Any]:
        """The ``summary.json`` document of the result (without its ``files`` list, which
        :meth:`write` fills): :func:`fegear.results.summary_document` of :attr:`model`."""
        doc = summary_document(self.model)
        doc.pop("files", None)
        return doc

    @property
    def pinion_angle_deg(self) -> np.ndarray:
        """``(n,)`` pinion angles of the positions (deg)."""
        return np.array([p.pinion_angle_deg for p in self.positions])

    @property
    def te_unloaded_arcsec(self) -> np.ndarray:
        """``(n,)`` unloaded TE (arcsec)."""
        return np.array([p.te_unloaded_arcsec for p in self.positions])

    @property
    def te_loaded_arcsec(self) -> np.ndarray:
        """``(n,)`` loaded TE (arcsec; NaN at fidelity ``tca``)."""
        return np.array(
            [np.nan if p.te_loaded_arcsec is None else p.te_loaded_arcsec for p in self.positions]
        )

    def write(self, folder: str | Path, overwrite: bool = False) -> tuple[Path, ...]:
        """Write the files of ``fegear run`` into ``folder`` (made if missing): ``summary.json``,
        ``cycle.pvd`` with ``vtk/`` (sectors, contact cells, flank views), the PNGs; each file
        atomically, ``summary.json`` last. The folder holds one run
        (:mod:`fegear.store.outputs`): the files of an earlier run written there are removed
        first, and a folder with files fegear did not write is refused unless ``overwrite``
        (then its other files are kept). A run given two or more workers draws the pictures in
        a second process while the VTK files are written. A run made without its displacement
        fields (``fegear.run(..., fields=False)``) computes them here, while its pictures are
        drawn (:func:`fegear.output.gear_output.write_gear_outputs`): the files and their
        ``summary.json`` are those of ``fegear run`` (the ``mesh`` sizes and ``timings_s``
        included, which the result's own :attr:`model` lacks). Returns the paths.

        Raises
        ------
        InputError
            ``folder`` cannot be written (a file, or no permission), or holds other files and
            ``overwrite`` is False.
        """
        run = self.run
        model = None if run.fields_pending else self.model  # rebuilt with the fields
        with output_run(inspect_output_folder(folder, overwrite, "folder")) as out:
            return tuple(write_gear_outputs(out, run, self._views, model, self._workers))

    def root_stress(self, member: str, what: str = "tension") -> dict[int, np.ndarray]:
        """Root stress of each tooth of ``member`` (``"pinion"``/``"gear"``) that can touch:
        ``{tooth: (n_positions,) MPa}``, ``what`` one of ``"tension"`` (largest maximum
        principal stress in the fillet on the loaded-flank side), ``"compression"`` (smallest
        minimum principal stress on the other side), ``"von_mises"`` (NaN without contact;
        :mod:`fegear.fem.stress`).

        Raises
        ------
        InputError
            A bad ``member`` or ``what``, or a fidelity without stress sectors (``tca``,
            ``hertz``).
        """
        fields = {"tension": "tension_MPa", "compression": "compression_MPa",
                  "von_mises": "von_mises_MPa"}  # fmt: skip
        if what not in fields:
            raise InputError("what", what, f"one of {sorted(fields)}")
        mf = next((m for m in self.run.members if m.name == member), None)
        if member not in ("pinion", "gear"):
            raise InputError("member", member, "'pinion' or 'gear'")
        if mf is None or not mf.root:
            raise InputError("fidelity", self.fidelity, "'hybrid' or 'fe' (cell loads on the FE)")
        return {t: mf.root_series(t, fields[what]) for t in mf.root_teeth}

    def plot_pattern(self, path: str | Path, member: str = "gear") -> Path:
        """The bearing pattern over the cycle on one member's flank as a PNG: the largest
        pressure each point of the flank saw (loaded fidelities), with the working-surface
        outline; ``member`` ``"gear"`` or ``"pinion"``.

        Raises
        ------
        InputError
            A bad ``member``, or a fidelity without contact cells (``tca``, ``hertz``: use
            :func:`plot_patterns` for the contact path).
        """
        if member not in ("pinion", "gear"):
            raise InputError("member", member, "'pinion' or 'gear'")
        if not self._views.patches or (self.run.kind is not None and not self.run.kind.cells):
            raise InputError(
                "fidelity", self.fidelity, "'hybrid' or 'fe' (a fidelity with contact cells)"
            )
        return plot_flank_pattern(
            self._views.frames[member],
            [p[member] for p in self._views.patches],
            Path(path),
            f"{self.case.name}: {self.fidelity} level {self.level}",
            self.cycle.p_max_MPa,
        )


def gear_result(run: GearRun, views: FlankViews, workers: int | None = 1) -> GearResult:
    """The :class:`GearResult` of a run: its result model, built once
    (:func:`fegear.results.build_result`); ``workers``: the processes the run was given (its
    :meth:`~GearResult.write` draws the pictures in a second process with two or more)."""
    model = build_result(run, views.pattern)
    return GearResult(
        case=run.case,
        fidelity=model.fidelity,
        level=model.level,
        cycle=model.cycle,
        checks=model.checks,
        positions=model.positions,
        pattern=dict(views.pattern),
        warnings=tuple(summary_warnings(model)),
        seconds=dict(model.seconds),
        cache=run.cache,
        model=model,
        run=run,
        _views=views,
        _workers=workers,
    )
