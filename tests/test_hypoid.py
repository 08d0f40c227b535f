"""Hypoid pairs (``kind = "hypoid"``, docs/geometry/hypoid.md): the spiral bevel at offset zero,
a pair with offset conjugate at its mean point with the designed TE parabola, ΔE (a change of
the offset) moving the bearing as the first-order geometry says, and the loaded mesh: torque
balance, load shares summing to one, Hertz at a single-pair position, more pairs and a larger
pattern under more load."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from fegear.case_files import load_case
from fegear.geometry.bevel import HypoidBlank
from fegear.geometry.pair_placement import InstallationErrors, spiral_bevel_assembly
from fegear.ltca import LTCAOptions, build_models, run_ltca
from fegear.mechanics.hertz_closed_form import effective_modulus, hertz_point
from fegear.pipeline.pair import build_pair
from fegear.tca import TCAOptions, run_tca
from fegear.tca.bevel import cycle_angles, error_effects, path_angle_on_gear, te_parabola

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests" / "reference"))
import summaries  # noqa: E402

SIDE = "drive"
SIDES = ("drive", "coast")
DL = 0.05  # mm: the ΔE of the error study (the spiral bevel's)


def _zero_offset_case(tmp_path: Path) -> Path:
    """``cases/spiral_bevel_nominal.toml`` as a hypoid of offset 0 (the same blank data)."""
    text = (REPO / "cases" / "spiral_bevel_nominal.toml").read_text(encoding="utf-8")
    text = text.replace('kind = "spiral_bevel"', 'kind = "hypoid"')
    text = text.replace("face_width_mm = 25.4\n", "face_width_mm = 25.4\noffset_mm = 0.0\n")
    path = tmp_path / "hypoid_offset_zero.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _results(doc: dict) -> dict:
    """A summary without what names the case (its kind, name, inputs echo)."""
    return {k: v for k, v in doc.items() if k not in ("case", "kind", "inputs")}


@pytest.fixture(scope="module")
def zero_offset(tmp_path_factory):
    path = _zero_offset_case(tmp_path_factory.mktemp("hypoid0"))
    return path, build_pair(load_case(path)).spiral_bevel


def test_offset_zero_cuts_the_spiral_bevel_flanks(spiral_bevel_pair, zero_offset):
    """The hypoid blank at E = 0 is the spiral bevel blank (tests/test_hypoid_blank.py), so the
    synthesis gives the same settings and the same flanks: to 1e-9 mm (the flank solves'
    tolerance is 1e-11 mm; the settings agree to round-off)."""
    _, hyp = zero_offset
    assert isinstance(hyp.blank, HypoidBlank) and hyp.blank.offset_mm == 0.0
    for name in ("gear_drive", "gear_coast", "pinion_drive", "pinion_coast"):
        a, b = getattr(hyp.settings, name), getattr(spiral_bevel_pair.settings, name)
        for f, v in vars(a).items():
            w = getattr(b, f)
            if isinstance(v, float):
                assert v == pytest.approx(w, rel=1e-10, abs=1e-12), (name, f)
            else:
                assert v == w, (name, f)
    for a, b in ((hyp.pinion, spiral_bevel_pair.pinion), (hyp.gear, spiral_bevel_pair.gear)):
        for side in SIDES:
            bd = b.boundaries()
            U, V = np.meshgrid(np.linspace(0.0, 1.0, 7), np.linspace(bd.v_start, bd.v_end, 5),
                               indexing="ij")  # fmt: skip
            pa, na = a.point_normal(side, U, V)
            pb, nb = b.point_normal(side, U, V)
            assert np.abs(pa - pb).max() < 1e-9, (a.name, side)
            assert np.abs(na - nb).max() < 1e-10, (a.name, side)


def test_offset_zero_gives_the_spiral_bevel_reference_tca(zero_offset):
    """The unloaded TCA summary of the offset-zero hypoid is the stored spiral bevel reference
    (tests/reference/summaries/spiral_bevel_nominal.tca.json) to the references' tolerances."""
    path, _ = zero_offset
    ref = json.loads(
        summaries.reference_path(REPO / "cases" / "spiral_bevel_nominal.toml", "tca").read_text(
            encoding="utf-8"
        )
    )
    new = summaries.run_summary(path, "tca")
    assert new["kind"] == "hypoid"
    diff = summaries.differences(_results(new), _results(ref))
    assert not diff, f"{len(diff)} values moved:\n" + "\n".join(diff[:20])


