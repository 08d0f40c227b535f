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

import pytest

import fegear

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
