"""Reference ``summary.json`` numbers of every case in ``cases/``, and their comparison.

The references guard refactoring: a change that is meant to leave the results alone must give
the same numbers to the tolerance of the solver that makes each of them
(:data:`TOLERANCES`), so that they hold on any x86-64 machine, whatever kernels its BLAS and
numpy pick (the TCA of the three nominal cases moved by up to 2e-6 relative between this
machine and the one that made the references, and between OpenBLAS/MKL/numpy kernels on one
machine: ``OPENBLAS_CORETYPE``, ``MKL_ENABLE_INSTRUCTIONS``, ``NPY_DISABLE_CPU_FEATURES``).
Regenerate them after a change that is meant to move the numbers::

    python tests/reference/summaries.py            # every case, tca and the case's fidelity
    python tests/reference/summaries.py tca        # the unloaded TCA only (fast)

What is compared: every number and string of ``summary.json`` except what describes the run
rather than its result (timings, cache use, software versions, file lists, paths) and the
solver's round-off measures (residuals, the smallest active force).

The runs take the test session's environment (``tests/conftest.py``): dense BLAS on one thread
and the positions in this process.

The unloaded TCA is computed on the exact flanks and holds on any machine. The loaded numbers
(the case's own fidelity) stand on the FE meshes, and gmsh (the same version) made another mesh
on another host (the seed face gear's gear sector: 8019 tetrahedra against the reference's 7987;
its loaded TE p-p then differs by 0.25 %, the pressures at the edges by up to 16 %): those
references hold on the machine that made them, and a different mesh is reported as such
(:func:`mesh_differences`), not as moved numbers.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as tests/conftest.py, before numpy loads
os.environ.setdefault("FEGEAR_WORKERS", "1")

import dataclasses  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import re  # noqa: E402
import sys  # noqa: E402
from collections.abc import Iterator
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"
STORE = Path(__file__).resolve().parent / "summaries"
#: keys of summary.json that describe the run, not its result
IGNORED = {"timings_s", "cache", "versions", "files", "source", "seconds"}
#: suffix of the solver's residuals: round-off measures (1e-16 against 1e-13 is no change)
ROUND_OFF = "_residual"
#: the smallest active cell force: a round-off measure of the contact solve (how close the
#: active set came to losing a cell), not a result
ROUND_OFF_KEYS = {"min_active_force_N"}
#: default relative tolerance: inputs echoed, counts, what no solver computes
RTOL = 1e-9
#: default absolute floor, in the summary's units (mm, arcsec, MPa, N)
ATOL = 1e-12

# The solvers' own tolerances, and what the reference cases' geometry makes of them.
#: TCA: the Newton solves on the exact flanks stop at this residual (mm;
#: ``fegear.tca.solve.TOL_MM``)
TCA_TOL_MM = 1e-10
#: the smallest lever of the cases' contact points about an axis (mm: FZG pinion base radius
#: 33.8, spiral bevel pinion toe ~20, face gear 470+): an angle is solved to TCA_TOL_MM / 10 mm
LEVER_MIN_MM = 10.0
#: the flattest contact of the cases, half the relative normal curvature along the path (1/mm):
#: the seed face gear, A = 2.31e-5 (the spiral bevel 6.9e-4; the FZG pair is a line contact,
#: placed at the centre of its line); and the largest across it, B = 0.057 (FZG)
A_MIN, B_MAX = 2.3e-5, 0.06
#: a minimum of the angular gap, a separation A x² along the flattest direction solved to
#: TCA_TOL_MM, is located to sqrt(2 TCA_TOL_MM / A_MIN) = 2.9e-3 mm (both ends of the
#: difference off by the tolerance): the TCA's contact points and what is measured from them
LOCATION_MM = math.sqrt(2.0 * TCA_TOL_MM / A_MIN)
_RAD = {"arcsec": math.pi / 180.0 / 3600.0, "deg": math.pi / 180.0, "urad": 1e-6}
ANGLE_RAD = TCA_TOL_MM / LEVER_MIN_MM
#: the contact path's ends: bisection on the pinion angle to cycle / (n 9^4), n >= 9 positions;
#: the handover's interior fraction to cycle / (48 8^3) (fegear/tca/path.py, engagement.py)
PATH_RATIO = 2.0 / (9 * 9**4)
HANDOVER_FRACTION = 2.0 / (48 * 8**3)
#: the loaded cycle: the contact solver is direct (an active set solved exactly, no iteration
#: tolerance), so its results carry the round-off of the operators and of the TCA's gaps and
#: contact points, amplified by the conditioning of the contact problem on fine cells; the
#: amplification measured on the cases: up to 2.4e-5 relative (FZG edge pressure, another
#: machine; 4.3e-7 between one and two BLAS threads)
LOADED_RTOL = 1e-4
#: a line-load bin without load (N/mm): the forces' round-off, up to 1.5e-6 N/mm measured
#: between two processes on ISO/TR 6336-30 example 1, against loads of 100-800 N/mm
LINE_LOAD_ATOL = 1e-4
#: the semi-axes (mm) and cells across of a patch of one loaded cell: 0 to round-off (4.5e-10 mm
#: measured between two processes)
PATCH_ATOL = 1e-6
#: a loaded-TE mesh order near zero (arcsec): LOADED_RTOL of a lag of some 10-100″ spread over
#: the orders
HARMONIC_ATOL_ARCSEC = 1e-3

#: the TCA's contact ellipses: the principal curvatures are central second differences of the
#: exact flanks (``fegear.tca.ellipse.contact_curvature``), accurate to 3e-3 of the relative
#: curvature (its docstring: against a quadratic fit of the exact separation); between kernels
#: they move within that (the face gear's gear flank, nearly flat: 1.9e-5 1/mm of 4.5e-3), and
#: the axes, p0 and approach made from them with it. The orientations: 3e-3 rad
ELLIPSE_RTOL = 3e-3
ELLIPSE_ATOL = ELLIPSE_RTOL * B_MAX

#: the ease-off (fegear/tca/ease_off.py): a gap θ_e solved to ANGLE_RAD times an arm of at most
#: 500 mm (the face gear) is 5e-9 mm; its fit is linear in the gaps. 20 x that, in µm and mm
EASE_OFF_ATOL_UM = 1e-4
#: a node of the ease-off's grid on the border of the gear's working flank may gain or lose its
#: contact position with round-off: one node of the grid (21 x 41, fegear.tca.ease_off_pair.GRID)
EASE_OFF_NODE = 1.0 / (21 * 41)

#: ``(path pattern, rtol, atol, reason)``: the first pattern matching a leaf's path decides
TOLERANCES: list[tuple[re.Pattern[str], float, float, str]] = [
    (re.compile(p), rtol, atol, why)
    for p, rtol, atol, why in [
        (r"\.(te_unloaded_arcsec|te_pp_unloaded_arcsec)$", 0.0, ANGLE_RAD / _RAD["arcsec"],
         "an unloaded TE is a closing rotation: TCA_TOL_MM over a lever >= LEVER_MIN_MM"),
        (r"\.gear_angle_deg$", 0.0, ANGLE_RAD / _RAD["deg"],
         "the gear angle holds the closing rotation: TCA_TOL_MM over LEVER_MIN_MM"),
        (r"\.backlash_mm$", LOCATION_MM / LEVER_MIN_MM, B_MAX * LOCATION_MM**2 + 2 * TCA_TOL_MM,
         "a separation at a point located to LOCATION_MM: the lever moves by LOCATION_MM / "
         "LEVER_MIN_MM of it, a tied pair's separation grows by B_MAX LOCATION_MM^2"),
        (r"^\.cycle\.contact_ratio_unloaded$", 0.0, PATH_RATIO,
         "the path's ends are bisected to cycle / (n 9^4), both ends"),
        (r"^\.cycle\.unloaded_interior_contact_fraction$", 0.0, HANDOVER_FRACTION,
         "the handover is bisected to cycle / (48 8^3), both ends"),
        (r"^\.cycle\.hertz_p0_max_MPa$", LOCATION_MM / LEVER_MIN_MM, 0.0,
         "Hertz at a point located to LOCATION_MM: its force arm moves by LOCATION_MM / "
         "LEVER_MIN_MM (the curvatures vary over the path's length, >= 8 mm, less)"),
        (r"\.contact_ellipses?\.point_mm", 0.0, LOCATION_MM,
         "the TCA's contact point, located to LOCATION_MM"),
        (r"\.contact_ellipses?\.(normal|principal_directions)", 0.0, ELLIPSE_RTOL,
         "unit vectors: the curvature tensor's directions, to ELLIPSE_RTOL rad"),
        (r"\.contact_ellipses?\..*_deg\b", 0.0, math.degrees(ELLIPSE_RTOL),
         "an orientation of the curvature tensor, to ELLIPSE_RTOL rad"),
        (r"\.contact_ellipses?\.", ELLIPSE_RTOL, ELLIPSE_ATOL,
         "finite-difference curvatures and what is made of them, to ELLIPSE_RTOL of B"),
        (r"^\.cylindrical\.load\.", LOADED_RTOL, LINE_LOAD_ATOL,
         "line loads, KHβ and stiffnesses of the loaded cycle's forces, to LOADED_RTOL; a bin "
         "without load reads the forces' round-off: LINE_LOAD_ATOL"),
        (r"^\.cycle\.te_harmonics\.loaded\.", LOADED_RTOL, HARMONIC_ATOL_ARCSEC,
         "the loaded TE's mesh orders: its positions' values to LOADED_RTOL through a DFT or "
         "fit; an order near zero to HARMONIC_ATOL_ARCSEC"),
        (r"\.(semi_m[a-z]+_mm|cells_across_patch)$", LOADED_RTOL, PATCH_ATOL,
         "a patch's axes, to LOADED_RTOL; a patch of one cell measures 0 to round-off"),
        (r"^\.validity\.checks\[\d+\]\.value$", LOADED_RTOL, ATOL,
         "the validity checks read the loaded cycle's approach and p_max"),
        (r"^\.ease_off\.(design\.)?defined_fraction$", 0.0, EASE_OFF_NODE,
         "a node on the border of the gear's working flank: EASE_OFF_NODE"),
        (r"^\.ease_off\.(design\.)?fit\.nodes$", 2e-3, 0.0,
         "the fit's nodes: one on the border of the gear's working flank, of >= 500 defined"),
        (r"^\.ease_off\..*_mm$", 0.0, 1e-3 * EASE_OFF_ATOL_UM,
         "the ease-off's level: a gap to EASE_OFF_ATOL_UM (in mm)"),
        (r"^\.ease_off\.", 0.0, EASE_OFF_ATOL_UM,
         "gaps solved to EASE_OFF_ATOL_UM and their linear fit"),
        (r"^\.(positions\[\d+\]\.pairs\[\d+\]\.contact_point_mm|cycle\.path_|pattern\.)",
         0.0, LOCATION_MM,
         "the TCA's contact points, located to LOCATION_MM, and what is measured from them (the "
         "loaded force centroids: the cells around them carry forces to LOADED_RTOL)"),
    ]
]  # fmt: skip
#: the numbers of the loaded cycle (own fidelity): LOADED_RTOL, and the TCA's location floor for
#: coordinates near zero
LOADED = re.compile(
    r"\.(te_loaded_arcsec|te_loaded_urad|elastic_lag_arcsec|te_pp_loaded_arcsec|"
    r"p_[a-z_]*MPa|force_N|total_force_N|load_share|torque_Nm|semi_m[a-z]+_mm|"
    r"cells_across_patch|g_max_mm|max_penetration_mm|contact_ratio_loaded|gap_mm|"
    r"root_stress[a-z_]*|[a-z_]*stress[a-z_]*MPa|stress_equilibrium)"
)


def tolerance(path: str) -> tuple[float, float]:
    """``(rtol, atol)`` of the leaf at ``path`` (:data:`TOLERANCES`; the loaded cycle's numbers
    :data:`LOADED_RTOL`; else :data:`RTOL`, :data:`ATOL`)."""
    for pattern, rtol, atol, _ in TOLERANCES:
        if pattern.search(path):
            return rtol, atol
    if LOADED.search(path):
        return LOADED_RTOL, ATOL
    return RTOL, ATOL


def case_files() -> list[Path]:
    """Every TOML case of ``cases/``."""
    return sorted(CASES.glob("*.toml"))


def reference_path(case: Path, fidelity: str) -> Path:
    """Where the reference of ``case`` run at ``fidelity`` (``"tca"`` or ``"own"``) lives."""
    return STORE / f"{case.stem}.{fidelity}.json"


def run_summary(case: Path, fidelity: str) -> dict[str, Any]:
    """``summary.json`` of ``case`` at level 0, at ``fidelity`` (``"own"``: the case's)."""
    import fegear

    c = fegear.load_case(case)
    if c.__class__.__name__ == "HertzCase":
        res = fegear.run(c.replace(level=0, study_levels=()))
        keep = (int, float, str, dict)
        doc = {f.name: getattr(res, f.name) for f in dataclasses.fields(res)}
        doc = {k: v for k, v in doc.items() if isinstance(v, keep) and k != "case"}
        return json.loads(json.dumps(doc, default=float))
    if fidelity == "tca":
        res = fegear.run(c, fidelity="tca")
    else:
        res = fegear.run(c, level=0)
    return json.loads(json.dumps(res.summary, default=float))


def leaves(doc: Any, path: str = "") -> Iterator[tuple[str, Any]]:
    """``(path, value)`` of every compared leaf of a summary."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            if k not in IGNORED and k not in ROUND_OFF_KEYS and not k.endswith(ROUND_OFF):
                yield from leaves(v, f"{path}.{k}")
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from leaves(v, f"{path}[{i}]")
    else:
        yield path, doc


def mesh_differences(new: dict[str, Any], ref: dict[str, Any]) -> list[str]:
    """The sizes of the FE meshes (``mesh.<member>.tets``, ``vertices``) that differ."""
    a = {k: v for k, v in leaves(new) if k.startswith(".mesh.")}
    b = {k: v for k, v in leaves(ref) if k.startswith(".mesh.")}
    return [
        f"{k}: {a.get(k)!r} != {b.get(k)!r} (reference)"
        for k in sorted(a | b)
        if a.get(k) != b.get(k)
    ]


def differences(new: dict[str, Any], ref: dict[str, Any]) -> list[str]:
    """The leaves of ``new`` that differ from ``ref`` (and those only one of them has)."""
    a, b = dict(leaves(new)), dict(leaves(ref))
    out = [f"{k}: only in the new run" for k in a.keys() - b.keys()]
    out += [f"{k}: missing in the new run" for k in b.keys() - a.keys()]
    for k in sorted(a.keys() & b.keys()):
        x, y = a[k], b[k]
        if isinstance(x, float | int) and isinstance(y, float | int) and not isinstance(x, bool):
            if math.isnan(x) and math.isnan(y):
                continue
            rtol, atol = tolerance(k)
            if not math.isclose(x, y, rel_tol=rtol, abs_tol=atol):
                out.append(f"{k}: {x!r} != {y!r} (reference)")
        elif x != y:
            out.append(f"{k}: {x!r} != {y!r} (reference)")
    return out


def main(argv: list[str]) -> None:
    fidelities = argv or ["tca", "own"]
    STORE.mkdir(exist_ok=True)
    for case in case_files():
        for fid in fidelities:
            if fid == "tca" and case.stem == "hertz_scene":
                continue
            doc = run_summary(case, fid)
            path = reference_path(case, fid)
            path.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n", encoding="utf-8")
            print(path, flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
