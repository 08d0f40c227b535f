"""The ``hertz`` fidelity at flank edges (issue 30, item 6; fegear/ltca/hertz_fidelity.py): no pair
in contact is dropped for want of a curvature, no edge pressure it cannot compute (None, with the
reason), and no TE step where the entering pair's closest point leaves a flank edge.

The seed face gear at moderate load with Δγ = +0.02° is the issue's case: at φ1 = −3.744° the
entering pair's closest point lies on the face gear's tip, where a stencil of separations left
the gear's flank and the pair was dropped (the other pair took 100 %, TE dip 1.5″), and the
loaded TE stepped by 0.39″ where that point left the tip (a one-sided fit gave a negative
curvature and a line law). Its FE models are slow to build (~1.5 min cold): the cycle tests are
``slow``; the curvature itself needs the TCA only.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import fegear
from fegear.ltca import LTCAOptions
from fegear.ltca.cycle import cycle_tca
from fegear.ltca.hertz_fidelity import _relative_curvature
from fegear.pipeline.pair import build_pair

CASES = Path(__file__).resolve().parents[1] / "cases"


def _seed_plus():
    """The seed face gear, moderate load (3e6 N·mm), Δγ = +0.02°, at ``hertz`` level 0."""
    case = fegear.load_case(CASES / "face_gear_load_moderate.toml")
    return case.with_errors(dgamma_deg=0.02).replace(fidelity="hertz")


def _angles(deg):
    return np.radians(np.asarray(deg, dtype=float))


def test_the_curvature_is_the_flanks_own_at_an_edge_and_continuous():
    """At φ1 = −3.744° the entering pair (−1, −1) has its closest point on the face gear's tip:
    its relative curvature is still defined (the flanks' principal curvatures there), positive,
    and continuous with the positions around it (the point runs along the tip); for the pair in
    unloaded contact it is the TCA's contact-ellipse curvature (the same construction)."""
    pair = build_pair(_seed_plus())
    phi = _angles([-3.754, -3.744, -3.734])
    tca, positions, _ = cycle_tca(pair.pinion, pair.gear, pair.assembly, LTCAOptions(), phi)
    i = int(np.flatnonzero((tca.pairs[:, 0] == -1) & (tca.pairs[:, 1] == -1))[0])
    assert all("gear:tip" in p.edge[i] for p in positions)
    AB = np.array([_relative_curvature(tca, p, i) for p in positions])
    assert np.all(np.isfinite(AB)) and np.all(AB > 0.0)
    # 0.01° of pinion roll moves the closest point 0.09 mm along the tip: the curvature by
    # 0.2 % (measured); 1 % bounds a smooth change, not a step
    np.testing.assert_allclose(AB[[0, 2]], AB[[1, 1]], rtol=0.01)
    p = positions[1]
    A, B = _relative_curvature(tca, p, p.contact_pair)
    # the TCA evaluates the same finite differences: equal to round-off
    assert (A, B) == pytest.approx((p.ellipse.A, p.ellipse.B), rel=1e-9)


def test_an_edge_pair_has_no_pressure_but_the_reason():
    """FZG at ``hertz``: the entering pair at the pinion tip (φ1 = −11.25°) carries its load
    (the law of the flanks' curvatures at the tip), but its pressure is the edge's: None, with
    the reason, never the Hertz value of the continued flanks; the position counts as an edge
    position and the cycle's edge value is None."""
    case = fegear.load_case(CASES / "fzg_spur.toml").replace(fidelity="hertz")
    r = fegear.run(case)
    (q,) = [q for q in r.positions[0].pairs if (q.pinion_tooth, q.gear_tooth) == (1, -1)]
    assert q.in_contact and q.load_share > 0.1
    assert q.p_max_MPa is None and q.p_interior_MPa is None and q.p_edge_MPa is None
    assert "flank edge (pinion tip)" in q.pressure_reason
    assert 0 in r.cycle.positions_with_edge_contact
    assert r.cycle.p_max_edge_MPa is None and r.cycle.p_max_MPa is not None


# --------------------------------------------------------------------------------------------
# The face gear's cycle (slow: its FE models)
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def seed_plus_models():
    from fegear.ltca import build_models

    case = _seed_plus()
    pair = build_pair(case)
    opt = LTCAOptions(n_positions=25, level=0, fidelity="hertz", workers=1)
    return case, pair, opt, build_models(pair.pinion, pair.gear, pair.assembly, opt)


def _cycle(seed_plus_models, deg):
    from fegear.ltca import run_ltca

    case, pair, opt, models = seed_plus_models
    return run_ltca(
        pair.pinion, pair.gear, pair.assembly, case.torque2_Nmm, opt, _angles(deg), models
    )


@pytest.mark.slow
def test_no_pair_in_contact_is_dropped_at_an_edge(seed_plus_models):
    """φ1 = −3.744° between its neighbours: the entering pair carries load at all three (it was
    dropped at the middle one); its share follows theirs (within 0.05, the share changes 0.02
    per position), and so does the TE."""
    c = _cycle(seed_plus_models, [-4.32, -3.744, -3.168])
    share = [sum(q.load_share for q in p.pairs if (q.k, q.j) == (-1, -1)) for p in c.positions]
    assert all(s > 0.3 for s in share), share
    assert abs(share[1] - 0.5 * (share[0] + share[2])) < 0.05, share
    te = c.te_loaded_arcsec
    assert abs(te[1] - 0.5 * (te[0] + te[2])) < 0.1, te  # the dip was 1.5″
    assert all(p.status == "ok" for p in c.positions)
    edge = [q for q in c.positions[1].pairs if (q.k, q.j) == (-1, -1)][0]
    assert edge.p_edge_MPa is None and math.isnan(edge.p_max_MPa) and edge.pressure_reason


@pytest.mark.slow
def test_the_te_is_continuous_where_the_entering_pair_leaves_the_tip(seed_plus_models):
    """The loaded TE at 21 angles 0.02° apart from −3.80° to −3.40°: the entering pair's closest
    point leaves the face gear's tip near −3.70°, and the stencil of separations the curvature
    was fitted to left it near −3.55°: no step (it stepped by 0.39″ there, and the pair was
    dropped from −3.78° to −3.71°, by 1.8″). The largest change between neighbours is 0.007″
    (measured): 0.03″ is 1.5″/°, twice the steepest slope of the cycle's TE between its 25
    positions (0.8″/°, measured) and a tenth of the step."""
    deg = np.linspace(-3.80, -3.40, 21)
    c = _cycle(seed_plus_models, deg)
    d = np.abs(np.diff(c.te_loaded_arcsec))
    assert d.max() < 0.03, d
    edges = [any(q.edges for q in p.pairs if (q.k, q.j) == (-1, -1)) for p in c.positions]
    assert edges[0] and not edges[-1]  # the switch from edge to interior is inside the scan
