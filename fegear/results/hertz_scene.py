"""The result model of a Hertz-scene run: what its ``summary.json`` holds, built once from the
run, written by :mod:`fegear.output.hertz_scene_output` and read by the Python API
(:class:`fegear.api.HertzResult`), and read back from a saved ``summary.json`` into an equal
model (:func:`load_hertz_result`).

The scene (:mod:`fegear.scenes.hertz_scene`) presses a crowned roller on a block; the model holds
the FE contact (peak pressure, patch semi-axes, approach), the closed-form Hertz values
(:mod:`fegear.mechanics.hertz_closed_form`), the relative errors ``FE / Hertz − 1``, and, with a
mesh study, one row per level and the observed convergence rates. Units are in the names (mm, N,
MPa, s).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from fegear.errors import InputError
from fegear.results.records import solver_record, versions
from fegear.scenes.hertz_scene import HertzLevelResult, HertzScene

__all__ = [
    "ERROR_KEYS",
    "HertzContact",
    "HertzInputs",
    "HertzLevel",
    "HertzReference",
    "HertzSceneResult",
    "build_hertz_result",
    "hertz_level",
    "hertz_summary_document",
    "load_hertz_result",
]

#: The quantities compared with Hertz (relative errors ``FE / Hertz − 1``).
ERROR_KEYS = ("p0", "a", "b", "approach")


@dataclass(frozen=True)
class HertzInputs:
    """What the scene was run with: the load (N), the roller's principal radii (mm; the block is
    flat), the moduli (MPa) and Poisson ratios of ``(roller, block)``, the symmetry, the
    fidelity and the level."""

    force_N: float
    roller_radii_mm: tuple[float, float]
    E_MPa: tuple[float, float]
    nu: tuple[float, float]
    symmetry: str
    fidelity: str
    level: int


@dataclass(frozen=True)
class HertzContact:
    """The FE contact at the run's level.

    ``p0_MPa`` is the recovered peak pressure and ``p_max_cell_MPa`` the largest cell pressure;
    ``a_mm``, ``b_mm`` the semi-axes from the second moments of the cell forces, ``a_extent_mm``,
    ``b_extent_mm`` those of the active cells; ``approach_mm`` the rigid approach of the roller's
    axle to the block's table; ``total_force_N`` the sum of the cell forces over the modelled
    fraction (the load, to the solver's residual)."""

    p0_MPa: float
    p_max_cell_MPa: float
    a_mm: float
    b_mm: float
    a_extent_mm: float
    b_extent_mm: float
    approach_mm: float
    n_cells: int
    n_active: int
    total_force_N: float
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class HertzReference:
    """The closed-form Hertz contact of the scene's load: peak pressure (MPa), semi-axes and
    approach (mm)."""

    p0_MPa: float
    a_mm: float
    b_mm: float
    approach_mm: float


@dataclass(frozen=True)
class HertzLevel:
    """One level of a mesh study: grid and element sizes (mm), the FE contact, the relative
    errors against Hertz, the FE size (``dofs`` per body), the timings (s) and whether the
    operators came from the cache."""

    level: int
    fidelity: str
    cells_across_minor: int
    cell_size_mm: float
    element_size_mm: float
    p0_MPa: float
    p_max_cell_MPa: float
    a_mm: float
    b_mm: float
    a_extent_mm: float
    b_extent_mm: float
    approach_mm: float
    error_p0: float
    error_a: float
    error_b: float
    error_approach: float
    n_cells: int
    n_active: int
    dofs: Mapping[str, int]
    seconds: Mapping[str, float]
    cache_hit: bool


@dataclass(frozen=True)
class HertzSceneResult:
    """A Hertz-scene run as ``summary.json`` reports it.

    Attributes
    ----------
    case, kind, fidelity
        The case's name, ``"hertz_scene"`` and the fidelity it ran at.
    inputs, result, hertz
        :class:`HertzInputs`, the FE contact (:class:`HertzContact`) and the closed form
        (:class:`HertzReference`).
    errors
        ``{"p0", "a", "b", "approach"}``: ``FE / Hertz − 1``.
    solver
        Iterations and residuals of the contact solve (:func:`fegear.results.records.
        solver_record`) and the linear-algebra backend.
    dofs, cell_size_mm, element_size_mm
        The FE size (per body) and the grid and element sizes (mm).
    timings_s
        Seconds per stage.
    levels
        The mesh study (:class:`HertzLevel` per level), empty without one.
    convergence_rate
        Observed rates ``|e| ~ h^rate`` of the study (``{"p0", "a", "b"}``), empty without one.
    versions
        Versions of fegear and the libraries that ran.
    """

    case: str
    fidelity: str
    inputs: HertzInputs
    result: HertzContact
    hertz: HertzReference
    errors: Mapping[str, float]
    solver: Mapping[str, Any]
    dofs: Mapping[str, int]
    cell_size_mm: float
    element_size_mm: float
    timings_s: Mapping[str, float]
    levels: tuple[HertzLevel, ...] = ()
    convergence_rate: Mapping[str, float] = field(default_factory=dict)
    versions: Mapping[str, Any] = field(default_factory=dict)
    kind: str = "hertz_scene"


def hertz_level(r: HertzLevelResult) -> HertzLevel:
    """The study row of one level's run."""
    return HertzLevel(
        level=r.level,
        fidelity=r.fidelity,
        cells_across_minor=r.cells_across_minor,
        cell_size_mm=r.cell_size_mm,
        element_size_mm=r.h_fine_mm,
        p0_MPa=r.p0_MPa,
        p_max_cell_MPa=r.p_max_cell_MPa,
        a_mm=r.a_mm,
        b_mm=r.b_mm,
        a_extent_mm=r.a_extent_mm,
        b_extent_mm=r.b_extent_mm,
        approach_mm=r.approach_mm,
        error_p0=r.error("p0"),
        error_a=r.error("a"),
        error_b=r.error("b"),
        error_approach=r.error("approach"),
        n_cells=r.n_cells,
        n_active=r.n_active,
        dofs=dict(r.dofs),
        seconds=dict(r.seconds),
        cache_hit=r.cache_hit,
    )


def build_hertz_result(
    case_name: str,
    scene: HertzScene,
    r: HertzLevelResult,
    study: Sequence[HertzLevelResult] = (),
    rate: Mapping[str, float] | None = None,
) -> HertzSceneResult:
    """The model of a Hertz-scene run: ``r`` the run's level, ``study`` the levels of a mesh
    study and ``rate`` their observed convergence rates."""
    return HertzSceneResult(
        case=case_name,
        fidelity=r.fidelity,
        inputs=HertzInputs(
            force_N=scene.force_N,
            roller_radii_mm=tuple(scene.roller_radii_mm),
            E_MPa=(scene.E_roller_MPa, scene.E_block_MPa),
            nu=(scene.nu_roller, scene.nu_block),
            symmetry=scene.symmetry,
            fidelity=r.fidelity,
            level=r.level,
        ),
        result=HertzContact(
            p0_MPa=r.p0_MPa,
            p_max_cell_MPa=r.p_max_cell_MPa,
            a_mm=r.a_mm,
            b_mm=r.b_mm,
            a_extent_mm=r.a_extent_mm,
            b_extent_mm=r.b_extent_mm,
            approach_mm=r.approach_mm,
            n_cells=r.n_cells,
            n_active=r.n_active,
            total_force_N=float(r.force.sum() / r.modelled_fraction),
            warnings=tuple(r.warnings),
        ),
        hertz=HertzReference(
            p0_MPa=r.hertz.p0_MPa,
            a_mm=r.hertz.a_mm,
            b_mm=r.hertz.b_mm,
            approach_mm=r.hertz.approach_mm,
        ),
        errors={k: r.error(k) for k in ERROR_KEYS},
        solver={**solver_record(r.solution), "backend": r.backend},
        dofs=dict(r.dofs),
        cell_size_mm=r.cell_size_mm,
        element_size_mm=r.h_fine_mm,
        timings_s=dict(r.seconds),
        levels=tuple(hertz_level(x) for x in study),
        convergence_rate=dict(rate or {}),
        versions=versions(),
    )


def _plain(obj: Any) -> dict[str, Any]:
    return {f.name: _json(getattr(obj, f.name)) for f in fields(obj)}


def _json(v: Any) -> Any:
    if isinstance(v, tuple):
        return [_json(x) for x in v]
    if isinstance(v, Mapping):
        return {k: _json(x) for k, x in v.items()}
    return v


def hertz_summary_document(m: HertzSceneResult) -> dict[str, Any]:
    """The ``summary.json`` document of the model (JSON-ready)."""
    i = m.inputs
    return {
        "case": m.case,
        "kind": m.kind,
        "fidelity": m.fidelity,
        "units": {"length": "mm", "force": "N", "pressure": "MPa"},
        "inputs": {
            "force_N": i.force_N,
            "radii_mm": [list(i.roller_radii_mm), [None, None]],
            "bodies": ["roller", "block"],
            "E_MPa": list(i.E_MPa),
            "nu": list(i.nu),
            "symmetry": i.symmetry,
            "fidelity": i.fidelity,
            "level": i.level,
        },
        "result": _plain(m.result),
        "hertz": _plain(m.hertz),
        "errors": dict(m.errors),
        "solver": dict(m.solver),
        "mesh": {
            "dofs": dict(m.dofs),
            "cell_size_mm": m.cell_size_mm,
            "element_size_mm": m.element_size_mm,
        },
        "timings_s": dict(m.timings_s),
        "levels": [_plain(x) for x in m.levels],
        "convergence_rate": dict(m.convergence_rate),
        "versions": _json(m.versions),
    }


def _take(cls: type, doc: Mapping[str, Any], where: str) -> Any:
    names = [f.name for f in fields(cls)]
    missing = [n for n in names if n not in doc and n != "warnings"]
    if missing:
        raise InputError(where, sorted(doc), f"the keys {names} of a Hertz-scene summary.json")
    values = {n: doc[n] for n in names if n in doc}
    if "warnings" in values:
        values["warnings"] = tuple(values["warnings"])
    return cls(**values)


def load_hertz_result(source: str | Path | Mapping[str, Any]) -> HertzSceneResult:
    """The model of a saved Hertz-scene run: ``source`` a ``summary.json``, the folder holding
    it, or its parsed document. Raises :class:`InputError` for a document of another kind or
    with a key missing."""
    if isinstance(source, Mapping):
        doc = source
    else:
        path = Path(source)
        if path.is_dir():
            path = path / "summary.json"
        if not path.is_file():
            raise InputError("summary", str(path), "a summary.json of a Hertz-scene run")
        doc = json.loads(path.read_text(encoding="utf-8"))
    if doc.get("kind") != "hertz_scene":
        raise InputError("kind", doc.get("kind"), "'hertz_scene'")
    try:
        i = doc["inputs"]
        mesh = doc["mesh"]
        return HertzSceneResult(
            case=doc["case"],
            kind=doc["kind"],
            fidelity=doc["fidelity"],
            inputs=HertzInputs(
                force_N=i["force_N"],
                roller_radii_mm=tuple(i["radii_mm"][0]),
                E_MPa=tuple(i["E_MPa"]),
                nu=tuple(i["nu"]),
                symmetry=i["symmetry"],
                fidelity=i["fidelity"],
                level=i["level"],
            ),
            result=_take(HertzContact, doc["result"], "result"),
            hertz=_take(HertzReference, doc["hertz"], "hertz"),
            errors=dict(doc["errors"]),
            solver=dict(doc["solver"]),
            dofs=dict(mesh["dofs"]),
            cell_size_mm=mesh["cell_size_mm"],
            element_size_mm=mesh["element_size_mm"],
            timings_s=dict(doc["timings_s"]),
            levels=tuple(_take(HertzLevel, row, "levels") for row in doc["levels"]),
            convergence_rate=dict(doc["convergence_rate"]),
            versions=dict(doc["versions"]),
        )
    except (KeyError, IndexError, TypeError) as exc:
        raise InputError("summary", repr(exc), "a complete Hertz-scene summary.json") from exc
