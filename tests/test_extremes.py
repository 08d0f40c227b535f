"""Honest at the extremes, round two (issue 30): one test per row of the README's "Reliability"
table that these items added, each asserting the exit code, the field or flag named, or the
corrected number.

- geometric limits of generated members refused when the case is read, naming the field and the
  computed limit (face-gear undercut and pointing radii and module, involute pointed tips and
  tip clearance, the face gear's pinion, bevel top land);
- the loaded cycle's worker processes end with their parent, however it ends;
- an output folder holds one run (manifest, ``--overwrite``, no temporary file survives);
- smaller items: a UTF-8 byte-order mark, a pair that jams, ``p_max.png``, ``te_overlay.png``.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from cli_checks import assert_refused

from fegear.cli import main

REPO = Path(__file__).resolve().parents[1]
FZG = REPO / "cases" / "fzg_spur.toml"
FACE_GEAR = REPO / "cases" / "face_gear_nominal.toml"
FZG_TEXT = FZG.read_text(encoding="utf-8")
FACE_GEAR_TEXT = FACE_GEAR.read_text(encoding="utf-8")


def _case(tmp_path: Path, text: str, old: str, new: str, name: str = "case.toml") -> Path:
    assert old in text, old
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


@pytest.fixture
def no_work(monkeypatch):
    """Fail if the run reaches the TCA (what "before any work" means here)."""
    import fegear.pipeline.run as gear_run
    import fegear.tca.cached as cached

    def refuse(*a, **k):
        raise AssertionError("the TCA ran: the limit was not checked when the case was read")

    # the TCA where it is defined and where the run calls it
    monkeypatch.setattr(cached, "cached_tca", refuse)
    monkeypatch.setattr(gear_run, "cached_tca", refuse)


# --------------------------------------------------------------------------------------------
# Geometric limits, refused naming the field
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        # the seed's undercut limit L1 = 464.970 mm and pointing limit L2 = 570.181 mm
        ("inner_radius_mm = 471.0", "inner_radius_mm = 460.0",
         ["pair.inner_radius_mm = 460.0", ">= 464.970 mm (undercut limit L1)"]),
        ("outer_radius_mm = 560.0", "outer_radius_mm = 575.0",
         ["pair.outer_radius_mm = 575.0", "<= 570.181 mm (pointed-tooth limit L2)"]),
        ("outer_radius_mm = 560.0", "outer_radius_mm = 700.0",
         ["pair.outer_radius_mm = 700.0", "<= 570.181 mm"]),
        # the limits scale with the module: 471/73.2237 and 560/89.7922 mm
        ("module_mm = 6.35", "module_mm = 4500",
         ["pair.module_mm = 4500", "in [6.237, 6.432] mm", "pitch radius"]),
        ("n_pinion = 25", "n_pinion = 8", ["pair.n_pinion = 8", ">= 13", "undercut"]),
    ],
    ids=["inner460", "outer575", "outer700", "module4500", "pinion8"],
)  # fmt: skip
def test_face_gear_limits_are_refused_when_the_case_is_read(
    tmp_path, capsys, no_work, old, new, words
):
    text = FACE_GEAR_TEXT
    if "n_pinion = 8" in new:
        text = text.replace("n_shaper = 27", "n_shaper = 10")
    path = _case(tmp_path, text, old, new)
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out), "-q"])
    assert_refused(code, capsys.readouterr().err, words)
    assert not out.exists()


def test_face_gear_limits_scale_with_the_module():
    """What the module range of the refusal rests on: the drive is similar in the module, so
    the limits solved at module 2 on its own surface are twice those at module 1 (each found to
    1e-10 mm by its root finder; the Newton solves stop at 1e-12 mm)."""
    from fegear.geometry import FaceGearDesign, FaceGearMember

    def member(m: float) -> FaceGearMember:
        return FaceGearMember(FaceGearDesign(module_mm=m, inner_radius_mm=74.0 * m,
                                             outer_radius_mm=88.0 * m))  # fmt: skip

    one, two = member(1.0), member(2.0)
    assert two.inner_limit() == pytest.approx(2.0 * one.inner_limit(), abs=1e-8)
    assert two.outer_limit() == pytest.approx(2.0 * one.outer_limit(), abs=1e-8)
    assert two.limits == pytest.approx((2.0 * one.limits[0], 2.0 * one.limits[1]), abs=1e-8)


def test_profile_shift_sum_is_refused_with_the_tip_clearance_limit(tmp_path, capsys, no_work):
    """``profile_shift = [0.7, 0.9]``: the tips run 0.1105 mm into the roots at the zero-backlash
    centre distance; the largest shift sum that clears is 1.5098. At that sum (the shifts in the
    same proportion) the measured clearance of the assembled pair is zero to a micrometre."""
    from fegear.case_files import load_case
    from fegear.pipeline.pair import build_pair
    from fegear.tca.engagement import tip_root_clearance

    path = _case(tmp_path, FZG_TEXT, "profile_shift = [0.1817, 0.1715]",
                 "profile_shift = [0.7, 0.9]")  # fmt: skip
    code = main(["run", str(path), "--out", str(tmp_path / "out"), "-q"])
    line = assert_refused(
        code, capsys.readouterr().err, ["pair.profile_shift = [0.7, 0.9]", "x1 + x2 <= 1.5098"]
    )
    assert "0.1105 mm into the mate's root" in line, line
    x1, x2 = (0.7 * 1.5098 / 1.6, 0.9 * 1.5098 / 1.6)
    at = _case(tmp_path, FZG_TEXT, "profile_shift = [0.1817, 0.1715]",
               f"profile_shift = [{x1!r}, {x2!r}]", "at.toml")  # fmt: skip
    pair = build_pair(load_case(at))
    c = tip_root_clearance(pair.pinion, pair.gear, pair.assembly)
    # the limit printed to 1e-4 in x: dc/dx_sum ~ 0.6 m = 2.7 mm, so 3e-4 mm; sampling < 1e-6
    assert abs(min(c.pinion_tip_mm, c.gear_tip_mm)) < 5e-4, c


def test_pointed_tip_is_refused_naming_the_members_shift(tmp_path, capsys, no_work):
    path = _case(tmp_path, FZG_TEXT, "profile_shift = [0.1817, 0.1715]",
                 "profile_shift = [1.2, 0.1]")  # fmt: skip
    code = main(["run", str(path), "--out", str(tmp_path / "out"), "-q"])
    assert_refused(
        code, capsys.readouterr().err, ["pair.profile_shift[0] = 1.2", "<= 1.0341", "pointed"]
    )


def test_bevel_tooth_check_names_the_field():
    """The decision of :meth:`SpiralBevelMember.check_tooth` on given top lands: a land that
    vanishes toward the toe names the face width with the cone distance where it crosses zero
    (linear between samples); one that vanishes at the heel names the tooth count; a singular
    line on the working surface (undercut) names the tooth count."""
    from types import SimpleNamespace

    from fegear.errors import DesignError
    from fegear.geometry.bevel import SpiralBevelMember

    L = np.linspace(60.0, 90.0, 4)  # toe -> heel

    def member(land, sing=(0.2, 0.3)):
        blank = SimpleNamespace(
            outer_cone_distance=lambda i: 90.0,
            face_width=lambda i: 30.0,
            field_prefix="spiral_bevel",
        )
        return SimpleNamespace(tooth_limits=lambda: (L, np.array(land), np.array(sing)),
                               blank=blank, name="pinion", index=1, n_teeth=9)  # fmt: skip

    with pytest.raises(DesignError, match=r"face_width_mm.*<= 25\.00 mm"):
        SpiralBevelMember.check_tooth(member([-0.5, 0.5, 1.0, 1.5]))  # zero at L = 65
    with pytest.raises(DesignError, match=r"spiral_bevel\.n1 = 9.*more teeth.*pointed"):
        SpiralBevelMember.check_tooth(member([1.5, 1.0, 0.5, -0.5]))
    with pytest.raises(DesignError, match=r"spiral_bevel\.n1 = 9.*undercut"):
        SpiralBevelMember.check_tooth(member([1.5, 1.0, 1.0, 1.0], sing=(0.2, -1.0)))
    SpiralBevelMember.check_tooth(member([1.5, 1.0, 1.0, 1.0]))  # passes


@pytest.mark.slow
def test_pointed_bevel_pinion_is_refused(tmp_path, capsys):
    """A 6-tooth pinion against 36: the top land of the pinion crosses zero toward the heel
    (-0.577 mm there): refused naming ``pair.n_pinion`` (45 s of synthesis)."""
    text = (REPO / "cases" / "spiral_bevel_nominal.toml").read_text("utf-8")
    path = _case(tmp_path, text, "n_pinion = 12", "n_pinion = 6")
    code = main(["run", str(path), "--fidelity", "tca", "--out", str(tmp_path / "out"), "-q"])
    assert_refused(code, capsys.readouterr().err, ["pair.n_pinion = 6", "pointed tooth"])


# --------------------------------------------------------------------------------------------
# Worker processes end with their parent
# --------------------------------------------------------------------------------------------

_STUCK = textwrap.dedent(
    """
    import os, sys, time
    import fegear.ltca.cycle as cycle

    def stuck(r, job=None):  # a position that takes forever (the workers are the real pool's)
        # one write() of a whole line: atomic on a pipe (print's may split, and the two workers'
        # lines then interleave)
        os.write(1, f"worker {os.getpid()}\\n".encode())
        time.sleep(600)

    cycle._solve_chunk = stuck
    job = cycle.CycleJob(tca=None, positions=(), models=None, options=None, torque2_Nmm=1.0)
    cycle._solve_all(job, [range(0, 1), range(1, 2)], 2, None)
    """
)


def _gone(pid: int) -> bool:
    """No process ``pid``, or only its zombie (its new parent has not reaped it yet)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] == "Z"
    except FileNotFoundError:
        return True


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM], ids=["SIGKILL", "SIGTERM"])
def test_workers_end_with_their_parent(sig):
    """The parent of two workers solving positions is killed: both workers are gone within a
    generous bound (measured: 0.22 s after SIGKILL or SIGTERM of a real `fegear run --workers 2`
    of FZG at 40 positions; the bound only keeps the test from hanging)."""
    p = subprocess.Popen([sys.executable, "-c", _STUCK], stdout=subprocess.PIPE, text=True)
    try:
        workers = [int(p.stdout.readline().split()[1]) for _ in range(2)]
        assert all(not _gone(w) for w in workers)
        p.send_signal(sig)
        p.wait(timeout=60)
        deadline = time.monotonic() + 60.0
        while not all(_gone(w) for w in workers) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert all(_gone(w) for w in workers), f"workers {workers} outlived their parent"
    finally:
        p.kill()
        for w in workers if "workers" in dir() else ():
            if not _gone(w):
                os.kill(w, signal.SIGKILL)


