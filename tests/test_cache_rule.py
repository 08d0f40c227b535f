"""One cache rule (issue 24): the key of every artefact is the hash of its kind, its content, the
code version of its producer and the versions of the third-party packages that produce it; no
pickles; a cache entry is complete or absent.

- The key changes with a content parameter, the producer's code hash or a dependency's version,
  and not with the order of the parameters; an object the key cannot hash is refused.
- A TCA read back from the cache (JSON + npz) is bit for bit the TCA that was computed.
- An interrupted write leaves no entry that a later run would trust.
- No source file of fegear imports pickle or loads arrays with pickles allowed.
"""

from __future__ import annotations

import ast
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from fegear.geometry import InvoluteDesign, InvoluteMember
from fegear.geometry.pair_placement import InstallationErrors, involute_assembly
from fegear.store import cache as fcache
from fegear.store import records as frecords
from fegear.tca import TCAOptions
from fegear.tca.cached import cached_tca
from fegear.tca.results import RECORD_CLASSES

PACKAGE = Path(__file__).resolve().parents[1] / "fegear"
PINION = InvoluteMember(
    InvoluteDesign(16, 4.5, 20, profile_shift=0.1817, face_width_mm=14), "pinion"
)
GEAR = InvoluteMember(InvoluteDesign(24, 4.5, 20, profile_shift=0.1715, face_width_mm=14), "gear")
OPT = TCAOptions(n_positions=5, separation_grid=(8, 4))
PHI1 = np.linspace(-0.1, 0.1, 5)


@pytest.fixture()
def private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path))
    return tmp_path


# --------------------------------------------------------------------------------------------
# The key
# --------------------------------------------------------------------------------------------

PARAMS = {"member": "InvoluteMember(...)", "level": 0, "zone": [[0, "drive", [0.0, 1.0]]]}


def test_key_changes_with_a_content_parameter_not_with_their_order():
    key = fcache.artefact_key("mesh", PARAMS)
    assert fcache.artefact_key("mesh", {**PARAMS, "level": 1}) != key
    assert fcache.artefact_key("mesh", {**PARAMS, "zone": [[0, "drive", [0.0, 0.9]]]}) != key
    assert fcache.artefact_key("mesh", dict(reversed(PARAMS.items()))) == key
    assert fcache.artefact_key("compliance", PARAMS) != key  # the kind is in the key


def test_key_changes_with_the_code_of_the_producer(monkeypatch):
    key = fcache.artefact_key("mesh", PARAMS)
    real = fcache.code_hash
    monkeypatch.setattr(
        fcache, "code_hash", lambda *m: "edited" if "fegear.mesh" in m else real(*m)
    )
    assert fcache.artefact_key("mesh", PARAMS) != key
    tca = fcache.artefact_key("tca", PARAMS)
    monkeypatch.setattr(fcache, "code_hash", real)
    assert fcache.artefact_key("tca", PARAMS) == tca  # fegear.mesh does not produce the TCA


def test_key_changes_with_a_dependency_version(monkeypatch):
    mesh, tca = fcache.artefact_key("mesh", PARAMS), fcache.artefact_key("tca", PARAMS)
    real = fcache._version
    monkeypatch.setattr(fcache, "_version", lambda d: "99.0" if d == "gmsh" else real(d))
    assert fcache.artefact_key("mesh", PARAMS) != mesh  # gmsh makes the meshes
    assert fcache.artefact_key("tca", PARAMS) == tca  # ... not the TCA
    monkeypatch.setattr(fcache, "_version", lambda d: "0.1" if d == "scipy" else real(d))
    assert fcache.artefact_key("tca", PARAMS) != tca


@pytest.fixture()
def fake_fegear(tmp_path, monkeypatch):
    """A source tree standing in for the fegear package (the code hashes of the real one are
    computed afresh after the test)."""
    root = tmp_path / "fegear"
    (root / "mesh").mkdir(parents=True)
    (root / "mesh" / "sector.py").write_text("A = 1\n")
    (root / "mechanics").mkdir()
    (root / "mechanics" / "hertz_closed_form.py").write_text("B = 1\n")
    monkeypatch.setattr(fcache, "_FEGEAR", root)
    fcache._code_hash.cache_clear()
    yield root
    fcache._code_hash.cache_clear()


