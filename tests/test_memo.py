"""Values kept in the process (:mod:`fegear.store.memo`): given again only while the cache
entries they were made from are the same files, and then counted as the cache hits reading
those entries again would be."""

from __future__ import annotations

import numpy as np
import pytest

from fegear.store.cache import cached_file, record_cache_use
from fegear.store.memo import Memo


@pytest.fixture
def cache(monkeypatch, tmp_path):
    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


class _Maker:
    """A value made from one cache entry (kind ``tca``: any registered kind does): the array
    ``[x, x + 1, ...]`` written as ``.npy``, read back; counts how often it was made."""

    def __init__(self) -> None:
        self.made = 0

    def __call__(self, x: float):
        def make():
            self.made += 1
            path, _ = cached_file(
                "tca", {"memo_test": x}, ".npy", lambda p: np.save(p, x + np.arange(1000.0))
            )
            return np.load(path)

        return make


def test_a_kept_value_is_given_again_and_counted_as_the_hits_that_made_it(cache):
    memo, make = Memo("test value", 2), _Maker()
    with record_cache_use() as used:
        a, kept = memo.get({"x": 1.0}, make(1.0))
    assert not kept and make.made == 1 and used().built == {"tca": 1}
    with record_cache_use() as used:
        b, kept = memo.get({"x": 1.0}, make(1.0))
    assert kept and b is a and make.made == 1
    # as reading the entry again would count: a hit of its kind, nothing built
    assert used().hits == {"tca": 1} and used().built == {}
    assert memo.holds({"x": 1.0}) and not memo.holds({"x": 2.0})


def test_a_damaged_or_cleared_entry_makes_the_value_again(cache):
    memo, make = Memo("test value", 2), _Maker()
    a, _ = memo.get({"x": 1.0}, make(1.0))
    (data,) = (cache / "tca").glob("*.npy")
    data.write_bytes(data.read_bytes()[:100])  # truncated: the cache rebuilds it
    assert not memo.holds({"x": 1.0})
    with record_cache_use() as used:
        b, kept = memo.get({"x": 1.0}, make(1.0))
    assert not kept and make.made == 2 and used().built == {"tca": 1}
    np.testing.assert_array_equal(a, b)
    for p in (cache / "tca").glob("*"):  # cleared (`fegear cache clear`)
        p.unlink()
    _, kept = memo.get({"x": 1.0}, make(1.0))
    assert not kept and make.made == 3


def test_another_cache_folder_makes_the_value_again(cache, monkeypatch, tmp_path):
    memo, make = Memo("test value", 2), _Maker()
    memo.get({"x": 1.0}, make(1.0))
    monkeypatch.setenv("FEGEAR_CACHE", str(tmp_path / "other"))
    with record_cache_use() as used:
        _, kept = memo.get({"x": 1.0}, make(1.0))
    assert not kept and make.made == 2 and used().built == {"tca": 1}


def test_the_least_recently_used_value_is_dropped_beyond_the_size(cache):
    memo, make = Memo("test value", 2), _Maker()
    memo.get({"x": 1.0}, make(1.0))
    memo.get({"x": 2.0}, make(2.0))
    memo.get({"x": 1.0}, make(1.0))  # 1 used last: 2 is the least recently used
    memo.get({"x": 3.0}, make(3.0))
    assert memo.holds({"x": 1.0}) and memo.holds({"x": 3.0}) and not memo.holds({"x": 2.0})
    assert make.made == 3
