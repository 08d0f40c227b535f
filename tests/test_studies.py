"""Installation-error studies at warm speed (issue 29): what a study changes does not rebuild
what does not depend on it.

A member's sector mesh and its compliance operator depend on the member's design, the tooth
count, the mesh level, the working side and the material; the installation errors only move
the contact over the flank, the torque only scales it, and the fidelities at one level read the
same flank block (``docs/ltca/studies.md``). Asserted through the cache's own records of what a
run read and built (:func:`fegear.store.cache.record_cache_use`), never by timing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import fegear
from fegear.store.cache import clear_cache

REPO = Path(__file__).resolve().parents[1]
FACE_GEAR = REPO / "cases" / "face_gear_nominal.toml"


@pytest.fixture(scope="module")
def seed_case():
    """The seed face gear at 2 positions (the models do not depend on the positions), run
    once at ``hybrid`` level 0 so that its meshes and operators are in the session's cache."""
    case = fegear.load_case(FACE_GEAR).replace(n_positions=2)
    fegear.run(case, workers=1)
    return case


@pytest.mark.parametrize(
    "what, change, fidelity",
    [
        ("shaft angle", {"errors": {"dgamma_deg": 0.02}}, None),
        ("offset", {"errors": {"dE_mm": 0.1}}, None),
        ("pinion axial", {"errors": {"dA1_mm": 0.5}}, None),
        ("gear axial", {"errors": {"dA2_mm": -0.1}}, None),
        ("torque", {"torque2_Nm": 1000.0}, None),
        ("hertz", {}, "hertz"),
        ("fe", {}, "fe"),
    ],
)
def test_a_study_reads_the_meshes_and_operators_of_the_nominal_run(seed_case, what, change,
                                                                   fidelity):  # fmt: skip
    errors = change.pop("errors", None)
    case = seed_case.with_errors(**errors) if errors else seed_case
    case = case.replace(**change) if change else case
    use = fegear.run(case, fidelity=fidelity, workers=1).run.cache
    # nothing of the FE model is built again: every mesh and operator block is a hit
    assert "mesh" not in use.built and "compliance" not in use.built, (what, use.built)
    assert use.hits["mesh"] == 2, what  # both sectors
    # hybrid reads the flank block and one layer block per loaded tooth (3 per member on the
    # seed's 5-tooth sectors); fe and hertz read the flank block alone, the same entry
    assert use.hits["compliance"] == (2 if fidelity in ("fe", "hertz") else 8), (what, use.hits)
    if errors:  # a new installation error: new TCAs (the cycle's, the zone's), the phase of
        # the error-free pair read
        assert use.built.get("tca", 0) >= 1 and "phase" not in use.built, (what, use)
        assert use.hits.get("phase", 0) >= 1, (what, use)
    # the loaded cycle is keyed on the installation, the torque and the fidelity: solved again
    assert use.built.get("cycle") == 1 and "cycle" not in use.hits, (what, use)


def test_a_process_builds_each_member_model_once(seed_case):
    """A process running a study (a sweep worker, a script over installation errors) keeps the
    member models of its last run (``fegear.ltca.analysis._MODELS``): the next run of the same
    members is given the very same objects, its cache record counting them as the hits reading
    them again would be (the parametrized test above asserts those counts)."""
    a = fegear.run(seed_case.with_errors(dgamma_deg=0.01), workers=1).run
    b = fegear.run(seed_case.with_errors(dgamma_deg=-0.01), workers=1).run
    assert b.cycle.models.pinion is a.cycle.models.pinion
    assert b.cycle.models.gear is a.cycle.models.gear
    assert "mesh" not in b.cache.built and b.cache.hits["mesh"] == 2, b.cache


def _cycle_numbers(result):
    """Every number of the loaded cycle that the solve produces, flattened: TEs, the lag, the
    cell forces and gaps of every position."""
    c = result.run.cycle
    parts = [c.te_loaded_arcsec, c.te_unloaded_arcsec]
    for p in c.positions:
        parts += [np.atleast_1d(p.theta)]
        if p.solution is not None:
            parts += [p.solution.force, p.solution.gap]
        parts += [cells.centers.ravel() for cells in p.cells]
    return np.concatenate([np.asarray(x, dtype=float).ravel() for x in parts])


