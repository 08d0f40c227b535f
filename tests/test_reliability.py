"""Numbers a gear engineer can trust by default (issue 21): one test per row of the README's
"Reliability" table, each asserting the exit code and the field or flag that answers it.

Written on the FZG spur pair (``cases/fzg_spur.toml``), the spiral bevel and synthetic inputs;
the face gear only where the row is about it, asserting behaviour (exit code, field named), not
its numbers (its flanks are being extended to the real fillet limit).

At the end, the spiral bevel's loaded analysis at fixed positions (issue 6; it was
``tests/test_ltca_bevel.py``) and its CalculiX deck (it was in ``tests/test_calculix.py``): in
this module they read the sector meshes and operators, and the contact zone, that the spiral
bevel row's run built in this process (~25 s and ~15 s cold) instead of building them again in
another.
"""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_checks import assert_refused

from fegear.cli import main
from fegear.geometry.pair_placement import InstallationErrors, spiral_bevel_assembly
from fegear.ltca import LTCAOptions, build_models, run_ltca

REPO = Path(__file__).resolve().parents[1]
FZG = REPO / "cases" / "fzg_spur.toml"
FACE_GEAR = REPO / "cases" / "face_gear_nominal.toml"
BEVEL = REPO / "cases" / "spiral_bevel_nominal.toml"
FZG_TEXT = FZG.read_text(encoding="utf-8")


def _case(tmp_path: Path, text: str, old: str, new: str, name: str = "case.toml") -> Path:
    assert old in text, old
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def _fzg(tmp_path: Path, old: str, new: str) -> Path:
    return _case(tmp_path, FZG_TEXT, old, new)


def _summary(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text(encoding="utf-8"))


# --------------------------------------------------------------------------------------------
# Default fidelity
# --------------------------------------------------------------------------------------------


def test_main_job_runs_the_seed_face_gear_at_hybrid(tmp_path, monkeypatch):
    """``fegear run`` with no case: the seed face gear at hybrid level 0 (the run itself, ~1 min
    cold, is ``test_gear_cli.test_no_argument_main_job_writes_all_outputs``, slow): here the
    case and fidelity that reach the analysis, and the summary that records them."""
    import fegear.api.runner as runner
    import fegear.pipeline.run as gear_run
    from fegear.output.gear_output import gear_summary

    seen = {}

    def fake_run(case, fidelity=None, level=None, **kw):
        seen["case"] = gear_run._override(case, fidelity, level)
        raise KeyboardInterrupt  # stop before the analysis

    monkeypatch.setattr(runner, "run_gear_case", fake_run)  # what fegear.run (the CLI) calls
    monkeypatch.chdir(tmp_path)
    assert main(["run", "-q"]) == 130
    case = seen["case"]
    assert case.name == "face_gear_nominal" and case.kind == "face_gear"
    assert case.fidelity == "hybrid" and case.level == 0 and case.n_positions == 25
    doc = gear_summary(gear_run.GearRun(case=case, pair=None, assembly=None, tca=_NoTCA()))
    assert doc["fidelity"] == "hybrid"


class _NoTCA:
    """The least a summary needs of an unloaded result (no positions)."""

    phi1 = np.zeros(0)
    te_arcsec = np.zeros(0)
    has_contact = np.zeros(0, dtype=bool)
    hertz_p0_MPa = np.zeros(0)
    paint_mm = 0.00632
    positions = ()


@pytest.fixture(scope="module")
def fzg_shipped(tmp_path_factory):
    """``cases/fzg_spur.toml`` as shipped (hybrid level 0, 9 positions)."""
    out = tmp_path_factory.mktemp("fzg")
    code = main(["run", str(FZG), "--out", str(out), "-q"])
    return code, out