@pytest.mark.slow
def test_offset_zero_gives_the_spiral_bevel_reference_loaded_summary(zero_offset):
    """The loaded summary at hybrid level 0 likewise (the same meshes: the same flanks)."""
    path, _ = zero_offset
    ref = json.loads(
        summaries.reference_path(REPO / "cases" / "spiral_bevel_nominal.toml", "own").read_text(
            encoding="utf-8"
        )
    )
    new = summaries.run_summary(path, "own")
    assert not summaries.mesh_differences(new, ref)
    diff = summaries.differences(_results(new), _results(ref))
    assert not diff, f"{len(diff)} values moved:\n" + "\n".join(diff[:20])


# --------------------------------------------------------------------------------------------
# the hypoid with offset (cases/hypoid_nominal.toml): unloaded
# --------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def nominal(hypoid_pair):
    """Error-free pair over 1.25 mesh cycles (both transfer points inside the range)."""
    pair = hypoid_pair
    phi = cycle_angles(pair.blank.n1, 21, margin=0.25)
    return run_tca(pair.pinion, pair.gear, spiral_bevel_assembly(pair, SIDE), TCAOptions(),
                   phi1=phi)  # fmt: skip


def test_the_case_is_a_hypoid_with_its_offset(hypoid_pair):
    b = hypoid_pair.blank
    assert isinstance(b, HypoidBlank) and b.offset_mm == 25.0
    A2, e2 = b.gear_axis()
    # the axes pass at the offset: distance of the gear axis from the pinion axis (z)
    c = np.cross([0.0, 0.0, 1.0], e2)
    assert abs(np.dot(A2, c) / np.linalg.norm(c)) == pytest.approx(25.0, abs=1e-9)
    # the pinion's spiral angle exceeds the gear's by the offset angle in the pitch plane
    eps = b.spiral_angle(1) - b.spiral_angle(2)
    assert eps == pytest.approx(b.offset_angle_pitch_plane, abs=1e-12) and eps > 0.1


def test_contact_at_the_mean_position_is_at_the_pitch_point_and_conjugate(hypoid_pair):
    """At φ1 = 0 the flanks touch at the blank's mean pitch point P (placement by the mean
    points) with a common normal across the relative velocity there (the equation of meshing
    n·v12 = 0 at the contact point). The TCA's Newton solves stop at a separation of 1e-10 mm,
    so the minimum of a separation A x² along the contact ellipse's major axis is located to
    sqrt(2e-10 / A) (tests/reference/summaries.py: LOCATION_MM); A from the TCA's own ellipse
    there (A = 7.0e-4 1/mm: 5.3e-4 mm; the points lie 3e-6 and 3e-8 mm from P)."""
    pair = hypoid_pair
    b = pair.blank
    for side in SIDES:
        asm = spiral_bevel_assembly(pair, side)
        r = run_tca(pair.pinion, pair.gear, asm, TCAOptions(separation_grid=None),
                    phi1=np.array([0.0]))  # fmt: skip
        p = r.positions[0]
        assert abs(p.te_rad) < 1e-9  # calibrated: TE 0 at the mean position
        x = p.points[p.contact_pair]
        located = np.sqrt(2.0 * 1e-10 / p.ellipse.A)
        assert np.linalg.norm(x - b.pitch_point()) < located, (side, x, b.pitch_point(), located)
        # the synthesis's mean point and normal (the TCA's point is that point to 1e-6 mm)
        rep = pair.reports[side]
        A2, e2 = b.gear_axis()
        s, M, n = rep.sigma, np.asarray(rep.point), np.asarray(rep.normal)
        assert np.linalg.norm(M - b.pitch_point()) < 1e-9
        v12 = np.cross(s * np.array([0.0, 0.0, 1.0]), M) - np.cross(-s * b.m21 * e2, M - A2)
        # the relative sliding velocity is large (the hypoid's lengthwise sliding, ~0.3 of the
        # rolling speed), yet normal to n: to the synthesis's 1e-10 relative tolerance
        assert np.linalg.norm(v12) > 0.1 * np.linalg.norm(np.cross([0, 0, 1.0], M))
        assert abs(np.dot(n, v12)) < 1e-9 * np.linalg.norm(v12), side


def test_te_parabola_with_the_designed_amplitude(hypoid_pair, nominal):
    r, n1 = nominal, hypoid_pair.blank.n1
    assert r.has_contact.all()
    amp_target = hypoid_pair.targets.te_amplitude_arcsec
    xv, tv, amp, rms = te_parabola(r, n1)
    # as the spiral bevel's (tests/test_tca_spiral_bevel.py): amplitude within 10 % of the
    # design, a parabola to 1 % of it, vertex at the mean position
    assert abs(amp - amp_target) < 0.1 * amp_target, amp
    assert rms < 0.01 * amp_target, rms
    assert abs(math.degrees(xv)) < 0.2 and abs(tv) < 0.05, (xv, tv)
    # transfer points at ±π/N1 (positions 2.25° apart: ~0.05° on the angle)
    tp = r.transfer_points
    assert tp.shape == (2, 2), tp
    assert np.allclose(np.degrees(tp[:, 0]), [-180 / n1, 180 / n1], atol=0.05), tp
    # the path stays inside the flanks, toe -> heel
    assert not r.edge.any()
    cyc = np.abs(r.phi1) < math.pi / n1
    assert np.all(np.diff(r.gear_uv[cyc, 1]) > 0)


