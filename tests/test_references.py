"""Every case of ``cases/`` gives the stored ``summary.json`` numbers (tests/reference/).

A refactoring that is meant to leave the results alone must give them to 1e-9 relative: the runs
are deterministic on one machine (same meshes, same cached operators, workers bitwise equal), so
the tolerance only admits the round-off of a reordered sum. The unloaded TCA of the three
nominal cases runs by default; every case at the TCA and at its own fidelity (level 0) is
``slow``. The references belong to the CI machine (gmsh meshes differ between hosts):
regenerate them with ``python tests/reference/summaries.py`` after a change meant to move them.
"""

from __future__ import annotations

import json
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
    diff = summaries.differences(summaries.run_summary(case, fidelity), ref)
    assert not diff, f"{len(diff)} values moved:\n" + "\n".join(diff[:20])


@pytest.mark.parametrize("name", NOMINAL)
def test_the_nominal_cases_give_the_reference_tca(name):
    _check(summaries.CASES / f"{name}.toml", "tca")


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
    """The comparison itself: a relative change of 1e-8 is reported, 1e-12 is not."""
    ref = {"cycle": {"te_pp_loaded_arcsec": 1.0, "timings_s": {"tca": 3.0}}, "positions": [1.5]}
    moved = {"cycle": {"te_pp_loaded_arcsec": 1.0 + 1e-8, "timings_s": {"tca": 9.0}},
             "positions": [1.5 * (1 + 1e-12)]}  # fmt: skip
    assert summaries.differences(moved, ref) == [
        ".cycle.te_pp_loaded_arcsec: 1.00000001 != 1.0 (reference)"
    ]
    assert summaries.differences({"a": 1}, {"b": 1}) == [
        ".a: only in the new run",
        ".b: missing in the new run",
    ]