def test_fzg_case_runs_hybrid_and_its_p_max_is_away_from_the_edges(fzg_shipped):
    code, out = fzg_shipped
    assert code == 0
    doc = _summary(out)
    c = doc["cycle"]
    assert doc["fidelity"] == "hybrid" and doc["level"] == 0
    # p_max away from the edges: line Hertz gives about 1100 MPa for this pair (issue 21);
    # hybrid level 0 reads 1264 MPa at the single-pair position (measured); fe level 0 read
    # 126-160 MPa. 20 %: the band between line Hertz and the converged hybrid.
    assert 1100.0 * 0.8 < c["p_max_MPa"] < 1100.0 * 1.2, c["p_max_MPa"]
    pos = doc["positions"][c["p_max_at"]["position"]]
    pair = next(q for q in pos["pairs"] if [q["pinion_tooth"], q["gear_tooth"]] ==
                c["p_max_at"]["pair"])  # fmt: skip
    assert pair["p_interior_MPa"] == c["p_max_MPa"]
    # the corner contact of the pair entering at the pinion tip is reported beside it, named
    assert c["p_max_edge_MPa"] > 3.0 * c["p_max_MPa"]
    assert "pinion tip" in c["p_max_edge_at"]["edges"]
    assert c["te_pp_loaded_positions_used"] == 9 and c["excluded_positions"] == []


# --------------------------------------------------------------------------------------------
# Honest headlines on the spiral bevel (Must show)
# --------------------------------------------------------------------------------------------


def test_spiral_bevel_p_max_is_the_hertz_value_of_its_most_loaded_interior_position(tmp_path):
    """Spiral bevel nominal at hybrid (the case as shipped): ``cycle.p_max_MPa`` within 10 % of
    the closed-form Hertz peak of its most loaded interior position (force of the solve, relative
    curvatures of the TCA at that pair's contact point), the edge value reported separately."""
    from fegear.case_files import load_case
    from fegear.ltca import LTCAOptions
    from fegear.ltca.cycle import cycle_tca
    from fegear.mechanics.hertz_closed_form import effective_modulus, hertz_point
    from fegear.pipeline.pair import build_pair

    out = tmp_path / "out"
    assert main(["run", str(BEVEL), "--out", str(out), "-q"]) == 0
    doc = _summary(out)
    c = doc["cycle"]
    assert doc["fidelity"] == "hybrid"
    assert doc["positions"][c["p_max_at"]["position"]]["status"] == "ok"
    interior = [
        (q["force_N"], i, q)
        for i, p in enumerate(doc["positions"])
        if p["status"] == "ok"
        for q in p["pairs"]
        if q["in_contact"] and not q["edges"]
    ]
    force, i, q = max(interior, key=lambda t: t[0])
    case = load_case(BEVEL)
    pair = build_pair(case)
    _, positions, _ = cycle_tca(
        pair.pinion, pair.gear, pair.assembly, LTCAOptions(n_positions=case.n_positions)
    )
    tp = positions[i]
    k = int(tp.contact_pair)
    assert [int(x) for x in tp.pairs[k]] == [q["pinion_tooth"], q["gear_tooth"]]
    e = tp.ellipse
    p0 = hertz_point(force, e.A, e.B, effective_modulus(case.E_MPa, case.nu, case.E_MPa, case.nu))
    # measured: 1525 MPa against Hertz 1510 MPa (+1.0 %); 10 %: the bound
    assert abs(c["p_max_MPa"] / p0.p0_MPa - 1.0) < 0.10, (c["p_max_MPa"], p0.p0_MPa)
    # the edge contacts (gear tip, toe) beside it, not in it: measured 7180 MPa
    assert c["p_max_edge_MPa"] > c["p_max_MPa"] and c["p_max_edge_at"]["edges"]
    named = {"pinion toe", "pinion heel", "pinion tip", "gear tip", "gear toe", "gear heel"}
    assert all(e in named or "fillet limit" in e for e in c["p_max_edge_at"]["edges"])


# --------------------------------------------------------------------------------------------
# Every way contact can fail
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("da", ["9.5", "20.0", "100.0"])
@pytest.mark.parametrize("fidelity", ["tca", "hertz", "hybrid"])
def test_no_contact_anywhere_is_refused_naming_the_error(tmp_path, capsys, da, fidelity):
    path = _fzg(tmp_path, "da_mm = 0.0 ", f"da_mm = {da} ")
    out = tmp_path / "out"
    code = main(["run", str(path), "--fidelity", fidelity, "--out", str(out), "-q"])
    line = assert_refused(code, capsys.readouterr().err, [f"errors.da_mm = {da}"])
    assert "no contact anywhere" in line and "any of the 9 positions" in line
    assert not out.exists()  # decided before any work