def test_contact_path_direction_as_designed(hypoid_pair):
    for side in SIDES:
        eta, target = path_angle_on_gear(hypoid_pair, side)
        # local synthesis is exact to first order at M; the chord at ±0.02 rad is O(dφ²): 0.5°
        assert abs(eta - target) < 0.5, (side, eta, target)


@pytest.fixture(scope="module")
def offset_effects(hypoid_pair):
    cases = {sg: InstallationErrors(dE_mm=sg * DL) for sg in (1, -1)}
    return error_effects(hypoid_pair, cases, SIDE, n_positions=13)


def test_a_change_of_offset_moves_the_bearing_as_the_first_order_geometry_says(offset_effects):
    """ΔE = ±0.05 mm moves the pinion along the common perpendicular of the axes (the offset
    becomes 25 ± 0.05 mm): the TE at the mean position shifts by the envelope theorem's
    ``−(δr·n)/h`` to 1 %, opposite changes give opposite shifts of pattern and TE (the linear
    regime), and the predesigned parabola absorbs the linear TE of the error."""
    _, eff, _ = offset_effects
    p, m = eff[1], eff[-1]
    for e in (p, m):
        assert e.has_contact
        assert abs(e.te0_arcsec - e.te0_first_order_arcsec) < 0.01 * abs(e.te0_first_order_arcsec)
        assert abs(e.amplitude_arcsec - 8.0) < 1.2, e.amplitude_arcsec
    assert abs(p.dL_mm + m.dL_mm) < 0.1 * abs(p.dL_mm) + 0.01
    assert abs(p.dh_mm + m.dh_mm) < 0.1 * abs(p.dh_mm) + 0.01
    assert abs(p.te0_arcsec + m.te0_arcsec) < 0.05 * abs(p.te0_arcsec)
    # as on the spiral bevel, the offset is the strong lengthwise mover: millimetres along the
    # face for 0.05 mm, far more than across the profile
    assert abs(p.dL_mm) > 1.0 and abs(p.dh_mm) < 0.3 * abs(p.dL_mm)


# --------------------------------------------------------------------------------------------
# loaded
# --------------------------------------------------------------------------------------------
OPTIONS = LTCAOptions(n_positions=9, level=0, fidelity="hybrid")  # the default fidelity


@pytest.fixture(scope="module")
def loaded(hypoid_pair):
    pair = hypoid_pair
    asm = spiral_bevel_assembly(pair, SIDE, InstallationErrors())
    return pair, asm, build_models(pair.pinion, pair.gear, asm, OPTIONS)


def test_a_single_pair_position_is_hertz_with_the_tca_curvatures(loaded):
    """At the mean position under a light torque only the mean pair carries (the neighbours'
    separations, ~8 arcsec of the parabola, stay open); its interior p_max is the closed-form
    Hertz peak of its force on the TCA's relative curvatures there, within 5 %."""
    pair, asm, models = loaded
    torque = 2.0e4 * pair.blank.n2 / pair.blank.n1  # N·mm on the gear: 20 N·m on the pinion
    c = run_ltca(pair.pinion, pair.gear, asm, torque, OPTIONS, phi1=np.array([0.0]),
                 models=models)  # fmt: skip
    pos = c.positions[0]
    assert int(c.n_in_contact[0]) == 1
    (q,) = [q for q in pos.pairs if q.force_N > 0]
    assert not q.edges and q.load_share == pytest.approx(1.0, abs=1e-12)
    tp = run_tca(pair.pinion, pair.gear, asm, TCAOptions(separation_grid=None),
                 phi1=np.array([0.0])).positions[0]  # fmt: skip
    e = tp.ellipse
    p0 = hertz_point(q.force_N, e.A, e.B, effective_modulus(206000.0, 0.3, 206000.0, 0.3))
    # 5 %: the bound (the compliance of the teeth does not change a patch this small)
    assert abs(q.p_max_MPa / p0.p0_MPa - 1.0) < 0.05, (q.p_max_MPa, p0.p0_MPa)
    assert pos.solution.equilibrium_residual < 1e-9  # torque balance enforced by the solver


