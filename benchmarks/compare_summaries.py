"""Compare two ``summary.json`` files bit for bit, except what describes the run rather than
its result (``timings_s``, ``cache``, ``versions``).

Run: ``python benchmarks/compare_summaries.py A/summary.json B/summary.json``; prints
``identical`` or the differing entries (path, the two values, their relative difference) and
exits 1. For a change meant to leave every number alone; the tolerances of the stored
references are in ``tests/reference/summaries.py``.
"""

from __future__ import annotations

import json
import math
import sys


def differences(a: object, b: object, path: str = "") -> list[tuple]:
    """``(path, a, b[, relative difference])`` of every entry that differs."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = [(path, "keys", sorted(set(a) ^ set(b)))] if set(a) != set(b) else []
        for k in a:
            if k in b:
                out += differences(a[k], b[k], f"{path}/{k}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [(path, "length", len(a), len(b))]
        pairs = enumerate(zip(a, b, strict=True))
        return [d for i, (x, y) in pairs for d in differences(x, y, f"{path}[{i}]")]
    if isinstance(a, float) and isinstance(b, float):
        if a == b or (math.isnan(a) and math.isnan(b)):
            return []
        return [(path, a, b, abs(a - b) / max(abs(a), abs(b)))]
    return [] if a == b else [(path, a, b)]


def main() -> int:
    a, b = (json.load(open(p, encoding="utf-8")) for p in sys.argv[1:3])
    for doc in (a, b):
        for k in ("timings_s", "cache", "versions"):
            doc.pop(k, None)
    out = differences(a, b)
    print("identical" if not out else f"{len(out)} differences")
    for d in out[:50]:
        print(*d)
    return 1 if out else 0


if __name__ == "__main__":
    sys.exit(main())