def test_face_gear_without_contact_is_refused_naming_the_error(tmp_path, capsys):
    path = _case(tmp_path, FACE_GEAR.read_text("utf-8"), "dA2_mm = 0.0", "dA2_mm = 30.0")
    out = tmp_path / "out"
    code = main(["run", str(path), "--fidelity", "tca", "--out", str(out), "-q"])
    line = assert_refused(code, capsys.readouterr().err, ["errors.dA2_mm = 30.0"])
    assert "no contact anywhere" in line
    assert not out.exists()


@pytest.mark.parametrize(
    ("path", "old", "new", "field", "depth"),
    [
        # rack clearance 0.25 m = 1.125 mm less the profile-shift change: 1.036 mm
        (FZG, "da_mm = 0.0 ", "da_mm = -2.0 ", "errors.da_mm = -2.0", 2.0 - 1.0357),
        # face-gear root plane 1.25 m below the pitch plane, pinion tip 1 m: 1.5875 mm
        (FACE_GEAR, "dA2_mm = 0.0", "dA2_mm = -3.0", "errors.dA2_mm = -3.0", 3.0 - 1.5875),
    ],
    ids=["fzg_da-2", "face_gear_dA2-3"],
)
def test_tip_root_interference_is_refused_with_the_field_and_depth(
    tmp_path, capsys, path, old, new, field, depth
):
    p = _case(tmp_path, path.read_text("utf-8"), old, new)
    out = tmp_path / "out"
    code = main(["run", str(p), "--out", str(out), "-q"])
    line = assert_refused(code, capsys.readouterr().err, [field, "interference"])
    m = re.search(r"tip runs ([0-9.]+) mm into the (pinion|gear) root", line)
    assert m, line
    # printed to 1 µm: the error less the error-free clearance
    assert abs(float(m.group(1)) - depth) < 1e-3, (line, depth)
    assert not out.exists()


def test_tip_clearance_of_the_error_free_pairs():
    """The clearance the interference test is measured against: exact for the spur pair (centre
    distance less tip radius less root radius), and both tips of the face gear clear by the
    dedendum less the addendum."""
    from fegear.case_files import load_case
    from fegear.pipeline.pair import build_pair
    from fegear.tca.engagement import tip_root_clearance

    pair = build_pair(load_case(FZG))
    c = tip_root_clearance(pair.pinion, pair.gear, pair.assembly)
    a = float(np.linalg.norm(pair.assembly.axis2()[0] - pair.assembly.axis1()[0]))
    exact = a - pair.pinion.r_a - pair.gear.r_f
    # sampled, then refined by 10^3: the sampling error is below a micrometre
    assert abs(c.pinion_tip_mm - exact) < 1e-6, (c.pinion_tip_mm, exact)
    assert c.interference_mm == 0.0
    pair = build_pair(load_case(FACE_GEAR))
    c = tip_root_clearance(pair.pinion, pair.gear, pair.assembly)
    assert abs(c.pinion_tip_mm - 0.25 * 6.35) < 1e-6 and abs(c.gear_tip_mm - 0.25 * 6.35) < 1e-6