def test_code_hash_is_the_source_of_the_producing_packages(fake_fegear):
    both = fcache.code_hash("fegear.mesh", "fegear.mechanics.hertz_closed_form")
    assert (
        fcache.code_hash("fegear.mechanics.hertz_closed_form", "fegear.mesh", "fegear.mesh") == both
    )
    mesh = fcache.code_hash("fegear.mesh")
    (fake_fegear / "mesh" / "sector.py").write_text("A = 2\n")
    assert fcache.code_hash("fegear.mesh") == mesh  # read once per process
    fcache._code_hash.cache_clear()
    assert fcache.code_hash("fegear.mesh") != mesh
    (fake_fegear / "mesh" / "sub").mkdir()
    (fake_fegear / "mesh" / "sub" / "deep.py").write_text("")
    changed = fcache.code_hash("fegear.mesh")
    fcache._code_hash.cache_clear()
    assert fcache.code_hash("fegear.mesh") != changed  # sub-packages are sources too
    for bad in ("fegear.nothing", "numpy", "fegear", "fegear.mesh/../x"):
        with pytest.raises(ValueError):
            fcache.code_hash(bad)


def test_every_kind_has_a_producer_found_in_this_installation():
    for kind, p in fcache.PRODUCERS.items():
        assert p.code and p.deps, kind
        assert len(fcache.code_hash(*p.code)) == 20
        assert all(fcache.dependency_versions(*p.deps).values()), (kind, p.deps)
    assert {"gmsh"} <= set(fcache.PRODUCERS["mesh"].deps)
    assert {"numpy", "scipy", "scikit-fem"} <= set(fcache.PRODUCERS["compliance"].deps)
    assert {"fegear.fem", "fegear.mechanics.compliance", "fegear.linalg"} <= set(
        fcache.PRODUCERS["compliance"].code
    )
    # the TCA's code: the pair's placement is fegear/geometry/pair_placement.py, and its
    # contact ellipses are closed-form Hertz
    assert {"fegear.tca", "fegear.geometry", "fegear.mechanics.hertz_closed_form"} <= set(
        fcache.PRODUCERS["tca"].code
    )


def test_a_kind_without_a_producer_is_refused(private_cache):
    with pytest.raises(ValueError, match="no producer"):
        fcache.cached_file("unknown_kind", {}, ".bin", lambda p: p.write_bytes(b""))
    assert not (private_cache / "unknown_kind").exists()


@dataclasses.dataclass(frozen=True)
class _Design:
    teeth: int
    shift: float
    memo: dict = dataclasses.field(default_factory=dict, compare=False)


def test_canonical_knows_plain_data_and_refuses_anything_else():
    same = [
        ({"a": np.float64(1.5), "b": np.int64(3), "c": np.bool_(1)}, {"a": 1.5, "b": 3, "c": True}),
        ({"t": (1, 2)}, {"t": [1, 2]}),
        ({"d": _Design(3, 0.1, {"x": object()})}, {"d": _Design(3, 0.1)}),  # compare=False out
    ]  # fmt: skip
    for a, b in same:
        assert fcache.content_hash(a) == fcache.content_hash(b)
    arr = np.arange(6.0).reshape(2, 3)
    assert fcache.content_hash({"x": arr}) != fcache.content_hash({"x": arr.reshape(3, 2)})
    assert fcache.content_hash({"x": arr}) != fcache.content_hash({"x": arr.astype(np.float32)})
    assert fcache.content_hash({"d": _Design(3, 0.1)}) != fcache.content_hash(
        {"d": _Design(3, 0.2)}
    )
    bad = [
        (object(), "object"),
        (Path("/tmp"), "Path"),
        ({1, 2}, "set"),
        (np.array([object()]), "dtype object"),
        (1 + 2j, "complex"),
        (lambda: None, "function"),
    ]
    for obj, name in bad:
        with pytest.raises(TypeError, match=name):
            fcache.content_hash({"p": {"q": [obj]}})
    with pytest.raises(TypeError, match=r"params\['p'\]\['q'\]\[0\]"):  # says where it is
        fcache.content_hash({"p": {"q": [object()]}})
    with pytest.raises(TypeError, match="key of type int"):
        fcache.content_hash({"p": {1: 2}})