def test_the_same_run_again_reads_its_cycle_and_fields_bit_for_bit(seed_case):
    """A run repeated with the same inputs reads its loaded cycle and displacement fields back
    (``docs/ltca/studies.md``, "The same run again") without reading a mesh or an operator, and
    they are the ones a fresh solve gives, bit for bit (floats are stored by their repr)."""
    case = seed_case.replace(torque2_Nm=1500.0)
    first = fegear.run(case, workers=1)
    assert first.run.cache.built.get("cycle") == 1
    again = fegear.run(case, workers=1)
    use = again.run.cache
    assert use.built == {}, use
    assert use.hits.get("cycle") == 1 and use.hits.get("member_fields") == 1, use
    assert "mesh" not in use.hits and "compliance" not in use.hits, use
    fresh = fegear.run(case, workers=1, reuse=False)  # solved again, the cache left alone
    assert "cycle" not in fresh.run.cache.hits and "cycle" not in fresh.run.cache.built
    assert "member_fields" not in fresh.run.cache.hits
    np.testing.assert_array_equal(_cycle_numbers(again), _cycle_numbers(fresh))
    np.testing.assert_array_equal(_cycle_numbers(first), _cycle_numbers(fresh))
    for a, b in zip(again.run.members, fresh.run.members, strict=True):
        assert a.name == b.name
        np.testing.assert_array_equal(a.displacement, b.displacement)
        np.testing.assert_array_equal(a.points, b.points)


def test_fields_of_a_cycle_read_back_are_those_of_its_models(seed_case):
    """A cycle read from the cache has no models; when its fields are not in the cache either,
    the models are built (read) on the cycle's contact zone and the fields computed: the same
    fields as the run that solved the cycle."""
    case = seed_case.with_errors(dE_mm=0.05)
    first = fegear.run(case, workers=1)
    clear_cache("member_fields")
    again = fegear.run(case, workers=1)
    use = again.run.cache
    assert use.hits.get("cycle") == 1 and use.built.get("member_fields") == 1, use
    assert use.hits.get("compliance") == 8 and "compliance" not in use.built, use
    for a, b in zip(again.run.members, first.run.members, strict=True):
        np.testing.assert_array_equal(a.displacement, b.displacement)


def test_the_same_run_again_copies_its_pictures(seed_case, tmp_path, monkeypatch):
    """The pictures of a run are kept in the cache under its cycle and its summary
    (:mod:`fegear.output.picture_cache`): the same run written again copies the bytes drawn the
    first time and draws nothing; another title (the case's name) or a run solved again without
    the cache (no cycle key) draws them."""
    from fegear.output import gear_output

    drawn = []
    draw = gear_output.loaded_plots
    monkeypatch.setattr(gear_output, "loaded_plots", lambda *a: drawn.append(1) or draw(*a))
    case = seed_case.replace(torque2_Nm=1200.0)
    fegear.run(case, workers=1).write(tmp_path / "first")
    assert len(drawn) == 1
    fegear.run(case, workers=1).write(tmp_path / "again")
    assert len(drawn) == 1  # copied, not drawn
    pngs = sorted(p.name for p in (tmp_path / "first").glob("*.png"))
    assert pngs and pngs == sorted(p.name for p in (tmp_path / "again").glob("*.png"))
    for name in pngs:
        assert (tmp_path / "first" / name).read_bytes() == (tmp_path / "again" / name).read_bytes()
    fegear.run(case.replace(name="renamed"), workers=1).write(tmp_path / "renamed")
    assert len(drawn) == 2  # the titles quote the name: drawn
    fegear.run(case, workers=1, reuse=False).write(tmp_path / "fresh")
    assert len(drawn) == 3  # no cycle key: drawn, nothing kept
