"""The result model (:mod:`fegear.results`): built once from a run, written as ``summary.json``
and read back into the same model.

- Round trip: the model built from a run, written by the command's writer and loaded back with
  :func:`fegear.results.load_result`, equals the model (every float exact: JSON keeps a float's
  shortest round-trip text), for a loaded run and for the unloaded TCA.
- The parts a nominal run does not exercise (excluded positions, an edge p_max, solver notes
  beside the run's warnings) survive the round trip too.
- The API's result is the model (no re-parsing of the document): its headlines are the model's
  objects.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

import fegear
from fegear.errors import InputError
from fegear.results import (
    Excluded,
    GearRunResult,
    load_result,
    result_from_summary,
    summary_document,
)

REPO = Path(__file__).resolve().parents[1]
FZG = REPO / "cases" / "fzg_spur.toml"
N_FZG = 5


@pytest.fixture(scope="module", params=["hybrid", "tca"])
def written(request, tmp_path_factory):
    """FZG over 5 positions at ``hybrid`` level 0 and at ``tca``, written by ``result.write``."""
    case = fegear.load_case(FZG).replace(n_positions=N_FZG)
    result = fegear.run(case, fidelity=request.param, level=0, workers=1)
    folder = tmp_path_factory.mktemp(f"model_{request.param}")
    result.write(folder)
    return result, folder


def test_build_write_load_gives_the_same_model(written):
    result, folder = written
    loaded = load_result(folder / "summary.json")
    assert isinstance(loaded, GearRunResult)
    for f in dataclasses.fields(GearRunResult):  # field by field first: a readable failure
        assert getattr(loaded, f.name) == getattr(result.model, f.name), f.name
    assert loaded == result.model
    assert load_result(folder) == result.model  # the run's folder reads the same


def test_the_summary_is_the_document_of_the_model(written):
    result, folder = written
    doc = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    files = doc["files"]
    assert doc == json.loads(json.dumps(summary_document(result.model, files)))
    assert files[-1] == "summary.json"


def test_the_api_result_is_the_model(written):
    result, _ = written
    m = result.model
    assert result.cycle is m.cycle and result.checks is m.checks
    assert result.positions is m.positions
    assert result.fidelity == m.fidelity and result.level == m.level
    assert set(result.pattern) == {"pinion", "gear"} == set(m.pattern)
    if m.loaded:
        assert m.cycle.te_pp_loaded_positions_used == N_FZG  # nominal FZG: all usable
        assert all(q.torque_Nm is not None for p in m.positions for q in p.pairs)
    else:
        assert m.cycle.te_pp_loaded_arcsec is None and m.cycle.contact_ratio_reason
        assert all(q.force_N is None and q.backlash_mm is not None
                   for p in m.positions for q in p.pairs)  # fmt: skip


def test_round_trip_of_excluded_positions_edges_and_notes(written):
    """A model with what the nominal run lacks: an excluded (degenerate) position, an edge
    p_max and solver notes, which ``summary.json`` appends to the run's warnings."""
    result, _ = written
    m = result.model
    if not m.loaded:
        pytest.skip("the loaded document's parts")
    p0 = dataclasses.replace(m.positions[0], warnings=("note b", "note a"), status="degenerate",
                             status_reason="one cell across")  # fmt: skip
    p1 = dataclasses.replace(m.positions[1], warnings=("note a",))
    cyc = dataclasses.replace(
        m.cycle,
        excluded_positions=(
            Excluded(0, m.positions[0].pinion_angle_deg, "degenerate", "one cell across"),
        ),  # fmt: skip
        te_pp_loaded_positions_used=N_FZG - 1,
        p_max_edge_MPa=1234.5,
        p_max_edge_position=1,
        p_max_edge_pair=(0, 0),
        p_max_edge_edges=("pinion tip",),
        positions_with_edge_contact=(1,),
    )
    odd = dataclasses.replace(
        m, cycle=cyc, positions=(p0, p1, *m.positions[2:]), warnings=("a run warning",)
    )
    doc = json.loads(json.dumps(summary_document(odd)))
    assert doc["warnings"] == ["a run warning", "note a", "note b"]
    assert doc["cycle"]["p_max_edge_at"] == {"position": 1, "pair": [0, 0],
                                             "edges": ["pinion tip"]}  # fmt: skip
    assert result_from_summary(doc) == odd


def test_load_result_refuses_what_is_not_a_gear_summary(tmp_path):
    with pytest.raises(InputError):
        load_result(tmp_path / "missing.json")
    (tmp_path / "summary.json").write_text('{"case": "hertz", "p0_MPa": 1.0}', encoding="utf-8")
    with pytest.raises(InputError):
        load_result(tmp_path)