# --------------------------------------------------------------------------------------------
# The TCA cache: JSON + npz, bit for bit
# --------------------------------------------------------------------------------------------


def _same(a, b, where="") -> None:
    """Equal bit for bit: the same types, array dtypes, shapes and bytes."""
    assert type(a) is type(b), (where, type(a), type(b))
    if dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            _same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, np.ndarray):
        assert (a.dtype, a.shape) == (b.dtype, b.shape), where
        assert a.tobytes() == b.tobytes(), where
    elif isinstance(a, (tuple, list)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{i}]")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for k in a:
            _same(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, float):
        assert np.float64(a).tobytes() == np.float64(b).tobytes(), (where, a, b)
    else:
        assert a == b, (where, a, b)


def _asm(f_sigma_beta_mm=0.01):
    return involute_assembly(PINION, GEAR, InstallationErrors(f_sigma_beta_mm=f_sigma_beta_mm))


def test_tca_round_trip_is_bitwise_and_holds_no_pickle(private_cache):
    cold = cached_tca(PINION, GEAR, _asm(), OPT, PHI1)
    warm = cached_tca(PINION, GEAR, _asm(), OPT, PHI1)
    assert not cold.cache_hit and warm.cache_hit
    _same(cold.positions, warm.positions, "positions")
    assert any(p.ellipse is not None for p in warm.positions)
    assert any(p.grids for p in warm.positions)
    assert warm.tca.asm.phase2 == cold.tca.asm.phase2
    _same(cold.tca.state_record(), warm.tca.state_record(), "state")
    # the TCA read back computes what the computed one does
    phi = PHI1[:2] + 0.013
    _same(tuple(cold.tca.positions(phi)), tuple(warm.tca.positions(phi)), "again")
    files = sorted(p.suffix for p in (private_cache / "tca").iterdir())
    assert files == [".json", ".npz"]
    npz = next((private_cache / "tca").glob("*.npz"))
    with np.load(npz, allow_pickle=False) as z:  # plain arrays: loads with pickles refused
        assert all(z[k].dtype.kind in "biuf" for k in z.files)
    doc = json.loads(next((private_cache / "tca").glob("*.json")).read_text())
    assert doc["files"] == [".npz"]


def test_a_record_of_an_unknown_object_is_refused():
    with pytest.raises(TypeError, match="object"):
        frecords.to_record({"x": object()}, {}, "s", RECORD_CLASSES)


# --------------------------------------------------------------------------------------------
# Complete or absent
# --------------------------------------------------------------------------------------------


class _Cut(Exception):
    pass


def test_an_interrupted_tca_write_leaves_no_trusted_entry(private_cache, monkeypatch):
    real = frecords.save_arrays

    def half(path, arrays):  # writes part of the file, then the run dies
        Path(path).write_bytes(b"PK\x03\x04 half an npz")
        raise _Cut

    monkeypatch.setattr(frecords, "save_arrays", half)
    with pytest.raises(_Cut):
        cached_tca(PINION, GEAR, _asm(), OPT, PHI1)
    assert list((private_cache / "tca").iterdir()) == []  # the temporary file is gone too
    monkeypatch.setattr(frecords, "save_arrays", real)
    again = cached_tca(PINION, GEAR, _asm(), OPT, PHI1)
    assert not again.cache_hit
    assert cached_tca(PINION, GEAR, _asm(), OPT, PHI1).cache_hit


_TEST_PRODUCER = fcache.Producer(("fegear.store",), ("numpy",))  # test kinds: not in PRODUCERS


