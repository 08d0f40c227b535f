"""The Hertz scene's result model (:mod:`fegear.results.hertz_scene`): built once from the run,
read by the API, written as ``summary.json`` by the scene's writer and read back into the same
model.

- Round trip: the model written by :meth:`fegear.api.HertzResult.write` and loaded back with
  :func:`~fegear.results.hertz_scene.load_hertz_result` equals the model, every float exact
  (JSON keeps a float's shortest round-trip text), with a two-level study.
- The API's numbers are the model's, and the errors are what they say: ``FE / Hertz − 1``.
- A summary of another kind is refused, naming the key.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

import fegear
from fegear.errors import InputError
from fegear.results import HertzSceneResult, hertz_summary_document, load_hertz_result

REPO = Path(__file__).resolve().parents[1]
CASE = REPO / "cases" / "hertz_scene.toml"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The scene at level 0 with a study of levels 0 and 1 (the coarsest: seconds), written."""
    case = fegear.load_case(CASE).replace(level=0, study_levels=(0, 1))
    result = fegear.run(case)
    out = tmp_path_factory.mktemp("hertz") / "run"
    result.write(out)
    return result, out


def test_the_written_summary_reads_back_into_the_same_model(written):
    result, out = written
    model = result.model
    assert isinstance(model, HertzSceneResult)
    loaded = load_hertz_result(out)
    for f in dataclasses.fields(model):  # field by field, for a readable failure
        assert getattr(loaded, f.name) == getattr(model, f.name), f.name
    assert loaded == model
    assert load_hertz_result(out / "summary.json") == model  # the file or its folder
    doc = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert doc == json.loads(json.dumps(hertz_summary_document(model)))  # the writer's document
    assert len(model.levels) == 2 and set(model.convergence_rate) <= {"p0", "a", "b"}


def test_the_api_reads_the_model(written):
    result, _ = written
    m = result.model
    assert (result.p0_MPa, result.a_mm, result.b_mm, result.approach_mm) == (
        m.result.p0_MPa,
        m.result.a_mm,
        m.result.b_mm,
        m.result.approach_mm,
    )
    assert (result.hertz_p0_MPa, result.hertz_a_mm, result.hertz_b_mm) == (
        m.hertz.p0_MPa,
        m.hertz.a_mm,
        m.hertz.b_mm,
    )
    assert result.errors == m.errors and result.rates == m.convergence_rate
    assert result.fidelity == m.fidelity and result.level == m.inputs.level == 0
    assert [row.level for row in m.levels] == [0, 1]


def test_the_errors_are_fe_over_hertz_minus_one(written):
    """The errors are relative to Hertz (to round-off: one division and one subtraction), and
    the cell forces carry the load (to the solver's equilibrium residual, N)."""
    m = written[0].model
    fe = {"p0": m.result.p0_MPa, "a": m.result.a_mm, "b": m.result.b_mm}
    fe["approach"] = m.result.approach_mm
    ref = {"p0": m.hertz.p0_MPa, "a": m.hertz.a_mm, "b": m.hertz.b_mm}
    ref["approach"] = m.hertz.approach_mm
    for k in ("p0", "a", "b", "approach"):
        assert m.errors[k] == pytest.approx(fe[k] / ref[k] - 1, rel=1e-12, abs=1e-15), k
    row = m.levels[0]  # the study's level 0 is the run's level
    assert (row.p0_MPa, row.error_p0) == (m.result.p0_MPa, m.errors["p0"])
    residual = abs(m.solver["equilibrium_residual"])
    assert m.result.total_force_N == pytest.approx(m.inputs.force_N, abs=10 * residual + 1e-9)


def test_a_summary_of_another_kind_is_refused():
    doc = json.loads(
        (REPO / "tests" / "reference" / "summaries" / "fzg_spur.tca.json").read_text("utf-8")
    )
    with pytest.raises(InputError) as exc:
        load_hertz_result(doc)
    assert exc.value.field == "kind"
    with pytest.raises(InputError):
        load_hertz_result({"kind": "hertz_scene", "case": "x"})  # keys missing