def test_a_worker_whose_parent_died_before_it_was_armed_exits(monkeypatch):
    """The race of PR_SET_PDEATHSIG: armed after the fork, so a parent that died in between is
    seen by the parent-pid check and the worker exits at once."""
    from fegear import forked

    code = subprocess.run(
        [sys.executable, "-c",
         "import os; from fegear.forked import die_with_parent; "
         "die_with_parent(os.getppid() + 1000003); print('survived')"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert code.returncode == 1 and "survived" not in code.stdout
    assert forked.PR_SET_PDEATHSIG == 1  # linux/prctl.h


# --------------------------------------------------------------------------------------------
# An output folder holds one run
# --------------------------------------------------------------------------------------------


def _tca_run(out: Path, *extra: str, case: Path = FZG) -> int:
    return main(["run", str(case), "--fidelity", "tca", "--out", str(out), *extra])


def test_an_earlier_runs_outputs_are_replaced_and_other_files_refused(tmp_path, capsys):
    """A face-gear run's folder (its manifest lists ``cycle.pvd``, ``vtk/`` and PNGs) receives
    an FZG ``tca`` run: the face gear's files are gone, the FZG's listed, the line says so. A
    folder with a file fegear did not write is refused naming ``--out`` (exit 2) before any work;
    with ``--overwrite`` it is written and the other file kept."""
    from fegear.store.outputs import MANIFEST

    out = tmp_path / "out"
    (out / "vtk").mkdir(parents=True)
    old = ["cycle.pvd", "load_share.png", "p_max.png"]
    old += [f"vtk/flank_gear_{i:03d}.vtp" for i in range(125)]
    for f in old:
        (out / f).write_text("face gear", encoding="utf-8")
    (out / MANIFEST).write_text("# header\n" + "\n".join(old) + "\n", encoding="utf-8")
    assert _tca_run(out) == 0
    err = capsys.readouterr().err
    assert f"{out}/: the 128 files of the previous run removed" in err, err
    names = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    tca_files = ["bearing_pattern.png", "ease_off.json", "ease_off.png", "ease_off.vts",
                 "summary.json", "te.png"]  # fmt: skip
    assert names == [MANIFEST, *tca_files], names
    listed = (out / MANIFEST).read_text("utf-8").split("\n")[1:]
    assert sorted(x for x in listed if x) == tca_files

    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("my notes", encoding="utf-8")
    code = _tca_run(mine, "-q")
    assert_refused(code, capsys.readouterr().err, [f"--out = '{mine}'", "--overwrite", "notes.txt"])
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]
    assert _tca_run(mine, "--overwrite") == 0
    assert "--overwrite: 1 files fegear did not write are kept" in capsys.readouterr().err
    assert (mine / "notes.txt").read_text("utf-8") == "my notes" and (mine / "te.png").is_file()


def test_api_write_has_the_same_choice(tmp_path):
    """``result.write(folder)`` refuses a foreign folder naming ``folder``; ``overwrite=True``
    writes into it (the API's twin of ``--overwrite``)."""
    import fegear
    from fegear.errors import InputError

    res = fegear.run(fegear.load_case(FZG), fidelity="tca")
    (tmp_path / "x.csv").write_text("1,2", encoding="utf-8")
    with pytest.raises(InputError, match=r"folder = .*overwrite=True"):
        res.write(tmp_path)
    paths = res.write(tmp_path, overwrite=True)
    assert (tmp_path / "x.csv").is_file() and all(p.is_file() for p in paths)
    res.write(tmp_path / "again")
    res.write(tmp_path / "again")  # its own earlier run: no flag needed


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_temporary_files_of_a_killed_write_are_removed_by_the_next_run(tmp_path, capsys):
    """A writer killed between writing and renaming (kill -9) leaves ``.<name>.tmp<pid>_*``: the
    next run into the folder removes it (its writer is gone), and the leftovers of an earlier
    fegear's temporary names (``vtk/.flank_pinion_013.<random>.vtp``); in the cache, the same
    for the mesh files (``.<key>.tmp<pid>_*.msh``), while a live writer's file stays."""
    from fegear.store.files import clean_stale_temps

    out = tmp_path / "out"
    killer = textwrap.dedent(
        f"""
        import time
        from pathlib import Path
        from fegear.store.files import atomic_write
        def slow(tmp):
            tmp.write_text("half", encoding="utf-8")
            print("writing", flush=True)
            time.sleep(600)
        atomic_write(Path({str(out / "summary.json")!r}), slow)
        """
    )
    p = subprocess.Popen([sys.executable, "-c", killer], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "writing"
    p.kill()
    p.wait(timeout=60)
    left = [q.name for q in out.iterdir()]
    assert len(left) == 1 and left[0].startswith(f".summary.tmp{p.pid}_"), left
    (out / "vtk").mkdir()
    (out / "vtk" / ".flank_pinion_013.k2j4x9qa.vtp").write_text("old", encoding="utf-8")
    assert _tca_run(out) == 0
    assert "2 temporary files of an interrupted run removed" in capsys.readouterr().err
    assert not list(out.rglob(".*tmp*")) and not (out / "vtk").exists()
    assert sorted(q.name for q in out.iterdir() if not q.name.startswith(".")) == [
        "bearing_pattern.png", "ease_off.json", "ease_off.png", "ease_off.vts", "summary.json",
        "te.png"]  # fmt: skip

    cache = tmp_path / "cache" / "sector_mesh"
    cache.mkdir(parents=True)
    dead = cache / f".0123456789abcdef0123.tmp{_dead_pid()}_abcdefgh.msh"
    live = cache / f".0123456789abcdef0124.tmp{os.getpid()}_abcdefgh.msh"
    kept = cache / "0123456789abcdef0123.msh"
    for f in (dead, live, kept):
        f.write_text("x", encoding="utf-8")
    assert clean_stale_temps(tmp_path / "cache", recursive=True) == [dead]
    assert live.exists() and kept.exists()


def test_the_cache_is_cleaned_when_a_run_starts(tmp_path, monkeypatch):
    import fegear
    import fegear.api.runner as api
    from fegear.store.cache import check_cache_root

    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(api, "_CLEANED", set())
    kind = check_cache_root() / "tca"  # a cache (with its tag), then a kill -9 in it
    kind.mkdir()
    dead = kind / f".0123456789abcdef0123.tmp{_dead_pid()}_abcdefgh.npz"
    dead.write_text("x", encoding="utf-8")
    with pytest.raises(fegear.InputError):
        fegear.run(fegear.load_case(FZG), fidelity="nonsense")  # cleaned before the checks
    assert not dead.exists()


def test_plot_draws_only_the_files_of_the_folders_run(tmp_path, monkeypatch, capsys):
    """``fegear plot`` reads the flank views the folder's run listed (``summary.json``), never a
    stale one of another run left beside them."""
    import fegear.output.flank_view as fv
    import fegear.output.flank_vtp as fvtp
    from fegear.store.outputs import MANIFEST

    out = tmp_path / "out"
    (out / "vtk").mkdir(parents=True)
    listed = [f"vtk/flank_gear_{i:03d}.vtp" for i in range(3)]
    for f in listed + ["vtk/flank_gear_099.vtp"]:  # 099: a stale file of another case
        (out / f).write_text("<vtp/>", encoding="utf-8")
    (out / MANIFEST).write_text("# h\n" + "\n".join(listed) + "\nsummary.json\n", "utf-8")
    doc = {"case": "c", "fidelity": "hybrid", "level": 0, "cycle": {"p_max_MPa": 1.0},
           "files": listed, "versions": {"fegear": "0"}}  # fmt: skip
    (out / "summary.json").write_text(json.dumps(doc), encoding="utf-8")
    read = []
    monkeypatch.setattr(fvtp, "read_flank_vtp", lambda f: read.append(Path(f).name) or (0, 0, 0))
    written = []

    def fake_plot(frame, patches, png, *a):  # writes as the real one does (atomically)
        from fegear.store.files import atomic_write

        written.append(atomic_write(png, lambda q: q.write_bytes(b"png")))
        return png

    monkeypatch.setattr(fv, "plot_flank_pattern", fake_plot)
    assert main(["plot", str(out), "-q"]) == 0
    assert read == [Path(f).name for f in listed]
    # the picture joins the run's files: the next run into the folder replaces it as well
    assert "bearing_pattern_gear_flank.png" in (out / MANIFEST).read_text("utf-8").split()


# --------------------------------------------------------------------------------------------
# Smaller items
# --------------------------------------------------------------------------------------------


def test_a_byte_order_mark_is_accepted():
    """A case file saved by a Windows editor (UTF-8 with a BOM) reads as the same case."""
    import tempfile

    from fegear.case_files import load_case

    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "bom.toml"
        p.write_bytes(b"\xef\xbb\xbf" + FZG.read_bytes())
        a, b = load_case(p), load_case(FZG)
    assert a.replace(source=b.source) == b


def test_a_pair_that_jams_is_warned_with_the_depth(tmp_path, capsys):
    """FZG at ``da_mm = -0.5``: the teeth, cut without backlash, overlap by 0.3755 mm along the
    line of action (warning naming ``errors.da_mm``). The closed form against the textbook's
    first-order backlash ``j_n = 2 Δa sin α_w cos β_b``: 1e-4 relative at Δa = -1 µm."""
    from fegear.case_files import load_case
    from fegear.pipeline.pair import build_pair
    from fegear.tca.engagement import jamming

    path = _case(tmp_path, FZG_TEXT, "da_mm = 0.0 ", "da_mm = -0.5 ")
    assert main(["run", str(path), "--fidelity", "tca", "--out", str(tmp_path / "o")]) == 0
    err = capsys.readouterr().err
    warn = [ln for ln in err.splitlines() if ln.startswith("warning: the pair jams")]
    assert len(warn) == 1 and "errors.da_mm = -0.5" in warn[0] and "0.3755 mm" in warn[0], err
    doc = json.loads((tmp_path / "o" / "summary.json").read_text("utf-8"))
    assert any("the pair jams" in w for w in doc["warnings"])
    pair = build_pair(load_case(FZG))
    case = load_case(FZG).with_errors(da_mm=-0.001)
    j = jamming(pair.pinion, pair.gear, case.errors)
    rb = pair.pinion.r_b + pair.gear.r_b  # spur: β_b = 0
    alpha_w = math.acos(rb / j.working_mm)
    assert j.depth_mm == pytest.approx(2 * 0.001 * math.sin(alpha_w), rel=1e-4)
    assert jamming(pair.pinion, pair.gear, load_case(FZG).errors) is None
    assert jamming(pair.pinion, pair.gear, load_case(FZG).with_errors(da_mm=0.1).errors) is None


class _Pair:
    def __init__(self, k, force, p_int=None, p_edge=None):
        self.k, self.force_N, self.p_interior_MPa, self.p_edge_MPa = k, force, p_int, p_edge


class _Pos:
    def __init__(self, *pairs):
        self.pairs = pairs


def test_p_max_plot_marks_the_edge_values_apart():
    """The "position max" line is the largest pressure away from the edges (a gap where a
    position has none); the singular edge values are markers, never on the line; the y range
    is that of the interior values."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from fegear.output.p_max_plot import p_max_series, plot_p_max

    cycle = type("C", (), {})()
    cycle.phi1 = np.radians([0.0, 1.0, 2.0])
    cycle.positions = (
        _Pos(_Pair(0, 10.0, p_int=1200.0, p_edge=7751.0), _Pair(1, 1.0, p_int=900.0)),
        _Pos(_Pair(0, 10.0, p_int=1250.0)),
        _Pos(_Pair(1, 10.0, p_edge=6000.0)),  # only an edge contact
    )
    s = p_max_series(cycle)
    assert s.position_max[:2].tolist() == [1200.0, 1250.0] and math.isnan(s.position_max[2])
    assert s.edge[:, 1].tolist() == [7751.0, 6000.0]
    fig, ax = plt.subplots()
    lo, hi = plot_p_max(ax, s)
    assert (lo, hi) == (0.0, pytest.approx(1.15 * 1250.0))
    assert max(ax.get_ylim()) < 6000.0
    plt.close(fig)


def test_te_overlay_draws_numerical_noise_flat():
    """A conjugate pair's unloaded TE is 0 up to 1e-10″ of round-off: drawn as 0 with a y range
    of ±0.1″; a real TE (0.01″) is drawn as it is."""
    from fegear.sweep.output import TE_NOISE_ARCSEC, about_mean, flat_limits

    assert 1e-10 < TE_NOISE_ARCSEC < 1e-4
    noise = np.array([-0.0, -9.16e-11, 3e-11, -0.0])
    dev, mean = about_mean(noise)
    assert np.all(dev == 0.0) and abs(mean) < 1e-10
    assert flat_limits([dev, np.array([0.0, np.nan])]) == (-0.1, 0.1)
    real, _ = about_mean(np.array([0.0, 0.01, 0.0, 0.01]))
    assert np.allclose(real, [-0.005, 0.005, -0.005, 0.005]) and flat_limits([real]) is None