def _record(kind, calls, producer=_TEST_PRODUCER):
    def build(entry):
        calls.append(1)
        entry.write(".npz", lambda p: p.write_bytes(b"arrays"))
        entry.write(".msh", lambda p: p.write_text("mesh"))
        return {"x": 0.1, "t": (1, 2)}

    return fcache.cached_record(kind, {"n": 1}, build, producer)


def test_a_record_is_trusted_only_when_its_json_and_all_its_files_are_there(
    private_cache, monkeypatch
):
    calls: list[int] = []
    entry, record, hit = _record("rec", calls)
    assert not hit and record == {"x": 0.1, "t": [1, 2]}  # as a hit reads it back
    assert _record("rec", calls)[1:] == (record, True) and len(calls) == 1
    entry.path(".msh").unlink()  # a data file gone: a miss, built again
    assert not _record("rec", calls)[2] and len(calls) == 2
    assert _record("rec", calls)[2]

    # the JSON that makes the entry valid is cut short: the data files are there, no entry
    real = fcache.atomic_write

    def dies_on_json(path, write):
        if Path(path).suffix == ".json":
            Path(path).with_name(".partial.json").write_text('{"format": "fegear.cac')
            raise _Cut
        return real(path, write)

    monkeypatch.setattr(fcache, "atomic_write", dies_on_json)
    with pytest.raises(_Cut):
        _record("cut", calls)
    monkeypatch.setattr(fcache, "atomic_write", real)
    folder = private_cache / "cut"
    assert {p.suffix for p in folder.glob("[0-9a-f]*")} == {".npz", ".msh"}  # no JSON
    n = len(calls)
    assert not _record("cut", calls)[2] and len(calls) == n + 1  # not trusted: built again

    # a build that fails after writing a data file leaves no JSON either
    def fails(entry):
        entry.write(".npz", lambda p: p.write_bytes(b"data"))
        raise _Cut

    with pytest.raises(_Cut):
        fcache.cached_record("fail", {"n": 1}, fails, fcache.Producer(("fegear.store",)))
    assert not list((private_cache / "fail").glob("*.json"))


def test_an_interrupted_single_file_write_leaves_nothing(private_cache):
    def dies(path):
        path.write_bytes(b"half")
        raise _Cut

    p = fcache.Producer(("fegear.store",))
    with pytest.raises(_Cut):
        fcache.cached_file("one", {"n": 1}, ".npy", dies, p)
    assert list((private_cache / "one").iterdir()) == []
    path, hit = fcache.cached_file("one", {"n": 1}, ".npy", lambda q: q.write_bytes(b"ok"), p)
    assert not hit and path.read_bytes() == b"ok"


# --------------------------------------------------------------------------------------------
# No pickles
# --------------------------------------------------------------------------------------------


def test_no_source_file_uses_pickle():
    """No module imports pickle (or its kin), and no array is loaded with pickles allowed
    (multiprocessing pickles the jobs of its worker processes: that is not a cache)."""
    banned = {"pickle", "cPickle", "dill", "cloudpickle", "joblib", "shelve", "marshal"}
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        for node in ast.walk(ast.parse(text)):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names = [node.module]
            found += [f"{path}:{node.lineno}: {n}" for n in names if n.split(".")[0] in banned]
        if "allow_pickle=True" in text.replace(" ", ""):
            found.append(f"{path}: allow_pickle=True")
    assert not found, found


def test_face_gear_limits_are_read_back_from_the_cache(private_cache):
    """The second pair of a face-gear case reads its limits and fillet-limit tables from the
    cache (one hit, nothing built) and they are the solved ones, bit for bit."""
    import fegear
    from fegear.pipeline.pair import build_pair
    from fegear.store.cache import record_cache_use

    case = fegear.load_case(PACKAGE.parent / "cases" / "face_gear_nominal.toml")
    first = build_pair(case).gear
    with record_cache_use() as used:
        again = build_pair(case).gear
    assert used().hits == {"face_gear_limits": 1} and not used().built
    assert again.limits == first.limits
    L = np.linspace(471.0, 560.0, 19)
    assert np.array_equal(again.fillet_height(L, "coast"), first.fillet_height(L, "coast"))
