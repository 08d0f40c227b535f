"""Every case of ``cases/`` gives the stored ``summary.json`` numbers (tests/reference/).

A refactoring that is meant to leave the results alone must give them to the tolerance of the
solver that makes each number (``summaries.TOLERANCES``: the TCA's Newton tolerance for its
angles, the location of a minimum it implies for its contact points, the bisections' resolution
for the path, the conditioning of the contact problem for the loaded cycle), so the references
hold on any x86-64 machine and BLAS/numpy kernel. The unloaded TCA of the three nominal cases
runs by default, in ``tests/test_validation.py`` (beside the spiral bevel's validation row, whose
run is the nominal spiral bevel's at the TCA: read back from the cache there, not made again in
another process); every case at the TCA and at its own fidelity (level 0) is ``slow``, here.
Regenerate them with ``python tests/reference/summaries.py`` after a change meant to move them.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent / "reference"))
import summaries  # noqa: E402

NOMINAL = ("face_gear_nominal", "spiral_bevel_nominal", "fzg_spur")
CASES = summaries.case_files()


def _check(case: Path, fidelity: str) -> None:
    ref_path = summaries.reference_path(case, fidelity)
    assert ref_path.is_file(), f"no reference {ref_path.name}: run tests/reference/summaries.py"
    ref = json.loads(ref_path.read_text(encoding="utf-8"))
    new = summaries.run_summary(case, fidelity)
    meshes = summaries.mesh_differences(new, ref)
    assert not meshes, (
        "the FE meshes are not the reference's (gmsh made another mesh on another host): "
        "the loaded numbers cannot be compared; regenerate the "
        "references on this machine (python tests/reference/summaries.py)\n" + "\n".join(meshes)
    )
    diff = summaries.differences(new, ref)
    assert not diff, f"{len(diff)} values moved:\n" + "\n".join(diff[:20])


@pytest.mark.slow
@pytest.mark.parametrize(
    "case",
    [c for c in CASES if c.stem not in NOMINAL and c.stem != "hertz_scene"],
    ids=lambda c: c.stem,
)
def test_every_case_gives_the_reference_tca(case):
    _check(case, "tca")


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=lambda c: c.stem)
def test_every_case_gives_the_reference_numbers_at_its_fidelity(case):
    _check(case, "own")


def test_a_moved_number_is_caught():
    """The comparison itself: each number against its own tolerance. An unloaded TE moved by
    1e-5 arcsec (5x the TCA's angular tolerance) is reported, by 1e-7 not; a TCA contact point
    moved by 0.01 mm (3x the location tolerance) is reported, by 1e-4 mm not; a loaded p_max
    moved by 1e-3 relative is reported, by 1e-6 not; an input echoed is exact to 1e-9."""
    ref = {
        "cycle": {"te_pp_unloaded_arcsec": 1.0, "p_max_MPa": 1000.0, "timings_s": {"tca": 3.0}},
        "positions": [{"te_unloaded_arcsec": -2.0, "pairs": [{"contact_point_mm": [40.0]}]}],
        "inputs": {"pair": {"module_mm": 4.5}},
    }
    moved = json.loads(json.dumps(ref))
    moved["cycle"].update(te_pp_unloaded_arcsec=1.0 + 1e-5, p_max_MPa=1001.0)
    moved["cycle"]["timings_s"]["tca"] = 9.0  # not a result
    moved["positions"][0]["te_unloaded_arcsec"] = -2.0 + 1e-7
    moved["positions"][0]["pairs"][0]["contact_point_mm"] = [40.01]
    moved["inputs"]["pair"]["module_mm"] = 4.5 * (1 + 1e-8)
    assert summaries.differences(moved, ref) == [
        ".cycle.p_max_MPa: 1001.0 != 1000.0 (reference)",
        ".cycle.te_pp_unloaded_arcsec: 1.00001 != 1.0 (reference)",
        ".inputs.pair.module_mm: 4.500000045 != 4.5 (reference)",
        ".positions[0].pairs[0].contact_point_mm[0]: 40.01 != 40.0 (reference)",
    ]
    still = json.loads(json.dumps(ref))
    still["cycle"]["p_max_MPa"] = 1000.0 * (1 + 1e-6)
    still["positions"][0]["pairs"][0]["contact_point_mm"] = [40.0001]
    assert summaries.differences(still, ref) == []
    assert summaries.differences({"a": 1}, {"b": 1}) == [
        ".a: only in the new run",
        ".b: missing in the new run",
    ]


def test_every_tolerance_has_its_reason():
    """Each class of numbers names the solver tolerance it follows from; none is looser than a
    percent (a test that cannot fail is no test)."""
    for pattern, rtol, atol, why in summaries.TOLERANCES:
        assert len(why) > 30, pattern.pattern
        # an angle in degrees is held to a percent of a radian
        scale = math.radians(1.0) if "_deg" in pattern.pattern else 1.0
        assert rtol <= 1e-2 and atol * scale <= 1e-2, pattern.pattern
    assert summaries.LOCATION_MM == pytest.approx(2.95e-3, rel=1e-2)
    assert summaries.LOADED_RTOL <= 1e-4
    from fegear.tca.ease_off_pair import GRID  # the ease-off's node tolerance is one node of it

    assert summaries.EASE_OFF_NODE == 1.0 / (GRID[0] * GRID[1])
