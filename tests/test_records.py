"""The plain-data records of the cache (:mod:`fegear.store.records`): a tree of result objects
written as JSON + arrays and read back equal, bit for bit; nothing outside the registry."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pytest

from fegear.store.records import from_record, load_arrays, registry, save_arrays, to_record


class Box(NamedTuple):
    tooth: int
    u: tuple[float, float]


@dataclass(frozen=True)
class Leaf:
    values: np.ndarray
    flags: np.ndarray
    scale: float
    box: Box | None = None


@dataclass(frozen=True)
class Tree:
    leaves: tuple[Leaf, ...]
    names: list[str]
    seconds: dict[str, float]
    count: np.int64


CLASSES = registry(Tree, Leaf, Box)


def _round_trip(obj, tmp_path):
    arrays: dict[str, np.ndarray] = {}
    doc = json.loads(json.dumps(to_record(obj, arrays, "t", CLASSES)))  # as the cache stores it
    index = save_arrays(tmp_path / "a.npz", arrays)
    return from_record(doc, load_arrays(tmp_path / "a.npz", json.loads(json.dumps(index))), CLASSES)


def test_a_tree_reads_back_equal_bit_for_bit(tmp_path):
    rng = np.random.default_rng(3)
    tree = Tree(
        leaves=(
            Leaf(rng.normal(size=(4, 3)), rng.normal(size=5) > 0, 0.1 + 0.2, Box(2, (0.3, 1 / 3))),
            Leaf(np.arange(6, dtype=np.int32).reshape(2, 3), np.zeros(0, bool), math.inf),
        ),
        names=["a", "b"],
        seconds={"solve": 1e-300, "nan": math.nan},
        count=np.int64(7),
    )
    back = _round_trip(tree, tmp_path)
    assert type(back) is Tree and type(back.leaves[0].box) is Box  # the classes, not tuples
    assert back.leaves[0].box == tree.leaves[0].box and back.names == tree.names
    assert back.leaves[0].scale == 0.1 + 0.2 and back.leaves[1].scale == math.inf
    assert back.seconds["solve"] == 1e-300 and math.isnan(back.seconds["nan"])
    assert back.count == 7 and isinstance(back.count, np.int64)
    for a, b in zip(back.leaves, tree.leaves, strict=True):
        assert a.values.dtype == b.values.dtype and a.values.shape == b.values.shape
        np.testing.assert_array_equal(a.values, b.values)
        np.testing.assert_array_equal(a.flags, b.flags)


def test_an_object_outside_the_registry_is_refused_both_ways():
    with pytest.raises(TypeError, match="Leaf"):
        to_record(Leaf(np.zeros(1), np.zeros(1, bool), 1.0), {}, "t", registry(Tree))
    with pytest.raises(TypeError, match="dtype"):
        to_record(np.array(["x"]), {}, "t", CLASSES)
    with pytest.raises(ValueError, match="Leaf"):
        from_record({"dataclass": "Leaf", "fields": {}}, {}, registry(Tree))
    with pytest.raises(TypeError, match="not a dataclass"):
        registry(dict)
