"""Work done in forked processes (:mod:`fegear.forked`): the pictures of a run drawn while its VTK
files are written, parts of one computation side by side. What the caller gets does not depend
on where it was done."""

from __future__ import annotations

import os

import pytest

from fegear.forked import apart


def test_work_apart_returns_what_it_returns_here(tmp_path):
    """The child writes its file and hands back its return value; the parent sees both."""
    target = tmp_path / "made_apart.txt"

    def work():
        target.write_text(str(os.getpid()))
        return [target, 42]

    wait = apart(work, fork=True)
    assert wait() == [target, 42]
    assert int(target.read_text()) != os.getpid()  # written by another process


def test_failed_work_is_done_again_here_and_raises_here(tmp_path):
    """A child that fails is reported and the work runs again in the caller, whose error the
    caller sees (not a lost child's)."""
    calls = tmp_path / "calls"
    calls.mkdir()

    def work():
        (calls / str(os.getpid())).touch()
        raise ValueError("no picture")

    wait = apart(work, fork=True)
    with pytest.raises(ValueError, match="no picture"):
        wait()
    pids = {int(p.name) for p in calls.iterdir()}
    assert os.getpid() in pids and len(pids) == 2  # once apart, once here


def test_without_fork_the_work_runs_here_when_asked():
    """``fork=False`` (one process wanted): nothing runs until the result is asked for, here."""
    ran = []
    wait = apart(lambda: ran.append(os.getpid()) or "here", fork=False)
    assert ran == []
    assert wait() == "here" and ran == [os.getpid()]


def test_fork_map_keeps_the_order_and_works_here_and_apart():
    """The first part here, the others in forked processes at the same time; results in the
    order of the parts."""
    from fegear.forked import fork_map

    out = fork_map(lambda p: (p, os.getpid()), [10, 11, 12])
    assert [p for p, _ in out] == [10, 11, 12]
    pids = [pid for _, pid in out]
    assert pids[0] == os.getpid() and os.getpid() not in pids[1:] and len(set(pids)) == 3
    assert fork_map(lambda p: os.getpid(), [1, 2], fork=False) == [os.getpid()] * 2
    assert fork_map(lambda p: p, []) == []


def test_sectors_meshed_side_by_side_are_the_meshes_made_here_and_counted_here():
    """The gear's sector meshed in a forked process while the pinion's is meshed here: the
    same meshes (same cache entries, same arrays) as both made here, and the run's cache record
    counts both lookups (the child's are sent back: ``fegear.store.cache.recorded``)."""
    import pickle
    from pathlib import Path

    import numpy as np

    from fegear.case_files import load_case
    from fegear.ltca.analysis import _sector_meshes_apart
    from fegear.pipeline.pair import build_pair
    from fegear.store.cache import record_cache_use

    pair = build_pair(load_case(Path(__file__).resolve().parents[1] / "cases" / "fzg_spur.toml"))
    members, sides = (pair.pinion, pair.gear), ("drive", "drive")
    with record_cache_use() as used:
        apart_ = [get() for get in _sector_meshes_apart(members, sides, 5, 0, workers=2)]
    use = used()
    assert sum(use.hits.values()) + sum(use.built.values()) == 2, use  # one lookup per member
    with record_cache_use() as again:
        here = [get() for get in _sector_meshes_apart(members, sides, 5, 0, workers=1)]
    assert again().hits == {"mesh": 2} and not again().built  # what the child built is cached
    for a, b in zip(apart_, here, strict=True):
        assert a.path == b.path and np.array_equal(a.points, b.points)
        assert np.array_equal(a.tets, b.tets) and a.boundaries.keys() == b.boundaries.keys()
        assert dict(a.parameters) == dict(b.parameters)
        c = pickle.loads(pickle.dumps(a))  # how it crossed: read-only mappings again
        assert np.array_equal(c.points, a.points) and c.parameters == a.parameters
        with pytest.raises(TypeError):
            c.parameters["level"] = 1  # type: ignore[index]


def test_nested_cache_records_each_count_their_own():
    """A block inside another (``recorded`` inside ``record_cache_use``) leaves the outer one
    in place however equal their counts (two empty records compare equal)."""
    from fegear.store.cache import record_cache_use, recorded

    with record_cache_use() as outer:
        value, lookups = recorded(lambda: 7)
    assert value == 7 and lookups.pid == os.getpid() and not lookups.hits
    assert outer().hits == {} and outer().built == {}


_MESH_AFTER_GMSH = """
import sys
from fegear.case_files import load_case
from fegear.ltca.analysis import _sector_meshes_apart
from fegear.mesh.sector import sector_mesh
from fegear.pipeline.pair import build_pair

pair = build_pair(load_case(sys.argv[1]))
sector_mesh(pair.pinion, 3, 0)  # gmsh started in this process
getters = _sector_meshes_apart((pair.pinion, pair.gear), ("drive", "drive"), 5, 0, workers=2)
meshes = [get() for get in getters]
print(len(meshes), meshes[1].tets.shape[0] > 0)
"""


def test_a_process_that_has_meshed_meshes_both_sectors_itself(tmp_path):
    """gmsh cannot mesh in a process forked after gmsh ran in its parent (the child's mesh
    generation waits forever on threads the fork did not copy): a process that has meshed
    before makes both sectors itself, and finishes (in a fresh process with a cold cache, so
    that both sectors are meshed; the timeout is what a hang would hit, ~10x the work)."""
    import subprocess
    import sys
    from pathlib import Path

    case = Path(__file__).resolve().parents[1] / "cases" / "fzg_spur.toml"
    env = dict(os.environ, FEGEAR_CACHE=str(tmp_path / "cache"))
    res = subprocess.run([sys.executable, "-c", _MESH_AFTER_GMSH, str(case)], env=env,
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    assert res.returncode == 0, res.stderr[-2000:]
    assert res.stdout.split() == ["2", "True"]
