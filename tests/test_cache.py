"""The artefact cache in the per-user cache folder (issue 22).

- ``$FEGEAR_CACHE`` wins, else the platform's per-user cache folder: never a folder under the
  current working directory, so two fresh working directories share one cache (the second run
  of the same case from another folder is warm: asserted by the cache hits it reports, not by
  its timing).
- ``fegear cache info`` says where the cache is and what it holds; ``fegear cache clear``
  deletes artefacts (all, or one ``--kind``) and refuses a folder that is not a fegear cache.
- The test suite itself runs on a private cache (``tests/conftest.py``).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import platformdirs
import pytest

from fegear.cli import main
from fegear.store import cache as fcache

REPO = Path(__file__).resolve().parents[1]
FZG = REPO / "cases" / "fzg_spur.toml"


def _user_cache_in(monkeypatch, tmp_path: Path) -> Path:
    """Unset ``$FEGEAR_CACHE`` and point the platform's per-user cache folder into ``tmp_path``
    (XDG on Linux, HOME on macOS); returns the cache root, checked to lie there (the test must
    never write into the real user cache)."""
    if sys.platform.startswith("win"):
        pytest.skip("the per-user cache folder of Windows cannot be redirected by environment")
    monkeypatch.delenv("FEGEAR_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    if sys.platform == "darwin":
        monkeypatch.setenv("HOME", str(tmp_path / "home"))
    root = fcache.cache_root()
    assert root == Path(platformdirs.user_cache_dir("fegear", appauthor=False))
    assert tmp_path in root.parents, root
    return root


def test_the_suite_runs_on_a_private_cache():
    """conftest.py points ``$FEGEAR_CACHE`` at a temporary folder for the whole session."""
    root = fcache.cache_root()
    assert os.environ["FEGEAR_CACHE"] and root == Path(os.environ["FEGEAR_CACHE"])
    assert root != Path(platformdirs.user_cache_dir("fegear", appauthor=False))
    assert root.name.startswith("fegear_test_cache_")


def test_root_is_fegear_cache_else_the_user_cache_folder(monkeypatch, tmp_path):
    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path / "mine"))
    assert fcache.cache_root() == tmp_path / "mine"
    root = _user_cache_in(monkeypatch, tmp_path)
    for name in ("a", "b"):  # the same root from any working directory
        (tmp_path / name).mkdir()
        monkeypatch.chdir(tmp_path / name)
        assert fcache.cache_root() == root


def _case(tmp_path: Path) -> Path:
    text = FZG.read_text(encoding="utf-8").replace("n_positions = 9", "n_positions = 3")
    path = tmp_path / "fzg3.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_two_working_directories_share_one_cache(monkeypatch, tmp_path):
    """``fegear run`` of the same case from two fresh folders: the first builds the meshes,
    operators, TCA and loaded cycle in the per-user cache, the second reads the run back."""
    root = _user_cache_in(monkeypatch, tmp_path)
    case = _case(tmp_path)
    docs = []
    for name in ("first", "second"):
        work = tmp_path / name
        work.mkdir()
        monkeypatch.chdir(work)
        # fe: the quickest loaded fidelity that builds sector meshes and operators
        assert main(["run", str(case), "-q", "--workers", "1", "--fidelity", "fe"]) == 0
        docs.append(json.loads((work / "out" / "summary.json").read_text()))
        assert not (work / "meshes").exists()  # nothing cached under the working directory
    first, second = (d["cache"] for d in docs)
    assert first["folder"] == second["folder"] == str(root)
    assert {"mesh", "compliance", "tca", "cycle", "member_fields"} <= set(first["built"])
    # warm: the second built nothing and read the run back (TCA, loaded cycle, fields), with
    # no need of the meshes and operators the cycle was solved on
    assert second["built"] == {}
    assert {"tca", "cycle", "member_fields"} <= set(second["hits"])
    te = [[p["te_loaded_arcsec"] for p in d["positions"]] for d in docs]
    assert te[0] == te[1]  # the same operators: the same numbers
    assert (root / fcache.CACHE_TAG).read_text().startswith("Signature: 8a477f597d28d172")


@pytest.mark.slow
def test_main_job_from_two_folders_shares_one_cache(monkeypatch, tmp_path):
    """The main job (``fegear run``, the seed face gear at hybrid level 0, ~1 min cold) from two
    fresh folders: the second run is warm."""
    _user_cache_in(monkeypatch, tmp_path)
    docs = []
    for name in ("first", "second"):
        work = tmp_path / name
        work.mkdir()
        monkeypatch.chdir(work)
        assert main(["run", "-q"]) == 0
        docs.append(json.loads((work / "out" / "summary.json").read_text()))
    assert {"mesh", "compliance", "cycle"} <= set(docs[0]["cache"]["built"])
    # the same run again: its loaded cycle and fields read back, no mesh or operator even read
    assert docs[1]["cache"]["built"] == {}
    assert docs[1]["cache"]["hits"]["cycle"] == 1 and docs[1]["cache"]["hits"]["member_fields"] == 1
    assert "compliance" not in docs[1]["cache"]["hits"]


# --------------------------------------------------------------------------------------------
# fegear cache info / clear
# --------------------------------------------------------------------------------------------


def _fill(kind: str, n: int) -> None:
    made_by = fcache.Producer(("fegear.store",))  # test kinds: not in fcache.PRODUCERS
    for i in range(n):
        fcache.cached_file(
            kind, {"i": i}, ".bin", lambda p, i=i: p.write_bytes(b"x" * (i + 1)), made_by
        )


def test_cache_info_and_clear(monkeypatch, tmp_path, capsys):
    root = tmp_path / "c"
    monkeypatch.setenv("FEGEAR_CACHE", str(root))
    assert main(["cache", "info"]) == 0
    assert "empty" in capsys.readouterr().out
    _fill("alpha", 3)
    _fill("beta", 2)
    info = fcache.cache_info()
    assert info.is_cache and info.source == "FEGEAR_CACHE"
    # an entry is its data file and its record (sizes and checksums)
    on_disk = {k: sum(p.stat().st_size for p in (root / k).iterdir()) for k in ("alpha", "beta")}
    assert [(k.kind, k.entries, k.files, k.bytes) for k in info.kinds] == [
        ("alpha", 3, 6, on_disk["alpha"]),
        ("beta", 2, 4, on_disk["beta"]),
    ]
    assert main(["cache", "info"]) == 0
    out = capsys.readouterr().out
    assert str(root) in out and "FEGEAR_CACHE" in out
    assert any(ln.split()[:3] == ["alpha", "3", "entries"] for ln in out.splitlines())
    lines = [ln.split() for ln in out.splitlines()]
    assert ["total", "5", "entries", "10", "files"] in [ln[:5] for ln in lines]
    assert "size cap 10.0 GB" in out  # the default cap, shown
    assert main(["cache", "clear", "--kind", "alpha"]) == 0
    assert "removed 6 files" in capsys.readouterr().out
    assert [k.kind for k in fcache.cache_info().kinds] == ["beta"]
    assert main(["cache", "clear", "--kind", "gamma"]) == 2  # not a kind of the cache
    assert "--kind" in capsys.readouterr().err
    (root / "notes.txt").write_text("mine")  # not an artefact: stays
    assert main(["cache", "clear"]) == 0
    assert fcache.cache_info().files == 0 and (root / "notes.txt").read_text() == "mine"


def test_clear_refuses_a_folder_that_is_not_a_fegear_cache(monkeypatch, tmp_path, capsys):
    root = tmp_path / "home"
    (root / "mesh").mkdir(parents=True)
    (root / "mesh" / "thesis.tex").write_text("precious")
    (root / "0123456789abcdef0123.npy").write_text("looks like an artefact, but no tag")
    monkeypatch.setenv("FEGEAR_CACHE", str(root))
    assert main(["cache", "clear"]) == 2
    err = capsys.readouterr().err
    assert "not allowed" in err and "fegear cache folder" in err and "nothing was deleted" in err
    assert (root / "mesh" / "thesis.tex").read_text() == "precious"
    assert (root / "0123456789abcdef0123.npy").exists()


def test_a_cache_of_an_older_fegear_is_recognised_by_its_layout(monkeypatch, tmp_path):
    """``meshes/cache`` of earlier versions has no tag: kind folders of content-hash files."""
    root = tmp_path / "meshes" / "cache"
    (root / "compliance").mkdir(parents=True)
    (root / "compliance" / "0123456789abcdef0123.npy").write_bytes(b"1234")
    (root / "tca").mkdir()
    (root / "tca" / ".0123456789abcdef0123.k2j3_x.pkl").write_bytes(b"12")  # a dead temp file
    monkeypatch.setenv("FEGEAR_CACHE", str(root))
    assert fcache.is_cache_folder(root)
    gone = fcache.clear_cache()
    assert (gone.files, gone.bytes) == (2, 6) and not any(root.iterdir())


# --------------------------------------------------------------------------------------------
# A cache that looks after itself: verified reads, a size cap, an unusable root refused
# --------------------------------------------------------------------------------------------

_MADE_BY = fcache.Producer(("fegear.store",))


def _entry(kind: str, i: int, size: int, built: list[int] | None = None) -> tuple[Path, bool]:
    """A test artefact of ``size`` bytes (``built`` collects ``i`` whenever it is built)."""

    def build(p: Path) -> None:
        if built is not None:
            built.append(i)
        p.write_bytes(bytes([i % 251]) * size)

    return fcache.cached_file(kind, {"i": i}, ".bin", build, _MADE_BY)


@pytest.mark.parametrize("damage", ["truncated", "overwritten", "record cut"])
def test_a_damaged_entry_is_rebuilt_with_a_warning(monkeypatch, tmp_path, caplog, damage):
    """What a full disk, a killed copy or a bad sector leaves: the next read finds it (size,
    checksum, record), says so naming the cache, and builds the entry again."""
    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path / "c"))
    built: list[int] = []
    path, hit = _entry("alpha", 7, 4096, built)
    assert not hit and built == [7]
    assert _entry("alpha", 7, 4096, built) == (path, True) and built == [7]  # verified: a hit
    record = path.with_suffix(".json")
    if damage == "truncated":
        path.write_bytes(path.read_bytes()[:1000])
    elif damage == "overwritten":  # same size, one byte changed
        data = bytearray(path.read_bytes())
        data[2049] ^= 0xFF
        path.write_bytes(bytes(data))
    else:
        record.write_text(record.read_text()[:20])
    with caplog.at_level("WARNING", logger="fegear.store.cache"):
        again, hit = _entry("alpha", 7, 4096, built)
    assert (again, hit) == (path, False) and built == [7, 7]
    assert path.read_bytes() == bytes([7]) * 4096
    (msg,) = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert "damaged" in msg and "alpha" in msg and str(tmp_path / "c") in msg
    assert _entry("alpha", 7, 4096, built) == (path, True) and built == [7, 7]


def test_a_truncated_operator_is_rebuilt_not_a_failed_run(monkeypatch, tmp_path):
    """The operator of a body cut short on disk (``mmap length is greater than file size``
    before the entries were verified) is computed again and equals the first one."""
    import numpy as np
    import skfem

    from fegear.fem.elasticity import assemble_body
    from fegear.mechanics.compliance import candidate_operator

    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path / "c"))
    mesh = skfem.MeshTet.init_tensor(*(np.linspace(0, 1, 4),) * 3).with_boundaries(
        {"bottom": lambda x: x[2] == 0.0, "top": lambda x: x[2] == 1.0}
    )
    body = assemble_body(mesh, 206000.0, 0.3, [("bottom", "xyz")])
    top = np.unique(body.basis.get_dofs("top").all())
    first = candidate_operator(body, top, "superlu", cache_key={"mesh": "cube"})
    (npy,) = (tmp_path / "c" / "compliance").glob("*.npy")
    G = np.array(first.blocks[0].G)
    npy.write_bytes(npy.read_bytes()[: npy.stat().st_size // 2])
    again = candidate_operator(body, top, "superlu", cache_key={"mesh": "cube"})
    assert not again.cache_hit
    np.testing.assert_array_equal(np.asarray(again.blocks[0].G), G)


def test_the_cap_evicts_the_least_recently_used_entries(monkeypatch, tmp_path):
    """Four entries of 1 MB under a cap of 3.5 MB: writing the fourth evicts the one used
    longest ago, not the one read last, nor one that a running piece of work has used."""
    root = tmp_path / "c"
    monkeypatch.setenv("FEGEAR_CACHE", str(root))
    monkeypatch.setenv("FEGEAR_CACHE_LIMIT", "3.5MB")
    mb = 10**6
    paths = [_entry("alpha", i, mb)[0] for i in range(3)]
    for k, p in enumerate(paths):  # last uses 1000, 2000, 3000 s after the epoch
        os.utime(p.with_suffix(".json"), (1000.0 * (k + 1),) * 2)
    assert _entry("alpha", 0, mb)[1]  # a hit: entry 0 is now the most recently used
    _entry("alpha", 3, mb)
    left = sorted(p.name for p in (root / "alpha").glob("*.bin"))
    assert left == sorted(p.name for p in (*paths[0:1], *paths[2:3], _entry("alpha", 3, mb)[0]))
    assert not paths[1].exists() and not paths[1].with_suffix(".json").exists()
    # inside a run (record_cache_use), its entries stay even beyond the cap
    with fcache.record_cache_use():
        kept = [_entry("beta", i, mb)[0] for i in range(4)]
        assert all(p.exists() for p in kept)
    assert fcache.cache_info().bytes < 3.5 * mb + 4 * mb
    monkeypatch.setenv("FEGEAR_CACHE_LIMIT", "lots")
    with pytest.raises(fcache.InputError, match="FEGEAR_CACHE_LIMIT"):
        fcache.cache_info()


def test_an_unusable_fegear_cache_exits_2_naming_it(monkeypatch, tmp_path, capsys):
    """Refused before any work (the run would otherwise fail on its first write, minutes in):
    a path under a file, a folder that cannot be written (a read-only mount, simulated: the
    tests run as root, which writes through permissions), a non-empty folder of other files."""
    import tempfile

    (tmp_path / "file").write_text("x")
    cases = {"under a file": tmp_path / "file" / "cache", "other files": tmp_path / "home"}
    (tmp_path / "home").mkdir()
    (tmp_path / "home" / "thesis.tex").write_text("precious")
    for why, root in cases.items():
        monkeypatch.setenv("FEGEAR_CACHE", str(root))
        assert main(["run", str(FZG), "--fidelity", "tca", "-q", "--out", str(tmp_path / "o")]) == 2
        err = capsys.readouterr().err
        assert "FEGEAR_CACHE" in err and str(root) in err, why
        assert not (tmp_path / "o").exists()  # nothing was run
    readonly = tmp_path / "ro"
    real = tempfile.mkstemp

    def mkstemp(*a, dir=None, **kw):
        if dir is not None and Path(dir) == readonly:
            raise OSError(30, "Read-only file system")
        return real(*a, dir=dir, **kw)

    readonly.mkdir()
    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    monkeypatch.setenv("FEGEAR_CACHE", str(readonly))
    assert main(["run", str(FZG), "--fidelity", "tca", "-q", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "FEGEAR_CACHE" in err and "Read-only file system" in err
    assert main(["sweep", str(FZG), "--out", str(tmp_path / "s"), "-q"]) == 2
    assert "FEGEAR_CACHE" in capsys.readouterr().err


def test_joined_cache_use_adds_the_counts_per_kind(tmp_path):
    """A run whose fields are computed after its numbers reports both pieces' lookups as one
    record: every kind's hits and builds added, the kinds of either kept."""
    a = fcache.CacheUse(tmp_path, {"mesh": 2, "tca": 1}, {"fields": 1})
    b = fcache.CacheUse(tmp_path, {"tca": 2}, {"fields": 1, "layer": 3})
    j = a.joined(b)
    assert j.root == tmp_path
    assert j.hits == {"mesh": 2, "tca": 3} and j.built == {"fields": 2, "layer": 3}
    assert not j.warm and fcache.CacheUse(tmp_path, {"tca": 1}, {}).joined(a).hits["tca"] == 2


def test_find_record_looks_without_building(monkeypatch, tmp_path, caplog):
    """``find_record`` is the hit half of ``cached_record``: None on a miss (nothing counted,
    nothing written), the entry and its record once built; a damaged entry is deleted with a
    warning and is a miss, as for ``cached_record``."""
    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path / "c"))
    made_by = fcache.Producer(("fegear.store",))
    params = {"run": "r1"}
    with fcache.record_cache_use() as used:
        assert fcache.find_record("delta", params, made_by) is None
    assert used().hits == {} and used().built == {}
    assert fcache.cache_info().files == 0

    def build(entry):
        entry.write(".one.png", lambda p: p.write_bytes(b"png bytes"))
        return {"names": ["one.png"]}

    fcache.cached_record("delta", params, build, made_by)
    with fcache.record_cache_use() as used:
        entry, record = fcache.find_record("delta", params, made_by)
    assert record == {"names": ["one.png"]} and used().hits == {"delta": 1}
    assert entry.path(".one.png").read_bytes() == b"png bytes"
    entry.path(".one.png").write_bytes(b"png bytez")  # same size, other bytes
    assert fcache.find_record("delta", params, made_by) is None
    assert "damaged" in caplog.text and not entry.record_path.exists()