def test_contact_lost_at_some_positions_is_named_and_left_out(tmp_path, capsys):
    """FZG with ``da_mm = 8``: the flanks meet only at their tips; at one position they do not
    meet, at another no pair has a Hertz law. Exit 0, both positions named on the terminal,
    the loaded TE p-p over the other 7 (it was 17 923″ across them)."""
    path = _fzg(tmp_path, "da_mm = 0.0 ", "da_mm = 8.0 ")
    out = tmp_path / "out"
    assert main(["run", str(path), "--fidelity", "hertz", "--out", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert "warning: contact lost at 1 of 9 positions: 8 (φ1 = 8.750°)" in err
    assert "warning: no load carried at 1 of 9 positions: 0 (φ1 = -11.250°)" in err
    c = _summary(out)["cycle"]
    assert c["positions_without_unloaded_contact"] == [8]
    assert [(e["index"], e["status"]) for e in c["excluded_positions"]] == [
        (0, "lost"),
        (8, "lost"),
    ]
    assert c["te_pp_loaded_positions_used"] == 7
    used = [p["te_loaded_arcsec"] for p in _summary(out)["positions"] if p["status"] == "ok"]
    assert c["te_pp_loaded_arcsec"] == pytest.approx(max(used) - min(used), rel=1e-12)


def test_contact_ratio_below_one_is_warned_with_the_number(tmp_path, capsys):
    """FZG with ``da_mm = 3``: contact ratio 0.918 (ISO 21771 at the 94.5 mm centre distance:
    0.917). At 9 positions none falls in the tip-contact handover: the TE p-p and contact ratio
    are null with the reason, not 0.00 and 1.00; at 14 positions one does and they are
    reported."""
    path = _fzg(tmp_path, "da_mm = 0.0 ", "da_mm = 3.0 ")
    out = tmp_path / "out9"
    assert main(["run", str(path), "--fidelity", "hertz", "--out", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert "warning: unloaded contact ratio 0.918 < 1 (errors.da_mm = 3)" in err
    assert "none of the 9 positions falls there" in err and "n_positions >= 14" in err
    c = _summary(out)["cycle"]
    assert c["contact_ratio_unloaded_below_1"] == pytest.approx(0.9176, abs=5e-4)
    for key in ("te_pp_unloaded_arcsec", "te_pp_loaded_arcsec", "contact_ratio_loaded"):
        assert c[key] is None, key
    assert "handover" in c["te_pp_loaded_reason"] and "handover" in c["contact_ratio_reason"]
    path14 = _case(
        tmp_path, path.read_text("utf-8"), "n_positions = 9", "n_positions = 14", "c14.toml"
    )
    out = tmp_path / "out14"
    assert main(["run", str(path14), "--fidelity", "hertz", "--out", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert "unloaded contact ratio 0.918 < 1" in err and "none of the" not in err
    c = _summary(out)["cycle"]
    # one position in the handover: a tip contact, the unloaded TE leaves 0 there (measured 9.5″)
    assert c["te_pp_unloaded_arcsec"] > 1.0 and c["te_pp_loaded_arcsec"] > 1.0
    assert c["contact_ratio_loaded"] > 0.0


def test_handover_of_a_conjugate_pair_is_its_contact_ratio():
    """The interior fraction of the cycle equals the ISO 21771 transverse contact ratio when it
    is below 1 (FZG at ``da = +3``); a pair meshing at its design centre distance (1.46) has
    interior contact over the whole cycle."""
    from dataclasses import replace

    from fegear.case_files import load_case
    from fegear.pipeline.pair import build_pair
    from fegear.tca import TCA, TCAOptions, reference_phase
    from fegear.tca.engagement import handover

    for da, expected in ((0.0, 1.0), (3.0, None)):
        case = load_case(FZG)
        case = replace(case, errors=replace(case.errors, da_mm=da))
        pair = build_pair(case)
        opt = TCAOptions(separation_grid=None)
        asm = pair.assembly.with_phase2(reference_phase(pair.pinion, pair.gear, pair.assembly, opt))
        h = handover(TCA(pair.pinion, pair.gear, asm, opt))
        if expected is None:
            p1, p2 = pair.pinion, pair.gear
            a = float(np.linalg.norm(asm.axis2()[0] - asm.axis1()[0]))
            alpha_w = math.acos((p1.r_b + p2.r_b) / a)
            pitch_b = 2.0 * math.pi * p1.r_b / p1.n_teeth
            expected = (
                math.sqrt(p1.r_a**2 - p1.r_b**2) + math.sqrt(p2.r_a**2 - p2.r_b**2)
                - a * math.sin(alpha_w)
            ) / pitch_b  # fmt: skip
        # bisection to cycle / (48 · 8³) per end: 1e-4 of a cycle
        assert abs(h.interior_fraction - expected) < 2e-4, (da, h.interior_fraction, expected)


def test_corner_contacts_under_a_large_axis_error_are_resolved(tmp_path, capsys):
    """FZG at hybrid with a 0.5 mm out-of-plane axis error: every contact is a corner contact
    at a face end or the gear tip. The cells are turned onto each patch and fitted to the face
    ends, so every position is resolved (6-19 cells across each patch; none degenerate, all 9
    in the TE p-p). p_max is null with the reason (all contacts at a flank edge), the edge value
    beside it, and no "0 MPa" is printed."""
    path = _fzg(tmp_path, "f_sigma_beta_mm = 0.0 ", "f_sigma_beta_mm = 0.5 ")
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "degenerate" not in err
    assert "warning: p_max not reported: every loaded contact is at a flank edge" in err
    assert " 0 MPa" not in err
    c = _summary(out)["cycle"]
    assert c["excluded_positions"] == [] and c["te_pp_loaded_positions_used"] == 9
    assert c["p_max_MPa"] is None and "flank edge" in c["p_max_reason"]
    assert c["p_max_edge_MPa"] > 1e4 and c["p_max_edge_at"]["edges"]


def test_degenerate_positions_are_flagged_and_left_out_of_the_te(tmp_path, capsys):
    """The same pair with ``[contact] max_cells = 30``: the cap makes the cells of a pair 0.18 x
    0.35 mm where 0.03 x 0.06 mm were asked, 2 or fewer across a 0.36 mm patch at 6 positions:
    the run says the option made the cells coarser than asked, flags those positions
    degenerate, names them on the terminal and leaves them out of the TE p-p (3 of 9 used)."""
    path = _fzg(tmp_path, "f_sigma_beta_mm = 0.0 ", "f_sigma_beta_mm = 0.5 ")
    path.write_text(path.read_text(encoding="utf-8") + "\n[contact]\nmax_cells = 30\n")
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning: contact cells coarser than asked at" in err and "max_cells = 30" in err
    assert "warning: degenerate (a loaded patch the cells do not resolve) at 6 of 9" in err
    assert "0 (φ1 = -11.250°), 4 (φ1 = -1.250°)" in err
    doc = _summary(out)
    c = doc["cycle"]
    left = [e["index"] for e in c["excluded_positions"] if e["status"] == "degenerate"]
    assert left == [0, 4, 5, 6, 7, 8]
    assert "across its patch" in c["excluded_positions"][0]["reason"]
    assert c["te_pp_loaded_positions_used"] == 3
    te = [p["te_loaded_arcsec"] for i, p in enumerate(doc["positions"]) if i not in left]
    assert c["te_pp_loaded_arcsec"] == pytest.approx(max(te) - min(te), rel=1e-12)


# --------------------------------------------------------------------------------------------
# Headline logic on synthetic cycles
# --------------------------------------------------------------------------------------------


def _pair(k, share, p_int=None, p_edge=None, edges=(), resolved=True):
    from fegear.ltca.results import PairContact

    return PairContact(
        k=k, j=-k, force_N=1000.0 * share, torque_Nmm=share, load_share=share,
        p_max_MPa=max(x for x in (p_int, p_edge, 0.0) if x is not None), p_peak_MPa=0.0,
        semi_major_mm=1.0, semi_minor_mm=0.1, n_active=10, edge_contact=bool(edges),
        contact_point=np.zeros(3), edges=tuple(edges), p_interior_MPa=p_int, p_edge_MPa=p_edge,
        cells_across=8.0 if resolved else 0.5, resolved=resolved,
    )  # fmt: skip


def _cycle(positions):
    from fegear.ltca.results import LoadedCycle, LoadedPosition
    from fegear.mechanics.contact import ContactSolution

    sol = ContactSolution(np.zeros(0), np.zeros(0), np.zeros(0, bool), 0.0, 0, 0.0, 0.0, 0.0, 0.0)
    pos = tuple(
        LoadedPosition(
            phi1=0.1 * i,
            te_unloaded_arcsec=-1.0,
            te_loaded_arcsec=te,
            theta=0.0,
            pairs=tuple(pairs),
            cells=(),
            pressure=(),
            solution=sol,
            g_max_mm=0.0,
            warnings=(),
            status=status,
            status_reason=status,
        )  # fmt: skip
        for i, (te, pairs, status) in enumerate(positions)
    )
    return LoadedCycle(
        positions=pos, torque2_Nmm=1.0, phi1=np.array([p.phi1 for p in pos]),
        te_unloaded_arcsec=np.array([p.te_unloaded_arcsec for p in pos]),
        te_loaded_arcsec=np.array([p.te_loaded_arcsec for p in pos]),
        n_in_contact=np.array([p.n_pairs_in_contact for p in pos]), fidelity="hybrid", level=0,
        seconds={},
    )  # fmt: skip


def test_headline_leaves_out_what_is_not_usable():
    c = _cycle([
        (-10.0, [_pair(0, 1.0, p_int=1000.0)], "ok"),
        (-500.0, [_pair(0, 1.0, p_int=300.0, resolved=False)], "degenerate"),
        (0.0, [], "lost"),
        (-12.0, [_pair(0, 0.6, p_int=900.0), _pair(1, 0.4, p_edge=9000.0, edges=["gear tip"])],
         "ok"),
    ])  # fmt: skip
    h = c.headline()
    assert h.te_pp_loaded_arcsec == 2.0 and h.te_pp_loaded_positions_used == 2  # not 500
    assert [(e.index, e.status) for e in h.excluded_positions] == [(1, "degenerate"), (2, "lost")]
    assert h.p_max_MPa == 1000.0 and h.p_max_position == 0
    assert h.p_max_edge_MPa == 9000.0 and h.p_max_edge_edges == ("gear tip",)
    assert h.positions_with_edge_contact == (3,)


def test_headline_is_null_with_a_reason_never_zero():
    every_edge = _cycle([
        (-10.0, [_pair(0, 1.0, p_edge=5000.0, edges=["pinion tip"])], "ok"),
        (-11.0, [_pair(0, 1.0, p_edge=6000.0, edges=["gear heel"])], "ok"),
    ])  # fmt: skip
    h = every_edge.headline()
    assert h.p_max_MPa is None and "every loaded contact is at a flank edge" in h.p_max_reason
    assert "gear heel" in h.p_max_reason and h.p_max_edge_MPa == 6000.0
    nothing = _cycle([(0.0, [], "lost"), (-3.0, [_pair(0, 1.0, resolved=False)], "degenerate")])
    h = nothing.headline()
    assert h.te_pp_loaded_arcsec is None and h.te_pp_loaded_positions_used == 0
    assert "no usable position (1 degenerate, 1 lost" in h.te_pp_loaded_reason
    assert h.p_max_MPa is None and h.p_max_reason.startswith("no usable position")
    one = _cycle([(-1.0, [_pair(0, 1.0, p_int=800.0)], "ok"), (0.0, [], "lost")])
    assert one.headline().te_pp_loaded_arcsec is None
    assert "only one usable position" in one.headline().te_pp_loaded_reason


# --------------------------------------------------------------------------------------------
# Output folder, case file, tiny torque, worker count
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["file", "under a file", "unwritable"])
@pytest.mark.parametrize("case", [FZG, REPO / "cases" / "hertz_scene.toml"], ids=["gear", "hertz"])
def test_bad_out_is_refused_before_the_analysis(tmp_path, capsys, kind, case):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    if kind == "file":
        out = blocker
    elif kind == "under a file":
        out = blocker / "out"
    else:
        if not Path("/proc/self").is_dir():
            pytest.skip("needs a read-only /proc (Linux)")
        out = Path("/proc/fegear-out")  # not writable, even by root
    code = main(["run", str(case), "--out", str(out)])
    line = assert_refused(code, capsys.readouterr().err, ["--out", str(out)])
    assert {"file": "existing file", "under a file": "under the file",
            "unwritable": "can write to"}[kind] in line  # fmt: skip
    assert blocker.read_text() == "not a folder"


def test_bad_sweep_out_is_refused_before_the_items(tmp_path, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    code = main(["sweep", str(FZG), "--out", str(blocker / "sweep")])
    assert_refused(code, capsys.readouterr().err, ["--out", "under the file"])


def test_missing_case_section_asks_for_the_kind(tmp_path, capsys):
    """A gear case without ``[case]``: the message asks for the section and its kind, and does
    not list the Hertz scene's sections (``roller``, ``block``)."""
    path = _fzg(tmp_path, '[case]\nkind = "spur"\nname = "fzg_spur"\n', "")
    code = main(["run", str(path), "--out", str(tmp_path / "out")])
    line = assert_refused(code, capsys.readouterr().err, ["[case]", "kind", "'spur'"])
    assert "roller" not in line and "block" not in line


def test_hertz_at_a_tiny_torque_shares_sum_to_one(tmp_path):
    """1e-6 N·m on FZG at the hertz fidelity: the lag is ~1e-10 rad; the root searches are
    relative, so the shares of every position sum to 1 to round-off (were 1 + 6.9e-6)."""
    path = _fzg(tmp_path, "torque2_Nm = 200.0 ", "torque2_Nm = 1e-6 ")
    out = tmp_path / "out"
    assert main(["run", str(path), "--fidelity", "hertz", "--out", str(out), "-q"]) == 0
    doc = _summary(out)
    for p in doc["positions"]:
        shares = [q["load_share"] for q in p["pairs"]]
        # a few ulps: the sum of two or three shares of a torque balanced to 4 eps
        assert abs(sum(shares) - 1.0) < 1e-14, shares
    assert doc["cycle"]["max_equilibrium_residual"] < 1e-14


def test_workers_one_and_two_give_the_same_numbers_at_hybrid(tmp_path, fzg_shipped):
    """``--workers 1`` and ``--workers 2`` at hybrid, in fresh processes with the BLAS thread
    count left to the machine (the test session pins it to 1, which would hide the difference):
    every TE and share equal to 1e-9 relative (they differed by 9e-6″ when the BLAS threads
    followed the worker count; now the positions run on one BLAS thread either way: bitwise)."""
    assert fzg_shipped[0] == 0  # the sectors are cached
    env = {k: v for k, v in os.environ.items()
           if k not in ("OPENBLAS_NUM_THREADS", "FEGEAR_WORKERS", "OMP_NUM_THREADS")}  # fmt: skip
    docs = []
    for w in ("1", "2"):
        out = tmp_path / f"w{w}"
        res = subprocess.run(
            [sys.executable, "-m", "fegear.cli", "run", str(FZG), "--out", str(out), "-q",
             "--workers", w, "--recompute"],  # both solve (the second would read the first)
            env=env, capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        assert res.returncode == 0, res.stderr
        docs.append(_summary(out))

    def numbers(doc):
        v = [doc["cycle"]["te_pp_loaded_arcsec"], doc["cycle"]["p_max_MPa"]]
        for p in doc["positions"]:
            v.append(p["te_loaded_arcsec"])
            v += [q["load_share"] for q in p["pairs"]] + [q["p_max_MPa"] for q in p["pairs"]]
        return np.array(v, dtype=float)

    a, b = numbers(docs[0]), numbers(docs[1])
    assert a.shape == b.shape
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=0.0)


# --------------------------------------------------------------------------------------------
# The spiral bevel's loaded analysis at fixed positions (issue 6; FE sectors at level 0)
# --------------------------------------------------------------------------------------------
#
# The 12/36 pair at a fixed mesh position: the number of tooth pairs in contact is found by the
# solver; raising the torque closes the separations of the neighbouring pairs one after the
# other (1 → 2 → 3). The sectors and their flank operators are those of the nominal case's
# contact zone: after the p_max row above, read from the cache.

BEVEL_OPTIONS = LTCAOptions(n_positions=9, level=0)


@pytest.fixture(scope="module")
def bevel(spiral_bevel_pair):
    pair = spiral_bevel_pair  # the session's (tests/conftest.py): the nominal case's pair
    asm = spiral_bevel_assembly(pair, "drive", InstallationErrors())
    return pair, asm, build_models(pair.pinion, pair.gear, asm, BEVEL_OPTIONS)


def test_bevel_pairs_in_contact_go_from_one_to_three_with_torque(bevel):
    pair, asm, models = bevel
    phi = np.array([-math.pi / 12 + 2 * math.pi / 12 * 5 / 9])  # 1.67 deg: mid single contact
    counts, balance = [], []
    for torque in (1e4, 1e5, 4e5, 1e6):  # N·mm on the gear (10 ... 1000 N·m)
        c = run_ltca(pair.pinion, pair.gear, asm, torque, BEVEL_OPTIONS, phi1=phi,
                     models=models)  # fmt: skip
        counts.append(int(c.n_in_contact[0]))
        balance.append(c.positions[0].solution.equilibrium_residual)
    # measured 1, 1, 3, 3: the count is the active set's, never an input
    assert counts[0] == 1 and counts[-1] == 3, counts
    assert counts == sorted(counts), counts
    assert max(balance) < 1e-9  # torque balance enforced by the solver


def test_bevel_loaded_te_keeps_the_designed_parabola_at_light_load(bevel):
    pair, asm, models = bevel
    c = run_ltca(pair.pinion, pair.gear, asm, 1e4, BEVEL_OPTIONS, models=models)
    # unloaded: the predesigned parabola of ~8 arcsec (TCA tests); loaded at 10 N·m: a small lag
    # on top, so the curve keeps its parabolic peak-to-peak within a few arcsec
    assert 8.0 * 0.9 < c.te_pp_unloaded_arcsec < 8.0 * 1.1
    assert np.all(c.te_loaded_arcsec <= c.te_unloaded_arcsec + 1e-9)  # the load only lags
    assert abs(c.te_pp_loaded_arcsec - c.te_pp_unloaded_arcsec) < 4.0


# --------------------------------------------------------------------------------------------
# The spiral bevel's CalculiX deck (docs/calculix.md): the nominal case's contact zone (its TCA)
# is the one the p_max row above computed
# --------------------------------------------------------------------------------------------


def test_spiral_bevel_deck_is_valid_with_a_pair_per_closing_tooth_pair():
    """The spiral bevel at position 6 with 1 mm contact elements (the cross-check's coarsest):
    positive C3D10 volumes, mid-edge nodes at their edges' midpoints but for the flank
    nodes moved onto the flank, and one contact pair per tooth pair that can touch: every pair
    whose sampled separation at the position is within the deck's reach, none that is not a
    valid pair there, and the other valid pairs recorded as left out."""
    from test_calculix import _deck_elements, _mid_edge_offsets, _volumes

    from fegear.case_files import load_case
    from fegear.export import position_angle
    from fegear.export.gear_deck import DEFAULT_REACH_MM, gear_deck
    from fegear.ltca import LTCAOptions
    from fegear.ltca.cycle import cycle_tca
    from fegear.pipeline.pair import build_pair

    case = load_case(BEVEL)
    phi1 = position_angle(case, 6)
    deck = gear_deck(case, phi1, 1.0)
    xyz, el = _deck_elements(deck.text)
    assert el.shape[1] == 10
    assert np.all(_volumes(xyz, el) > 0.0)
    dev, _ = _mid_edge_offsets(xyz, el)
    rec = deck.record
    # a mid-edge node moves only onto the flank, by at most the largest move the record states
    assert np.max(dev) <= max(rec["projected_mm"].values()) + 1e-9
    # the pairs the TCA closes within the reach at this position (the deck's own TCA inputs)
    pair = build_pair(case)
    opt = LTCAOptions(n_positions=case.n_positions, level=case.level, n_teeth=case.n_teeth,
                      E_MPa=case.E_MPa, nu=case.nu, fidelity="fe")  # fmt: skip
    _, positions, _ = cycle_tca(pair.pinion, pair.gear, pair.assembly, opt, np.array([phi1]))
    sep = {(g.k, g.j): float(np.min(g.separation[g.valid], initial=np.inf))
           for g in positions[0].grids}  # fmt: skip
    in_deck = {(p["k"], p["j"]) for p in rec["pairs"]}
    sampled = {kj for kj, s in sep.items() if s <= DEFAULT_REACH_MM}
    # the deck also takes a pair whose exact closest point (between the samples) is within the
    # reach: its sampled separation exceeds the reach by less than the sampling's sag
    assert sampled <= in_deck and all(sep[kj] <= 2 * DEFAULT_REACH_MM for kj in in_deck)
    assert len(in_deck) >= 1
    assert deck.text.count("*CONTACT PAIR") == 1  # one card, one line per pair
    for p in rec["pairs"]:
        assert f"\n{p['slave']}, {p['master']}\n" in deck.text
    left = {(q["k"], q["j"]) for q in rec["left_out"]}
    assert not (left & in_deck)
    assert sorted(in_deck | left) == sorted(
        (int(k), int(j)) for (k, j), ok in zip(positions[0].pairs, positions[0].pair_valid,
                                               strict=True) if ok
    )  # fmt: skip