def test_more_load_closes_more_pairs_and_spreads_the_pattern(loaded):
    """Over one cycle at 20, 100 and 400 N·m on the pinion: the load shares of every position
    sum to one (torque balance), the loaded contact ratio (pairs in contact averaged over the
    positions) and the contact area never decrease and grow over the range (measured: see the
    assertion messages)."""
    pair, asm, models = loaded
    ratio, area = [], []
    for t1 in (2.0e4, 1.0e5, 4.0e5):  # N·mm on the pinion
        c = run_ltca(pair.pinion, pair.gear, asm, t1 * pair.blank.n2 / pair.blank.n1, OPTIONS,
                     models=models)  # fmt: skip
        for pos in c.positions:
            shares = [q.load_share for q in pos.pairs]
            assert sum(shares) == pytest.approx(1.0, abs=1e-9)
            assert pos.solution.equilibrium_residual < 1e-9
        ratio.append(float(np.mean(c.n_in_contact)))
        # the patch of each pair: the ellipse of its pressure's semi-axes (mm²)
        area.append(sum(math.pi * q.semi_major_mm * q.semi_minor_mm
                        for pos in c.positions for q in pos.pairs))  # fmt: skip
    assert ratio == sorted(ratio) and ratio[-1] > ratio[0], ratio
    # Hertz: a patch grows as F^(2/3), 7.4x for 20x the load; more pairs add theirs: at least 2x
    assert area == sorted(area) and area[-1] > 2.0 * area[0], area


# --------------------------------------------------------------------------------------------
# a hypoid from its summary sheet (cases/hypoid_sheet.toml: inches, degrees-minutes)
# --------------------------------------------------------------------------------------------
SHEET = (REPO / "cases" / "hypoid_sheet.toml").read_text(encoding="utf-8")


def test_the_sheet_case_in_inches_has_the_nominal_unloaded_contact():
    """cases/hypoid_sheet.toml holds the nominal pair's settings in inches and degrees-minutes
    (``fegear settings cases/hypoid_nominal.toml --units in``): the rigid TCA of the nominal
    case to the printed digits (9 decimals of an inch, 8 of an arc minute)."""
    import fegear

    nominal = fegear.run(load_case(REPO / "cases" / "hypoid_nominal.toml"), fidelity="tca")
    sheet_case = load_case(REPO / "cases" / "hypoid_sheet.toml")
    assert sheet_case.machine is not None and sheet_case.kind == "hypoid"
    sheet = fegear.run(sheet_case, fidelity="tca")
    # the TE is ~8″ from differences of µm: the printed digits move it by ~1e-6 of that
    # (measured 8.098896 against 8.098894)
    assert sheet.cycle.te_pp_unloaded_arcsec == pytest.approx(
        nominal.cycle.te_pp_unloaded_arcsec, rel=1e-5
    )
    te_a = [p.te_unloaded_arcsec for p in nominal.positions]
    te_b = [p.te_unloaded_arcsec for p in sheet.positions]
    np.testing.assert_allclose(te_b, te_a, atol=1e-4)
    assert sheet.checks.path_length_mm == pytest.approx(nominal.checks.path_length_mm, rel=1e-6)


BAD = [
    ("wrong_unit", ("radial_in = ", "radial_ft = "), ["machine.gear_drive.radial_ft"]),
    ("missing_blade_angle", None, ["machine.pinion_drive.blade_angle", "required"]),
    ("impossible_blade_angle", ('blade_angle_degmin = "21 03', 'blade_angle_degmin = "81 03'),
     ["machine.gear_drive.blade_angle_degmin", "(0, 60)"]),
    ("negative_offset", ("offset_mm = 25.0", "offset_mm = -25.0"), ["pair.offset_mm", ">= 0"]),
]  # fmt: skip


@pytest.mark.parametrize(("edit", "words"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_a_bad_hypoid_sheet_is_refused_at_input_naming_the_field(tmp_path, capsys, edit, words):
    from cli_checks import assert_refused

    from fegear.cli import main

    if edit is None:  # the pinion drive flank's blade angle line removed
        start = SHEET.index("[machine.pinion_drive]")
        line = SHEET[SHEET.index("blade_angle_degmin", start) :].split("\n")[0] + "\n"
        text = SHEET[:start] + SHEET[start:].replace(line, "", 1)
    else:
        assert edit[0] in SHEET
        text = SHEET.replace(edit[0], edit[1], 1)
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    code = main(["run", str(path), "--fidelity", "tca", "--out", str(tmp_path / "out")])
    assert_refused(code, capsys.readouterr().err, words)
    assert not (tmp_path / "out").exists()  # nothing written
