"""The case-file schema: one set of declarations validates, fills defaults and documents.

The declarations are data, so the invariants are checked over all of them: every default passes
its own key's check, every range's message is what the validator says, and every key reaches the
case (a key that validates but is dropped would be a silent no-op for the user).
"""

from __future__ import annotations

import pytest

from fegear.case_files import parse_case
from fegear.errors import InputError
from fegear.io import gear_case as gc
from fegear.io.schema import INTEGER, NUMBER, Key, Range
from fegear.scenes.hertz_case import SECTIONS as HERTZ_SECTIONS

SEED_BEVEL = {
    "case": {"kind": "spiral_bevel"},
    "pair": {
        "n_pinion": 12,
        "n_gear": 36,
        "module_mm": 4.941634,
        "spiral_angle_deg": 35.0,
        "pressure_angle_deg": 22.5,
        "face_width_mm": 25.4,
    },
    "load": {"torque2_Nm": 300.0},
}


def _all_sections():
    for kind in gc.GEAR_KINDS:
        yield from gc.sections(kind)
    yield from HERTZ_SECTIONS


@pytest.mark.parametrize(
    ("rng", "integer", "text"),
    [
        (Range(0, None, lo_open=True), False, "> 0"),
        (Range(0, None), False, ">= 0"),
        (Range(10, 35, unit="deg"), False, "in [10, 35] deg"),
        (Range(-1, 0.5, lo_open=True, hi_open=True), False, "in (-1, 0.5)"),
        (Range(0, 4), True, "an integer in [0, 4]"),
        (Range(5, None), True, "an integer >= 5"),
    ],
)
def test_a_range_says_what_it_allows(rng, integer, text):
    assert rng.text(integer) == text


def test_open_and_closed_ends_are_kept():
    r = Range(0, 60, lo_open=True)
    assert not r.contains(0.0) and r.contains(1e-12) and r.contains(60.0)
    assert not r.contains(60.0 + 1e-9)


def test_every_declared_default_passes_its_own_check():
    """A default the validator would refuse would make the reference lie."""
    n = 0
    for sec in _all_sections():
        for k in sec.keys:
            if k.default is not None:
                k.check(f"{sec.name}.{k.name}", k.default)
                n += 1
    assert n >= 30  # the declarations carry their defaults (30+ keys)


def test_a_value_out_of_range_names_the_field_and_the_range():
    doc = {**SEED_BEVEL, "pair": {**SEED_BEVEL["pair"], "edge_radius_mm": -0.5}}
    with pytest.raises(InputError) as exc:
        parse_case(doc)
    assert exc.value.field == "pair.edge_radius_mm"
    assert exc.value.allowed == "> 0"


def test_a_pair_element_out_of_range_is_named_with_its_index():
    doc = {
        "case": {"kind": "spur"},
        "pair": {
            "teeth": [16, 24],
            "module_mm": 4.5,
            "pressure_angle_deg": 20.0,
            "tip_relief_mm": [0.0, -0.01],
        },  # fmt: skip
        "load": {"torque2_Nm": 200.0},
    }
    with pytest.raises(InputError) as exc:
        parse_case(doc)
    assert (exc.value.field, exc.value.allowed) == ("pair.tip_relief_mm[1]", ">= 0")


def test_a_wrong_type_is_refused_before_its_range():
    k = Key("level", INTEGER, range=Range(0, 4))
    with pytest.raises(InputError, match="an integer"):
        k.check("analysis.level", 1.5)
    with pytest.raises(InputError, match="a finite number"):
        Key("x", NUMBER).check("pair.x", float("nan"))


def test_the_defaults_are_the_cases_values():
    case = parse_case(SEED_BEVEL)
    assert case.fidelity == gc.ANALYSIS.key("fidelity").default == "hybrid"
    assert (case.level, case.n_positions, case.backend) == (0, 25, "auto")
    assert (case.E_MPa, case.nu) == (206000.0, 0.3)


def test_the_bevel_edge_radius_reaches_the_synthesis(monkeypatch):
    """``pair.edge_radius_mm`` is not only accepted: it is part of the blank the synthesis gets
    (the blank's edge radius is what generates the fillet; the synthesis itself, 10-20 s, is
    replaced by a recorder here)."""
    seen = {}

    def record(blank_kw, target_kw, machine=None, blank_type=None):
        seen.update(blank_kw)
        raise RuntimeError("recorded")

    from fegear.pipeline import pair as pp

    monkeypatch.setattr(pp, "_bevel_pair", record)
    doc = {**SEED_BEVEL, "pair": {**SEED_BEVEL["pair"], "edge_radius_mm": 0.6}}
    with pytest.raises(RuntimeError, match="recorded"):
        pp.build_pair(parse_case(doc))
    assert seen["edge_radius_mm"] == 0.6
    seen.clear()
    with pytest.raises(RuntimeError, match="recorded"):
        pp.build_pair(parse_case(SEED_BEVEL))
    assert "edge_radius_mm" not in seen  # absent: the synthesis chooses it
